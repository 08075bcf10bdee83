// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/RaytracingShaderHelper.hlsli (the parts the
// MandelJuliaPac shaders call: Ray, IsInRange, Load3x16BitIndices, HitWorldPosition, GenerateCameraRay, IsCulled,
// IsAValidHit, FresnelReflectanceSchlick). Dead helpers (checkers, ray differentials, swap, ...) are not ported.
#ifndef PROCEDURAY_RAYTRACING_SHADER_HELPER_GLSL
#define PROCEDURAY_RAYTRACING_SHADER_HELPER_GLSL

#include "proceduray/shader_compat.glsl"
#include "proceduray/hlsl_intrinsics.glsl"

// PORT: HLSL's DXR intrinsics as GLSL built-ins. RayTCurrent() is gl_RayTmaxEXT, which in an intersection shader is
// the current committed t (or TMax) and in a closest-hit shader the hit's t, as in DXR.
#if defined(PROCEDURAY_RCHIT) || defined(PROCEDURAY_RINT)
#define WorldRayOrigin() gl_WorldRayOriginEXT
#define WorldRayDirection() gl_WorldRayDirectionEXT
#define ObjectRayOrigin() gl_ObjectRayOriginEXT
#define ObjectRayDirection() gl_ObjectRayDirectionEXT
#define RayTMin() gl_RayTminEXT
#define RayTCurrent() gl_RayTmaxEXT
#define RayFlags() gl_IncomingRayFlagsEXT
// HLSL WorldToObject3x4() is 3 rows x 4 columns (column vectors); GLSL's gl_WorldToObjectEXT (mat4x3) is the same
// matrix, so (float3x3)WorldToObject3x4() is mat3(gl_WorldToObjectEXT) and mul(n, M3) is n * M3.
#define WorldToObject3x3() mat3(gl_WorldToObjectEXT)
#endif

#define RAY_FLAG_CULL_BACK_FACING_TRIANGLES gl_RayFlagsCullBackFacingTrianglesEXT
#define RAY_FLAG_CULL_FRONT_FACING_TRIANGLES gl_RayFlagsCullFrontFacingTrianglesEXT

struct Ray
{
    vec3 origin;
    vec3 direction;
};

bool IsInRange(in float val, in float min, in float max)
{
    return (val >= min && val <= max);
}

// Load three 16 bit indices.
// PORT: the HLSL passes the ByteAddressBuffer as a parameter; GLSL cannot, so this reads g_indices (t1) directly.
uvec3 Load3x16BitIndices(uint offsetBytes)
{
    uvec3 indices;

    // ByteAdressBuffer loads must be aligned at a 4 byte boundary.
    // Since we need to read three 16 bit indices: { 0, 1, 2 }
    // aligned at a 4 byte boundary as: { 0 1 } { 2 0 } { 1 2 } { 0 1 } ...
    // we will load 8 bytes (~ 4 indices { a b | c d }) to handle two possible index triplet layouts,
    // based on first index's offsetBytes being aligned at the 4 byte boundary or not:
    //  Aligned:     { 0 1 | 2 - }
    //  Not aligned: { - 0 | 1 2 }
    const uint dwordAlignedOffset = offsetBytes & ~3u;
    const uvec2 four16BitIndices = uvec2(g_indices[dwordAlignedOffset / 4u], g_indices[dwordAlignedOffset / 4u + 1u]);

    // Aligned: { 0 1 | 2 - } => retrieve first three 16bit indices
    if (dwordAlignedOffset == offsetBytes)
    {
        indices.x = four16BitIndices.x & 0xffffu;
        indices.y = (four16BitIndices.x >> 16) & 0xffffu;
        indices.z = four16BitIndices.y & 0xffffu;
    }
    else // Not aligned: { - 0 | 1 2 } => retrieve last three 16bit indices
    {
        indices.x = (four16BitIndices.x >> 16) & 0xffffu;
        indices.y = four16BitIndices.y & 0xffffu;
        indices.z = (four16BitIndices.y >> 16) & 0xffffu;
    }

    return indices;
}

#if defined(PROCEDURAY_RCHIT) || defined(PROCEDURAY_RINT)
// Retrieve hit world position.
vec3 HitWorldPosition()
{
    return WorldRayOrigin() + RayTCurrent() * WorldRayDirection();
}

// Test if a hit is culled based on specified RayFlags.
bool IsCulled(in Ray ray, in vec3 hitSurfaceNormal)
{
    float rayDirectionNormalDot = dot(ray.direction, hitSurfaceNormal);

    bool isCulled =
        (((RayFlags() & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) != 0u) && (rayDirectionNormalDot > 0.0))
        ||
        (((RayFlags() & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) != 0u) && (rayDirectionNormalDot < 0.0));

    return isCulled;
}

// Test if a hit is valid based on specified RayFlags and <RayTMin, RayTCurrent> range.
bool IsAValidHit(in Ray ray, in float thit, in vec3 hitSurfaceNormal)
{
    return IsInRange(thit, RayTMin(), RayTCurrent()) && !IsCulled(ray, hitSurfaceNormal);
}
#endif

#if defined(PROCEDURAY_RGEN)
// Generate a ray in world space for a camera pixel corresponding to an index from the dispatched 2D grid.
Ray GenerateCameraRay(uvec2 index, in vec3 cameraPosition, in mat4 projectionToWorld)
{
    vec2 xy = vec2(index) + 0.5f; // center in the middle of the pixel.
    vec2 screenPos = xy / vec2(gl_LaunchSizeEXT.xy) * 2.0 - 1.0;

    // Invert Y for DirectX-style coordinates.
    screenPos.y = -screenPos.y;

    // Unproject the pixel coordinate into a world positon.
    vec4 world = vec4(screenPos, 0.0, 1.0) * projectionToWorld;
    world.xyz /= world.w;

    Ray ray;
    ray.origin = cameraPosition;
    ray.direction = normalize(world.xyz - ray.origin);

    return ray;
}
#endif

// Fresnel reflectance - schlick approximation.
vec3 FresnelReflectanceSchlick(in vec3 I, in vec3 N, in vec3 f0)
{
    float cosi = saturate(dot(-I, N));
    // PORT: pow is hlsl_pow, DXC's exp2(y*log2(x)).
    return f0 + (1.0 - f0) * hlsl_pow(1.0 - cosi, 5.0);
}

#endif // PROCEDURAY_RAYTRACING_SHADER_HELPER_GLSL
