// refray: inline shadows for Microsoft's D3D12RaytracingProceduralGeometry sample (DXR 1.1, Shader Model 6.5).
//
// Written for refray (no public sample traces this scene's shadows inline). It changes one function of the
// sample's Raytracing.hlsl (microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/Raytracing.hlsl):
// TraceShadowRayAndReportIfHit traces its ray with a RayQuery instead of TraceRay, and the two closest-hit
// shaders that call it become MyClosestHitShader_Triangle_InlineShadow and MyClosestHitShader_AABB_InlineShadow
// (bodies unchanged otherwise). Everything else is the sample's file, included here.
//
// The lesson: TraceRay ran the procedural primitives' intersection shaders for the shadow ray; a RayQuery runs
// none. Its procedural candidates are intersected by the shader that owns the query, with the same intersection
// code, and committed with CommitProceduralPrimitiveHit. Without that loop body the ten procedural shapes cast
// no shadow (lesson scenes/lessons/inline-procedural-never-intersected.json).
//
// No shader table is involved in inline tracing, so what the intersection shaders read from their records'
// local root arguments (l_aabbCB, l_materialCB.stepScale) comes from one more global buffer,
// g_inlinePrimitives, indexed by the candidate's GeometryIndex (the AABB BLAS has one geometry per primitive).
//
// The sample's intersection helpers read RayTMin(), RayTCurrent() and RayFlags(). In a closest-hit shader those
// intrinsics describe the closest hit's own ray, not the query's, so the helpers are called with the query's
// values: RayTMin() -> q.RayTMin(), RayTCurrent() -> q.CommittedRayT(), RayFlags() -> q.RayFlags(). (The ports
// pass them as parameters: procedural/math's RayExtent in C++, macros around the include in GLSL.)
//
// The images equal the TraceRay scene's bit for bit: the same candidates meet the same intersection code with
// the same extent ([0, 10000] until a hit is committed, and a commit ends the search), and a shadow ray's
// answer is only "hit or not".

#include "Raytracing.hlsl"   // the sample's file: structs, resources, helpers, the other entry points

// One element per geometry of the AABB BLAS: what the records' local root arguments give the intersection
// shaders in the TraceRay version.
struct InlinePrimitive
{
    UINT intersectionShader;  // 0 MyIntersectionShader_AnalyticPrimitive, 1 ..._VolumetricPrimitive, 2 ..._SignedDistancePrimitive
    UINT instanceIndex;       // l_aabbCB.instanceIndex: the element of g_AABBPrimitiveAttributes
    UINT primitiveType;       // l_aabbCB.primitiveType
    float stepScale;          // l_materialCB.stepScale
};
StructuredBuffer<InlinePrimitive> g_inlinePrimitives : register(t4, space0);

// The intersection shaders' code for the query's current procedural candidate. Returns true with the hit's t and
// world normal when the candidate's primitive is hit inside [q.RayTMin(), q.CommittedRayT()].
template <uint QueryFlags>
bool IntersectCandidateProceduralPrimitive(RayQuery<QueryFlags> q, out float thit, out ProceduralPrimitiveAttributes attr)
{
    thit = 0;
    attr = (ProceduralPrimitiveAttributes)0;
    InlinePrimitive primitive = g_inlinePrimitives[q.CandidateGeometryIndex()];
    PrimitiveInstancePerFrameBuffer aabbAttribute = g_AABBPrimitiveAttributes[primitive.instanceIndex];

    // GetRayInAABBPrimitiveLocalSpace, with the candidate's object-space ray.
    Ray localRay;
    localRay.origin = mul(float4(q.CandidateObjectRayOrigin(), 1), aabbAttribute.bottomLevelASToLocalSpace).xyz;
    localRay.direction = mul(q.CandidateObjectRayDirection(), (float3x3) aabbAttribute.bottomLevelASToLocalSpace);

    // The helpers' RayTMin(), RayTCurrent() and RayFlags() are the query's here (see the top of this file).
    bool hit = false;
    switch (primitive.intersectionShader)
    {
    case 0: hit = RayAnalyticGeometryIntersectionTest(localRay, (AnalyticPrimitive::Enum) primitive.primitiveType, thit, attr); break;
    case 1: hit = RayVolumetricGeometryIntersectionTest(localRay, (VolumetricPrimitive::Enum) primitive.primitiveType, thit, attr, g_sceneCB.elapsedTime); break;
    case 2: hit = RaySignedDistancePrimitiveTest(localRay, (SignedDistancePrimitive::Enum) primitive.primitiveType, thit, attr, primitive.stepScale); break;
    }
    if (hit)
    {
        attr.normal = mul(attr.normal, (float3x3) aabbAttribute.localSpaceToBottomLevelAS);
        attr.normal = normalize(mul((float3x3) q.CandidateObjectToWorld3x4(), attr.normal));
    }
    return hit;
}

// True when the ray from origin along direction meets a surface in [0, tMax]: the query of the shadow rays, which the
// occlusion rays of InlineAmbientOcclusion.hlsl trace too.
bool TraceAnyHitInline(float3 origin, float3 direction, float tMax)
{
    RayDesc rayDesc;
    rayDesc.Origin = origin;
    rayDesc.Direction = direction;
    rayDesc.TMin = 0;
    rayDesc.TMax = tMax;

    // The TraceRay version's flags less SKIP_CLOSEST_HIT_SHADER, which a RayQuery may not carry (RQ-4): nothing
    // runs on a hit anyway.
    RayQuery<RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH> q;
    q.TraceRayInline(g_scene, RAY_FLAG_NONE, TraceRayParameters::InstanceMask, rayDesc);
    while (q.Proceed())
    {
        // FORCE_OPAQUE: the ground plane's triangles are committed inside Proceed (RQ-14) and never get here.
        if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE)
        {
            float thit;
            ProceduralPrimitiveAttributes attr;
            if (IntersectCandidateProceduralPrimitive(q, thit, attr))
            {
                q.CommitProceduralPrimitiveHit(thit);  // ACCEPT_FIRST_HIT_AND_END_SEARCH: the next Proceed returns false
            }
        }
    }
    return q.CommittedStatus() != COMMITTED_NOTHING;
}

// TraceShadowRayAndReportIfHit, traced inline: TMax 10000, as the TraceRay version.
bool TraceShadowRayInlineAndReportIfHit(in Ray ray, in UINT currentRayRecursionDepth)
{
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH)
    {
        return false;
    }
    return TraceAnyHitInline(ray.origin, ray.direction, 10000);
}

// MyClosestHitShader_Triangle with TraceShadowRayInlineAndReportIfHit; the rest of the body is the sample's.
[shader("closesthit")]
void MyClosestHitShader_Triangle_InlineShadow(inout RayPayload rayPayload, in BuiltInTriangleIntersectionAttributes attr)
{
    uint indexSizeInBytes = 2;
    uint indicesPerTriangle = 3;
    uint triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    uint baseIndex = PrimitiveIndex() * triangleIndexStride;
    const uint3 indices = Load3x16BitIndices(baseIndex, g_indices);
    float3 triangleNormal = g_vertices[indices[0]].normal;

    float3 hitPosition = HitWorldPosition();
    Ray shadowRay = { hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition) };
    bool shadowRayHit = TraceShadowRayInlineAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    float checkers = AnalyticalCheckersTexture(HitWorldPosition(), triangleNormal, g_sceneCB.cameraPosition.xyz, g_sceneCB.projectionToWorld);

    float4 reflectedColor = float4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        Ray reflectionRay = { HitWorldPosition(), reflect(WorldRayDirection(), triangleNormal) };
        float4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);
        float3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), triangleNormal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * float4(fresnelR, 1) * reflectionColor;
    }

    float4 phongColor = CalculatePhongLighting(l_materialCB.albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    float4 color = checkers * (phongColor + reflectedColor);

    float t = RayTCurrent();
    color = lerp(color, BackgroundColor, 1.0 - exp(-0.000002*t*t*t));
    rayPayload.color = color;
}

// MyClosestHitShader_AABB with TraceShadowRayInlineAndReportIfHit; the rest of the body is the sample's.
[shader("closesthit")]
void MyClosestHitShader_AABB_InlineShadow(inout RayPayload rayPayload, in ProceduralPrimitiveAttributes attr)
{
    float3 hitPosition = HitWorldPosition();
    Ray shadowRay = { hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition) };
    bool shadowRayHit = TraceShadowRayInlineAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    float4 reflectedColor = float4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        Ray reflectionRay = { HitWorldPosition(), reflect(WorldRayDirection(), attr.normal) };
        float4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);
        float3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), attr.normal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * float4(fresnelR, 1) * reflectionColor;
    }

    float4 phongColor = CalculatePhongLighting(l_materialCB.albedo, attr.normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    float4 color = phongColor + reflectedColor;

    float t = RayTCurrent();
    color = lerp(color, BackgroundColor, 1.0 - exp(-0.000002*t*t*t));
    rayPayload.color = color;
}
