#include "emulator/ray_generation_wave.h"

namespace refray::dxr {

void RayGenerationWave::runAlone(const std::function<void(RayGenerationWave&)>& shader, ShaderContext& ctx) {
    std::array<ShaderContext*, kMaxWaveWidth> contexts{};
    contexts[0] = &ctx;
    RayGenerationWave wave(contexts, LaneMask::only(0), nullptr);
    shader(wave);
    wave.rethrowAloneFailure();
}

}  // namespace refray::dxr
