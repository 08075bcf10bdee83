// Ports: Proceduray (dsilvavinicius/Proceduray) Raytracing.hlsl, Helpers.hlsli, Triangles.hlsli, Pacman.hlsli,
// JuliaSets.hlsli, Mandelbulb.hlsli entry points, and the structs of engine/{Payloads,AttribStructs,RootComponents,
// RootArguments,ShaderCompat}.h. Facts: docs reference-scene-proceduray.md (§1.3-1.8, §3, §4, §5).
//
// The "MandelJuliaPac" shader library: ray generation, two miss shaders, the slab's closest hit and the
// intersection / closest-hit pairs of the Julia set, the Pac-man and the Mandelbulb. The pure math lives in
// procedural/math/; the entry points here transform the ray, call it, shade and TraceRay exactly as the HLSL
// does, including its t-space bug (H1: intersection shaders report t in normalised local units).
//
// Precision (issue 3): the shader-internal math (local ray, marches, distance estimators, normals, lighting)
// runs in T = float or double. The structs below are the GPU interface and stay float; values are rounded to
// float where they cross it (ReportHit's t, attributes, payload colour, RayDesc, the render target). HLSL
// literals are float, so double mode uses their float values. Float mode flushes denormals (H18); double does not.
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
#include "procedural/perturbation.h"
#include "procedural/precision.h"
#include "procedural/sample_layout.h"
#include "procedural/trace_ray_parameters.h"

namespace refray::procedural::proceduray {

// ---- Shader-visible structs (HLSL layout; the C++ side of the shared headers) ---------------------

// Shared with the other reference scene's port (procedural/sample_layout.h).
using procedural::Float4x4;
using procedural::FresnelReflectanceSchlick;
using procedural::GenerateCameraRay;
using procedural::Load3x16BitIndices;
using procedural::mul;

// engine/Payloads.h. `hit` is an HLSL bool, i.e. a 32-bit value.
struct RayPayload {
    vec4 color;
    uint32_t recursionDepth;
    float dist;
    int32_t count;
    uint32_t hit;
};
static_assert(sizeof(RayPayload) == 32);

struct ShadowRayPayload {
    float dist;
    uint32_t hit;
};
static_assert(sizeof(ShadowRayPayload) == 8);

// engine/AttribStructs.h: 28 bytes, under the 32-byte attribute limit.
struct ProceduralPrimitiveAttributes {
    vec3 normal;
    vec4 color;
};
static_assert(sizeof(ProceduralPrimitiveAttributes) == 28);

// engine/RootComponents.h: the material (12 root constants at b1).
using procedural::PrimitiveConstantBuffer;  // procedural/sample_layout.h

// Per procedural instance (2 root constants at b2). instanceIndex is the procedural ordinal (0..3), not
// InstanceIndex(); primitiveType is a SignedDistancePrimitive.
using procedural::PrimitiveInstanceConstantBuffer;  // procedural/sample_layout.h

// engine/RootArguments.h: the record bytes after the identifier.
struct TriangleRootArguments {
    PrimitiveConstantBuffer materialCb;
};
static_assert(sizeof(TriangleRootArguments) == 48);
struct ProceduralRootArguments {
    PrimitiveConstantBuffer materialCb;
    PrimitiveInstanceConstantBuffer aabbCB;
};
static_assert(sizeof(ProceduralRootArguments) == 56);

// The root CBV b0. The HLSL cbuffer uses 140 bytes; the C++ struct (XMMATRIX-aligned) is 144.
struct SceneConstantBuffer {
    Float4x4 projectionToWorld;
    vec4 cameraPosition;
    vec4 lightPosition;
    vec4 lightAmbientColor;
    vec4 lightDiffuseColor;
    float reflectance;  // never written or read (§1.7)
    float elapsedTime;
    int32_t debugFlag;
    uint32_t padding;
};
static_assert(sizeof(SceneConstantBuffer) == 144);

// One element of StructuredBuffer<InstanceBuffer> (root SRV t3), indexed by l_aabbCB.instanceIndex.
// Despite the name, localSpaceToBottomLevelAS holds world -> object, i.e. inverse(M) (§1.7, §5.3).
struct InstanceBuffer {
    Float4x4 localSpaceToBottomLevelAS;
    Float4x4 bottomLevelASToLocalSpace;
};
static_assert(sizeof(InstanceBuffer) == 128);

// engine/ShaderCompat.h: the slab's vertex (StructuredBuffer<Vertex>, 24-byte stride).
using procedural::Vertex;  // procedural/sample_layout.h

// ---- Constants of engine/ShaderCompat.h ------------------------------------------------------------

inline constexpr uint32_t MAX_RAY_RECURSION_DEPTH = 3;
enum RayType : uint32_t { Radiance = 0, Shadow = 1, RayTypeCount = 2 };
// TraceRayParameters: InstanceMask = ~0 (only the low 8 bits count), hit-group offset = ray type,
// geometry stride = ray type count, miss offset = ray type.
inline constexpr uint32_t kInstanceMask = ~0u;
static_assert(RayTypeCount == kTraceRayTypeCount);
// What TraceRadianceRay and TraceShadowRayAndReportIfHit pass to TraceRay in the HLSL, per ray type.
constexpr TraceRayArgumentSet defaultTraceRayArguments() {
    TraceRayArgumentSet traceRay;
    traceRay[Radiance] = {Radiance, RayTypeCount, Radiance, kInstanceMask};
    traceRay[Shadow] = {Shadow, RayTypeCount, Shadow, kInstanceMask};
    return traceRay;
}
// The RAY_FLAGs TraceRadianceRay and TraceShadowRayAndReportIfHit pass, per ray type (§1.4).
inline constexpr std::array<uint32_t, RayTypeCount> kTraceRayFlags = {
    dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
    dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES | dxr::RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH |
        dxr::RAY_FLAG_FORCE_OPAQUE | dxr::RAY_FLAG_SKIP_CLOSEST_HIT_SHADER};
inline constexpr vec4 kBackgroundColor{0.6f, 0.7f, 0.9f, 1.0f};
inline constexpr float kInShadowRadiance = 0.35f;

// The primitiveType of l_aabbCB. It equals the procedural geometry ordinal (§1.5).
enum class SignedDistancePrimitive : uint32_t { JuliaSets = 0, IntersectedRoundCube = 1, Mandelbulb = 2 };

// ---- Root signatures (§1.6) ------------------------------------------------------------------------

enum GlobalRootParameter : uint32_t {
    kOutputView = 0,             // table {UAV u0}: RWTexture2D<float4> g_renderTarget
    kAccelerationStructure = 1,  // root SRV t0: g_scene
    kSceneConstantBuffer = 2,    // root CBV b0: g_sceneCB
    kInstanceBuffer = 3,         // root SRV t3: g_instanceBuffer (4 elements)
    kVertexBuffers = 4,          // table {SRV t1, t2}: g_indices (raw), g_vertices (structured)
};
// Local "Triangle": [0] l_materialCB. Local "Procedural": [0] l_materialCB, [1] l_aabbCB.
enum LocalRootParameter : uint32_t {
    kMaterialConstantBuffer = 0,  // 12 constants at b1
    kAABBConstantBuffer = 1,      // 2 constants at b2 ("Procedural" only)
};

dxr::RootSignatureDesc globalRootSignatureDesc();
dxr::RootSignatureDesc triangleLocalRootSignatureDesc();    // named "Triangle"
dxr::RootSignatureDesc proceduralLocalRootSignatureDesc();  // named "Procedural"

// The eight hit groups of MandelJuliaPacSceneBuilder::BuildHitGroups (the table of §1.5 uses them).
std::vector<dxr::HitGroupDesc> procedurayHitGroups();

// ---- The shader library ----------------------------------------------------------------------------

// Exports, with their HLSL names: Raygen, Miss, Miss_Shadow, ClosestHit_Triangle, Intersection_Julia,
// ClosestHit_Julia, Intersection_Pacman, ClosestHit_Pacman, Intersection_Mandelbulb, ClosestHit_Mandelbulb.
// PORT: `precision` selects the scalar type of the shader-internal math (Precision::Double is not the GPU's).
// PORT: `traceRay` holds the TraceRay arguments the HLSL compiles in as constants, per ray type; the default is the
// HLSL's. Other values reproduce the shaders compiled with other constants (IDX-1, IDX-7).
// PORT: `accuracy` replaces the HLSL's march constants (procedural/accuracy.h); the default is the HLSL's.
// PORT: `effects` switches call sites off (procedural/effects.h): with traceShadowRays false, ClosestHit_Triangle and
// ClosestHit_Pacman take every point as lit without tracing; the default is the HLSL's.
// PORT: `perturbation` (float only) runs the math in PerturbedFloat: the GPU that seed picks from the variation
// model (procedural/math/perturbed.h, docs/numerical-variation.md); unset: float or double as `precision` says.
std::shared_ptr<dxr::ShaderLibrary> makeProcedurayShaderLibrary(
    Precision precision = Precision::Float, const TraceRayArgumentSet& traceRay = defaultTraceRayArguments(),
    const Accuracy& accuracy = {}, const Effects& effects = {},
    const std::optional<Perturbation>& perturbation = std::nullopt);

// ---- The slab's index and vertex buffers (§1.1) ----------------------------------------------------
// What the scene uploads as g_indices (36 16-bit indices = 18 dwords, a raw view) and g_vertices (8 vertices,
// stride 24), which ClosestHit_Triangle reads through the descriptor table of global parameter 4. Scene data for
// hosts and tests; the shaders never read these arrays.
extern const std::array<uint16_t, 36> kSlabIndices;
extern const std::array<Vertex, 8> kSlabVertices;

// ---- Pure helpers of the entry points, exposed for tests -------------------------------------------

// The helpers below are templates on the scalar type, defined and instantiated (float, double) in the .cpp.

// JuliaSets.hlsli colorSurface(pos, tn): the iteration-count palette (tn.y = n).
template <typename T>
glm::vec<3, T> colorSurface(glm::vec<3, T> pos, glm::vec<2, T> tn);

// ClosestHit_Mandelbulb's own lighting (no scene light): the colour before the reflection is added.
// D = WorldRayDirection(), N = attr.normal, trap = attr.color.
template <typename T>
glm::vec<4, T> MandelbulbSurfaceColor(glm::vec<3, T> D, glm::vec<3, T> N, glm::vec<4, T> trap);

// Helpers.hlsli CalculatePhongLighting: ambient (darkened towards -y) + diffuse (scaled by kInShadowRadiance in shadow)
// + white specular (only when not in shadow) for the point light of g_sceneCB.
// PORT: HitWorldPosition() and WorldRayDirection(), which the HLSL reads inside, are parameters.
template <typename T>
glm::vec<4, T> CalculatePhongLighting(const SceneConstantBuffer& g_sceneCB, glm::vec<4, T> albedo, glm::vec<3, T> normal,
                                      bool isInShadow, T diffuseCoef, T specularCoef, T specularPower,
                                      glm::vec<3, T> hitPosition, glm::vec<3, T> worldRayDirection);

// ---- The accuracy knobs as the entry points pass them (procedural/accuracy.h) ----------------------
// PORT: each value is a constant of the HLSL; Accuracy{} gives exactly those constants, so every march is the
// HLSL's bit for bit. Factors multiply in T (scaledConstant), step counts round with scaledSteps.

// The SDF intersection shader's sphere tracing with the knobs (one conversion for both libraries: math/sdf.h).
using math::sphereTraceParams;

// Intersection_Mandelbulb's march: threshold 1e-4 x thresholdFactor, mandelbulbIterations (4), tetrahedral offset
// 0.5773e-4 x normalEpsilonFactor.
template <typename T>
math::mandelbulb::MandelbulbParams<T> mandelbulbParams(const Accuracy& accuracy);

// The animated step count iMax (MandelbulbIterationCount) x stepsFactor; a count below 1 is left as it is (the
// march does not run either way).
int mandelbulbStepCount(int iMax, const Accuracy& accuracy);

// Intersection_Julia's raycast and normal: juliaIterations (200), 1024 x stepsFactor march steps, the stop test's
// precis 0.00025 x thresholdFactor, the normal offset 0.5773 x 0.00025 x normalEpsilonFactor.
template <typename T>
math::julia::JuliaParams<T> juliaParams(const Accuracy& accuracy);

// MAX_RAY_RECURSION_DEPTH as the shaders use it: maxRecursionDepth, or the HLSL's 3.
uint32_t maxRayRecursionDepth(const Accuracy& accuracy);

}  // namespace refray::procedural::proceduray
