// RayQuery (dxr-semantics.md section 18): the state machine behind RayQueryObject, its candidates, commits and
// getters, each checked against the specification's tables (RQ-19), with trace events for `refray explain`.
#include "emulator/ray_query.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "emulator/detail/candidate_gathering.h"
#include "emulator/detail/candidate_rules.h"
#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_events.h"
#include "emulator/detail/trace_ray.h"
#include "emulator/lane_mask.h"
#include "emulator/shader_api.h"

namespace refray::dxr {

namespace detail {

// Where the query is in the tables of DXR §RayQuery intrinsics.
enum class QueryPhase : uint8_t {
    Fresh,        // constructed, no TraceRayInline yet: only TraceRayInline is valid
    Initialised,  // TraceRayInline called, Proceed not yet (first table)
    Candidate,    // the last Proceed returned TRUE (second table)
    Finished,     // the last Proceed returned FALSE, or Abort was called (third table)
};

const char* phaseName(QueryPhase p) {
    switch (p) {
        case QueryPhase::Fresh: return "not initialised (no TraceRayInline yet)";
        case QueryPhase::Initialised: return "initialised, Proceed not called yet";
        case QueryPhase::Candidate: return "a candidate (the last Proceed returned TRUE)";
        case QueryPhase::Finished: return "finished (the last Proceed returned FALSE, or Abort)";
    }
    return "unknown";
}

const char* committedStatusName(uint32_t s) {
    switch (s) {
        case COMMITTED_NOTHING: return "COMMITTED_NOTHING";
        case COMMITTED_TRIANGLE_HIT: return "COMMITTED_TRIANGLE_HIT";
        case COMMITTED_PROCEDURAL_PRIMITIVE_HIT: return "COMMITTED_PROCEDURAL_PRIMITIVE_HIT";
    }
    return "?";
}

// A candidate or committed hit as the getters report it.
struct QueryHit {
    const BuiltInstance* instance = nullptr;
    uint32_t instanceIndex = 0, geometryIndex = 0, primitiveIndex = 0;
    bool procedural = false;
    float t = 0.0f;  // triangles: the hit t; procedural candidates: the box entry; committed: the committed t
    vec2 barycentrics{0.0f};
    bool frontFace = false;
    bool nonOpaque = false;  // candidates: OPQ-1 opacity from geometry, instance and ray flags
    vec3 objectRayOrigin{0.0f}, objectRayDirection{0.0f};
};

struct RayQueryState {
    uint32_t handles = 0;  // the RayQueryObjects that refer to it
    Invocation* inv = nullptr;
    uint32_t templateFlags = 0;
    uint32_t rayQueryFlags = 0;
    uint32_t id = 0;  // the query's number on this launch, from 1 (TraceRayInline renumbers)

    QueryPhase phase = QueryPhase::Fresh;
    bool proceeded = false;           // Proceed was called since TraceRayInline
    bool searchEnded = false;         // ACCEPT_FIRST_HIT_AND_END_SEARCH after a commit (RQ-16)
    bool candidateCommitted = false;  // the current triangle candidate was committed (RQ-21)
    RayState rs;                      // the ray, its flags and TLAS (tCurrent = CommittedRayT)
    uint32_t dynamicFlags = 0;
    std::vector<Candidate> candidates;
    size_t next = 0;
    QueryHit candidate;
    uint32_t status = COMMITTED_NOTHING;
    QueryHit committed;
};

namespace {

ThreadState& threadOf(const RayQueryState& q) { return *q.inv->thread; }

// The diagnostic of a call in a state the tables do not list: the call, the query's state and its committed status.
DiagnosticBuilder stateDiag(const RayQueryState& q, const char* rule, const std::string& call, const std::string& why) {
    return diag(rule, call + "() " + why)
        .value("query", q.id)
        .value("state", phaseName(q.phase))
        .value("CommittedStatus", committedStatusName(q.status));
}

void raiseQuery(const RayQueryState& q, const Diagnostic& d) { raise(threadOf(q), siteOf(*q.inv), d); }

// IS-10: an intersection shader registered with ReportHitEnd::Return uses nothing after a ReportHit that ended the
// search, its queries included.
void requireLive(const RayQueryState& q, const char* call) {
    if (q.inv->searchEnded) [[unlikely]]
        stageError(*q.inv, "IS-10",
                   "intersection shader '" + q.inv->shader->name + "' is registered with ReportHitEnd::Return (each "
                       "ReportHit is its last action) but called RayQuery::" + call + "() after a ReportHit that "
                       "ended the search");
}

// A use DXR defines and SPIR-V does not (18e): a note, counted per kind (NoteTally).
enum class SpirvUndefined : uint8_t { ProceedAfterFalse, AbortWithoutCandidate, CommittedRayTOfNothing };

void spirvNote(const RayQueryState& q, SpirvUndefined kind, const char* rule, const char* what) {
    ThreadState& ts = threadOf(q);
    if (countRepeatedNote(ts, ts.queryNotes[size_t(kind)])) return;  // most calls: no site to build
    note(ts, siteOf(*q.inv), ts.queryNotes[size_t(kind)], [&] {
        return Diagnostic(DiagnosticBuilder(rule,
                                            std::string(what) + ": defined in DXR, undefined in SPIR-V (a Vulkan port "
                                                                "must guard it; dxr-semantics.md 18e)",
                                            Severity::Note)
                              .value("state", phaseName(q.phase)));
    });
}

TraceEvent queryEvent(const RayQueryState& q, TraceEvent::Kind kind) {
    TraceEvent e = event(threadOf(q), kind, q.inv->depth);
    e.queryId = q.id;
    e.stage = q.inv->stage;
    e.exportName = q.inv->shader ? std::string_view(q.inv->shader->name) : std::string_view();
    return e;
}

void setQueryHit(TraceEvent& e, const QueryHit& h) {
    e.instanceIndex = h.instanceIndex;
    e.instanceID = h.instance ? h.instance->desc.InstanceID : 0;
    e.geometryIndex = h.geometryIndex;
    e.primitiveIndex = h.primitiveIndex;
    e.procedural = h.procedural;
    e.t = h.t;
}

void emitQuerySkip(const RayQueryState& q, const QueryHit& h, std::string_view why) {
    if (!observer(threadOf(q))) return;
    TraceEvent e = queryEvent(q, TraceEvent::Kind::Skipped);
    setQueryHit(e, h);
    e.note = why;
    observer(threadOf(q))->onEvent(e);
}

// The commit of the hit already in q.committed.
void commitInPlace(RayQueryState& q, uint32_t status, std::string_view how) {
    const QueryHit& hit = q.committed;
    q.status = status;
    q.rs.tCurrent = hit.t;
    threadOf(q).stats.queryCommits++;
    if (q.rs.effectiveFlags & RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH) q.searchEnded = true;  // RQ-16
    ThreadState& ts = threadOf(q);
    if (observer(ts)) {
        TraceEvent e = queryEvent(q, TraceEvent::Kind::QueryCommit);
        setQueryHit(e, hit);
        e.committed = true;
        e.note = how;
        observer(ts)->onEvent(e);
    }
}

void commit(RayQueryState& q, const QueryHit& hit, uint32_t status, std::string_view how) {
    q.committed = hit;
    commitInPlace(q, status, how);
}

// `h` made the hit of candidate `c`, field by field in place: a QueryHit put together on the stack and copied was
// read back with wide loads across its narrow stores (a store-forwarding stall per candidate).
void setHitOf(QueryHit& h, const RayState& rs, const Candidate& c) {
    h.instance = &rs.tlas->instances()[c.instanceIndex];
    h.instanceIndex = c.instanceIndex;
    h.geometryIndex = c.geometryIndex;
    h.primitiveIndex = c.primitiveIndex;
    h.procedural = c.procedural;
    h.t = c.procedural ? c.key : c.t;
    h.barycentrics = c.barycentrics;
    h.frontFace = false;
    h.nonOpaque = false;
    h.objectRayOrigin = c.objectRayOrigin;
    h.objectRayDirection = c.objectRayDirection;
}

// The next candidate that needs the shader, committing opaque triangles on the way (RQ-14); false at the end.
bool advance(RayQueryState& q) {
    ThreadState& ts = threadOf(q);
    RayState& rs = q.rs;
    while (q.next < q.candidates.size() && !q.searchEnded) {
        const Candidate& c = q.candidates[q.next++];
        QueryHit& h = q.candidate;  // the candidate a TRUE Proceed shows; a skipped one is overwritten
        setHitOf(h, rs, c);
        if (observer(ts)) {
            TraceEvent e = queryEvent(q, TraceEvent::Kind::Candidate);
            setQueryHit(e, h);
            observer(ts)->onEvent(e);
        }
        const BuiltInstance& inst = *h.instance;
        const BuiltGeometry& geom = inst.blas->geometries()[c.geometryIndex];
        const bool opaque = isOpaque(geom.flags, inst.desc.Flags, rs.effectiveFlags);
        h.nonOpaque = !opaque;
        if (!c.procedural) {
            if (!(rs.ray.TMin < c.t && c.t < rs.tCurrent)) {  // RQ-20: TMin < t < CommittedRayT
                emitQuerySkip(q, h, "t outside (RayTMin, CommittedRayT)");
                continue;
            }
            h.frontFace = isFrontFacing(geom, c, inst.desc.Flags);
            if (isFaceCulled(rs.effectiveFlags, inst.desc.Flags, h.frontFace)) {
                emitQuerySkip(q, h, h.frontFace ? "front face culled: CULL_FRONT_FACING_TRIANGLES (FLAG-10)"
                                                : "back face culled: CULL_BACK_FACING_TRIANGLES (FLAG-10)");
                continue;
            }
            if (isOpacityCulled(rs.effectiveFlags, opaque)) {
                emitQuerySkip(q, h, opaque ? "opaque, culled: CULL_OPAQUE (FLAG-11)" : "non-opaque, culled: CULL_NON_OPAQUE (FLAG-11)");
                continue;
            }
            if (opaque) {  // RQ-14: committed by the system, never seen by the shader
                setHitOf(q.committed, rs, c);  // in place, as h (not copied from it: the same stall)
                q.committed.frontFace = h.frontFace;
                commitInPlace(q, COMMITTED_TRIANGLE_HIT, "opaque triangle: committed inside Proceed (RQ-14)");
                continue;
            }
        } else {
            if (c.key > rs.tCurrent) {
                emitQuerySkip(q, h, "the box starts beyond CommittedRayT");
                continue;
            }
            if (isOpacityCulled(rs.effectiveFlags, opaque)) {  // RQ-24: the system's only use of the opacity
                emitQuerySkip(q, h, opaque ? "opaque, culled: CULL_OPAQUE (FLAG-11)" : "non-opaque, culled: CULL_NON_OPAQUE (FLAG-11)");
                continue;
            }
        }
        q.candidateCommitted = false;
        return true;
    }
    return false;
}

}  // namespace

}  // namespace detail

using detail::QueryPhase;
using detail::RayQueryState;

namespace {

// The states this worker thread's queries no longer use, at most kSpareQueryStates of them. A state never leaves the
// thread that made its query (its invocation runs there), and each thread keeps its own.
constexpr size_t kSpareQueryStates = 256;
thread_local std::vector<std::unique_ptr<RayQueryState>> tSpareQueryStates;

// A fresh state (Fresh, nothing traced), a spare one where the thread has one: its candidate list keeps its storage.
RayQueryState* takeQueryState() {
    if (tSpareQueryStates.empty()) return new RayQueryState();
    RayQueryState* q = tSpareQueryStates.back().release();
    tSpareQueryStates.pop_back();
    std::vector<detail::Candidate> candidates = std::move(q->candidates);
    candidates.clear();
    // Made anew where it lies (a fresh state assigned over it was put together on the stack and copied, with wide
    // loads across its narrow stores: a store-forwarding stall per query).
    std::destroy_at(q);
    std::construct_at(q);
    q->candidates = std::move(candidates);
    return q;
}

void releaseQueryState(RayQueryState* q) {
    if (!q || --q->handles > 0) return;
    if (tSpareQueryStates.size() < kSpareQueryStates) tSpareQueryStates.emplace_back(q);
    else delete q;
}

}  // namespace

RayQueryObject::RayQueryObject(const RayQueryObject& other) : state_(other.state_) { ++state_->handles; }

RayQueryObject& RayQueryObject::operator=(const RayQueryObject& other) {
    ++other.state_->handles;  // first: assigning a handle to itself keeps its state
    releaseQueryState(state_);
    state_ = other.state_;
    return *this;
}

RayQueryObject::~RayQueryObject() { releaseQueryState(state_); }

RayQueryObject::RayQueryObject(ShaderContext& ctx, uint32_t templateRayFlags, uint32_t rayQueryFlags)
    : state_(nullptr) {
    // The checks first: a constructor that throws leaves no handle to give the state back.
    ctx.requireLive("RayQuery");
    const ShaderExport* shader = ctx.inv_.shader;
    if (shader && std::find(shader->rayQueryFlags.begin(), shader->rayQueryFlags.end(), templateRayFlags) ==
                      shader->rayQueryFlags.end())
        detail::stageError(ctx.inv_, "RQ-2",
                           "shader '" + shader->name + "' makes a RayQuery<" + rayFlagsToString(templateRayFlags) +
                               "> that its export does not declare (ShaderLibrary::declareRayQueries)");
    state_ = takeQueryState();
    state_->handles = 1;
    state_->inv = &ctx.inv_;
    state_->templateFlags = templateRayFlags;
    state_->rayQueryFlags = rayQueryFlags;
}

void RayQueryObject::TraceRayInline(GpuVirtualAddress as, uint32_t rayFlags, uint32_t mask, const RayDesc& ray) {
    if (!initialise(as, rayFlags, mask, ray)) return;
    RayQueryState& q = *state_;
    detail::gatherQueryCandidates(detail::threadOf(q), q.rs, detail::siteOf(*q.inv), q.candidates);
}

bool RayQueryObject::initialise(GpuVirtualAddress as, uint32_t rayFlags, uint32_t mask, const RayDesc& ray) {
    RayQueryState& q = *state_;
    detail::requireLive(q, "TraceRayInline");
    detail::ThreadState& ts = detail::threadOf(q);
    const detail::Site site = detail::siteOf(*q.inv);
    // RQ-9: whatever the state, the current query is discarded.
    q.id = ++ts.queriesTraced;
    ts.stats.rayQueries++;
    q.phase = QueryPhase::Initialised;
    q.proceeded = false;
    q.searchEnded = false;
    q.status = COMMITTED_NOTHING;
    q.committed = {};
    q.candidate = {};
    q.candidates.clear();
    q.next = 0;
    q.rs = {};
    q.rs.depth = q.inv->depth;

    if (rayFlags & RAY_FLAG_SKIP_CLOSEST_HIT_SHADER) {  // RQ-4 (dynamic flags)
        raise(ts, site, detail::stateDiag(q, "RQ-4", "TraceRayInline", "was given RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, "
                                                                       "which a RayQuery may not carry")
                            .value("RayFlags", rayFlagsToString(rayFlags)));
        rayFlags &= ~uint32_t(RAY_FLAG_SKIP_CLOSEST_HIT_SHADER);
    }
    if (rayFlags & ~kDefinedRayFlags) {  // RQ-3: unknown bits
        raise(ts, site, detail::stateDiag(q, "RQ-3", "TraceRayInline", "was given undefined ray flag bits")
                            .hex("RayFlags", rayFlags)
                            .hex("undefined bits", rayFlags & ~kDefinedRayFlags));
        rayFlags &= kDefinedRayFlags;
    }
    q.dynamicFlags = rayFlags;
    q.rs.ray = ray;
    q.rs.rayFlags = rayFlags | q.templateFlags;  // RQ-26
    q.rs.effectiveFlags = rayFlags | (q.templateFlags & kDefinedRayFlags);  // RQ-3
    q.rs.instanceInclusionMask = mask & kInstanceInclusionMaskBits;  // RQ-10
    q.rs.tCurrent = ray.TMax;                                        // RQ-27
    ts.rayCounter++;

    if (ts.dispatch->options.observer) {
        TraceEvent e = detail::queryEvent(q, TraceEvent::Kind::QueryInit);
        e.accelerationStructure = as;
        e.ray = ray;
        e.rayFlags = rayFlags;
        e.effectiveFlags = q.rs.effectiveFlags;
        e.instanceInclusionMask = mask;
        ts.dispatch->options.observer->onEvent(e);
    }

    // RQ-5 on the OR'd flags, RQ-11 on the ray: an invalid query finds nothing.
    if (!detail::validateFlags(ts, site, rayFlags, q.templateFlags & kDefinedRayFlags, "RQ-5")) return false;
    bool rayOk = true;
    detail::validateRay(ts, site, ray, rayOk, "RQ-11");
    if (!rayOk || as == 0 || !detail::inTraversalRange(ray)) return false;  // RQ-10: a null AS is a miss
    q.rs.tlas = detail::findTopLevelAS(ts, site, as);
    return q.rs.tlas != nullptr;
}

namespace detail {

void runTraceRayInlineCalls(std::span<void* const> lanes) {
    REFRAY_ASSERT(lanes.size() <= size_t(kMaxWaveWidth), "a TraceRayInline call of " << lanes.size() << " lanes");
    std::array<GatherRay, kMaxWaveWidth> rays;
    std::array<std::vector<Candidate>*, kMaxWaveWidth> outs{};
    std::array<Site, kMaxWaveWidth> sites;
    std::array<RayQueryTraceCall*, kMaxWaveWidth> of{};  // the call of each gathered ray
    size_t count = 0;
    for (void* lane : lanes) {
        RayQueryTraceCall& call = *static_cast<RayQueryTraceCall*>(lane);
        call.failure = nullptr;
        try {
            if (!call.query->initialise(call.accelerationStructure, call.rayFlags, call.instanceInclusionMask,
                                        call.ray))
                continue;
        } catch (...) {
            call.failure = std::current_exception();
            continue;
        }
        RayQueryState& q = *call.query->state_;
        sites[count] = siteOf(*q.inv);
        setGatherRay(rays[count], threadOf(q), q.rs, sites[count]);
        outs[count] = &q.candidates;
        of[count++] = &call;
    }
    gatherQueryCandidatesPacket(std::span(rays.data(), count), std::span(outs.data(), count));
    for (size_t r = 0; r < count; ++r)
        if (rays[r].error) of[r]->failure = rays[r].error;
}

}  // namespace detail

bool RayQueryObject::Proceed() {
    RayQueryState& q = *state_;
    detail::requireLive(q, "Proceed");
    detail::ThreadState& ts = detail::threadOf(q);
    bool result = false;
    if (q.phase == QueryPhase::Fresh) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-19", "Proceed", "was called before TraceRayInline"));
    } else if (q.phase == QueryPhase::Finished) {
        // RQ-12: FALSE again, and nothing happens; SPIR-V leaves it undefined.
        detail::spirvNote(q, detail::SpirvUndefined::ProceedAfterFalse, "RQ-12",
                          "Proceed() after it returned FALSE (or after Abort)");
    } else {
        q.proceeded = true;
        result = detail::advance(q);
        q.phase = result ? QueryPhase::Candidate : QueryPhase::Finished;
        if (result) ts.stats.queryCandidates++;
    }
    if (detail::observer(ts) && q.id != 0) {  // a query never initialised has no life to show
        TraceEvent e = detail::queryEvent(q, TraceEvent::Kind::QueryProceed);
        e.accepted = result;
        if (result) detail::setQueryHit(e, q.candidate);
        e.committed = q.status != COMMITTED_NOTHING;
        e.note = result ? (q.candidate.procedural ? "TRUE: a procedural candidate for the shader to intersect"
                                                  : "TRUE: a non-opaque triangle candidate for the shader to accept or not")
                        : (q.searchEnded ? "FALSE: ACCEPT_FIRST_HIT_AND_END_SEARCH ended the search after a commit"
                                         : "FALSE: the search is finished");
        e.t = result ? q.candidate.t : q.rs.tCurrent;
        detail::observer(ts)->onEvent(e);
    }
    return result;
}

void RayQueryObject::Abort() {
    RayQueryState& q = *state_;
    detail::requireLive(q, "Abort");
    if (q.phase == QueryPhase::Fresh) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-19", "Abort", "was called before TraceRayInline"));
        return;
    }
    if (q.phase != QueryPhase::Candidate)  // RQ-15: legal in DXR; SPIR-V needs a TRUE Proceed just before
        detail::spirvNote(q, detail::SpirvUndefined::AbortWithoutCandidate, "RQ-15",
                          "Abort() without a Proceed() that returned TRUE just before");
    q.phase = QueryPhase::Finished;
    detail::ThreadState& ts = detail::threadOf(q);
    if (detail::observer(ts)) {
        TraceEvent e = detail::queryEvent(q, TraceEvent::Kind::QueryAbort);
        e.committed = q.status != COMMITTED_NOTHING;
        e.t = q.rs.tCurrent;
        e.note = "Abort: the next Proceed returns FALSE; the committed hit stays readable (RQ-15)";
        detail::observer(ts)->onEvent(e);
    }
}

namespace {

// The candidate, or null after reporting a call outside Proceed() == TRUE (RQ-17, RQ-28); `triangleOnly` for the
// getters of triangle candidates.
const detail::QueryHit* candidateFor(const RayQueryState& q, const char* call, bool triangleOnly) {
    detail::requireLive(q, call);
    if (q.phase != QueryPhase::Candidate) {
        detail::raiseQuery(q, detail::stateDiag(q, q.phase == QueryPhase::Fresh ? "RQ-19" : "RQ-28", call,
                                                "is valid only after Proceed() returned TRUE"));
        return nullptr;
    }
    if (triangleOnly && q.candidate.procedural) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-28", call, "is valid only for a CANDIDATE_NON_OPAQUE_TRIANGLE "
                                                                   "candidate; this one is CANDIDATE_PROCEDURAL_PRIMITIVE"));
        return nullptr;
    }
    return &q.candidate;
}

// The committed hit, or null after reporting a call the third table does not list for the status (RQ-29).
const detail::QueryHit* committedFor(const RayQueryState& q, const char* call, bool triangleOnly) {
    detail::requireLive(q, call);
    if (q.phase == QueryPhase::Fresh || q.phase == QueryPhase::Initialised) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-29", call, "is valid only after Proceed() has been called"));
        return nullptr;
    }
    if (q.status == COMMITTED_NOTHING || (triangleOnly && q.status != COMMITTED_TRIANGLE_HIT)) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-29", call,
                                                triangleOnly ? "needs COMMITTED_TRIANGLE_HIT"
                                                             : "needs a committed hit (COMMITTED_TRIANGLE_HIT or "
                                                               "COMMITTED_PROCEDURAL_PRIMITIVE_HIT)"));
        return nullptr;
    }
    return &q.committed;
}

// The six getters of RQ-25: valid once Proceed has been called; before it (after TraceRayInline) a warning "not in
// the table"; before TraceRayInline an error.
void checkQueryGetter(const RayQueryState& q, const char* call) {
    detail::requireLive(q, call);
    if (q.phase == QueryPhase::Fresh)
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-19", call, "was called before TraceRayInline"));
    else if (!q.proceeded && q.phase == QueryPhase::Initialised)
        detail::warn(detail::threadOf(q), detail::siteOf(*q.inv),
                     warning("RQ-25", std::string(call) + "() before the first Proceed(): not in the specification's "
                                                          "table (its text defines the value; refray returns it)")
                         .value("query", q.id));
}

const BuiltInstance* instanceOf(const detail::QueryHit* h) { return h ? h->instance : nullptr; }

}  // namespace

uint32_t RayQueryObject::CandidateType() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateType", false);
    return h && h->procedural ? CANDIDATE_PROCEDURAL_PRIMITIVE : CANDIDATE_NON_OPAQUE_TRIANGLE;
}
bool RayQueryObject::CandidateProceduralPrimitiveNonOpaque() const {
    const RayQueryState& q = *state_;
    const detail::QueryHit* h = candidateFor(q, "CandidateProceduralPrimitiveNonOpaque", false);
    if (h && !h->procedural) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-28", "CandidateProceduralPrimitiveNonOpaque",
                                                "is valid only for a CANDIDATE_PROCEDURAL_PRIMITIVE candidate"));
        return false;
    }
    return h && h->nonOpaque;
}
uint32_t RayQueryObject::CandidateInstanceIndex() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateInstanceIndex", false);
    return h ? h->instanceIndex : 0;
}
uint32_t RayQueryObject::CandidateInstanceID() const {
    const BuiltInstance* i = instanceOf(candidateFor(*state_, "CandidateInstanceID", false));
    return i ? i->desc.InstanceID : 0;
}
uint32_t RayQueryObject::CandidateInstanceContributionToHitGroupIndex() const {
    const BuiltInstance* i = instanceOf(candidateFor(*state_, "CandidateInstanceContributionToHitGroupIndex", false));
    return i ? i->desc.InstanceContributionToHitGroupIndex : 0;
}
uint32_t RayQueryObject::CandidateGeometryIndex() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateGeometryIndex", false);
    return h ? h->geometryIndex : 0;
}
uint32_t RayQueryObject::CandidatePrimitiveIndex() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidatePrimitiveIndex", false);
    return h ? h->primitiveIndex : 0;
}
vec3 RayQueryObject::CandidateObjectRayOrigin() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateObjectRayOrigin", false);
    return h ? h->objectRayOrigin : vec3(0.0f);
}
vec3 RayQueryObject::CandidateObjectRayDirection() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateObjectRayDirection", false);
    return h ? h->objectRayDirection : vec3(0.0f);
}
Matrix3x4 RayQueryObject::CandidateObjectToWorld3x4() const {
    const BuiltInstance* i = instanceOf(candidateFor(*state_, "CandidateObjectToWorld3x4", false));
    return i ? i->objectToWorld : Matrix3x4{};
}
std::array<std::array<float, 3>, 4> RayQueryObject::CandidateObjectToWorld4x3() const {
    const BuiltInstance* i = instanceOf(candidateFor(*state_, "CandidateObjectToWorld4x3", false));
    return transposed(i ? i->objectToWorld : Matrix3x4{});
}
Matrix3x4 RayQueryObject::CandidateWorldToObject3x4() const {
    const BuiltInstance* i = instanceOf(candidateFor(*state_, "CandidateWorldToObject3x4", false));
    return i ? i->worldToObject : Matrix3x4{};
}
std::array<std::array<float, 3>, 4> RayQueryObject::CandidateWorldToObject4x3() const {
    const BuiltInstance* i = instanceOf(candidateFor(*state_, "CandidateWorldToObject4x3", false));
    return transposed(i ? i->worldToObject : Matrix3x4{});
}
float RayQueryObject::CandidateTriangleRayT() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateTriangleRayT", true);
    return h ? h->t : 0.0f;
}
vec2 RayQueryObject::CandidateTriangleBarycentrics() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateTriangleBarycentrics", true);
    return h ? h->barycentrics : vec2(0.0f);
}
bool RayQueryObject::CandidateTriangleFrontFace() const {
    const detail::QueryHit* h = candidateFor(*state_, "CandidateTriangleFrontFace", true);
    return h && h->frontFace;
}

void RayQueryObject::CommitNonOpaqueTriangleHit() {
    RayQueryState& q = *state_;
    const detail::QueryHit* h = candidateFor(q, "CommitNonOpaqueTriangleHit", true);
    if (!h || q.candidateCommitted) return;  // RQ-21: a second call for the same candidate has no effect
    q.candidateCommitted = true;
    detail::commit(q, *h, COMMITTED_TRIANGLE_HIT, "CommitNonOpaqueTriangleHit (RQ-21)");
}

void RayQueryObject::CommitProceduralPrimitiveHit(float tHit) {
    RayQueryState& q = *state_;
    const detail::QueryHit* h = candidateFor(q, "CommitProceduralPrimitiveHit", false);
    if (!h) return;
    if (!h->procedural) {
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-22", "CommitProceduralPrimitiveHit",
                                                "is valid only for a CANDIDATE_PROCEDURAL_PRIMITIVE candidate"));
        return;
    }
    if (!(tHit >= q.rs.ray.TMin && tHit <= q.rs.tCurrent)) {  // RQ-22: the shader's duty, checked here
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-22", "CommitProceduralPrimitiveHit",
                                                "was given a t outside [RayTMin, CommittedRayT]; the commit is dropped")
                                  .value("tHit", tHit)
                                  .value("RayTMin", q.rs.ray.TMin)
                                  .value("CommittedRayT", q.rs.tCurrent));
        return;
    }
    detail::QueryHit hit = *h;
    hit.t = tHit;  // RQ-23: t and the node; no attributes
    detail::commit(q, hit, COMMITTED_PROCEDURAL_PRIMITIVE_HIT, "CommitProceduralPrimitiveHit (RQ-22)");
}

uint32_t RayQueryObject::CommittedStatus() const {
    const RayQueryState& q = *state_;
    detail::requireLive(q, "CommittedStatus");
    if (q.phase == QueryPhase::Fresh)  // RQ-18: valid any time after TraceRayInline
        detail::raiseQuery(q, detail::stateDiag(q, "RQ-19", "CommittedStatus", "was called before TraceRayInline"));
    return q.status;
}
uint32_t RayQueryObject::RayFlags() const {
    checkQueryGetter(*state_, "RayFlags");
    return state_->rs.rayFlags;
}
vec3 RayQueryObject::WorldRayOrigin() const {
    checkQueryGetter(*state_, "WorldRayOrigin");
    return state_->rs.ray.Origin;
}
vec3 RayQueryObject::WorldRayDirection() const {
    checkQueryGetter(*state_, "WorldRayDirection");
    return state_->rs.ray.Direction;
}
float RayQueryObject::RayTMin() const {
    checkQueryGetter(*state_, "RayTMin");
    return state_->rs.ray.TMin;
}
float RayQueryObject::CommittedRayT() const {
    const RayQueryState& q = *state_;
    checkQueryGetter(q, "CommittedRayT");
    if (q.status == COMMITTED_NOTHING && q.phase != QueryPhase::Fresh)  // RQ-27: TMax
        detail::spirvNote(q, detail::SpirvUndefined::CommittedRayTOfNothing, "RQ-27",
                          "CommittedRayT() with COMMITTED_NOTHING (DXR: TMax)");
    return q.rs.tCurrent;
}
uint32_t RayQueryObject::CommittedInstanceIndex() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedInstanceIndex", false);
    return h ? h->instanceIndex : 0;
}
uint32_t RayQueryObject::CommittedInstanceID() const {
    const BuiltInstance* i = instanceOf(committedFor(*state_, "CommittedInstanceID", false));
    return i ? i->desc.InstanceID : 0;
}
uint32_t RayQueryObject::CommittedInstanceContributionToHitGroupIndex() const {
    const BuiltInstance* i = instanceOf(committedFor(*state_, "CommittedInstanceContributionToHitGroupIndex", false));
    return i ? i->desc.InstanceContributionToHitGroupIndex : 0;
}
uint32_t RayQueryObject::CommittedGeometryIndex() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedGeometryIndex", false);
    return h ? h->geometryIndex : 0;
}
uint32_t RayQueryObject::CommittedPrimitiveIndex() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedPrimitiveIndex", false);
    return h ? h->primitiveIndex : 0;
}
vec3 RayQueryObject::CommittedObjectRayOrigin() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedObjectRayOrigin", false);
    return h ? h->objectRayOrigin : vec3(0.0f);
}
vec3 RayQueryObject::CommittedObjectRayDirection() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedObjectRayDirection", false);
    return h ? h->objectRayDirection : vec3(0.0f);
}
Matrix3x4 RayQueryObject::CommittedObjectToWorld3x4() const {
    const BuiltInstance* i = instanceOf(committedFor(*state_, "CommittedObjectToWorld3x4", false));
    return i ? i->objectToWorld : Matrix3x4{};
}
std::array<std::array<float, 3>, 4> RayQueryObject::CommittedObjectToWorld4x3() const {
    const BuiltInstance* i = instanceOf(committedFor(*state_, "CommittedObjectToWorld4x3", false));
    return transposed(i ? i->objectToWorld : Matrix3x4{});
}
Matrix3x4 RayQueryObject::CommittedWorldToObject3x4() const {
    const BuiltInstance* i = instanceOf(committedFor(*state_, "CommittedWorldToObject3x4", false));
    return i ? i->worldToObject : Matrix3x4{};
}
std::array<std::array<float, 3>, 4> RayQueryObject::CommittedWorldToObject4x3() const {
    const BuiltInstance* i = instanceOf(committedFor(*state_, "CommittedWorldToObject4x3", false));
    return transposed(i ? i->worldToObject : Matrix3x4{});
}
vec2 RayQueryObject::CommittedTriangleBarycentrics() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedTriangleBarycentrics", true);
    return h ? h->barycentrics : vec2(0.0f);
}
bool RayQueryObject::CommittedTriangleFrontFace() const {
    const detail::QueryHit* h = committedFor(*state_, "CommittedTriangleFrontFace", true);
    return h && h->frontFace;
}

std::array<vec3, 3> RayQueryObject::CandidateTriangleObjectPositions() const {
    detail::stageError(*state_->inv, "RQ-32",
                       "CandidateTriangleObjectPositions() is planned for Shader Model 6.10 and is not emulated");
}
std::array<vec3, 3> RayQueryObject::CommittedTriangleObjectPositions() const {
    detail::stageError(*state_->inv, "RQ-32",
                       "CommittedTriangleObjectPositions() is planned for Shader Model 6.10 and is not emulated");
}

}  // namespace refray::dxr
