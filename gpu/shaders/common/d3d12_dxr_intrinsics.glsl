// DXR system values and RAY_FLAG constants under their HLSL names, as GL_EXT_ray_tracing built-ins, for GLSL ports
// of D3D12 DXR HLSL. Not a port of one HLSL file. The including entry point defines its stage first:
// DXR_STAGE_RAYGEN, DXR_STAGE_MISS, DXR_STAGE_CLOSEST_HIT, DXR_STAGE_ANY_HIT or DXR_STAGE_INTERSECTION, or
// DXR_STAGE_COMPUTE for a compute shader that traces inline (each system value exists only in the stages DXR allows
// it in; GLSL rejects a built-in of another stage). A compute shader gets the RAY_FLAG_* constants only.
#ifndef D3D12_DXR_INTRINSICS_GLSL
#define D3D12_DXR_INTRINSICS_GLSL

// RAY_FLAG_*: DXR and Vulkan use the same bit for each.
const uint RAY_FLAG_NONE = 0x00u;
const uint RAY_FLAG_FORCE_OPAQUE = 0x01u;                    // gl_RayFlagsOpaqueEXT
const uint RAY_FLAG_FORCE_NON_OPAQUE = 0x02u;                // gl_RayFlagsNoOpaqueEXT
const uint RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH = 0x04u; // gl_RayFlagsTerminateOnFirstHitEXT
const uint RAY_FLAG_SKIP_CLOSEST_HIT_SHADER = 0x08u;         // gl_RayFlagsSkipClosestHitShaderEXT
const uint RAY_FLAG_CULL_BACK_FACING_TRIANGLES = 0x10u;      // gl_RayFlagsCullBackFacingTrianglesEXT
const uint RAY_FLAG_CULL_FRONT_FACING_TRIANGLES = 0x20u;     // gl_RayFlagsCullFrontFacingTrianglesEXT
const uint RAY_FLAG_CULL_OPAQUE = 0x40u;                     // gl_RayFlagsCullOpaqueEXT
const uint RAY_FLAG_CULL_NON_OPAQUE = 0x80u;                 // gl_RayFlagsCullNoOpaqueEXT

// Every ray-tracing stage.
#if !defined(DXR_STAGE_COMPUTE)
uvec3 DispatchRaysIndex() { return gl_LaunchIDEXT; }
uvec3 DispatchRaysDimensions() { return gl_LaunchSizeEXT; }
#endif

#if defined(DXR_STAGE_MISS) || defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || \
    defined(DXR_STAGE_INTERSECTION)
vec3 WorldRayOrigin() { return gl_WorldRayOriginEXT; }
vec3 WorldRayDirection() { return gl_WorldRayDirectionEXT; }
float RayTMin() { return gl_RayTminEXT; }
// RayTCurrent(): TMax in a miss shader, the closest committed t so far in an intersection / any-hit shader, the hit's
// t in a closest-hit shader. Vulkan's gl_RayTmaxEXT has the same meaning in each stage.
float RayTCurrent() { return gl_RayTmaxEXT; }
uint RayFlags() { return gl_IncomingRayFlagsEXT; }
#endif

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION)
vec3 ObjectRayOrigin() { return gl_ObjectRayOriginEXT; }
vec3 ObjectRayDirection() { return gl_ObjectRayDirectionEXT; }
// HLSL float3x4 (3 rows, 4 columns) is GLSL mat4x3 (4 columns of 3): the same matrix, column-vector convention.
mat4x3 ObjectToWorld3x4() { return gl_ObjectToWorldEXT; }
mat4x3 WorldToObject3x4() { return gl_WorldToObjectEXT; }
uint PrimitiveIndex() { return uint(gl_PrimitiveID); }
uint InstanceIndex() { return uint(gl_InstanceID); }
uint InstanceID() { return uint(gl_InstanceCustomIndexEXT); }
uint GeometryIndex() { return uint(gl_GeometryIndexEXT); }
#endif

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT)
uint HitKind() { return gl_HitKindEXT; }
#endif

#endif  // D3D12_DXR_INTRINSICS_GLSL
