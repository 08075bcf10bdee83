// TraceRayCall: the arguments of one TraceRay, held as values, for a shader written for waves that issues the
// TraceRays of its lanes together (emulator/ray_generation_wave.h). The payload is the lane's own variable: the
// TraceRay copies it in and back (RAY-9) exactly as ShaderContext::TraceRay does.
#pragma once

#include <cstdint>

#include "emulator/state_object.h"
#include "emulator/types.h"

namespace refray::dxr {

struct TraceRayCall {
    GpuVirtualAddress accelerationStructure = 0;
    uint32_t rayFlags = 0;
    uint32_t instanceInclusionMask = 0;
    uint32_t rayContribution = 0;  // RayContributionToHitGroupIndex
    uint32_t multiplier = 0;       // MultiplierForGeometryContributionToHitGroupIndex
    uint32_t missShaderIndex = 0;
    RayDesc ray{};
    void* payload = nullptr;
    TypeTag payloadType;
};

// The call TraceRay(accelerationStructure, RayFlags, ..., Ray, payload) would make, in HLSL's argument order.
template <class Payload>
TraceRayCall traceRayCall(GpuVirtualAddress accelerationStructure, uint32_t RayFlags, uint32_t InstanceInclusionMask,
                          uint32_t RayContributionToHitGroupIndex,
                          uint32_t MultiplierForGeometryContributionToHitGroupIndex, uint32_t MissShaderIndex,
                          const RayDesc& Ray, Payload& payload) {
    return {accelerationStructure, RayFlags, InstanceInclusionMask, RayContributionToHitGroupIndex,
            MultiplierForGeometryContributionToHitGroupIndex, MissShaderIndex, Ray, &payload, typeTag<Payload>()};
}

}  // namespace refray::dxr
