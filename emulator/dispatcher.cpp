// DispatchRays and TraceRay: the DXR control flow of dxr-semantics.md sections 4-11.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <random>

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "emulator/detail/dispatch_state.h"
#include "emulator/device.h"
#include "emulator/embree_bridge.h"
#include "emulator/limits.h"
#include "emulator/shader_api.h"

namespace refray::dxr {

namespace detail {

// Exclusive stage times (DispatchOptions::profileStages): at each switch the running section is charged
// the time since the previous switch. Sections are ProfileStage values; kOutside is time in no stage
// (the launch loop, tile scheduling), which is not reported.
struct StageClock {
    using Clock = std::chrono::steady_clock;
    static constexpr uint8_t kOutside = uint8_t(kProfileStageCount);
    Clock::time_point mark = Clock::now();
    uint8_t section = kOutside;
    std::array<Clock::duration, kProfileStageCount + 1> spent{};

    // Switches to `next`; returns the section to switch back to.
    uint8_t enter(uint8_t next) {
        const Clock::time_point now = Clock::now();
        spent[section] += now - mark;
        mark = now;
        const uint8_t previous = section;
        section = next;
        return previous;
    }
};

// Invocations of one export on one thread, keyed by the export (names are attached when merging).
struct ExportCount {
    const ShaderExport* shader = nullptr;
    uint64_t count = 0;
};

struct ThreadState {
    DispatchState* dispatch = nullptr;
    uvec3 launchIndex{0u};
    uint64_t linearIndex = 0;
    DiagnosticLog log;
    DispatchStats stats;
    std::vector<Candidate> candidates;
    uint64_t rayCounter = 0;
    std::vector<Diagnostic> stopErrors;  // OnError::Stop: the errors that ended a launch
    std::vector<const ShaderExport*> callChain;  // the shaders running on this launch, outermost first
    GpuVirtualAddress lastTlasAddress = 0;  // one-entry cache of the TLAS lookup
    const TopLevelAS* lastTlas = nullptr;
    // Statistics beyond `stats`, in forms cheap to update; folded into `stats` when the dispatch ends.
    std::vector<ExportCount> exportCounts;  // in first-call order: a handful of exports, searched linearly
    bool profiling = false;                 // DispatchOptions::profileStages
    StageClock clock;
    LookupCache lookups;
};

LookupCache& lookupCache(Invocation& inv) { return inv.thread->lookups; }

// Charges this thread's time to `stage` while alive, when profiling; otherwise one untaken branch each way.
class ProfileScope {
public:
    ProfileScope(ThreadState& ts, ProfileStage stage) : ts_(ts) {
        if (ts_.profiling) previous_ = ts_.clock.enter(uint8_t(stage));
    }
    ~ProfileScope() {
        if (ts_.profiling) ts_.clock.enter(previous_);
    }
    ProfileScope(const ProfileScope&) = delete;
    ProfileScope& operator=(const ProfileScope&) = delete;

private:
    ThreadState& ts_;
    uint8_t previous_ = StageClock::kOutside;
};

void countInvocation(ThreadState& ts, const ShaderExport* shader) {
    for (ExportCount& e : ts.exportCounts)
        if (e.shader == shader) {
            ++e.count;
            return;
        }
    ts.exportCounts.push_back({shader, 1});
}

void countRay(ThreadState& ts, RayTypeKey key, uint32_t depth) {
    DispatchStats& st = ts.stats;
    st.raysTraced++;
    if (st.raysPerDepth.size() <= depth) st.raysPerDepth.resize(depth + 1);
    st.raysPerDepth[depth]++;
    RayTypeCounts* type = nullptr;
    for (RayTypeCounts& t : st.raysPerType)
        if (t.key == key) {
            type = &t;
            break;
        }
    if (!type) type = &st.raysPerType.emplace_back(RayTypeCounts{key, {}});
    if (type->raysPerDepth.size() <= depth) type->raysPerDepth.resize(depth + 1);
    type->raysPerDepth[depth]++;
}

// The thread's statistics in DispatchStats form (raysPerType stays unsorted: merge sorts).
DispatchStats finishedStats(const ThreadState& ts) {
    DispatchStats st = ts.stats;
    for (const ExportCount& e : ts.exportCounts) st.invocationsPerExport.push_back({e.shader->name, e.shader->stage, e.count});
    st.stagesProfiled = ts.profiling;
    if (ts.profiling)
        for (size_t i = 0; i < kProfileStageCount; ++i) st.stageSeconds[i] = std::chrono::duration<double>(ts.clock.spent[i]).count();
    return st;
}

// Non-local exits (IS-10, AHS-4). They never carry errors and never leave the dispatcher.
struct IgnoreHitSignal {};
struct AcceptHitAndEndSearchSignal {};
struct EndSearchSignal {};

namespace {

struct Site {
    ShaderStage stage;
    const std::string* exportName;
    uint32_t depth;
};

const std::string kNoExport;

Site siteOf(const Invocation& inv) { return {inv.stage, inv.shader ? &inv.shader->name : &kNoExport, inv.depth}; }

Diagnostic locate(const ThreadState& ts, Diagnostic d, const Site& site) {
    d.site = DiagnosticSite{ts.launchIndex, site.depth, site.stage, *site.exportName};
    return d;
}

// An error at `site`. OnError::Stop: throws. Continue: records it and returns, and the
// caller applies the fallback its rule documents.
void raise(ThreadState& ts, const Site& site, const Diagnostic& d) {
    Diagnostic located = locate(ts, d, site);
    if (ts.dispatch->options.onError == OnError::Stop) throw DxrError(std::move(located));
    ts.log.add(located, ts.linearIndex);
}

void warn(ThreadState& ts, const Site& site, const Diagnostic& d) { ts.log.add(locate(ts, d, site), ts.linearIndex); }

// ---- Trace events (emulator/trace.h): built only when an observer is installed.

TraceObserver* observer(const ThreadState& ts) { return ts.dispatch->options.observer; }

TraceEvent event(const ThreadState& ts, TraceEvent::Kind kind, uint32_t depth) {
    TraceEvent e;
    e.kind = kind;
    e.launchIndex = ts.launchIndex;
    e.depth = depth;
    return e;
}

void setHit(TraceEvent& e, const BuiltInstance& inst, uint32_t instanceIndex, uint32_t geometryIndex,
            uint32_t primitiveIndex) {
    e.instanceIndex = instanceIndex;
    e.instanceID = inst.desc.InstanceID;
    e.geometryIndex = geometryIndex;
    e.primitiveIndex = primitiveIndex;
}

void emitSkipped(const ThreadState& ts, const RayState& rs, std::string_view why) {
    TraceEvent e = event(ts, TraceEvent::Kind::Skipped, rs.depth);
    e.note = why;
    observer(ts)->onEvent(e);
}

const char* tableName(ProgramEntry::Kind kind) {
    switch (kind) {
        case ProgramEntry::Kind::HitGroup: return "hit-group table";
        case ProgramEntry::Kind::Miss: return "miss shader table";
        case ProgramEntry::Kind::Callable: return "callable shader table";
        case ProgramEntry::Kind::RayGeneration: return "ray generation record";
    }
    return "table";
}

// Extra values a hit-group lookup diagnostic carries (IDX-11).
struct HitLookupContext {
    const HitGroupIndexTerms* terms = nullptr;
    const HitInfo* hit = nullptr;
    GeometryType geometryType = GeometryType::Triangles;
};

void addHitValues(DiagnosticBuilder& b, const HitLookupContext* h) {
    if (!h || !h->terms) return;
    const HitGroupIndexTerms& t = *h->terms;
    b.value("I = R + M*G + C", std::to_string(t.rayContribution) + " + " + std::to_string(t.multiplier) + "*" +
                                   std::to_string(t.geometryIndex) + " + " + std::to_string(t.instanceContribution) +
                                   " = " + std::to_string(t.index));
    if (h->hit) {
        b.value("InstanceIndex", h->hit->instanceIndex)
            .value("GeometryIndex", h->hit->geometryIndex)
            .value("PrimitiveIndex", h->hit->primitiveIndex);
    }
}

// Resolves the record at `index` of `table` (IDX-9..14, REC-7..11). Returns false when
// the lookup failed in OnError::Continue mode (the caller treats it as a NULL record).
bool lookupRecordChecked(ThreadState& ts, const Site& site, ProgramEntry::Kind kind,
                         const GpuVirtualAddressRangeAndStride& table, uint64_t index, RecordView& out,
                         const HitLookupContext* hit) {
    // A record that passed these checks for this table, index and geometry type passes them again (LookupCache).
    LookupCache::Record& cached = ts.lookups.records[LookupCache::recordSlot(index, uint8_t(kind))];
    const uint8_t geometry = hit ? uint8_t(1 + uint8_t(hit->geometryType)) : uint8_t(0);
    if (cached.index == index && cached.kind == uint8_t(kind) && cached.geometry == geometry &&
        cached.table.StartAddress == table.StartAddress && cached.table.SizeInBytes == table.SizeInBytes &&
        cached.table.StrideInBytes == table.StrideInBytes) {
        out = cached.view;
        return true;
    }
    auto remember = [&] {
        cached = {table, index, uint8_t(kind), geometry, out};
        return true;
    };

    const DispatchState& ds = *ts.dispatch;
    const std::string_view name = tableName(kind);
    out = RecordView{};
    out.index = index;
    const uint64_t offset = table.StrideInBytes * index;
    out.address = table.StartAddress + offset;

    if (table.StartAddress == 0 && table.SizeInBytes == 0) {
        auto b = diag("IDX-11", "the " + std::string(name) + " is missing (StartAddress 0, SizeInBytes 0) but a record is needed");
        b.value("index", index);
        addHitValues(b, hit);
        raise(ts, site, b);
        return false;
    }
    if (offset + kShaderIdentifierSizeInBytes > table.SizeInBytes) {
        auto b = diag("IDX-11", "record index past the end of the " + std::string(name));
        addHitValues(b, hit);
        b.value("index", index)
            .value("stride", table.StrideInBytes)
            .value("record offset + 32", offset + kShaderIdentifierSizeInBytes, "SizeInBytes " + std::to_string(table.SizeInBytes))
            .value("records in table", table.StrideInBytes == 0 ? 1
                                       : table.SizeInBytes < kShaderIdentifierSizeInBytes
                                           ? 0
                                           : (table.SizeInBytes - kShaderIdentifierSizeInBytes) / table.StrideInBytes + 1);
        raise(ts, site, b);
        return false;
    }
    const GpuBuffer* buffer = ds.memory->find(out.address, kShaderIdentifierSizeInBytes);
    const uint8_t* bytes = buffer ? buffer->bytes.data() + (out.address - buffer->base) : nullptr;
    const uint8_t* identifierWritten = buffer ? buffer->written.data() + (out.address - buffer->base) : nullptr;
    if (!bytes || std::memchr(identifierWritten, 0, kShaderIdentifierSizeInBytes)) {
        auto b = diag("IDX-11", "the record's shader identifier at this index was never written (uninitialized record)");
        addHitValues(b, hit);
        b.value("index", index).hex("address", out.address);
        raise(ts, site, b);
        return false;
    }
    bool isNull = false;
    const ProgramEntry* entry = ds.pipeline->resolve(bytes, isNull);
    if (isNull) return remember();  // REC-8: nothing runs for this purpose
    if (!entry) {
        auto b = diag("REC-8", "the " + std::string(name) + " record holds an identifier that is not an export of the bound state object '" +
                                   ds.pipeline->name() + "': it is " + StateObject::describeForeignIdentifier(bytes));
        addHitValues(b, hit);
        b.value("index", index).hex("address", out.address);
        raise(ts, site, b);
        return false;
    }
    if (entry->kind != kind) {
        auto b = diag("IDX-13", "the " + std::string(name) + " record holds " + std::string(toString(entry->kind)) + " '" +
                                    entry->name + "', which does not belong in this table");
        addHitValues(b, hit);
        b.value("index", index);
        raise(ts, site, b);
        return false;
    }
    if (kind == ProgramEntry::Kind::HitGroup && hit) {
        const bool procedural = hit->geometryType == GeometryType::ProceduralPrimitiveAABBs;
        if (procedural != (entry->hitGroupType == HitGroupType::ProceduralPrimitive)) {
            auto b = diag("IDX-14", "hit group '" + entry->name + "' (" +
                                        (entry->hitGroupType == HitGroupType::ProceduralPrimitive ? "procedural" : "triangle") +
                                        ") was selected for " + (procedural ? "AABB" : "triangle") + " geometry");
            addHitValues(b, hit);
            raise(ts, site, b);
            return false;
        }
    }
    const uint32_t layout = entry->localRootSignature ? entry->localRootSignature->recordSize() : kShaderIdentifierSizeInBytes;
    if (table.StrideInBytes != 0 && table.StrideInBytes < layout) {
        auto b = diag("IDX-10", "the " + std::string(name) + " stride is smaller than the record of '" + entry->name + "'");
        addHitValues(b, hit);
        b.value("stride", table.StrideInBytes).value("record bytes (REC-5)", layout, "<= stride");
        raise(ts, site, b);
        return false;
    }
    const uint64_t available = table.StrideInBytes ? table.StrideInBytes : table.SizeInBytes - offset;
    if (kind == ProgramEntry::Kind::RayGeneration && table.SizeInBytes < layout) {
        // The ray generation record has no stride: its SizeInBytes must cover it (IDX-9).
        raise(ts, site, diag("IDX-9", "RayGenerationShaderRecord.SizeInBytes does not cover the identifier and local root "
                                      "arguments of '" + entry->name + "'")
                            .value("SizeInBytes", table.SizeInBytes, ">= " + std::to_string(layout)));
        return false;
    }
    if (available < layout || offset + layout > table.SizeInBytes) {
        auto b = diag(available < layout ? "REC-11" : "IDX-11",
                      "the record of '" + entry->name + "' does not fit in the " + std::string(name));
        addHitValues(b, hit);
        b.value("record offset", offset)
            .value("record bytes (REC-5)", layout)
            .value("SizeInBytes", table.SizeInBytes);
        raise(ts, site, b);
        return false;
    }
    out.entry = entry;
    out.arguments = bytes + kShaderIdentifierSizeInBytes;
    out.argumentsWritten = buffer->written.data() + (out.address - buffer->base) + kShaderIdentifierSizeInBytes;
    out.argumentBytesAvailable = std::min<uint64_t>(available, buffer->size() - (out.address - buffer->base)) -
                                 kShaderIdentifierSizeInBytes;
    return remember();
}

bool lookupRecord(ThreadState& ts, const Site& site, ProgramEntry::Kind kind,
                  const GpuVirtualAddressRangeAndStride& table, uint64_t index, RecordView& out,
                  const HitLookupContext* hit = nullptr) {
    if (!observer(ts)) return lookupRecordChecked(ts, site, kind, table, index, out, hit);
    TraceEvent e = event(ts, TraceEvent::Kind::RecordLookup,                        site.depth + (kind == ProgramEntry::Kind::HitGroup || kind == ProgramEntry::Kind::Miss ? 1 : 0));
    e.table = tableName(kind);
    e.recordIndex = index;
    e.recordAddress = table.StartAddress + table.StrideInBytes * index;
    e.stride = table.StrideInBytes;
    if (hit && hit->terms) {
        e.hasTerms = true;
        e.terms = *hit->terms;
    }
    if (hit && hit->hit) setHit(e, *hit->hit->instance, hit->hit->instanceIndex, hit->hit->geometryIndex, hit->hit->primitiveIndex);
    bool ok = false;
    try {
        ok = lookupRecordChecked(ts, site, kind, table, index, out, hit);
    } catch (...) {
        e.note = "invalid";
        observer(ts)->onEvent(e);
        throw;
    }
    e.note = !ok ? "invalid" : out.entry ? "" : "NULL";
    if (out.entry) e.exportName = out.entry->name;
    observer(ts)->onEvent(e);
    return ok;
}

// PIPE-6: the shader's global root signature must be the one bound for the dispatch.
void checkGlobalSignature(ThreadState& ts, const Site& site, const ProgramEntry& entry) {
    const DispatchState& ds = *ts.dispatch;
    const RootSignature* bound = ds.global ? ds.global->signature().get() : nullptr;
    if (entry.globalRootSignature && entry.globalRootSignature.get() != bound)
        raise(ts, site,
              diag("PIPE-6", "'" + entry.name + "' uses a global root signature other than the one bound for the dispatch")
                  .value("shader's", entry.globalRootSignature->name())
                  .value("bound", bound ? bound->name() : std::string("(none)")));
}

void checkPayload(ThreadState& ts, const Site& site, const ShaderExport& shader, TypeTag traced) {
    if (!(shader.payload == traced))
        raise(ts, site, diag("PAY-1", std::string(toString(shader.stage)) + " shader '" + shader.name +
                                          "' declares another payload type than the TraceRay that invokes it")
                            .value("TraceRay payload", traced.name() + " (" + std::to_string(traced.size) + " B)")
                            .value("shader payload", shader.payload.name() + " (" + std::to_string(shader.payload.size) + " B)"));
}

void invoke(ThreadState& ts, Invocation& inv, void* payload, const void* attributes) {
    ts.stats.invocations[size_t(inv.stage)]++;
    countInvocation(ts, inv.shader);
    if (observer(ts)) {
        TraceEvent e = event(ts, TraceEvent::Kind::ShaderCall, inv.depth);
        e.stage = inv.stage;
        e.exportName = inv.shader->name;
        if (inv.record) {
            e.recordIndex = inv.record->index;
            e.recordAddress = inv.record->address;
        }
        if (inv.hit) setHit(e, *inv.hit->instance, inv.hit->instanceIndex, inv.hit->geometryIndex, inv.hit->primitiveIndex);
        observer(ts)->onEvent(e);
    }
    ShaderContext ctx(inv);
    // On every exit, non-local ones included: pop the call chain and, when profiling, hand the clock back
    // to the caller's section. One object, so the IgnoreHit / end-search signals unwind one cleanup here.
    struct ShaderScope {
        ThreadState& ts;
        uint8_t callerSection;
        ~ShaderScope() {
            ts.callChain.pop_back();
            if (ts.profiling) ts.clock.enter(callerSection);
        }
    };
    ts.callChain.push_back(inv.shader);
    const ShaderScope scope{ts, ts.profiling ? ts.clock.enter(uint8_t(profileStageOf(inv.stage))) : StageClock::kOutside};
    inv.shader->function(ctx, payload, attributes);
}

std::string describeCallChain(const ThreadState& ts) {
    std::string out;
    for (const ShaderExport* s : ts.callChain) {
        if (!out.empty()) out += " -> ";
        out += std::string(toString(s->stage)) + " '" + s->name + "'";
    }
    return out;
}

bool isOpaque(uint32_t geometryFlags, uint32_t instanceFlags, uint32_t rayFlags) {  // OPQ-1
    bool opaque = (geometryFlags & GEOMETRY_FLAG_OPAQUE) != 0;
    if (instanceFlags & INSTANCE_FLAG_FORCE_OPAQUE) opaque = true;
    if (instanceFlags & INSTANCE_FLAG_FORCE_NON_OPAQUE) opaque = false;
    if (rayFlags & RAY_FLAG_FORCE_OPAQUE) opaque = true;
    if (rayFlags & RAY_FLAG_FORCE_NON_OPAQUE) opaque = false;
    return opaque;
}

void commit(const ThreadState& ts, RayState& rs, const HitInfo& hit) {  // TRV-4 step 4
    if (observer(ts)) {
        TraceEvent e = event(ts, TraceEvent::Kind::Commit, rs.depth);
        setHit(e, *hit.instance, hit.instanceIndex, hit.geometryIndex, hit.primitiveIndex);
        e.t = hit.t;
        e.hitKind = hit.hitKind;
        observer(ts)->onEvent(e);
    }
    rs.committed = true;
    rs.committedHit = hit;
    rs.tCurrent = hit.t;
}

enum class AnyHitOutcome { Accept, Ignore, AcceptAndEnd };

AnyHitOutcome runAnyHit(ThreadState& ts, RayState& rs, const RecordView& record, HitInfo& candidate) {
    Invocation inv;
    inv.stage = ShaderStage::AnyHit;
    inv.shader = record.entry->anyHit;
    inv.record = &record;
    inv.ray = &rs;
    inv.hit = &candidate;
    inv.dispatch = ts.dispatch;
    inv.thread = &ts;
    inv.depth = rs.depth;
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
        setHit(e, *candidate.instance, candidate.instanceIndex, candidate.geometryIndex, candidate.primitiveIndex);
        e.t = candidate.t;
        e.note = outcome == AnyHitOutcome::Ignore         ? "IgnoreHit: the candidate is dropped"
                 : outcome == AnyHitOutcome::AcceptAndEnd ? "AcceptHitAndEndSearch: commit and end the search"
                                                          : "accept (returned normally)";
        observer(ts)->onEvent(e);
    }
    return outcome;
}

}  // namespace

// ReportHit (IS-3..IS-9): the body behind ShaderContext::ReportHit. `inv` is the intersection
// shader's invocation: its record is the hit group, its candidateOpaque the box's OPQ-1 opacity.
bool reportHit(Invocation& inv, float tHit, uint32_t hitKind, const void* attributes, TypeTag type) {
    ThreadState& ts = *inv.thread;
    RayState& rs = *inv.ray;
    const Site site = siteOf(inv);
    const ProgramEntry& group = *inv.record->entry;
    if (observer(ts)) {
        TraceEvent e = event(ts, TraceEvent::Kind::ReportHit, rs.depth);
        setHit(e, *inv.hit->instance, inv.hit->instanceIndex, inv.hit->geometryIndex, inv.hit->primitiveIndex);
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
    if (std::isnan(tHit)) {
        raise(ts, site, diag("IS-3", "ReportHit called with a NaN THit; the hit is rejected").value("THit", tHit));
        return false;
    }
    if (!(type == group.attributes)) {  // IS-5: checked on every call, in range or not
        raise(ts, site, diag("IS-5", "ReportHit attributes are not the type hit group '" + group.name + "' consumes")
                            .value("reported", type.name() + " (" + std::to_string(type.size) + " B)")
                            .value("expected", group.attributes.name() + " (" + std::to_string(group.attributes.size) + " B)"));
        return false;
    }
    if (tHit < rs.ray.TMin || tHit > rs.tCurrent) return false;  // IS-3: closed interval
    if (hitKind > kMaxProceduralHitKind)
        raise(ts, site, diag("IS-4", "ReportHit HitKind outside 0..127 (254 and 255 mean triangle faces)")
                            .value("HitKind", hitKind, "0..127"));
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

namespace {

// FACE-1..3: facing from the object-space winding; the instance transform never flips it.
bool isFrontFacing(const BuiltGeometry& geom, const Candidate& c, uint32_t instanceFlags) {
    const vec3* v = &geom.triangleVertices[size_t(c.primitiveIndex) * 3];
    const dvec3 e1 = dvec3(v[1]) - dvec3(v[0]), e2 = dvec3(v[2]) - dvec3(v[0]);
    const double facing = glm::dot(glm::cross(e1, e2), dvec3(c.objectRayDirection));
    bool front = facing < 0.0;
    if (instanceFlags & INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE) front = !front;
    return front;
}

// FLAG-10, FACE-5: whether the ray's facing-culling flags drop this triangle.
bool isFaceCulled(uint32_t rayFlags, uint32_t instanceFlags, bool front) {
    if (instanceFlags & INSTANCE_FLAG_TRIANGLE_CULL_DISABLE) return false;
    return ((rayFlags & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) && !front) ||
           ((rayFlags & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) && front);
}

// FLAG-11.
bool isOpacityCulled(uint32_t rayFlags, bool opaque) {
    return ((rayFlags & RAY_FLAG_CULL_OPAQUE) && opaque) || ((rayFlags & RAY_FLAG_CULL_NON_OPAQUE) && !opaque);
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

    HitInfo hit;
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
    std::memcpy(hit.attributes, &attributes, sizeof attributes);

    bool endSearch = false;
    if (!opaque) {  // OPQ-3: the record is needed only to find an AHS (IDX-12)
        const HitGroupIndexTerms terms = hitGroupRecordIndex(rs.rayContribution, rs.multiplier, c.geometryIndex,
                                                             inst.desc.InstanceContributionToHitGroupIndex);
        HitLookupContext lookup{&terms, &hit, GeometryType::Triangles};
        RecordView record;
        if (lookupRecord(ts, site, ProgramEntry::Kind::HitGroup, ts.dispatch->desc->HitGroupTable, terms.index, record,
                         &lookup) &&
            record.entry && record.entry->anyHit) {
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

void processProcedural(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site) {
    if (c.key > rs.tCurrent) {  // the box no longer overlaps [TMin, TCurrent]
        if (observer(ts)) emitSkipped(ts, rs, "the box starts beyond RayTCurrent: no intersection shader call");
        return;
    }
    const BuiltInstance& inst = rs.tlas->instances()[c.instanceIndex];
    const BuiltGeometry& geom = inst.blas->geometries()[c.geometryIndex];
    const bool opaque = isOpaque(geom.flags, inst.desc.Flags, rs.effectiveFlags);
    if (isOpacityCulled(rs.effectiveFlags, opaque)) {
        if (observer(ts)) emitSkipped(ts, rs, opaque ? "opaque, culled: CULL_OPAQUE (FLAG-11)" : "non-opaque, culled: CULL_NON_OPAQUE (FLAG-11)");
        return;  // FLAG-11: before the IS
    }

    HitInfo box;
    box.instance = &inst;
    box.instanceIndex = c.instanceIndex;
    box.geometryIndex = c.geometryIndex;
    box.primitiveIndex = c.primitiveIndex;
    box.objectRayOrigin = c.objectRayOrigin;
    box.objectRayDirection = c.objectRayDirection;

    const HitGroupIndexTerms terms = hitGroupRecordIndex(rs.rayContribution, rs.multiplier, c.geometryIndex,
                                                         inst.desc.InstanceContributionToHitGroupIndex);
    HitLookupContext lookup{&terms, &box, GeometryType::ProceduralPrimitiveAABBs};
    RecordView record;
    if (!lookupRecord(ts, site, ProgramEntry::Kind::HitGroup, ts.dispatch->desc->HitGroupTable, terms.index, record,
                      &lookup))
        return;
    if (!record.entry) {  // OPQ-4: a NULL hit group has no IS, so no hit
        if (observer(ts)) emitSkipped(ts, rs, "NULL hit group: no intersection shader, no hit (OPQ-4)");
        return;
    }

    Invocation inv;
    inv.stage = ShaderStage::Intersection;
    inv.shader = record.entry->intersection;
    inv.record = &record;
    inv.ray = &rs;
    inv.hit = &box;
    inv.dispatch = ts.dispatch;
    inv.thread = &ts;
    inv.depth = rs.depth;
    inv.candidateOpaque = opaque;
    checkGlobalSignature(ts, siteOf(inv), *record.entry);
    try {
        invoke(ts, inv, nullptr, nullptr);
        if (inv.searchEnded) rs.searchEnded = true;  // ReportHitEnd::Return: the IS returned after it
    } catch (const EndSearchSignal&) {
        rs.searchEnded = true;  // IS-6/IS-7/FLAG-8: the IS ended at the accepting ReportHit
    }
}

// The traversal shortcuts (GatherMode; docs/emulator.md, "Traversal shortcuts").
struct ShortcutContext {
    ThreadState* ts;
    RayState* rs;
    const Site* site;
};

// Closest: an in-range triangle the ordered loop commits whenever it reaches it: not culled, and either
// opaque or in a pipeline without any-hit shaders (then nothing can ignore it).
bool commitsSurely(const void* user, const Candidate& c) {
    const auto& sc = *static_cast<const ShortcutContext*>(user);
    const BuiltInstance& inst = sc.rs->tlas->instances()[c.instanceIndex];
    const BuiltGeometry& geom = inst.blas->geometries()[c.geometryIndex];
    const uint32_t flags = sc.rs->effectiveFlags;
    if (isFaceCulled(flags, inst.desc.Flags, isFrontFacing(geom, c, inst.desc.Flags))) return false;
    const bool opaque = isOpaque(geom.flags, inst.desc.Flags, flags);
    if (isOpacityCulled(flags, opaque)) return false;
    return opaque || !sc.ts->dispatch->anyHitInPipeline;
}

// FirstHit: the TRV-4 step for one candidate, as Embree meets it.
bool processNow(void* user, const Candidate& c) {
    auto& sc = *static_cast<ShortcutContext*>(user);
    sc.ts->stats.candidates++;
    if (c.procedural) processProcedural(*sc.ts, *sc.rs, c, *sc.site);
    else processTriangle(*sc.ts, *sc.rs, c, *sc.site);
    return sc.rs->searchEnded;
}

// The shortcut a ray may take: none when it is observed, in adversarial order or with shortcuts off;
// FirstHit when no order can change its outcome; else Closest.
GatherMode traversalMode(const ThreadState& ts, const RayState& rs) {
    const DispatchState& ds = *ts.dispatch;
    if (!ds.options.specialise || observer(ts) || ds.options.order != TraversalOrder::Ordered) return GatherMode::All;
    const uint32_t firstHit = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    if ((rs.effectiveFlags & firstHit) == firstHit && !ds.anyHitInPipeline) return GatherMode::FirstHit;
    return GatherMode::Closest;
}

// Orders candidates per DispatchOptions::order (GEN-3).
void orderCandidates(ThreadState& ts, RayState& rs) {
    auto& cs = ts.candidates;
    std::sort(cs.begin(), cs.end(), [](const Candidate& a, const Candidate& b) {
        if (a.key != b.key) return a.key < b.key;
        if (a.instanceIndex != b.instanceIndex) return a.instanceIndex < b.instanceIndex;
        if (a.geometryIndex != b.geometryIndex) return a.geometryIndex < b.geometryIndex;
        return a.primitiveIndex < b.primitiveIndex;
    });
    // One candidate per primitive: Embree may report a primitive more than once (AHS-6, IS-1).
    cs.erase(std::unique(cs.begin(), cs.end(),
                         [](const Candidate& a, const Candidate& b) {
                             return a.instanceIndex == b.instanceIndex && a.geometryIndex == b.geometryIndex &&
                                    a.primitiveIndex == b.primitiveIndex;
                         }),
             cs.end());
    if (ts.dispatch->options.order != TraversalOrder::Adversarial) return;

    std::mt19937_64 rng(ts.dispatch->options.adversarialSeed * 0x9E3779B97F4A7C15ull ^ (ts.linearIndex << 20) ^
                        ts.rayCounter);
    const size_t n = cs.size();
    for (size_t i = 0; i < n; ++i) {
        const Candidate& c = cs[i];
        const BuiltGeometry& g = rs.tlas->instances()[c.instanceIndex].blas->geometries()[c.geometryIndex];
        if (!(g.flags & GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION) && (rng() & 1)) cs.push_back(c);
    }
    std::shuffle(cs.begin(), cs.end(), rng);
}

// Embree's traversal accepts origin and direction components up to ±1.844e18 (its FLT_LARGE) and asserts
// beyond; refray treats a finite ray beyond that like an infinite one (RAY-7: a warning, then a miss).
constexpr float kTraversalRange = 1.844e18f;
bool inTraversalRange(const RayDesc& ray) {
    for (int c = 0; c < 3; ++c)
        if (!(std::fabs(ray.Origin[c]) <= kTraversalRange && std::fabs(ray.Direction[c]) <= kTraversalRange)) return false;
    return true;
}

std::string vec3Values(const vec3& v) {
    return std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z);
}

void validateRay(ThreadState& ts, const Site& site, const RayDesc& ray, bool& ok) {
    // inTraversalRange also fails for NaN and infinite components, so it covers their finiteness too.
    if (inTraversalRange(ray) && std::isfinite(ray.TMin) && !std::isnan(ray.TMax) && ray.TMin >= 0.0f &&
        ray.TMin <= ray.TMax && ray.Direction != vec3(0.0f))
        return;  // the common case: nothing to report
    auto field = [&](const char* name, float v) {
        if (std::isnan(v)) {
            raise(ts, site, diag("RAY-5", std::string("RayDesc.") + name + " is NaN").value(name, v));
            ok = false;
        }
    };
    for (int c = 0; c < 3; ++c) {
        static const char* o[3] = {"Origin.x", "Origin.y", "Origin.z"};
        static const char* d[3] = {"Direction.x", "Direction.y", "Direction.z"};
        field(o[c], ray.Origin[c]);
        field(d[c], ray.Direction[c]);
    }
    field("TMin", ray.TMin);
    field("TMax", ray.TMax);
    if (!ok) return;
    if (ray.TMin < 0.0f) {
        raise(ts, site, diag("RAY-5", "RayDesc.TMin is negative").value("TMin", ray.TMin, ">= 0"));
        ok = false;
    } else if (ray.TMin > ray.TMax) {
        raise(ts, site, diag("RAY-5", "RayDesc.TMin is greater than TMax").value("TMin", ray.TMin).value("TMax", ray.TMax, ">= TMin"));
        ok = false;
    }
    if (std::isinf(ray.TMin))
        warn(ts, site, warning("RAY-5", "RayDesc.TMin is infinite; no hit can follow").value("TMin", ray.TMin));
    if (ray.Direction == vec3(0.0f))
        warn(ts, site, warning("RAY-7", "RayDesc.Direction is the zero vector"));
    else if (!allFinite(ray.Origin) || !allFinite(ray.Direction))
        warn(ts, site, warning("RAY-7", "RayDesc has an infinite Origin or Direction component")
                           .value("Origin", vec3Values(ray.Origin))
                           .value("Direction", vec3Values(ray.Direction)));
    else if (!inTraversalRange(ray))
        warn(ts, site, warning("RAY-7", "RayDesc has an Origin or Direction component beyond +-1.844e18, the range "
                                        "refray's traversal (Embree) accepts; the ray is treated as a miss")
                           .value("Origin", vec3Values(ray.Origin))
                           .value("Direction", vec3Values(ray.Direction)));
}

// FLAG-2..5 on the effective flags; returns false (and has raised) when they are invalid.
bool validateFlags(ThreadState& ts, const Site& site, uint32_t rayFlags, uint32_t pipelineFlags) {
    const uint32_t eff = rayFlags | pipelineFlags;
    auto fail = [&](const char* rule, const std::string& what) {
        raise(ts, site, diag(rule, what)
                            .value("TraceRay flags", rayFlagsToString(rayFlags))
                            .value("pipeline flags", pipelineFlagsToString(pipelineFlags)));
        return false;
    };
    const uint32_t opacity = eff & (RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_FORCE_NON_OPAQUE | RAY_FLAG_CULL_OPAQUE | RAY_FLAG_CULL_NON_OPAQUE);
    if (opacity & (opacity - 1))
        return fail(pipelineFlags ? "FLAG-5" : "FLAG-2",
                    "at most one of FORCE_OPAQUE, FORCE_NON_OPAQUE, CULL_OPAQUE, CULL_NON_OPAQUE may be set");
    if ((eff & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) && (eff & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES))
        return fail(pipelineFlags ? "FLAG-5" : "FLAG-3", "CULL_BACK_FACING_TRIANGLES and CULL_FRONT_FACING_TRIANGLES are exclusive");
    if ((eff & RAY_FLAG_SKIP_TRIANGLES) &&
        (eff & (RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_CULL_FRONT_FACING_TRIANGLES | RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES)))
        return fail(pipelineFlags ? "FLAG-5" : "FLAG-4",
                    "SKIP_TRIANGLES excludes CULL_*_FACING_TRIANGLES and SKIP_PROCEDURAL_PRIMITIVES");
    return true;
}

}  // namespace

// TraceRay (sections 4-10): validation, candidate gathering, the TRV-4 loop, then
// the closest-hit or miss shader.
void traceRay(Invocation& caller, GpuVirtualAddress asAddress, uint32_t rayFlags, uint32_t mask, uint32_t r,
              uint32_t m, uint32_t missIndex, const RayDesc& ray, void* payload, TypeTag payloadType) {
    ThreadState& ts = *caller.thread;
    DispatchState& ds = *ts.dispatch;
    const Site site = siteOf(caller);

    if (caller.depth >= ds.pipeline->maxTraceRecursionDepth()) {  // LIM-2
        raise(ts, site, diag("LIM-2", "TraceRay at the recursion limit: a call at depth == MaxTraceRecursionDepth removes the device")
                            .value("depth", caller.depth, "< MaxTraceRecursionDepth " + std::to_string(ds.pipeline->maxTraceRecursionDepth()))
                            .value("call chain", describeCallChain(ts)));
        return;  // fallback: the call does nothing
    }
    if (rayFlags & ~kDefinedRayFlags) {  // RAY-10
        raise(ts, site, diag("RAY-10", "TraceRay flags set undefined bits")
                            .hex("RayFlags", rayFlags)
                            .hex("undefined bits", rayFlags & ~kDefinedRayFlags));
        rayFlags &= kDefinedRayFlags;
    }
    if (!validateFlags(ts, site, rayFlags, ds.pipeline->pipelineFlags())) return;
    bool rayOk = true;
    validateRay(ts, site, ray, rayOk);
    if (!rayOk) return;
    if ((r & ~kRayContributionMask) || (m & ~kGeometryMultiplierMask))  // IDX-2
        warn(ts, site, warning("IDX-2", "TraceRay index arguments have bits above the low 4; DXR ignores them")
                           .value("RayContributionToHitGroupIndex", r, "0..15")
                           .value("MultiplierForGeometryContributionToHitGroupIndex", m, "0..15"));

    RayState rs;
    rs.ray = ray;
    rs.rayFlags = rayFlags;
    rs.effectiveFlags = rayFlags | ds.pipeline->pipelineFlags();
    rs.instanceInclusionMask = mask & kInstanceInclusionMaskBits;
    rs.rayContribution = r;
    rs.multiplier = m;
    rs.missShaderIndex = missIndex;
    rs.depth = caller.depth + 1;
    rs.tCurrent = ray.TMax;
    rs.payloadType = payloadType;

    // RAY-9: the payload is passed by value.
    alignas(16) uint8_t inlinePayload[256];
    std::unique_ptr<uint8_t[]> heapPayload;
    uint8_t* local = inlinePayload;
    if (payloadType.size > sizeof inlinePayload) {
        heapPayload.reset(new uint8_t[payloadType.size]);
        local = heapPayload.get();
    }
    std::memcpy(local, payload, payloadType.size);
    rs.payload = local;
    auto emitRay = [&](TraceEvent::Kind kind) {
        TraceEvent e = event(ts, kind, rs.depth);
        e.accelerationStructure = asAddress;
        e.ray = ray;
        e.rayFlags = rayFlags;
        e.effectiveFlags = rs.effectiveFlags;
        e.instanceInclusionMask = mask;
        e.rayContribution = r;
        e.multiplier = m;
        e.missShaderIndex = missIndex;
        e.committed = rs.committed;
        if (rs.committed) {
            const HitInfo& h = rs.committedHit;
            setHit(e, *h.instance, h.instanceIndex, h.geometryIndex, h.primitiveIndex);
            e.t = h.t;
            e.hitKind = h.hitKind;
        }
        if (kind == TraceEvent::Kind::TraceRayEnd && rs.committed && (rs.effectiveFlags & RAY_FLAG_SKIP_CLOSEST_HIT_SHADER))
            e.note = "closest hit skipped: SKIP_CLOSEST_HIT_SHADER (FLAG-9)";
        e.payloadTypeId = payloadType.id;
        e.payloadTypeName = payloadType.mangledName;
        e.payload = local;
        e.payloadSize = payloadType.size;
        observer(ts)->onEvent(e);
    };
    if (observer(ts)) emitRay(TraceEvent::Kind::TraceRay);

    countRay(ts, {r & kRayContributionMask, missIndex & kMissShaderIndexMask}, rs.depth);
    ts.rayCounter++;

    // RAY-7: an infinite origin or direction component makes the plain math NaN, so the ray finds nothing;
    // components beyond Embree's range get the same treatment. Embree never sees either kind of ray.
    const bool traceable = inTraversalRange(ray);  // false for NaN and infinite components too
    if (asAddress != 0 && traceable) {
        if (asAddress != ts.lastTlasAddress) {
            ts.lastTlas = ds.device->findTopLevelAS(asAddress);
            ts.lastTlasAddress = ts.lastTlas ? asAddress : 0;
        }
        rs.tlas = ts.lastTlas;
        if (!rs.tlas) {
            const bool isBottom = ds.device->findBottomLevelAS(asAddress) != nullptr;
            raise(ts, site, diag(isBottom ? "INST-10" : "RAY-1",
                                 isBottom ? "TraceRay was given a BLAS; it needs a TLAS"
                                          : "TraceRay was given an address that is not an acceleration structure")
                                .hex("AccelerationStructure", asAddress));
            return;
        }
        if (rs.tlas->checkedEpoch() != ds.epoch) {  // INST-8
            for (size_t i = 0; i < rs.tlas->instances().size(); ++i) {
                const BuiltInstance& inst = rs.tlas->instances()[i];
                if (inst.blas && inst.blas->generation() != inst.blasGeneration) {
                    raise(ts, site, diag("INST-8", "the TLAS was not rebuilt or updated after a BLAS it references was updated")
                                        .value("InstanceIndex", i)
                                        .hex("BLAS", inst.blas->address()));
                    return;
                }
            }
            rs.tlas->markChecked(ds.epoch);
        }

        // Gather (Embree broad phase + exact tests), order (GEN-3), then TRV-4 per candidate.
        ts.candidates.clear();
        GatherRequest gather;
        gather.tlas = rs.tlas;
        gather.origin = ray.Origin;
        gather.direction = ray.Direction;
        gather.tMin = ray.TMin;
        gather.tMax = ray.TMax;
        gather.instanceInclusionMask = rs.instanceInclusionMask;
        gather.skipTriangles = (rs.effectiveFlags & RAY_FLAG_SKIP_TRIANGLES) != 0;            // FLAG-12
        gather.skipProcedural = (rs.effectiveFlags & RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES) != 0;
        gather.alternateEdgeRule = ds.options.order == TraversalOrder::Adversarial && (ds.options.adversarialSeed & 1);
        gather.out = &ts.candidates;
        ShortcutContext shortcut{&ts, &rs, &site};
        gather.user = &shortcut;
        gather.commitsSurely = commitsSurely;
        gather.onCandidate = processNow;
        gather.mode = traversalMode(ts, rs);
        ts.stats.raysPerGatherMode[size_t(gather.mode)]++;
        gatherCandidates(gather);
        if (gather.mode != GatherMode::FirstHit) ts.stats.candidates += ts.candidates.size();
        else ts.candidates.clear();  // processed during the traversal
        orderCandidates(ts, rs);
        // Nested TraceRays (from the CHS below) reuse ts.candidates: iterate over a copy only
        // while shaders of this ray may run, which ends before the CHS starts.
        for (size_t i = 0; i < ts.candidates.size() && !rs.searchEnded; ++i) {
            const Candidate c = ts.candidates[i];
            if (observer(ts)) {
                TraceEvent e = event(ts, TraceEvent::Kind::Candidate, rs.depth);
                setHit(e, rs.tlas->instances()[c.instanceIndex], c.instanceIndex, c.geometryIndex, c.primitiveIndex);
                e.procedural = c.procedural;
                e.t = c.procedural ? c.key : c.t;
                observer(ts)->onEvent(e);
            }
            if (c.procedural) processProcedural(ts, rs, c, site);
            else processTriangle(ts, rs, c, site);
        }
    }

    // TRV-5, TRV-6: at most one CHS or one miss shader.
    if (rs.committed) {
        if (!(rs.effectiveFlags & RAY_FLAG_SKIP_CLOSEST_HIT_SHADER)) {  // FLAG-9
            const HitInfo& hit = rs.committedHit;
            const HitGroupIndexTerms terms =
                hitGroupRecordIndex(r, m, hit.geometryIndex, hit.instance->desc.InstanceContributionToHitGroupIndex);
            const BuiltGeometry& geom = hit.instance->blas->geometries()[hit.geometryIndex];
            HitLookupContext lookup{&terms, &hit, geom.type};
            RecordView record;
            if (lookupRecord(ts, site, ProgramEntry::Kind::HitGroup, ds.desc->HitGroupTable, terms.index, record, &lookup) &&
                record.entry && record.entry->closestHit) {
                Invocation inv;
                inv.stage = ShaderStage::ClosestHit;
                inv.shader = record.entry->closestHit;
                inv.record = &record;
                inv.ray = &rs;
                inv.hit = &rs.committedHit;
                inv.dispatch = &ds;
                inv.thread = &ts;
                inv.depth = rs.depth;
                checkGlobalSignature(ts, siteOf(inv), *record.entry);
                checkPayload(ts, siteOf(inv), *inv.shader, payloadType);
                invoke(ts, inv, rs.payload, rs.committedHit.attributes);
            }
        }
    } else {
        RecordView record;
        if (lookupRecord(ts, site, ProgramEntry::Kind::Miss, ds.desc->MissShaderTable, missRecordIndex(missIndex), record) &&
            record.entry) {
            Invocation inv;
            inv.stage = ShaderStage::Miss;
            inv.shader = record.entry->shader;
            inv.record = &record;
            inv.ray = &rs;
            inv.dispatch = &ds;
            inv.thread = &ts;
            inv.depth = rs.depth;
            checkGlobalSignature(ts, siteOf(inv), *record.entry);
            checkPayload(ts, siteOf(inv), *inv.shader, payloadType);
            invoke(ts, inv, rs.payload, nullptr);
        }
    }
    if (observer(ts)) emitRay(TraceEvent::Kind::TraceRayEnd);
    std::memcpy(payload, local, payloadType.size);
}

void callShader(Invocation& caller, uint32_t shaderIndex, void* parameters, TypeTag type) {
    ThreadState& ts = *caller.thread;
    DispatchState& ds = *ts.dispatch;
    const Site site = siteOf(caller);
    RecordView record;
    if (!lookupRecord(ts, site, ProgramEntry::Kind::Callable, ds.desc->CallableShaderTable,
                      callableRecordIndex(shaderIndex), record) ||
        !record.entry)
        return;  // REC-8: a NULL callable returns with the parameters unchanged
    const ShaderExport& shader = *record.entry->shader;
    if (!(shader.parameters == type)) {
        raise(ts, site, diag("CALL-1", "CallShader parameters are not the type callable shader '" + shader.name + "' declares")
                            .value("passed", type.name() + " (" + std::to_string(type.size) + " B)")
                            .value("declared", shader.parameters.name() + " (" + std::to_string(shader.parameters.size) + " B)"));
        return;
    }
    Invocation inv;
    inv.stage = ShaderStage::Callable;
    inv.shader = &shader;
    inv.record = &record;
    inv.dispatch = &ds;
    inv.thread = &ts;
    inv.depth = caller.depth;  // CALL-3: callables do not count toward recursion
    checkGlobalSignature(ts, siteOf(inv), *record.entry);
    alignas(16) uint8_t local[256];
    std::unique_ptr<uint8_t[]> heap;
    uint8_t* copy = local;
    if (type.size > sizeof local) {
        heap.reset(new uint8_t[type.size]);
        copy = heap.get();
    }
    std::memcpy(copy, parameters, type.size);
    invoke(ts, inv, copy, nullptr);
    std::memcpy(parameters, copy, type.size);
}


}  // namespace detail

// ---------------------------------------------------------------------------------------
// ShaderContext intrinsics.

using detail::Invocation;

namespace detail {
[[noreturn]] void stageError(Invocation& inv, const char* rule, const std::string& message) {
    detail::ThreadState& ts = *inv.thread;
    Diagnostic d = diag(rule, message).value("stage", toString(inv.stage));
    d.site = DiagnosticSite{ts.launchIndex, inv.depth, inv.stage, inv.shader ? inv.shader->name : std::string()};
    throw DxrError(std::move(d));  // misuse of the API always stops: there is no fallback
}
}  // namespace detail
using detail::stageError;

void ShaderContext::stageViolation(const char* intrinsic) const {
    stageError(inv_, "SV-1", std::string(intrinsic) + "() may not be called from a " + std::string(toString(inv_.stage)) +
                                 " shader");
}

void ShaderContext::calledAfterSearchEnded(const char* intrinsic) const {
    // `intrinsic` is an intrinsic's name ("RayTCurrent") or a description ("a memory read").
    std::string what = intrinsic;
    if (what.find(' ') == std::string::npos) what += "()";
    stageError(inv_, "IS-10", "intersection shader '" + inv_.shader->name + "' is registered with ReportHitEnd::Return " +
                                  "(each ReportHit is its last action) but used " + what +
                                  " after a ReportHit that ended the search");
}

uvec3 ShaderContext::DispatchRaysIndex() const {
    requireLive("DispatchRaysIndex");
    return inv_.thread->launchIndex;
}

uvec3 ShaderContext::DispatchRaysDimensions() const {
    requireLive("DispatchRaysDimensions");
    const DispatchRaysDesc& d = *inv_.dispatch->desc;
    return {d.Width, d.Height, d.Depth};
}

float ShaderContext::RayTCurrent() const {
    requireStage(kRay, "RayTCurrent");
    switch (inv_.stage) {  // SV-5
        case ShaderStage::Intersection: return inv_.ray->tCurrent;
        case ShaderStage::AnyHit:
        case ShaderStage::ClosestHit: return inv_.hit->t;
        default: return inv_.ray->ray.TMax;
    }
}

uint32_t ShaderContext::InstanceID() const { return hitInfo("InstanceID").instance->desc.InstanceID; }

Matrix3x4 ShaderContext::ObjectToWorld3x4() const { return hitInfo("ObjectToWorld3x4").instance->objectToWorld; }
std::array<std::array<float, 3>, 4> ShaderContext::ObjectToWorld4x3() const {
    return transposed(hitInfo("ObjectToWorld4x3").instance->objectToWorld);
}
Matrix3x4 ShaderContext::WorldToObject3x4() const { return hitInfo("WorldToObject3x4").instance->worldToObject; }
std::array<std::array<float, 3>, 4> ShaderContext::WorldToObject4x3() const {
    return transposed(hitInfo("WorldToObject4x3").instance->worldToObject);
}

uint32_t ShaderContext::HitKind() const {
    requireStage(bit(ShaderStage::AnyHit) | bit(ShaderStage::ClosestHit), "HitKind");
    return inv_.hit->hitKind;
}

bool ShaderContext::reportHit(float tHit, uint32_t hitKind, const void* attributes, TypeTag type) {
    requireStage(bit(ShaderStage::Intersection), "ReportHit");
    return detail::reportHit(inv_, tHit, hitKind, attributes, type);
}

void ShaderContext::IgnoreHit() {
    requireStage(bit(ShaderStage::AnyHit), "IgnoreHit");
    throw detail::IgnoreHitSignal{};
}

void ShaderContext::AcceptHitAndEndSearch() {
    requireStage(bit(ShaderStage::AnyHit), "AcceptHitAndEndSearch");
    throw detail::AcceptHitAndEndSearchSignal{};
}

void ShaderContext::traceRay(GpuVirtualAddress as, uint32_t flags, uint32_t mask, uint32_t r, uint32_t m, uint32_t miss,
                             const RayDesc& ray, void* payload, TypeTag payloadType) {
    requireLive("TraceRay");
    if (!(bit(inv_.stage) & (bit(ShaderStage::RayGeneration) | bit(ShaderStage::ClosestHit) | bit(ShaderStage::Miss))))
        stageError(inv_, "RAY-2", "TraceRay() may not be called from a " + std::string(toString(inv_.stage)) + " shader");
    // Timed here rather than inside detail::traceRay: a cleanup there would lengthen the unwind table that
    // every end-search signal caught in it walks. The shaders it invokes charge their own time.
    const detail::ProfileScope traversal(*inv_.thread, ProfileStage::Traversal);
    detail::traceRay(inv_, as, flags, mask, r, m, miss, ray, payload, payloadType);
}

void ShaderContext::callShader(uint32_t index, void* parameters, TypeTag type) {
    requireLive("CallShader");
    if (!(bit(inv_.stage) & (bit(ShaderStage::RayGeneration) | bit(ShaderStage::ClosestHit) | bit(ShaderStage::Miss) |
                             bit(ShaderStage::Callable))))
        stageError(inv_, "CALL-2", "CallShader() may not be called from a " + std::string(toString(inv_.stage)) + " shader");
    detail::callShader(inv_, index, parameters, type);
}

const uint8_t* ShaderContext::rootArgument(bool local, uint32_t parameter, size_t size, TypeTag type) const {
    requireLive(local ? "a local root argument read" : "a global root argument read");
    // Arguments that passed rootArgumentChecked's checks pass them again (LookupCache): the same argument bytes
    // (those of one record, or the dispatch's global ones), parameter, size and type.
    const detail::ArgumentBytes arguments = detail::argumentBytes(inv_, *inv_.dispatch, local);
    const detail::LookupCache::RootArgument& cached =
        inv_.thread->lookups.rootArguments[detail::LookupCache::rootArgumentSlot(arguments.bytes, parameter)];
    if (arguments.bytes && cached.arguments == arguments.bytes && cached.available == arguments.available &&
        cached.parameter == parameter && cached.size == size && cached.type == type.id)
        return cached.bytes;
    return rootArgumentChecked(local, parameter, size, type, arguments);
}

const uint8_t* ShaderContext::rootArgumentChecked(bool local, uint32_t parameter, size_t size, TypeTag type,
                                                  const detail::ArgumentBytes& arguments) const {
    const RootSignature* signature = nullptr;
    if (local) {
        if (inv_.record && inv_.record->entry) signature = inv_.record->entry->localRootSignature.get();
    } else if (inv_.dispatch->global) {
        signature = inv_.dispatch->global->signature().get();
    }
    const auto& [bytes, written, available] = arguments;
    const char* which = local ? "local" : "global";
    if (!signature)
        stageError(inv_, local ? "REC-11" : "PIPE-6",
                   std::string("shader reads ") + which + " root parameter " + std::to_string(parameter) + " but has no " +
                       which + " root signature");
    if (parameter >= signature->parameterCount())
        stageError(inv_, local ? "REC-11" : "PIPE-6",
                   std::string(which) + " root signature '" + signature->name() + "' has " +
                       std::to_string(signature->parameterCount()) + " parameters; the shader reads parameter " +
                       std::to_string(parameter));
    const RootParameter& p = signature->parameter(parameter);
    const bool wantConstants = type.valid();
    if (wantConstants != (p.parameterType == RootParameterType::Constants32Bit) ||
        (wantConstants && size != p.num32BitValues * 4u))
        stageError(inv_, "REC-11",
                   std::string(which) + " root parameter " + std::to_string(parameter) + " of '" + signature->name() +
                       "' is " + std::string(toString(p.parameterType)) +
                       (p.parameterType == RootParameterType::Constants32Bit ? " (" + std::to_string(p.num32BitValues * 4) + " bytes)" : std::string()) +
                       "; the shader reads it as " + (wantConstants ? type.name() + " (" + std::to_string(size) + " bytes)" : std::string("a descriptor")));
    const uint32_t offset = signature->argumentOffset(parameter) - kShaderIdentifierSizeInBytes;
    if (offset + size > available)
        stageError(inv_, "REC-11", std::string(which) + " root parameter " + std::to_string(parameter) +
                                       " lies past the bytes available to the record");
    if (std::memchr(written + offset, 0, size))
        stageError(inv_, "REC-7", std::string("shader reads ") + which + " root parameter " + std::to_string(parameter) +
                                      " of '" + signature->name() + "', whose bytes were never written");
    inv_.thread->lookups.rootArguments[detail::LookupCache::rootArgumentSlot(bytes, parameter)] = {
        bytes, available, parameter, uint32_t(size), type.id, bytes + offset};
    return bytes + offset;
}

GpuVirtualAddress ShaderContext::localRootDescriptor(uint32_t parameter) const {
    GpuVirtualAddress va;
    std::memcpy(&va, rootArgument(true, parameter, 8, TypeTag{}), 8);
    return va;
}

GpuVirtualAddress ShaderContext::globalRootDescriptor(uint32_t parameter) const {
    GpuVirtualAddress va;
    std::memcpy(&va, rootArgument(false, parameter, 8, TypeTag{}), 8);
    return va;
}

GpuDescriptorHandle ShaderContext::globalDescriptorTable(uint32_t parameter) const { return globalRootDescriptor(parameter); }

// ---------------------------------------------------------------------------------------
// DispatchRays.

namespace {

// Locks every table the dispatch reads for its whole duration (REC-12).
class TableLock {
public:
    TableLock(GpuMemory& memory, std::vector<GpuVirtualAddress> addresses) : memory_(memory), addresses_(std::move(addresses)) {
        for (auto a : addresses_) memory_.setLocked(a, true);
    }
    ~TableLock() {
        for (auto a : addresses_) memory_.setLocked(a, false);
    }
    TableLock(const TableLock&) = delete;
    TableLock& operator=(const TableLock&) = delete;

private:
    GpuMemory& memory_;
    std::vector<GpuVirtualAddress> addresses_;
};

void checkTableRange(const char* name, GpuVirtualAddress start, uint64_t size, uint64_t stride, bool hasStride) {
    if (start == 0 && size == 0) return;
    if (start % kShaderTableByteAlignment)
        throw DxrError(diag("REC-2", std::string(name) + " StartAddress is not a multiple of 64")
                           .hex("StartAddress", start)
                           .value("StartAddress % 64", start % kShaderTableByteAlignment, "0"));
    if (hasStride && (stride % kShaderRecordByteAlignment || stride > kMaxShaderRecordStride))
        throw DxrError(diag("REC-3", std::string(name) + " StrideInBytes must be a multiple of 32 in [0, 4096]")
                           .value("StrideInBytes", stride, "multiple of 32, <= 4096"));
}

}  // namespace

DispatchResult Device::dispatchRays(const DispatchRaysDesc& desc, const StateObjectPtr& pipeline,
                                    const GlobalRootArguments* globalArguments, const DispatchOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    if (!pipeline)
        throw DxrError(diag("RGS-3", "DispatchRays without a bound ray-tracing pipeline state object"));
    const uint64_t threads = uint64_t(desc.Width) * desc.Height * desc.Depth;
    if (threads > kMaxRayGenerationShaderThreads)
        throw DxrError(diag("RGS-1", "DispatchRays launches too many threads")
                           .value("Width*Height*Depth", threads, std::to_string(kMaxRayGenerationShaderThreads))
                           .value("Width", desc.Width)
                           .value("Height", desc.Height)
                           .value("Depth", desc.Depth));
    checkTableRange("RayGenerationShaderRecord", desc.RayGenerationShaderRecord.StartAddress,
                    desc.RayGenerationShaderRecord.SizeInBytes, 0, false);
    checkTableRange("MissShaderTable", desc.MissShaderTable.StartAddress, desc.MissShaderTable.SizeInBytes,
                    desc.MissShaderTable.StrideInBytes, true);
    checkTableRange("HitGroupTable", desc.HitGroupTable.StartAddress, desc.HitGroupTable.SizeInBytes,
                    desc.HitGroupTable.StrideInBytes, true);
    checkTableRange("CallableShaderTable", desc.CallableShaderTable.StartAddress, desc.CallableShaderTable.SizeInBytes,
                    desc.CallableShaderTable.StrideInBytes, true);
    for (auto [name, range] : {std::pair{"MissShaderTable", GpuVirtualAddressRange{desc.MissShaderTable.StartAddress, desc.MissShaderTable.SizeInBytes}},
                               std::pair{"HitGroupTable", GpuVirtualAddressRange{desc.HitGroupTable.StartAddress, desc.HitGroupTable.SizeInBytes}},
                               std::pair{"CallableShaderTable", GpuVirtualAddressRange{desc.CallableShaderTable.StartAddress, desc.CallableShaderTable.SizeInBytes}},
                               std::pair{"RayGenerationShaderRecord", desc.RayGenerationShaderRecord}}) {
        if (range.SizeInBytes && !memory_.find(range.StartAddress, range.SizeInBytes))
            throw DxrError(diag("IDX-11", std::string(name) + " range is not inside one GPU buffer")
                               .hex("StartAddress", range.StartAddress)
                               .value("SizeInBytes", range.SizeInBytes));
    }
    LaunchRegion region{0, 0, desc.Width, desc.Height};
    if (options.region) {
        region = *options.region;
        REFRAY_CHECK(uint64_t(region.x) + region.width <= desc.Width && uint64_t(region.y) + region.height <= desc.Height,
                     "the launch region " << region.width << "x" << region.height << " at (" << region.x << ", "
                                          << region.y << ") is not inside the " << desc.Width << "x" << desc.Height
                                          << " dispatch");
    }
    if (globalArguments && globalArguments->signature()->isLocal())
        throw DxrError(diag("PIPE-7", "the root signature bound for the dispatch is a local root signature")
                           .value("signature", globalArguments->signature()->name()));

    detail::DispatchState ds;
    ds.device = this;
    ds.memory = &memory_;
    ds.pipeline = pipeline.get();
    ds.desc = &desc;
    ds.global = globalArguments;
    ds.options = options;
    ds.epoch = epoch_.load();
    for (const ProgramEntry& entry : pipeline->entries())
        if (entry.anyHit) ds.anyHitInPipeline = true;

    // The ray generation record (IDX-9, IDX-13), resolved once for every thread.
    {
        detail::ThreadState probe;
        probe.dispatch = &ds;
        static const std::string none;
        const detail::Site site{ShaderStage::RayGeneration, &none, 0};
        DispatchOptions stop = options;
        stop.onError = OnError::Stop;
        ds.options = stop;
        const GpuVirtualAddressRangeAndStride rg{desc.RayGenerationShaderRecord.StartAddress,
                                                 desc.RayGenerationShaderRecord.SizeInBytes, 0};
        if (rg.StartAddress == 0 || rg.SizeInBytes < kShaderIdentifierSizeInBytes)
            throw DxrError(diag("IDX-9", "RayGenerationShaderRecord must hold at least the 32-byte identifier")
                               .hex("StartAddress", rg.StartAddress)
                               .value("SizeInBytes", rg.SizeInBytes, ">= 32"));
        detail::lookupRecord(probe, site, ProgramEntry::Kind::RayGeneration, rg, 0, ds.rayGenRecord);
        ds.options = options;
    }
    DispatchResult result;
    result.stats.stagesProfiled = options.profileStages;
    if (!ds.rayGenRecord.entry || threads == 0) {  // REC-8: NULL ray generation; RGS-1: zero size
        result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return result;
    }

    TableLock lock(memory_, {desc.RayGenerationShaderRecord.StartAddress, desc.MissShaderTable.StartAddress,
                             desc.HitGroupTable.StartAddress, desc.CallableShaderTable.StartAddress});
    tbb::enumerable_thread_specific<detail::ThreadState> threadStates([&] {
        detail::ThreadState ts;
        ts.dispatch = &ds;
        ts.candidates.reserve(64);
        ts.profiling = options.profileStages;
        return ts;
    });

    const uint32_t tile = std::max(1u, options.tileSize);
    const int arenaThreads = options.threads ? int(options.threads) : tbb::task_arena::automatic;
    tbb::task_arena arena(arenaThreads);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range2d<uint32_t>(region.y, region.y + region.height, tile, region.x, region.x + region.width, tile),
            [&](const tbb::blocked_range2d<uint32_t>& range) {
                detail::ThreadState& ts = threadStates.local();
                for (uint32_t z = 0; z < desc.Depth; ++z) {
                    for (uint32_t y = range.rows().begin(); y < range.rows().end(); ++y) {
                        for (uint32_t x = range.cols().begin(); x < range.cols().end(); ++x) {
                            ts.launchIndex = uvec3(x, y, z);
                            ts.linearIndex = (uint64_t(z) * desc.Height + y) * desc.Width + x;
                            if (ts.linearIndex > ds.firstErrorIndex.load(std::memory_order_relaxed)) continue;
                            ts.rayCounter = 0;
                            detail::Invocation inv;
                            inv.stage = ShaderStage::RayGeneration;
                            inv.shader = ds.rayGenRecord.entry->shader;
                            inv.record = &ds.rayGenRecord;
                            inv.dispatch = &ds;
                            inv.thread = &ts;
                            inv.depth = 0;
                            try {
                                detail::checkGlobalSignature(ts, detail::siteOf(inv), *ds.rayGenRecord.entry);
                                detail::invoke(ts, inv, nullptr, nullptr);
                            } catch (const DxrError& e) {
                                ts.stopErrors.push_back(e.diagnostic());
                                uint64_t seen = ds.firstErrorIndex.load();
                                while (ts.linearIndex < seen && !ds.firstErrorIndex.compare_exchange_weak(seen, ts.linearIndex)) {
                                }
                            } catch (const Error& e) {
                                Diagnostic d = diag("GEN-1", e.what());
                                d.site = DiagnosticSite{ts.launchIndex, 0, ShaderStage::RayGeneration, inv.shader->name};
                                ts.stopErrors.push_back(d);
                                uint64_t seen = ds.firstErrorIndex.load();
                                while (ts.linearIndex < seen && !ds.firstErrorIndex.compare_exchange_weak(seen, ts.linearIndex)) {
                                }
                            }
                        }
                    }
                }
                if (options.progress) options.progress->advance(range.rows().size() * range.cols().size());
            });
    });

    std::vector<Diagnostic> errors;
    for (auto& ts : threadStates) {
        result.diagnostics.merge(ts.log);
        result.stats.merge(detail::finishedStats(ts));
        errors.insert(errors.end(), ts.stopErrors.begin(), ts.stopErrors.end());
    }
    if (!errors.empty()) {
        auto linear = [&](const Diagnostic& d) {
            const uvec3 l = d.site ? d.site->launchIndex : uvec3(0u);
            return (uint64_t(l.z) * desc.Height + l.y) * desc.Width + l.x;
        };
        auto first = std::min_element(errors.begin(), errors.end(),
                                      [&](const Diagnostic& a, const Diagnostic& b) { return linear(a) < linear(b); });
        throw DxrError(*first);
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace refray::dxr
