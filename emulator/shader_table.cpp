#include "emulator/shader_table.h"

#include <algorithm>

#include "core/error.h"

namespace refray::dxr {

HitGroupIndexTerms hitGroupRecordIndex(uint32_t rayContributionToHitGroupIndex,
                                       uint32_t multiplierForGeometryContributionToHitGroupIndex,
                                       uint32_t geometryIndex, uint32_t instanceContributionToHitGroupIndex) {
    HitGroupIndexTerms t;
    t.rawRayContribution = rayContributionToHitGroupIndex;
    t.rawMultiplier = multiplierForGeometryContributionToHitGroupIndex;
    t.rayContribution = rayContributionToHitGroupIndex & kRayContributionMask;
    t.multiplier = multiplierForGeometryContributionToHitGroupIndex & kGeometryMultiplierMask;
    t.geometryIndex = geometryIndex;
    t.instanceContribution = instanceContributionToHitGroupIndex & kInstanceContributionMask;
    t.index = uint64_t(t.rayContribution) + uint64_t(t.multiplier) * uint64_t(t.geometryIndex) +
              uint64_t(t.instanceContribution);
    return t;
}

ShaderTableBuilder& ShaderTableBuilder::addRecord(const ShaderIdentifier& identifier) {
    records_.push_back({identifier, {}, {}});
    return *this;
}

ShaderTableBuilder& ShaderTableBuilder::addRecord(const ShaderIdentifier& identifier,
                                                  const LocalRootArguments& arguments) {
    records_.push_back({identifier, arguments.bytes(), arguments.setMask()});
    return *this;
}

uint64_t ShaderTableBuilder::naturalStride() const {
    uint64_t largest = kShaderIdentifierSizeInBytes;
    for (const auto& r : records_) largest = std::max<uint64_t>(largest, kShaderIdentifierSizeInBytes + r.arguments.size());
    return (largest + kShaderRecordByteAlignment - 1) / kShaderRecordByteAlignment * kShaderRecordByteAlignment;
}

GpuVirtualAddressRangeAndStride ShaderTableBuilder::upload(GpuMemory& memory, uint64_t strideOverride) const {
    REFRAY_CHECK(!records_.empty(), "shader table '" << name_ << "' has no records");
    const uint64_t stride = strideOverride == ~0ull ? naturalStride() : strideOverride;
    // The last record needs its own bytes even when the stride is smaller than a record.
    uint64_t size = 0;
    for (size_t i = 0; i < records_.size(); ++i)
        size = std::max(size, stride * i + kShaderIdentifierSizeInBytes + records_[i].arguments.size());
    const GpuVirtualAddress base = memory.allocate(size, name_);
    for (size_t i = 0; i < records_.size(); ++i) {
        const Record& r = records_[i];
        const GpuVirtualAddress at = base + stride * i;
        memory.write(at, r.identifier.data(), kShaderIdentifierSizeInBytes);
        // Only the arguments that were set count as written (REC-7).
        for (size_t b = 0; b < r.arguments.size(); ++b)
            if (r.argumentSetMask[b]) memory.write(at + kShaderIdentifierSizeInBytes + b, &r.arguments[b], 1);
    }
    return {base, size, stride};
}

}  // namespace refray::dxr
