// DXR constants and limits (dxr-semantics.md LIM-1), with the d3d12.h names in comments.
#pragma once

#include <cstdint>

namespace refray::dxr {

inline constexpr uint32_t kShaderIdentifierSizeInBytes = 32;          // D3D12_SHADER_IDENTIFIER_SIZE_IN_BYTES
inline constexpr uint32_t kShaderRecordByteAlignment = 32;            // D3D12_RAYTRACING_SHADER_RECORD_BYTE_ALIGNMENT
inline constexpr uint32_t kShaderTableByteAlignment = 64;             // D3D12_RAYTRACING_SHADER_TABLE_BYTE_ALIGNMENT
inline constexpr uint32_t kMaxShaderRecordStride = 4096;              // D3D12_RAYTRACING_MAX_SHADER_RECORD_STRIDE
inline constexpr uint32_t kMaxLocalRootArgumentBytes = kMaxShaderRecordStride - kShaderIdentifierSizeInBytes;  // REC-4
inline constexpr uint32_t kMaxAttributeSizeInBytes = 32;              // D3D12_RAYTRACING_MAX_ATTRIBUTE_SIZE_IN_BYTES
inline constexpr uint32_t kMaxDeclarableTraceRecursionDepth = 31;     // D3D12_RAYTRACING_MAX_DECLARABLE_TRACE_RECURSION_DEPTH
inline constexpr uint64_t kMaxRayGenerationShaderThreads = 1ull << 30;  // D3D12_RAYTRACING_MAX_RAY_GENERATION_SHADER_THREADS
inline constexpr uint64_t kMaxGeometriesPerBottomLevelAS = 1ull << 24;  // D3D12_RAYTRACING_MAX_GEOMETRIES_PER_BOTTOM_LEVEL_ACCELERATION_STRUCTURE
inline constexpr uint64_t kMaxPrimitivesPerBottomLevelAS = 1ull << 29;  // D3D12_RAYTRACING_MAX_PRIMITIVES_PER_BOTTOM_LEVEL_ACCELERATION_STRUCTURE
inline constexpr uint64_t kMaxInstancesPerTopLevelAS = 1ull << 24;      // D3D12_RAYTRACING_MAX_INSTANCES_PER_TOP_LEVEL_ACCELERATION_STRUCTURE
inline constexpr uint32_t kAccelerationStructureByteAlignment = 256;  // D3D12_RAYTRACING_ACCELERATION_STRUCTURE_BYTE_ALIGNMENT
inline constexpr uint32_t kInstanceDescsByteAlignment = 16;           // D3D12_RAYTRACING_INSTANCE_DESCS_BYTE_ALIGNMENT
inline constexpr uint32_t kTransform3x4ByteAlignment = 16;            // D3D12_RAYTRACING_TRANSFORM3X4_BYTE_ALIGNMENT
inline constexpr uint32_t kAABBByteAlignment = 8;                     // D3D12_RAYTRACING_AABB_BYTE_ALIGNMENT
inline constexpr uint32_t kMaxProceduralHitKind = 127;                // IS-4

// Field widths of the indexing rule (IDX-2, IDX-7) and of D3D12_RAYTRACING_INSTANCE_DESC (INST-1).
inline constexpr uint32_t kRayContributionMask = 0xF;
inline constexpr uint32_t kGeometryMultiplierMask = 0xF;
inline constexpr uint32_t kMissShaderIndexMask = 0xFFFF;
inline constexpr uint32_t kInstanceInclusionMaskBits = 0xFF;
inline constexpr uint32_t kInstanceContributionMask = 0xFFFFFF;
inline constexpr uint32_t kInstanceIDMask = 0xFFFFFF;

}  // namespace refray::dxr
