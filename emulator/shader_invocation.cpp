// Shader invocation: the checks before a shader runs (PIPE-6, PAY-1), the call itself with its statistics,
// trace event, call chain and stage time, and CallShader.
#include "emulator/detail/shader_invocation.h"

#include "emulator/detail/record_lookup.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_events.h"
#include "emulator/shader_api.h"

namespace refray::dxr::detail {

namespace {

void countInvocation(ThreadState& ts, const ShaderExport* shader) {
    for (ExportCount& e : ts.exportCounts)
        if (e.shader == shader) {
            ++e.count;
            return;
        }
    ts.exportCounts.push_back({shader, 1});
}


// The PIPE-6 and PAY-1 reports (cold: out of the frames of the shader calls that check).
[[gnu::cold, gnu::noinline]] void raiseGlobalSignature(ThreadState& ts, const Site& site, const ProgramEntry& entry,
                                                       const RootSignature* bound) {
    raise(ts, site,
          diag("PIPE-6", "'" + entry.name + "' uses a global root signature other than the one bound for the dispatch")
              .value("shader's", entry.globalRootSignature->name())
              .value("bound", bound ? bound->name() : std::string("(none)")));
}

[[gnu::cold, gnu::noinline]] void raisePayload(ThreadState& ts, const Site& site, const ShaderExport& shader,
                                               TypeTag traced) {
    raise(ts, site, diag("PAY-1", std::string(toString(shader.stage)) + " shader '" + shader.name +
                                      "' declares another payload type than the TraceRay that invokes it")
                        .value("TraceRay payload", traced.name() + " (" + std::to_string(traced.size) + " B)")
                        .value("shader payload", shader.payload.name() + " (" + std::to_string(shader.payload.size) + " B)"));
}

}  // namespace

void checkGlobalSignature(ThreadState& ts, const Site& site, const ProgramEntry& entry) {
    const DispatchState& ds = *ts.dispatch;
    const RootSignature* bound = ds.global ? ds.global->signature().get() : nullptr;
    if (entry.globalRootSignature && entry.globalRootSignature.get() != bound)
        raiseGlobalSignature(ts, site, entry, bound);
}

void checkPayload(ThreadState& ts, const Site& site, const ShaderExport& shader, TypeTag traced) {
    if (!(shader.payload == traced)) raisePayload(ts, site, shader, traced);
}

namespace {

// The ShaderCall event (out of line: an event is large, and beginInvocation runs for every shader call).
[[gnu::noinline]] void emitShaderCall(const ThreadState& ts, const Invocation& inv) {
    TraceEvent e = event(ts, TraceEvent::Kind::ShaderCall, inv.depth);
    e.stage = inv.stage;
    e.exportName = inv.shader->name;
    if (inv.record) {
        e.recordIndex = inv.record->index;
        e.recordAddress = inv.record->address;
    }
    if (inv.hit) setHit(e, *inv.hit);
    observer(ts)->onEvent(e);
}

}  // namespace

uint8_t beginInvocation(ThreadState& ts, const Invocation& inv) {
    ts.stats.invocations[size_t(inv.stage)]++;
    countInvocation(ts, inv.shader);
    if (observer(ts)) emitShaderCall(ts, inv);
    ts.callChain.push_back(inv.shader);
    return ts.profiling ? ts.clock.enter(uint8_t(profileStageOf(inv.stage))) : StageClock::kOutside;
}

void endInvocation(ThreadState& ts, uint8_t callerSection) {
    ts.callChain.pop_back();
    if (ts.profiling) ts.clock.enter(callerSection);
}

void invoke(ThreadState& ts, Invocation& inv, void* payload, const void* attributes) {
    // On every exit, non-local ones included: pop the call chain and, when profiling, hand the clock back
    // to the caller's section. One object, so the IgnoreHit / end-search signals unwind one cleanup here.
    struct ShaderScope {
        ThreadState& ts;
        uint8_t callerSection;
        ~ShaderScope() { endInvocation(ts, callerSection); }
    };
    const ShaderScope scope{ts, beginInvocation(ts, inv)};
    ShaderContext ctx(inv);
    inv.shader->function(ctx, payload, attributes);
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
    // CALL-3: callables do not count toward recursion.
    Invocation inv = invocation(ts, ShaderStage::Callable, &shader, &record, caller.depth);
    checkGlobalSignature(ts, siteOf(inv), *record.entry);
    ValueCopy copy(parameters, type.size);
    invoke(ts, inv, copy.data(), nullptr);
    copy.copyBack(parameters);
}

}  // namespace refray::dxr::detail
