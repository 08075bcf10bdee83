// RayGenerationWave: a ray generation shader run once for the lanes of a wave (a block of launches), as a GPU runs
// one shader over the threads of a wave (emulator/tracing_wave.h). A shader written for waves
// (ShaderLibrary::addWaveRayGeneration) runs its code lane by lane through each lane's ShaderContext, and issues the
// TraceRays of its lanes together (TracingWave::TraceRay). No fiber is parked for a ray generation shader.
#pragma once

#include <functional>

#include "emulator/tracing_wave.h"

namespace refray::dxr {

class RayGenerationWave : public TracingWave {
public:
    using TracingWave::TracingWave;

    // Runs a wave shader for one lane alone (the export's ShaderExport::function): its TraceRay is the lane's
    // ShaderContext::TraceRay, and what stopped the lane is rethrown.
    static void runAlone(const std::function<void(RayGenerationWave&)>& shader, ShaderContext& ctx);
};

}  // namespace refray::dxr
