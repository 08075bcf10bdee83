#include "emulator/closest_hit_wave.h"

namespace refray::dxr {

void ClosestHitWave::runAlone(const std::function<void(ClosestHitWave&)>& shader, ShaderContext& ctx, void* payload,
                              const void* attributes) {
    std::array<ShaderContext*, kMaxWaveWidth> contexts{};
    std::array<void*, kMaxWaveWidth> payloads{};
    std::array<const void*, kMaxWaveWidth> attributeValues{};
    contexts[0] = &ctx;
    payloads[0] = payload;
    attributeValues[0] = attributes;
    ClosestHitWave wave(contexts, LaneMask::only(0), nullptr, payloads, attributeValues);
    shader(wave);
    wave.rethrowAloneFailure();
}

}  // namespace refray::dxr
