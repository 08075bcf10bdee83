// The shader-facing API: what HLSL intrinsics are to DXR, ShaderContext is to refray.
//
// A shader receives a ShaderContext& and calls intrinsics with their HLSL names:
//   ctx.DispatchRaysIndex(), ctx.RayTCurrent(), ctx.ReportHit(t, kind, attr),
//   ctx.TraceRay(tlas, RAY_FLAG_..., mask, R, M, miss, ray, payload), ...
// Each intrinsic checks that the calling stage may use it (SV-1) and reports misuse as
// a DxrError carrying the rule id. Non-local exits (IgnoreHit, AcceptHitAndEndSearch,
// an accepting ReportHit under ACCEPT_FIRST_HIT_AND_END_SEARCH) unwind the shader:
// code after them never runs (IS-10, AHS-4).
#pragma once

#include <array>
#include <cstring>

#include "core/image.h"
#include "emulator/descriptor_heap.h"
#include "emulator/detail/invocation.h"

namespace refray::dxr {

namespace detail {
constexpr uint8_t stageBit(ShaderStage s) { return uint8_t(1u << uint8_t(s)); }
}  // namespace detail

class ShaderContext {
public:
    explicit ShaderContext(detail::Invocation& invocation) : inv_(invocation) {}
    ShaderContext(const ShaderContext&) = delete;
    ShaderContext& operator=(const ShaderContext&) = delete;

    ShaderStage stage() const { return inv_.stage; }

    // --- Launch (SV-2), every stage.
    uvec3 DispatchRaysIndex() const;
    uvec3 DispatchRaysDimensions() const;

    // --- Ray values (SV-3..SV-6): IS, AHS, CHS, miss.
    vec3 WorldRayOrigin() const { return rayState(kRay, "WorldRayOrigin").ray.Origin; }
    vec3 WorldRayDirection() const { return rayState(kRay, "WorldRayDirection").ray.Direction; }
    float RayTMin() const { return rayState(kRay, "RayTMin").ray.TMin; }
    float RayTCurrent() const;
    uint32_t RayFlags() const { return rayState(kRay, "RayFlags").rayFlags; }

    // --- Hit values (SV-7..SV-12): IS, AHS, CHS.
    uint32_t InstanceIndex() const { return hitInfo("InstanceIndex").instanceIndex; }
    uint32_t InstanceID() const;
    uint32_t GeometryIndex() const { return hitInfo("GeometryIndex").geometryIndex; }
    uint32_t PrimitiveIndex() const { return hitInfo("PrimitiveIndex").primitiveIndex; }
    vec3 ObjectRayOrigin() const { return hitInfo("ObjectRayOrigin").objectRayOrigin; }
    vec3 ObjectRayDirection() const { return hitInfo("ObjectRayDirection").objectRayDirection; }
    Matrix3x4 ObjectToWorld3x4() const;
    std::array<std::array<float, 3>, 4> ObjectToWorld4x3() const;
    Matrix3x4 WorldToObject3x4() const;
    std::array<std::array<float, 3>, 4> WorldToObject4x3() const;
    // AHS and CHS only (SV-10).
    uint32_t HitKind() const;

    // --- Intersection shaders (IS-3..IS-10).
    template <class Attributes>
    bool ReportHit(float THit, uint32_t HitKind, const Attributes& attributes) {
        return reportHit(THit, HitKind, &attributes, typeTag<Attributes>());
    }

    // --- Any-hit shaders (AHS-3, AHS-4): end the shader at once.
    [[noreturn]] void IgnoreHit();
    [[noreturn]] void AcceptHitAndEndSearch();

    // --- TraceRay (RAY-1): ray generation, closest-hit and miss shaders. The payload is
    // copied in and out (RAY-9). `accelerationStructure` is the TLAS's GPU address, as
    // bound through a root SRV; 0 forces a miss (RAY-3).
    template <class Payload>
    void TraceRay(GpuVirtualAddress accelerationStructure, uint32_t RayFlags, uint32_t InstanceInclusionMask,
                  uint32_t RayContributionToHitGroupIndex, uint32_t MultiplierForGeometryContributionToHitGroupIndex,
                  uint32_t MissShaderIndex, const RayDesc& Ray, Payload& payload) {
        traceRay(accelerationStructure, RayFlags, InstanceInclusionMask, RayContributionToHitGroupIndex,
                 MultiplierForGeometryContributionToHitGroupIndex, MissShaderIndex, Ray, &payload,
                 typeTag<Payload>());
    }

    // --- CallShader (CALL-1): ray generation, closest-hit, miss and callable shaders.
    template <class Parameters>
    void CallShader(uint32_t ShaderIndex, Parameters& parameters) {
        callShader(ShaderIndex, &parameters, typeTag<Parameters>());
    }

    // --- Local root arguments of the executing shader's record, type-checked against its
    // local root signature (REC-5, REC-7, REC-11).
    template <class T>
    T localRootConstants(uint32_t parameter) const {
        T value;
        std::memcpy(&value, rootArgument(true, parameter, sizeof(T), typeTag<T>()), sizeof(T));
        return value;
    }
    GpuVirtualAddress localRootDescriptor(uint32_t parameter) const;

    // --- Global root arguments of the dispatch, checked against the global root signature.
    template <class T>
    T globalRootConstants(uint32_t parameter) const {
        T value;
        std::memcpy(&value, rootArgument(false, parameter, sizeof(T), typeTag<T>()), sizeof(T));
        return value;
    }
    GpuVirtualAddress globalRootDescriptor(uint32_t parameter) const;
    GpuDescriptorHandle globalDescriptorTable(uint32_t parameter) const;

    // --- Resources.
    // `count` elements of T at a GPU address (a CBV, StructuredBuffer or ByteAddressBuffer view).
    template <class T>
    const T* buffer(GpuVirtualAddress address, uint64_t count = 1) const {
        return reinterpret_cast<const T*>(readMemory(address, sizeof(T) * count));
    }
    template <class T>
    T load(GpuVirtualAddress address) const {
        T value;
        std::memcpy(&value, readMemory(address, sizeof(T)), sizeof(T));
        return value;
    }
    // RWTexture2D<float4> bound as descriptor `offset` of the table at `tableHandle`.
    Image& rwTexture2D(GpuDescriptorHandle tableHandle, uint32_t offset = 0) const;
    // A T at `byteOffset` in the buffer bound as descriptor `offset` of the table at
    // `tableHandle` (ByteAddressBuffer.Load, StructuredBuffer[i] with byteOffset = i * stride).
    // Reads past the view's end return zeros, as D3D defines for buffer views.
    template <class T>
    T loadFromTable(GpuDescriptorHandle tableHandle, uint32_t offset, uint64_t byteOffset) const {
        T value;
        readBufferView(tableHandle, offset, byteOffset, sizeof(T), &value);
        return value;
    }

private:
    // Stage masks for SV-1.
    static constexpr uint8_t bit(ShaderStage s) { return detail::stageBit(s); }
    static constexpr uint8_t kRay = detail::stageBit(ShaderStage::Intersection) | detail::stageBit(ShaderStage::AnyHit) |
                                    detail::stageBit(ShaderStage::ClosestHit) | detail::stageBit(ShaderStage::Miss);
    static constexpr uint8_t kHit = detail::stageBit(ShaderStage::Intersection) | detail::stageBit(ShaderStage::AnyHit) |
                                    detail::stageBit(ShaderStage::ClosestHit);

    void requireStage(uint8_t allowed, const char* intrinsic) const {
        if (!(allowed & bit(inv_.stage))) stageViolation(intrinsic);
    }
    [[noreturn]] void stageViolation(const char* intrinsic) const;
    const detail::RayState& rayState(uint8_t allowed, const char* intrinsic) const {
        requireStage(allowed, intrinsic);
        return *inv_.ray;
    }
    const detail::HitInfo& hitInfo(const char* intrinsic) const {
        requireStage(kHit, intrinsic);
        return *inv_.hit;
    }
    bool reportHit(float tHit, uint32_t hitKind, const void* attributes, TypeTag type);
    void traceRay(GpuVirtualAddress as, uint32_t flags, uint32_t mask, uint32_t r, uint32_t m, uint32_t miss,
                  const RayDesc& ray, void* payload, TypeTag payloadType);
    void callShader(uint32_t index, void* parameters, TypeTag type);
    const uint8_t* rootArgument(bool local, uint32_t parameter, size_t size, TypeTag type) const;
    const uint8_t* readMemory(GpuVirtualAddress address, uint64_t size) const;
    void readBufferView(GpuDescriptorHandle tableHandle, uint32_t offset, uint64_t byteOffset, uint64_t size,
                        void* out) const;

    detail::Invocation& inv_;
};

}  // namespace refray::dxr
