#include "emulator/closest_hit_wave.h"

namespace refray::dxr {

void ClosestHitWave::runAlone(const std::function<void(ClosestHitWave&)>& shader, ShaderContext& ctx, void* payload,
                              const void* attributes) {
    std::array<void*, kMaxWaveWidth> payloads{};
    std::array<const void*, kMaxWaveWidth> attributeValues{};
    payloads[0] = payload;
    attributeValues[0] = attributes;
    runLaneAlone(shader, ctx, payloads, attributeValues);
}

}  // namespace refray::dxr
