// BLAS and TLAS: D3D12 build descriptions in, immutable Embree-backed structures out.
//
// Inputs are read from GpuMemory at build time and copied (BLAS-8); nothing here keeps
// a reference to app buffers. Embree types stay inside embree_bridge.cpp.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "emulator/gpu_memory.h"
#include "emulator/types.h"
#include "emulator/validation.h"

namespace refray::dxr {

enum class Format : uint8_t {
    UNKNOWN,
    R32G32B32_FLOAT,
    R32G32_FLOAT,
    R16G16B16A16_FLOAT,
    R16G16_FLOAT,
    R16G16B16A16_SNORM,
    R16G16_SNORM,
    R16G16B16A16_UNORM,  // Tier 1.1
    R16G16_UNORM,        // Tier 1.1
    R10G10B10A2_UNORM,   // Tier 1.1
    R8G8B8A8_UNORM,      // Tier 1.1
    R8G8_UNORM,          // Tier 1.1
    R8G8B8A8_SNORM,      // Tier 1.1
    R8G8_SNORM,          // Tier 1.1
    R16_UINT,            // index format
    R32_UINT,            // index format
};
std::string_view toString(Format format);

struct GpuVirtualAddressAndStride {
    GpuVirtualAddress StartAddress = 0;
    uint64_t StrideInBytes = 0;
};

enum class GeometryType : uint8_t { Triangles = 0, ProceduralPrimitiveAABBs = 1 };

struct GeometryTrianglesDesc {
    GpuVirtualAddress Transform3x4 = 0;  // optional row-major 3x4 (BLAS-5)
    Format IndexFormat = Format::UNKNOWN;
    Format VertexFormat = Format::R32G32B32_FLOAT;
    uint32_t IndexCount = 0;
    uint32_t VertexCount = 0;
    GpuVirtualAddress IndexBuffer = 0;
    GpuVirtualAddressAndStride VertexBuffer;
};

// D3D12_RAYTRACING_AABB.
struct RaytracingAABB {
    float MinX, MinY, MinZ, MaxX, MaxY, MaxZ;
};

struct GeometryAABBsDesc {
    uint64_t AABBCount = 0;
    GpuVirtualAddressAndStride AABBs;
};

struct GeometryDesc {
    GeometryType Type = GeometryType::Triangles;
    uint32_t Flags = GEOMETRY_FLAG_NONE;
    GeometryTrianglesDesc Triangles;
    GeometryAABBsDesc AABBs;
};

// D3D12_RAYTRACING_ACCELERATION_STRUCTURE_BUILD_FLAGS.
enum BuildFlag : uint32_t {
    BUILD_FLAG_NONE = 0x0,
    BUILD_FLAG_ALLOW_UPDATE = 0x1,
    BUILD_FLAG_ALLOW_COMPACTION = 0x2,
    BUILD_FLAG_PREFER_FAST_TRACE = 0x4,
    BUILD_FLAG_PREFER_FAST_BUILD = 0x8,
    BUILD_FLAG_MINIMIZE_MEMORY = 0x10,
    BUILD_FLAG_PERFORM_UPDATE = 0x20,
};

enum class ElementsLayout : uint8_t { Array, ArrayOfPointers };

struct BottomLevelInputs {
    uint32_t Flags = BUILD_FLAG_NONE;
    std::vector<GeometryDesc> GeometryDescs;  // GeometryIndex() = position here (IDX-4)
};

// D3D12_RAYTRACING_INSTANCE_DESC, bit for bit (INST-1).
struct InstanceDesc {
    float Transform[3][4];
    uint32_t InstanceID : 24;
    uint32_t InstanceMask : 8;
    uint32_t InstanceContributionToHitGroupIndex : 24;
    uint32_t Flags : 8;
    GpuVirtualAddress AccelerationStructure;
};
static_assert(sizeof(InstanceDesc) == 64, "D3D12_RAYTRACING_INSTANCE_DESC is 64 bytes");

InstanceDesc makeInstanceDesc(const Matrix3x4& transform, uint32_t instanceID, uint32_t mask,
                              uint32_t contribution, uint32_t flags, GpuVirtualAddress blas);
Matrix3x4 instanceTransform(const InstanceDesc& desc);

struct TopLevelInputs {
    uint32_t Flags = BUILD_FLAG_NONE;
    uint32_t NumDescs = 0;
    ElementsLayout DescsLayout = ElementsLayout::Array;
    GpuVirtualAddress InstanceDescs = 0;
};

namespace detail {
struct EmbreeScene;  // embree_bridge.cpp
}

// One geometry of a built BLAS, decoded and transformed (object space).
struct BuiltGeometry {
    GeometryType type = GeometryType::Triangles;
    uint32_t flags = 0;
    bool hasTransform = false;
    // Triangles: 3 post-transform vertices per triangle in app order; active[i] per DEGEN-1.
    std::vector<vec3> triangleVertices;
    // AABBs: as declared, with inverted boxes collapsed to their centre point (DEGEN-8).
    std::vector<RaytracingAABB> aabbs;
    std::vector<uint8_t> active;
    std::vector<uint32_t> indices;  // the index buffer as built (UPD-2 forbids changing it)
    uint32_t primitiveCount() const { return uint32_t(active.size()); }
};

class BottomLevelAS {
public:
    ~BottomLevelAS();
    GpuVirtualAddress address() const { return address_; }
    uint32_t buildFlags() const { return buildFlags_; }
    // The build inputs of the last build or update, as given (the GPU back end rebuilds from them).
    const BottomLevelInputs& inputs() const { return inputs_; }
    const std::vector<BuiltGeometry>& geometries() const { return geometries_; }
    bool isTriangles() const { return !geometries_.empty() && geometries_[0].type == GeometryType::Triangles; }
    uint64_t generation() const { return generation_.load(); }
    bool hasActivePrimitive() const;
    const detail::EmbreeScene& embree() const { return *embree_; }

private:
    friend class Device;
    GpuVirtualAddress address_ = 0;
    uint32_t buildFlags_ = 0;
    BottomLevelInputs inputs_;  // kept to diff updates against (UPD-2)
    std::vector<BuiltGeometry> geometries_;
    std::atomic<uint64_t> generation_{0};
    std::unique_ptr<detail::EmbreeScene> embree_;
};

struct BuiltInstance {
    InstanceDesc desc{};
    const BottomLevelAS* blas = nullptr;  // null: inactive (INST-6, INST-9)
    uint64_t blasGeneration = 0;
    Matrix3x4 objectToWorld;
    Matrix3x4 worldToObject;
};

class TopLevelAS {
public:
    ~TopLevelAS();
    GpuVirtualAddress address() const { return address_; }
    const std::vector<BuiltInstance>& instances() const { return instances_; }
    const detail::EmbreeScene& embree() const { return *embree_; }
    // INST-8: the device epoch at which every instance's BLAS was last found current.
    uint64_t checkedEpoch() const { return checkedEpoch_.load(std::memory_order_acquire); }
    void markChecked(uint64_t epoch) const { checkedEpoch_.store(epoch, std::memory_order_release); }

private:
    friend class Device;
    GpuVirtualAddress address_ = 0;
    uint32_t buildFlags_ = 0;
    std::vector<BuiltInstance> instances_;
    std::unique_ptr<detail::EmbreeScene> embree_;
    mutable std::atomic<uint64_t> checkedEpoch_{~0ull};  // INST-8 staleness check cache
};

}  // namespace refray::dxr
