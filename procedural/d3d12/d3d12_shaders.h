// Ports: Microsoft D3D12RaytracingProceduralGeometry Raytracing.hlsl (every entry point), the shading helpers of
// RaytracingShaderHelper.hlsli (camera ray, ray differentials, Fresnel, index loads) and CheckersTextureBoxFilter of
// SignedDistancePrimitives.hlsli, plus the shared structs of RayTracingHlslCompat.h and RaytracingSceneDefines.h.
// Facts: docs/reference-scene-d3d12-procedural.md (§1.4-1.9, §2, §4).
//
// The sample's shader library: one ray generation shader, two miss shaders, the ground plane's closest hit (Phong,
// shadow, Fresnel reflection, box-filtered analytic grid from ray differentials, fog), the AABB closest hit, and the
// three intersection shaders (analytic box and spheres, animated metaballs, seven sphere-traced SDFs). The pure math
// lives in procedural/math/; the entry points here transform the ray, call it, shade and TraceRay as the HLSL does.
//
// Precision (issue 3): the shader-internal math (local ray, analytic / volumetric / SDF intersections, normals, grid
// filter, lighting, fog) runs in T = float or double. The structs below are the GPU interface and stay float; values
// are rounded to float where they cross it (ReportHit's t, attributes, payload colour, RayDesc, the render target).
// HLSL literals are float, so double mode uses their float values. Float mode flushes denormals; double does not.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/math.h"
#include "emulator/root_signature.h"
#include "emulator/state_object.h"
#include "procedural/accuracy.h"
#include "procedural/effects.h"
#include "procedural/math/fractals.h"
#include "procedural/math/metaballs.h"
#include "procedural/perturbation.h"
#include "procedural/precision.h"
#include "procedural/sample_layout.h"
#include "procedural/trace_ray_parameters.h"

namespace refray::procedural::d3d12 {

// ---- Shader-visible structs (RayTracingHlslCompat.h) -------------------------------------------------

// Shared with the other reference scene's port (procedural/sample_layout.h).
using procedural::Float4x4;
using procedural::FresnelReflectanceSchlick;
using procedural::GenerateCameraRay;
using procedural::Load3x16BitIndices;
using procedural::mul;

struct RayPayload {
    vec4 color;
    uint32_t recursionDepth;
};
static_assert(sizeof(RayPayload) == 20);

// PORT: the C++ header declares `bool hit` (1 byte); the HLSL bool is 32 bits, which is what this mirrors (I11).
struct ShadowRayPayload {
    uint32_t hit;
};
static_assert(sizeof(ShadowRayPayload) == 4);

// A world-space normal; HitKind is always 0.
struct ProceduralPrimitiveAttributes {
    vec3 normal;
};
static_assert(sizeof(ProceduralPrimitiveAttributes) == 12);

// The root CBV b0. The HLSL cbuffer uses 136 bytes; the C++ struct (XMMATRIX-aligned) is 144.
struct SceneConstantBuffer {
    Float4x4 projectionToWorld;
    vec4 cameraPosition;
    vec4 lightPosition;
    vec4 lightAmbientColor;
    vec4 lightDiffuseColor;
    float reflectance;  // never written or read (I10)
    float elapsedTime;  // the geometry time T
    vec2 padding;
};
static_assert(sizeof(SceneConstantBuffer) == 144);

// The material: 12 root constants at b1 (§1.4).
using procedural::PrimitiveConstantBuffer;  // procedural/sample_layout.h

// Per AABB primitive: 2 root constants at b2. instanceIndex is the primitive index i of §1.3 (it indexes
// g_AABBPrimitiveAttributes); primitiveType is the enum of the hit group's intersection shader.
using procedural::PrimitiveInstanceConstantBuffer;  // procedural/sample_layout.h

// One element of StructuredBuffer<PrimitiveInstancePerFrameBuffer> (root SRV t3): S·R·Tr and its inverse.
struct PrimitiveInstancePerFrameBuffer {
    Float4x4 localSpaceToBottomLevelAS;
    Float4x4 bottomLevelASToLocalSpace;
};
static_assert(sizeof(PrimitiveInstancePerFrameBuffer) == 128);

using procedural::Vertex;  // procedural/sample_layout.h

// LocalRootSignature::{Triangle, AABB}::RootArguments: the record bytes after the identifier.
struct TriangleRootArguments {
    PrimitiveConstantBuffer materialCb;
};
static_assert(sizeof(TriangleRootArguments) == 48);
struct AABBRootArguments {
    PrimitiveConstantBuffer materialCb;
    PrimitiveInstanceConstantBuffer aabbCB;
};
static_assert(sizeof(AABBRootArguments) == 56);

// ---- Constants (RayTracingHlslCompat.h) -----------------------------------------------------------------

inline constexpr uint32_t MAX_RAY_RECURSION_DEPTH = 3;
inline constexpr uint32_t N_FRACTAL_ITERATIONS = uint32_t(math::d3d12::N_FRACTAL_ITERATIONS);
inline constexpr vec4 ChromiumReflectance{0.549f, 0.556f, 0.554f, 1.0f};
inline constexpr vec4 BackgroundColor{0.8f, 0.9f, 1.0f, 1.0f};
inline constexpr float InShadowRadiance = 0.35f;

// The pipeline's shader config (§1.9): max(sizeof RayPayload, C++ sizeof(bool)) and the attribute struct.
inline constexpr uint32_t kMaxPayloadSizeInBytes = 20;
inline constexpr uint32_t kMaxAttributeSizeInBytes = 12;

namespace RayType {
enum Enum : uint32_t { Radiance = 0, Shadow = 1, Count = 2 };
}

// TraceRayParameters: InstanceMask ~0; hit-group offset = ray type, geometry stride = ray type count;
// miss offset = ray type.
namespace TraceRayParameters {
inline constexpr uint32_t InstanceMask = ~0u;
inline constexpr uint32_t GeometryStride = RayType::Count;
}  // namespace TraceRayParameters

static_assert(RayType::Count == kTraceRayTypeCount);
// What TraceRadianceRay and TraceShadowRayAndReportIfHit pass to TraceRay in the HLSL, per ray type.
constexpr TraceRayArgumentSet defaultTraceRayArguments() {
    TraceRayArgumentSet traceRay;
    traceRay[RayType::Radiance] = {RayType::Radiance, TraceRayParameters::GeometryStride, RayType::Radiance,
                                   TraceRayParameters::InstanceMask};
    traceRay[RayType::Shadow] = {RayType::Shadow, TraceRayParameters::GeometryStride, RayType::Shadow,
                                 TraceRayParameters::InstanceMask};
    return traceRay;
}
// The RAY_FLAGs TraceRadianceRay and TraceShadowRayAndReportIfHit pass, per ray type (§1.7).
inline constexpr std::array<uint32_t, RayType::Count> kTraceRayFlags = {
    dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
    dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES | dxr::RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH |
        dxr::RAY_FLAG_FORCE_OPAQUE | dxr::RAY_FLAG_SKIP_CLOSEST_HIT_SHADER};

// primitiveType per intersection shader.
namespace AnalyticPrimitive {
enum Enum : uint32_t { AABB = 0, Spheres = 1, Count = 2 };
}
namespace VolumetricPrimitive {
enum Enum : uint32_t { Metaballs = 0, Count = 1 };
}
using SignedDistancePrimitive = math::d3d12::SignedDistancePrimitive;  // MiniSpheres (0) ... FractalPyramid (6)

// ---- Root signatures (RaytracingSceneDefines.h, §1.9) -------------------------------------------------

// GlobalRootSignature::Slot.
enum GlobalRootParameter : uint32_t {
    kOutputView = 0,             // table {UAV u0}: RWTexture2D<float4> g_renderTarget
    kAccelerationStructure = 1,  // root SRV t0: g_scene
    kSceneConstant = 2,          // root CBV b0: g_sceneCB
    kAABBattributeBuffer = 3,    // root SRV t3: g_AABBPrimitiveAttributes (10 elements)
    kVertexBuffers = 4,          // table {SRV t1, t2}: g_indices (raw), g_vertices (structured)
};
// LocalRootSignature::Triangle::Slot and LocalRootSignature::AABB::Slot.
enum LocalRootParameter : uint32_t {
    kMaterialConstant = 0,  // 12 constants at b1: l_materialCB
    kGeometryIndex = 1,     // 2 constants at b2: l_aabbCB (AABB only)
};

dxr::RootSignatureDesc globalRootSignatureDesc();         // named "GlobalRootSignature"
dxr::RootSignatureDesc triangleLocalRootSignatureDesc();  // named "Triangle"
dxr::RootSignatureDesc aabbLocalRootSignatureDesc();      // named "AABB"

// ---- Hit groups (APP CreateHitGroupSubobjects, §1.8) -------------------------------------------------

// MyHitGroup_Triangle[_ShadowRay], then MyHitGroup_AABB_{Analytic,Volumetric,SignedDistance}Primitive[_ShadowRay].
// Shadow groups have no closest hit; no group has an any-hit shader.
std::vector<dxr::HitGroupDesc> d3d12HitGroups();
// The hit groups that take the "Triangle" local root signature, and those that take "AABB".
std::vector<std::string> triangleHitGroupNames();
std::vector<std::string> aabbHitGroupNames();
// The suffixes of the inline-tracing exports' variants (InlineVariant in d3d12_shaders.cpp: "_IgnoreProcedural",
// ...): MyClosestHitShader_{Triangle,AABB}_InlineShadow<suffix> and InlineAmbientOcclusionCS<suffix> are exports of
// the library, for the RayQuery lessons and discrimination mutants.
std::vector<std::string> inlineVariantSuffixes();

// ---- The shader library -------------------------------------------------------------------------------

// Exports, with their HLSL names: MyRaygenShader, MyClosestHitShader_Triangle, MyClosestHitShader_AABB, MyMissShader,
// MyMissShader_ShadowRay, MyIntersectionShader_AnalyticPrimitive, MyIntersectionShader_VolumetricPrimitive,
// MyIntersectionShader_SignedDistancePrimitive.
// PORT: `precision` selects the scalar type of the shader-internal math (Precision::Double is not the GPU's).
// PORT: `traceRay` holds the TraceRay arguments the HLSL compiles in as constants, per ray type; the default is the
// HLSL's. Other values reproduce the shaders compiled with other constants (IDX-1, IDX-7).
// PORT: `accuracy` replaces the HLSL's march constants (procedural/accuracy.h); the default is the HLSL's.
// PORT: `effects` switches call sites off (procedural/effects.h): with traceShadowRays false, both closest hits take
// every point as lit without tracing; the default is the HLSL's.
// PORT: `perturbation` (float only) runs the math in PerturbedFloat: the GPU that seed picks from the variation
// model (procedural/math/perturbed.h, docs/numerical-variation.md); unset: float or double as `precision` says.
std::shared_ptr<dxr::ShaderLibrary> makeD3D12ShaderLibrary(
    Precision precision = Precision::Float, const TraceRayArgumentSet& traceRay = defaultTraceRayArguments(),
    const Accuracy& accuracy = {}, const Effects& effects = {},
    const std::optional<Perturbation>& perturbation = std::nullopt);

// ---- The ground plane's index and vertex buffers (§1.2) ----------------------------------------------
// What the app uploads as g_indices (6 16-bit indices, a raw view) and g_vertices (4 vertices, stride 24), which
// MyClosestHitShader_Triangle reads through the descriptor table of global parameter 4.
extern const std::array<uint16_t, 6> kPlaneIndices;
extern const std::array<Vertex, 4> kPlaneVertices;

// ---- Pure helpers of the entry points, exposed for tests ---------------------------------------------
// PORT: intrinsics these helpers read in HLSL (DispatchRaysIndex/Dimensions, WorldRayDirection) are parameters.

// The helpers below are templates on the scalar type, defined and instantiated (float, double) in the .cpp.

// CheckersTextureBoxFilter: the grid of lines 1/ratio wide at every integer u and v, box-filtered over
// w = max(|dpdx|, |dpdy|); 1 on the white cells, 0 on a line (§2.9 step 3).
template <typename T>
T CheckersTextureBoxFilter(glm::vec<2, T> uv, glm::vec<2, T> dpdx, glm::vec<2, T> dpdy, uint32_t ratio);

// CalculateRayDifferentials: the primary camera rays of pixels index + (1,0) and index + (0,1) intersected with the
// plane through hitPosition with normal surfaceNormal; the footprint in uv = position.xz (I7).
template <typename T>
void CalculateRayDifferentials(glm::vec<2, T>& ddx_uv, glm::vec<2, T>& ddy_uv, glm::vec<2, T> uv,
                               glm::vec<3, T> hitPosition, glm::vec<3, T> surfaceNormal, glm::vec<3, T> cameraPosition,
                               const Float4x4& projectionToWorld, uvec2 dispatchRaysIndex,
                               uvec2 dispatchRaysDimensions);

// AnalyticalCheckersTexture: CheckersTextureBoxFilter(hitPosition.xz, footprint, 50).
template <typename T>
T AnalyticalCheckersTexture(glm::vec<3, T> hitPosition, glm::vec<3, T> surfaceNormal, glm::vec<3, T> cameraPosition,
                            const Float4x4& projectionToWorld, uvec2 dispatchRaysIndex, uvec2 dispatchRaysDimensions);

// CalculatePhongLighting: ambient (darkened towards -y) + diffuse (scaled by InShadowRadiance in shadow) + white
// specular (only when not in shadow, not gated by N·L: I8) for the point light of g_sceneCB (§2.11). isInShadow is
// a bool for a scalar T, a lane mask for lanes (one closest hit per lane: procedural/math/lanes.h).
template <typename T>
glm::vec<4, T> CalculatePhongLighting(const SceneConstantBuffer& sceneCB, glm::vec<4, T> albedo, glm::vec<3, T> normal,
                                      math::LaneMask<T> isInShadow, T diffuseCoef, T specularCoef, T specularPower,
                                      glm::vec<3, T> hitPosition, glm::vec<3, T> worldRayDirection);

// The "visibility falloff" of both closest hits: lerp(color, BackgroundColor, 1 - exp(-0.000002·t³)).
template <typename T>
glm::vec<4, T> ApplyVisibilityFalloff(glm::vec<4, T> color, T t);

// ---- The accuracy knobs as the entry points pass them (procedural/accuracy.h) ------------------------
// PORT: each value is a constant of the HLSL; Accuracy{} gives exactly those constants, so every march is the
// HLSL's bit for bit. Factors multiply in T (scaledConstant), step counts round with scaledSteps.

// The SDF intersection shader's sphere tracing with the knobs (one conversion for both libraries: math/sdf.h).
using math::sphereTraceParams;

// MyIntersectionShader_VolumetricPrimitive's march: metaballSteps (128) samples, central-difference step
// 0.5773e-5 x normalEpsilonFactor.
template <typename T>
math::MetaballsParams<T> metaballsParams(const Accuracy& accuracy);

// MAX_RAY_RECURSION_DEPTH as the shaders use it: maxRecursionDepth, or the HLSL's 3.
uint32_t maxRayRecursionDepth(const Accuracy& accuracy);

}  // namespace refray::procedural::d3d12
