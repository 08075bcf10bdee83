#include "emulator/compute_wave.h"

namespace refray::dxr {

void ComputeWave::runAlone(const std::function<void(ComputeWave&)>& shader, ShaderContext& ctx) {
    runLaneAlone(shader, ctx);
}

}  // namespace refray::dxr
