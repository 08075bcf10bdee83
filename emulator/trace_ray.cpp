// TraceRay (dxr-semantics.md sections 4-10): argument validation, the TLAS, candidate gathering and the TRV-4
// loop, then the closest-hit or miss shader.
#include "emulator/detail/trace_ray.h"

#include <cmath>
#include <optional>

#include "emulator/detail/record_lookup.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_events.h"
#include "emulator/detail/wave.h"
#include "emulator/device.h"
#include "emulator/limits.h"

namespace refray::dxr::detail {

namespace {

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

std::string describeCallChain(const ThreadState& ts) {
    std::string out;
    for (const ShaderExport* s : ts.callChain) {
        if (!out.empty()) out += " -> ";
        out += std::string(toString(s->stage)) + " '" + s->name + "'";
    }
    return out;
}

// Embree's traversal accepts origin and direction components up to ±1.844e18 (its FLT_LARGE) and asserts
// beyond; refray treats a finite ray beyond that like an infinite one (RAY-7: a warning, then a miss).
constexpr float kTraversalRange = 1.844e18f;

}  // namespace

bool inTraversalRange(const RayDesc& ray) {
    for (int c = 0; c < 3; ++c)
        if (!(std::fabs(ray.Origin[c]) <= kTraversalRange && std::fabs(ray.Direction[c]) <= kTraversalRange)) return false;
    return true;
}

namespace {

std::string vec3Values(const vec3& v) {
    return std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z);
}

// validateRay's reports, for a ray that is not plainly valid: out of line, so that the common case's frame (and the
// frames of TraceRay and RayQuery around it) stays small.
[[gnu::cold, gnu::noinline]] void reportRay(ThreadState& ts, const Site& site, const RayDesc& ray, bool& ok,
                                            const char* rule) {
    auto field = [&](const char* name, float v) {
        if (std::isnan(v)) {
            raise(ts, site, diag(rule, std::string("RayDesc.") + name + " is NaN").value(name, v));
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
        raise(ts, site, diag(rule, "RayDesc.TMin is negative").value("TMin", ray.TMin, ">= 0"));
        ok = false;
    } else if (ray.TMin > ray.TMax) {
        raise(ts, site, diag(rule, "RayDesc.TMin is greater than TMax").value("TMin", ray.TMin).value("TMax", ray.TMax, ">= TMin"));
        ok = false;
    }
    if (std::isinf(ray.TMin))
        warn(ts, site, warning(rule, "RayDesc.TMin is infinite; no hit can follow").value("TMin", ray.TMin));
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

}  // namespace

void validateRay(ThreadState& ts, const Site& site, const RayDesc& ray, bool& ok, const char* rule) {
    // inTraversalRange also fails for NaN and infinite components, so it covers their finiteness too.
    if (inTraversalRange(ray) && std::isfinite(ray.TMin) && !std::isnan(ray.TMax) && ray.TMin >= 0.0f &&
        ray.TMin <= ray.TMax && ray.Direction != vec3(0.0f))
        return;  // the common case: nothing to report
    reportRay(ts, site, ray, ok, rule);
}

namespace {

// validateFlags' report of a broken flag rule (cold: out of the callers' frames).
[[gnu::cold, gnu::noinline]] bool reportFlags(ThreadState& ts, const Site& site, uint32_t rayFlags,
                                              uint32_t pipelineFlags, const char* queryRule, const char* rule,
                                              const char* what) {
    if (queryRule)
        raise(ts, site, diag(queryRule, what)
                            .value("template flags", rayFlagsToString(pipelineFlags))
                            .value("TraceRayInline flags", rayFlagsToString(rayFlags))
                            .value("OR'd", rayFlagsToString(rayFlags | pipelineFlags)));
    else
        raise(ts, site, diag(rule, what)
                            .value("TraceRay flags", rayFlagsToString(rayFlags))
                            .value("pipeline flags", pipelineFlagsToString(pipelineFlags)));
    return false;
}

}  // namespace

bool validateFlags(ThreadState& ts, const Site& site, uint32_t rayFlags, uint32_t pipelineFlags,
                   const char* queryRule) {
    const uint32_t eff = rayFlags | pipelineFlags;
    auto fail = [&](const char* rule, const char* what) {
        return reportFlags(ts, site, rayFlags, pipelineFlags, queryRule, rule, what);
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

namespace {

// The TraceRay and TraceRayEnd events. `asAddress` and `mask` are the TraceRay arguments as passed. Out of line: the
// event is large, and TraceRay's frame stays with the lane while its closest-hit shader runs.
[[gnu::noinline]] void emitRay(const ThreadState& ts, const RayState& rs, TraceEvent::Kind kind, GpuVirtualAddress asAddress,
             uint32_t mask) {
    TraceEvent e = event(ts, kind, rs.depth);
    e.accelerationStructure = asAddress;
    e.ray = rs.ray;
    e.rayFlags = rs.rayFlags;
    e.effectiveFlags = rs.effectiveFlags;
    e.instanceInclusionMask = mask;
    e.rayContribution = rs.rayContribution;
    e.multiplier = rs.multiplier;
    e.missShaderIndex = rs.missShaderIndex;
    e.committed = rs.committed;
    if (rs.committed) {
        setHit(e, rs.committedHit);
        e.t = rs.committedHit.t;
        e.hitKind = rs.committedHit.hitKind;
    }
    if (kind == TraceEvent::Kind::TraceRayEnd && rs.committed && (rs.effectiveFlags & RAY_FLAG_SKIP_CLOSEST_HIT_SHADER))
        e.note = "closest hit skipped: SKIP_CLOSEST_HIT_SHADER (FLAG-9)";
    e.payloadTypeId = rs.payloadType.id;
    e.payloadTypeName = rs.payloadType.mangledName;
    e.payload = static_cast<const uint8_t*>(rs.payload);
    e.payloadSize = rs.payloadType.size;
    observer(ts)->onEvent(e);
}

// The TLAS at `asAddress`, or null: a one-entry cache per thread in front of the device's lookup.
const TopLevelAS* lookupTopLevelAS(ThreadState& ts, GpuVirtualAddress asAddress) {
    if (asAddress != ts.lastTlasAddress) {
        ts.lastTlas = ts.dispatch->device->findTopLevelAS(asAddress);
        ts.lastTlasAddress = ts.lastTlas ? asAddress : 0;
    }
    return ts.lastTlas;
}

// RAY-1, INST-10: TraceRay was given an address that holds no TLAS.
void raiseNotTopLevelAS(ThreadState& ts, const Site& site, GpuVirtualAddress asAddress) {
    const bool isBottom = ts.dispatch->device->findBottomLevelAS(asAddress) != nullptr;
    raise(ts, site, diag(isBottom ? "INST-10" : "RAY-1",
                         isBottom ? "TraceRay/TraceRayInline was given a BLAS; it needs a TLAS"
                                  : "TraceRay/TraceRayInline was given an address that is not an acceleration structure")
                        .hex("AccelerationStructure", asAddress));
}

// INST-8, once per acceleration-structure epoch: no BLAS that `tlas` references was updated after the TLAS was
// built. False when it has raised INST-8.
bool checkBottomLevelsCurrent(ThreadState& ts, const Site& site, const TopLevelAS& tlas) {
    for (size_t i = 0; i < tlas.instances().size(); ++i) {
        const BuiltInstance& inst = tlas.instances()[i];
        if (inst.blas && inst.blas->generation() != inst.blasGeneration) {
            raise(ts, site, diag("INST-8", "the TLAS was not rebuilt or updated after a BLAS it references was updated")
                                .value("InstanceIndex", i)
                                .hex("BLAS", inst.blas->address()));
            return false;
        }
    }
    tlas.markChecked(ts.dispatch->epoch);
    return true;
}

// TRV-5, TRV-6: at most one CHS or one miss shader.
void runClosestHitOrMiss(ThreadState& ts, RayState& rs, const Site& site) {
    const DispatchState& ds = *ts.dispatch;
    if (rs.committed) {
        RecordView record;
        Invocation inv;
        if (prepareClosestHit(ts, rs, site, record, inv)) invoke(ts, inv, rs.payload, rs.committedHit.attributes);
    } else {
        RecordView record;
        if (lookupRecord(ts, site, ProgramEntry::Kind::Miss, ds.desc->MissShaderTable, missRecordIndex(rs.missShaderIndex),
                         record) &&
            record.entry) {
            Invocation inv = invocation(ts, ShaderStage::Miss, record.entry->shader, &record, rs.depth, &rs);
            checkGlobalSignature(ts, siteOf(inv), *record.entry);
            checkPayload(ts, siteOf(inv), *inv.shader, rs.payloadType);
            invoke(ts, inv, rs.payload, nullptr);
        }
    }
}

// TraceRay's argument reports (cold: out of its frame, which stays with the lane while its closest-hit shader runs).
[[gnu::cold, gnu::noinline]] void raiseRecursionLimit(ThreadState& ts, const Site& site, uint32_t depth) {
    const uint32_t limit = ts.dispatch->pipeline->maxTraceRecursionDepth();
    raise(ts, site, diag("LIM-2", "TraceRay at the recursion limit: a call at depth == MaxTraceRecursionDepth removes the device")
                        .value("depth", depth, "< MaxTraceRecursionDepth " + std::to_string(limit))
                        .value("call chain", describeCallChain(ts)));
}

[[gnu::cold, gnu::noinline]] void raiseUndefinedFlags(ThreadState& ts, const Site& site, uint32_t rayFlags) {
    raise(ts, site, diag("RAY-10", "TraceRay flags set undefined bits")
                        .hex("RayFlags", rayFlags)
                        .hex("undefined bits", rayFlags & ~kDefinedRayFlags));
}

[[gnu::cold, gnu::noinline]] void warnIndexBits(ThreadState& ts, const Site& site, uint32_t r, uint32_t m) {
    warn(ts, site, warning("IDX-2", "TraceRay index arguments have bits above the low 4; DXR ignores them")
                       .value("RayContributionToHitGroupIndex", r, "0..15")
                       .value("MultiplierForGeometryContributionToHitGroupIndex", m, "0..15"));
}

}  // namespace

bool prepareClosestHit(ThreadState& ts, RayState& rs, const Site& site, RecordView& record, Invocation& inv) {
    if (!rs.committed || (rs.effectiveFlags & RAY_FLAG_SKIP_CLOSEST_HIT_SHADER)) return false;  // FLAG-9
    HitInfo& hit = rs.committedHit;
    const GeometryType type = hit.instance->blas->geometries()[hit.geometryIndex].type;
    if (!lookupHitGroupRecord(ts, site, rs, hit, type, record) || !record.entry || !record.entry->closestHit)
        return false;
    setInvocation(inv, ts, ShaderStage::ClosestHit, record.entry->closestHit, &record, rs.depth, &rs, &hit);
    checkGlobalSignature(ts, siteOf(inv), *record.entry);
    checkPayload(ts, siteOf(inv), *inv.shader, rs.payloadType);
    return true;
}

void endTraceRay(Invocation& caller, const TraceRayCall& call, RayState& rs, ValueCopy& payload) {
    ThreadState& ts = *caller.thread;
    if (observer(ts)) emitRay(ts, rs, TraceEvent::Kind::TraceRayEnd, call.accelerationStructure, call.instanceInclusionMask);
    payload.copyBack(call.payload);
}

const TopLevelAS* findTopLevelAS(ThreadState& ts, const Site& site, GpuVirtualAddress asAddress) {
    const TopLevelAS* tlas = lookupTopLevelAS(ts, asAddress);
    if (!tlas) {
        raiseNotTopLevelAS(ts, site, asAddress);
        return nullptr;
    }
    if (tlas->checkedEpoch() != ts.dispatch->epoch && !checkBottomLevelsCurrent(ts, site, *tlas)) return nullptr;
    return tlas;
}

TraceRayStart beginTraceRay(Invocation& caller, const TraceRayCall& call, RayState& rs,
                            std::optional<ValueCopy>& payload) {
    ThreadState& ts = *caller.thread;
    const DispatchState& ds = *ts.dispatch;
    const Site site = siteOf(caller);
    uint32_t rayFlags = call.rayFlags;
    const uint32_t r = call.rayContribution, m = call.multiplier;

    // The arguments: LIM-2, RAY-10 (undefined bits are dropped), FLAG-2..5, RAY-5 and RAY-7, IDX-2.
    if (caller.depth >= ds.pipeline->maxTraceRecursionDepth()) {  // LIM-2
        raiseRecursionLimit(ts, site, caller.depth);
        return TraceRayStart::Ended;  // fallback: the call does nothing
    }
    if (rayFlags & ~kDefinedRayFlags) {  // RAY-10
        raiseUndefinedFlags(ts, site, rayFlags);
        rayFlags &= kDefinedRayFlags;
    }
    if (!validateFlags(ts, site, rayFlags, ds.pipeline->pipelineFlags())) return TraceRayStart::Ended;
    bool rayOk = true;
    validateRay(ts, site, call.ray, rayOk, "RAY-5");
    if (!rayOk) return TraceRayStart::Ended;
    if ((r & ~kRayContributionMask) || (m & ~kGeometryMultiplierMask)) warnIndexBits(ts, site, r, m);  // IDX-2

    rs.ray = call.ray;
    rs.rayFlags = rayFlags;
    rs.effectiveFlags = rayFlags | ds.pipeline->pipelineFlags();
    rs.instanceInclusionMask = call.instanceInclusionMask & kInstanceInclusionMaskBits;
    rs.rayContribution = r;
    rs.multiplier = m;
    rs.missShaderIndex = call.missShaderIndex;
    rs.depth = caller.depth + 1;
    rs.tCurrent = call.ray.TMax;
    rs.payloadType = call.payloadType;

    // RAY-9: the payload is passed by value.
    rs.payload = payload.emplace(call.payload, call.payloadType.size).data();
    if (observer(ts)) emitRay(ts, rs, TraceEvent::Kind::TraceRay, call.accelerationStructure, call.instanceInclusionMask);

    countRay(ts, {r & kRayContributionMask, call.missShaderIndex & kMissShaderIndexMask}, rs.depth);
    ts.rayCounter++;

    // RAY-7: an infinite origin or direction component makes the plain math NaN, so the ray finds nothing;
    // components beyond Embree's range get the same treatment. Embree never sees either kind of ray.
    const bool traceable = inTraversalRange(call.ray);  // false for NaN and infinite components too
    if (call.accelerationStructure == 0 || !traceable) return TraceRayStart::Invoke;
    rs.tlas = findTopLevelAS(ts, site, call.accelerationStructure);
    return rs.tlas ? TraceRayStart::Traverse : TraceRayStart::Ended;
}

void finishTraceRay(Invocation& caller, const TraceRayCall& call, RayState& rs, ValueCopy& payload) {
    runClosestHitOrMiss(*caller.thread, rs, siteOf(caller));
    endTraceRay(caller, call, rs, payload);
}

void traceRay(Invocation& caller, const TraceRayCall& call) {
    RayState rs;
    std::optional<ValueCopy> payload;
    switch (beginTraceRay(caller, call, rs, payload)) {
        case TraceRayStart::Ended: return;
        case TraceRayStart::Traverse:
            // The wave's packet gathers and processes the candidates (detail/wave.h).
            awaitTraversal(*caller.thread, rs, siteOf(caller));
            break;
        case TraceRayStart::Invoke: break;
    }
    finishTraceRay(caller, call, rs, *payload);
}

}  // namespace refray::dxr::detail
