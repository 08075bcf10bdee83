// Ports the shared part of refray's own DXR path tracer, the library "dxr-path-tracer": the resource declarations,
// structs, TraceRay arguments and helpers of procedural/pathtracer/pathtracer_shaders.{h,cpp}, and offsetRayOrigin
// of core/ray_offset.h. There is no HLSL original: the C++ is written the way its HLSL would be, and this file follows
// it with its names. The estimator is pathtracer_shaders.h's header comment; PORTING.md maps every piece.
//
// The including entry point defines its stage (DXR_STAGE_RAYGEN, _MISS, _CLOSEST_HIT) and enables
// GL_EXT_ray_tracing, GL_EXT_scalar_block_layout and GL_GOOGLE_include_directive (the closest hit also
// GL_EXT_nonuniform_qualifier, for the texture arrays).
//
// Bindings (gpu/shaders/CONTRACT.md; set = register space, binding = register + 0 b / 100 t / 200 u / 300 s), global
// root signature "PathTracerGlobal":
//   set 0 binding 200  u0         g_output              table [0]: RWTexture2D<float4> (rgba32f image)
//   set 0 binding 100  t0         g_scene               root SRV [1]: the TLAS
//   set 0 binding 0    b0         g_constants           root CBV [2]: PathTracerConstants, 128 bytes
//   set 1 binding 100  t0 space1  g_vertices            table [3]: StructuredBuffer<VertexGPU>, 48 bytes each
//   set 2 binding 100  t0 space2  g_indices             table [3]: StructuredBuffer<uint>
//   set 3 binding 100  t0 space3  g_materials           table [3]: StructuredBuffer<MaterialGPU>, 64 bytes each
//   set 3 binding 101  t1 space3  g_triangleMaterials   table [3]: StructuredBuffer<uint>
//   set 4 binding 100  t0 space4  g_objects             table [3]: StructuredBuffer<ObjectGPU>, 32 bytes each
//   set 7 binding 100  t0 space7  g_lights              table [3]: StructuredBuffer<LightTriangleGPU>, 64 bytes each
//   set 5 binding 100  t0 space5  g_diffuseTextures[]   table [4]: unbounded Texture2D array
//   set 6 binding 100  t0 space6  g_normalTextures[]    table [5]: unbounded Texture2D array
//   set 0 binding 300  s0         g_sampler             static sampler (anisotropic, wrap: trilinear on both sides)
// No local root arguments (the shader table's records are identifiers only).
// Payloads: location 0 RadiancePayload (96 bytes), location 1 ShadowPayload (4 bytes); incoming payloads carry no
// location. Attributes: the built-in barycentrics (hitAttributeEXT vec2).
#ifndef PATHTRACER_GLSL
#define PATHTRACER_GLSL

#include "common/d3d12_dxr_intrinsics.glsl"
#include "dxr-path-tracer/pt_math.glsl"

#define PAYLOAD_LOCATION_RADIANCE 0
#define PAYLOAD_LOCATION_SHADOW 1

// ---- Shader-visible structs (HLSL layout; pathtracer_shaders.h static_asserts the C++ twins) -------------------

struct VertexGPU {
    vec3 position;  //  0 (object space)
    float u;        // 12
    vec3 normal;    // 16
    float v;        // 28
    vec4 tangent;   // 32: xyz along +u, w = handedness; 0 when the model has none
};

struct MaterialGPU {
    vec4 albedo;               //  0: Kd
    vec4 emission;             // 16: Ke
    vec4 specularRoughness;    // 32: Ks (w unused here)
    int diffuseTextureIndex;   // 48: into g_diffuseTextures, -1 for none
    int normalTextureIndex;    // 52: into g_normalTextures, -1 for none
    uint type;                 // 56
    float shininess;           // 60: Ns
};

struct ObjectGPU {
    uint vertexOffset;
    uint indexOffset;
    uint materialOffset;
    uint triangleOffset;
    uint vertexCount;
    uint indexCount;
    uint materialCount;
    uint modelIndex;
};

struct LightTriangleGPU {
    vec4 v0;        //  0: world position, w = 0
    vec4 v1;        // 16
    vec4 v2;        // 32
    vec4 emission;  // 48: rgb radiance, w = world-space area
};

// DebugMode (pathtracer_shaders.h).
const uint kDebugNone = 0u;
const uint kDebugAlbedo = 1u;
const uint kDebugEmission = 2u;
const uint kDebugShadingNormal = 3u;
const uint kDebugGeometricNormal = 4u;
const uint kDebugInstanceID = 5u;

// The radiance ray's payload (96 bytes in the C++): what the closest hit found, for PT_RayGen to shade.
struct RadiancePayload {
    vec3 position;
    float hitT;  // negative: the ray missed and `emission` holds the background radiance
    vec3 shadingNormal;
    uint instanceID;
    vec3 geometricNormal;
    float area;
    vec3 albedo;
    float shininess;
    vec3 specular;
    uint primitiveIndex;
    vec3 emission;
    uint materialIndex;
};

struct ShadowPayload {
    uint visible;
};

// ---- Resources ---------------------------------------------------------------------------------------------

layout(set = 0, binding = 0, scalar) uniform PathTracerConstants {
    // Row-vector form (HLSL /Zpr): mul(v, M) is v * M with a row_major matrix.
    layout(offset = 0, row_major) mat4 projectionToWorld;
    layout(offset = 64) vec4 cameraPosition;
    layout(offset = 80) vec4 backgroundColor;
    layout(offset = 96) uint samplesPerPixel;
    layout(offset = 100) uint maxBounces;
    layout(offset = 104) uint seed;
    layout(offset = 108) uint lightCount;
    layout(offset = 112) uint debugMode;
} g_constants;

#if defined(DXR_STAGE_RAYGEN)
layout(set = 0, binding = 200, rgba32f) uniform image2D g_output;
layout(set = 0, binding = 100) uniform accelerationStructureEXT g_scene;
layout(set = 7, binding = 100, scalar) readonly buffer Lights { LightTriangleGPU g_lights[]; };
#endif

#if defined(DXR_STAGE_CLOSEST_HIT)
layout(set = 1, binding = 100, scalar) readonly buffer Vertices { VertexGPU g_vertices[]; };
layout(set = 2, binding = 100, scalar) readonly buffer Indices { uint g_indices[]; };
layout(set = 3, binding = 100, scalar) readonly buffer Materials { MaterialGPU g_materials[]; };
layout(set = 3, binding = 101, scalar) readonly buffer TriangleMaterials { uint g_triangleMaterials[]; };
layout(set = 4, binding = 100, scalar) readonly buffer Objects { ObjectGPU g_objects[]; };
// PORT: HLSL's `Texture2D g_diffuseTextures[] : register(t0, space5)` is one arrayed binding (as DXC maps an unbounded
// array); the host binds the heap's run of Texture2D descriptors from the range's start (gpu/vulkan_bindings.h).
layout(set = 5, binding = 100) uniform texture2D g_diffuseTextures[];
layout(set = 6, binding = 100) uniform texture2D g_normalTextures[];
// The static sampler s0: an immutable sampler of set 0's layout (gpu/vulkan_sampler.h).
layout(set = 0, binding = 300) uniform sampler g_sampler;
#endif

// ---- Ray types and TraceRay arguments -------------------------------------------------------------------------

const uint kRadianceRayFlags = RAY_FLAG_NONE;
const uint kShadowRayFlags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
const float kRadianceTMax = 1.0e30;

// PORT: TraceRay arguments are specialization constants (docs/vulkan-backend.md): ray type r's field f is
// constant_id 16 * (r + 1) + f (0 R, 1 M, 2 miss index, 3 mask). The defaults are the C++ shaders' fixed arguments
// (R = ray type, M = 2, miss = ray type, mask 0xFF); the C++ library refuses a scene that overrides them, so the host
// always gives these same values. The ray flags stay constants.
layout(constant_id = 16) const uint kTraceRayRadiance_RayContribution = 0u;
layout(constant_id = 17) const uint kTraceRayRadiance_Multiplier = 2u;
layout(constant_id = 18) const uint kTraceRayRadiance_MissShaderIndex = 0u;
layout(constant_id = 19) const uint kTraceRayRadiance_InstanceMask = 0xFFu;
layout(constant_id = 32) const uint kTraceRayShadow_RayContribution = 1u;
layout(constant_id = 33) const uint kTraceRayShadow_Multiplier = 2u;
layout(constant_id = 34) const uint kTraceRayShadow_MissShaderIndex = 1u;
layout(constant_id = 35) const uint kTraceRayShadow_InstanceMask = 0xFFu;

struct RayDesc {
    vec3 Origin;
    float TMin;
    vec3 Direction;
    float TMax;
};

// ---- Helpers -------------------------------------------------------------------------------------------------

// PORT: std::isfinite.
bool isFinite(float x) { return !(isnan(x) || isinf(x)); }

bool isZero(vec3 v) { return v.x == 0.0 && v.y == 0.0 && v.z == 0.0; }

// core/ray_offset.h: offsetRayOrigin.
#include "common/ray_offset.glsl"

#endif  // PATHTRACER_GLSL
