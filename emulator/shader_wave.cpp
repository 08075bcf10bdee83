#include "emulator/shader_wave.h"

#include <bit>

#include "core/error.h"
#include "emulator/detail/wave.h"

namespace refray::dxr {

ShaderWave::ShaderWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active, detail::Wave* wave)
    : contexts_(contexts), active_(active), wave_(wave) {}

void ShaderWave::fail(int lane, std::exception_ptr failure) {
    failures_[size_t(lane)] = std::move(failure);
    active_.clear(lane);
}

void ShaderWave::CallInWave(LaneMask lanes, std::span<const WaveCall> calls) {
    const LaneMask calling(lanes.bits() & active_.bits());
    if (calling.empty()) return;
    REFRAY_ASSERT(size_t(31 - std::countl_zero(calling.bits())) < calls.size(),
                  "wave calls for lanes " << calling.bits() << " with " << calls.size() << " calls");
    if (!wave_) {
        // Alone: the lane's own wave call, which parks its fiber where it runs on one among a wave's lanes.
        for (int i : calling) {
            const WaveCall& call = calls[size_t(i)];
            try {
                contexts_[size_t(i)]->callInWave(*call.function, call.key, call.state);
            } catch (...) {
                fail(i, std::current_exception());
            }
        }
        return;
    }
    std::array<std::exception_ptr, kMaxWaveWidth> failures{};
    detail::runWaveCallsOfShader(*wave_, calling, calls.data(), failures);
    for (int i : calling)
        if (failures[size_t(i)]) fail(i, std::move(failures[size_t(i)]));
}

}  // namespace refray::dxr
