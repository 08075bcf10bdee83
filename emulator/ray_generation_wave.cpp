#include "emulator/ray_generation_wave.h"

#include "emulator/detail/wave.h"

namespace refray::dxr {

RayGenerationWave::RayGenerationWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active,
                                     detail::Wave* wave)
    : contexts_(contexts), active_(active), wave_(wave) {}

void RayGenerationWave::fail(int lane, std::exception_ptr failure) {
    failures_[size_t(lane)] = std::move(failure);
    active_.clear(lane);
}

void RayGenerationWave::TraceRay(LaneMask lanes, const std::array<TraceRayCall, kMaxWaveWidth>& calls) {
    const LaneMask tracing(lanes.bits() & active_.bits());
    if (!wave_) {
        for (int i : tracing) {
            try {
                contexts_[size_t(i)]->TraceRay(calls[size_t(i)]);
            } catch (...) {
                fail(i, std::current_exception());
            }
        }
        return;
    }
    // RAY-2 holds (a ray generation shader may trace), and no ReportHit can have ended a ray generation shader.
    std::array<detail::Invocation*, kMaxWaveWidth> callers{};
    for (int i : tracing) callers[size_t(i)] = &contexts_[size_t(i)]->inv_;
    std::array<std::exception_ptr, kMaxWaveWidth> failures{};
    detail::traceRaysInWave(*wave_, callers, calls, tracing, failures);
    for (int i : tracing)
        if (failures[size_t(i)]) fail(i, std::move(failures[size_t(i)]));
}

void RayGenerationWave::runAlone(const std::function<void(RayGenerationWave&)>& shader, ShaderContext& ctx) {
    std::array<ShaderContext*, kMaxWaveWidth> contexts{};
    contexts[0] = &ctx;
    RayGenerationWave wave(contexts, LaneMask::only(0), nullptr);
    shader(wave);
    if (wave.failures_[0]) std::rethrow_exception(wave.failures_[0]);
}

}  // namespace refray::dxr
