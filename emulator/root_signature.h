// Global and local root signatures and their argument layouts (REC-5, REC-6, PIPE-6, PIPE-7), static samplers,
// and the register map that resolves HLSL register/space bindings (BIND-1, BIND-7..BIND-10; the BIND rules are
// refray's own, listed in docs/emulator.md, "Resource binding (BIND)").
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "emulator/texture.h"
#include "emulator/types.h"

namespace refray::dxr {

enum class DescriptorRangeType : uint8_t { SRV, UAV, CBV, Sampler };
std::string_view toString(DescriptorRangeType type);
// The HLSL register letter of a range type: t (SRV), u (UAV), b (CBV), s (Sampler).
char registerLetter(DescriptorRangeType type);

inline constexpr uint32_t kDescriptorRangeOffsetAppend = 0xFFFFFFFF;  // D3D12_DESCRIPTOR_RANGE_OFFSET_APPEND
// numDescriptors of an unbounded range (UINT_MAX, as in D3D12): HLSL `Texture2D t[] : register(t0, space5)`.
inline constexpr uint32_t kDescriptorRangeUnbounded = 0xFFFFFFFF;

// D3D12_DESCRIPTOR_RANGE. A table may not mix Sampler ranges with others (BIND-8); a range after an unbounded one
// must give an explicit offset (BIND-9).
struct DescriptorRange {
    DescriptorRangeType rangeType = DescriptorRangeType::SRV;
    uint32_t numDescriptors = 1;  // >= 1, or kDescriptorRangeUnbounded
    uint32_t baseShaderRegister = 0;
    uint32_t registerSpace = 0;
    uint32_t offsetInDescriptorsFromTableStart = kDescriptorRangeOffsetAppend;
};

enum class RootParameterType : uint8_t { DescriptorTable, Constants32Bit, CBV, SRV, UAV };
std::string_view toString(RootParameterType type);

struct RootParameter {
    RootParameterType parameterType = RootParameterType::Constants32Bit;
    uint32_t shaderRegister = 0;
    uint32_t registerSpace = 0;
    uint32_t num32BitValues = 0;          // Constants32Bit only
    std::vector<DescriptorRange> ranges;  // DescriptorTable only

    static RootParameter constants(uint32_t num32BitValues, uint32_t shaderRegister, uint32_t registerSpace = 0);
    static RootParameter cbv(uint32_t shaderRegister, uint32_t registerSpace = 0);
    static RootParameter srv(uint32_t shaderRegister, uint32_t registerSpace = 0);
    static RootParameter uav(uint32_t shaderRegister, uint32_t registerSpace = 0);
    static RootParameter table(std::vector<DescriptorRange> ranges);
};

// D3D12_ROOT_SIGNATURE_FLAGS that matter here.
enum RootSignatureFlag : uint32_t {
    ROOT_SIGNATURE_FLAG_NONE = 0x0,
    ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE = 0x80,
};

// D3D12_STATIC_SAMPLER_DESC without ComparisonFunc and ShaderVisibility: a sampler baked into the root signature
// at register s<ShaderRegister> of space <RegisterSpace> (HLSL `SamplerState s : register(s0)`).
struct StaticSamplerDesc {
    SamplerFilter Filter = FILTER_MIN_MAG_MIP_LINEAR;
    TextureAddressMode AddressU = TEXTURE_ADDRESS_MODE_WRAP;
    TextureAddressMode AddressV = TEXTURE_ADDRESS_MODE_WRAP;
    TextureAddressMode AddressW = TEXTURE_ADDRESS_MODE_WRAP;
    float MipLODBias = 0.0f;
    uint32_t MaxAnisotropy = 16;
    StaticBorderColor BorderColor = STATIC_BORDER_COLOR_TRANSPARENT_BLACK;
    float MinLOD = 0.0f;
    float MaxLOD = std::numeric_limits<float>::max();
    uint32_t ShaderRegister = 0;
    uint32_t RegisterSpace = 0;

    // The sampler it stands for (BorderColor as RGBA).
    SamplerDesc sampler() const;
};

struct RootSignatureDesc {
    std::string name;  // for diagnostics
    std::vector<RootParameter> parameters;
    uint32_t flags = ROOT_SIGNATURE_FLAG_NONE;
    std::vector<StaticSamplerDesc> staticSamplers = {};  // D3D12_ROOT_SIGNATURE_DESC::pStaticSamplers
};

// What binds a run of registers of one type in one space: a root parameter, one range of a descriptor table, or
// a static sampler. RootSignature::create() lists them once, sorted, and refuses overlaps (BIND-7), so a shader
// register resolves by one binary search (RootSignature::findRegister).
struct RegisterBinding {
    enum class Source : uint8_t { RootConstants, RootDescriptor, DescriptorTable, StaticSampler };
    DescriptorRangeType type = DescriptorRangeType::SRV;  // t, u, b or s registers
    uint32_t space = 0;
    uint32_t firstRegister = 0;
    uint32_t count = 1;  // registers covered; kDescriptorRangeUnbounded: every register from firstRegister on
    Source source = Source::RootDescriptor;
    uint32_t index = 0;  // the root parameter, or for a static sampler its index in staticSamplers
    uint32_t range = 0;  // DescriptorTable: the range's index in the table
    // DescriptorTable: descriptors from the table start to firstRegister's descriptor (OFFSET_APPEND resolved).
    uint32_t offsetInTable = 0;

    bool unbounded() const { return count == kDescriptorRangeUnbounded; }
    uint32_t lastRegister() const { return unbounded() ? 0xFFFFFFFFu : firstRegister + count - 1; }
    // "t0..t3, space5 (range 1 of the descriptor table in parameter [2])", "s0, space0 (static sampler 0)".
    std::string describe() const;
};

// An immutable root signature. Offsets are the REC-5 byte offsets of each argument from
// the start of a shader record (so the first is 32); global arguments use the same packing.
class RootSignature {
public:
    // Validates (PIPE-7, REC-4, REC-5, BIND-7..BIND-10), lays out and builds the register map. Throws DxrError on
    // a bad description.
    static std::shared_ptr<const RootSignature> create(RootSignatureDesc desc);

    const std::string& name() const { return desc_.name; }
    const RootSignatureDesc& desc() const { return desc_; }
    bool isLocal() const { return (desc_.flags & ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE) != 0; }
    size_t parameterCount() const { return desc_.parameters.size(); }
    const RootParameter& parameter(uint32_t index) const { return desc_.parameters.at(index); }
    // Byte offset of argument `index` from the record start (REC-5).
    uint32_t argumentOffset(uint32_t index) const { return offsets_.at(index); }
    // Local: bytes of argument `index` (constants 4*N, everything else 8).
    uint32_t argumentSize(uint32_t index) const;
    // Local: identifier + arguments, i.e. the smallest record this signature needs (REC-5).
    uint32_t recordSize() const { return recordSize_; }
    // A one-line description: "Procedural{[0] 12 constants b1 @32, [1] 2 constants b2 @80}"; static samplers
    // follow the parameters: "Global{[0] table(2 ranges); static samplers s0, s1 space2}".
    std::string describe() const;

    // Static sampler `index` (in desc().staticSamplers order) as a SamplerDesc.
    const SamplerDesc& staticSampler(uint32_t index) const { return staticSamplers_.at(index); }
    // The binding that covers register `shaderRegister` of `type` in `space`, or nullptr. O(log bindings).
    const RegisterBinding* findRegister(DescriptorRangeType type, uint32_t space, uint32_t shaderRegister) const;
    // Every binding, sorted by (type, space, firstRegister).
    const std::vector<RegisterBinding>& registerBindings() const { return bindings_; }

private:
    explicit RootSignature(RootSignatureDesc desc);
    RootSignatureDesc desc_;
    std::vector<uint32_t> offsets_;
    uint32_t recordSize_ = 0;
    std::vector<SamplerDesc> staticSamplers_;
    std::vector<RegisterBinding> bindings_;
};

using RootSignaturePtr = std::shared_ptr<const RootSignature>;

// Typed, checked packing of root arguments (REC-5). For a local signature these are the
// record bytes after the identifier; for a global one, what SetComputeRoot* would set.
// Unset arguments stay unwritten, so a shader reading them is reported (REC-7).
class RootArguments {
public:
    explicit RootArguments(RootSignaturePtr signature);

    template <class T>
    RootArguments& setConstants(uint32_t parameter, const T& value) {
        return setConstantBytes(parameter, &value, sizeof(T));
    }
    RootArguments& setConstantBytes(uint32_t parameter, const void* data, uint32_t size);
    // Root CBV/SRV/UAV: a GPU virtual address; descriptor table: a GPU descriptor handle.
    RootArguments& setDescriptor(uint32_t parameter, uint64_t addressOrHandle);

    const RootSignaturePtr& signature() const { return signature_; }
    // Bytes after the identifier (record offset 32 onward) and which of them were set.
    const std::vector<uint8_t>& bytes() const { return bytes_; }
    const std::vector<uint8_t>& setMask() const { return set_; }

private:
    RootSignaturePtr signature_;
    std::vector<uint8_t> bytes_;
    std::vector<uint8_t> set_;
};
using LocalRootArguments = RootArguments;
using GlobalRootArguments = RootArguments;

}  // namespace refray::dxr
