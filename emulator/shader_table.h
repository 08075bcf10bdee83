// Shader tables as real bytes, and the indexing rule (IDX-1..14, REC-1..12).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "emulator/gpu_memory.h"
#include "emulator/limits.h"
#include "emulator/root_signature.h"
#include "emulator/state_object.h"

namespace refray::dxr {

// D3D12_GPU_VIRTUAL_ADDRESS_RANGE and _RANGE_AND_STRIDE.
struct GpuVirtualAddressRange {
    GpuVirtualAddress StartAddress = 0;
    uint64_t SizeInBytes = 0;
};
struct GpuVirtualAddressRangeAndStride {
    GpuVirtualAddress StartAddress = 0;
    uint64_t SizeInBytes = 0;
    uint64_t StrideInBytes = 0;
};

// D3D12_DISPATCH_RAYS_DESC.
struct DispatchRaysDesc {
    GpuVirtualAddressRange RayGenerationShaderRecord;
    GpuVirtualAddressRangeAndStride MissShaderTable;
    GpuVirtualAddressRangeAndStride HitGroupTable;
    GpuVirtualAddressRangeAndStride CallableShaderTable;
    uint32_t Width = 0;
    uint32_t Height = 0;
    uint32_t Depth = 1;
};

// The four terms of the hit-group index, masked to their DXR widths, and the result.
struct HitGroupIndexTerms {
    uint32_t rayContribution = 0;        // R: TraceRay argument 4, low 4 bits
    uint32_t multiplier = 0;             // M: TraceRay argument 5, low 4 bits
    uint32_t geometryIndex = 0;          // G: position of the geometry in its BLAS
    uint32_t instanceContribution = 0;   // C: InstanceContributionToHitGroupIndex, 24 bits
    uint32_t rawRayContribution = 0;     // the unmasked arguments, for IDX-2 warnings
    uint32_t rawMultiplier = 0;
    uint64_t index = 0;                  // I = R + M*G + C  (< 2^28, IDX-3)
};

// THE indexing rule (IDX-1, IDX-2, IDX-3). Every hit-group record lookup goes through here:
//
//   I    = (RayContributionToHitGroupIndex & 0xF)
//        + (MultiplierForGeometryContributionToHitGroupIndex & 0xF) * GeometryIndex
//        + (InstanceContributionToHitGroupIndex & 0xFFFFFF)
//   addr = HitGroupTable.StartAddress + HitGroupTable.StrideInBytes * I
//
// All arithmetic is 64-bit; the terms are kept for the trace log and for diagnostics.
HitGroupIndexTerms hitGroupRecordIndex(uint32_t rayContributionToHitGroupIndex,
                                       uint32_t multiplierForGeometryContributionToHitGroupIndex,
                                       uint32_t geometryIndex, uint32_t instanceContributionToHitGroupIndex);
// Miss: addr = MissShaderTable.StartAddress + stride * (MissShaderIndex & 0xFFFF) (IDX-7).
inline uint64_t missRecordIndex(uint32_t missShaderIndex) { return missShaderIndex & kMissShaderIndexMask; }
// Callable: all 32 bits (IDX-8).
inline uint64_t callableRecordIndex(uint32_t shaderIndex) { return shaderIndex; }
inline uint64_t recordAddress(const GpuVirtualAddressRangeAndStride& table, uint64_t index) {
    return table.StartAddress + table.StrideInBytes * index;
}

// Composes a shader table: records of identifier + local root arguments (REC-1, REC-5),
// uploaded at a 64-byte aligned address with a 32-byte aligned stride (REC-2, REC-3).
class ShaderTableBuilder {
public:
    explicit ShaderTableBuilder(std::string name) : name_(std::move(name)) {}
    // A record for `identifier` (32 bytes; all zero for NULL) with optional arguments.
    ShaderTableBuilder& addRecord(const ShaderIdentifier& identifier);
    ShaderTableBuilder& addRecord(const ShaderIdentifier& identifier, const LocalRootArguments& arguments);
    // Stride defaults to the largest record rounded up to 32; pass one to override
    // (a smaller one is allowed here so lessons can break the layout on purpose).
    GpuVirtualAddressRangeAndStride upload(GpuMemory& memory, uint64_t strideOverride = ~0ull) const;
    uint64_t naturalStride() const;
    size_t recordCount() const { return records_.size(); }

private:
    struct Record {
        ShaderIdentifier identifier;
        std::vector<uint8_t> arguments;
        std::vector<uint8_t> argumentSetMask;
    };
    std::string name_;
    std::vector<Record> records_;
};

}  // namespace refray::dxr
