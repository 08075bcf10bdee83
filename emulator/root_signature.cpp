#include "emulator/root_signature.h"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <tuple>

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

char registerLetter(DescriptorRangeType type) {
    switch (type) {
        case DescriptorRangeType::SRV: return 't';
        case DescriptorRangeType::UAV: return 'u';
        case DescriptorRangeType::CBV: return 'b';
        case DescriptorRangeType::Sampler: return 's';
    }
    return '?';
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

SamplerDesc StaticSamplerDesc::sampler() const {
    SamplerDesc d;
    d.Filter = Filter;
    d.AddressU = AddressU;
    d.AddressV = AddressV;
    d.AddressW = AddressW;
    d.MipLODBias = MipLODBias;
    d.MaxAnisotropy = MaxAnisotropy;
    d.BorderColor = toColor(BorderColor);
    d.MinLOD = MinLOD;
    d.MaxLOD = MaxLOD;
    return d;
}

std::string RegisterBinding::describe() const {
    std::ostringstream s;
    const char letter = registerLetter(type);
    s << letter << firstRegister;
    if (unbounded())
        s << ".. (unbounded)";
    else if (count > 1)
        s << ".." << letter << lastRegister();
    s << ", space" << space << " (";
    switch (source) {
        case Source::RootConstants: s << "root constants, parameter [" << index << "]"; break;
        case Source::RootDescriptor: s << "root " << toString(type) << ", parameter [" << index << "]"; break;
        case Source::DescriptorTable:
            s << "range " << range << " of the descriptor table in parameter [" << index << "]";
            break;
        case Source::StaticSampler: s << "static sampler " << index; break;
    }
    s << ")";
    return s.str();
}

namespace {

bool bindingBefore(const RegisterBinding& a, const RegisterBinding& b) {
    return std::tie(a.type, a.space, a.firstRegister) < std::tie(b.type, b.space, b.firstRegister);
}

// The register map of a root signature: every binding, with table offsets resolved (BIND-8, BIND-9), checked for
// overlaps (BIND-7) and sorted for findRegister.
std::vector<RegisterBinding> registerMap(const RootSignatureDesc& desc) {
    const std::string where = "root signature '" + desc.name + "'";
    std::vector<RegisterBinding> bindings;
    for (uint32_t i = 0; i < desc.parameters.size(); ++i) {
        const RootParameter& p = desc.parameters[i];
        RegisterBinding b;
        b.space = p.registerSpace;
        b.firstRegister = p.shaderRegister;
        b.index = i;
        switch (p.parameterType) {
            case RootParameterType::Constants32Bit:
                b.type = DescriptorRangeType::CBV;
                b.source = RegisterBinding::Source::RootConstants;
                bindings.push_back(b);
                break;
            case RootParameterType::CBV:
            case RootParameterType::SRV:
            case RootParameterType::UAV:
                b.type = p.parameterType == RootParameterType::CBV   ? DescriptorRangeType::CBV
                         : p.parameterType == RootParameterType::SRV ? DescriptorRangeType::SRV
                                                                     : DescriptorRangeType::UAV;
                b.source = RegisterBinding::Source::RootDescriptor;
                bindings.push_back(b);
                break;
            case RootParameterType::DescriptorTable: {
                const std::string table = where + " parameter [" + std::to_string(i) + "]";
                uint64_t next = 0;            // where an APPEND range starts
                bool afterUnbounded = false;  // ... unknown after an unbounded range
                for (uint32_t r = 0; r < p.ranges.size(); ++r) {
                    const DescriptorRange& range = p.ranges[r];
                    const std::string at = table + " range " + std::to_string(r);
                    if ((range.rangeType == DescriptorRangeType::Sampler) !=
                        (p.ranges[0].rangeType == DescriptorRangeType::Sampler))
                        throw DxrError(
                            diag("BIND-8", table + ": a descriptor table mixes Sampler ranges with CBV/SRV/UAV "
                                                   "ranges; D3D12 keeps samplers in tables (and heaps) of their own")
                                .value("range 0", toString(p.ranges[0].rangeType))
                                .value("range " + std::to_string(r), toString(range.rangeType)));
                    const bool unbounded = range.numDescriptors == kDescriptorRangeUnbounded;
                    if (range.numDescriptors == 0)
                        throw DxrError(diag("BIND-9", at + " declares no descriptors")
                                           .value("NumDescriptors", 0, ">= 1, or UINT_MAX for an unbounded range"));
                    if (!unbounded && uint64_t(range.baseShaderRegister) + range.numDescriptors - 1 > 0xFFFFFFFFull)
                        throw DxrError(diag("BIND-9", at + " runs past the last register")
                                           .value("BaseShaderRegister", range.baseShaderRegister)
                                           .value("NumDescriptors", range.numDescriptors));
                    uint64_t offset = range.offsetInDescriptorsFromTableStart;
                    if (offset == kDescriptorRangeOffsetAppend) {
                        if (afterUnbounded)
                            throw DxrError(
                                diag("BIND-9", at + " uses DESCRIPTOR_RANGE_OFFSET_APPEND after an unbounded "
                                                    "range, so it has no offset; an unbounded range must be "
                                                    "the last one or the next range must give an explicit offset"));
                        offset = next;
                    }
                    if (!unbounded && offset + range.numDescriptors > 0xFFFFFFFFull)
                        throw DxrError(diag("BIND-9", at + " ends past the largest descriptor offset")
                                           .value("offset", offset)
                                           .value("NumDescriptors", range.numDescriptors));
                    afterUnbounded = unbounded;
                    next = unbounded ? 0 : offset + range.numDescriptors;
                    RegisterBinding t;
                    t.type = range.rangeType;
                    t.space = range.registerSpace;
                    t.firstRegister = range.baseShaderRegister;
                    t.count = range.numDescriptors;
                    t.source = RegisterBinding::Source::DescriptorTable;
                    t.index = i;
                    t.range = r;
                    t.offsetInTable = uint32_t(offset);
                    bindings.push_back(t);
                }
                break;
            }
        }
    }
    for (uint32_t i = 0; i < desc.staticSamplers.size(); ++i) {
        const StaticSamplerDesc& s = desc.staticSamplers[i];
        const std::string at = where + " static sampler " + std::to_string(i) + " (s" +
                               std::to_string(s.ShaderRegister) + ", space" + std::to_string(s.RegisterSpace) + ")";
        if (s.BorderColor > STATIC_BORDER_COLOR_OPAQUE_WHITE)
            throw DxrError(
                diag("BIND-10", at + ": BorderColor is not a D3D12_STATIC_BORDER_COLOR")
                    .value("BorderColor", uint32_t(s.BorderColor), "0 (TRANSPARENT_BLACK) .. 2 (OPAQUE_WHITE)"));
        validateSamplerDesc(s.sampler(), at);
        RegisterBinding b;
        b.type = DescriptorRangeType::Sampler;
        b.space = s.RegisterSpace;
        b.firstRegister = s.ShaderRegister;
        b.source = RegisterBinding::Source::StaticSampler;
        b.index = i;
        bindings.push_back(b);
    }

    // BIND-7: within one type and space, every register has at most one binding.
    std::stable_sort(bindings.begin(), bindings.end(), bindingBefore);
    for (size_t k = 1; k < bindings.size(); ++k) {
        const RegisterBinding& a = bindings[k - 1];
        const RegisterBinding& b = bindings[k];
        if (a.type == b.type && a.space == b.space && b.firstRegister <= a.lastRegister())
            throw DxrError(diag("BIND-7", where + " binds register " + registerLetter(b.type) +
                                              std::to_string(b.firstRegister) + ", space" + std::to_string(b.space) +
                                              " twice: " + a.describe() + " and " + b.describe()));
    }
    return bindings;
}

}  // namespace

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

    std::vector<RegisterBinding> bindings = registerMap(desc);

    auto signature = std::shared_ptr<RootSignature>(new RootSignature(std::move(desc)));
    signature->bindings_ = std::move(bindings);
    for (const StaticSamplerDesc& s : signature->desc_.staticSamplers)
        signature->staticSamplers_.push_back(s.sampler());
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
    for (size_t i = 0; i < desc_.staticSamplers.size(); ++i) {
        const StaticSamplerDesc& sampler = desc_.staticSamplers[i];
        s << (i ? ", s" : "; static samplers s") << sampler.ShaderRegister;
        if (sampler.RegisterSpace) s << " space" << sampler.RegisterSpace;
    }
    s << "}";
    return s.str();
}

const RegisterBinding* RootSignature::findRegister(DescriptorRangeType type, uint32_t space,
                                                   uint32_t shaderRegister) const {
    RegisterBinding key;
    key.type = type;
    key.space = space;
    key.firstRegister = shaderRegister;
    // The last binding that starts at or before the register; bindings never overlap (BIND-7).
    auto it = std::upper_bound(bindings_.begin(), bindings_.end(), key, bindingBefore);
    if (it == bindings_.begin()) return nullptr;
    --it;
    if (it->type != type || it->space != space || shaderRegister > it->lastRegister()) return nullptr;
    return &*it;
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
