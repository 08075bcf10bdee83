#include "procedural/builtin/builtin_shaders.h"

#include <cmath>

#include "core/ray_offset.h"
#include "emulator/intersection_wave.h"
#include "emulator/ray_generation_wave.h"
#include "emulator/shader_api.h"
#include "procedural/wave_shader.h"

namespace refray::procedural::builtin {

using namespace refray::dxr;

namespace {

constexpr float kTMax = 10000.0f;
constexpr float kFixedTMin = 0.001f;

// Where a secondary ray leaving `position` (geometric normal `normal`) in `direction` starts, and its TMin.
RayDesc secondaryRay(SecondaryRayOrigin mode, vec3 position, vec3 normal, vec3 direction, float tMax) {
    switch (mode) {
        case SecondaryRayOrigin::WaechterBinder: {
            const vec3 side = glm::dot(normal, direction) >= 0.0f ? normal : -normal;
            return RayDesc{offsetRayOrigin(position, side), 0.0f, direction, tMax};
        }
        case SecondaryRayOrigin::FixedTMin: return RayDesc{position, kFixedTMin, direction, tMax};
        case SecondaryRayOrigin::HitPoint: break;
    }
    return RayDesc{position, 0.0f, direction, tMax};
}

SceneConstants sceneConstants(ShaderContext& ctx) {
    return ctx.load<SceneConstants>(ctx.globalRootDescriptor(kSceneConstants));
}

vec3 hitWorldPosition(ShaderContext& ctx) { return ctx.WorldRayOrigin() + ctx.RayTCurrent() * ctx.WorldRayDirection(); }

// traceRadiance up to its TraceRay: false at the recursion limit (black, no ray); else `payload` initialised and
// `call` the TraceRay with it, for the caller to make (alone, or with a wave's other lanes).
bool radianceCall(ShaderContext& ctx, const RayDesc& ray, uint32_t depth, RadiancePayload& payload,
                  TraceRayCall& call) {
    if (depth >= kMaxRecursionDepth) return false;
    payload = RadiancePayload{vec4(0.0f), depth + 1};
    setTraceRayCall(call, ctx.globalRootDescriptor(kAccelerationStructure), RAY_FLAG_CULL_BACK_FACING_TRIANGLES, 0xFF,
                    0, kRayTypeCount, 0, ray, payload);
    return true;
}

vec4 traceRadiance(ShaderContext& ctx, const RayDesc& ray, uint32_t depth) {
    RadiancePayload payload{};
    TraceRayCall call;
    if (!radianceCall(ctx, ray, depth, payload, call)) return vec4(0.0f);
    ctx.TraceRay(call);
    return payload.color;
}

bool inShadow(ShaderContext& ctx, const RayDesc& ray, uint32_t depth) {
    if (depth >= kMaxRecursionDepth) return false;
    ShadowPayload payload{1};
    ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure),
                 RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, 0xFF,
                 1, kRayTypeCount, 1, ray, payload);
    return payload.hit != 0;
}

// `normal` is the geometric normal (the plane's and the sphere's are their shading normals too).
vec3 shade(ShaderContext& ctx, SecondaryRayOrigin mode, vec3 albedo, vec3 normal, vec3 position, uint32_t depth) {
    const SceneConstants sc = sceneConstants(ctx);
    const vec3 toLight = vec3(sc.lightPosition) - position;
    const float distance = glm::length(toLight);
    const vec3 l = toLight / distance;
    const bool shadowed = glm::dot(normal, l) > 0.0f && inShadow(ctx, secondaryRay(mode, position, normal, l, distance), depth);
    return lambert(albedo, normal, l, shadowed);
}

}  // namespace

vec4 skyColor(vec3 direction) {
    constexpr vec4 kSkyTop{0.35f, 0.55f, 0.9f, 1.0f};
    constexpr vec4 kSkyHorizon{0.85f, 0.9f, 1.0f, 1.0f};
    const float up = std::clamp(glm::normalize(direction).y, 0.0f, 1.0f);
    return kSkyHorizon + (kSkyTop - kSkyHorizon) * up;
}

vec3 checkerAlbedo(vec3 p, vec3 albedo) {
    const bool checker = (int(std::floor(p.x)) + int(std::floor(p.z))) & 1;
    return albedo * (checker ? 1.0f : 0.55f);
}

vec3 lambert(vec3 albedo, vec3 normal, vec3 toLightUnit, bool shadowed) {
    const float cosine = std::max(0.0f, glm::dot(normal, toLightUnit));
    return albedo * (0.15f + (shadowed ? 0.0f : 0.85f * cosine));
}

vec3 primaryDirection(const SceneConstants& sc, uvec3 index, uvec3 dims) {
    const float sx = (float(index.x) + 0.5f) / float(dims.x) * 2.0f - 1.0f;
    const float sy = -((float(index.y) + 0.5f) / float(dims.y) * 2.0f - 1.0f);
    return glm::normalize(vec3(sc.cameraForward) + sx * vec3(sc.cameraRight) + sy * vec3(sc.cameraUp));
}

std::string_view toString(SecondaryRayOrigin origin) {
    switch (origin) {
        case SecondaryRayOrigin::WaechterBinder: return "waechter-binder";
        case SecondaryRayOrigin::FixedTMin: return "fixed-tmin";
        case SecondaryRayOrigin::HitPoint: return "hit-point";
    }
    return "?";
}

std::shared_ptr<ShaderLibrary> makeShaderLibrary(SecondaryRayOrigin mode) {
    auto lib = std::make_shared<ShaderLibrary>();

    // Written for waves (emulator/ray_generation_wave.h): each lane computes its camera ray, the wave's lanes trace
    // them together, then each lane writes its pixel.
    lib->addWaveRayGeneration("RayGen", [](RayGenerationWave& wave) {
        wave.TraceRayInEachLane<RadiancePayload>(
            [](ShaderContext& ctx, RadiancePayload& payload, TraceRayCall& call) {
                const SceneConstants sc = sceneConstants(ctx);
                const vec3 d = primaryDirection(sc, ctx.DispatchRaysIndex(), ctx.DispatchRaysDimensions());
                return radianceCall(ctx, RayDesc{vec3(sc.cameraPosition), 0.001f, d, kTMax}, 0, payload, call);
            },
            [](ShaderContext& ctx, const RadiancePayload& payload, bool traced) {
                const uvec3 index = ctx.DispatchRaysIndex();
                ctx.rwTexture2D(ctx.globalDescriptorTable(kOutputTable)).at(index.x, index.y) =
                    traced ? payload.color : vec4(0.0f);
            });
    });

    lib->addMiss<RadiancePayload>("Miss", [](ShaderContext& ctx, RadiancePayload& payload) {
        payload.color = skyColor(ctx.WorldRayDirection());
    });

    lib->addMiss<ShadowPayload>("Miss_Shadow", [](ShaderContext&, ShadowPayload& payload) { payload.hit = 0; });

    lib->addClosestHit<RadiancePayload, BuiltInTriangleIntersectionAttributes>(
        "ClosestHit_Plane", [mode](ShaderContext& ctx, RadiancePayload& payload, const BuiltInTriangleIntersectionAttributes&) {
            const MaterialConstants m = ctx.localRootConstants<MaterialConstants>(kMaterialParameter);
            const vec3 p = hitWorldPosition(ctx);
            payload.color =
                vec4(shade(ctx, mode, checkerAlbedo(p, vec3(m.albedo)), vec3(0.0f, 1.0f, 0.0f), p, payload.recursionDepth), 1.0f);
        });

    // Analytic sphere in object space; reports t in the caller's (object = world) units.
    // Run over the lanes of a record group (emulator/intersection_wave.h): each lane reads its ray and the sphere,
    // the root is found for all lanes at once, each lane reports its own hit.
    lib->addWaveIntersection<SphereAttributes>("Intersection_Sphere", kWaveLanes, [](IntersectionWave& wave) {
        struct LaneInput {
            vec3 o, d;
            float radius, tMin, tCurrent;
        };
        const auto in = gatherLanes(wave, [](ShaderContext& ctx) {
            const SceneConstants sc = sceneConstants(ctx);
            return LaneInput{ctx.ObjectRayOrigin() - vec3(sc.sphere), ctx.ObjectRayDirection(), sc.sphere.w,
                             ctx.RayTMin(), ctx.RayTCurrent()};
        });
        if (wave.active().empty()) return;
        using L = WaveLanes<float>;
        const auto o = toLanes<glm::vec<3, L>>(in, [](const LaneInput& l) { return l.o; });
        const auto d = toLanes<glm::vec<3, L>>(in, [](const LaneInput& l) { return l.d; });
        const L radius = toLanes<L>(in, [](const LaneInput& l) { return l.radius; });
        const L tMin = toLanes<L>(in, [](const LaneInput& l) { return l.tMin; });
        const L tCurrent = toLanes<L>(in, [](const LaneInput& l) { return l.tCurrent; });
        L t(0.0f);
        const math::LaneMask<L> hit = intersectSphere(o, d, radius, tMin, tCurrent, t);
        for (int i : wave.active()) {
            if (!math::lane(hit, i)) continue;
            const LaneInput& l = in[size_t(i)];
            const float ti = math::lane(t, i);
            wave.ReportHit(i, ti, 0, SphereAttributes{(l.o + ti * l.d) / l.radius});
        }
    }, ReportHitEnd::Return);  // the ReportHit is its last action

    lib->addClosestHit<RadiancePayload, SphereAttributes>(
        "ClosestHit_Sphere", [mode](ShaderContext& ctx, RadiancePayload& payload, const SphereAttributes& attr) {
            const MaterialConstants m = ctx.localRootConstants<MaterialConstants>(kMaterialParameter);
            // Object-space normal to world: the inverse transpose of ObjectToWorld.
            const Matrix3x4 w2o = ctx.WorldToObject3x4();
            const vec3 n = glm::normalize(vec3(w2o.m[0][0] * attr.normal.x + w2o.m[1][0] * attr.normal.y + w2o.m[2][0] * attr.normal.z,
                                               w2o.m[0][1] * attr.normal.x + w2o.m[1][1] * attr.normal.y + w2o.m[2][1] * attr.normal.z,
                                               w2o.m[0][2] * attr.normal.x + w2o.m[1][2] * attr.normal.y + w2o.m[2][2] * attr.normal.z));
            const vec3 p = hitWorldPosition(ctx);
            vec3 color = shade(ctx, mode, vec3(m.albedo), n, p, payload.recursionDepth);
            const float reflectance = m.albedo.w;
            if (reflectance > 0.0f) {
                const vec3 r = glm::reflect(ctx.WorldRayDirection(), n);
                color += reflectance * vec3(traceRadiance(ctx, secondaryRay(mode, p, n, r, kTMax), payload.recursionDepth));
            }
            payload.color = vec4(color, 1.0f);
        });
    return lib;
}

}  // namespace refray::procedural::builtin
