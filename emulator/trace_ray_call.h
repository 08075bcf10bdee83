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

// `call` made the call TraceRay(accelerationStructure, RayFlags, ..., Ray, payload) would make, in HLSL's argument
// order, field by field in place: a call returned by value and assigned was copied with wider loads than the stores
// that built it (a store-forwarding stall per TraceRay).
template <class Payload>
void setTraceRayCall(TraceRayCall& call, GpuVirtualAddress accelerationStructure, uint32_t RayFlags,
                     uint32_t InstanceInclusionMask, uint32_t RayContributionToHitGroupIndex,
                     uint32_t MultiplierForGeometryContributionToHitGroupIndex, uint32_t MissShaderIndex,
                     const RayDesc& Ray, Payload& payload) {
    call.accelerationStructure = accelerationStructure;
    call.rayFlags = RayFlags;
    call.instanceInclusionMask = InstanceInclusionMask;
    call.rayContribution = RayContributionToHitGroupIndex;
    call.multiplier = MultiplierForGeometryContributionToHitGroupIndex;
    call.missShaderIndex = MissShaderIndex;
    call.ray = Ray;
    call.payload = &payload;
    call.payloadType = typeTag<Payload>();
}

// setTraceRayCall's call, by value.
template <class Payload>
TraceRayCall traceRayCall(GpuVirtualAddress accelerationStructure, uint32_t RayFlags, uint32_t InstanceInclusionMask,
                          uint32_t RayContributionToHitGroupIndex,
                          uint32_t MultiplierForGeometryContributionToHitGroupIndex, uint32_t MissShaderIndex,
                          const RayDesc& Ray, Payload& payload) {
    TraceRayCall call;
    setTraceRayCall(call, accelerationStructure, RayFlags, InstanceInclusionMask, RayContributionToHitGroupIndex,
                    MultiplierForGeometryContributionToHitGroupIndex, MissShaderIndex, Ray, payload);
    return call;
}

}  // namespace refray::dxr
