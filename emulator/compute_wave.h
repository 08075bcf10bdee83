// ComputeWave: a compute shader run once for the threads of a wave (a block of dispatch threads), as a GPU runs one
// shader over the threads of a wave (emulator/shader_wave.h). A shader written for waves
// (ShaderLibrary::addWaveCompute) runs its code lane by lane through each lane's ShaderContext (its thread ids,
// resources and RayQuery objects) and makes its lanes' wave calls together (ShaderWave::CallInWave, CallsInLoop): a
// RayQuery's procedural candidates' tests run over the lanes that reach them. No fiber is parked for a compute shader
// written this way.
#pragma once

#include <functional>

#include "emulator/shader_wave.h"

namespace refray::dxr {

class ComputeWave : public ShaderWave {
public:
    using ShaderWave::ShaderWave;

    // Runs a wave shader for one thread alone (the export's ShaderExport::function): its wave calls are the lane's
    // ShaderContext::callInWave, and what stopped the lane is rethrown.
    static void runAlone(const std::function<void(ComputeWave&)>& shader, ShaderContext& ctx);
};

}  // namespace refray::dxr
