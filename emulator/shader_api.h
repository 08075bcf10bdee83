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
#include <type_traits>

#include "core/image.h"
#include "emulator/descriptor_heap.h"
#include "emulator/detail/invocation.h"
#include "emulator/ray_query.h"
#include "emulator/trace_ray_call.h"
#include "emulator/wave_call.h"

namespace refray::dxr {

namespace detail {
constexpr uint8_t stageBit(ShaderStage s) { return uint8_t(1u << uint8_t(s)); }
struct BoundResource;  // shader_resources.cpp
struct ArgumentBytes;  // dispatch_state.h
}  // namespace detail

class ShaderContext;
class RayQueryObject;
class IntersectionWave;
class RayGenerationWave;

// HLSL SamplerState: a sampler resolved from an s register by ShaderContext::SamplerState. Valid for the dispatch
// that resolved it.
class SamplerRef {
public:
    const SamplerDesc& desc() const { return *desc_; }

private:
    friend class ShaderContext;
    explicit SamplerRef(const SamplerDesc* desc) : desc_(desc) {}
    const SamplerDesc* desc_;
};

// HLSL Texture2D<float4>: a texture resolved from a t register by ShaderContext::Texture2D. Valid for the dispatch
// that resolved it. Ray-tracing shaders have no implicit derivatives, so there is no Sample(): use SampleLevel,
// SampleGrad or Load (filtering rules: texture.h). A null descriptor reads (0, 0, 0, 0) and has dimensions 0.
// A texture file that can no longer be read stops the dispatch with BIND-6.
class Texture2DRef {
public:
    vec4 SampleLevel(SamplerRef S, vec2 Location, float LOD) const;
    vec4 SampleGrad(SamplerRef S, vec2 Location, vec2 DDX, vec2 DDY) const;
    // Location = (x, y, MIP level); out of range reads (0, 0, 0, 0).
    vec4 Load(glm::ivec3 Location) const;
    // Width and Height of MipLevel (0 past the last level) and the number of levels.
    void GetDimensions(uint32_t MipLevel, uint32_t& Width, uint32_t& Height, uint32_t& NumberOfLevels) const;
    void GetDimensions(uint32_t& Width, uint32_t& Height) const;

    bool isNull() const { return texture_ == nullptr; }
    const dxr::Texture2D* texture() const { return texture_; }

private:
    friend class ShaderContext;
    Texture2DRef(const ShaderContext& ctx, const dxr::Texture2D* texture, uint32_t shaderRegister, uint32_t space,
                 uint32_t arrayIndex)
        : ctx_(&ctx), texture_(texture), register_(shaderRegister), space_(space), index_(arrayIndex) {}
    [[noreturn]] void readFailed(const char* method, const std::string& why) const;
    const ShaderContext* ctx_;
    const dxr::Texture2D* texture_;
    uint32_t register_, space_, index_;
};

class ShaderContext {
public:
    explicit ShaderContext(detail::Invocation& invocation) : inv_(invocation) {}
    ShaderContext(const ShaderContext&) = delete;
    ShaderContext& operator=(const ShaderContext&) = delete;

    ShaderStage stage() const { return inv_.stage; }

    // --- Launch (SV-2), every ray-tracing stage.
    uvec3 DispatchRaysIndex() const;
    uvec3 DispatchRaysDimensions() const;

    // --- Compute shaders (Device::dispatch): SV_DispatchThreadID, SV_GroupID, SV_GroupThreadID, SV_GroupIndex.
    uvec3 DispatchThreadID() const;
    uvec3 GroupID() const;
    uvec3 GroupThreadID() const;
    uint32_t GroupIndex() const;

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
        TraceRay(traceRayCall(accelerationStructure, RayFlags, InstanceInclusionMask, RayContributionToHitGroupIndex,
                              MultiplierForGeometryContributionToHitGroupIndex, MissShaderIndex, Ray, payload));
    }
    // The same TraceRay, its arguments held in a TraceRayCall (emulator/trace_ray_call.h).
    void TraceRay(const TraceRayCall& call);

    // --- CallShader (CALL-1): ray generation, closest-hit, miss and callable shaders.
    template <class Parameters>
    void CallShader(uint32_t ShaderIndex, Parameters& parameters) {
        callShader(ShaderIndex, &parameters, typeTag<Parameters>());
    }

    // --- Wave calls (emulator/wave_call.h): runs `function` for this lane's `state`, grouped with the other lanes
    // of the wave that call it with the same key; returns when the lane's outputs are in `state`. Outside a wave of
    // several lanes (width 1, an observed or profiled dispatch, a shader that runs during a packet's traversal) it
    // runs for this lane alone, at once.
    void callInWave(const WaveFunction& function, const WaveCallKey& key, void* state) const;

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

    // --- Resources by HLSL register and space, every stage (BIND-1..BIND-6, docs/emulator.md "Resource binding
    // (BIND)"). Resolved through the global root signature bound to the dispatch, then the local root signature of
    // the executing shader's record (PIPE-7 keeps them apart): the root parameter, table range or static sampler
    // that binds the register (RootSignature::findRegister), then for a table the descriptor at table handle +
    // range offset + (register - range base) + arrayIndex in its heap. Root arguments read here are checked like
    // globalRootDescriptor/localRootDescriptor (REC-7 for unwritten bytes). An HLSL array
    // `T name[] : register(tN, spaceM)` is (N, M, i) for name[i]; element i must lie in the binding that covers
    // register N. Every failure stops the dispatch with a DxrError naming the register, space, index, the root
    // signature and what was found; a null descriptor (written as one) reads zeros, a never-written one is BIND-4.

    // `Texture2D<float4> name[] : register(t<shaderRegister>, space<space>)`, element arrayIndex: a Texture2D SRV
    // in a descriptor table (BIND-3 for anything else).
    Texture2DRef Texture2D(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex = 0) const;
    // `SamplerState name : register(s<shaderRegister>, space<space>)`: a static sampler of either root signature or
    // a sampler in a sampler table (a Sampler heap).
    SamplerRef SamplerState(uint32_t shaderRegister, uint32_t space = 0, uint32_t arrayIndex = 0) const;
    // `StructuredBuffer<T> name[] : register(t<shaderRegister>, space<space>)`, name[arrayIndex][elementIndex].
    // In a table, sizeof(T) must equal the view's StructureByteStride (BIND-5) and an element past the view reads
    // zeros, as D3D defines. A root SRV has no view: it reads address + elementIndex * sizeof(T) (GEN-1 outside
    // GPU memory).
    template <class T>
    T loadStructured(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex, uint64_t elementIndex) const {
        static_assert(std::is_trivially_copyable_v<T>, "structured buffer elements are plain bytes");
        T value;
        readStructured(shaderRegister, space, arrayIndex, elementIndex, sizeof(T), &value);
        return value;
    }
    // `ByteAddressBuffer name[] : register(t<shaderRegister>, space<space>)`, name[arrayIndex].Load<T>(byteOffset).
    // byteOffset must be a multiple of 4 and a table view must be raw (StructureByteStride 0) (BIND-5); bytes past
    // the view read zeros.
    template <class T>
    T loadByteAddress(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex, uint64_t byteOffset) const {
        static_assert(std::is_trivially_copyable_v<T>, "ByteAddressBuffer loads are plain bytes");
        T value;
        readByteAddress(shaderRegister, space, arrayIndex, byteOffset, sizeof(T), &value);
        return value;
    }
    // `ConstantBuffer<T> name : register(b<shaderRegister>, space<space>)`: root constants (at least sizeof(T)
    // bytes of them, BIND-5; REC-7 if unwritten), a root CBV, or a CBV in a table (bytes past the view read zeros).
    template <class T>
    T constantBuffer(uint32_t shaderRegister, uint32_t space = 0) const {
        static_assert(std::is_trivially_copyable_v<T>, "constant buffers are plain bytes");
        T value;
        readConstantBuffer(shaderRegister, space, sizeof(T), &value);
        return value;
    }

private:
    friend class RayQueryObject;  // a query belongs to the invocation that made it (emulator/ray_query.h)
    friend class IntersectionWave;  // reads whether a lane's ReportHit ended its search (emulator/intersection_wave.h)
    friend class TracingWave;  // issues its lanes' TraceRays together (emulator/tracing_wave.h)

    // Stage masks for SV-1.
    static constexpr uint8_t bit(ShaderStage s) { return detail::stageBit(s); }
    static constexpr uint8_t kRay = detail::stageBit(ShaderStage::Intersection) | detail::stageBit(ShaderStage::AnyHit) |
                                    detail::stageBit(ShaderStage::ClosestHit) | detail::stageBit(ShaderStage::Miss);
    static constexpr uint8_t kRayTracingStages = uint8_t(~detail::stageBit(ShaderStage::Compute));
    static constexpr uint8_t kHit = detail::stageBit(ShaderStage::Intersection) | detail::stageBit(ShaderStage::AnyHit) |
                                    detail::stageBit(ShaderStage::ClosestHit);

    void requireStage(uint8_t allowed, const char* intrinsic) const {
        requireLive(intrinsic);
        if (!(allowed & bit(inv_.stage))) stageViolation(intrinsic);
    }
    [[noreturn]] void stageViolation(const char* intrinsic) const;
    // ReportHitEnd::Return: nothing may follow a ReportHit that ended the search (IS-10).
    void requireLive(const char* intrinsic) const {
        if (inv_.searchEnded) [[unlikely]]
            calledAfterSearchEnded(intrinsic);
    }
    [[noreturn]] void calledAfterSearchEnded(const char* intrinsic) const;
    const detail::RayState& rayState(uint8_t allowed, const char* intrinsic) const {
        requireStage(allowed, intrinsic);
        return *inv_.ray;
    }
    const detail::HitInfo& hitInfo(const char* intrinsic) const {
        requireStage(kHit, intrinsic);
        return *inv_.hit;
    }
    bool reportHit(float tHit, uint32_t hitKind, const void* attributes, TypeTag type);
    void callShader(uint32_t index, void* parameters, TypeTag type);
    const uint8_t* rootArgument(bool local, uint32_t parameter, size_t size, TypeTag type) const;
    const uint8_t* rootArgumentChecked(bool local, uint32_t parameter, size_t size, TypeTag type,
                                       const detail::ArgumentBytes& arguments) const;
    const uint8_t* readMemory(GpuVirtualAddress address, uint64_t size) const;
    void readBufferView(GpuDescriptorHandle tableHandle, uint32_t offset, uint64_t byteOffset, uint64_t size,
                        void* out) const;
    // Register resolution (shader_resources.cpp).
    friend class Texture2DRef;
    detail::BoundResource resolve(DescriptorRangeType type, uint32_t shaderRegister, uint32_t space,
                                  uint32_t arrayIndex, const char* hlslType) const;
    [[noreturn]] void bindingError(const char* rule, const detail::BoundResource& bound, const std::string& what) const;
    void readStructured(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex, uint64_t elementIndex,
                        uint64_t size, void* out) const;
    void readByteAddress(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex, uint64_t byteOffset,
                         uint64_t size, void* out) const;
    void readConstantBuffer(uint32_t shaderRegister, uint32_t space, uint64_t size, void* out) const;

    detail::Invocation& inv_;
};

}  // namespace refray::dxr
