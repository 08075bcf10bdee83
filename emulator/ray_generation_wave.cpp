#include "emulator/ray_generation_wave.h"

namespace refray::dxr {

void RayGenerationWave::runAlone(const std::function<void(RayGenerationWave&)>& shader, ShaderContext& ctx) {
    runLaneAlone(shader, ctx);
}

}  // namespace refray::dxr
