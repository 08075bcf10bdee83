// Ports RaytracingShaderHelper.hlsli of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/RaytracingShaderHelper.hlsli.
// Needs common/d3d12_hlsl_intrinsics.glsl, common/d3d12_dxr_intrinsics.glsl and RaytracingHlslCompat.glsl first.
// Functions that read a system value exist only in the stages DXR allows that value in (DXR_STAGE_* guards). IsCulled
// and IsAValidHit also exist where the includer traces inline and has made RayTMin(), RayTCurrent() and RayFlags()
// macros for the query's values (DXR_RAY_EXTENT_OF_QUERY, InlineShadows.glsl).
#ifndef RAYTRACINGSHADERHELPER_GLSL
#define RAYTRACINGSHADERHELPER_GLSL

// PORT: HLSL writes (1.0/0.0); the bit pattern of +inf says the same without a constant-folded division by zero.
#define INFINITY uintBitsToFloat(0x7F800000u)

struct Ray
{
    vec3 origin;
    vec3 direction;
};

float length_toPow2(vec2 p)
{
    return dot(p, p);
}

float length_toPow2(vec3 p)
{
    return dot(p, p);
}

// Returns a cycling <0 -> 1 -> 0> animation interpolant
float CalculateAnimationInterpolant(in float elapsedTime, in float cycleDuration)
{
    float curLinearCycleTime = fmod(elapsedTime, cycleDuration) / cycleDuration;
    curLinearCycleTime = (curLinearCycleTime <= 0.5f) ? 2 * curLinearCycleTime : 1 - 2 * (curLinearCycleTime - 0.5f);
    return hlsl_smoothstep(0, 1, curLinearCycleTime);
}

void swap(inout float a, inout float b)
{
    float temp = a;
    a = b;
    b = temp;
}

bool IsInRange(in float val, in float min, in float max)
{
    return (val >= min && val <= max);
}

// Load3x16BitIndices is in Raytracing.glsl, beside g_indices.
// PORT: GLSL cannot pass a buffer as a parameter, so it reads the global g_indices (the only buffer HLSL passes).

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION)
// Retrieve hit world position.
// PORT: HLSL may call it in an intersection shader too; there RayTCurrent() is the closest committed t, as in DXR.
// PORT: RayTCurrent() is written as what it is here, gl_RayTmaxEXT (common/d3d12_dxr_intrinsics.glsl), so that this
// stays the shader's own hit also where a file that traces inline makes the intersection helpers' RayTCurrent() a
// macro for the query's committed t (InlineShadows.glsl).
vec3 HitWorldPosition()
{
    return WorldRayOrigin() + gl_RayTmaxEXT * WorldRayDirection();
}
#endif

// Retrieve attribute at a hit position interpolated from vertex attributes using the hit's barycentrics.
vec3 HitAttribute(vec3 vertexAttribute[3], vec2 barycentrics)
{
    return vertexAttribute[0] +
        barycentrics.x * (vertexAttribute[1] - vertexAttribute[0]) +
        barycentrics.y * (vertexAttribute[2] - vertexAttribute[0]);
}

#if !defined(DXR_STAGE_COMPUTE)
// Generate a ray in world space for a camera pixel corresponding to an index from the dispatched 2D grid.
Ray GenerateCameraRay(uvec2 index, in vec3 cameraPosition, in mat4 projectionToWorld)
{
    vec2 xy = vec2(index) + 0.5f; // center in the middle of the pixel.
    vec2 screenPos = xy / vec2(DispatchRaysDimensions().xy) * 2.0 - 1.0;

    // Invert Y for DirectX-style coordinates.
    screenPos.y = -screenPos.y;

    // Unproject the pixel coordinate into a world positon.
    // PORT: HLSL mul(rowVector, M) is rowVector * M in GLSL (the matrix is the same: row_major block).
    vec4 world = vec4(screenPos, 0, 1) * projectionToWorld;
    world.xyz /= world.w;

    Ray ray;
    ray.origin = cameraPosition;
    ray.direction = normalize(world.xyz - ray.origin);

    return ray;
}
#endif

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION) || \
    defined(DXR_RAY_EXTENT_OF_QUERY)
// Test if a hit is culled based on specified RayFlags.
bool IsCulled(in Ray ray, in vec3 hitSurfaceNormal)
{
    float rayDirectionNormalDot = dot(ray.direction, hitSurfaceNormal);

    bool isCulled =
        (((RayFlags() & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) != 0u) && (rayDirectionNormalDot > 0))
        ||
        (((RayFlags() & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) != 0u) && (rayDirectionNormalDot < 0));

    return isCulled;
}

// Test if a hit is valid based on specified RayFlags and <RayTMin, RayTCurrent> range.
bool IsAValidHit(in Ray ray, in float thit, in vec3 hitSurfaceNormal)
{
    return IsInRange(thit, RayTMin(), RayTCurrent()) && !IsCulled(ray, hitSurfaceNormal);
}
#endif

// Texture coordinates on a horizontal plane.
vec2 TexCoords(in vec3 position)
{
    return position.xz;
}

#if !defined(DXR_STAGE_COMPUTE)
// Calculate ray differentials.
void CalculateRayDifferentials(out vec2 ddx_uv, out vec2 ddy_uv, in vec2 uv, in vec3 hitPosition, in vec3 surfaceNormal, in vec3 cameraPosition, in mat4 projectionToWorld)
{
    // Compute ray differentials by intersecting the tangent plane to the  surface.
    Ray ddx = GenerateCameraRay(DispatchRaysIndex().xy + uvec2(1, 0), cameraPosition, projectionToWorld);
    Ray ddy = GenerateCameraRay(DispatchRaysIndex().xy + uvec2(0, 1), cameraPosition, projectionToWorld);

    // Compute ray differentials.
    vec3 ddx_pos = ddx.origin - ddx.direction * dot(ddx.origin - hitPosition, surfaceNormal) / dot(ddx.direction, surfaceNormal);
    vec3 ddy_pos = ddy.origin - ddy.direction * dot(ddy.origin - hitPosition, surfaceNormal) / dot(ddy.direction, surfaceNormal);

    // Calculate texture sampling footprint.
    ddx_uv = TexCoords(ddx_pos) - uv;
    ddy_uv = TexCoords(ddy_pos) - uv;
}

// Forward declaration (defined in SignedDistancePrimitives.glsl).
float CheckersTextureBoxFilter(in vec2 uv, in vec2 dpdx, in vec2 dpdy, in uint ratio);

// Return analytically integrated checkerboard texture (box filter).
float AnalyticalCheckersTexture(in vec3 hitPosition, in vec3 surfaceNormal, in vec3 cameraPosition, in mat4 projectionToWorld)
{
    vec2 ddx_uv;
    vec2 ddy_uv;
    vec2 uv = TexCoords(hitPosition);

    CalculateRayDifferentials(ddx_uv, ddy_uv, uv, hitPosition, surfaceNormal, cameraPosition, projectionToWorld);
    return CheckersTextureBoxFilter(uv, ddx_uv, ddy_uv, 50);
}
#endif

// Fresnel reflectance - schlick approximation.
vec3 FresnelReflectanceSchlick(in vec3 I, in vec3 N, in vec3 f0)
{
    float cosi = saturate(dot(-I, N));
    return f0 + (1 - f0)*hlsl_pow(1 - cosi, 5);
}

#endif // RAYTRACINGSHADERHELPER_GLSL
