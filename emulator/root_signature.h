// Global and local root signatures and their argument layouts (REC-5, REC-6, PIPE-6, PIPE-7).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "emulator/types.h"

namespace refray::dxr {

enum class DescriptorRangeType : uint8_t { SRV, UAV, CBV, Sampler };
std::string_view toString(DescriptorRangeType type);

inline constexpr uint32_t kDescriptorRangeOffsetAppend = 0xFFFFFFFF;  // D3D12_DESCRIPTOR_RANGE_OFFSET_APPEND

struct DescriptorRange {
    DescriptorRangeType rangeType = DescriptorRangeType::SRV;
    uint32_t numDescriptors = 1;
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

struct RootSignatureDesc {
    std::string name;  // for diagnostics
    std::vector<RootParameter> parameters;
    uint32_t flags = ROOT_SIGNATURE_FLAG_NONE;
};

// An immutable root signature. Offsets are the REC-5 byte offsets of each argument from
// the start of a shader record (so the first is 32); global arguments use the same packing.
class RootSignature {
public:
    // Validates (PIPE-7, REC-4) and lays out. Throws DxrError on a bad description.
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
    // A one-line description: "Procedural{[0] 12 constants b1 @32, [1] 2 constants b2 @80}".
    std::string describe() const;

private:
    explicit RootSignature(RootSignatureDesc desc);
    RootSignatureDesc desc_;
    std::vector<uint32_t> offsets_;
    uint32_t recordSize_ = 0;
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
