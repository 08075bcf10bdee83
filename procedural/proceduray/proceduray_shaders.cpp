// Ports: Proceduray Raytracing.hlsl, Helpers.hlsli, RaytracingShaderHelper.hlsli (camera ray, Fresnel, index loads),
// Triangles.hlsli, Pacman.hlsli, JuliaSets.hlsli, Mandelbulb.hlsli entry points; see proceduray_shaders.h.
#include "procedural/proceduray/proceduray_shaders.h"

#include <array>
#include <cstring>

#include "emulator/closest_hit_wave.h"
#include "emulator/intersection_wave.h"
#include "emulator/ray_generation_wave.h"
#include "emulator/shader_api.h"
#include "procedural/math/fractals.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/perturbed.h"
#include "procedural/math/ray.h"
#include "procedural/math/sdf.h"
#include "procedural/wave_shader.h"

namespace refray::procedural::proceduray {

using namespace refray::dxr;

// ---- Scene data (§1.1) -----------------------------------------------------------------------------

const std::array<uint16_t, 36> kSlabIndices = {0, 4, 7, 0, 7, 3, 1, 5, 4, 1, 4, 0, 5, 2, 6, 5, 1, 2,
                                               3, 7, 6, 3, 6, 2, 2, 0, 3, 2, 1, 0, 4, 6, 7, 4, 5, 6};

const std::array<Vertex, 8> kSlabVertices = {{
    {{-0.5f, -0.2f, 0.2f}, {0.0f, 0.0f, -1.0f}},
    {{-0.5f, -0.2f, -0.2f}, {0.0f, 1.0f, 0.0f}},
    {{-0.5f, 0.2f, -0.2f}, {1.0f, 0.0f, 0.0f}},
    {{-0.5f, 0.2f, 0.2f}, {0.0f, -1.0f, 0.0f}},
    {{0.5f, -0.2f, 0.2f}, {-1.0f, 0.0f, 0.0f}},
    {{0.5f, -0.2f, -0.2f}, {0.0f, 0.0f, 1.0f}},
    {{0.5f, 0.2f, -0.2f}, {0.0f, 1.0f, 0.0f}},
    {{0.5f, 0.2f, 0.2f}, {0.0f, 1.0f, 0.0f}},
}};

// ---- Root signatures and hit groups ----------------------------------------------------------------

RootSignatureDesc globalRootSignatureDesc() { return sampleGlobalRootSignatureDesc("GlobalSignature"); }

RootSignatureDesc triangleLocalRootSignatureDesc() {
    return sampleTriangleLocalRootSignatureDesc("Triangle");
}

RootSignatureDesc proceduralLocalRootSignatureDesc() {
    return sampleProceduralLocalRootSignatureDesc("Procedural");
}

std::vector<HitGroupDesc> procedurayHitGroups() {
    using enum HitGroupType;
    return {
        {"HitGroup_Triangle", Triangles, "", "ClosestHit_Triangle", ""},
        {"HitGroup_Triangle_Shadow", Triangles, "", "", ""},
        {"HitGroup_Pacman", ProceduralPrimitive, "", "ClosestHit_Pacman", "Intersection_Pacman"},
        {"HitGroup_Pacman_Shadow", ProceduralPrimitive, "", "", "Intersection_Pacman"},
        {"HitGroup_Mandelbulb", ProceduralPrimitive, "", "ClosestHit_Mandelbulb", "Intersection_Mandelbulb"},
        {"HitGroup_Mandelbulb_Shadow", ProceduralPrimitive, "", "", "Intersection_Mandelbulb"},
        {"HitGroup_Julia", ProceduralPrimitive, "", "ClosestHit_Julia", "Intersection_Julia"},
        {"HitGroup_Julia_Shadow", ProceduralPrimitive, "", "", "Intersection_Julia"},
    };
}

// ---- Pure helpers ----------------------------------------------------------------------------------

namespace {

template <typename T>
using tvec2 = math::vec2<T>;
template <typename T>
using tvec3 = math::vec3<T>;
template <typename T>
using tvec4 = math::vec4<T>;

}  // namespace

template <typename T>
tvec3<T> colorSurface(tvec3<T> pos, tvec2<T> tn) {
    tvec3<T> col = T(0.5f) + T(0.5f) * hlsl::cos(hlsl::log2(tn.y) * T(0.9f) + T(3.5f) + tvec3<T>(0.0f, 0.6f, 1.0f));
    if (pos.y > T(0)) col = hlsl::lerp(col, tvec3<T>(T(1)), T(0.2f));
    const T inside = hlsl::smoothstep(T(14), T(15), tn.y);
    col *= tvec3<T>(0.45f, 0.42f, 0.40f) + tvec3<T>(0.55f, 0.58f, 0.60f) * inside;
    col = hlsl::lerp(col * col * (T(3) - T(2) * col), col, inside);
    col = hlsl::lerp(hlsl::lerp(col, tvec3<T>(hlsl::dot(col, tvec3<T>(0.3333f, 0.333f, 0.333f))), T(-0.4f)), col,
                     inside);
    return hlsl::clamp(col * T(0.65f), T(0), T(1));
}

template <typename T>
tvec4<T> MandelbulbSurfaceColor(tvec3<T> D, tvec3<T> N, tvec4<T> trap) {
    // Colour from the orbit trap.
    tvec3<T> col(0.01f, 0.01f, 0.01f);
    col = hlsl::lerp(col, tvec3<T>(0.10f, 0.20f, 0.30f), hlsl::clamp(trap.y, T(0), T(1)));
    col = hlsl::lerp(col, tvec3<T>(0.02f, 0.10f, 0.30f), hlsl::clamp(trap.z * trap.z, T(0), T(1)));
    col = hlsl::lerp(col, tvec3<T>(0.30f, 0.10f, 0.02f), hlsl::clamp(hlsl::pow(trap.w, T(6)), T(0), T(1)));
    col *= T(0.5f);

    // Lighting terms: two fixed lights, no scene light, no shadow (sha1 = 1).
    const tvec3<T> light1(0.577f, 0.577f, -0.577f);
    const tvec3<T> light2(-0.707f, 0.000f, 0.707f);
    const tvec3<T> nor = N;
    const tvec3<T> hal = hlsl::normalize(light1 - D);
    const T occ = hlsl::clamp(T(0.05f) * hlsl::log(trap.x), T(0), T(1));
    const T fac = hlsl::clamp(T(1) + hlsl::dot(D, nor), T(0), T(1));

    const T sha1 = T(1);
    const T dif1 = hlsl::clamp(hlsl::dot(light1, nor), T(0), T(1)) * sha1;
    const T spe1 = hlsl::pow(hlsl::clamp(hlsl::dot(nor, hal), T(0), T(1)), T(32)) * dif1 *
                   (T(0.04f) + T(0.96f) * hlsl::pow(hlsl::clamp(T(1) - hlsl::dot(hal, light1), T(0), T(1)), T(5)));
    const T dif2 = hlsl::clamp(T(0.5f) + T(0.5f) * hlsl::dot(light2, nor), T(0), T(1)) * occ;
    const T dif3 = (T(0.7f) + T(0.3f) * nor.y) * (T(0.2f) + T(0.8f) * occ);

    tvec3<T> lin(T(0));
    lin += T(7) * tvec3<T>(1.50f, 1.10f, 0.70f) * dif1;
    lin += T(4) * tvec3<T>(0.25f, 0.20f, 0.15f) * dif2;
    lin += T(1.5f) * tvec3<T>(0.10f, 0.20f, 0.30f) * dif3;
    lin += T(2.5f) * tvec3<T>(0.35f, 0.30f, 0.25f) * (T(0.05f) + T(0.95f) * occ);
    lin += T(4) * fac * occ;
    col *= lin;
    col = hlsl::pow(col, tvec3<T>(0.7f, 0.9f, 1.0f));
    col += spe1 * T(15);
    col = hlsl::sqrt(col);
    return tvec4<T>(col, T(1));
}

namespace {

template <typename T>
T CalculateDiffuseCoefficient(const tvec3<T>& incidentLightRay, const tvec3<T>& normal) {
    return hlsl::saturate(hlsl::dot(-incidentLightRay, normal));
}

template <typename T>
T CalculateSpecularCoefficient(const tvec3<T>& incidentLightRay, const tvec3<T>& normal, T specularPower,
                               const tvec3<T>& worldRayDirection) {
    const tvec3<T> reflectedLightRay = hlsl::normalize(hlsl::reflect(incidentLightRay, normal));
    return hlsl::pow(hlsl::saturate(hlsl::dot(reflectedLightRay, hlsl::normalize(-worldRayDirection))), specularPower);
}

}  // namespace

// Phong = ambient (with the "fake AO" towards -y) + diffuse + specular; the light is a point light.
template <typename T>
tvec4<T> CalculatePhongLighting(const SceneConstantBuffer& g_sceneCB, tvec4<T> albedo, tvec3<T> normal, bool isInShadow,
                                T diffuseCoef, T specularCoef, T specularPower, tvec3<T> hitPosition,
                                tvec3<T> worldRayDirection) {
    const tvec3<T> lightPosition = tvec3<T>(g_sceneCB.lightPosition);
    const T shadowFactor = isInShadow ? T(kInShadowRadiance) : T(1);
    const tvec3<T> incidentLightRay = hlsl::normalize(hitPosition - lightPosition);

    // Diffuse component.
    const tvec4<T> lightDiffuseColor = tvec4<T>(g_sceneCB.lightDiffuseColor);
    const T Kd = CalculateDiffuseCoefficient(incidentLightRay, normal);
    const tvec4<T> diffuseColor = shadowFactor * diffuseCoef * Kd * lightDiffuseColor * albedo;

    // Specular component.
    tvec4<T> specularColor(T(0));
    if (!isInShadow) {
        const tvec4<T> lightSpecularColor(T(1));
        const T Ks = CalculateSpecularCoefficient(incidentLightRay, normal, specularPower, worldRayDirection);
        specularColor = specularCoef * Ks * lightSpecularColor;
    }

    // Ambient component.
    const tvec4<T> ambientColorMin = tvec4<T>(g_sceneCB.lightAmbientColor) - T(0.1f);
    const tvec4<T> ambientColorMax = tvec4<T>(g_sceneCB.lightAmbientColor);
    const T a = T(1) - hlsl::saturate(hlsl::dot(normal, tvec3<T>(0.0f, -1.0f, 0.0f)));
    const tvec4<T> ambientColor = albedo * hlsl::lerp(ambientColorMin, ambientColorMax, a);

    return ambientColor + diffuseColor + specularColor;
}

#define REFRAY_INSTANTIATE_HELPERS(T)                                                                          \
    template tvec3<T> colorSurface<T>(tvec3<T>, tvec2<T>);                                                     \
    template tvec4<T> MandelbulbSurfaceColor<T>(tvec3<T>, tvec3<T>, tvec4<T>);                                 \
    template tvec4<T> CalculatePhongLighting<T>(const SceneConstantBuffer&, tvec4<T>, tvec3<T>, bool, T, T, T, \
                                                tvec3<T>, tvec3<T>);
REFRAY_INSTANTIATE_HELPERS(float)
REFRAY_INSTANTIATE_HELPERS(double)
#undef REFRAY_INSTANTIATE_HELPERS

// ---- Accuracy knobs --------------------------------------------------------------------------------

template <typename T>
math::mandelbulb::MandelbulbParams<T> mandelbulbParams(const Accuracy& accuracy) {
    math::mandelbulb::MandelbulbParams<T> params;  // the HLSL's constants
    params.threshold = scaledConstant(params.threshold, accuracy.thresholdFactor);
    if (accuracy.mandelbulbIterations) params.iterations = hlslLoopCount(*accuracy.mandelbulbIterations);
    params.normalOffset = scaledConstant(params.normalOffset, accuracy.normalEpsilonFactor);
    return params;
}

int mandelbulbStepCount(int iMax, const Accuracy& accuracy) {
    if (iMax < 1) return iMax;
    return hlslLoopCount(scaledSteps(uint32_t(iMax), accuracy.stepsFactor));
}

template <typename T>
math::julia::JuliaParams<T> juliaParams(const Accuracy& accuracy) {
    math::julia::JuliaParams<T> params;  // the HLSL's constants
    if (accuracy.juliaIterations) params.iterations = hlslLoopCount(*accuracy.juliaIterations);
    params.marchSteps = hlslLoopCount(scaledSteps(uint32_t(params.marchSteps), accuracy.stepsFactor));
    params.precis = scaledConstant(params.precis, accuracy.thresholdFactor);
    params.normalOffset = scaledConstant(params.normalOffset, accuracy.normalEpsilonFactor);
    return params;
}

uint32_t maxRayRecursionDepth(const Accuracy& accuracy) {
    return accuracy.maxRecursionDepth.value_or(MAX_RAY_RECURSION_DEPTH);
}

#define REFRAY_INSTANTIATE_KNOBS(T)                                                                     \
    template math::mandelbulb::MandelbulbParams<T> mandelbulbParams<T>(const Accuracy&);                \
    template math::julia::JuliaParams<T> juliaParams<T>(const Accuracy&);
REFRAY_INSTANTIATE_KNOBS(float)
REFRAY_INSTANTIATE_KNOBS(double)
#undef REFRAY_INSTANTIATE_KNOBS

// ---- Shader-side helpers (Helpers.hlsli, RaytracingShaderHelper.hlsli) -----------------------------

namespace {

SceneConstantBuffer sceneCB(const ShaderContext& ctx) {
    return ctx.load<SceneConstantBuffer>(ctx.globalRootDescriptor(kSceneConstantBuffer));
}

PrimitiveConstantBuffer materialCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveConstantBuffer>(kMaterialConstantBuffer);
}

PrimitiveInstanceConstantBuffer aabbCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveInstanceConstantBuffer>(kAABBConstantBuffer);
}

template <typename T>
tvec3<T> HitWorldPosition(const ShaderContext& ctx) {
    return tvec3<T>(ctx.WorldRayOrigin()) + T(ctx.RayTCurrent()) * tvec3<T>(ctx.WorldRayDirection());
}

// The world ray in the AABB's local space through g_instanceBuffer[l_aabbCB.instanceIndex]; the
// direction is normalised, which is where H1 comes from.
// PORT: in two parts, the instance's element (g_instanceBuffer[l_aabbCB.instanceIndex]) and the ray through it, so
// that the lanes of a record group read the element once (ProceduralWave).
InstanceBuffer AABBPrimitiveInstance(const ShaderContext& ctx, const PrimitiveInstanceConstantBuffer& l_aabbCB) {
    const GpuVirtualAddress element =
        ctx.globalRootDescriptor(kInstanceBuffer) + uint64_t(l_aabbCB.instanceIndex) * sizeof(InstanceBuffer);
    return ctx.load<InstanceBuffer>(element);
}

template <typename T>
math::Ray<T> GetRayInAABBPrimitiveLocalSpace(const ShaderContext& ctx, const InstanceBuffer& attr) {
    math::Ray<T> ray;
    ray.origin = tvec3<T>(mul(tvec4<T>(tvec3<T>(ctx.WorldRayOrigin()), T(1)), attr.localSpaceToBottomLevelAS));
    ray.direction = hlsl::normalize(mul3x3(tvec3<T>(ctx.WorldRayDirection()), attr.localSpaceToBottomLevelAS));
    return ray;
}

// normalize(mul(n, (float3x3)WorldToObject3x4())): the inverse transpose of ObjectToWorld.
template <typename T>
tvec3<T> NormalToWorld(const ShaderContext& ctx, const tvec3<T>& n) {
    const Matrix3x4 w = ctx.WorldToObject3x4();
    tvec3<T> r;
    for (int j = 0; j < 3; ++j) r[j] = n.x * T(w.m[0][j]) + n.y * T(w.m[1][j]) + n.z * T(w.m[2][j]);
    return hlsl::normalize(r);
}

template <typename T>
math::RayExtent<T> CurrentExtent(const ShaderContext& ctx) {
    const uint32_t flags = ctx.RayFlags();
    return {T(ctx.RayTMin()), T(ctx.RayTCurrent()), (flags & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) != 0,
            (flags & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) != 0};
}

// TraceRay wrappers: both stop at MAX_RAY_RECURSION_DEPTH (black / "not in shadow"); TMin 0, TMax 10000.
// The RayDesc and the payload are the GPU interface: the ray is rounded to float on the way in.
// PORT: the HLSL passes the constants kInstanceMask, <ray type>, RayTypeCount, <ray type>; here they come from
// `traceRay` (the library's TraceRayArgumentSet, those same values by default), which every caller passes down.
// PORT: MAX_RAY_RECURSION_DEPTH is the library's `maxDepth` (maxRayRecursionDepth of its Accuracy), passed down
// the same way; so is the library's Effects, whose traceShadowRays false makes every shadow call site return "not in
// shadow" untraced, as at that depth.
// PORT: TraceRadianceRay up to its TraceRay: false at MAX_RAY_RECURSION_DEPTH (no ray: black); else `rayPayload`
// initialised and `call` the TraceRay with it, for the caller to make (alone, or with a wave's other lanes).
template <typename T>
bool RadianceRayCall(ShaderContext& ctx, const TraceRayArgumentSet& traceRay, uint32_t maxDepth,
                     const tvec3<T>& origin, const tvec3<T>& direction, uint32_t currentRayRecursionDepth,
                     RayPayload& rayPayload, TraceRayCall& call) {
    if (currentRayRecursionDepth >= maxDepth) return false;
    rayPayload = RayPayload{vec4(0.0f), currentRayRecursionDepth + 1, 0.0f, 0, 0};
    const TraceRayArguments& radiance = traceRay[Radiance];
    setTraceRayCall(call, ctx.globalRootDescriptor(kAccelerationStructure), kTraceRayFlags[Radiance],
                    radiance.instanceInclusionMask, /*RayContributionToHitGroupIndex*/ radiance.rayContribution,
                    /*MultiplierForGeometryContribution*/ radiance.multiplier,
                    /*MissShaderIndex*/ radiance.missShaderIndex, /*RayDesc*/ vec3(origin), 0.0f, vec3(direction),
                    10000.0f, rayPayload);
    return true;
}

// PORT: TraceShadowRayAndReportIfHit towards the light from HitWorldPosition(), up to its TraceRay: false where the
// HLSL returns false untraced (at MAX_RAY_RECURSION_DEPTH, or with shadows switched off); else `shadowPayload`
// initialised and `call` the TraceRay with it, for the caller to make (alone, or with a wave's other lanes). The
// function's result is then shadowPayload.hit != 0.
template <typename T>
bool ShadowRayTowardsLightCall(ShaderContext& ctx, const TraceRayArgumentSet& traceRay, uint32_t maxDepth,
                               const Effects& effects, const SceneConstantBuffer& g_sceneCB,
                               uint32_t currentRayRecursionDepth, ShadowRayPayload& shadowPayload, TraceRayCall& call) {
    const tvec3<T> origin = HitWorldPosition<T>(ctx);
    const tvec3<T> direction = hlsl::normalize(tvec3<T>(g_sceneCB.lightPosition) - origin);
    if (currentRayRecursionDepth >= maxDepth) return false;
    if (!kShadowMachinery || !effects.traceShadowRays) return false;  // PORT: shadows switched off (procedural/effects.h)
    // Starts as "hit": closest-hit and any-hit shaders are skipped, only Miss_Shadow clears it.
    shadowPayload = ShadowRayPayload{0.0f, 1};
    const TraceRayArguments& shadow = traceRay[Shadow];
    setTraceRayCall(call, ctx.globalRootDescriptor(kAccelerationStructure), kTraceRayFlags[Shadow],
                    shadow.instanceInclusionMask, /*RayContributionToHitGroupIndex*/ shadow.rayContribution,
                    /*MultiplierForGeometryContribution*/ shadow.multiplier,
                    /*MissShaderIndex*/ shadow.missShaderIndex, /*RayDesc*/ vec3(origin), 0.0f, vec3(direction),
                    10000.0f, shadowPayload);
    return true;
}

// reflectanceCoef·(Fresnel, 1)·(reflection ray colour), for the reflection ray along reflect(D, normal) (D: the
// incoming ray's WorldRayDirection()).
template <typename T>
tvec4<T> ReflectedColor(const tvec3<T>& D, const tvec3<T>& normal, T reflectanceCoef, const tvec3<T>& f0,
                        const tvec4<T>& reflectionColor) {
    const tvec3<T> fresnelR = FresnelReflectanceSchlick(D, normal, f0);
    return reflectanceCoef * tvec4<T>(fresnelR, T(1)) * reflectionColor;
}

// What a closest hit's lane carries from one TraceRay to the next.
template <typename T>
struct ClosestHitLane {
    WaveShared<SceneConstantBuffer>* scene = nullptr;  // g_sceneCB, which the wave's lanes read once between them
    bool returned = false;  // the shader returned early (a debug colour)
    const SceneConstantBuffer* sceneCB = nullptr;  // PORT: the wave's one copy in `scene`, not a copy per lane
    PrimitiveConstantBuffer materialCB;
    tvec3<T> normal;
    tvec4<T> albedo;
    tvec4<T> color;  // what the shader computed before its reflection (the Mandelbulb's surface colour)
    ShadowRayPayload shadowPayload;
    bool shadowTraced = false;
    bool shadowRayHit = false;
    bool reflects = false;  // reflectanceCoef > 0.001
    T reflectanceCoef;
    tvec3<T> f0;  // the Fresnel term's
    tvec3<T> D;
    RayPayload reflectionPayload;
    bool reflected = false;

    // The material's reflection (read into materialCB): reflectanceCoef > 0.001 reflects, with Fresnel's `fresnelF0`.
    void reflectMaterial(const tvec3<T>& fresnelF0) {
        reflects = materialCB.reflectanceCoef > 0.001f;
        reflectanceCoef = T(materialCB.reflectanceCoef);
        f0 = fresnelF0;
    }
    // CalculatePhongLighting with the material's coefficients, at HitWorldPosition() seen along WorldRayDirection().
    tvec4<T> materialPhong(const ShaderContext& ctx) const {
        return CalculatePhongLighting(*sceneCB, albedo, normal, shadowRayHit, T(materialCB.diffuseCoef),
                                      T(materialCB.specularCoef), T(materialCB.specularPower), HitWorldPosition<T>(ctx),
                                      tvec3<T>(ctx.WorldRayDirection()));
    }
};

// The shape of the closest hits, over the lanes of a wave (emulator/closest_hit_wave.h), lane by lane the HLSL's:
// `open(ctx, lane, payload, attr)` runs a lane's code up to its shadow ray (false: the shader returns there), then,
// where `shadows` is set, its shadow ray towards the light (TraceShadowRayTowardsLight); its reflection ray when
// lane.reflects (ReflectedColor); `close(ctx, lane, payload, attr, reflectedColor)` the rest. The lanes' shadow rays
// go out together, then their reflection rays (TracingWave::TraceRaysInSteps).
template <typename T, class Attributes, class Open, class Close>
void LitClosestHit(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, uint32_t maxDepth, const Effects& effects,
                   bool shadows, Open open, Close close) {
    [[maybe_unused]] PrecisionScope<T> scope;
    WaveShared<SceneConstantBuffer> scene;  // PORT: g_sceneCB, read once between the lanes
    wave.TraceRaysInSteps<ClosestHitLane<T>>(
        [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l, TraceRayCall& call) {
            RayPayload& rayPayload = wave.payload<RayPayload>(i);
            l.scene = &scene;
            l.returned = !open(ctx, l, rayPayload, wave.attributes<Attributes>(i));
            if (l.returned || !shadows) return false;
            return l.shadowTraced = ShadowRayTowardsLightCall<T>(ctx, traceRay, maxDepth, effects, *l.sceneCB,
                                                                 rayPayload.recursionDepth, l.shadowPayload, call);
        },
        [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l, TraceRayCall& call) {
            if (l.shadowTraced) l.shadowRayHit = l.shadowPayload.hit != 0;  // TraceShadowRayAndReportIfHit's result
            if (l.returned || !l.reflects) return false;
            l.D = tvec3<T>(ctx.WorldRayDirection());
            return l.reflected = RadianceRayCall(ctx, traceRay, maxDepth, HitWorldPosition<T>(ctx),
                                                 hlsl::reflect(l.D, l.normal), wave.payload<RayPayload>(i).recursionDepth,
                                                 l.reflectionPayload, call);
        },
        [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l, TraceRayCall&) {
            if (l.returned) return false;
            tvec4<T> reflectedColor(T(0));
            if (l.reflects) {
                // TraceRadianceRay's colour: black where RadianceRayCall made no ray (MAX_RAY_RECURSION_DEPTH).
                const tvec4<T> reflectionColor = l.reflected ? tvec4<T>(l.reflectionPayload.color) : tvec4<T>(T(0));
                reflectedColor = ReflectedColor(l.D, l.normal, l.reflectanceCoef, l.f0, reflectionColor);
            }
            close(ctx, l, wave.payload<RayPayload>(i), wave.attributes<Attributes>(i), reflectedColor);
            return false;
        });
}

// ProceduralPrimitivesLibrary.hlsli GetDistanceFromSignedDistancePrimitive: only the Pac-man case is live.
// PORT: takes the mouth interpolant instead of the time (computed once per IS, see fractals.h).
template <typename T>
T GetDistanceFromSignedDistancePrimitive(const tvec3<T>& position, SignedDistancePrimitive signedDistancePrimitive,
                                         T mouth) {
    switch (signedDistancePrimitive) {
        case SignedDistancePrimitive::IntersectedRoundCube: return math::pacman::pacMan(position, mouth);
        default: return T(0);
    }
}

constexpr ProceduralPrimitiveAttributes kInitialAttributes{vec3(0.0f), vec4(0.0f, 0.0f, 0.0f, 1.0f)};

// ---- Entry points ----------------------------------------------------------------------------------
// Each is a template on the scalar type; results are rounded to float where they cross the interface. Those that
// trace rays take the library's TraceRay arguments, and those that march or recurse its Accuracy (PORT: constants
// in the HLSL); those that trace shadow rays take its Effects.

// PORT: written for waves: the samples' shared CameraRaygen (procedural/sample_layout.h).
template <typename T>
void Raygen(RayGenerationWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy) {
    [[maybe_unused]] PrecisionScope<T> scope;
    const uint32_t maxDepth = maxRayRecursionDepth(accuracy);
    CameraRaygen<T, RayPayload>(
        wave, kOutputView,
        [](ShaderContext& ctx) {
            const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
            return CameraSetup<T>{tvec3<T>(g_sceneCB.cameraPosition), g_sceneCB.projectionToWorld};
        },
        [&](ShaderContext& ctx, const tvec3<T>& origin, const tvec3<T>& direction, uint32_t depth, RayPayload& payload,
            TraceRayCall& call) {
            return RadianceRayCall(ctx, traceRay, maxDepth, origin, direction, depth, payload, call);
        });
}

void Miss(ShaderContext&, RayPayload& rayPayload) {
    rayPayload.color = kBackgroundColor;
    rayPayload.hit = 0;
}

void Miss_Shadow(ShaderContext&, ShadowRayPayload& rayPayload) {
    const float gStep = 4.0f;
    rayPayload.dist += gStep;
    rayPayload.hit = 0;
}

// PORT: written for waves (LitClosestHit).
template <typename T>
void ClosestHit_Triangle(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                         const Effects& effects) {
    const uint32_t maxDepth = maxRayRecursionDepth(accuracy);
    LitClosestHit<T, BuiltInTriangleIntersectionAttributes>(
        wave, traceRay, maxDepth, effects, /*shadows*/ true,
        [](ShaderContext& ctx, ClosestHitLane<T>& l, RayPayload& rayPayload, const BuiltInTriangleIntersectionAttributes&) {
            l.sceneCB = &l.scene->get(ctx, sceneCB);
            if (l.sceneCB->debugFlag) {
                rayPayload.color = vec4(0.0f, 0.0f, 1.0f, 0.0f);
                return false;
            }
            l.materialCB = materialCB(ctx);
            // The negated stored normal of the triangle's first vertex (g_indices is t1, g_vertices t2 of the table
            // at global parameter 4).
            const vec3 storedNormal = FirstVertexNormal(ctx, kVertexBuffers);
            l.normal = -tvec3<T>(storedNormal);
            l.albedo = tvec4<T>(l.materialCB.albedo);
            l.reflectMaterial(tvec3<T>(l.albedo));
            return true;
        },
        [](ShaderContext& ctx, const ClosestHitLane<T>& l, RayPayload& rayPayload,
           const BuiltInTriangleIntersectionAttributes&, const tvec4<T>& reflectedColor) {
            const tvec4<T> phongColor = l.materialPhong(ctx);
            tvec4<T> color = phongColor + reflectedColor;
            color += tvec4<T>(rayPayload.color);
            rayPayload.dist += ctx.RayTCurrent();
            rayPayload.color = vec4(color);
        });
}

// ---- The intersection shaders, run over the lanes of a record group (emulator/intersection_wave.h) ----------------
// PORT: each lane reads its own ray, record and constants and reports its own hit with the one-ray code in T; the
// march between runs over the lanes at once (WaveLanes<T>; T itself for a group of one lane, withLaneType). Lanes of a record group share its record (primitive
// type, instance index, step scale).

// What the lanes of a record group read alike: the scene's constants (a global root argument), the record's
// (l_aabbCB, l_materialCB.stepScale) and the instance element l_aabbCB names.
struct GroupInput {
    SceneConstantBuffer sceneCB{};
    PrimitiveInstanceConstantBuffer aabbCB{};
    float stepScale = 0.0f;
    InstanceBuffer instance{};
};

GroupInput readGroup(const ShaderContext& ctx) {
    GroupInput in;  // in the order a lane alone reads them
    in.aabbCB = aabbCB(ctx);
    in.instance = AABBPrimitiveInstance(ctx, in.aabbCB);
    in.sceneCB = sceneCB(ctx);
    in.stepScale = materialCB(ctx).stepScale;
    return in;
}

// What one lane of an intersection shader reads of its own before its march.
template <typename T>
struct LaneInput {
    math::Ray<T> localRay;
    math::RayExtent<T> extent;
};

// The opening every Proceduray intersection shader shares: the group's input, then each lane's; `if
// (g_sceneCB.debugFlag) { ReportHit(0, 1, attr); return; }` per lane; the lanes that go on march (and only they call
// libm: LiveLanes).
// PORT: the lanes of a record group share their record and the scene's constants, so what they read alike is read
// once, by the first lane whose read succeeds (a lane whose read fails leaves the wave with its error, as it would
// alone; all of them do for a broken binding), and each lane reads only its ray and extent.
template <typename T>
struct ProceduralWave {
    explicit ProceduralWave(IntersectionWave& wave)
        : shared(readByTheGroup(wave, readGroup)),
          in(gatherLanes(wave,
                         [this](ShaderContext& ctx) {
                             return LaneInput<T>{GetRayInAABBPrimitiveLocalSpace<T>(ctx, shared.instance),
                                                 CurrentExtent<T>(ctx)};
                         })),
          marching(openLanes(wave, shared)),
          live(marching.bits(), 0) {}
    GroupInput shared;
    std::array<LaneInput<T>, kMaxWaveWidth> in;
    LaneMask marching;
    math::LiveLanes live;
    static LaneMask openLanes(IntersectionWave& wave, const GroupInput& shared) {
        LaneMask marching;
        for (int i = 0; i < kMaxWaveWidth; ++i) {
            if (!wave.isActive(i)) continue;
            if (shared.sceneCB.debugFlag) wave.ReportHit(i, 0.0f, 1, kInitialAttributes);
            else marching.set(i);
        }
        return marching;
    }
    // What the group's lanes share (its record and constants).
    const GroupInput& group() const { return shared; }
    template <typename L>
    math::Ray<L> localRay() const {
        return toLanes<math::Ray<L>>(in, [](const LaneInput<T>& l) { return l.localRay; });
    }
    // The marching lanes' local rays through a march queue, `queue(ro, rd, count, out)` (out[k]: ray k's result),
    // and each lane's result at its lane.
    template <typename Hit, typename Queue>
    std::array<Hit, kMaxWaveWidth> queued(Queue&& queue) const {
        return throughQueue<Hit>(
            marching, in, [](const LaneInput<T>& l) { return l.localRay; },
            [&](const math::Ray<T>* rays, int count, Hit* out) {
                std::array<tvec3<T>, kMaxWaveWidth> ro{}, rd{};
                for (int k = 0; k < count; ++k) {
                    ro[size_t(k)] = rays[k].origin;
                    rd[size_t(k)] = rays[k].direction;
                }
                queue(ro.data(), rd.data(), count, out);
            });
    }
};

template <typename T>
ProceduralWave<T> openProceduralWave(IntersectionWave& wave) {
    return ProceduralWave<T>(wave);
}

template <typename T, typename L>
void Intersection_Pacman(IntersectionWave& wave, const Accuracy& accuracy) {
    [[maybe_unused]] PrecisionScope<L> scope;
    const ProceduralWave<T> lanes = openProceduralWave<T>(wave);
    const auto& in = lanes.in;
    const LaneMask marching = lanes.marching;
    if (marching.empty()) return;
    const GroupInput& group = lanes.group();
    const auto primitiveType = SignedDistancePrimitive(group.aabbCB.primitiveType);

    const L mouth = L(math::pacman::PacmanMouthInterpolant(T(group.sceneCB.elapsedTime)));
    // PORT: the march's threshold, step limit and normal offset come from the library's Accuracy.
    const math::SphereTraceParams<T> params = sphereTraceParams(accuracy, T(group.stepScale));
    const auto sdf = [primitiveType, mouth](const tvec3<L>& p) {
        return GetDistanceFromSignedDistancePrimitive(p, primitiveType, mouth);
    };
    // PORT: the marching lanes' sphere tracing runs through one queue over L's lanes (a whole wave's lanes a call).
    std::array<math::SphereTraceResult<T>, kMaxWaveWidth> primitiveTest{};
    if constexpr (math::kIsLanes<L>) {
        primitiveTest = throughQueue<math::SphereTraceResult<T>>(
            marching, in,
            [&params](const LaneInput<T>& l) { return math::SphereTraceRay<T>{l.localRay, l.extent, params.stepScale}; },
            [&](const math::SphereTraceRay<T>* rays, int count, math::SphereTraceResult<T>* out) {
                math::RaySignedDistancePrimitiveTestQueue<L>(rays, count, sdf, params, out);
            });
    } else {
        const LaneInput<T>& ray = in[size_t(marching.lowest())];  // a group of one lane
        primitiveTest[size_t(marching.lowest())] = math::RaySignedDistancePrimitiveTest(ray.localRay, ray.extent, sdf, params);
    }

    // H1: thit is in normalised local units, compared with and reported as if it were world t.
    wave.forEachLane([&](int i, ShaderContext& ctx) {
        if (!marching.test(i)) return;
        const math::SphereTraceResult<T>& test = primitiveTest[size_t(i)];
        const T thit = test.thit;
        if (!(test.hit && thit < T(in[size_t(i)].extent.tCurrent))) return;
        const tvec3<T> normal = test.normal;
        ProceduralPrimitiveAttributes attr = kInitialAttributes;
        attr.color = vec4(math::pacman::PacmanHitColor(normal, test.position));
        attr.normal = vec3(NormalToWorld(ctx, normal));
        wave.ReportHit(i, float(thit), /*hitKind*/ 0, attr);
    });
}

// PORT: written for waves (LitClosestHit).
template <typename T>
void ClosestHit_Pacman(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                       const Effects& effects) {
    const uint32_t maxDepth = maxRayRecursionDepth(accuracy);
    LitClosestHit<T, ProceduralPrimitiveAttributes>(
        wave, traceRay, maxDepth, effects, /*shadows*/ true,
        [](ShaderContext& ctx, ClosestHitLane<T>& l, RayPayload& rayPayload, const ProceduralPrimitiveAttributes& attr) {
            if (ctx.HitKind() == 1) {
                rayPayload.color = vec4(0.0f, 0.0f, 1.0f, 0.0f);
                return false;
            }
            l.sceneCB = &l.scene->get(ctx, sceneCB);
            l.materialCB = materialCB(ctx);
            l.normal = tvec3<T>(attr.normal);
            l.albedo = tvec4<T>(l.materialCB.albedo);
            l.reflectMaterial(tvec3<T>(l.albedo));
            return true;
        },
        [](ShaderContext& ctx, const ClosestHitLane<T>& l, RayPayload& rayPayload,
           const ProceduralPrimitiveAttributes& attr, const tvec4<T>& reflectedColor) {
            const tvec4<T> phongColor = l.materialPhong(ctx);
            tvec4<T> color = tvec4<T>(attr.color) * (phongColor + reflectedColor);
            color += tvec4<T>(rayPayload.color);
            rayPayload.dist += ctx.RayTCurrent();
            rayPayload.color = vec4(color);
        });
}

template <typename T, typename L>
void Intersection_Mandelbulb(IntersectionWave& wave, const Accuracy& accuracy) {
    [[maybe_unused]] PrecisionScope<L> scope;
    const ProceduralWave<T> lanes = openProceduralWave<T>(wave);
    const auto& in = lanes.in;
    const LaneMask marching = lanes.marching;
    if (marching.empty()) return;
    const GroupInput& group = lanes.group();

    // The step count animates with time and the procedural instance ordinal (not InstanceIndex()).
    // l_materialCB.stepScale is passed by the HLSL but never used, so it is not read here.
    // PORT: the step count is scaled, and the threshold, iterations and normal offset come, from the library's
    // Accuracy.
    const int iMax = mandelbulbStepCount(
        math::mandelbulb::MandelbulbIterationCount(T(group.sceneCB.elapsedTime), int(group.aabbCB.instanceIndex)),
        accuracy);
    // PORT: over lanes, the marching lanes' rays go through MandelbulbDistanceQueue (up to a whole wave of them: the
    // shader takes kMaxWaveWidth lanes a call), whose lanes take the next ray as soon as theirs ends.
    const math::mandelbulb::MandelbulbParams<T> params = mandelbulbParams<T>(accuracy);
    std::array<math::mandelbulb::MandelbulbHit<T>, kMaxWaveWidth> primitiveTest{};
    if constexpr (math::kIsLanes<L>) {
        primitiveTest = lanes.template queued<math::mandelbulb::MandelbulbHit<T>>(
            [&](const tvec3<T>* ro, const tvec3<T>* rd, int count, math::mandelbulb::MandelbulbHit<T>* out) {
                math::mandelbulb::MandelbulbDistanceQueue<L>(ro, rd, count, iMax, out, params);
            });
    } else {
        const LaneInput<T>& ray = in[size_t(marching.lowest())];  // a group of one lane
        primitiveTest[size_t(marching.lowest())] =
            math::mandelbulb::MandelbulbDistance(ray.localRay.origin, ray.localRay.direction, iMax, params);
    }

    wave.forEachLane([&](int i, ShaderContext& ctx) {
        if (!marching.test(i)) return;
        const math::mandelbulb::MandelbulbHit<T>& test = primitiveTest[size_t(i)];
        const T thit = test.thit;
        if (!(test.hit && thit < T(in[size_t(i)].extent.tCurrent))) return;
        ProceduralPrimitiveAttributes attr = kInitialAttributes;
        attr.color = vec4(test.color);
        attr.normal = vec3(NormalToWorld(ctx, test.normal));
        wave.ReportHit(i, float(thit), /*hitKind*/ 0, attr);
    });
}

// PORT: written for waves (LitClosestHit; no shadow ray).
template <typename T>
void ClosestHit_Mandelbulb(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                           const Effects& effects) {
    LitClosestHit<T, ProceduralPrimitiveAttributes>(
        wave, traceRay, maxRayRecursionDepth(accuracy), effects, /*shadows*/ false,
        [](ShaderContext& ctx, ClosestHitLane<T>& l, RayPayload& rayPayload, const ProceduralPrimitiveAttributes& attr) {
            if (ctx.HitKind() == 1) {
                rayPayload.color = vec4(0.0f, 1.0f, 0.0f, 0.0f);
                return false;
            }
            l.materialCB = materialCB(ctx);
            l.normal = tvec3<T>(attr.normal);
            l.color = MandelbulbSurfaceColor(tvec3<T>(ctx.WorldRayDirection()), l.normal, tvec4<T>(attr.color));
            l.reflectMaterial(tvec3<T>(vec3(l.materialCB.albedo)));
            return true;
        },
        [](ShaderContext& ctx, const ClosestHitLane<T>& l, RayPayload& rayPayload, const ProceduralPrimitiveAttributes&,
           const tvec4<T>& reflectedColor) {
            tvec4<T> color = l.color + reflectedColor;
            color += tvec4<T>(rayPayload.color);
            rayPayload.dist += ctx.RayTCurrent();
            rayPayload.color = vec4(color);
        });
}

template <typename T, typename L>
void Intersection_Julia(IntersectionWave& wave, const Accuracy& accuracy) {
    [[maybe_unused]] PrecisionScope<L> scope;
    const ProceduralWave<T> lanes = openProceduralWave<T>(wave);
    const auto& in = lanes.in;
    const LaneMask marching = lanes.marching;
    if (marching.empty()) return;

    // PORT: JuliaDistance takes no time; the HLSL's cut animation is computed and then ignored (§5.5).
    // PORT: the iterations, march steps, stop precision and normal offset come from the library's Accuracy.
    // PORT: over lanes, the marching lanes' rays go through JuliaDistanceQueue (up to a whole wave of them: the
    // shader takes kMaxWaveWidth lanes a call), whose lanes take the next ray as soon as theirs ends.
    std::array<math::julia::JuliaHit<T>, kMaxWaveWidth> primitiveTest{};
    if constexpr (math::kIsLanes<L>) {
        primitiveTest = lanes.template queued<math::julia::JuliaHit<T>>(
            [&](const tvec3<T>* ro, const tvec3<T>* rd, int count, math::julia::JuliaHit<T>* out) {
                math::julia::JuliaDistanceQueue<L>(ro, rd, count, out, juliaParams<T>(accuracy));
            });
    } else {
        const LaneInput<T>& ray = in[size_t(marching.lowest())];  // a group of one lane
        primitiveTest[size_t(marching.lowest())] =
            math::julia::JuliaDistance(ray.localRay.origin, ray.localRay.direction, juliaParams<T>(accuracy));
    }

    // H1: thit.x is in q-space units (0.4 x normalised local units).
    wave.forEachLane([&](int i, ShaderContext& ctx) {
        if (!marching.test(i)) return;
        const math::julia::JuliaHit<T>& test = primitiveTest[size_t(i)];
        const tvec2<T> thit = test.resT;
        if (!(test.hit && thit.x < T(in[size_t(i)].extent.tCurrent))) return;
        ProceduralPrimitiveAttributes attr = kInitialAttributes;
        attr.normal = vec3(NormalToWorld(ctx, test.normal));
        attr.color = vec4(vec2(thit), 0.0f, 0.0f);  // (t, iteration count) for ClosestHit_Julia
        wave.ReportHit(i, float(thit.x), /*hitKind*/ 0, attr);
    });
}

// PORT: written for waves (LitClosestHit; no shadow ray: the HLSL has it commented out).
template <typename T>
void ClosestHit_Julia(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                      const Effects& effects) {
    // PORT: MAX_RAY_RECURSION_DEPTH is the library's (maxRayRecursionDepth); with 0 the subtraction wraps, as the
    // HLSL's unsigned comparison does.
    const uint32_t maxDepth = maxRayRecursionDepth(accuracy);
    LitClosestHit<T, ProceduralPrimitiveAttributes>(
        wave, traceRay, maxDepth, effects, /*shadows*/ false,
        [maxDepth](ShaderContext& ctx, ClosestHitLane<T>& l, RayPayload& rayPayload,
                   const ProceduralPrimitiveAttributes& attr) {
            l.sceneCB = &l.scene->get(ctx, sceneCB);
            if (l.sceneCB->debugFlag) {
                rayPayload.color = vec4(1.0f, 0.0f, 0.0f, 0.0f);
                return false;
            }
            l.normal = tvec3<T>(attr.normal);
            // H1: with the local-unit t this point lies near the object-space ray origin, not on the surface.
            const tvec3<T> pos =
                tvec3<T>(ctx.ObjectRayOrigin()) + T(ctx.RayTCurrent()) * tvec3<T>(ctx.ObjectRayDirection());
            l.albedo = tvec4<T>(T(3.5f) * colorSurface(pos, tvec2<T>(attr.color)), T(1));
            if (rayPayload.recursionDepth == maxDepth - 1) l.albedo += T(1.65f) * hlsl::step(T(0), hlsl::abs(pos.y));
            const T reflecCoef = T(0.1f);
            l.reflects = reflecCoef > T(0.001f);
            l.reflectanceCoef = reflecCoef;
            l.f0 = tvec3<T>(l.albedo);
            return true;
        },
        [](ShaderContext& ctx, const ClosestHitLane<T>& l, RayPayload& rayPayload, const ProceduralPrimitiveAttributes&,
           const tvec4<T>& reflectedColor) {
            const T diffuseCoef = T(0.6f);
            const T specularCoef = T(0.08f);
            const T specularPower = T(0.2f);
            const bool shadowRayHit = false;
            const tvec4<T> phongColor =
                CalculatePhongLighting(*l.sceneCB, l.albedo, l.normal, shadowRayHit, diffuseCoef, specularCoef,
                                       specularPower, HitWorldPosition<T>(ctx), tvec3<T>(ctx.WorldRayDirection()));
            tvec4<T> color = phongColor + reflectedColor;
            color += tvec4<T>(rayPayload.color);
            rayPayload.color = vec4(color);
        });
}

// Every export, with its math in T. The lambdas hold copies of the TraceRay arguments and the Accuracy, which the
// shaders take by reference; a PerturbedFloat library's also hold its perturbation (withArithmetic).
template <typename T>
void addExports(ShaderLibrary& lib, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                const Effects& effects, const std::optional<Perturbation>& perturbation) {
    const auto in = [&perturbation](auto entry) { return withArithmetic<T>(perturbation, entry); };
    lib.addWaveRayGeneration(
        "Raygen", in([traceRay, accuracy](RayGenerationWave& wave) { Raygen<T>(wave, traceRay, accuracy); }));
    lib.addMiss<RayPayload>("Miss", Miss);
    lib.addMiss<ShadowRayPayload>("Miss_Shadow", Miss_Shadow);
    // The closest hits are written for waves.
    lib.addWaveClosestHit<RayPayload, BuiltInTriangleIntersectionAttributes>(
        "ClosestHit_Triangle", in([traceRay, accuracy, effects](ClosestHitWave& wave) {
            ClosestHit_Triangle<T>(wave, traceRay, accuracy, effects);
        }));
    // Each intersection shader below ends with its ReportHit (the debug-flag path returns right after it), as in
    // the HLSL: ReportHitEnd::Return (docs/emulator.md, "Ending an intersection shader").
    // Julia: a whole wave's lanes a call, for JuliaDistanceQueue's refilled lanes.
    lib.addWaveIntersection<ProceduralPrimitiveAttributes>("Intersection_Julia", kMaxWaveWidth, in([accuracy](IntersectionWave& wave) {
            withLaneType<T>(wave, [&]<class L>() { Intersection_Julia<T, L>(wave, accuracy); });
        }),
        ReportHitEnd::Return);
    lib.addWaveClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
        "ClosestHit_Julia", in([traceRay, accuracy, effects](ClosestHitWave& wave) {
            ClosestHit_Julia<T>(wave, traceRay, accuracy, effects);
        }));
    // Pac-man: a whole wave's lanes a call, for RaySignedDistancePrimitiveTestQueue's refilled lanes.
    lib.addWaveIntersection<ProceduralPrimitiveAttributes>("Intersection_Pacman", kMaxWaveWidth, in([accuracy](IntersectionWave& wave) {
            withLaneType<T>(wave, [&]<class L>() { Intersection_Pacman<T, L>(wave, accuracy); });
        }),
        ReportHitEnd::Return);
    lib.addWaveClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
        "ClosestHit_Pacman", in([traceRay, accuracy, effects](ClosestHitWave& wave) {
            ClosestHit_Pacman<T>(wave, traceRay, accuracy, effects);
        }));
    // Mandelbulb: a whole wave's lanes a call, for MandelbulbDistanceQueue's refilled lanes.
    lib.addWaveIntersection<ProceduralPrimitiveAttributes>("Intersection_Mandelbulb", kMaxWaveWidth,
        in([accuracy](IntersectionWave& wave) {
            withLaneType<T>(wave, [&]<class L>() { Intersection_Mandelbulb<T, L>(wave, accuracy); });
        }), ReportHitEnd::Return);
    lib.addWaveClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
        "ClosestHit_Mandelbulb", in([traceRay, accuracy, effects](ClosestHitWave& wave) {
            ClosestHit_Mandelbulb<T>(wave, traceRay, accuracy, effects);
        }));
}

}  // namespace

std::shared_ptr<ShaderLibrary> makeProcedurayShaderLibrary(Precision precision, const TraceRayArgumentSet& traceRay,
                                                            const Accuracy& accuracy, const Effects& effects,
                                                            const std::optional<Perturbation>& perturbation) {
    auto lib = std::make_shared<ShaderLibrary>();
    forScalarType(precision, perturbation,
                  [&]<typename T>() { addExports<T>(*lib, traceRay, accuracy, effects, perturbation); });
    return lib;
}

}  // namespace refray::procedural::proceduray
