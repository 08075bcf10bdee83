// refray: ambient occlusion of Microsoft's D3D12RaytracingProceduralGeometry scene, traced inline from a compute
// shader (DXR 1.1, Shader Model 6.5). Written for refray; it includes the sample's Raytracing.hlsl
// (microsoft/DirectX-Graphics-Samples@357ade6e) for its structs, resources and intersection helpers, and
// InlineShadows.hlsl for g_inlinePrimitives and IntersectCandidateProceduralPrimitive.
//
// One thread per pixel. A primary RayQuery finds the closest surface: procedural candidates are intersected by
// this shader with the intersection shaders' code and committed with CommitProceduralPrimitiveHit; the ground
// plane's opaque triangles are committed inside Proceed (RQ-14). The committed procedural hit keeps no attributes
// (RQ-23), so the shader keeps the normal itself. Then AO_RAY_COUNT occlusion queries leave the point in a
// cosine-weighted hemisphere around the normal, each ending at its first hit
// (RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH). The pixel is the fraction of them that escape within AO_RADIUS.
//
// The directions come from an integer hash of the pixel and the ray number, so every implementation traces the
// same rays up to the float math that turns the hash into a direction.
//
// Dispatch: ceil(width / 8) x ceil(height / 8) x 1 groups; threads past the render target's edge return.

#include "InlineShadows.hlsl"

static const uint AO_RAY_COUNT = 8;
static const float AO_RADIUS = 3.0;
static const float AO_ORIGIN_OFFSET = 0.01;  // along the normal, in world units

// Chris Wellons' "lowbias32" integer hash.
uint Hash(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
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
float3 CosineHemisphereDirection(float3 n, float u1, float u2)
{
    float s = n.z >= 0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    float3 t1 = float3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    float3 t2 = float3(b, s + n.y * n.y * a, -n.y);
    float r = sqrt(u1);
    float phi = 2.0 * 3.14159265 * u2;
    return r * cos(phi) * t1 + r * sin(phi) * t2 + sqrt(1.0 - u1) * n;
}

// The committed hit of the primary query: the world normal, as the closest-hit shaders of the sample compute it.
bool TracePrimaryInline(float3 origin, float3 direction, out float3 hitPosition, out float3 normal)
{
    RayDesc rayDesc;
    rayDesc.Origin = origin;
    rayDesc.Direction = direction;
    rayDesc.TMin = 0;
    rayDesc.TMax = 10000;

    float3 committedNormal = float3(0, 0, 0);  // RQ-23: the system keeps no attributes of a procedural hit
    RayQuery<RAY_FLAG_CULL_BACK_FACING_TRIANGLES> q;  // the radiance rays' flags
    q.TraceRayInline(g_scene, RAY_FLAG_NONE, TraceRayParameters::InstanceMask, rayDesc);
    while (q.Proceed())
    {
        if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE)
        {
            float thit;
            ProceduralPrimitiveAttributes attr;
            if (IntersectCandidateProceduralPrimitive(q, thit, attr))
            {
                q.CommitProceduralPrimitiveHit(thit);
                committedNormal = attr.normal;
            }
        }
        else
        {
            // A non-opaque triangle: the sample's hit groups have no any-hit shader, so TraceRay would accept it.
            q.CommitNonOpaqueTriangleHit();
        }
    }

    hitPosition = float3(0, 0, 0);
    normal = float3(0, 0, 0);
    if (q.CommittedStatus() == COMMITTED_NOTHING)
    {
        return false;
    }
    hitPosition = origin + q.CommittedRayT() * direction;
    if (q.CommittedStatus() == COMMITTED_TRIANGLE_HIT)
    {
        // MyClosestHitShader_Triangle's normal: the first vertex's, untransformed.
        uint baseIndex = q.CommittedPrimitiveIndex() * 6;
        const uint3 indices = Load3x16BitIndices(baseIndex, g_indices);
        normal = g_vertices[indices[0]].normal;
    }
    else
    {
        normal = committedNormal;
    }
    return true;
}

// True when the occlusion ray finds any surface within AO_RADIUS: the shadow rays' query (InlineShadows.hlsl).
bool TraceOcclusionInline(float3 origin, float3 direction)
{
    return TraceAnyHitInline(origin, direction, AO_RADIUS);
}

[numthreads(8, 8, 1)]
void InlineAmbientOcclusionCS(uint3 dispatchThreadID : SV_DispatchThreadID)
{
    uint width, height;
    g_renderTarget.GetDimensions(width, height);
    if (dispatchThreadID.x >= width || dispatchThreadID.y >= height)
    {
        return;
    }

    float3 rayDir;
    float3 origin;
    GenerateCameraRay(dispatchThreadID.xy, uint2(width, height), origin, rayDir);  // the sample's, with the thread's pixel

    float3 hitPosition, normal;
    float4 color = BackgroundColor;
    if (TracePrimaryInline(origin, rayDir, hitPosition, normal))
    {
        uint seed = Hash(dispatchThreadID.x ^ Hash(dispatchThreadID.y));
        uint escaped = 0;
        for (uint i = 0; i < AO_RAY_COUNT; ++i)
        {
            float u1 = UnitFloat(Hash(seed ^ (2 * i)));
            float u2 = UnitFloat(Hash(seed ^ (2 * i + 1)));
            float3 direction = CosineHemisphereDirection(normal, u1, u2);
            if (!TraceOcclusionInline(hitPosition + AO_ORIGIN_OFFSET * normal, direction))
            {
                escaped++;
            }
        }
        float ao = float(escaped) / float(AO_RAY_COUNT);
        color = float4(ao, ao, ao, 1);
    }
    g_renderTarget[dispatchThreadID.xy] = color;
}
