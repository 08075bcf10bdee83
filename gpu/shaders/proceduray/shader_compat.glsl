// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/engine/ShaderCompat.h (with the headers it
// includes: engine/Payloads.h, engine/AttribStructs.h, engine/RootComponents.h, engine/RootArguments.h) and the
// resource declarations of Raytracing.hlsl L33-47.
//
// ---- The proceduray library's GPU interface (gpu/shaders/CONTRACT.md) ---------------------------------------------
// Global root signature (register -> set 0, binding):
//   u0 g_renderTarget   binding 200  image2D rgba32f            (table {UAV u0}, global parameter 0)
//   t0 g_scene          binding 100  accelerationStructureEXT   (root SRV, parameter 1)
//   b0 g_sceneCB        binding   0  uniform, scalar, row_major (root CBV, parameter 2), 144 bytes as refray stores
//                                    SceneConstantBuffer: projectionToWorld @0 (64 B, row-major, row vectors),
//                                    cameraPosition @64, lightPosition @80, lightAmbientColor @96,
//                                    lightDiffuseColor @112, reflectance @128, elapsedTime @132, debugFlag @136
//   t3 g_instanceBuffer binding 103  readonly buffer, scalar, row_major: InstanceBuffer[4], stride 128
//                                    (localSpaceToBottomLevelAS @0 = world->object, bottomLevelASToLocalSpace @64)
//   t1 g_indices        binding 101  ByteAddressBuffer = uint words[] (36 16-bit indices = 18 dwords)
//   t2 g_vertices       binding 102  StructuredBuffer<Vertex>, scalar, stride 24 (position @0, normal @12)
// Local root arguments (shaderRecordEXT, byte 0 = first byte after the 32-byte identifier):
//   "Triangle":   l_materialCB @0 (PrimitiveConstantBuffer, 48 B: albedo @0, reflectanceCoef @16, diffuseCoef @20,
//                 specularCoef @24, specularPower @28, stepScale @32, padding @36)
//   "Procedural": l_materialCB @0 (48 B), l_aabbCB @48 (instanceIndex @48, primitiveType @52); 56 B in all
// Ray payloads (locations are this library's choice; a location only names a variable inside one stage, the
// payload a shader receives is the one its caller traced with):
//   RayPayload        {vec4 color; uint recursionDepth; float dist; int count; bool hit;}  32 B
//                     outgoing (rayPayloadEXT, rgen/rchit) location 0, incoming (rayPayloadInEXT) location 2
//   ShadowRayPayload  {float dist; bool hit;}                                               8 B
//                     outgoing (rchit) location 1, incoming (Miss_Shadow) location 3
//   (glslang refuses a rayPayloadInEXT and a rayPayloadEXT at one location, hence the separate incoming ones.)
// Hit attributes: ProceduralPrimitiveAttributes {vec3 normal; vec4 color;} = 28 B (triangles: built-in barycentrics).
// TraceRay: radiance = (flags CULL_BACK_FACING_TRIANGLES, mask 0xFF, R 0, M 2, miss 0, TMin 0, TMax 10000);
//           shadow   = (CULL_BACK | TERMINATE_ON_FIRST_HIT | OPAQUE | SKIP_CLOSEST_HIT, 0xFF, R 1, M 2, miss 1, 0, 10000).
//
// Each entry point defines exactly one of PROCEDURAY_RGEN, PROCEDURAY_RMISS, PROCEDURAY_RCHIT, PROCEDURAY_RINT
// before including this file, because GLSL declares the ray-tracing built-ins per stage.
#ifndef PROCEDURAY_SHADER_COMPAT_GLSL
#define PROCEDURAY_SHADER_COMPAT_GLSL

#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require

// ---- engine/ShaderCompat.h ------------------------------------------------------------------------------------------

#define MAX_RAY_RECURSION_DEPTH 3u    // ~ primary rays + reflections + shadow rays from reflected geometry.

struct Vertex
{
    vec3 position;
    vec3 normal;
};

// Ray types traced in this sample (namespace RayType).
#define RayType_Radiance 0u   // ~ Primary, reflected camera/view rays calculating color for each hit.
#define RayType_Shadow 1u     // ~ Shadow/visibility rays, only testing for occlusion
#define RayType_Count 2u

// namespace TraceRayParameters. PORT: HLSL's InstanceMask is ~0; only its low 8 bits count, GLSL takes them as 0xFF.
#define TraceRayParameters_InstanceMask 0xFFu
const uint TraceRayParameters_HitGroup_Offset[RayType_Count] = uint[](
    0u, // Radiance ray
    1u  // Shadow ray
);
#define TraceRayParameters_HitGroup_GeometryStride RayType_Count
const uint TraceRayParameters_MissShader_Offset[RayType_Count] = uint[](
    0u, // Radiance ray
    1u  // Shadow ray
);

// PORT: TraceRay arguments a scene overrides become specialization constants (docs/vulkan-backend.md). refray's C++
// library takes each ray type's R, M, miss index and mask from the scene (a ray type's "traceRay", e.g. the lesson
// scenes/lessons/multiplier-one.json); the host (gpu/vulkan_pipeline.h, traceRayConstantId) gives ray type r's
// field f as constant_id 16 * (r + 1) + f: 0 R, 1 M, 2 miss index, 3 mask. The defaults are the HLSL's arguments,
// so with no values given this file means the HLSL. The ray flags stay constants (a scene cannot override them).
layout(constant_id = 16) const uint TraceRayArguments_Radiance_RayContribution = 0u;
layout(constant_id = 17) const uint TraceRayArguments_Radiance_Multiplier = 2u;
layout(constant_id = 18) const uint TraceRayArguments_Radiance_MissShaderIndex = 0u;
layout(constant_id = 19) const uint TraceRayArguments_Radiance_InstanceMask = 0xFFu;  // TraceRayParameters_InstanceMask
layout(constant_id = 32) const uint TraceRayArguments_Shadow_RayContribution = 1u;
layout(constant_id = 33) const uint TraceRayArguments_Shadow_Multiplier = 2u;
layout(constant_id = 34) const uint TraceRayArguments_Shadow_MissShaderIndex = 1u;
layout(constant_id = 35) const uint TraceRayArguments_Shadow_InstanceMask = 0xFFu;

const vec4 BackgroundColor = vec4(0.6f, 0.7f, 0.9f, 1.0f);
const float InShadowRadiance = 0.35f;

// namespace SignedDistancePrimitive (the value of l_aabbCB.primitiveType).
#define SignedDistancePrimitive_JuliaSets 0u
#define SignedDistancePrimitive_IntersectedRoundCube 1u
#define SignedDistancePrimitive_Mandelbulb 2u
#define SignedDistancePrimitive_Count 3u

// ---- engine/Payloads.h ----------------------------------------------------------------------------------------------

// PORT: HLSL bool is 32 bits; a GLSL bool in a ray payload is opaque, so the payload's size is the HLSL's 32 B
// (and 8 B for the shadow payload) in members, not in an observable memory layout.
struct RayPayload
{
    vec4 color;
    uint recursionDepth;
    float dist;
    int count;
    bool hit;
};

struct ShadowRayPayload
{
    float dist;
    bool hit;
};

// ---- engine/AttribStructs.h -----------------------------------------------------------------------------------------

struct ProceduralPrimitiveAttributes
{
    vec3 normal;
    vec4 color;
};

// ---- engine/RootComponents.h ----------------------------------------------------------------------------------------

// Attributes per primitive type.
struct PrimitiveConstantBuffer
{
    vec4 albedo;
    float reflectanceCoef;
    float diffuseCoef;
    float specularCoef;
    float specularPower;
    float stepScale;                      // Step scale for ray marching of signed distance primitives.
    // PORT: XMFLOAT3 padding as three floats: a vec3 would align to 16 under the relaxed (std430-like) rules that
    // spirv-val applies, moving l_aabbCB from byte 48 to 64. With floats the struct is 48 B in every layout.
    float padding_x;
    float padding_y;
    float padding_z;
};

// Attributes per primitive instance.
struct PrimitiveInstanceConstantBuffer
{
    uint instanceIndex;
    uint primitiveType; // Procedural primitive type
};

// PORT: XMMATRIX/XMVECTOR are float4x4/float4; the matrices are row-major in memory (/Zpr) and used with row vectors
// (mul(v, M) = v * M in GLSL), hence row_major on the blocks below.
struct SceneConstantBuffer
{
    mat4 projectionToWorld;
    vec4 cameraPosition;
    vec4 lightPosition;
    vec4 lightAmbientColor;
    vec4 lightDiffuseColor;
    float reflectance;
    float elapsedTime;                 // Elapsed application time.
    int debugFlag;
};

// Dynamic attributes per primitive instance.
struct InstanceBuffer
{
    mat4 localSpaceToBottomLevelAS;   // Matrix from local primitive space to bottom-level object space.
    mat4 bottomLevelASToLocalSpace;   // Matrix from bottom-level object space to local primitive space.
};

// ---- Raytracing.hlsl L33-47: resources bound via the global root signature -----------------------------------------
// PORT: HLSL declares every resource in every shader; GLSL declares only those the stage's code can use.

#if defined(PROCEDURAY_RGEN) || defined(PROCEDURAY_RCHIT)
layout(set = 0, binding = 100) uniform accelerationStructureEXT g_scene;              // t0
#endif
#if defined(PROCEDURAY_RGEN)
layout(set = 0, binding = 200, rgba32f) uniform writeonly image2D g_renderTarget;    // u0
#endif
layout(set = 0, binding = 0, scalar, row_major) uniform SceneConstantBufferBlock     // b0
{
    SceneConstantBuffer g_sceneCB;
};

// Triangle resources
// PORT: ByteAddressBuffer g_indices is the raw dwords; Load2(offset) reads g_indices[offset / 4] and the next one.
layout(set = 0, binding = 101, scalar) readonly buffer IndexBufferBlock               // t1
{
    uint g_indices[];
};
// PORT: StructuredBuffer<Vertex> g_vertices (stride 24) is read as raw floats: an array of a struct of two vec3 has a
// 16-byte alignment that `spirv-val --target-env vulkan1.2` (relaxed block layout) refuses for a 24-byte stride.
// g_vertices(i) returns element i, so `g_vertices[i].normal` reads `g_vertices(i).normal`.
layout(set = 0, binding = 102, scalar) readonly buffer VertexBufferBlock              // t2
{
    float g_verticesFloats[];
};
Vertex g_vertices(uint i)
{
    const uint f = i * 6u;
    Vertex v;
    v.position = vec3(g_verticesFloats[f + 0u], g_verticesFloats[f + 1u], g_verticesFloats[f + 2u]);
    v.normal = vec3(g_verticesFloats[f + 3u], g_verticesFloats[f + 4u], g_verticesFloats[f + 5u]);
    return v;
}

// Procedural geometry resources
layout(set = 0, binding = 103, scalar, row_major) readonly buffer InstanceBufferBlock // t3
{
    InstanceBuffer g_instanceBuffer[];
};

// ---- Local root arguments (engine/RootArguments.h): l_materialCB (b1) and l_aabbCB (b2) ----------------------------
// PORT: HLSL ConstantBuffer<...> l_materialCB : register(b1) and l_aabbCB : register(b2) are the record's root
// constants; an entry point of the "Triangle" signature defines PROCEDURAY_TRIANGLE_ROOT_ARGUMENTS, one of the
// "Procedural" signature PROCEDURAY_PROCEDURAL_ROOT_ARGUMENTS.
#if defined(PROCEDURAY_TRIANGLE_ROOT_ARGUMENTS)
layout(shaderRecordEXT, scalar) buffer TriangleRootArguments
{
    PrimitiveConstantBuffer l_materialCB;     // @0
};
#elif defined(PROCEDURAY_PROCEDURAL_ROOT_ARGUMENTS)
layout(shaderRecordEXT, scalar) buffer ProceduralRootArguments
{
    PrimitiveConstantBuffer l_materialCB;     // @0
    PrimitiveInstanceConstantBuffer l_aabbCB; // @48
};
#endif

// ---- Ray payloads this library traces with (see the table above) ---------------------------------------------------
// PORT: HLSL's TraceRay takes a local payload; GLSL's traceRayEXT names a rayPayloadEXT variable by location.
#define PROCEDURAY_RADIANCE_PAYLOAD_LOCATION 0
#define PROCEDURAY_SHADOW_PAYLOAD_LOCATION 1
#define PROCEDURAY_INCOMING_RADIANCE_PAYLOAD_LOCATION 2
#define PROCEDURAY_INCOMING_SHADOW_PAYLOAD_LOCATION 3
#if defined(PROCEDURAY_RGEN) || defined(PROCEDURAY_RCHIT)
layout(location = PROCEDURAY_RADIANCE_PAYLOAD_LOCATION) rayPayloadEXT RayPayload tracedRayPayload;
#endif
#if defined(PROCEDURAY_RCHIT)
layout(location = PROCEDURAY_SHADOW_PAYLOAD_LOCATION) rayPayloadEXT ShadowRayPayload shadowPayload;
#endif

#endif // PROCEDURAY_SHADER_COMPAT_GLSL
