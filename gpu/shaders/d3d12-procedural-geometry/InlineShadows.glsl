// Ports InlineShadows.hlsl of refray (scenes/inline/InlineShadows.hlsl; written for refray over
// microsoft/DirectX-Graphics-Samples@357ade6e, Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/
// Raytracing.hlsl): g_inlinePrimitives, IntersectCandidateProceduralPrimitive and TraceShadowRayInlineAndReportIfHit.
// Its two closest-hit shaders are MyClosestHitShader_{Triangle,AABB}_InlineShadow.rchit; the compute shader of
// InlineAmbientOcclusion.hlsl, which includes this file, is InlineAmbientOcclusionCS.comp.
//
// The including file defines its stage (DXR_STAGE_CLOSEST_HIT with LOCAL_ROOT_SIGNATURE_TRIANGLE or
// LOCAL_ROOT_SIGNATURE_AABB, or DXR_STAGE_COMPUTE) and enables GL_EXT_ray_query, GL_EXT_scalar_block_layout,
// GL_EXT_spirv_intrinsics and GL_GOOGLE_include_directive (and GL_EXT_ray_tracing in a closest hit).
//
// Bindings: Raytracing.glsl's, and
//   set 0 binding 104  t4  g_inlinePrimitives  root SRV, StructuredBuffer<InlinePrimitive>, stride 16 (scalar):
//                                              intersectionShader 0, instanceIndex 4, primitiveType 8, stepScale 12
//
// The sample's intersection helpers (AnalyticPrimitives, VolumetricPrimitives, SignedDistancePrimitives, IsCulled,
// IsAValidHit) read RayTMin(), RayTCurrent() and RayFlags(). For a query's candidate they must be the query's TMin,
// committed t and flags, not the closest hit's own ray (gl_RayTmaxEXT of a closest hit is its hit's t, not the
// query's), as InlineShadows.hlsl says at its top. So Raytracing.glsl (which includes the helpers) is included here
// with those three names as macros for g_queryRayTMin, g_queryRayTCurrent and g_queryRayFlags, which
// IntersectCandidateProceduralPrimitive sets from the query before it calls a helper; after the include they are the
// stage's own again (a closest hit's RayTCurrent() for its fog, HitWorldPosition() for its shading point).
#ifndef INLINESHADOWS_GLSL
#define INLINESHADOWS_GLSL

#include "common/d3d12_hlsl_intrinsics.glsl"
#include "common/d3d12_dxr_intrinsics.glsl"
#include "common/d3d12_ray_query.glsl"

// PORT: the extent the sample's intersection helpers test a candidate against: the query's RayTMin(), CommittedRayT()
// and RayFlags() (C++: procedural/math's RayExtent parameter; GLSL has no pointer to the query, so its values).
float g_queryRayTMin = 0.0;
float g_queryRayTCurrent = 0.0;
uint g_queryRayFlags = 0u;

#define DXR_RAY_EXTENT_OF_QUERY
#define RayTMin() g_queryRayTMin
#define RayTCurrent() g_queryRayTCurrent
#define RayFlags() g_queryRayFlags
#include "d3d12-procedural-geometry/Raytracing.glsl"   // the sample's file: structs, resources, helpers
#undef RayTMin
#undef RayTCurrent
#undef RayFlags

// One element per geometry of the AABB BLAS: what the records' local root arguments give the intersection
// shaders in the TraceRay version.
struct InlinePrimitive
{
    uint intersectionShader;  // 0 MyIntersectionShader_AnalyticPrimitive, 1 ..._VolumetricPrimitive, 2 ..._SignedDistancePrimitive
    uint instanceIndex;       // l_aabbCB.instanceIndex: the element of g_AABBPrimitiveAttributes
    uint primitiveType;       // l_aabbCB.primitiveType
    float stepScale;          // l_materialCB.stepScale
};
layout(set = 0, binding = 104, scalar) readonly buffer InlinePrimitiveBuffer
{
    InlinePrimitive g_inlinePrimitives[];
};

// The intersection shaders' code for the query's current procedural candidate. Returns true with the hit's t and
// world normal when the candidate's primitive is hit inside [q.RayTMin(), q.CommittedRayT()].
// PORT: HLSL's template over the query's flags is not needed: a rayQueryEXT has no template flags (they are OR'd in
// at RayQuery_TraceRayInline). The query's state travels beside it (common/d3d12_ray_query.glsl).
bool IntersectCandidateProceduralPrimitive(rayQueryEXT q, RayQueryState qs, out float thit, out ProceduralPrimitiveAttributes attr)
{
    thit = 0;
    attr = ProceduralPrimitiveAttributes(vec3(0)); // (ProceduralPrimitiveAttributes)0
    InlinePrimitive primitive = g_inlinePrimitives[RayQuery_CandidateGeometryIndex(q)];
    PrimitiveInstancePerFrameBuffer aabbAttribute = g_AABBPrimitiveAttributes[primitive.instanceIndex];

    // GetRayInAABBPrimitiveLocalSpace, with the candidate's object-space ray.
    // PORT: HLSL mul(rowVector, M) is rowVector * M; (float3x3)M is mat3(M), the upper-left 3x3.
    Ray localRay;
    localRay.origin = (vec4(RayQuery_CandidateObjectRayOrigin(q), 1) * aabbAttribute.bottomLevelASToLocalSpace).xyz;
    localRay.direction = RayQuery_CandidateObjectRayDirection(q) * mat3(aabbAttribute.bottomLevelASToLocalSpace);

    // The helpers' RayTMin(), RayTCurrent() and RayFlags() are the query's here (see the top of this file).
    // PORT: CommittedRayT() is TMax while nothing is committed (RayQuery_CommittedRayT: undefined in SPIR-V).
    g_queryRayTMin = RayQuery_RayTMin(q);
    g_queryRayTCurrent = RayQuery_CommittedRayT(q, qs);
    g_queryRayFlags = RayQuery_RayFlags(q);
    bool hit = false;
    switch (primitive.intersectionShader)
    {
    case 0u: hit = RayAnalyticGeometryIntersectionTest(localRay, primitive.primitiveType, thit, attr); break;
    case 1u: hit = RayVolumetricGeometryIntersectionTest(localRay, primitive.primitiveType, thit, attr, g_sceneCB.elapsedTime); break;
    case 2u: hit = RaySignedDistancePrimitiveTest(localRay, primitive.primitiveType, thit, attr, primitive.stepScale); break;
    }
    if (hit)
    {
        // PORT: mul(n, (float3x3)M) is n * mat3(M); mul((float3x3)ObjectToWorld3x4(), n) is mat3(ObjectToWorld) * n.
        attr.normal = attr.normal * mat3(aabbAttribute.localSpaceToBottomLevelAS);
        attr.normal = normalize(mat3(RayQuery_CandidateObjectToWorld3x4(q)) * attr.normal);
    }
    return hit;
}

// The lesson variants (scenes/lessons/, InlineVariant in procedural/d3d12/d3d12_shaders.cpp) are the same closest hits
// compiled with one of these defined: INLINE_VARIANT_SEARCH_ALL_HITS drops ACCEPT_FIRST_HIT_AND_END_SEARCH from the
// shadow query, INLINE_VARIANT_IGNORE_PROCEDURAL never intersects its procedural candidates.
#ifdef INLINE_VARIANT_SEARCH_ALL_HITS
#define INLINE_SHADOW_QUERY_FLAGS (RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE)
#else
#define INLINE_SHADOW_QUERY_FLAGS (RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH)
#endif

// True when the ray from origin along direction meets a surface in [0, tMax]: the query of the shadow rays, which the
// occlusion rays of InlineAmbientOcclusion.glsl trace too.
bool TraceAnyHitInline(vec3 origin, vec3 direction, float tMax)
{
    RayDesc rayDesc;
    rayDesc.Origin = origin;
    rayDesc.Direction = direction;
    rayDesc.TMin = 0;
    rayDesc.TMax = tMax;

    // The TraceRay version's flags less SKIP_CLOSEST_HIT_SHADER, which a RayQuery may not carry (RQ-4): nothing
    // runs on a hit anyway.
    // PORT: RayQuery<F> q; q.TraceRayInline(...) is a rayQueryEXT and its RayQueryState (common/d3d12_ray_query.glsl).
    // The mask is TraceRayParameters::InstanceMask, as the HLSL passes it (not a specialization constant: no scene
    // overrides an inline query's arguments).
    rayQueryEXT q;
    RayQueryState qs = RayQuery_TraceRayInline(q, g_scene,
        INLINE_SHADOW_QUERY_FLAGS,
        RAY_FLAG_NONE, TraceRayParameters_InstanceMask, rayDesc);
    while (RayQuery_Proceed(q, qs))
    {
        // FORCE_OPAQUE: the ground plane's triangles are committed inside Proceed (RQ-14) and never get here.
#ifndef INLINE_VARIANT_IGNORE_PROCEDURAL  // LESSON: without this branch no procedural candidate is intersected
        if (RayQuery_CandidateType(q) == CANDIDATE_PROCEDURAL_PRIMITIVE)
        {
            float thit;
            ProceduralPrimitiveAttributes attr;
            if (IntersectCandidateProceduralPrimitive(q, qs, thit, attr))
            {
                RayQuery_CommitProceduralPrimitiveHit(q, thit);  // ACCEPT_FIRST_HIT_AND_END_SEARCH: the next Proceed returns false
            }
        }
#endif
    }
    return RayQuery_CommittedStatus(q) != COMMITTED_NOTHING;
}

// TraceShadowRayAndReportIfHit, traced inline: TMax 10000, as the TraceRay version.
bool TraceShadowRayInlineAndReportIfHit(in Ray ray, in uint currentRayRecursionDepth)
{
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH)
    {
        return false;
    }
    return TraceAnyHitInline(ray.origin, ray.direction, 10000.0);
}

#endif // INLINESHADOWS_GLSL
