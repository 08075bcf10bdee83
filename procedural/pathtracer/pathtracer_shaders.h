// refray's own DXR path tracer (not a port): one shader library over a scene of OBJ models in global buffers
// (the layout of scenes/model_buffers.h), written the way its HLSL would be written.
//
// The estimator (procedural/pathtracer/pt_math.h has the math): PT_RayGen runs samplesPerPixel independent paths
// per pixel and writes the running mean to g_output after each one. A path is iterative, at most maxBounces
// scattering events long:
//   1. trace a radiance ray; on a miss add throughput * backgroundColor (PT_Miss's radiance) and stop;
//   2. at the hit, add its emission (front side only: the side cross(v1 - v0, v2 - v0) faces) times throughput,
//      weighted by the power heuristic against light sampling (weight 1 on the camera ray);
//   3. stop after maxBounces scattering events; otherwise next-event estimation: one light triangle of g_lights
//      chosen uniformly, a point on it uniform by area, a shadow ray, the contribution weighted by the power
//      heuristic against the BSDF's pdf;
//   4. sample the BSDF (Lambert + normalized Phong) for the next direction, multiply the throughput by f cos / pdf;
//   5. once the path has bounced three times, Russian roulette (survival min(max throughput, 0.95)).
// Surfaces reflect on both sides (the normals are turned to face the incoming ray); geometry is opaque. Directions
// below the geometric surface are absorbed even where the shading normal (interpolated, normal-mapped) would accept
// them, in both strategies alike: unbiased for the BSDF so restricted, which reflects a little less than its albedo
// where shading and geometric normals differ. The output is float RGBA radiance, alpha 1: no tone mapping.
//
// Resources (the HLSL declarations, global root signature "PathTracerGlobal"):
//   [0] table {u0}                RWTexture2D<float4> g_output
//   [1] root SRV t0               RaytracingAccelerationStructure g_scene
//   [2] root CBV b0               ConstantBuffer<PathTracerConstants> g_constants
//   [3] table {t0 space1          StructuredBuffer<VertexGPU> g_vertices
//              t0 space2          StructuredBuffer<uint> g_indices
//              t0 space3          StructuredBuffer<MaterialGPU> g_materials
//              t1 space3          StructuredBuffer<uint> g_triangleMaterials
//              t0 space4          StructuredBuffer<ObjectGPU> g_objects
//              t0 space7}         StructuredBuffer<LightTriangleGPU> g_lights
//   [4] table {t0 space5, unbounded}  Texture2D g_diffuseTextures[]
//   [5] table {t0 space6, unbounded}  Texture2D g_normalTextures[]
//   static sampler s0 space0      SamplerState g_sampler: anisotropic, wrap
// Ray types: Radiance (0) and Shadow (1). TraceRay(RayContributionToHitGroupIndex = ray type,
// MultiplierForGeometryContributionToHitGroupIndex = 2, MissShaderIndex = ray type), so a shader table holds
// [PT_HitGroup, PT_ShadowHitGroup] per geometry and the miss table [PT_Miss, PT_ShadowMiss].
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "core/math.h"
#include "emulator/root_signature.h"
#include "emulator/state_object.h"
#include "emulator/types.h"
#include "procedural/sample_layout.h"

namespace refray::procedural::pathtracer {

using procedural::Float4x4;

// ---- Shader-visible structs (HLSL layout) ----------------------------------------------------------------------
// The structured-buffer elements as the HLSL declares them. They mirror scenes/model_buffers.h (the host's
// VertexGPU, MaterialGPU and ObjectGPU), which static_asserts that the two agree byte for byte.

// struct VertexGPU { float3 position; float u; float3 normal; float v; float4 tangent; };       48 bytes
struct VertexGPU {
    vec3 position;  //  0 (object space)
    float u;        // 12
    vec3 normal;    // 16
    float v;        // 28
    vec4 tangent;   // 32: xyz along +u, w = handedness (+v = w * cross(normal, tangent)); 0 when the model has none
};
static_assert(sizeof(VertexGPU) == 48 && std::is_trivially_copyable_v<VertexGPU>);

// struct MaterialGPU { float4 albedo; float4 emission; float4 specularRoughness; int diffuseTextureIndex;
//                      int normalTextureIndex; uint type; float shininess; };                                64 bytes
struct MaterialGPU {
    vec4 albedo;                  //  0: Kd
    vec4 emission;                // 16: Ke (radiance)
    vec4 specularRoughness;       // 32: Ks, w = roughness (unused here: the Phong lobe takes shininess)
    int32_t diffuseTextureIndex;  // 48: into g_diffuseTextures, -1 for none
    int32_t normalTextureIndex;   // 52: into g_normalTextures, -1 for none
    uint32_t type;                // 56: 0 diffuse, 1 glossy, 2 emissive (informative; shading reads the colours)
    float shininess;              // 60: Ns, the Phong exponent
};
static_assert(sizeof(MaterialGPU) == 64 && std::is_trivially_copyable_v<MaterialGPU>);

// struct ObjectGPU { uint vertexOffset, indexOffset, materialOffset, triangleOffset, vertexCount, indexCount,
//                    materialCount, modelIndex; };                                                       32 bytes
struct ObjectGPU {
    uint32_t vertexOffset;
    uint32_t indexOffset;
    uint32_t materialOffset;
    uint32_t triangleOffset;
    uint32_t vertexCount;
    uint32_t indexCount;
    uint32_t materialCount;
    uint32_t modelIndex;
};
static_assert(sizeof(ObjectGPU) == 32 && std::is_trivially_copyable_v<ObjectGPU>);

// struct LightTriangleGPU { float4 v0, v1, v2; float4 emission; };                                   64 bytes
// One emissive triangle in world space (its object's instance transform applied, vertex order kept, so it emits
// towards cross(v1 - v0, v2 - v0)); the host lists every triangle whose material has a nonzero emission and a
// nonzero area. Next-event estimation picks one uniformly (probability 1 / lightCount).
struct LightTriangleGPU {
    vec4 v0;        //  0: xyz world position, w = 0
    vec4 v1;        // 16
    vec4 v2;        // 32
    vec4 emission;  // 48: rgb emitted radiance (Ke), w = world-space area (triangleArea of v0, v1, v2)
};
static_assert(sizeof(LightTriangleGPU) == 64 && std::is_trivially_copyable_v<LightTriangleGPU>);
static_assert(offsetof(LightTriangleGPU, v0) == 0 && offsetof(LightTriangleGPU, v1) == 16 &&
              offsetof(LightTriangleGPU, v2) == 32 && offsetof(LightTriangleGPU, emission) == 48);

// What PT_RayGen writes instead of the path-traced radiance (no lighting, pixel centres, first hit only); a miss
// writes backgroundColor in every mode.
enum DebugMode : uint32_t {
    kDebugNone = 0,             // path tracing
    kDebugAlbedo = 1,           // Kd times the diffuse texture
    kDebugEmission = 2,         // Ke
    kDebugShadingNormal = 3,    // world shading normal (after the normal map) * 0.5 + 0.5, as interpolated
    kDebugGeometricNormal = 4,  // world normalize(cross(v1 - v0, v2 - v0)) * 0.5 + 0.5
    kDebugInstanceID = 5,       // (InstanceID(), PrimitiveIndex(), material index) as floats
};

// cbuffer PathTracerConstants : register(b0), 128 bytes (HLSL packing: every row 16 bytes):
//   offset   0  float4x4 projectionToWorld   row-vector form (HLSL /Zpr), as SceneConstantBuffer of the other
//                                            libraries: GenerateCameraRay unprojects (x, y, 0, 1) with it
//   offset  64  float4   cameraPosition      w unused
//   offset  80  float4   backgroundColor     the radiance of rays that miss (PT_Miss); w unused
//   offset  96  uint     samplesPerPixel     paths per pixel in this dispatch
//   offset 100  uint     maxBounces          scattering events per path (0: emission seen by the camera only)
//   offset 104  uint     seed                keys the random streams (pt_math.h makePathRng)
//   offset 108  uint     lightCount          elements of g_lights
//   offset 112  uint     debugMode           DebugMode; 0 for path tracing
//   offset 116  uint3    padding
struct PathTracerConstants {
    Float4x4 projectionToWorld;
    vec4 cameraPosition;
    vec4 backgroundColor;
    uint32_t samplesPerPixel;
    uint32_t maxBounces;
    uint32_t seed;
    uint32_t lightCount;
    uint32_t debugMode;
    uint32_t padding[3];
};
static_assert(sizeof(PathTracerConstants) == 128 && std::is_trivially_copyable_v<PathTracerConstants>);
static_assert(offsetof(PathTracerConstants, projectionToWorld) == 0 &&
              offsetof(PathTracerConstants, cameraPosition) == 64 &&
              offsetof(PathTracerConstants, backgroundColor) == 80 &&
              offsetof(PathTracerConstants, samplesPerPixel) == 96 &&
              offsetof(PathTracerConstants, maxBounces) == 100 &&
              offsetof(PathTracerConstants, seed) == 104 && offsetof(PathTracerConstants, lightCount) == 108 &&
              offsetof(PathTracerConstants, debugMode) == 112);

// The radiance ray's payload: what the closest hit found, for PT_RayGen to shade (96 bytes).
struct RadiancePayload {
    vec3 position;         // world space, from the barycentrics of the world-space triangle
    float hitT;            // RayTCurrent(); negative: the ray missed and `emission` holds the background radiance
    vec3 shadingNormal;    // world, unit: interpolated vertex normal, normal-mapped; not yet turned to the ray
    uint32_t instanceID;   // InstanceID(): the object
    vec3 geometricNormal;  // world, unit, along cross(v1 - v0, v2 - v0): the emitting side
    float area;            // world-space area of the triangle (for the light pdf of an emitter the path hits)
    vec3 albedo;           // Kd times the diffuse texture
    float shininess;       // Ns
    vec3 specular;         // Ks
    uint32_t primitiveIndex;
    vec3 emission;         // Ke (or the background on a miss)
    uint32_t materialIndex;
};
static_assert(sizeof(RadiancePayload) == 96 && std::is_trivially_copyable_v<RadiancePayload>);

// The shadow ray's payload: PT_ShadowMiss sets `visible`; a hit (no shader runs) leaves it 0.
struct ShadowPayload {
    uint32_t visible;
};
static_assert(sizeof(ShadowPayload) == 4);

using Attributes = dxr::BuiltInTriangleIntersectionAttributes;

// ---- Ray types and TraceRay arguments ------------------------------------------------------------------------

namespace RayType {
enum Enum : uint32_t { Radiance = 0, Shadow = 1, Count = 2 };
}
// MultiplierForGeometryContributionToHitGroupIndex: one record per ray type per geometry.
inline constexpr uint32_t kGeometryStride = RayType::Count;
inline constexpr uint32_t kShadowRayFlags =
    dxr::RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | dxr::RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
inline constexpr uint32_t kRadianceRayFlags = dxr::RAY_FLAG_NONE;
// Radiance rays end here (scene units); shadow rays end at the light sample.
inline constexpr float kRadianceTMax = 1.0e30f;

// ---- Root signature, hit groups, pipeline ---------------------------------------------------------------------

enum GlobalRootParameter : uint32_t {
    kOutputTable = 0,            // table {UAV u0}: g_output
    kAccelerationStructure = 1,  // root SRV t0: g_scene
    kConstants = 2,              // root CBV b0: g_constants
    kSceneBuffers = 3,           // table: the six structured buffers below, in this order
    kDiffuseTextures = 4,        // table {SRV t0 space5, unbounded}
    kNormalTextures = 5,         // table {SRV t0 space6, unbounded}
};
// Descriptor offsets inside the kSceneBuffers table.
enum SceneBufferDescriptor : uint32_t {
    kVerticesDescriptor = 0,           // t0 space1
    kIndicesDescriptor = 1,            // t0 space2
    kMaterialsDescriptor = 2,          // t0 space3
    kTriangleMaterialsDescriptor = 3,  // t1 space3
    kObjectsDescriptor = 4,            // t0 space4
    kLightsDescriptor = 5,             // t0 space7
    kSceneBufferDescriptorCount = 6,
};

// "PathTracerGlobal": the six parameters above and the static sampler s0 (FILTER_ANISOTROPIC, 16x, wrap).
dxr::RootSignatureDesc globalRootSignatureDesc();

// PT_HitGroup {closest hit PT_ClosestHit} and PT_ShadowHitGroup {no shaders}, both triangles.
std::vector<dxr::HitGroupDesc> pathTracerHitGroups();

inline constexpr uint32_t kMaxPayloadSizeInBytes = sizeof(RadiancePayload);
inline constexpr uint32_t kMaxAttributeSizeInBytes = sizeof(Attributes);
inline constexpr uint32_t kMaxTraceRecursionDepth = 2;
dxr::ShaderConfig pathTracerShaderConfig();
dxr::PipelineConfig pathTracerPipelineConfig();

// Exports PT_RayGen, PT_ClosestHit, PT_Miss and PT_ShadowMiss (float precision).
std::shared_ptr<dxr::ShaderLibrary> makePathTracerShaderLibrary();

// ---- Helpers of the entry points, exposed for tests -------------------------------------------------------------

// GenerateCameraRay with the pixel position index + jitter (jitter (0.5, 0.5) is the pixel centre, as the other
// libraries' GenerateCameraRay): origin = cameraPosition, direction unit.
void generateCameraRay(uvec2 index, uvec2 dimensions, vec2 jitter, const PathTracerConstants& constants, vec3& origin,
                       vec3& direction);

}  // namespace refray::procedural::pathtracer
