// The emulator's BLASes and TLAS rebuilt as Vulkan acceleration structures from the same build inputs: the same
// vertex and index buffers with their formats, geometry transforms, AABBs and geometry flags, and the TLAS's
// instance descs with the same transforms, InstanceIDs, masks, contributions and flags.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <vector>

#include "emulator/device.h"
#include "gpu/vulkan_memory.h"

namespace refray::gpu {

// The translations, pure functions of emulator state (tests/gpu checks them without a GPU).

// D3D12_RAYTRACING_INSTANCE_DESC -> VkAccelerationStructureInstanceKHR: the 3x4 row-major transform verbatim,
// InstanceID -> instanceCustomIndex, InstanceMask -> mask, InstanceContributionToHitGroupIndex ->
// instanceShaderBindingTableRecordOffset, the flags bit for bit (TRIANGLE_CULL_DISABLE, FRONT_COUNTERCLOCKWISE =
// FLIP_FACING, FORCE_OPAQUE, FORCE_NON_OPAQUE have the same values), and `blasReference` (0: inactive).
VkAccelerationStructureInstanceKHR translateInstance(const dxr::InstanceDesc& desc, uint64_t blasReference);
// Every instance of `tlas` in InstanceIndex order; `blasReference(blas)` gives the device address of a BLAS.
// An instance the emulator treats as inactive (no BLAS, INST-6; a singular transform, INST-9) gets reference 0,
// which Vulkan also treats as inactive.
std::vector<VkAccelerationStructureInstanceKHR> translateInstances(
    const dxr::TopLevelAS& tlas, const std::function<uint64_t(const dxr::BottomLevelAS&)>& blasReference);

// GEOMETRY_FLAG_OPAQUE -> VK_GEOMETRY_OPAQUE_BIT_KHR, NO_DUPLICATE_ANYHIT_INVOCATION ->
// VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR (same values).
VkGeometryFlagsKHR translateGeometryFlags(uint32_t flags);
// D3D12_RAYTRACING_ACCELERATION_STRUCTURE_BUILD_FLAGS -> VkBuildAccelerationStructureFlagsKHR (same values for
// ALLOW_UPDATE .. MINIMIZE_MEMORY; PERFORM_UPDATE is a build mode in Vulkan, not a flag, and is dropped).
VkBuildAccelerationStructureFlagsKHR translateBuildFlags(uint32_t flags);
// DXGI vertex format -> VkFormat; nullopt for a format no AS accepts.
std::optional<VkFormat> translateVertexFormat(dxr::Format format);
// R16_UINT / R32_UINT / UNKNOWN (non-indexed) -> VkIndexType.
VkIndexType translateIndexFormat(dxr::Format format);

// The BLASes the TLAS at `tlas` references and the TLAS itself, built on the GPU.
class AccelerationStructures {
public:
    // Builds every BLAS an active instance references (once each), then the TLAS. Buffers come through `addresses`.
    AccelerationStructures(const VulkanContext& context, AddressMap& addresses, const dxr::Device& device,
                           dxr::GpuVirtualAddress tlas);
    ~AccelerationStructures();
    AccelerationStructures(const AccelerationStructures&) = delete;
    AccelerationStructures& operator=(const AccelerationStructures&) = delete;

    VkAccelerationStructureKHR topLevel() const { return topLevel_.handle; }

private:
    struct Built {
        Buffer storage;
        VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
        VkDeviceAddress address = 0;
    };
    Built build(const VkAccelerationStructureBuildGeometryInfoKHR& info, const std::vector<uint32_t>& primitiveCounts,
                const std::vector<VkAccelerationStructureBuildRangeInfoKHR>& ranges);

    const VulkanContext& context_;
    std::map<const dxr::BottomLevelAS*, Built> bottomLevel_;
    Buffer instances_;
    Built topLevel_;
};

}  // namespace refray::gpu
