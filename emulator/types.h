// DXR enums and plain structs shared by the emulator and the shaders (HLSL / d3d12.h names).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/math.h"

namespace refray::dxr {

using GpuVirtualAddress = uint64_t;

// Ray flags (FLAG-1), D3D12_RAY_FLAG_* / HLSL RAY_FLAG_*.
enum RayFlag : uint32_t {
    RAY_FLAG_NONE = 0x00,
    RAY_FLAG_FORCE_OPAQUE = 0x01,
    RAY_FLAG_FORCE_NON_OPAQUE = 0x02,
    RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH = 0x04,
    RAY_FLAG_SKIP_CLOSEST_HIT_SHADER = 0x08,
    RAY_FLAG_CULL_BACK_FACING_TRIANGLES = 0x10,
    RAY_FLAG_CULL_FRONT_FACING_TRIANGLES = 0x20,
    RAY_FLAG_CULL_OPAQUE = 0x40,
    RAY_FLAG_CULL_NON_OPAQUE = 0x80,
    RAY_FLAG_SKIP_TRIANGLES = 0x100,
    RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES = 0x200,
};
// Bits defined for Tier 1.1 (FORCE_OMM_2_STATE needs opacity micromaps, which refray rejects: EXT-1).
inline constexpr uint32_t kDefinedRayFlags = 0x3FF;

// D3D12_RAYTRACING_INSTANCE_FLAGS (INST-5).
enum InstanceFlag : uint32_t {
    INSTANCE_FLAG_NONE = 0x0,
    INSTANCE_FLAG_TRIANGLE_CULL_DISABLE = 0x1,
    INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE = 0x2,
    INSTANCE_FLAG_FORCE_OPAQUE = 0x4,
    INSTANCE_FLAG_FORCE_NON_OPAQUE = 0x8,
};
inline constexpr uint32_t kDefinedInstanceFlags = 0xF;

// D3D12_RAYTRACING_GEOMETRY_FLAGS (BLAS-2).
enum GeometryFlag : uint32_t {
    GEOMETRY_FLAG_NONE = 0x0,
    GEOMETRY_FLAG_OPAQUE = 0x1,
    GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION = 0x2,
};
inline constexpr uint32_t kDefinedGeometryFlags = 0x3;

// D3D12_RAYTRACING_PIPELINE_FLAGS (PIPE-3).
enum PipelineFlag : uint32_t {
    PIPELINE_FLAG_NONE = 0x0,
    PIPELINE_FLAG_SKIP_TRIANGLES = 0x100,
    PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES = 0x200,
};
inline constexpr uint32_t kDefinedPipelineFlags = 0x300;

// D3D12_HIT_KIND (FACE-4).
inline constexpr uint32_t HIT_KIND_TRIANGLE_FRONT_FACE = 0xFE;
inline constexpr uint32_t HIT_KIND_TRIANGLE_BACK_FACE = 0xFF;

// HLSL RayDesc (RAY-4): the direction is never normalized.
struct RayDesc {
    vec3 Origin{0.0f};
    float TMin = 0.0f;
    vec3 Direction{0.0f, 0.0f, 1.0f};
    float TMax = 0.0f;
};

// HLSL BuiltInTriangleIntersectionAttributes (SV-12): x weights v1, y weights v2.
struct BuiltInTriangleIntersectionAttributes {
    vec2 barycentrics{0.0f};
};

// Compute: a compute shader of Device::dispatch (inline ray tracing from compute, RQ-1); not a ray-tracing stage.
enum class ShaderStage : uint8_t { RayGeneration, Intersection, AnyHit, ClosestHit, Miss, Callable, Compute };
inline constexpr size_t kShaderStageCount = 7;
std::string_view toString(ShaderStage stage);

// Names a flag set ("CULL_BACK_FACING_TRIANGLES|FORCE_OPAQUE"); unknown bits as hex.
std::string rayFlagsToString(uint32_t flags);
std::string instanceFlagsToString(uint32_t flags);
std::string geometryFlagsToString(uint32_t flags);
std::string pipelineFlagsToString(uint32_t flags);

}  // namespace refray::dxr
