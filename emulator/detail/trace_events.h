// Trace events (emulator/trace.h) as the dispatcher builds them: only when an observer is installed.
// Internal to the emulator.
#pragma once

#include <cstdint>
#include <string_view>

#include "emulator/detail/thread_state.h"
#include "emulator/trace.h"

namespace refray::dxr::detail {

inline TraceObserver* observer(const ThreadState& ts) { return ts.dispatch->options.observer; }

inline TraceEvent event(const ThreadState& ts, TraceEvent::Kind kind, uint32_t depth) {
    TraceEvent e;
    e.kind = kind;
    e.launchIndex = ts.launchIndex;
    e.depth = depth;
    return e;
}

inline void setHit(TraceEvent& e, const BuiltInstance& inst, uint32_t instanceIndex, uint32_t geometryIndex,
                   uint32_t primitiveIndex) {
    e.instanceIndex = instanceIndex;
    e.instanceID = inst.desc.InstanceID;
    e.geometryIndex = geometryIndex;
    e.primitiveIndex = primitiveIndex;
}

inline void setHit(TraceEvent& e, const HitInfo& hit) {
    setHit(e, *hit.instance, hit.instanceIndex, hit.geometryIndex, hit.primitiveIndex);
}

inline void emitSkipped(const ThreadState& ts, const RayState& rs, std::string_view why) {
    TraceEvent e = event(ts, TraceEvent::Kind::Skipped, rs.depth);
    e.note = why;
    observer(ts)->onEvent(e);
}

}  // namespace refray::dxr::detail
