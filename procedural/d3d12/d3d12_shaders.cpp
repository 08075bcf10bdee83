// Ports: D3D12RaytracingProceduralGeometry Raytracing.hlsl, RaytracingShaderHelper.hlsli (camera ray, ray
// differentials, Fresnel, index loads), CheckersTextureBoxFilter and the intersection-test dispatch of
// ProceduralPrimitivesLibrary.hlsli; see d3d12_shaders.h.
#include "procedural/d3d12/d3d12_shaders.h"

#include <cstring>
#if defined(__AVX__)
#endif
#include <optional>
#include <span>
#include <type_traits>
#include <utility>

#include "emulator/closest_hit_wave.h"
#include "emulator/compute_wave.h"
#include "emulator/intersection_wave.h"
#include "emulator/ray_generation_wave.h"
#include "emulator/shader_api.h"
#include "procedural/math/analytic.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/perturbed.h"
#include "procedural/math/ray.h"
#include "procedural/math/sdf.h"
#include "procedural/wave_shader.h"

namespace refray::procedural::d3d12 {

using namespace refray::dxr;

// ---- Scene data (§1.2) -----------------------------------------------------------------------------

const std::array<uint16_t, 6> kPlaneIndices = {3, 1, 0, 2, 1, 3};

const std::array<Vertex, 4> kPlaneVertices = {{
    {{0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
    {{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
    {{1.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}},
    {{0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}},
}};

// ---- Root signatures and hit groups ----------------------------------------------------------------

RootSignatureDesc globalRootSignatureDesc() { return sampleGlobalRootSignatureDesc("GlobalRootSignature"); }

RootSignatureDesc triangleLocalRootSignatureDesc() {
    return sampleTriangleLocalRootSignatureDesc("Triangle");
}

RootSignatureDesc aabbLocalRootSignatureDesc() {
    return sampleProceduralLocalRootSignatureDesc("AABB");
}

std::vector<HitGroupDesc> d3d12HitGroups() {
    using enum HitGroupType;
    const char* chsAABB = "MyClosestHitShader_AABB";
    return {
        {"MyHitGroup_Triangle", Triangles, "", "MyClosestHitShader_Triangle", ""},
        {"MyHitGroup_Triangle_ShadowRay", Triangles, "", "", ""},
        {"MyHitGroup_AABB_AnalyticPrimitive", ProceduralPrimitive, "", chsAABB,
         "MyIntersectionShader_AnalyticPrimitive"},
        {"MyHitGroup_AABB_AnalyticPrimitive_ShadowRay", ProceduralPrimitive, "", "",
         "MyIntersectionShader_AnalyticPrimitive"},
        {"MyHitGroup_AABB_VolumetricPrimitive", ProceduralPrimitive, "", chsAABB,
         "MyIntersectionShader_VolumetricPrimitive"},
        {"MyHitGroup_AABB_VolumetricPrimitive_ShadowRay", ProceduralPrimitive, "", "",
         "MyIntersectionShader_VolumetricPrimitive"},
        {"MyHitGroup_AABB_SignedDistancePrimitive", ProceduralPrimitive, "", chsAABB,
         "MyIntersectionShader_SignedDistancePrimitive"},
        {"MyHitGroup_AABB_SignedDistancePrimitive_ShadowRay", ProceduralPrimitive, "", "",
         "MyIntersectionShader_SignedDistancePrimitive"},
    };
}

std::vector<std::string> triangleHitGroupNames() { return {"MyHitGroup_Triangle", "MyHitGroup_Triangle_ShadowRay"}; }

std::vector<std::string> aabbHitGroupNames() {
    std::vector<std::string> names;
    for (const HitGroupDesc& g : d3d12HitGroups())
        if (g.Type == HitGroupType::ProceduralPrimitive) names.push_back(g.HitGroupExport);
    return names;
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
T CheckersTextureBoxFilter(tvec2<T> uv, tvec2<T> dpdx, tvec2<T> dpdy, uint32_t ratio) {
    const T fRatio = T(ratio);
    const tvec2<T> w = hlsl::max(hlsl::abs(dpdx), hlsl::abs(dpdy));  // filter kernel
    const tvec2<T> a = uv + T(0.5f) * w;
    const tvec2<T> b = uv - T(0.5f) * w;

    // Analytical integral (box filter), per component.
    tvec2<T> i;
    for (glm::length_t k = 0; k < 2; ++k)
        i[k] = (hlsl::floor(a[k]) + hlsl::min(hlsl::frac(a[k]) * fRatio, T(1)) - hlsl::floor(b[k]) -
                hlsl::min(hlsl::frac(b[k]) * fRatio, T(1))) /
               (fRatio * w[k]);
    return (T(1) - i.x) * (T(1) - i.y);
}

namespace {

// CalculateRayDifferentials with the neighbouring pixels given in T: ddxPixel = DispatchRaysIndex().xy + uint2(1, 0)
// and ddyPixel = DispatchRaysIndex().xy + uint2(0, 1), added in uint and converted as GenerateCameraRay converts them.
// PORT: so that a wave's lanes, each with its own pixel, run it as one (FinalColor).
template <typename T>
void RayDifferentialsThrough(tvec2<T>& ddx_uv, tvec2<T>& ddy_uv, tvec2<T> uv, tvec3<T> hitPosition,
                             tvec3<T> surfaceNormal, tvec3<T> cameraPosition, const Float4x4& projectionToWorld,
                             tvec2<T> ddxPixel, tvec2<T> ddyPixel, tvec2<T> dispatchRaysDimensions) {
    // Intersect the neighbouring pixels' primary rays with the tangent plane of the surface.
    tvec3<T> ddxOrigin, ddxDirection, ddyOrigin, ddyDirection;
    GenerateCameraRayFromPixel(ddxPixel, dispatchRaysDimensions, cameraPosition, projectionToWorld, ddxOrigin,
                               ddxDirection);
    GenerateCameraRayFromPixel(ddyPixel, dispatchRaysDimensions, cameraPosition, projectionToWorld, ddyOrigin,
                               ddyDirection);

    const tvec3<T> ddx_pos = ddxOrigin - ddxDirection * hlsl::dot(ddxOrigin - hitPosition, surfaceNormal) /
                                             hlsl::dot(ddxDirection, surfaceNormal);
    const tvec3<T> ddy_pos = ddyOrigin - ddyDirection * hlsl::dot(ddyOrigin - hitPosition, surfaceNormal) /
                                             hlsl::dot(ddyDirection, surfaceNormal);

    // TexCoords(position) = position.xz.
    ddx_uv = tvec2<T>(ddx_pos.x, ddx_pos.z) - uv;
    ddy_uv = tvec2<T>(ddy_pos.x, ddy_pos.z) - uv;
}

// AnalyticalCheckersTexture with the neighbouring pixels given in T (RayDifferentialsThrough).
template <typename T>
T CheckersThrough(tvec3<T> hitPosition, tvec3<T> surfaceNormal, tvec3<T> cameraPosition,
                  const Float4x4& projectionToWorld, tvec2<T> ddxPixel, tvec2<T> ddyPixel,
                  tvec2<T> dispatchRaysDimensions) {
    tvec2<T> ddx_uv, ddy_uv;
    const tvec2<T> uv(hitPosition.x, hitPosition.z);
    RayDifferentialsThrough(ddx_uv, ddy_uv, uv, hitPosition, surfaceNormal, cameraPosition, projectionToWorld, ddxPixel,
                            ddyPixel, dispatchRaysDimensions);
    return CheckersTextureBoxFilter(uv, ddx_uv, ddy_uv, 50);
}

}  // namespace

template <typename T>
void CalculateRayDifferentials(tvec2<T>& ddx_uv, tvec2<T>& ddy_uv, tvec2<T> uv, tvec3<T> hitPosition,
                               tvec3<T> surfaceNormal, tvec3<T> cameraPosition, const Float4x4& projectionToWorld,
                               uvec2 dispatchRaysIndex, uvec2 dispatchRaysDimensions) {
    RayDifferentialsThrough(ddx_uv, ddy_uv, uv, hitPosition, surfaceNormal, cameraPosition, projectionToWorld,
                            tvec2<T>(dispatchRaysIndex + uvec2(1, 0)), tvec2<T>(dispatchRaysIndex + uvec2(0, 1)),
                            tvec2<T>(dispatchRaysDimensions));
}

template <typename T>
T AnalyticalCheckersTexture(tvec3<T> hitPosition, tvec3<T> surfaceNormal, tvec3<T> cameraPosition,
                            const Float4x4& projectionToWorld, uvec2 dispatchRaysIndex, uvec2 dispatchRaysDimensions) {
    return CheckersThrough(hitPosition, surfaceNormal, cameraPosition, projectionToWorld,
                           tvec2<T>(dispatchRaysIndex + uvec2(1, 0)), tvec2<T>(dispatchRaysIndex + uvec2(0, 1)),
                           tvec2<T>(dispatchRaysDimensions));
}

template <typename T>
tvec4<T> CalculatePhongLighting(const SceneConstantBuffer& sceneCB, tvec4<T> albedo, tvec3<T> normal,
                                math::LaneMask<T> isInShadow, T diffuseCoef, T specularCoef, T specularPower,
                                tvec3<T> hitPosition, tvec3<T> worldRayDirection) {
    const tvec3<T> lightPosition = tvec3<T>(vec3(sceneCB.lightPosition));
    const T shadowFactor = math::select(isInShadow, T(InShadowRadiance), T(1));
    const tvec3<T> incidentLightRay = hlsl::normalize(hitPosition - lightPosition);

    // Diffuse component.
    const tvec4<T> lightDiffuseColor = tvec4<T>(sceneCB.lightDiffuseColor);
    const T Kd = hlsl::saturate(hlsl::dot(-incidentLightRay, normal));
    const tvec4<T> diffuseColor = shadowFactor * diffuseCoef * Kd * lightDiffuseColor * albedo;

    // Specular component.
    // PORT: `if (!isInShadow)`; over lanes, the lanes in shadow keep 0 (and skip its pow).
    tvec4<T> specularColor(T(0));
    const auto specular = [&] {
        const tvec4<T> lightSpecularColor(T(1));
        const tvec3<T> reflectedLightRay = hlsl::normalize(hlsl::reflect(incidentLightRay, normal));
        const T Ks = hlsl::pow(hlsl::saturate(hlsl::dot(reflectedLightRay, hlsl::normalize(-worldRayDirection))),
                               specularPower);
        return specularCoef * Ks * lightSpecularColor;
    };
    if constexpr (math::kIsLanes<T>) {
        const math::LaneMask<T> lit = !isInShadow;
        if (math::anyLane(lit)) {
            const math::LiveLanes live(lit);
            specularColor = math::select(lit, specular(), specularColor);
        }
    } else if (!isInShadow) {
        specularColor = specular();
    }

    // Ambient component, with the fake AO that darkens faces turned towards -y.
    const tvec4<T> ambientColorMin = tvec4<T>(sceneCB.lightAmbientColor) - T(0.1f);
    const tvec4<T> ambientColorMax = tvec4<T>(sceneCB.lightAmbientColor);
    const T a = T(1) - hlsl::saturate(hlsl::dot(normal, tvec3<T>(T(0), T(-1), T(0))));
    const tvec4<T> ambientColor = albedo * hlsl::lerp(ambientColorMin, ambientColorMax, a);

    return ambientColor + diffuseColor + specularColor;
}

template <typename T>
tvec4<T> ApplyVisibilityFalloff(tvec4<T> color, T t) {
    return hlsl::lerp(color, tvec4<T>(BackgroundColor), T(1) - hlsl::exp(T(-0.000002f) * t * t * t));
}

#define REFRAY_INSTANTIATE_HELPERS(T)                                                                               \
    template T CheckersTextureBoxFilter<T>(tvec2<T>, tvec2<T>, tvec2<T>, uint32_t);                                 \
    template void CalculateRayDifferentials<T>(tvec2<T>&, tvec2<T>&, tvec2<T>, tvec3<T>, tvec3<T>, tvec3<T>,        \
                                               const Float4x4&, uvec2, uvec2);                                      \
    template T AnalyticalCheckersTexture<T>(tvec3<T>, tvec3<T>, tvec3<T>, const Float4x4&, uvec2, uvec2);           \
    template tvec4<T> CalculatePhongLighting<T>(const SceneConstantBuffer&, tvec4<T>, tvec3<T>, math::LaneMask<T>,  \
                                                T, T, T, tvec3<T>, tvec3<T>);                                       \
    template tvec4<T> ApplyVisibilityFalloff<T>(tvec4<T>, T);
REFRAY_INSTANTIATE_HELPERS(float)
REFRAY_INSTANTIATE_HELPERS(double)
#undef REFRAY_INSTANTIATE_HELPERS

// ---- Accuracy knobs --------------------------------------------------------------------------------

template <typename T>
math::MetaballsParams<T> metaballsParams(const Accuracy& accuracy) {
    math::MetaballsParams<T> params;  // the HLSL's constants
    if (accuracy.metaballSteps) params.maxSteps = *accuracy.metaballSteps;
    params.normalOffset = scaledConstant(params.normalOffset, accuracy.normalEpsilonFactor);
    return params;
}

uint32_t maxRayRecursionDepth(const Accuracy& accuracy) {
    return accuracy.maxRecursionDepth.value_or(MAX_RAY_RECURSION_DEPTH);
}

#define REFRAY_INSTANTIATE_KNOBS(T)                                                                     \
    template math::MetaballsParams<T> metaballsParams<T>(const Accuracy&);
REFRAY_INSTANTIATE_KNOBS(float)
REFRAY_INSTANTIATE_KNOBS(double)
#undef REFRAY_INSTANTIATE_KNOBS

// ---- Shader-side helpers (Raytracing.hlsl) ---------------------------------------------------------

namespace {

SceneConstantBuffer sceneCB(const ShaderContext& ctx) {
    return ctx.load<SceneConstantBuffer>(ctx.globalRootDescriptor(kSceneConstant));
}

PrimitiveConstantBuffer materialCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveConstantBuffer>(kMaterialConstant);
}

PrimitiveInstanceConstantBuffer aabbCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveInstanceConstantBuffer>(kGeometryIndex);
}

// g_AABBPrimitiveAttributes[l_aabbCB.instanceIndex].
PrimitiveInstancePerFrameBuffer primitiveAttributes(const ShaderContext& ctx) {
    const GpuVirtualAddress element = ctx.globalRootDescriptor(kAABBattributeBuffer) +
                                      uint64_t(aabbCB(ctx).instanceIndex) * sizeof(PrimitiveInstancePerFrameBuffer);
    return ctx.load<PrimitiveInstancePerFrameBuffer>(element);
}

template <typename T>
[[gnu::always_inline]] inline tvec3<T> HitWorldPosition(const ShaderContext& ctx) {  // inlined: see hlsl::normalize
    return tvec3<T>(ctx.WorldRayOrigin()) + T(ctx.RayTCurrent()) * tvec3<T>(ctx.WorldRayDirection());
}

// The object ray in the primitive's local space. The direction is not renormalised, so t means the same in world,
// object and local space (§2.2).
// PORT: the object-space ray is a parameter, so that a RayQuery's candidate ray goes the same way. Inlined: see
// hlsl::normalize.
template <typename T>
[[gnu::always_inline]] inline math::Ray<T> GetRayInAABBPrimitiveLocalSpace(
    vec3 objectRayOrigin, vec3 objectRayDirection, const PrimitiveInstancePerFrameBuffer& attr) {
    math::Ray<T> ray;
    ray.origin = tvec3<T>(mul(tvec4<T>(tvec3<T>(objectRayOrigin), T(1)), attr.bottomLevelASToLocalSpace));
    ray.direction = mul3x3(tvec3<T>(objectRayDirection), attr.bottomLevelASToLocalSpace);
    return ray;
}
template <typename T>
[[gnu::always_inline]] inline math::Ray<T> GetRayInAABBPrimitiveLocalSpace(
    const ShaderContext& ctx, const PrimitiveInstancePerFrameBuffer& attr) {
    return GetRayInAABBPrimitiveLocalSpace<T>(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(), attr);
}

// mul(n, (float3x3)localSpaceToBottomLevelAS), then normalize(mul((float3x3)ObjectToWorld3x4(), n)): the forward
// matrix, not the inverse transpose (I1).
// PORT: ObjectToWorld3x4() is a parameter (a RayQuery's candidate matrix, or the intersection shader's).
template <typename T>
[[gnu::always_inline]] inline tvec3<T> NormalToWorld(const Matrix3x4& o2w, const PrimitiveInstancePerFrameBuffer& attr,
                                                     const tvec3<T>& localNormal) {  // inlined: see hlsl::normalize
    const tvec3<T> n = mul3x3(localNormal, attr.localSpaceToBottomLevelAS);
    tvec3<T> r;
    for (int i = 0; i < 3; ++i) r[i] = T(o2w.m[i][0]) * n.x + T(o2w.m[i][1]) * n.y + T(o2w.m[i][2]) * n.z;
    return hlsl::normalize(r);
}

// The sample applies the triangle culling flags to its procedural hits itself (I3).
template <typename T>
math::RayExtent<T> CurrentExtent(float tMin, float tCurrent, uint32_t flags) {
    return {T(tMin), T(tCurrent), (flags & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) != 0,
            (flags & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) != 0};
}
template <typename T>
math::RayExtent<T> CurrentExtent(const ShaderContext& ctx) {
    return CurrentExtent<T>(ctx.RayTMin(), ctx.RayTCurrent(), ctx.RayFlags());
}

// The three intersection shaders' tests (RayAnalyticGeometryIntersectionTest, RayVolumetricGeometryIntersectionTest,
// RaySignedDistancePrimitiveTest) on the primitive's local ray inside `extent`: shared by the intersection shaders
// and the inline-tracing shaders, which intersect their procedural candidates themselves (scenes/inline/).
enum class IntersectionShader : uint32_t { AnalyticPrimitive = 0, VolumetricPrimitive = 1, SignedDistancePrimitive = 2 };

// PORT: hit is a LaneMask<T> (bool for a scalar T, one flag per ray for a wave's lanes).
template <typename T>
struct PrimitiveHit {
    math::LaneMask<T> hit = math::LaneMask<T>(false);
    T thit = T(0);
    tvec3<T> normal{T(0)};  // local space
};

template <typename T>
PrimitiveHit<T> IntersectPrimitive(IntersectionShader shader, uint32_t primitiveType, const math::Ray<T>& localRay,
                                   const math::RayExtent<T>& extent, T elapsedTime, T stepScale,
                                   const Accuracy& accuracy) {
    switch (shader) {
        case IntersectionShader::AnalyticPrimitive: {
            // RayAnalyticGeometryIntersectionTest: the local box is <-1,1>^3.
            math::AnalyticHit<T> test;
            switch (AnalyticPrimitive::Enum(primitiveType)) {
                case AnalyticPrimitive::AABB: test = math::RayUnitCubeIntersectionTest(localRay, extent); break;
                case AnalyticPrimitive::Spheres: test = math::RaySpheresIntersectionTest(localRay, extent); break;
                default: break;
            }
            return {test.hit, test.thit, test.normal};
        }
        case IntersectionShader::VolumetricPrimitive: {
            // RayVolumetricGeometryIntersectionTest: metaballs animated over a 12 s cycle. The march step depends on
            // the extent's tCurrent at call time (H10).
            // PORT: the sample count and the normal's step come from the library's Accuracy.
            math::MetaballsHit<T> test;
            if (VolumetricPrimitive::Enum(primitiveType) == VolumetricPrimitive::Metaballs)
                test = math::RayMetaballsIntersectionTest(localRay, extent, elapsedTime, T(12),
                                                          metaballsParams<T>(accuracy));
            return {test.hit, test.thit, test.normal};
        }
        case IntersectionShader::SignedDistancePrimitive: {
            // RaySignedDistancePrimitiveTest: sphere tracing from the extent's tMin, not from the box entry (I6).
            // PORT: the threshold, step limit and normal offset come from the library's Accuracy.
            const math::SphereTraceParams<T> params = sphereTraceParams(accuracy, stepScale);
            const auto sdf = [primitiveType](const tvec3<T>& position) {
                return math::d3d12::GetDistanceFromSignedDistancePrimitive(position,
                                                                           SignedDistancePrimitive(primitiveType));
            };
            const math::SphereTraceResult<T> test = math::RaySignedDistancePrimitiveTest(localRay, extent, sdf, params);
            return {test.hit, test.thit, test.normal};
        }
    }
    return {};
}

// The float lanes of the latency-bound marches below (the sphere-tracing queue, and inline tracing's procedural
// calls of more than kWaveLanes lanes, which take up to this many a call).
inline constexpr int kWideLanes = 16;
using WideLanes = math::Lanes<float, kWideLanes>;

// The SignedDistancePrimitive test (RaySignedDistancePrimitiveTest) for up to kMaxWaveWidth rays of one primitive
// type over 16 float lanes (two sets of them, stepped one after the other, while more than 16 rays march), refilled
// as rays stop, the last 8 or fewer rays over 8 (math::RaySignedDistancePrimitiveTestQueue): out[k] is bit for bit
// IntersectPrimitive<float>'s hit for ray k. What a
// record group of the intersection shader, and a wave call of inline ray tracing, run for their lanes.
// PORT: 16 lanes, not WaveLanes' 8: the sphere tracing is one chain of dependent instructions a step (the fractal
// pyramid's iterations above all), and a 16-float step is two independent 8-float chains that the core overlaps;
// a queue of 26 rays a call on average (the D3D12 view) keeps 16 lanes busy until its last 8 rays.
void SignedDistanceQueue(uint32_t primitiveType, const Accuracy& accuracy, const math::SphereTraceRay<float>* rays,
                         int count, PrimitiveHit<float>* out) {
    using L = WideLanes;
    using Tail = WaveLanes<float>;
    [[maybe_unused]] PrecisionScope<L> scope;
    // The fractal pyramid's Scale^-n, once for the queue rather than at every sample (in the queue's floating-point
    // mode, as every sample's pow).
    const auto type = SignedDistancePrimitive(primitiveType);
    const bool pyramid = type == SignedDistancePrimitive::FractalPyramid;
    const L wideFactor = pyramid ? math::d3d12::fractalPyramidPrimitiveScaleFactor<L>() : L(0.0f);
    const Tail tailFactor = pyramid ? math::d3d12::fractalPyramidPrimitiveScaleFactor<Tail>() : Tail(0.0f);
    // Over 16 lanes, and over 8 for the queue's tail.
    const auto sdf = [type, pyramid, &wideFactor, &tailFactor](const auto& position) {
        using P = std::remove_cvref_t<decltype(position.x)>;
        const P* factor = nullptr;
        if constexpr (std::is_same_v<P, L>) factor = pyramid ? &wideFactor : nullptr;
        else if constexpr (std::is_same_v<P, Tail>) factor = pyramid ? &tailFactor : nullptr;
        return math::d3d12::GetDistanceFromSignedDistancePrimitive(position, type, factor);
    };
    std::array<math::SphereTraceResult<float>, kMaxWaveWidth> results;
    math::RaySignedDistancePrimitiveTestQueue<L>(rays, count, sdf, sphereTraceParams(accuracy, 1.0f), results.data());
    for (int k = 0; k < count; ++k) out[k] = {results[size_t(k)].hit, results[size_t(k)].thit, results[size_t(k)].normal};
}

// Inline ray tracing's IntersectPrimitive, run once over the lanes of a wave that intersect a procedural candidate
// of the same kind (dxr::ShaderContext::callInWave, emulator/wave_call.h), as the TraceRay version's intersection
// shaders run over a record group: the shader, primitive type and Accuracy are the call's key; each lane's ray,
// extent, time and step scale are its own. A call of one lane runs in float, of up to 8 in WaveLanes<float>, of up to
// 16 in 16 float lanes (the lanes no ray fills hold the first lane's values): each lane's hit is bit for bit the
// one-lane result. double and PerturbedFloat run alone, for withLaneType's reasons.
// PORT: up to 16 lanes a call for the metaballs' march (the ambient-occlusion view's costliest test after the
// pyramid): its 128 samples are one latency-bound chain a ray, all rays take them all, and 16 float lanes, two
// independent 8-float halves, cost about 1.2 times 8 for twice the rays.
struct PrimitiveCall {
    IntersectionShader shader = IntersectionShader::AnalyticPrimitive;
    uint32_t primitiveType = 0;
    const Accuracy* accuracy = nullptr;
    math::Ray<float> localRay;
    math::RayExtent<float> extent;
    float elapsedTime = 0.0f, stepScale = 1.0f;
    PrimitiveHit<float> result;
};

// The calls of `lanes` over the lanes of L.
template <class L>
void runPrimitiveCallsIn(std::span<void* const> lanes) {
    const auto call = [&lanes](size_t i) -> PrimitiveCall& { return *static_cast<PrimitiveCall*>(lanes[i]); };
    const PrimitiveCall& first = call(0);
    [[maybe_unused]] PrecisionScope<L> scope;
    const math::LiveLanes live(uint32_t(dxr::LaneMask::first(int(lanes.size())).bits()), 0);
    math::Ray<L> localRay;
    math::RayExtent<L> extent;
    L elapsedTime, stepScale;
    for (int i = 0; i < L::kCount; ++i) {
        const PrimitiveCall& c = size_t(i) < lanes.size() ? call(size_t(i)) : first;
        math::setLane(localRay, i, c.localRay);
        math::setLane(extent, i, c.extent);
        math::setLane(elapsedTime, i, c.elapsedTime);
        math::setLane(stepScale, i, c.stepScale);
    }
    const PrimitiveHit<L> hit = IntersectPrimitive<L>(first.shader, first.primitiveType, localRay, extent, elapsedTime,
                                                      stepScale, *first.accuracy);
    for (size_t i = 0; i < lanes.size(); ++i) {
        PrimitiveHit<float>& r = call(i).result;
        r.hit = math::lane(hit.hit, int(i));
        r.thit = math::lane(hit.thit, int(i));
        r.normal = math::lane(hit.normal, int(i));
    }
}

void runPrimitiveCalls(std::span<void* const> lanes) {
    if (lanes.size() == 1) {
        PrimitiveCall& c = *static_cast<PrimitiveCall*>(lanes[0]);
        [[maybe_unused]] PrecisionScope<float> scope;
        c.result = IntersectPrimitive<float>(c.shader, c.primitiveType, c.localRay, c.extent, c.elapsedTime,
                                             c.stepScale, *c.accuracy);
        return;
    }
    if (lanes.size() <= size_t(kWaveLanes)) return runPrimitiveCallsIn<WaveLanes<float>>(lanes);
    runPrimitiveCallsIn<WideLanes>(lanes);
}

inline constexpr dxr::WaveFunction kPrimitiveCalls{runPrimitiveCalls, kWideLanes};

// The SignedDistancePrimitive calls of a wave: a whole wave's lanes a call, through SignedDistanceQueue (one lane
// alone in float, as runPrimitiveCalls).
void runSignedDistanceCalls(std::span<void* const> lanes) {
    const auto call = [&lanes](size_t i) -> PrimitiveCall& { return *static_cast<PrimitiveCall*>(lanes[i]); };
    if (lanes.size() == 1) return runPrimitiveCalls(lanes);
    std::array<math::SphereTraceRay<float>, kMaxWaveWidth> rays;
    std::array<PrimitiveHit<float>, kMaxWaveWidth> hits;
    for (size_t i = 0; i < lanes.size(); ++i) rays[i] = {call(i).localRay, call(i).extent, call(i).stepScale};
    const PrimitiveCall& first = call(0);
    SignedDistanceQueue(first.primitiveType, *first.accuracy, rays.data(), int(lanes.size()), hits.data());
    for (size_t i = 0; i < lanes.size(); ++i) call(i).result = hits[i];
}

inline constexpr dxr::WaveFunction kSignedDistanceCalls{runSignedDistanceCalls, kMaxWaveWidth};

// TraceRay wrappers: both stop at MAX_RAY_RECURSION_DEPTH (black / "not in shadow"); TMin 0, TMax 10000.
// The RayDesc and the payload are the GPU interface: the ray is rounded to float on the way in.
// PORT: the HLSL passes the constants TraceRayParameters::InstanceMask, TraceRayParameters::HitGroup::Offset[rayType],
// TraceRayParameters::HitGroup::GeometryStride and TraceRayParameters::MissShader::Offset[rayType]; here they come
// from `traceRay` (the library's TraceRayArgumentSet, those same values by default), which every caller passes down.
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
    rayPayload = RayPayload{vec4(0.0f), currentRayRecursionDepth + 1};
    const TraceRayArguments& radiance = traceRay[RayType::Radiance];
    setTraceRayCall(call, ctx.globalRootDescriptor(kAccelerationStructure), kTraceRayFlags[RayType::Radiance],
                    radiance.instanceInclusionMask, /*HitGroup::Offset*/ radiance.rayContribution,
                    /*HitGroup::GeometryStride*/ radiance.multiplier,
                    /*MissShader::Offset*/ radiance.missShaderIndex, /*RayDesc*/ vec3(origin), 0.0f, vec3(direction),
                    10000.0f, rayPayload);
    return true;
}

// PORT: TraceShadowRayAndReportIfHit up to its TraceRay: false where the HLSL returns false untraced (at
// MAX_RAY_RECURSION_DEPTH, or with shadows switched off); else `shadowPayload` initialised and `call` the TraceRay
// with it, for the caller to make (alone, or with a wave's other lanes). The function's result is then
// shadowPayload.hit != 0.
template <typename T>
bool ShadowRayCall(ShaderContext& ctx, const TraceRayArgumentSet& traceRay, uint32_t maxDepth, const Effects& effects,
                   const tvec3<T>& origin, const tvec3<T>& direction, uint32_t currentRayRecursionDepth,
                   ShadowRayPayload& shadowPayload, TraceRayCall& call) {
    if (currentRayRecursionDepth >= maxDepth) return false;
    if (!kShadowMachinery || !effects.traceShadowRays) return false;  // PORT: shadows switched off (procedural/effects.h)
    // Starts as "hit": closest-hit and any-hit shaders are skipped, only MyMissShader_ShadowRay clears it.
    shadowPayload = ShadowRayPayload{1};
    const TraceRayArguments& shadow = traceRay[RayType::Shadow];
    setTraceRayCall(call, ctx.globalRootDescriptor(kAccelerationStructure), kTraceRayFlags[RayType::Shadow],
                    shadow.instanceInclusionMask, /*HitGroup::Offset*/ shadow.rayContribution,
                    /*HitGroup::GeometryStride*/ shadow.multiplier, /*MissShader::Offset*/ shadow.missShaderIndex,
                    /*RayDesc, TMax 10000, not the distance to the light (I2)*/ vec3(origin), 0.0f,
                    vec3(direction), 10000.0f, shadowPayload);
    return true;
}

// ---- Inline tracing (scenes/inline/InlineShadows.hlsl, InlineAmbientOcclusion.hlsl) -------------------

// StructuredBuffer<InlinePrimitive> g_inlinePrimitives : register(t4): per geometry of the AABB BLAS, what the
// records' local root arguments give the intersection shaders in the TraceRay version.
struct InlinePrimitive {
    uint32_t intersectionShader;  // IntersectionShader
    uint32_t instanceIndex;       // l_aabbCB.instanceIndex
    uint32_t primitiveType;       // l_aabbCB.primitiveType
    float stepScale;              // l_materialCB.stepScale
};
static_assert(sizeof(InlinePrimitive) == 16);
inline constexpr uint32_t kInlinePrimitivesRegister = 4;  // t4, space0

// The query flags of TraceShadowRayInlineAndReportIfHit and TraceOcclusionInline: the TraceRay shadow ray's flags
// less SKIP_CLOSEST_HIT_SHADER, which a RayQuery may not carry (RQ-4).
inline constexpr uint32_t kInlineShadowQueryFlags =
    RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
// TracePrimaryInline's: the radiance rays' flags.
inline constexpr uint32_t kInlinePrimaryQueryFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;

// The inline-tracing shaders as written (scenes/inline/*.hlsl), and variants with one classic mistake or one GPU
// back-end bug each: extra exports named <export>_<variant> (inlineVariantSuffix) that the lessons
// (scenes/lessons/) and the discrimination mutants (verify/discrimination.cpp) select. AsWritten is the code the
// HLSL ports; every other value changes only the line its comment names.
enum class InlineVariant : uint8_t {
    AsWritten,
    // LESSON inline-procedural-never-intersected: the Proceed loop handles triangles only; procedural candidates
    // are never intersected, so inline rays pass through the procedural geometry.
    IgnoreProcedural,
    // LESSON accept-first-hit-for-shadows: the shadow / occlusion query without RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH:
    // it searches for the closest hit where any hit answers the question (same image, more candidates).
    SearchAllHits,
    // LESSON committed-getters-after-a-miss: the primary query asks which instance it hit (CommittedInstanceIndex)
    // before asking whether it hit anything (CommittedStatus): RQ-29 on the first ray that misses.
    ReadCommittedAfterMiss,
    // MUTANT rq-commit-outside-range: the shader-side range check dropped: each procedural candidate is intersected
    // over the whole ray line (-TMax, TMax) instead of [RayTMin, CommittedRayT], and the t found is committed
    // unchecked (RQ-22).
    NoRangeCheck,
    // MUTANT rq-committed-t-is-tmax: a back end whose CommittedRayT() returns the ray's TMax after a commit: the
    // shader's reads of it after its commits get TMax.
    CommittedTIsTMax,
};
inline constexpr InlineVariant kInlineVariants[] = {InlineVariant::AsWritten,        InlineVariant::IgnoreProcedural,
                                                    InlineVariant::SearchAllHits,    InlineVariant::ReadCommittedAfterMiss,
                                                    InlineVariant::NoRangeCheck,     InlineVariant::CommittedTIsTMax};

// "" for AsWritten, else "_IgnoreProcedural", ...: appended to the export's name.
std::string inlineVariantSuffix(InlineVariant v) {
    switch (v) {
        case InlineVariant::AsWritten: return "";
        case InlineVariant::IgnoreProcedural: return "_IgnoreProcedural";
        case InlineVariant::SearchAllHits: return "_SearchAllHits";
        case InlineVariant::ReadCommittedAfterMiss: return "_ReadCommittedAfterMiss";
        case InlineVariant::NoRangeCheck: return "_NoRangeCheck";
        case InlineVariant::CommittedTIsTMax: return "_CommittedTIsTMax";
    }
    return "_Unknown";
}

// The shadow / occlusion query's template flags: kInlineShadowQueryFlags, less ACCEPT_FIRST_HIT_AND_END_SEARCH for
// SearchAllHits.
constexpr uint32_t inlineShadowQueryFlags(InlineVariant v) {
    return v == InlineVariant::SearchAllHits ? kInlineShadowQueryFlags & ~uint32_t(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH)
                                             : kInlineShadowQueryFlags;
}

// q.CommittedRayT() as the variant's back end returns it (CommittedTIsTMax: TMax once something is committed).
float committedRayT(const RayQueryObject& q, float rayTMax, InlineVariant v) {
    if (v == InlineVariant::CommittedTIsTMax && q.CommittedStatus() != COMMITTED_NOTHING) return rayTMax;
    return q.CommittedRayT();
}

// The Proceed loop of the inline-tracing shaders' RayQuery objects (TraceAnyHitInline, TracePrimaryInline):
//   while (q.Proceed()) {
//       if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE) {
//           if (IntersectCandidateProceduralPrimitive(q, thit, attr)) q.CommitProceduralPrimitiveHit(thit);
//       } else {
//           q.CommitNonOpaqueTriangleHit();  // the primary query only
//       }
//   }
// IntersectCandidateProceduralPrimitive is the intersection shaders' code for the query's current procedural
// candidate, with the query's extent: RayTMin() -> q.RayTMin(), RayTCurrent() -> q.CommittedRayT(), RayFlags() ->
// q.RayFlags() (a closest hit's own intrinsics describe its own ray); its hit's world normal is the attribute.
// PORT: the loop runs in steps that end at each procedural candidate's test, so that the lanes of a wave run their
// loops together and their tests as wave calls (emulator/wave_call.h): proceed(call) runs the loop up to the next
// procedural candidate and returns true with its test as `call` (IntersectPrimitive for the lanes that make one, in
// float: runPrimitiveCalls, runSignedDistanceCalls), or false once Proceed returns FALSE; the next proceed commits
// the test's hit and goes on. Its TraceRayInline is a wave call too (traceRayInlineCall: the wave's queries' rays
// gather their candidates in Embree packets): trace(ray) readies it, and the next proceed hands it out. A shader
// written for waves runs its lanes' loops through ShaderWave::CallsInLoop. double and PerturbedFloat test at once,
// for withLaneType's reasons. The variant (InlineVariant) changes only the lines its comment names.
template <typename T>
class InlineQueryLoop {
public:
    // RayQuery<templateFlags> q, whose TraceRayInline(the scene, RAY_FLAG_NONE, instanceMask, ray) trace(ray) readies.
    // `commitTriangles`: the loop commits its triangle candidates (the shadow query's are opaque, committed inside
    // Proceed, RQ-14).
    InlineQueryLoop(ShaderContext& ctx, uint32_t templateFlags, uint32_t instanceMask, bool commitTriangles,
                    const Accuracy& accuracy, InlineVariant variant)
        : ctx_(&ctx), q_(ctx, templateFlags, RAYQUERY_FLAG_NONE), commitTriangles_(commitTriangles),
          accuracy_(&accuracy), variant_(variant) {
        traceCall_.query = &q_;
        traceCall_.accelerationStructure = ctx.globalRootDescriptor(kAccelerationStructure);
        traceCall_.instanceInclusionMask = instanceMask;
    }
    // q.TraceRayInline(the scene, RAY_FLAG_NONE, instanceMask, ray), made by the next proceed. A lane's next query
    // of the same kind traces the same object again (RQ-9: what it held is discarded), as a new RayQuery of the same
    // flags would trace it.
    // PORT: the HLSL declares a RayQuery per call of TraceAnyHitInline; one object traced again is the same query
    // (the same checks, counts and events), made once per lane, with the scene's address read once.
    void trace(const vec3& origin, const vec3& direction, float tMax) {
        pending_ = false;
        tracing_ = true;
        committedNormal_ = tvec3<T>(T(0));
        storeRayDesc(traceCall_.ray, origin, 0.0f, direction, tMax);  // whole: TraceRayInline reads it at once
    }
    InlineQueryLoop(const InlineQueryLoop&) = delete;
    InlineQueryLoop& operator=(const InlineQueryLoop&) = delete;

    // trace(ray), made at once, alone: for a lane whose next query follows its last one in the same step, so that it
    // reaches its first procedural test in that step rather than wait a round for its TraceRayInline.
    void traceNow(const vec3& origin, const vec3& direction, float tMax) {
        trace(origin, direction, tMax);
        tracing_ = false;
        q_.TraceRayInline(traceCall_.accelerationStructure, traceCall_.rayFlags, traceCall_.instanceInclusionMask,
                          traceCall_.ray);
    }

    bool proceed(WaveCall& call) {
        if (tracing_) {  // the TraceRayInline first: handed out, then done
            if (!traced_) {
                traced_ = true;
                call = traceRayInlineCall(traceCall_);
                return true;
            }
            tracing_ = traced_ = false;
            if (traceCall_.failure) std::rethrow_exception(std::exchange(traceCall_.failure, nullptr));
        }
        if (pending_) {
            pending_ = false;
            if constexpr (std::is_same_v<T, float>) commitTest(call_.result);
        }
        while (q_.Proceed()) {
            if (q_.CandidateType() != CANDIDATE_PROCEDURAL_PRIMITIVE) {
                if (commitTriangles_) q_.CommitNonOpaqueTriangleHit();  // no any-hit shader: TraceRay would accept it
                continue;
            }
            if (variant_ == InlineVariant::IgnoreProcedural) continue;  // LESSON: the candidate is never intersected
            const InlinePrimitive primitive =
                ctx_->loadStructured<InlinePrimitive>(kInlinePrimitivesRegister, 0, 0, q_.CandidateGeometryIndex());
            // PORT: the attribute buffer's address and the scene's elapsedTime are read once per query object.
            if (!aabbAttributes_) aabbAttributes_ = ctx_->globalRootDescriptor(kAABBattributeBuffer);
            aabbAttribute_ = ctx_->load<PrimitiveInstancePerFrameBuffer>(
                *aabbAttributes_ + uint64_t(primitive.instanceIndex) * sizeof(PrimitiveInstancePerFrameBuffer));
            const math::Ray<T> localRay = GetRayInAABBPrimitiveLocalSpace<T>(
                q_.CandidateObjectRayOrigin(), q_.CandidateObjectRayDirection(), aabbAttribute_);
            const auto shader = IntersectionShader(primitive.intersectionShader);
            if (shader == IntersectionShader::VolumetricPrimitive && !elapsedTime_)
                elapsedTime_ = sceneCB(*ctx_).elapsedTime;
            const T elapsedTime = shader == IntersectionShader::VolumetricPrimitive ? T(*elapsedTime_) : T(0);
            const math::RayExtent<T> extent =
                variant_ == InlineVariant::NoRangeCheck
                    ? CurrentExtent<T>(-rayTMax(), rayTMax(), q_.RayFlags())  // MUTANT: the whole line
                    : CurrentExtent<T>(q_.RayTMin(), committedRayT(q_, rayTMax(), variant_), q_.RayFlags());
            objectToWorld_ = q_.CandidateObjectToWorld3x4();
            if constexpr (std::is_same_v<T, float>) {
                // PORT: the pending call's fields set one by one (an aggregate assigned from a temporary was copied
                // with wider loads than the stores that built it, a store-forwarding stall per candidate).
                call_.shader = shader;
                call_.primitiveType = primitive.primitiveType;
                call_.accuracy = accuracy_;
                call_.localRay = localRay;
                call_.extent = extent;
                call_.elapsedTime = elapsedTime;
                call_.stepScale = primitive.stepScale;
                call_.result = {};
                call = {shader == IntersectionShader::SignedDistancePrimitive ? &kSignedDistanceCalls : &kPrimitiveCalls,
                        {accuracy_, (uint64_t(shader) << 32) | primitive.primitiveType}, &call_};
                pending_ = true;
                return true;
            } else {
                commitTest(IntersectPrimitive<T>(shader, primitive.primitiveType, localRay, extent, elapsedTime,
                                                 T(primitive.stepScale), *accuracy_));
            }
        }
        return false;
    }

    RayQueryObject& query() { return q_; }
    const RayQueryObject& query() const { return q_; }
    float rayTMax() const { return traceCall_.ray.TMax; }
    // The world normal of the procedural hit committed last (zero before one): the system keeps no attributes of a
    // procedural hit (RQ-23), the shader keeps them.
    const tvec3<T>& committedNormal() const { return committedNormal_; }

private:

    // The candidate's test done: a hit is committed (ACCEPT_FIRST_HIT_AND_END_SEARCH: Proceed then returns FALSE).
    void commitTest(const PrimitiveHit<T>& test) {
        if (!test.hit) return;
        const tvec3<T> normal = NormalToWorld(objectToWorld_, aabbAttribute_, test.normal);
        q_.CommitProceduralPrimitiveHit(float(test.thit));
        committedNormal_ = tvec3<T>(vec3(normal));  // float, as the HLSL's attribute
    }

    ShaderContext* ctx_;
    RayQueryObject q_;
    RayQueryTraceCall traceCall_;  // the query's TraceRayInline
    std::optional<GpuVirtualAddress> aabbAttributes_;  // g_AABBPrimitiveAttributes, once read
    std::optional<float> elapsedTime_;                 // g_sceneCB.elapsedTime, once read
    bool tracing_ = false, traced_ = false;
    bool commitTriangles_;
    const Accuracy* accuracy_;
    InlineVariant variant_;
    bool pending_ = false;
    PrimitiveCall call_;  // the pending test's (float)
    PrimitiveInstancePerFrameBuffer aabbAttribute_{};
    Matrix3x4 objectToWorld_{};
    tvec3<T> committedNormal_{T(0)};
};

// TraceAnyHitInline's query: true when the ray from origin along direction meets a surface in [0, tMax]. Procedural
// candidates are intersected in the loop and committed; the ground plane's triangles are opaque (FORCE_OPAQUE) and
// committed inside Proceed (RQ-14). The shadow rays' query, which the AO occlusion rays trace too.
// PORT: RayQuery<kInlineShadowQueryFlags> q; the object is made with the variant's template flags
// (inlineShadowQueryFlags), which for AsWritten are kInlineShadowQueryFlags.
// PORT: TraceRayParameters::InstanceMask is the library's shadow-ray mask, as in the TraceRay version.
// PORT: a lane's next query (`loop` already made: its next occlusion ray) traces the same object again
// (InlineQueryLoop::trace).
// PORT: `now`: the query is traced at once (InlineQueryLoop::traceNow), else by the loop's next proceed.
template <typename T>
void AnyHitQuery(std::optional<InlineQueryLoop<T>>& loop, ShaderContext& ctx, const TraceRayArgumentSet& traceRay,
                 const Accuracy& accuracy, const tvec3<T>& origin, const tvec3<T>& direction, float tMax,
                 InlineVariant variant, bool now = false) {
    if (!loop)
        loop.emplace(ctx, inlineShadowQueryFlags(variant), traceRay[RayType::Shadow].instanceInclusionMask,
                     /*commitTriangles*/ false, accuracy, variant);
    if (now) loop->traceNow(vec3(origin), vec3(direction), tMax);
    else loop->trace(vec3(origin), vec3(direction), tMax);
}

// TraceAnyHitInline's result, after its loop.
template <typename T>
bool AnyHitQueryResult(const InlineQueryLoop<T>& loop) {
    return loop.query().CommittedStatus() != COMMITTED_NOTHING;
}

// TraceShadowRayAndReportIfHit, traced inline (TraceShadowRayInlineAndReportIfHit) up to its query: false where the
// HLSL returns false untraced (at MAX_RAY_RECURSION_DEPTH, or with shadows switched off); else true with the query
// TraceAnyHitInline makes, TMax 10000 as the TraceRay version. The function's result is then AnyHitQueryResult.
template <typename T>
bool ShadowQueryInline(std::optional<InlineQueryLoop<T>>& loop, ShaderContext& ctx, const TraceRayArgumentSet& traceRay,
                       uint32_t maxDepth, const Effects& effects, const Accuracy& accuracy, const tvec3<T>& origin,
                       const tvec3<T>& direction, uint32_t currentRayRecursionDepth, InlineVariant variant) {
    if (currentRayRecursionDepth >= maxDepth) return false;
    if (!kShadowMachinery || !effects.traceShadowRays) return false;  // PORT: shadows switched off (procedural/effects.h)
    AnyHitQuery(loop, ctx, traceRay, accuracy, origin, direction, 10000.0f, variant);
    return true;
}

// How a closest hit traces its shadow ray: TraceRay (the sample) or a RayQuery (InlineShadows.hlsl).
enum class ShadowTracing : uint8_t { TraceRay, Inline };

// reflectanceCoef·(Fresnel, 1)·(reflection ray colour), for the reflection ray along reflect(D, normal) (D: the
// incoming ray's WorldRayDirection()); albedo and reflectanceCoef are l_materialCB's.
template <typename T>
tvec4<T> ReflectedColor(const tvec3<T>& D, const tvec3<T>& normal, const tvec3<T>& albedo, const T& reflectanceCoef,
                        const tvec4<T>& reflectionColor) {
    const tvec3<T> fresnelR = FresnelReflectanceSchlick(D, normal, albedo);
    return reflectanceCoef * tvec4<T>(fresnelR, T(1)) * reflectionColor;
}

// What a closest hit's final colour reads once its rays are back, in the math type U: T for one lane, or
// WaveLanes<float> for up to kWaveLanes lanes of a float wave (one closest hit per lane).
template <typename U>
struct FinalColorInput {
    tvec4<U> albedo;  // l_materialCB's
    U diffuseCoef, specularCoef, specularPower, reflectanceCoef;
    math::LaneMask<U> reflects;   // l_materialCB.reflectanceCoef > 0.001 (in float)
    math::LaneMask<U> reflected;  // RadianceRayCall made the reflection ray (else its colour is black)
    tvec4<U> reflectionColor;     // the reflection ray's payload colour
    math::LaneMask<U> inShadow;   // TraceShadowRayAndReportIfHit's result
    tvec3<U> normal, hitPosition, worldRayDirection;
    U tCurrent;                   // RayTCurrent()
    // DispatchRaysIndex().xy + uint2(1, 0), + uint2(0, 1), and DispatchRaysDimensions().xy (the triangle's checkers).
    tvec2<U> ddxPixel, ddyPixel, dimensions;
};

// A closest hit's final colour: its reflected component (reflectanceCoef > 0.001), its Phong colour,
// `combine(in, sceneCB, phongColor, reflectedColor)` and the visibility falloff; lane by lane the HLSL's.
template <typename U, class Combine>
tvec4<U> FinalColor(const SceneConstantBuffer& sceneCB, const FinalColorInput<U>& in, Combine& combine) {
    // PORT: `if (l_materialCB.reflectanceCoef > 0.001)`; over lanes, the lanes without it keep 0.
    tvec4<U> reflectedColor(U(0));
    const auto reflected = [&] {
        // TraceRadianceRay's colour: black where RadianceRayCall made no ray (MAX_RAY_RECURSION_DEPTH).
        const tvec4<U> reflectionColor = math::select(in.reflected, in.reflectionColor, tvec4<U>(U(0)));
        return ReflectedColor(in.worldRayDirection, in.normal, tvec3<U>(in.albedo), in.reflectanceCoef,
                              reflectionColor);
    };
    if constexpr (math::kIsLanes<U>) {
        if (math::anyLane(in.reflects)) {
            const math::LiveLanes live(in.reflects);
            reflectedColor = math::select(in.reflects, reflected(), reflectedColor);
        }
    } else if (in.reflects) {
        reflectedColor = reflected();
    }
    const tvec4<U> phongColor =
        CalculatePhongLighting(sceneCB, in.albedo, in.normal, in.inShadow, in.diffuseCoef, in.specularCoef,
                               in.specularPower, in.hitPosition, in.worldRayDirection);
    const tvec4<U> color = combine(in, sceneCB, phongColor, reflectedColor);
    return ApplyVisibilityFalloff(color, in.tCurrent);
}

// What a closest hit's lane carries from one TraceRay to the next: its constants, its normal, its shadow ray's
// origin, direction, payload and result, and its reflection ray's.
template <typename T>
struct ClosestHitLane {
    const SceneConstantBuffer* sceneCB = nullptr;  // PORT: the wave's one copy (WaveShared), not a copy per lane
    PrimitiveConstantBuffer materialCB;
    tvec3<T> normal;
    tvec3<T> hitPosition, toLight;
    ShadowRayPayload shadowPayload;
    bool shadowTraced = false;
    bool shadowRayHit = false;
    RayPayload reflectionPayload;
    bool reflected = false;
};

// Lane `l`'s FinalColorInput, its rays back.
template <typename T>
FinalColorInput<T> finalColorInput(const ClosestHitLane<T>& l, const ShaderContext& ctx) {
    FinalColorInput<T> in;
    in.albedo = tvec4<T>(l.materialCB.albedo);
    in.diffuseCoef = T(l.materialCB.diffuseCoef);
    in.specularCoef = T(l.materialCB.specularCoef);
    in.specularPower = T(l.materialCB.specularPower);
    in.reflectanceCoef = T(l.materialCB.reflectanceCoef);
    in.reflects = l.materialCB.reflectanceCoef > 0.001f;
    in.reflected = l.reflected;
    in.reflectionColor = tvec4<T>(l.reflectionPayload.color);
    in.inShadow = l.shadowRayHit;
    in.normal = l.normal;
    in.hitPosition = l.hitPosition;
    in.worldRayDirection = tvec3<T>(ctx.WorldRayDirection());
    in.tCurrent = T(ctx.RayTCurrent());
    const uvec2 index(ctx.DispatchRaysIndex());
    in.ddxPixel = tvec2<T>(index + uvec2(1, 0));
    in.ddyPixel = tvec2<T>(index + uvec2(0, 1));
    in.dimensions = tvec2<T>(uvec2(ctx.DispatchRaysDimensions()));
    return in;
}

// Lane j of `lanes` set to `in` (FinalColorInput over WaveLanes<float>).
void setLane(FinalColorInput<WaveLanes<float>>& lanes, int j, const FinalColorInput<float>& in) {
    math::setLane(lanes.albedo, j, in.albedo);
    math::setLane(lanes.diffuseCoef, j, in.diffuseCoef);
    math::setLane(lanes.specularCoef, j, in.specularCoef);
    math::setLane(lanes.specularPower, j, in.specularPower);
    math::setLane(lanes.reflectanceCoef, j, in.reflectanceCoef);
    math::setLane(lanes.reflects, j, in.reflects);
    math::setLane(lanes.reflected, j, in.reflected);
    math::setLane(lanes.reflectionColor, j, in.reflectionColor);
    math::setLane(lanes.inShadow, j, in.inShadow);
    math::setLane(lanes.normal, j, in.normal);
    math::setLane(lanes.hitPosition, j, in.hitPosition);
    math::setLane(lanes.worldRayDirection, j, in.worldRayDirection);
    math::setLane(lanes.tCurrent, j, in.tCurrent);
    math::setLane(lanes.ddxPixel, j, in.ddxPixel);
    math::setLane(lanes.ddyPixel, j, in.ddyPixel);
    math::setLane(lanes.dimensions, j, in.dimensions);
}

// The final colours of a float wave's lanes `finishing` (their FinalColorInput in `inputs`) into their payloads, in
// WaveLanes<float>, kWaveLanes lanes at a time (a call of one lane alone in float): each lane's colour is bit for bit
// what FinalColor<float> gives it alone (procedural/math/lanes.h).
template <class Combine>
void FinalColorsInLanes(ClosestHitWave& wave, const SceneConstantBuffer& sceneCB, LaneMask finishing,
                        const std::array<FinalColorInput<float>, kMaxWaveWidth>& inputs, Combine& combine) {
    using L = WaveLanes<float>;
    const auto group = [&](const std::array<int, kWaveLanes>& lane, int n) {
        FinalColorInput<L> in;
        for (int j = 0; j < kWaveLanes; ++j) setLane(in, j, inputs[size_t(lane[size_t(j)])]);
        const tvec4<L> color = FinalColor(sceneCB, in, combine);
        for (int j = 0; j < n; ++j) wave.payload<RayPayload>(lane[size_t(j)]).color = math::lane(color, j);
    };
    const auto alone = [&](int i) {
        wave.payload<RayPayload>(i).color = vec4(FinalColor(sceneCB, inputs[size_t(i)], combine));
    };
    inGroupsOfLanes(finishing, group, alone);
}

// The code both closest hits share, over the lanes of a wave (emulator/closest_hit_wave.h), lane by lane the HLSL's:
// `open(ctx, lane, attr)` reads a lane's normal; its shadow ray from HitWorldPosition() towards the light
// (TraceShadowRayAndReportIfHit, or traced inline); its reflected component, reflectanceCoef > 0.001 (ReflectedColor:
// a reflection ray); then FinalColor, with `combine(in, sceneCB, phongColor, reflectedColor)` (the triangle's
// checkers). The lanes' shadow rays go out together (TraceRay), or their inline queries' loops run together
// (ShaderWave::CallsInLoop); then their reflection rays (TracingWave::TraceRaysInSteps); then, in float, their final
// colours in lanes (FinalColorsInLanes).
// PORT: the checkers, which the HLSL computes before the reflection ray, come with the final colour: they read
// nothing the ray changes.
template <typename T, class Attributes, class Open, class Combine>
void SampleClosestHit(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                      const Effects& effects, ShadowTracing tracing, InlineVariant variant, Open open,
                      Combine combine) {
    [[maybe_unused]] PrecisionScope<T> scope;
    const uint32_t maxDepth = maxRayRecursionDepth(accuracy);
    std::array<ClosestHitLane<T>, kMaxWaveWidth> lanes;
    WaveShared<SceneConstantBuffer> scene;  // PORT: g_sceneCB, read once between the lanes
    // Up to the shadow ray: the lane's constants, normal, hit position and the direction to the light.
    const auto openLane = [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l) {
        l.sceneCB = &scene.get(ctx, sceneCB);
        l.materialCB = materialCB(ctx);
        open(ctx, l, wave.attributes<Attributes>(i));
        l.hitPosition = HitWorldPosition<T>(ctx);
        l.toLight = hlsl::normalize(tvec3<T>(vec3(l.sceneCB->lightPosition)) - l.hitPosition);
    };
    // Shadow component, traced by TraceRay.
    const auto shadowRay = [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l, TraceRayCall& call) {
        openLane(i, ctx, l);
        return l.shadowTraced = ShadowRayCall(ctx, traceRay, maxDepth, effects, l.hitPosition, l.toLight,
                                              wave.payload<RayPayload>(i).recursionDepth, l.shadowPayload, call);
    };
    // Reflected component: the ray of ReflectedColor, when reflectanceCoef > 0.001.
    const auto reflectionRay = [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l, TraceRayCall& call) {
        if (l.shadowTraced) l.shadowRayHit = l.shadowPayload.hit != 0;  // TraceShadowRayAndReportIfHit's result
        if (!(l.materialCB.reflectanceCoef > 0.001f)) return false;
        const tvec3<T> D(ctx.WorldRayDirection());
        return l.reflected = RadianceRayCall(ctx, traceRay, maxDepth, l.hitPosition, hlsl::reflect(D, l.normal),
                                             wave.payload<RayPayload>(i).recursionDepth, l.reflectionPayload, call);
    };
    // Final colour, then the visibility falloff: in float, each lane's input kept for FinalColorsInLanes (the other
    // types shade each lane at once and keep none).
    struct NoInputs {};
    std::conditional_t<std::is_same_v<T, float>, std::array<FinalColorInput<float>, kMaxWaveWidth>, NoInputs>
        finalInputs;
    LaneMask finishing;
    const auto finalColor = [&](int i, ShaderContext& ctx, ClosestHitLane<T>& l, TraceRayCall&) {
        if constexpr (std::is_same_v<T, float>) {
            finalInputs[size_t(i)] = finalColorInput(l, ctx);
            finishing.set(i);
        } else {
            wave.payload<RayPayload>(i).color = vec4(FinalColor(*l.sceneCB, finalColorInput(l, ctx), combine));
        }
        return false;
    };
    const auto finalColorsInLanes = [&] {
        if constexpr (std::is_same_v<T, float>)
            if (finishing.any())
                FinalColorsInLanes(wave, *lanes[size_t(finishing.lowest())].sceneCB, finishing, finalInputs, combine);
    };
    if (tracing == ShadowTracing::TraceRay) {
        wave.TraceRaysInSteps(std::span<ClosestHitLane<T>>(lanes), shadowRay, reflectionRay, finalColor);
        finalColorsInLanes();
        return;
    }
    // Shadow component, traced inline: the lanes' queries' loops together.
    std::array<std::optional<InlineQueryLoop<T>>, kMaxWaveWidth> shadowQueries;
    LaneMask querying;
    wave.forEachLane([&](int i, ShaderContext& ctx) {
        ClosestHitLane<T>& l = lanes[size_t(i)];
        openLane(i, ctx, l);
        if (ShadowQueryInline(shadowQueries[size_t(i)], ctx, traceRay, maxDepth, effects, accuracy, l.hitPosition,
                              l.toLight, wave.payload<RayPayload>(i).recursionDepth, variant))
            querying.set(i);
    });
    wave.CallsInLoop(querying, [&](int i, ShaderContext&, WaveCall& call) {
        return shadowQueries[size_t(i)]->proceed(call);
    });
    wave.forEachLane([&](int i, ShaderContext&) {
        ClosestHitLane<T>& l = lanes[size_t(i)];
        if (querying.test(i)) l.shadowRayHit = AnyHitQueryResult(*shadowQueries[size_t(i)]);
    });
    wave.TraceRaysInSteps(std::span<ClosestHitLane<T>>(lanes), reflectionRay, finalColor);
    finalColorsInLanes();
}

// ---- Entry points ----------------------------------------------------------------------------------
// Each is a template on the scalar type; results are rounded to float where they cross the interface. Those that
// trace rays take the library's TraceRay arguments, and those that march or recurse its Accuracy (PORT: constants
// in the HLSL); those that trace shadow rays take its Effects.

// PORT: written for waves: the samples' shared CameraRaygen (procedural/sample_layout.h).
template <typename T>
void MyRaygenShader(RayGenerationWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy) {
    [[maybe_unused]] PrecisionScope<T> scope;
    const uint32_t maxDepth = maxRayRecursionDepth(accuracy);
    CameraRaygen<T, RayPayload>(
        wave, kOutputView,
        [](ShaderContext& ctx) {
            const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
            return CameraSetup<T>{tvec3<T>(vec3(g_sceneCB.cameraPosition)), g_sceneCB.projectionToWorld};
        },
        [&](ShaderContext& ctx, const tvec3<T>& origin, const tvec3<T>& direction, uint32_t depth, RayPayload& payload,
            TraceRayCall& call) {
            return RadianceRayCall(ctx, traceRay, maxDepth, origin, direction, depth, payload, call);
        });
}

// PORT: written for waves (SampleClosestHit).
template <typename T>
void MyClosestHitShader_Triangle(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                                 const Effects& effects, ShadowTracing tracing, InlineVariant variant) {
    SampleClosestHit<T, BuiltInTriangleIntersectionAttributes>(
        wave, traceRay, accuracy, effects, tracing, variant,
        [](ShaderContext& ctx, ClosestHitLane<T>& l, const BuiltInTriangleIntersectionAttributes&) {
            // The normal of the triangle's first vertex, untransformed.
            l.normal = tvec3<T>(FirstVertexNormal(ctx, kVertexBuffers));
        },
        []<typename U>(const FinalColorInput<U>& in, const SceneConstantBuffer& sceneCB, const tvec4<U>& phongColor,
                       const tvec4<U>& reflectedColor) {
            // Grid lines from the primary camera rays' footprint, even for secondary hits (I7, H4).
            const U checkers = CheckersThrough(in.hitPosition, in.normal, tvec3<U>(vec3(sceneCB.cameraPosition)),
                                               sceneCB.projectionToWorld, in.ddxPixel, in.ddyPixel, in.dimensions);
            return checkers * (phongColor + reflectedColor);
        });
}

// PORT: written for waves (SampleClosestHit).
template <typename T>
void MyClosestHitShader_AABB(ClosestHitWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                             const Effects& effects, ShadowTracing tracing, InlineVariant variant) {
    SampleClosestHit<T, ProceduralPrimitiveAttributes>(
        wave, traceRay, accuracy, effects, tracing, variant,
        [](ShaderContext&, ClosestHitLane<T>& l, const ProceduralPrimitiveAttributes& attr) {
            l.normal = tvec3<T>(attr.normal);
        },
        []<typename U>(const FinalColorInput<U>&, const SceneConstantBuffer&, const tvec4<U>& phongColor,
                       const tvec4<U>& reflectedColor) { return phongColor + reflectedColor; });
}

void MyMissShader(ShaderContext&, RayPayload& rayPayload) { rayPayload.color = BackgroundColor; }

void MyMissShader_ShadowRay(ShaderContext&, ShadowRayPayload& rayPayload) { rayPayload.hit = 0; }

// ---- InlineAmbientOcclusionCS (scenes/inline/InlineAmbientOcclusion.hlsl) ------------------------------

inline constexpr uint32_t AO_RAY_COUNT = 8;
inline constexpr float AO_RADIUS = 3.0f;
inline constexpr float AO_ORIGIN_OFFSET = 0.01f;  // along the normal, in world units

// Chris Wellons' "lowbias32" integer hash.
uint32_t Hash(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// The top 24 bits of h as a float in [0, 1): exact.
float UnitFloat(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

// The cosine-weighted hemisphere around n, in the orthonormal basis of Duff et al. (JCGT 2017).
template <typename T>
tvec3<T> CosineHemisphereDirection(const tvec3<T>& n, T u1, T u2) {
    const T s = math::select(n.z >= T(0), T(1), T(-1));  // PORT: select, so that T may be lanes
    const T a = T(-1) / (s + n.z);
    const T b = n.x * n.y * a;
    const tvec3<T> t1(T(1) + s * n.x * n.x * a, s * b, -s * n.x);
    const tvec3<T> t2(b, s + n.y * n.y * a, -n.y);
    const T r = hlsl::sqrt(u1);
    const T phi = T(2) * T(3.14159265f) * u2;
    return r * hlsl::cos(phi) * t1 + r * hlsl::sin(phi) * t2 + hlsl::sqrt(T(1) - u1) * n;
}

// The primary query (TracePrimaryInline): the closest surface and its world normal, as the sample's closest hits
// compute it. The system keeps no attributes of a procedural hit (RQ-23): the loop keeps the normal of the hit it
// commits.
template <typename T>
void PrimaryQuery(std::optional<InlineQueryLoop<T>>& loop, ShaderContext& ctx, const TraceRayArgumentSet& traceRay,
                  const Accuracy& accuracy, const tvec3<T>& origin, const tvec3<T>& direction, InlineVariant variant) {
    static_assert(rayQueryTemplateError(kInlinePrimaryQueryFlags, RAYQUERY_FLAG_NONE) == nullptr);
    loop.emplace(ctx, kInlinePrimaryQueryFlags, traceRay[RayType::Radiance].instanceInclusionMask,
                 /*commitTriangles*/ true, accuracy, variant);
    loop->trace(vec3(origin), vec3(direction), 10000.0f);
}

// TracePrimaryInline's result, after its loop: whether it hit, with the hit's position and normal.
template <typename T>
bool PrimaryQueryResult(ShaderContext& ctx, const InlineQueryLoop<T>& loop, const tvec3<T>& origin,
                        const tvec3<T>& direction, tvec3<T>& hitPosition, tvec3<T>& normal, InlineVariant variant) {
    const RayQueryObject& q = loop.query();
    hitPosition = tvec3<T>(T(0));
    normal = tvec3<T>(T(0));
    uint32_t status = q.CommittedStatus();
    if (variant == InlineVariant::ReadCommittedAfterMiss)  // LESSON: the instance (0: the ground) before the status
        status = q.CommittedInstanceIndex() == 0 ? COMMITTED_TRIANGLE_HIT : status;
    if (status == COMMITTED_NOTHING) return false;
    hitPosition = origin + T(committedRayT(q, loop.rayTMax(), variant)) * direction;
    if (status == COMMITTED_TRIANGLE_HIT) {
        // MyClosestHitShader_Triangle's normal: the first vertex's, untransformed.
        const uint32_t baseIndex = q.CommittedPrimitiveIndex() * 6;
        const GpuDescriptorHandle vertexBuffers = ctx.globalDescriptorTable(kVertexBuffers);
        const uvec3 indices = unpack3x16BitIndices(
            baseIndex, ctx.loadFromTable<uvec2>(vertexBuffers, /*g_indices*/ 0, /*Load2 at*/ baseIndex & ~3u));
        normal = tvec3<T>(
            ctx.loadFromTable<Vertex>(vertexBuffers, /*g_vertices*/ 1, uint64_t(indices[0]) * sizeof(Vertex)).normal);
    } else {
        normal = loop.committedNormal();
    }
    return true;
}

// The AO_RAY_COUNT occlusion rays' directions of the pixel whose hash is `seed`, around `normal`: ray i's is
// CosineHemisphereDirection(normal, u1, u2) with u1 = UnitFloat(Hash(seed ^ 2i)), u2 = UnitFloat(Hash(seed ^ (2i + 1))).
// PORT: in float the HLSL's loop computes them one ray at a time; here they are computed at once over WaveLanes<float>
// (ray i in lane i), each lane bit for bit its ray's scalar direction (procedural/math/lanes.h). The other types go
// ray by ray.
template <typename T>
std::array<tvec3<T>, AO_RAY_COUNT> OcclusionDirections(uint32_t seed, const tvec3<T>& normal) {
    const auto u = [seed](uint32_t i) { return UnitFloat(Hash(seed ^ i)); };
    std::array<tvec3<T>, AO_RAY_COUNT> out;
    if constexpr (std::is_same_v<T, float> && int(AO_RAY_COUNT) == kWaveLanes) {
        using L = WaveLanes<float>;
        [[maybe_unused]] PrecisionScope<L> scope;
        const L u1 = L::generate([&](int i) { return u(2 * uint32_t(i)); });
        const L u2 = L::generate([&](int i) { return u(2 * uint32_t(i) + 1); });
        const tvec3<L> d = CosineHemisphereDirection(tvec3<L>(normal), u1, u2);
        for (uint32_t i = 0; i < AO_RAY_COUNT; ++i) out[i] = math::lane(d, int(i));
    } else {
        for (uint32_t i = 0; i < AO_RAY_COUNT; ++i) out[i] = CosineHemisphereDirection(normal, T(u(2 * i)), T(u(2 * i + 1)));
    }
    return out;
}

// TraceOcclusionInline's query: the occlusion ray along `direction` from `hitPosition` off `normal`; it meets a
// surface when any lies within AO_RADIUS: the shadow rays' query.
template <typename T>
void OcclusionQuery(std::optional<InlineQueryLoop<T>>& loop, ShaderContext& ctx, const TraceRayArgumentSet& traceRay,
                    const Accuracy& accuracy, const tvec3<T>& direction, const tvec3<T>& hitPosition,
                    const tvec3<T>& normal, InlineVariant variant, bool now = false) {
    AnyHitQuery(loop, ctx, traceRay, accuracy, hitPosition + T(AO_ORIGIN_OFFSET) * normal, direction, AO_RADIUS,
                variant, now);
}

// [numthreads(8, 8, 1)] InlineAmbientOcclusionCS: one thread per pixel; threads past the render target's edge return.
//   if (TracePrimaryInline(origin, rayDir, hitPosition, normal)) {
//       seed = Hash(id.x ^ Hash(id.y)); escaped = 0;
//       for (i = 0; i < AO_RAY_COUNT; ++i) if (!TraceOcclusionInline(...ray i...)) escaped++;
//       color = float4(ao, ao, ao, 1) with ao = escaped / AO_RAY_COUNT;
//   }
// PORT: written for waves (emulator/compute_wave.h): each lane's code up to its primary query; the lanes' query
// loops together (ComputeWave::CallsInLoop, InlineQueryLoop: their TraceRayInlines and procedural tests are wave
// calls); each lane's result and its rays' directions (OcclusionDirections); then each lane's occlusion rays, one
// after another in the lane, their loops together (the first rays' TraceRayInlines go out together; a lane's next
// ray is traced at once as its last ends, InlineQueryLoop::traceNow); then each lane's colour.
template <typename T>
void InlineAmbientOcclusionCS(ComputeWave& wave, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                              InlineVariant variant) {
    [[maybe_unused]] PrecisionScope<T> scope;
    struct Lane {
        Image* target = nullptr;
        uvec2 id{0u};
        tvec3<T> origin, rayDir, hitPosition, normal;
        std::optional<InlineQueryLoop<T>> primary, occlusion;
        std::array<tvec3<T>, AO_RAY_COUNT> directions;
        uint32_t ray = 0, escaped = 0;
        bool hit = false;
    };
    std::array<Lane, kMaxWaveWidth> lanes;
    LaneMask inside;  // threads inside the render target
    // PORT: the render target and g_sceneCB are read once between the lanes (WaveShared).
    WaveShared<Image*> target;
    WaveShared<SceneConstantBuffer> scene;
    wave.forEachLane([&](int i, ShaderContext& ctx) {
        Lane& l = lanes[size_t(i)];
        const uvec3 id = ctx.DispatchThreadID();
        l.target = target.get(ctx, [](const ShaderContext& lane) {
            return &lane.rwTexture2D(lane.globalDescriptorTable(kOutputView));
        });
        const uint32_t width = l.target->width(), height = l.target->height();  // g_renderTarget.GetDimensions
        if (id.x >= width || id.y >= height) return;
        l.id = uvec2(id);
        const SceneConstantBuffer& g_sceneCB = scene.get(ctx, sceneCB);
        GenerateCameraRay(l.id, uvec2(width, height), tvec3<T>(vec3(g_sceneCB.cameraPosition)),
                          g_sceneCB.projectionToWorld, l.origin, l.rayDir);
        PrimaryQuery(l.primary, ctx, traceRay, accuracy, l.origin, l.rayDir, variant);
        inside.set(i);
    });
    wave.CallsInLoop(inside, [&](int i, ShaderContext&, WaveCall& call) { return lanes[size_t(i)].primary->proceed(call); });
    LaneMask occluded;  // lanes whose primary ray hit: they trace occlusion rays
    wave.forEachLane([&](int i, ShaderContext& ctx) {
        Lane& l = lanes[size_t(i)];
        if (!inside.test(i)) return;
        l.hit = PrimaryQueryResult(ctx, *l.primary, l.origin, l.rayDir, l.hitPosition, l.normal, variant);
        if (!l.hit) return;
        l.directions = OcclusionDirections(Hash(l.id.x ^ Hash(l.id.y)), l.normal);
        OcclusionQuery(l.occlusion, ctx, traceRay, accuracy, l.directions[0], l.hitPosition, l.normal, variant);
        occluded.set(i);
    });
    wave.CallsInLoop(occluded, [&](int i, ShaderContext& ctx, WaveCall& call) {
        Lane& l = lanes[size_t(i)];
        while (!l.occlusion->proceed(call)) {  // the lane's occlusion ray l.ray is over
            if (!AnyHitQueryResult(*l.occlusion)) l.escaped++;
            if (++l.ray == AO_RAY_COUNT) return false;
            OcclusionQuery(l.occlusion, ctx, traceRay, accuracy, l.directions[l.ray], l.hitPosition, l.normal, variant,
                           /*now*/ true);
        }
        return true;
    });
    wave.forEachLane([&](int i, ShaderContext&) {
        const Lane& l = lanes[size_t(i)];
        if (!inside.test(i)) return;
        tvec4<T> color = tvec4<T>(BackgroundColor);
        if (l.hit) {
            const T ao = T(l.escaped) / T(AO_RAY_COUNT);
            color = tvec4<T>(ao, ao, ao, T(1));
        }
        l.target->at(l.id.x, l.id.y) = vec4(color);
    });
}

// Each intersection shader starts from zero-initialised attributes (H6) and reports HitKind 0 with the world normal.
// The three intersection shaders (MyIntersectionShader_AnalyticPrimitive, _VolumetricPrimitive,
// _SignedDistancePrimitive), run once over the lanes of a record group (emulator/intersection_wave.h).
// PORT: each lane reads its own ray, record and constants, and reports its own hit, with the one-ray code in T; the
// intersection test between them runs over the lanes at once (T's lanes: WaveLanes<T>, 16 float lanes for a group of
// more than 8, T itself for a group of one lane; withLaneType). The lanes of a record group share the record, so the
// primitive type is the group's.
template <typename T, typename L>
void IntersectionShaderOf(IntersectionWave& wave, IntersectionShader shader, const Accuracy& accuracy) {
    [[maybe_unused]] PrecisionScope<L> scope;
    // PORT: what the lanes of a record group read alike (their record's constants, the attribute element it names,
    // the scene's time) is read once, by the first lane whose read succeeds (one whose read fails leaves the wave with
    // its error, as it would alone), in the order a lane alone reads it; each lane reads its own ray and extent.
    struct GroupInput {
        PrimitiveInstancePerFrameBuffer aabbAttribute{};
        uint32_t primitiveType = 0;
        T elapsedTime = T(0), stepScale = T(1);
    };
    const GroupInput group = readByTheGroup(wave, [shader](const ShaderContext& ctx) {
        GroupInput g;
        g.aabbAttribute = primitiveAttributes(ctx);
        g.primitiveType = aabbCB(ctx).primitiveType;
        if (shader == IntersectionShader::VolumetricPrimitive) g.elapsedTime = T(sceneCB(ctx).elapsedTime);
        if (shader == IntersectionShader::SignedDistancePrimitive) g.stepScale = T(materialCB(ctx).stepScale);
        return g;
    });
    struct LaneInput {
        math::Ray<T> localRay;
        math::RayExtent<T> extent;
    };
    const auto in = gatherLanes(wave, [&group](ShaderContext& ctx) {
        return LaneInput{GetRayInAABBPrimitiveLocalSpace<T>(ctx, group.aabbAttribute), CurrentExtent<T>(ctx)};
    });
    if (wave.active().empty()) return;
    const uint32_t primitiveType = group.primitiveType;
    // Each lane's hit.
    const std::array<PrimitiveHit<T>, kMaxWaveWidth> hits = [&] {
        if constexpr (math::kIsLanes<L>) {
            if (shader == IntersectionShader::SignedDistancePrimitive)  // all the group's lanes through one queue
                return throughQueue<PrimitiveHit<T>>(
                    wave.active(), in,
                    [&group](const LaneInput& l) {
                        return math::SphereTraceRay<T>{l.localRay, l.extent, group.stepScale};
                    },
                    [&](const math::SphereTraceRay<T>* rays, int count, PrimitiveHit<T>* out) {
                        SignedDistanceQueue(primitiveType, accuracy, rays, count, out);
                    });
        }
        const math::LiveLanes live(wave.active().bits(), 0);  // duplicated inactive lanes skip libm's calls
        constexpr int kLanes = math::kLaneCount<L>;
        const auto localRay = toLanes<math::Ray<L>, kLanes>(in, [](const LaneInput& l) { return l.localRay; });
        const auto extent = toLanes<math::RayExtent<L>, kLanes>(in, [](const LaneInput& l) { return l.extent; });
        const L elapsedTime(group.elapsedTime);
        const L stepScale(group.stepScale);
        const PrimitiveHit<L> test =
            IntersectPrimitive<L>(shader, primitiveType, localRay, extent, elapsedTime, stepScale, accuracy);
        std::array<PrimitiveHit<T>, kMaxWaveWidth> byLane{};
        for (int i : wave.active())
            byLane[size_t(i)] = {math::lane(test.hit, i), math::lane(test.thit, i), math::lane(test.normal, i)};
        return byLane;
    }();
    wave.forEachLane([&](int i, ShaderContext& ctx) {
        const PrimitiveHit<T>& hit = hits[size_t(i)];
        if (!hit.hit) return;
        const ProceduralPrimitiveAttributes attr{
            vec3(NormalToWorld(ctx.ObjectToWorld3x4(), group.aabbAttribute, hit.normal))};
        wave.ReportHit(i, float(hit.thit), /*hitKind*/ 0, attr);
    });
}

// Every export, with its math in T. The lambdas hold copies of the TraceRay arguments and the Accuracy, which the
// shaders take by reference; a PerturbedFloat library's also hold its perturbation (withArithmetic).
template <typename T>
void addExports(ShaderLibrary& lib, const TraceRayArgumentSet& traceRay, const Accuracy& accuracy,
                const Effects& effects, const std::optional<Perturbation>& perturbation) {
    const auto in = [&perturbation](auto entry) { return withArithmetic<T>(perturbation, entry); };
    lib.addWaveRayGeneration("MyRaygenShader", in([traceRay, accuracy](RayGenerationWave& wave) {
                                 MyRaygenShader<T>(wave, traceRay, accuracy);
                             }));
    // The sample's closest hits, as <name><suffix>, for one way of tracing their shadow rays (and one variant of the
    // inline way), written for waves (addWaveClosestHit): traced inline, their lanes' queries run in lockstep
    // (SampleClosestHit).
    const auto addClosestHits = [&](const std::string& suffix, ShadowTracing tracing, InlineVariant variant) {
        lib.addWaveClosestHit<RayPayload, BuiltInTriangleIntersectionAttributes>(
            "MyClosestHitShader_Triangle" + suffix,
            in([traceRay, accuracy, effects, tracing, variant](ClosestHitWave& wave) {
                MyClosestHitShader_Triangle<T>(wave, traceRay, accuracy, effects, tracing, variant);
            }));
        lib.addWaveClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
            "MyClosestHitShader_AABB" + suffix, in([traceRay, accuracy, effects, tracing, variant](ClosestHitWave& wave) {
                MyClosestHitShader_AABB<T>(wave, traceRay, accuracy, effects, tracing, variant);
            }));
    };
    // The sample's closest hits, and the inline-shadow variants of scenes/inline/InlineShadows.hlsl.
    addClosestHits("", ShadowTracing::TraceRay, InlineVariant::AsWritten);
    addClosestHits("_InlineShadow", ShadowTracing::Inline, InlineVariant::AsWritten);
    lib.declareRayQueries("MyClosestHitShader_Triangle_InlineShadow", {kInlineShadowQueryFlags});
    lib.declareRayQueries("MyClosestHitShader_AABB_InlineShadow", {kInlineShadowQueryFlags});
    lib.addWaveCompute("InlineAmbientOcclusionCS", uvec3(8, 8, 1), in([traceRay, accuracy](ComputeWave& wave) {
                           InlineAmbientOcclusionCS<T>(wave, traceRay, accuracy, InlineVariant::AsWritten);
                       }));
    lib.declareRayQueries("InlineAmbientOcclusionCS", {kInlinePrimaryQueryFlags, kInlineShadowQueryFlags});
    // The variants of the inline-tracing exports (InlineVariant): <export>_<variant>, for the lessons and mutants.
    for (const InlineVariant variant : kInlineVariants) {
        if (variant == InlineVariant::AsWritten) continue;
        const std::string suffix = "_InlineShadow" + inlineVariantSuffix(variant);
        addClosestHits(suffix, ShadowTracing::Inline, variant);
        lib.declareRayQueries("MyClosestHitShader_Triangle" + suffix, {inlineShadowQueryFlags(variant)});
        lib.declareRayQueries("MyClosestHitShader_AABB" + suffix, {inlineShadowQueryFlags(variant)});
        const std::string cs = "InlineAmbientOcclusionCS" + inlineVariantSuffix(variant);
        lib.addWaveCompute(cs, uvec3(8, 8, 1), in([traceRay, accuracy, variant](ComputeWave& wave) {
                               InlineAmbientOcclusionCS<T>(wave, traceRay, accuracy, variant);
                           }));
        lib.declareRayQueries(cs, {kInlinePrimaryQueryFlags, inlineShadowQueryFlags(variant)});
    }
    lib.addMiss<RayPayload>("MyMissShader", MyMissShader);
    lib.addMiss<ShadowRayPayload>("MyMissShader_ShadowRay", MyMissShader_ShadowRay);
    // Each intersection shader's ReportHit is its last action, as in the HLSL: ReportHitEnd::Return spares the unwind
    // when a shadow ray's hit ends the search (docs/emulator.md, "Ending an intersection shader"). The analytic and
    // volumetric ones take up to 16 lanes a call, over 16 float lanes beyond 8 (the metaballs' latency-bound march,
    // as inline tracing's kPrimitiveCalls).
    lib.addWaveIntersection<ProceduralPrimitiveAttributes>("MyIntersectionShader_AnalyticPrimitive", kWideLanes,
        in([accuracy](IntersectionWave& wave) {
            withLaneType<T, kWideLanes>(wave, [&]<class L>() {
                IntersectionShaderOf<T, L>(wave, IntersectionShader::AnalyticPrimitive, accuracy);
            });
        }),
        ReportHitEnd::Return);
    lib.addWaveIntersection<ProceduralPrimitiveAttributes>("MyIntersectionShader_VolumetricPrimitive", kWideLanes,
        in([accuracy](IntersectionWave& wave) {
            withLaneType<T, kWideLanes>(wave, [&]<class L>() {
                IntersectionShaderOf<T, L>(wave, IntersectionShader::VolumetricPrimitive, accuracy);
            });
        }),
        ReportHitEnd::Return);
    // The sphere tracing takes a whole wave's lanes a call, refilling its WaveLanes from a queue (SignedDistanceQueue).
    lib.addWaveIntersection<ProceduralPrimitiveAttributes>("MyIntersectionShader_SignedDistancePrimitive", kMaxWaveWidth,
        in([accuracy](IntersectionWave& wave) {
            withLaneType<T>(wave, [&]<class L>() {
                IntersectionShaderOf<T, L>(wave, IntersectionShader::SignedDistancePrimitive, accuracy);
            });
        }),
        ReportHitEnd::Return);
}

}  // namespace

std::vector<std::string> inlineVariantSuffixes() {
    std::vector<std::string> out;
    for (const InlineVariant v : kInlineVariants)
        if (v != InlineVariant::AsWritten) out.push_back(inlineVariantSuffix(v));
    return out;
}

std::shared_ptr<ShaderLibrary> makeD3D12ShaderLibrary(Precision precision, const TraceRayArgumentSet& traceRay,
                                                      const Accuracy& accuracy, const Effects& effects,
                                                      const std::optional<Perturbation>& perturbation) {
    auto lib = std::make_shared<ShaderLibrary>();
    forScalarType(precision, perturbation,
                  [&]<typename T>() { addExports<T>(*lib, traceRay, accuracy, effects, perturbation); });
    return lib;
}

}  // namespace refray::procedural::d3d12
