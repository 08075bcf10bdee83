#include "emulator/compute_wave.h"

namespace refray::dxr {

void ComputeWave::runAlone(const std::function<void(ComputeWave&)>& shader, ShaderContext& ctx) {
    std::array<ShaderContext*, kMaxWaveWidth> contexts{};
    contexts[0] = &ctx;
    ComputeWave wave(contexts, LaneMask::only(0), nullptr);
    shader(wave);
    wave.rethrowAloneFailure();
}

}  // namespace refray::dxr
