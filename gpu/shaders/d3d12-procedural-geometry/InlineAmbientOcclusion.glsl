// Ports InlineAmbientOcclusion.hlsl of refray (scenes/inline/InlineAmbientOcclusion.hlsl; written for refray over
// microsoft/DirectX-Graphics-Samples@357ade6e, D3D12RaytracingProceduralGeometry): everything but the entry point,
// which is InlineAmbientOcclusionCS.comp. Includes InlineShadows.glsl (g_inlinePrimitives,
// IntersectCandidateProceduralPrimitive) and, through it, Raytracing.glsl.
//
// One thread per pixel. A primary query finds the closest surface: procedural candidates are intersected by this
// shader with the intersection shaders' code and committed with CommitProceduralPrimitiveHit; the ground plane's
// opaque triangles are committed inside Proceed (RQ-14). The committed procedural hit keeps no attributes (RQ-23), so
// the shader keeps the normal itself. Then AO_RAY_COUNT occlusion queries leave the point in a cosine-weighted
// hemisphere around the normal, each ending at its first hit (RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH).
//
// The including file defines DXR_STAGE_COMPUTE and enables GL_EXT_ray_query, GL_EXT_scalar_block_layout,
// GL_EXT_spirv_intrinsics and GL_GOOGLE_include_directive.
#ifndef INLINEAMBIENTOCCLUSION_GLSL
#define INLINEAMBIENTOCCLUSION_GLSL

#include "d3d12-procedural-geometry/InlineShadows.glsl"

const uint AO_RAY_COUNT = 8u;
const float AO_RADIUS = 3.0;
const float AO_ORIGIN_OFFSET = 0.01;  // along the normal, in world units

// Chris Wellons' "lowbias32" integer hash.
uint Hash(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// The top 24 bits of h as a float in [0, 1): exact.
float UnitFloat(uint h)
{
    return float(h >> 8) * (1.0 / 16777216.0);
}

// A direction of the cosine-weighted hemisphere around n for the unit square point (u1, u2), in the orthonormal
// basis of Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017).
vec3 CosineHemisphereDirection(vec3 n, float u1, float u2)
{
    float s = n.z >= 0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 t2 = vec3(b, s + n.y * n.y * a, -n.y);
    float r = sqrt(u1);
    float phi = 2.0 * 3.14159265 * u2;
    return r * cos(phi) * t1 + r * sin(phi) * t2 + sqrt(1.0 - u1) * n;
}

// PORT: the HLSL calls GenerateCameraRay(pixel, size, out origin, out direction), "the sample's, with the thread's
// pixel": the sample's GenerateCameraRay (RaytracingShaderHelper.glsl, whose copy reads DispatchRaysDimensions(),
// which a compute shader lacks) with the render target's size in its place and the camera of g_sceneCB.
void GenerateCameraRay(uvec2 index, uvec2 dimensions, out vec3 origin, out vec3 direction)
{
    vec2 xy = vec2(index) + 0.5f; // center in the middle of the pixel.
    vec2 screenPos = xy / vec2(dimensions) * 2.0 - 1.0;

    // Invert Y for DirectX-style coordinates.
    screenPos.y = -screenPos.y;

    // Unproject the pixel coordinate into a world positon.
    // PORT: HLSL mul(rowVector, M) is rowVector * M in GLSL (the matrix is the same: row_major block).
    vec4 world = vec4(screenPos, 0, 1) * g_sceneCB.projectionToWorld;
    world.xyz /= world.w;

    origin = g_sceneCB.cameraPosition.xyz;
    direction = normalize(world.xyz - origin);
}

// The committed hit of the primary query: the world normal, as the closest-hit shaders of the sample compute it.
bool TracePrimaryInline(vec3 origin, vec3 direction, out vec3 hitPosition, out vec3 normal)
{
    RayDesc rayDesc;
    rayDesc.Origin = origin;
    rayDesc.Direction = direction;
    rayDesc.TMin = 0;
    rayDesc.TMax = 10000;

    vec3 committedNormal = vec3(0, 0, 0);  // RQ-23: the system keeps no attributes of a procedural hit
    // PORT: RayQuery<RAY_FLAG_CULL_BACK_FACING_TRIANGLES> q (the radiance rays' flags) is a rayQueryEXT and its
    // RayQueryState (common/d3d12_ray_query.glsl).
    rayQueryEXT q;
    RayQueryState qs = RayQuery_TraceRayInline(q, g_scene, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, RAY_FLAG_NONE,
                                               TraceRayParameters_InstanceMask, rayDesc);
    while (RayQuery_Proceed(q, qs))
    {
        if (RayQuery_CandidateType(q) == CANDIDATE_PROCEDURAL_PRIMITIVE)
        {
            float thit;
            ProceduralPrimitiveAttributes attr;
            if (IntersectCandidateProceduralPrimitive(q, qs, thit, attr))
            {
                RayQuery_CommitProceduralPrimitiveHit(q, thit);
                committedNormal = attr.normal;
            }
        }
        else
        {
            // A non-opaque triangle: the sample's hit groups have no any-hit shader, so TraceRay would accept it.
            RayQuery_CommitNonOpaqueTriangleHit(q);
        }
    }

    hitPosition = vec3(0, 0, 0);
    normal = vec3(0, 0, 0);
    if (RayQuery_CommittedStatus(q) == COMMITTED_NOTHING)
    {
        return false;
    }
    hitPosition = origin + RayQuery_CommittedRayT(q, qs) * direction;
    if (RayQuery_CommittedStatus(q) == COMMITTED_TRIANGLE_HIT)
    {
        // MyClosestHitShader_Triangle's normal: the first vertex's, untransformed.
        uint baseIndex = RayQuery_CommittedPrimitiveIndex(q) * 6u;
        const uvec3 indices = Load3x16BitIndices(baseIndex); // PORT: g_indices is global (Raytracing.glsl)
        normal = g_vertices(indices[0]).normal;               // PORT: g_vertices[i] is g_vertices(i)
    }
    else
    {
        normal = committedNormal;
    }
    return true;
}

// True when the occlusion ray finds any surface within AO_RADIUS: the shadow rays' query (InlineShadows.glsl). The
// lesson variants' defines never reach this file's exports, so its flags are the HLSL's.
bool TraceOcclusionInline(vec3 origin, vec3 direction)
{
    return TraceAnyHitInline(origin, direction, AO_RADIUS);
}

#endif // INLINEAMBIENTOCCLUSION_GLSL
