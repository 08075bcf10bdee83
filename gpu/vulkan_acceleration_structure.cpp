#include "gpu/vulkan_acceleration_structure.h"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>

namespace refray::gpu {

using dxr::Format;

static_assert(uint32_t(VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR) == dxr::INSTANCE_FLAG_TRIANGLE_CULL_DISABLE);
static_assert(uint32_t(VK_GEOMETRY_INSTANCE_TRIANGLE_FRONT_COUNTERCLOCKWISE_BIT_KHR) ==
              dxr::INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE);
static_assert(uint32_t(VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR) == dxr::INSTANCE_FLAG_FORCE_OPAQUE);
static_assert(uint32_t(VK_GEOMETRY_INSTANCE_FORCE_NO_OPAQUE_BIT_KHR) == dxr::INSTANCE_FLAG_FORCE_NON_OPAQUE);
static_assert(uint32_t(VK_GEOMETRY_OPAQUE_BIT_KHR) == dxr::GEOMETRY_FLAG_OPAQUE);
static_assert(uint32_t(VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR) ==
              dxr::GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION);
static_assert(uint32_t(VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR) == dxr::BUILD_FLAG_ALLOW_UPDATE);
static_assert(uint32_t(VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR) == dxr::BUILD_FLAG_ALLOW_COMPACTION);
static_assert(uint32_t(VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR) == dxr::BUILD_FLAG_PREFER_FAST_TRACE);
static_assert(uint32_t(VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR) == dxr::BUILD_FLAG_PREFER_FAST_BUILD);
static_assert(uint32_t(VK_BUILD_ACCELERATION_STRUCTURE_LOW_MEMORY_BIT_KHR) == dxr::BUILD_FLAG_MINIMIZE_MEMORY);
static_assert(sizeof(VkTransformMatrixKHR) == sizeof(dxr::InstanceDesc::Transform), "both are row-major 3x4 floats");

VkAccelerationStructureInstanceKHR translateInstance(const dxr::InstanceDesc& desc, uint64_t blasReference) {
    VkAccelerationStructureInstanceKHR out{};
    std::memcpy(out.transform.matrix, desc.Transform, sizeof out.transform.matrix);
    out.instanceCustomIndex = desc.InstanceID & dxr::kInstanceIDMask;
    out.mask = desc.InstanceMask & dxr::kInstanceInclusionMaskBits;
    out.instanceShaderBindingTableRecordOffset = desc.InstanceContributionToHitGroupIndex & dxr::kInstanceContributionMask;
    out.flags = desc.Flags & dxr::kDefinedInstanceFlags;
    out.accelerationStructureReference = blasReference;
    return out;
}

std::vector<VkAccelerationStructureInstanceKHR> translateInstances(
    const dxr::TopLevelAS& tlas, const std::function<uint64_t(const dxr::BottomLevelAS&)>& blasReference) {
    std::vector<VkAccelerationStructureInstanceKHR> out;
    out.reserve(tlas.instances().size());
    for (const dxr::BuiltInstance& instance : tlas.instances())
        out.push_back(translateInstance(instance.desc, instance.blas ? blasReference(*instance.blas) : 0));
    return out;
}

VkGeometryFlagsKHR translateGeometryFlags(uint32_t flags) { return flags & dxr::kDefinedGeometryFlags; }

VkBuildAccelerationStructureFlagsKHR translateBuildFlags(uint32_t flags) {
    return flags & (dxr::BUILD_FLAG_ALLOW_UPDATE | dxr::BUILD_FLAG_ALLOW_COMPACTION | dxr::BUILD_FLAG_PREFER_FAST_TRACE |
                    dxr::BUILD_FLAG_PREFER_FAST_BUILD | dxr::BUILD_FLAG_MINIMIZE_MEMORY);
}

std::optional<VkFormat> translateVertexFormat(Format format) {
    switch (format) {
        case Format::R32G32B32_FLOAT: return VK_FORMAT_R32G32B32_SFLOAT;
        case Format::R32G32_FLOAT: return VK_FORMAT_R32G32_SFLOAT;
        case Format::R16G16B16A16_FLOAT: return VK_FORMAT_R16G16B16A16_SFLOAT;
        case Format::R16G16_FLOAT: return VK_FORMAT_R16G16_SFLOAT;
        case Format::R16G16B16A16_SNORM: return VK_FORMAT_R16G16B16A16_SNORM;
        case Format::R16G16_SNORM: return VK_FORMAT_R16G16_SNORM;
        case Format::R16G16B16A16_UNORM: return VK_FORMAT_R16G16B16A16_UNORM;
        case Format::R16G16_UNORM: return VK_FORMAT_R16G16_UNORM;
        case Format::R10G10B10A2_UNORM: return VK_FORMAT_A2B10G10R10_UNORM_PACK32;
        case Format::R8G8B8A8_UNORM: return VK_FORMAT_R8G8B8A8_UNORM;
        case Format::R8G8_UNORM: return VK_FORMAT_R8G8_UNORM;
        case Format::R8G8B8A8_SNORM: return VK_FORMAT_R8G8B8A8_SNORM;
        case Format::R8G8_SNORM: return VK_FORMAT_R8G8_SNORM;
        default: return std::nullopt;
    }
}

VkIndexType translateIndexFormat(Format format) {
    switch (format) {
        case Format::R16_UINT: return VK_INDEX_TYPE_UINT16;
        case Format::R32_UINT: return VK_INDEX_TYPE_UINT32;
        default: return VK_INDEX_TYPE_NONE_KHR;
    }
}

namespace {

uint64_t alignUp(uint64_t v, uint64_t a) { return (v + a - 1) / a * a; }

// Build results of one stage become visible to the next build and to the ray-tracing shaders.
void accelerationStructureBarrier(const VulkanFunctions& f, VkCommandBuffer commands) {
    auto barrier = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    f.vkCmdPipelineBarrier(commands,
                           VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR |
                               VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
                           0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace

AccelerationStructures::AccelerationStructures(const VulkanContext& context, AddressMap& addresses,
                                               const dxr::Device& device, dxr::GpuVirtualAddress tlasAddress)
    : context_(context) {
    const dxr::TopLevelAS* tlas = device.findTopLevelAS(tlasAddress);
    REFRAY_CHECK(tlas, "the TLAS at GPU address 0x" << std::hex << tlasAddress << std::dec
                                                     << " was not built on this device");

    // BLASes, from their DXR build inputs.
    for (const dxr::BuiltInstance& instance : tlas->instances()) {
        if (!instance.blas || bottomLevel_.count(instance.blas)) continue;
        const dxr::BottomLevelInputs& inputs = instance.blas->inputs();
        std::vector<VkAccelerationStructureGeometryKHR> geometries;
        std::vector<uint32_t> counts;
        std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
        for (size_t g = 0; g < inputs.GeometryDescs.size(); ++g) {
            const dxr::GeometryDesc& desc = inputs.GeometryDescs[g];
            const std::string where = "BLAS at 0x" + [&] {
                std::ostringstream s;
                s << std::hex << instance.blas->address();
                return s.str();
            }() + " geometry " + std::to_string(g);
            auto geometry = vkStruct<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
            geometry.flags = translateGeometryFlags(desc.Flags);
            uint32_t primitives = 0;
            if (desc.Type == dxr::GeometryType::Triangles) {
                const dxr::GeometryTrianglesDesc& t = desc.Triangles;
                const std::optional<VkFormat> format = translateVertexFormat(t.VertexFormat);
                REFRAY_CHECK(format, where << ": vertex format " << dxr::toString(t.VertexFormat)
                                           << " has no Vulkan acceleration-structure format");
                const VkIndexType indexType = translateIndexFormat(t.IndexFormat);
                primitives = (indexType == VK_INDEX_TYPE_NONE_KHR ? t.VertexCount : t.IndexCount) / 3;
                geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
                VkAccelerationStructureGeometryTrianglesDataKHR& data = geometry.geometry.triangles;
                data.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
                data.vertexFormat = *format;
                data.vertexStride = t.VertexBuffer.StrideInBytes;
                data.maxVertex = t.VertexCount ? t.VertexCount - 1 : 0;
                data.indexType = indexType;
                if (primitives > 0) {
                    data.vertexData.deviceAddress =
                        addresses.translate(t.VertexBuffer.StartAddress, 1, where + " vertex buffer");
                    if (indexType != VK_INDEX_TYPE_NONE_KHR)
                        data.indexData.deviceAddress = addresses.translate(
                            t.IndexBuffer, uint64_t(t.IndexCount) * (indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4),
                            where + " index buffer");
                }
                if (t.Transform3x4)
                    data.transformData.deviceAddress = addresses.translate(t.Transform3x4, 48, where + " Transform3x4");
            } else {
                const dxr::GeometryAABBsDesc& a = desc.AABBs;
                primitives = uint32_t(a.AABBCount);
                geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
                VkAccelerationStructureGeometryAabbsDataKHR& data = geometry.geometry.aabbs;
                data.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
                data.stride = a.AABBs.StrideInBytes;
                if (primitives > 0) data.data.deviceAddress = addresses.translate(a.AABBs.StartAddress, 24, where + " AABBs");
            }
            geometries.push_back(geometry);
            counts.push_back(primitives);
            ranges.push_back({primitives, 0, 0, 0});
        }
        auto info = vkStruct<VkAccelerationStructureBuildGeometryInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR);
        info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
        info.flags = translateBuildFlags(instance.blas->buildFlags());
        info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
        info.geometryCount = uint32_t(geometries.size());
        info.pGeometries = geometries.data();
        bottomLevel_.emplace(instance.blas, build(info, counts, ranges));
    }

    // The TLAS over the translated instance descs.
    const std::vector<VkAccelerationStructureInstanceKHR> instances = translateInstances(
        *tlas, [&](const dxr::BottomLevelAS& blas) { return uint64_t(bottomLevel_.at(&blas).address); });
    const uint32_t count = uint32_t(instances.size());
    if (count > 0)
        instances_ = uploadBuffer(context, instances.data(), instances.size() * sizeof instances[0],
                                  VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    auto geometry = vkStruct<VkAccelerationStructureGeometryKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR);
    geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    geometry.geometry.instances.arrayOfPointers = VK_FALSE;
    geometry.geometry.instances.data.deviceAddress = count ? instances_.address() : 0;
    auto info = vkStruct<VkAccelerationStructureBuildGeometryInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR);
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = 1;
    info.pGeometries = &geometry;
    topLevel_ = build(info, {count}, {{count, 0, 0, 0}});
}

AccelerationStructures::Built AccelerationStructures::build(const VkAccelerationStructureBuildGeometryInfoKHR& buildInfo,
                                                            const std::vector<uint32_t>& primitiveCounts,
                                                            const std::vector<VkAccelerationStructureBuildRangeInfoKHR>& ranges) {
    const VulkanFunctions& f = context_.vk();
    VkAccelerationStructureBuildGeometryInfoKHR info = buildInfo;
    auto sizes = vkStruct<VkAccelerationStructureBuildSizesInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR);
    f.vkGetAccelerationStructureBuildSizesKHR(context_.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                              primitiveCounts.data(), &sizes);

    Built built;
    built.storage = Buffer(context_, std::max<VkDeviceSize>(sizes.accelerationStructureSize, 256),
                           VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, MemoryLocation::Device);
    auto create = vkStruct<VkAccelerationStructureCreateInfoKHR>(VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR);
    create.buffer = built.storage.handle();
    create.size = sizes.accelerationStructureSize;
    create.type = info.type;
    REFRAY_VK(f.vkCreateAccelerationStructureKHR(context_.device(), &create, nullptr, &built.handle));
    auto addressInfo = vkStruct<VkAccelerationStructureDeviceAddressInfoKHR>(
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR);
    addressInfo.accelerationStructure = built.handle;
    built.address = f.vkGetAccelerationStructureDeviceAddressKHR(context_.device(), &addressInfo);

    const uint64_t alignment = std::max<uint64_t>(context_.limits().minAccelerationStructureScratchOffsetAlignment, 1);
    Buffer scratch(context_, sizes.buildScratchSize + alignment, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryLocation::Device);
    info.dstAccelerationStructure = built.handle;
    info.scratchData.deviceAddress = alignUp(scratch.address(), alignment);
    const VkAccelerationStructureBuildRangeInfoKHR* rangePointer = ranges.data();
    context_.submitAndWait([&](VkCommandBuffer commands) {
        accelerationStructureBarrier(f, commands);
        f.vkCmdBuildAccelerationStructuresKHR(commands, 1, &info, &rangePointer);
        accelerationStructureBarrier(f, commands);
    });
    return built;
}

AccelerationStructures::~AccelerationStructures() {
    const VulkanFunctions& f = context_.vk();
    if (topLevel_.handle) f.vkDestroyAccelerationStructureKHR(context_.device(), topLevel_.handle, nullptr);
    for (auto& [blas, built] : bottomLevel_)
        if (built.handle) f.vkDestroyAccelerationStructureKHR(context_.device(), built.handle, nullptr);
}

}  // namespace refray::gpu
