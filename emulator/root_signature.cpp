#include "emulator/root_signature.h"

#include <cstring>
#include <sstream>

#include "emulator/limits.h"
#include "emulator/validation.h"

namespace refray::dxr {

std::string_view toString(DescriptorRangeType type) {
    switch (type) {
        case DescriptorRangeType::SRV: return "SRV";
        case DescriptorRangeType::UAV: return "UAV";
        case DescriptorRangeType::CBV: return "CBV";
        case DescriptorRangeType::Sampler: return "Sampler";
    }
    return "?";
}

std::string_view toString(RootParameterType type) {
    switch (type) {
        case RootParameterType::DescriptorTable: return "descriptor table";
        case RootParameterType::Constants32Bit: return "root constants";
        case RootParameterType::CBV: return "root CBV";
        case RootParameterType::SRV: return "root SRV";
        case RootParameterType::UAV: return "root UAV";
    }
    return "?";
}

RootParameter RootParameter::constants(uint32_t num32BitValues, uint32_t shaderRegister, uint32_t registerSpace) {
    RootParameter p;
    p.parameterType = RootParameterType::Constants32Bit;
    p.num32BitValues = num32BitValues;
    p.shaderRegister = shaderRegister;
    p.registerSpace = registerSpace;
    return p;
}

namespace {
RootParameter descriptorParameter(RootParameterType type, uint32_t shaderRegister, uint32_t registerSpace) {
    RootParameter p;
    p.parameterType = type;
    p.shaderRegister = shaderRegister;
    p.registerSpace = registerSpace;
    return p;
}
}  // namespace

RootParameter RootParameter::cbv(uint32_t r, uint32_t s) { return descriptorParameter(RootParameterType::CBV, r, s); }
RootParameter RootParameter::srv(uint32_t r, uint32_t s) { return descriptorParameter(RootParameterType::SRV, r, s); }
RootParameter RootParameter::uav(uint32_t r, uint32_t s) { return descriptorParameter(RootParameterType::UAV, r, s); }

RootParameter RootParameter::table(std::vector<DescriptorRange> ranges) {
    RootParameter p;
    p.parameterType = RootParameterType::DescriptorTable;
    p.ranges = std::move(ranges);
    return p;
}

RootSignature::RootSignature(RootSignatureDesc desc) : desc_(std::move(desc)) {}

std::shared_ptr<const RootSignature> RootSignature::create(RootSignatureDesc desc) {
    if (desc.name.empty()) desc.name = "(unnamed root signature)";
    const uint32_t unknownFlags = desc.flags & ~uint32_t(ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE);
    if ((desc.flags & ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE) && unknownFlags)
        throw DxrError(diag("PIPE-7", "local root signature '" + desc.name +
                                          "' carries flags other than LOCAL_ROOT_SIGNATURE")
                           .hex("flags", desc.flags, "0x80 only"));
    for (size_t i = 0; i < desc.parameters.size(); ++i) {
        const RootParameter& p = desc.parameters[i];
        if (p.parameterType == RootParameterType::Constants32Bit && p.num32BitValues == 0)
            throw DxrError(diag("REC-5", "root signature '" + desc.name + "' parameter " + std::to_string(i) +
                                             " declares 0 root constants")
                               .value("Num32BitValues", 0, ">= 1"));
        if (p.parameterType == RootParameterType::DescriptorTable && p.ranges.empty())
            throw DxrError(diag("REC-5", "root signature '" + desc.name + "' parameter " + std::to_string(i) +
                                             " is a descriptor table without ranges"));
    }

    auto signature = std::shared_ptr<RootSignature>(new RootSignature(std::move(desc)));
    // REC-5: constants 4-byte aligned and packed, 8-byte arguments at the next multiple of 8.
    uint32_t offset = kShaderIdentifierSizeInBytes;
    for (uint32_t i = 0; i < signature->parameterCount(); ++i) {
        const uint32_t size = signature->argumentSize(i);
        // Only GPU addresses and descriptor handles are 8-byte aligned; constants pack at 4.
        if (signature->parameter(i).parameterType != RootParameterType::Constants32Bit) offset = (offset + 7u) & ~7u;
        signature->offsets_.push_back(offset);
        offset += size;
    }
    signature->recordSize_ = offset;
    if (signature->isLocal()) {
        if (offset - kShaderIdentifierSizeInBytes > kMaxLocalRootArgumentBytes)
            throw DxrError(diag("REC-4", "local root signature '" + signature->name() +
                                             "' needs more local root argument bytes than a record can hold")
                               .value("argument bytes", offset - kShaderIdentifierSizeInBytes,
                                      std::to_string(kMaxLocalRootArgumentBytes)));
    }
    return signature;
}

uint32_t RootSignature::argumentSize(uint32_t index) const {
    const RootParameter& p = parameter(index);
    return p.parameterType == RootParameterType::Constants32Bit ? 4 * p.num32BitValues : 8;
}

std::string RootSignature::describe() const {
    std::ostringstream s;
    s << name() << "{";
    for (uint32_t i = 0; i < parameterCount(); ++i) {
        const RootParameter& p = parameter(i);
        s << (i ? ", " : "") << "[" << i << "] ";
        if (p.parameterType == RootParameterType::Constants32Bit) s << p.num32BitValues << " constants b" << p.shaderRegister;
        else if (p.parameterType == RootParameterType::DescriptorTable) s << "table(" << p.ranges.size() << " ranges)";
        else s << toString(p.parameterType) << " " << p.shaderRegister;
        if (isLocal()) s << " @" << argumentOffset(i);
    }
    s << "}";
    return s.str();
}

RootArguments::RootArguments(RootSignaturePtr signature) : signature_(std::move(signature)) {
    REFRAY_CHECK(signature_, "RootArguments needs a root signature");
    bytes_.assign(signature_->recordSize() - kShaderIdentifierSizeInBytes, 0);
    set_.assign(bytes_.size(), 0);
}

RootArguments& RootArguments::setConstantBytes(uint32_t parameter, const void* data, uint32_t size) {
    REFRAY_CHECK(parameter < signature_->parameterCount(),
                 "local root signature '" << signature_->name() << "' has no parameter " << parameter);
    const RootParameter& p = signature_->parameter(parameter);
    REFRAY_CHECK(p.parameterType == RootParameterType::Constants32Bit,
                 "parameter " << parameter << " of '" << signature_->name() << "' is a " << toString(p.parameterType)
                              << ", not root constants");
    REFRAY_CHECK(size == p.num32BitValues * 4, "parameter " << parameter << " of '" << signature_->name() << "' holds "
                                                            << p.num32BitValues * 4 << " bytes of constants, got "
                                                            << size);
    const uint32_t offset = signature_->argumentOffset(parameter) - kShaderIdentifierSizeInBytes;
    std::memcpy(bytes_.data() + offset, data, size);
    std::fill_n(set_.begin() + offset, size, uint8_t(1));
    return *this;
}

RootArguments& RootArguments::setDescriptor(uint32_t parameter, uint64_t addressOrHandle) {
    REFRAY_CHECK(parameter < signature_->parameterCount(),
                 "local root signature '" << signature_->name() << "' has no parameter " << parameter);
    const RootParameter& p = signature_->parameter(parameter);
    REFRAY_CHECK(p.parameterType != RootParameterType::Constants32Bit,
                 "parameter " << parameter << " of '" << signature_->name()
                              << "' is root constants; use setConstants");
    const uint32_t offset = signature_->argumentOffset(parameter) - kShaderIdentifierSizeInBytes;
    std::memcpy(bytes_.data() + offset, &addressOrHandle, 8);
    std::fill_n(set_.begin() + offset, 8, uint8_t(1));
    return *this;
}

}  // namespace refray::dxr
