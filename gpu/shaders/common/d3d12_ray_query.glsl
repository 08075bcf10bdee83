// DXR 1.1's RayQuery (inline ray tracing) as GL_EXT_ray_query, for GLSL ports of D3D12 HLSL that trace inline. Not a
// port of one HLSL file: the DXR methods under their HLSL names, each one GL_EXT_ray_query call, except where SPIR-V
// leaves undefined what DXR defines (../shared/docs/dxr-semantics.md, 18e). Those are guarded here, with a
// RayQueryState kept beside each rayQueryEXT (// PORT: on each):
//   - CommittedRayT() with COMMITTED_NOTHING is RayDesc.TMax in DXR (RQ-27) and undefined for
//     rayQueryGetIntersectionTEXT(q, true): RayQuery_CommittedRayT returns the TMax it kept.
//   - Proceed() after it returned FALSE returns FALSE in DXR (RQ-12), undefined for rayQueryProceedEXT:
//     RayQuery_Proceed returns FALSE without calling it again.
//   - Abort() is legal at any time after TraceRayInline in DXR (RQ-15); rayQueryTerminateEXT only after a Proceed that
//     returned true: RayQuery_Abort calls it only then, and otherwise just ends the query.
// The names are crossed (18e): DXR's InstanceIndex is Vulkan's InstanceId, DXR's InstanceID Vulkan's
// InstanceCustomIndex.
//
// HLSL `RayQuery<F> q; q.TraceRayInline(AS, flags, mask, ray);` is
//   rayQueryEXT q; RayQueryState qs = RayQuery_TraceRayInline(q, AS, F, flags, mask, ray);
// and `q.Method()` is RayQuery_Method(q) or RayQuery_Method(q, qs). A rayQueryEXT passed to a function is passed by
// reference (glslang: a pointer parameter), as HLSL passes a RayQuery (RQ-7).
//
// Needs, in the including file: #extension GL_EXT_ray_query : require. RAY_FLAG_* come from
// common/d3d12_dxr_intrinsics.glsl.
#ifndef D3D12_RAY_QUERY_GLSL
#define D3D12_RAY_QUERY_GLSL

// CANDIDATE_TYPE and COMMITTED_STATUS: DXR's values are Vulkan's (RQ-17, RQ-18).
const uint CANDIDATE_NON_OPAQUE_TRIANGLE = gl_RayQueryCandidateIntersectionTriangleEXT;        // 0
const uint CANDIDATE_PROCEDURAL_PRIMITIVE = gl_RayQueryCandidateIntersectionAABBEXT;           // 1
const uint COMMITTED_NOTHING = gl_RayQueryCommittedIntersectionNoneEXT;                         // 0
const uint COMMITTED_TRIANGLE_HIT = gl_RayQueryCommittedIntersectionTriangleEXT;                // 1
const uint COMMITTED_PROCEDURAL_PRIMITIVE_HIT = gl_RayQueryCommittedIntersectionGeneratedEXT;   // 2

// HLSL's RayDesc.
struct RayDesc
{
    vec3 Origin;
    float TMin;
    vec3 Direction;
    float TMax;
};

// What a DXR RayQuery defines that a rayQueryEXT does not keep, or keeps only where SPIR-V defines it.
struct RayQueryState
{
    float tMax;      // RayDesc.TMax: CommittedRayT() while nothing is committed (Vulkan has no TMax getter)
    bool finished;   // a Proceed returned FALSE, or Abort was called: Proceed returns FALSE from now on
    bool candidate;  // the last Proceed returned TRUE: the only state in which rayQueryTerminateEXT is defined
#if defined(REFRAY_AOV_FIRST_QUERY)
    bool first;      // the invocation's first TraceRayInline (refray's AOV, below)
#endif
};

#if defined(REFRAY_AOV_FIRST_QUERY)
// refray's index maps of a compute shader (not DXR; docs/vulkan-backend.md, "AOVs"). The build compiles every .comp a
// second time with this define (<Export>.aov.comp.spv). The shader then also records, when its invocation's first
// query finishes (Proceed returns FALSE), that query's committed hit: the invocation (x, y, z) is pixel (x, y) of
// plane z, and at 5 * (its index in the dispatch's row-major thread grid) go five uint32: the committed status
// (COMMITTED_TRIANGLE_HIT or COMMITTED_PROCEDURAL_PRIMITIVE_HIT), InstanceIndex, InstanceID, GeometryIndex,
// PrimitiveIndex. A miss, a thread that never traces and a first query that never finishes leave 0xFFFFFFFF (the
// host fills the buffer with it). Set 0, binding 1000, as the AOV closest hit's (gpu/shaders/aov).
#if !defined(DXR_STAGE_COMPUTE)
#error REFRAY_AOV_FIRST_QUERY is for compute shaders (ray-tracing stages get the AOV closest hit instead)
#endif
layout(set = 0, binding = 1000, scalar) buffer RefrayAovValues
{
    uint values[];
} refray_aov;
bool refray_aovFirstQueryTraced = false;

void Refray_RecordFirstQuery(rayQueryEXT q)
{
    const uint status = rayQueryGetIntersectionTypeEXT(q, true);
    if (status == gl_RayQueryCommittedIntersectionNoneEXT)
    {
        return;
    }
    const uvec3 grid = gl_NumWorkGroups * gl_WorkGroupSize;
    const uvec3 id = gl_GlobalInvocationID;
    const uint base = 5u * ((id.z * grid.y + id.y) * grid.x + id.x);
    refray_aov.values[base + 0u] = status;
    refray_aov.values[base + 1u] = uint(rayQueryGetIntersectionInstanceIdEXT(q, true));           // DXR InstanceIndex
    refray_aov.values[base + 2u] = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true));  // DXR InstanceID
    refray_aov.values[base + 3u] = uint(rayQueryGetIntersectionGeometryIndexEXT(q, true));
    refray_aov.values[base + 4u] = uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true));
}
#endif

// q.TraceRayInline(as, rayFlags, mask, ray) of a RayQuery<templateFlags>. Vulkan has no template flags: they are
// OR'd into the dynamic ones (RQ-3), as dxil-spirv does. Only the low 8 bits of the mask count, in both APIs (RQ-10).
RayQueryState RayQuery_TraceRayInline(rayQueryEXT q, accelerationStructureEXT as, uint templateFlags, uint rayFlags,
                                      uint instanceInclusionMask, RayDesc ray)
{
    rayQueryInitializeEXT(q, as, templateFlags | rayFlags, instanceInclusionMask & 0xFFu, ray.Origin, ray.TMin,
                          ray.Direction, ray.TMax);
#if defined(REFRAY_AOV_FIRST_QUERY)
    const bool first = !refray_aovFirstQueryTraced;
    refray_aovFirstQueryTraced = true;
    return RayQueryState(ray.TMax, false, false, first);
#else
    return RayQueryState(ray.TMax, false, false);
#endif
}

// q.Proceed().
// PORT: after a FALSE, rayQueryProceedEXT is not called again (undefined in SPIR-V; FALSE again in DXR, RQ-12).
bool RayQuery_Proceed(rayQueryEXT q, inout RayQueryState s)
{
    if (s.finished)
    {
        return false;
    }
    s.candidate = rayQueryProceedEXT(q);
    s.finished = !s.candidate;
#if defined(REFRAY_AOV_FIRST_QUERY)
    if (s.finished && s.first)
    {
        Refray_RecordFirstQuery(q);
    }
#endif
    return s.candidate;
}

// q.Abort().
// PORT: rayQueryTerminateEXT only where the last Proceed returned true (undefined otherwise in SPIR-V); elsewhere DXR's
// Abort only finishes the query (RQ-15), which the state does by itself.
void RayQuery_Abort(rayQueryEXT q, inout RayQueryState s)
{
    if (s.candidate)
    {
        rayQueryTerminateEXT(q);
    }
#if defined(REFRAY_AOV_FIRST_QUERY)
    if (!s.finished && s.first)
    {
        Refray_RecordFirstQuery(q);
    }
#endif
    s.candidate = false;
    s.finished = true;
}

uint RayQuery_CandidateType(rayQueryEXT q) { return rayQueryGetIntersectionTypeEXT(q, false); }
uint RayQuery_CommittedStatus(rayQueryEXT q) { return rayQueryGetIntersectionTypeEXT(q, true); }

// q.CommitNonOpaqueTriangleHit() / q.CommitProceduralPrimitiveHit(t). t must lie in [RayTMin(), CommittedRayT()] in
// both APIs (RQ-22; VUID-RuntimeSpirv-OpRayQueryGenerateIntersectionKHR-06353): the caller's intersection test
// checks it.
void RayQuery_CommitNonOpaqueTriangleHit(rayQueryEXT q) { rayQueryConfirmIntersectionEXT(q); }
void RayQuery_CommitProceduralPrimitiveHit(rayQueryEXT q, float t) { rayQueryGenerateIntersectionEXT(q, t); }

// q.RayFlags(): the template and dynamic flags OR'd (RQ-26), as RayQuery_TraceRayInline passed them.
uint RayQuery_RayFlags(rayQueryEXT q) { return rayQueryGetRayFlagsEXT(q); }
float RayQuery_RayTMin(rayQueryEXT q) { return rayQueryGetRayTMinEXT(q); }
vec3 RayQuery_WorldRayOrigin(rayQueryEXT q) { return rayQueryGetWorldRayOriginEXT(q); }
vec3 RayQuery_WorldRayDirection(rayQueryEXT q) { return rayQueryGetWorldRayDirectionEXT(q); }

// q.CommittedRayT().
// PORT: TMax while nothing is committed (RQ-27); rayQueryGetIntersectionTEXT(q, true) is undefined then in SPIR-V
// (DirectXShaderCompiler issue 7860), and lavapipe may crash on it.
float RayQuery_CommittedRayT(rayQueryEXT q, RayQueryState s)
{
    if (rayQueryGetIntersectionTypeEXT(q, true) == COMMITTED_NOTHING)
    {
        return s.tMax;
    }
    return rayQueryGetIntersectionTEXT(q, true);
}

// Candidate* getters, valid after a Proceed that returned TRUE (RQ-28).
// PORT: Candidate/CommittedInstanceIndex is Vulkan's InstanceId, Candidate/CommittedInstanceID its InstanceCustomIndex.
uint RayQuery_CandidateInstanceIndex(rayQueryEXT q) { return uint(rayQueryGetIntersectionInstanceIdEXT(q, false)); }
uint RayQuery_CandidateInstanceID(rayQueryEXT q) { return uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, false)); }
uint RayQuery_CandidateGeometryIndex(rayQueryEXT q) { return uint(rayQueryGetIntersectionGeometryIndexEXT(q, false)); }
uint RayQuery_CandidatePrimitiveIndex(rayQueryEXT q) { return uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, false)); }
vec3 RayQuery_CandidateObjectRayOrigin(rayQueryEXT q) { return rayQueryGetIntersectionObjectRayOriginEXT(q, false); }
vec3 RayQuery_CandidateObjectRayDirection(rayQueryEXT q) { return rayQueryGetIntersectionObjectRayDirectionEXT(q, false); }
// HLSL float3x4 (3 rows, 4 columns) is GLSL mat4x3 (4 columns of 3): the same matrix, column-vector convention.
mat4x3 RayQuery_CandidateObjectToWorld3x4(rayQueryEXT q) { return rayQueryGetIntersectionObjectToWorldEXT(q, false); }

// Committed* node getters, valid with COMMITTED_TRIANGLE_HIT or COMMITTED_PROCEDURAL_PRIMITIVE_HIT (RQ-29).
uint RayQuery_CommittedInstanceIndex(rayQueryEXT q) { return uint(rayQueryGetIntersectionInstanceIdEXT(q, true)); }
uint RayQuery_CommittedInstanceID(rayQueryEXT q) { return uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)); }
uint RayQuery_CommittedGeometryIndex(rayQueryEXT q) { return uint(rayQueryGetIntersectionGeometryIndexEXT(q, true)); }
uint RayQuery_CommittedPrimitiveIndex(rayQueryEXT q) { return uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true)); }

#endif  // D3D12_RAY_QUERY_GLSL
