#include "gpu/vulkan_dispatch.h"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>

#include "gpu/vulkan_acceleration_structure.h"
#include "gpu/vulkan_bindings.h"
#include "gpu/vulkan_descriptor_sets.h"
#include "gpu/vulkan_memory.h"
#include "gpu/vulkan_pipeline.h"
#include "gpu/vulkan_sampler.h"
#include "gpu/vulkan_shader_table.h"
#include "gpu/vulkan_texture.h"

namespace refray::gpu {

namespace {

// The AOV output buffer: set 0, binding 1000 (above every register binding of CONTRACT.md), five uint32 per
// launch index: record, InstanceIndex, InstanceID, GeometryIndex, PrimitiveIndex.
constexpr uint32_t kAovBinding = 1000;
constexpr uint32_t kAovValuesPerPixel = 5;

uint64_t alignUp(uint64_t v, uint64_t a) { return a ? (v + a - 1) / a * a : v; }

VkStridedDeviceAddressRegionKHR region(VkDeviceAddress base, const ShaderTableRegion& r) {
    if (r.size == 0) return {0, 0, 0};
    return {base + r.offset, r.stride, r.size};
}

}  // namespace

std::filesystem::path defaultSpirvDirectory(const std::filesystem::path& executable) {
    if (const char* env = std::getenv("REFRAY_SPIRV_DIR"); env && *env) return env;
    const std::filesystem::path dir = executable.parent_path();
    const std::filesystem::path buildTree = dir / ".." / "gpu" / "shaders";
    for (const std::filesystem::path& candidate : {buildTree, dir / "shaders"}) {
        std::error_code ec;
        if (std::filesystem::is_directory(candidate, ec)) return candidate.lexically_normal();
    }
    return buildTree.lexically_normal();
}

VulkanBackend::VulkanBackend(VulkanBackendOptions options)
    : options_(std::move(options)), context_(std::make_unique<VulkanContext>([&] {
          VulkanContextOptions context;
          context.device = options_.device;
          return context;
      }())) {}

VulkanBackend::~VulkanBackend() = default;

dxr::DispatchResult VulkanBackend::dispatchRays(dxr::Device& device, const dxr::DispatchRaysDesc& desc,
                                                const dxr::StateObjectPtr& pipeline,
                                                const dxr::GlobalRootArguments* globals,
                                                const dxr::DispatchOptions& options) {
    REFRAY_CHECK(!options.region, "the Vulkan back end renders whole dispatches; a launch region (refray explain) is "
                                  "the emulator's");
    REFRAY_CHECK(!options.observer, "the Vulkan back end records no trace events (refray explain, --aov on the "
                                    "emulator); they are the emulator's");
    REFRAY_CHECK(options.order == dxr::TraversalOrder::Ordered,
                 "--order adversarial is the emulator's; the GPU traverses in its own order");
    return run(device, desc, pipeline, globals, nullptr);
}

AovPixels VulkanBackend::dispatchAov(dxr::Device& device, const dxr::DispatchRaysDesc& desc,
                                     const dxr::StateObjectPtr& pipeline, const dxr::GlobalRootArguments* globals) {
    AovPixels aov;
    run(device, desc, pipeline, globals, &aov);
    return aov;
}

dxr::DispatchResult VulkanBackend::run(dxr::Device& device, const dxr::DispatchRaysDesc& desc,
                                       const dxr::StateObjectPtr& stateObject, const dxr::GlobalRootArguments* globals,
                                       AovPixels* aov) {
    const VulkanContext& context = *context_;
    const VulkanFunctions& f = context.vk();
    const RayTracingLimits& limits = context.limits();
    REFRAY_CHECK(stateObject, "DispatchRays on the Vulkan back end needs a state object");
    REFRAY_CHECK(globals, "the Vulkan back end needs the global root arguments (the render target, the TLAS, ...)");
    REFRAY_CHECK(desc.Width > 0 && desc.Height > 0 && desc.Depth > 0,
                 "DispatchRays of " << desc.Width << "x" << desc.Height << "x" << desc.Depth << " threads");

    // Global root arguments -> resources.
    const std::vector<DescriptorBinding> bindings = translateGlobalBindings(*globals, device);
    AddressMap addresses(context, device.memory());
    std::map<dxr::GpuVirtualAddress, std::unique_ptr<AccelerationStructures>> tlases;
    std::map<Image*, std::unique_ptr<StorageImage>> images;
    // One upload per texture (an unbounded range may reach into the next table's textures) and per sampler.
    std::map<const dxr::Texture2D*, std::unique_ptr<SampledTexture>> textures;
    std::vector<std::unique_ptr<Sampler>> samplers;
    Buffer nullBuffer;
    std::vector<DescriptorWrite> writes;
    for (const DescriptorBinding& b : bindings) {
        DescriptorWrite w;
        w.set = b.set;
        w.binding = b.binding;
        w.type = b.type;
        switch (b.resource) {
            case DescriptorBinding::Resource::AccelerationStructure: {
                auto& built = tlases[b.address];
                if (!built) built = std::make_unique<AccelerationStructures>(context, addresses, device, b.address);
                w.accelerationStructure = built->topLevel();
                break;
            }
            case DescriptorBinding::Resource::StorageImage: {
                auto& image = images[b.image];
                if (!image) {
                    image = std::make_unique<StorageImage>(context, b.image->width(), b.image->height());
                    image->upload(*b.image);
                }
                w.imageView = image->view();
                break;
            }
            case DescriptorBinding::Resource::SampledImages: {
                REFRAY_CHECK(!b.runtimeArray || limits.sampledImageArrays,
                             b.what << " is an unbounded texture array; the device lacks what such arrays need "
                                       "(runtimeDescriptorArray, shaderSampledImageArrayNonUniformIndexing, "
                                       "shaderSampledImageArrayDynamicIndexing)");
                for (const dxr::Texture2D* texture : b.textures) {
                    auto& uploaded = textures[texture];
                    if (!uploaded) uploaded = std::make_unique<SampledTexture>(context, texture, b.what);
                    w.sampledImages.push_back(uploaded->view());
                }
                break;
            }
            case DescriptorBinding::Resource::Sampler:
                samplers.push_back(std::make_unique<Sampler>(context, b.sampler, b.what));
                w.sampler = samplers.back()->handle();
                w.immutableSampler = b.staticSampler;
                break;
            case DescriptorBinding::Resource::NullBuffer: {
                if (!nullBuffer.handle()) {
                    const std::vector<uint8_t> zeros(256, 0);
                    nullBuffer = uploadBuffer(context, zeros.data(), zeros.size(), kEmulatorBufferUsage);
                }
                w.buffer = {nullBuffer.handle(), 0, VK_WHOLE_SIZE};
                break;
            }
            case DescriptorBinding::Resource::Buffer: {
                const AddressMap::Resolved r = addresses.resolve(b.address, b.size, b.what);
                VkDeviceSize range = b.size ? std::min<VkDeviceSize>(b.size, r.bytesToEnd) : r.bytesToEnd;
                if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER)
                    range = std::min<VkDeviceSize>(range, limits.maxUniformBufferRange);
                w.buffer = {r.buffer, r.offset, range};
                break;
            }
        }
        writes.push_back(w);
    }
    Buffer aovBuffer;
    const uint64_t launches = uint64_t(desc.Width) * desc.Height * desc.Depth;
    if (aov) {
        aovBuffer = Buffer(context, launches * kAovValuesPerPixel * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                           MemoryLocation::Host);
        std::memset(aovBuffer.mapped(), 0xFF, aovBuffer.size());
        DescriptorWrite w;
        w.binding = kAovBinding;
        w.buffer = {aovBuffer.handle(), 0, VK_WHOLE_SIZE};
        writes.push_back(w);
    }
    DescriptorSets sets(context, writes);

    // The pipeline, one group per state-object entry.
    std::optional<AovShaders> aovShaders;
    ShaderTableTranslation translation;
    translation.baseAlignment = limits.shaderGroupBaseAlignment;
    translation.handleAlignment = limits.shaderGroupHandleAlignment;
    translation.appendHitGroupRecordIndex = aov != nullptr;
    translation.deviceAddress = [&](uint64_t address, std::string_view what) { return addresses.translate(address, 8, what); };
    // AOV: the record index sits right after the DXR stride's bytes (vulkan_shader_table.h).
    uint32_t recordIndexOffset = 0;
    if (aov) {
        recordIndexOffset = desc.HitGroupTable.StrideInBytes >= 32 ? uint32_t(desc.HitGroupTable.StrideInBytes - 32) : 0;
        aovShaders = AovShaders{options_.spirvDirectory / "aov" / "ClosestHit_AOV.rchit.spv",
                                options_.spirvDirectory / "aov" / "Miss_AOV.rmiss.spv", recordIndexOffset};
    }
    const PipelineShape shape =
        describePipeline(*stateObject, options_.spirvDirectory, options_.library, aovShaders ? &*aovShaders : nullptr);
    REFRAY_CHECK(!options_.traceRay.empty(),
                 "the Vulkan back end was given no TraceRay arguments for the " << options_.library
                     << " shaders' ray types (VulkanBackendOptions::traceRay); the GLSL ports read them as "
                        "specialization constants");
    RayTracingPipeline rayTracingPipeline(context, shape, sets.pipelineLayout(), options_.traceRay, recordIndexOffset);

    // The shader binding table, in device memory at a shaderGroupBaseAlignment-aligned address.
    translation.groupHandle = [&](uint32_t entry) { return rayTracingPipeline.groupHandles().at(entry); };
    const TranslatedShaderTables tables = translateShaderTables(desc, *stateObject, device.memory(), translation);
    REFRAY_CHECK(tables.miss.stride <= limits.maxShaderGroupStride && tables.hitGroup.stride <= limits.maxShaderGroupStride &&
                     tables.callable.stride <= limits.maxShaderGroupStride,
                 "a shader table stride is larger than the device's maxShaderGroupStride " << limits.maxShaderGroupStride);
    const uint64_t baseAlignment = std::max<uint64_t>(limits.shaderGroupBaseAlignment, 1);
    Buffer sbt(context, tables.bytes.size() + baseAlignment,
               VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryLocation::Device);
    const VkDeviceAddress sbtBase = alignUp(sbt.address(), baseAlignment);
    {
        Buffer staging(context, tables.bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryLocation::Host);
        std::memcpy(staging.mapped(), tables.bytes.data(), tables.bytes.size());
        context.submitAndWait([&](VkCommandBuffer commands) {
            const VkBufferCopy copy{0, sbtBase - sbt.address(), tables.bytes.size()};
            f.vkCmdCopyBuffer(commands, staging.handle(), sbt.handle(), 1, &copy);
        });
    }
    const VkStridedDeviceAddressRegionKHR rayGen = region(sbtBase, tables.rayGeneration);
    const VkStridedDeviceAddressRegionKHR miss = region(sbtBase, tables.miss);
    const VkStridedDeviceAddressRegionKHR hit = region(sbtBase, tables.hitGroup);
    const VkStridedDeviceAddressRegionKHR callable = region(sbtBase, tables.callable);

    // Trace, timed with two timestamps where the queue has them.
    VkQueryPool queries = VK_NULL_HANDLE;
    if (limits.timestampPeriod > 0.0f) {
        auto info = vkStruct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
        info.queryType = VK_QUERY_TYPE_TIMESTAMP;
        info.queryCount = 2;
        REFRAY_VK(f.vkCreateQueryPool(context.device(), &info, nullptr, &queries));
    }
    const auto traceStarted = std::chrono::steady_clock::now();
    try {
        context.submitAndWait([&](VkCommandBuffer commands) {
            auto barrier = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
            barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR |
                                    VK_ACCESS_HOST_WRITE_BIT;
            barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                                    VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
            f.vkCmdPipelineBarrier(commands,
                                   VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR |
                                       VK_PIPELINE_STAGE_HOST_BIT,
                                   VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0, nullptr);
            f.vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, rayTracingPipeline.handle());
            if (!sets.sets().empty())
                f.vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, sets.pipelineLayout(), 0,
                                          uint32_t(sets.sets().size()), sets.sets().data(), 0, nullptr);
            if (queries) {
                f.vkCmdResetQueryPool(commands, queries, 0, 2);
                f.vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
            }
            f.vkCmdTraceRaysKHR(commands, &rayGen, &miss, &hit, &callable, desc.Width, desc.Height, desc.Depth);
            if (queries) f.vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
            auto after = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
            after.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            after.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
            f.vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
                                   VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &after, 0, nullptr,
                                   0, nullptr);
        });
    } catch (...) {
        if (queries) f.vkDestroyQueryPool(context.device(), queries, nullptr);
        throw;
    }
    const double wallTrace = std::chrono::duration<double>(std::chrono::steady_clock::now() - traceStarted).count();
    dxr::DispatchResult result;
    result.seconds = wallTrace;
    if (queries) {
        uint64_t ticks[2] = {0, 0};
        const VkResult r = f.vkGetQueryPoolResults(context.device(), queries, 0, 2, sizeof ticks, ticks, sizeof ticks[0],
                                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
        if (r == VK_SUCCESS && ticks[1] >= ticks[0])
            result.seconds = double(ticks[1] - ticks[0]) * double(limits.timestampPeriod) * 1e-9;
        f.vkDestroyQueryPool(context.device(), queries, nullptr);
    }

    // Read back: every render target, and the AOV values.
    for (auto& [image, storage] : images) storage->download(*image);
    if (aov) {
        aov->width = desc.Width;
        aov->height = desc.Height * desc.Depth;
        std::vector<uint32_t> values(launches * kAovValuesPerPixel);
        std::memcpy(values.data(), aovBuffer.mapped(), values.size() * 4);
        std::vector<uint32_t>* columns[kAovValuesPerPixel] = {&aov->record, &aov->instanceIndex, &aov->instanceID,
                                                             &aov->geometryIndex, &aov->primitiveIndex};
        for (uint32_t k = 0; k < kAovValuesPerPixel; ++k) {
            columns[k]->resize(launches);
            for (uint64_t i = 0; i < launches; ++i) (*columns[k])[i] = values[i * kAovValuesPerPixel + k];
        }
    }
    return result;
}

}  // namespace refray::gpu
