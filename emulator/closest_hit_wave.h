// ClosestHitWave: a closest-hit shader run once over the lanes of a wave whose rays selected it, as a GPU gathers
// the threads that call one shader and runs it over them (emulator/tracing_wave.h). A shader written for waves
// (ShaderLibrary::addWaveClosestHit) runs its code lane by lane through each lane's ShaderContext, reading and
// writing each lane's payload and attributes, and issues its lanes' TraceRays together (TracingWave::TraceRay), whose
// closest-hit shaders run as waves in turn: recursion is per wave. Each lane keeps its own record, hit and
// intrinsics; lanes share nothing but the call. No fiber is parked for a closest-hit shader written this way.
#pragma once

#include <array>
#include <functional>

#include "emulator/tracing_wave.h"

namespace refray::dxr {

class ClosestHitWave : public TracingWave {
public:
    // As TracingWave's, with each active lane's payload and attributes (the types the export declares: the emulator
    // checks the payload, PAY-1, before the shader runs).
    ClosestHitWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active, detail::Wave* wave,
                   const std::array<void*, kMaxWaveWidth>& payloads,
                   const std::array<const void*, kMaxWaveWidth>& attributes)
        : TracingWave(contexts, active, wave), payloads_(payloads), attributes_(attributes) {}

    // Lane `lane`'s payload (inout) and attributes (in), as the export declared them.
    template <class Payload>
    Payload& payload(int lane) const {
        return *static_cast<Payload*>(payloads_[size_t(lane)]);
    }
    template <class Attributes>
    const Attributes& attributes(int lane) const {
        return *static_cast<const Attributes*>(attributes_[size_t(lane)]);
    }

    // Runs a wave shader for one lane alone (the export's ShaderExport::function): its TraceRay is the lane's
    // ShaderContext::TraceRay, and what stopped the lane is rethrown.
    static void runAlone(const std::function<void(ClosestHitWave&)>& shader, ShaderContext& ctx, void* payload,
                         const void* attributes);

private:
    std::array<void*, kMaxWaveWidth> payloads_;
    std::array<const void*, kMaxWaveWidth> attributes_;
};

}  // namespace refray::dxr
