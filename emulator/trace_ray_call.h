// TraceRayCall: the arguments of one TraceRay, held as values, for a shader written for waves that issues the
// TraceRays of its lanes together (emulator/ray_generation_wave.h). The payload is the lane's own variable: the
// TraceRay copies it in and back (RAY-9) exactly as ShaderContext::TraceRay does.
#pragma once

#include <cstdint>
#include <cstring>
#if defined(__AVX__)
#include <immintrin.h>
#endif

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

// ray = {origin, tMin, direction, tMax}, written whole: one 32-byte store from registers where the CPU has AVX. A
// RayDesc pieced together from 4-byte stores and read back at once with wider loads (TraceRay's and TraceRayInline's
// copies of it) cannot be forwarded to them: the loads wait until the stores reach the cache (a store-forwarding
// stall).
inline void storeRayDesc(RayDesc& ray, const vec3& origin, float tMin, const vec3& direction, float tMax) {
#if defined(__AVX__)
    static_assert(sizeof(RayDesc) == 8 * sizeof(float));
    const __m256 whole =
        _mm256_setr_ps(origin.x, origin.y, origin.z, tMin, direction.x, direction.y, direction.z, tMax);
    std::memcpy(static_cast<void*>(&ray), &whole, sizeof ray);
#else
    ray = RayDesc{origin, tMin, direction, tMax};
#endif
}

namespace detail {
// Everything of a TraceRayCall but its ray.
template <class Payload>
void setTraceRayArguments(TraceRayCall& call, GpuVirtualAddress accelerationStructure, uint32_t RayFlags,
                          uint32_t InstanceInclusionMask, uint32_t RayContributionToHitGroupIndex,
                          uint32_t MultiplierForGeometryContributionToHitGroupIndex, uint32_t MissShaderIndex,
                          Payload& payload) {
    call.accelerationStructure = accelerationStructure;
    call.rayFlags = RayFlags;
    call.instanceInclusionMask = InstanceInclusionMask;
    call.rayContribution = RayContributionToHitGroupIndex;
    call.multiplier = MultiplierForGeometryContributionToHitGroupIndex;
    call.missShaderIndex = MissShaderIndex;
    call.payload = &payload;
    call.payloadType = typeTag<Payload>();
}
}  // namespace detail

// `call` made the call TraceRay(accelerationStructure, RayFlags, ..., Ray, payload) would make, in HLSL's argument
// order, field by field in place: a call returned by value and assigned was copied with wider loads than the stores
// that built it (a store-forwarding stall per TraceRay).
template <class Payload>
void setTraceRayCall(TraceRayCall& call, GpuVirtualAddress accelerationStructure, uint32_t RayFlags,
                     uint32_t InstanceInclusionMask, uint32_t RayContributionToHitGroupIndex,
                     uint32_t MultiplierForGeometryContributionToHitGroupIndex, uint32_t MissShaderIndex,
                     const RayDesc& Ray, Payload& payload) {
    detail::setTraceRayArguments(call, accelerationStructure, RayFlags, InstanceInclusionMask,
                                 RayContributionToHitGroupIndex, MultiplierForGeometryContributionToHitGroupIndex,
                                 MissShaderIndex, payload);
    call.ray = Ray;
}

// setTraceRayCall with the ray given by its parts and stored whole (storeRayDesc): for a ray made just before the
// call, whose RayDesc would otherwise be pieced together on the stack and copied.
template <class Payload>
void setTraceRayCall(TraceRayCall& call, GpuVirtualAddress accelerationStructure, uint32_t RayFlags,
                     uint32_t InstanceInclusionMask, uint32_t RayContributionToHitGroupIndex,
                     uint32_t MultiplierForGeometryContributionToHitGroupIndex, uint32_t MissShaderIndex,
                     const vec3& origin, float tMin, const vec3& direction, float tMax, Payload& payload) {
    detail::setTraceRayArguments(call, accelerationStructure, RayFlags, InstanceInclusionMask,
                                 RayContributionToHitGroupIndex, MultiplierForGeometryContributionToHitGroupIndex,
                                 MissShaderIndex, payload);
    storeRayDesc(call.ray, origin, tMin, direction, tMax);
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
