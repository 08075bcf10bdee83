// Ports RayTracingHlslCompat.h of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/RayTracingHlslCompat.h (the HLSL side).
//
// Payload locations of this library (the same in every shader of it):
//   location 0: RayPayload        (radiance rays, 20 bytes: color at 0, recursionDepth at 16)
//   location 1: ShadowRayPayload  (shadow rays, 4 bytes: hit at 0)
// (The locations name the outgoing rayPayloadEXT variables of raygen and closest hit; an incoming rayPayloadInEXT
// has none: Vulkan hands a shader the caller's payload, whose type must match.)
// Hit attributes: ProceduralPrimitiveAttributes (12 bytes: normal at 0), HitKind always 0.
#ifndef RAYTRACINGHLSLCOMPAT_GLSL
#define RAYTRACINGHLSLCOMPAT_GLSL

// Number of metaballs to use within an AABB.
#define N_METABALLS 3    // = {3, 5}

// Limitting calculations only to metaballs a ray intersects can speed up raytracing
// dramatically particularly when there is a higher number of metaballs used.
#if N_METABALLS >= 5
#define USE_DYNAMIC_LOOPS 1
#define LIMIT_TO_ACTIVE_METABALLS 1
#else
#define USE_DYNAMIC_LOOPS 0
#define LIMIT_TO_ACTIVE_METABALLS 0
#endif

#define N_FRACTAL_ITERATIONS 4      // = <1,...>

#define MAX_RAY_RECURSION_DEPTH 3    // ~ primary rays + reflections + shadow rays from reflected geometry.

#define PAYLOAD_LOCATION_RADIANCE 0
#define PAYLOAD_LOCATION_SHADOW 1

struct ProceduralPrimitiveAttributes
{
    vec3 normal;
};

struct RayPayload
{
    vec4 color;
    uint recursionDepth;
};

// PORT: the HLSL `bool hit` is a 32-bit value; a uint keeps its size and 0 / non-0 meaning.
struct ShadowRayPayload
{
    uint hit;
};

// SceneConstantBuffer is the uniform block g_sceneCB (Raytracing.glsl), laid out there with its offsets.

// Attributes per primitive type.
struct PrimitiveConstantBuffer
{
    vec4 albedo;             // offset 0
    float reflectanceCoef;   // 16
    float diffuseCoef;       // 20
    float specularCoef;      // 24
    float specularPower;     // 28
    float stepScale;         // 32: step scale for ray marching of signed distance primitives.
    vec3 padding;            // 36 (48 bytes in all)
};

// Attributes per primitive instance.
struct PrimitiveInstanceConstantBuffer
{
    uint instanceIndex;      // offset 0
    uint primitiveType;      // 4: procedural primitive type
};

// Dynamic attributes per primitive instance. The matrices are row-major in memory (the sample compiles with /Zpr
// and stores XMMATRIX rows); the buffer block that holds them is row_major.
struct PrimitiveInstancePerFrameBuffer
{
    mat4 localSpaceToBottomLevelAS;   // offset 0:  local primitive space -> bottom-level object space.
    mat4 bottomLevelASToLocalSpace;   // offset 64: bottom-level object space -> local primitive space.
};

struct Vertex
{
    vec3 position;   // offset 0
    vec3 normal;     // 12 (stride 24)
};

// Ray types traced in this sample.
const uint RayType_Radiance = 0u;   // ~ Primary, reflected camera/view rays calculating color for each hit.
const uint RayType_Shadow = 1u;     // ~ Shadow/visibility rays, only testing for occlusion
const uint RayType_Count = 2u;

const uint TraceRayParameters_InstanceMask = ~0u;   // Everything is visible.
const uint TraceRayParameters_HitGroup_Offset[RayType_Count] = uint[](
    0u, // Radiance ray
    1u  // Shadow ray
);
const uint TraceRayParameters_HitGroup_GeometryStride = RayType_Count;
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
layout(constant_id = 19) const uint TraceRayArguments_Radiance_InstanceMask = 0xFFFFFFFFu;  // ~0: TraceRayParameters_InstanceMask
layout(constant_id = 32) const uint TraceRayArguments_Shadow_RayContribution = 1u;
layout(constant_id = 33) const uint TraceRayArguments_Shadow_Multiplier = 2u;
layout(constant_id = 34) const uint TraceRayArguments_Shadow_MissShaderIndex = 1u;
layout(constant_id = 35) const uint TraceRayArguments_Shadow_InstanceMask = 0xFFFFFFFFu;

const vec4 ChromiumReflectance = vec4(0.549, 0.556, 0.554, 1.0);

const vec4 BackgroundColor = vec4(0.8, 0.9, 1.0, 1.0);
const float InShadowRadiance = 0.35;

// AnalyticPrimitive::Enum
const uint AnalyticPrimitive_AABB = 0u;
const uint AnalyticPrimitive_Spheres = 1u;
const uint AnalyticPrimitive_Count = 2u;

// VolumetricPrimitive::Enum
const uint VolumetricPrimitive_Metaballs = 0u;
const uint VolumetricPrimitive_Count = 1u;

// SignedDistancePrimitive::Enum
const uint SignedDistancePrimitive_MiniSpheres = 0u;
const uint SignedDistancePrimitive_IntersectedRoundCube = 1u;
const uint SignedDistancePrimitive_SquareTorus = 2u;
const uint SignedDistancePrimitive_TwistedTorus = 3u;
const uint SignedDistancePrimitive_Cog = 4u;
const uint SignedDistancePrimitive_Cylinder = 5u;
const uint SignedDistancePrimitive_FractalPyramid = 6u;
const uint SignedDistancePrimitive_Count = 7u;

#endif // RAYTRACINGHLSLCOMPAT_GLSL
