#include "emulator/tracing_wave.h"

#include <bit>

#include "core/error.h"
#include "emulator/detail/wave.h"

namespace refray::dxr {

void TracingWave::TraceRay(LaneMask lanes, std::span<const TraceRayCall> calls) {
    const LaneMask tracing(lanes.bits() & active().bits());
    REFRAY_ASSERT(tracing.empty() || size_t(31 - std::countl_zero(tracing.bits())) < calls.size(),
                  "TraceRay for lanes " << tracing.bits() << " with " << calls.size() << " calls");
    if (runsAlone()) {
        for (int i : tracing) {
            try {
                lane(i).TraceRay(calls[size_t(i)]);
            } catch (...) {
                fail(i, std::current_exception());
            }
        }
        return;
    }
    // RAY-2 holds (ray generation and closest-hit shaders may trace), and no ReportHit can have ended either stage.
    std::array<detail::Invocation*, kMaxWaveWidth> callers{};
    for (int i : tracing) callers[size_t(i)] = &lane(i).inv_;
    std::array<std::exception_ptr, kMaxWaveWidth> failures{};
    detail::traceRaysInWave(*wave(), callers, calls.data(), tracing, failures);
    for (int i : tracing)
        if (failures[size_t(i)]) fail(i, std::move(failures[size_t(i)]));
}

}  // namespace refray::dxr
