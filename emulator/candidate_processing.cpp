// TRV-4 for one candidate: the TRV-2 interval, culling and opacity, the intersection shader and its ReportHit
// (IS-3..IS-10), the any-hit shader (AHS-3, AHS-4) and the commit.
#include "emulator/detail/candidate_processing.h"

#include <cmath>
#include <cstring>

#include "emulator/detail/candidate_rules.h"
#include "emulator/detail/record_lookup.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_events.h"
#include "emulator/limits.h"

namespace refray::dxr::detail {

namespace {

[[gnu::noinline]] void emitCommit(const ThreadState& ts, const RayState& rs, const HitInfo& hit) {
    TraceEvent e = event(ts, TraceEvent::Kind::Commit, rs.depth);
    setHit(e, hit);
    e.t = hit.t;
    e.hitKind = hit.hitKind;
    observer(ts)->onEvent(e);
}

// TRV-4 step 4 for the hit already written in rs.committedHit.
void commitInPlace(const ThreadState& ts, RayState& rs) {
    if (observer(ts)) emitCommit(ts, rs, rs.committedHit);
    rs.committed = true;
    rs.tCurrent = rs.committedHit.t;
}

void commit(const ThreadState& ts, RayState& rs, const HitInfo& hit) {  // TRV-4 step 4
    rs.committedHit = hit;
    commitInPlace(ts, rs);
}

enum class AnyHitOutcome { Accept, Ignore, AcceptAndEnd };

AnyHitOutcome runAnyHit(ThreadState& ts, RayState& rs, const RecordView& record, HitInfo& candidate) {
    Invocation inv = invocation(ts, ShaderStage::AnyHit, record.entry->anyHit, &record, rs.depth, &rs, &candidate);
    checkGlobalSignature(ts, siteOf(inv), *record.entry);
    checkPayload(ts, siteOf(inv), *inv.shader, rs.payloadType);
    AnyHitOutcome outcome = AnyHitOutcome::Accept;
    try {
        invoke(ts, inv, rs.payload, candidate.attributes);
    } catch (const IgnoreHitSignal&) {
        outcome = AnyHitOutcome::Ignore;
    } catch (const AcceptHitAndEndSearchSignal&) {
        outcome = AnyHitOutcome::AcceptAndEnd;
    }
    if (observer(ts)) {
        TraceEvent e = event(ts, TraceEvent::Kind::AnyHit, rs.depth);
        setHit(e, candidate);
        e.t = candidate.t;
        e.note = outcome == AnyHitOutcome::Ignore         ? "IgnoreHit: the candidate is dropped"
                 : outcome == AnyHitOutcome::AcceptAndEnd ? "AcceptHitAndEndSearch: commit and end the search"
                                                          : "accept (returned normally)";
        observer(ts)->onEvent(e);
    }
    return outcome;
}

// The ReportHit event (out of line: an event is large, and ReportHit runs for every hit an intersection shader finds).
[[gnu::noinline]] void emitReportHit(const ThreadState& ts, const Invocation& inv, float tHit, uint32_t hitKind,
                                     TypeTag type) {
    const RayState& rs = *inv.ray;
    const ProgramEntry& group = *inv.record->entry;
    TraceEvent e = event(ts, TraceEvent::Kind::ReportHit, rs.depth);
    setHit(e, *inv.hit);
    e.t = tHit;
    e.hitKind = hitKind;
    e.accepted = !std::isnan(tHit) && type == group.attributes && tHit >= rs.ray.TMin && tHit <= rs.tCurrent;
    e.note = std::isnan(tHit)               ? "rejected: THit is NaN (IS-3)"
             : !(type == group.attributes)  ? "rejected: the attributes are not the hit group's type (IS-5)"
             : !e.accepted                  ? "ignored: THit outside [RayTMin, RayTCurrent] (IS-3)"
             : !inv.candidateOpaque && group.anyHit ? "in range: the any-hit shader decides (IS-7)"
                                                    : "in range: committed (IS-6)";
    observer(ts)->onEvent(e);
}

// ReportHit's IS-3 (NaN THit), IS-5 and IS-4 reports (cold: out of the frame of every ReportHit).
[[gnu::cold, gnu::noinline]] void raiseNaNTHit(ThreadState& ts, const Site& site, float tHit) {
    raise(ts, site, diag("IS-3", "ReportHit called with a NaN THit; the hit is rejected").value("THit", tHit));
}

[[gnu::cold, gnu::noinline]] void raiseAttributeType(ThreadState& ts, const Site& site, const ProgramEntry& group,
                                                     TypeTag type) {
    raise(ts, site, diag("IS-5", "ReportHit attributes are not the type hit group '" + group.name + "' consumes")
                        .value("reported", type.name() + " (" + std::to_string(type.size) + " B)")
                        .value("expected", group.attributes.name() + " (" + std::to_string(group.attributes.size) + " B)"));
}

[[gnu::cold, gnu::noinline]] void raiseHitKind(ThreadState& ts, const Site& site, uint32_t hitKind) {
    raise(ts, site, diag("IS-4", "ReportHit HitKind outside 0..127 (254 and 255 mean triangle faces)")
                        .value("HitKind", hitKind, "0..127"));
}

}  // namespace

bool reportHit(Invocation& inv, float tHit, uint32_t hitKind, const void* attributes, TypeTag type) {
    ThreadState& ts = *inv.thread;
    RayState& rs = *inv.ray;
    const Site site = siteOf(inv);
    const ProgramEntry& group = *inv.record->entry;
    if (observer(ts)) emitReportHit(ts, inv, tHit, hitKind, type);
    if (std::isnan(tHit)) {
        raiseNaNTHit(ts, site, tHit);
        return false;
    }
    if (!(type == group.attributes)) {  // IS-5: checked on every call, in range or not
        raiseAttributeType(ts, site, group, type);
        return false;
    }
    if (tHit < rs.ray.TMin || tHit > rs.tCurrent) return false;  // IS-3: closed interval
    if (hitKind > kMaxProceduralHitKind) raiseHitKind(ts, site, hitKind);
    HitInfo candidate = *inv.hit;
    candidate.t = tHit;
    candidate.hitKind = hitKind;
    candidate.attributeType = type;
    std::memcpy(candidate.attributes, attributes, type.size);

    // IS-10: the search has ended, and so does the shader: by unwinding, or by its promised return.
    auto endShader = [&] {
        if (inv.shader->reportHitEnd == ReportHitEnd::Return && ts.dispatch->options.specialise) {
            inv.searchEnded = true;
            return true;
        }
        throw EndSearchSignal{};
    };
    if (!inv.candidateOpaque && group.anyHit) {  // IS-7: the AHS runs inside ReportHit
        switch (runAnyHit(ts, rs, *inv.record, candidate)) {
            case AnyHitOutcome::Ignore: return false;
            case AnyHitOutcome::AcceptAndEnd: commit(ts, rs, candidate); return endShader();
            case AnyHitOutcome::Accept: break;
        }
    }
    commit(ts, rs, candidate);  // IS-6
    if (rs.effectiveFlags & RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH) return endShader();  // FLAG-8
    return true;
}

void processTriangle(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site) {
    if (!(rs.ray.TMin < c.t && c.t < rs.tCurrent)) {  // TRV-2: open interval, current TCurrent
        if (observer(ts)) emitSkipped(ts, rs, "t outside (RayTMin, RayTCurrent) (TRV-2)");
        return;
    }
    const BuiltInstance& inst = rs.tlas->instances()[c.instanceIndex];
    const BuiltGeometry& geom = inst.blas->geometries()[c.geometryIndex];
    const uint32_t instanceFlags = inst.desc.Flags;

    const bool front = isFrontFacing(geom, c, instanceFlags);
    if (isFaceCulled(rs.effectiveFlags, instanceFlags, front)) {  // FLAG-10, FACE-5
        if (observer(ts))
            emitSkipped(ts, rs, front ? "front face culled: CULL_FRONT_FACING_TRIANGLES (FLAG-10)"
                                      : "back face culled: CULL_BACK_FACING_TRIANGLES (FLAG-10)");
        return;
    }
    const bool opaque = isOpaque(geom.flags, instanceFlags, rs.effectiveFlags);
    if (isOpacityCulled(rs.effectiveFlags, opaque)) {
        if (observer(ts)) emitSkipped(ts, rs, opaque ? "opaque, culled: CULL_OPAQUE (FLAG-11)" : "non-opaque, culled: CULL_NON_OPAQUE (FLAG-11)");
        return;  // FLAG-11
    }

    // The hit, field by field. An opaque triangle commits at once (OPQ-3: no any-hit shader), so its hit is written
    // where the commit keeps it: a HitInfo put together on the stack and copied was read back with wide loads across
    // its narrow stores (a store-forwarding stall per commit).
    const auto fill = [&](HitInfo& hit) {
        hit.instance = &inst;
        hit.instanceIndex = c.instanceIndex;
        hit.geometryIndex = c.geometryIndex;
        hit.primitiveIndex = c.primitiveIndex;
        hit.hitKind = front ? HIT_KIND_TRIANGLE_FRONT_FACE : HIT_KIND_TRIANGLE_BACK_FACE;  // FACE-4
        hit.t = c.t;
        hit.objectRayOrigin = c.objectRayOrigin;
        hit.objectRayDirection = c.objectRayDirection;
        const BuiltInTriangleIntersectionAttributes attributes{c.barycentrics};
        hit.attributeType = typeTag<BuiltInTriangleIntersectionAttributes>();
        std::memset(hit.attributes, 0, sizeof hit.attributes);
        std::memcpy(hit.attributes, &attributes, sizeof attributes);
    };
    if (opaque) {
        fill(rs.committedHit);
        commitInPlace(ts, rs);
        if (rs.effectiveFlags & RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH) rs.searchEnded = true;  // FLAG-8
        return;
    }
    HitInfo hit;
    fill(hit);

    bool endSearch = false;
    {  // OPQ-3: the record is needed only to find an AHS (IDX-12)
        RecordView record;
        if (lookupHitGroupRecord(ts, site, rs, hit, GeometryType::Triangles, record) && record.entry &&
            record.entry->anyHit) {
            switch (runAnyHit(ts, rs, record, hit)) {
                case AnyHitOutcome::Ignore: return;
                case AnyHitOutcome::AcceptAndEnd: endSearch = true; break;
                case AnyHitOutcome::Accept: break;
            }
        }
    }
    commit(ts, rs, hit);
    if (endSearch || (rs.effectiveFlags & RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH)) rs.searchEnded = true;  // FLAG-8
}

bool prepareIntersection(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site, HitInfo& box,
                         RecordView& record, Invocation& inv) {
    if (c.key > rs.tCurrent) {  // the box no longer overlaps [TMin, TCurrent]
        if (observer(ts)) emitSkipped(ts, rs, "the box starts beyond RayTCurrent: no intersection shader call");
        return false;
    }
    const BuiltInstance& inst = rs.tlas->instances()[c.instanceIndex];
    const BuiltGeometry& geom = inst.blas->geometries()[c.geometryIndex];
    const bool opaque = isOpaque(geom.flags, inst.desc.Flags, rs.effectiveFlags);
    if (isOpacityCulled(rs.effectiveFlags, opaque)) {
        if (observer(ts)) emitSkipped(ts, rs, opaque ? "opaque, culled: CULL_OPAQUE (FLAG-11)" : "non-opaque, culled: CULL_NON_OPAQUE (FLAG-11)");
        return false;  // FLAG-11: before the IS
    }

    // Field by field in place (a HitInfo() assigned was copied with wide loads across its narrow stores: a
    // store-forwarding stall per box). The lookup writes the whole record.
    box.instance = &inst;
    box.instanceIndex = c.instanceIndex;
    box.geometryIndex = c.geometryIndex;
    box.primitiveIndex = c.primitiveIndex;
    box.hitKind = 0;
    box.t = 0.0f;
    box.objectRayOrigin = c.objectRayOrigin;
    box.objectRayDirection = c.objectRayDirection;
    std::memset(box.attributes, 0, sizeof box.attributes);
    box.attributeType = TypeTag();

    if (!lookupHitGroupRecord(ts, site, rs, box, GeometryType::ProceduralPrimitiveAABBs, record)) return false;
    if (!record.entry) {  // OPQ-4: a NULL hit group has no IS, so no hit
        if (observer(ts)) emitSkipped(ts, rs, "NULL hit group: no intersection shader, no hit (OPQ-4)");
        return false;
    }

    setInvocation(inv, ts, ShaderStage::Intersection, record.entry->intersection, &record, rs.depth, &rs, &box);
    inv.candidateOpaque = opaque;
    checkGlobalSignature(ts, siteOf(inv), *record.entry);
    return true;
}

void runIntersection(ThreadState& ts, RayState& rs, Invocation& inv) {
    try {
        invoke(ts, inv, nullptr, nullptr);
        if (inv.searchEnded) rs.searchEnded = true;  // ReportHitEnd::Return: the IS returned after it
    } catch (const EndSearchSignal&) {
        rs.searchEnded = true;  // IS-6/IS-7/FLAG-8: the IS ended at the accepting ReportHit
    }
}

void processProcedural(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site) {
    HitInfo box;
    RecordView record;
    Invocation inv;
    if (prepareIntersection(ts, rs, c, site, box, record, inv)) runIntersection(ts, rs, inv);
}

}  // namespace refray::dxr::detail
