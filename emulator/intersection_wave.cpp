#include "emulator/intersection_wave.h"

#include "emulator/detail/candidate_processing.h"
#include "emulator/detail/invocation.h"

namespace refray::dxr {

IntersectionWave::IntersectionWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active)
    : contexts_(contexts), active_(active), fallback_(active.any() ? active.lowest() : 0) {}

bool IntersectionWave::searchEnded(int lane) const { return contexts_[lane]->inv_.searchEnded; }

void IntersectionWave::leave(int lane) {
    active_.clear(lane);
    if (active_.any()) fallback_ = active_.lowest();
}

void IntersectionWave::fail(int lane) {
    failures_[lane] = std::current_exception();
    leave(lane);
}

void IntersectionWave::runAlone(const std::function<void(IntersectionWave&)>& shader, ShaderContext& ctx) {
    std::array<ShaderContext*, kMaxWaveWidth> contexts{};
    contexts[0] = &ctx;
    IntersectionWave wave(contexts, LaneMask::only(0));
    shader(wave);
    if (wave.failures_[0]) std::rethrow_exception(wave.failures_[0]);
    if (wave.unwound_.test(0)) throw detail::EndSearchSignal{};
}

void IntersectionWave::endOrFail(int lane) {
    try {
        throw;
    } catch (const detail::EndSearchSignal&) {
        unwound_.set(lane);  // IS-10 by unwinding: the search ended at this ReportHit
        leave(lane);
    } catch (...) {
        fail(lane);
    }
}

}  // namespace refray::dxr
