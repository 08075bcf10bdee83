// Recording what TraceRay does, event by event: the data behind `refray explain` and the index maps.
//
// A dispatch with DispatchOptions::observer set reports every step of every ray to the observer: each
// TraceRay with its arguments, each candidate the traversal meets and why it was dropped, each record
// lookup with the indexing rule's four terms (IDX-1), each shader call, ReportHit result (IS-3..IS-6),
// any-hit decision (AHS-3, AHS-4), commit (TRV-4) and the end of the ray with the payload. Without an
// observer each event site costs one predictable branch and nothing is built.
#pragma once

#include <cstdint>
#include <string_view>

#include "emulator/shader_table.h"
#include "emulator/types.h"

namespace refray::dxr {

struct TraceEvent {
    enum class Kind : uint8_t {
        ShaderCall,    // a shader starts: stage, exportName, recordIndex, recordAddress (of its record)
        TraceRay,      // a TraceRay passed validation: the ray fields, payload = the payload passed in
        Candidate,     // the traversal met a candidate: instance, geometry, primitive, t (hit t or box entry)
        Skipped,       // the candidate was dropped before any shader ran for it: note says why
        RecordLookup,  // a record was read: table, terms (hit groups), recordIndex, recordAddress, exportName
        ReportHit,     // an intersection shader called ReportHit: t, hitKind, accepted, note
        AnyHit,        // an any-hit shader decided: note ("accept", "IgnoreHit", "AcceptHitAndEndSearch")
        Commit,        // a candidate became the closest hit: instance, geometry, primitive, t, hitKind
        TraceRayEnd,   // the ray is done: committed (hit) or not (miss); payload = what TraceRay returns
        // RayQuery (emulator/ray_query.h), each with queryId, stage and exportName of the owning shader. The query's
        // walk over its candidates reuses Candidate and Skipped (with queryId set).
        QueryInit,     // TraceRayInline: accelerationStructure, ray, rayFlags (dynamic), effectiveFlags (OR'd), mask
        QueryProceed,  // Proceed returned `accepted`: the candidate (instance.., procedural, t) when TRUE; note
        QueryCommit,   // a hit was committed: by the system or the shader (note), instance.., procedural, t
        QueryAbort,    // Abort: committed, t = CommittedRayT
    };
    Kind kind = Kind::ShaderCall;
    uvec3 launchIndex{0u};
    uint32_t queryId = 0;  // RayQuery events and the candidates of a query: the query's number on this launch (from 1)
    uint32_t depth = 0;  // the recursion level of the shaders this event belongs to (ray generation = 0)

    // TraceRay: its arguments (raw, as passed; the rule masks R and M).
    GpuVirtualAddress accelerationStructure = 0;
    RayDesc ray;
    uint32_t rayFlags = 0;
    uint32_t effectiveFlags = 0;  // rayFlags | the pipeline's SKIP_* flags (FLAG-5)
    uint32_t instanceInclusionMask = 0;
    uint32_t rayContribution = 0;
    uint32_t multiplier = 0;
    uint32_t missShaderIndex = 0;

    // Candidates and hits.
    uint32_t instanceIndex = 0;
    uint32_t instanceID = 0;
    uint32_t geometryIndex = 0;
    uint32_t primitiveIndex = 0;
    bool procedural = false;
    float t = 0.0f;
    uint32_t hitKind = 0;
    bool accepted = false;   // ReportHit: the hit was committed
    bool committed = false;  // TraceRayEnd: the ray hit something

    // Records. `terms` is set for hit-group lookups (hasTerms).
    std::string_view table;  // "hit-group table", "miss shader table", ...
    bool hasTerms = false;
    HitGroupIndexTerms terms;
    uint64_t recordIndex = 0;
    GpuVirtualAddress recordAddress = 0;
    uint64_t stride = 0;

    // Shaders: the stage and export (ShaderCall), or the entry a record holds (RecordLookup; empty: NULL).
    ShaderStage stage = ShaderStage::RayGeneration;
    std::string_view exportName;
    std::string_view note;  // a fixed phrase: why a candidate was skipped, what ReportHit or the AHS did

    // TraceRay and TraceRayEnd: the payload's type and bytes (valid only during the call).
    const void* payloadTypeId = nullptr;
    std::string_view payloadTypeName;  // mangled C++ name; TypeTag::name() demangles
    const uint8_t* payload = nullptr;
    uint32_t payloadSize = 0;
};

// Receives the events of a dispatch. Called on worker threads, concurrently for different launch
// indices; the events of one launch index arrive in program order from one thread.
class TraceObserver {
public:
    virtual ~TraceObserver() = default;
    virtual void onEvent(const TraceEvent& event) = 0;
};

}  // namespace refray::dxr
