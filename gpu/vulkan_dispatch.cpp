#include "gpu/vulkan_dispatch.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <functional>
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

// The emulator's options that the GPU cannot honour.
void checkDispatchOptions(const dxr::DispatchOptions& options) {
    REFRAY_CHECK(!options.region, "the Vulkan back end renders whole dispatches; a launch region (refray explain) is "
                                  "the emulator's");
    REFRAY_CHECK(!options.observer, "the Vulkan back end records no trace events (refray explain, --aov on the "
                                    "emulator); they are the emulator's");
    REFRAY_CHECK(options.order == dxr::TraversalOrder::Ordered,
                 "--order adversarial is the emulator's; the GPU traverses in its own order");
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
    checkDispatchOptions(options);
    return run(device, desc, pipeline, globals, nullptr);
}


ComputeDispatch VulkanBackend::computeDispatchOf(const dxr::DispatchDesc& desc,
                                                 const dxr::StateObjectPtr& pipeline) const {
    REFRAY_CHECK(pipeline, "Dispatch on the Vulkan back end needs a state object");
    const dxr::ShaderExport* shader = pipeline->findComputeShader(desc.ComputeShader);
    REFRAY_CHECK(shader, "Dispatch: state object '" << pipeline->name() << "' has no compute shader '"
                                                    << desc.ComputeShader << "'");
    ComputeDispatch out;
    out.exportName = shader->name;
    out.numThreads = {shader->numThreads.x, shader->numThreads.y, shader->numThreads.z};
    out.groups = {desc.ThreadGroupCountX, desc.ThreadGroupCountY, desc.ThreadGroupCountZ};
    return out;
}

dxr::DispatchResult VulkanBackend::dispatch(dxr::Device& device, const dxr::DispatchDesc& desc,
                                            const dxr::StateObjectPtr& pipeline, const dxr::GlobalRootArguments* globals,
                                            const dxr::DispatchOptions& options) {
    checkDispatchOptions(options);
    return dispatchCompute(device, computeDispatchOf(desc, pipeline), globals);
}

AovPixels VulkanBackend::dispatchAov(dxr::Device& device, const dxr::DispatchDesc& desc,
                                     const dxr::StateObjectPtr& pipeline, const dxr::GlobalRootArguments* globals) {
    return dispatchComputeAov(device, computeDispatchOf(desc, pipeline), globals);
}

AovPixels VulkanBackend::dispatchAov(dxr::Device& device, const dxr::DispatchRaysDesc& desc,
                                     const dxr::StateObjectPtr& pipeline, const dxr::GlobalRootArguments* globals) {
    AovPixels aov;
    run(device, desc, pipeline, globals, &aov);
    return aov;
}

// The global root arguments on the device: every resource they name, uploaded, and the descriptor sets that bind
// them (with the AOV buffer at set 0, binding 1000, when one is asked for). Shared by DispatchRays and Dispatch.
struct VulkanBackend::BoundGlobals {
    BoundGlobals(const VulkanContext& context, const dxr::GpuMemory& memory) : addresses(context, memory) {}
    AddressMap addresses;
    std::map<dxr::GpuVirtualAddress, std::unique_ptr<AccelerationStructures>> tlases;
    std::map<Image*, std::unique_ptr<StorageImage>> images;
    // One upload per texture (an unbounded range may reach into the next table's textures) and per sampler.
    std::map<const dxr::Texture2D*, std::unique_ptr<SampledTexture>> textures;
    std::vector<std::unique_ptr<Sampler>> samplers;
    Buffer nullBuffer;
    Buffer aovBuffer;  // host-visible, filled with kAovMiss
    std::unique_ptr<DescriptorSets> sets;
};

std::unique_ptr<VulkanBackend::BoundGlobals> VulkanBackend::bindGlobals(dxr::Device& device,
                                                                        const dxr::GlobalRootArguments& globals,
                                                                        uint64_t aovValues) const {
    const VulkanContext& context = *context_;
    const RayTracingLimits& limits = context.limits();
    const std::vector<DescriptorBinding> bindings = translateGlobalBindings(globals, device);
    auto bound = std::make_unique<BoundGlobals>(context, device.memory());
    std::vector<DescriptorWrite> writes;
    for (const DescriptorBinding& b : bindings) {
        DescriptorWrite w;
        w.set = b.set;
        w.binding = b.binding;
        w.type = b.type;
        switch (b.resource) {
            case DescriptorBinding::Resource::AccelerationStructure: {
                auto& built = bound->tlases[b.address];
                if (!built) built = std::make_unique<AccelerationStructures>(context, bound->addresses, device, b.address);
                w.accelerationStructure = built->topLevel();
                break;
            }
            case DescriptorBinding::Resource::StorageImage: {
                auto& image = bound->images[b.image];
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
                    auto& uploaded = bound->textures[texture];
                    if (!uploaded) uploaded = std::make_unique<SampledTexture>(context, texture, b.what);
                    w.sampledImages.push_back(uploaded->view());
                }
                break;
            }
            case DescriptorBinding::Resource::Sampler:
                bound->samplers.push_back(std::make_unique<Sampler>(context, b.sampler, b.what));
                w.sampler = bound->samplers.back()->handle();
                w.immutableSampler = b.staticSampler;
                break;
            case DescriptorBinding::Resource::NullBuffer: {
                if (!bound->nullBuffer.handle()) {
                    const std::vector<uint8_t> zeros(256, 0);
                    bound->nullBuffer = uploadBuffer(context, zeros.data(), zeros.size(), kEmulatorBufferUsage);
                }
                w.buffer = {bound->nullBuffer.handle(), 0, VK_WHOLE_SIZE};
                break;
            }
            case DescriptorBinding::Resource::Buffer: {
                const AddressMap::Resolved r = bound->addresses.resolve(b.address, b.size, b.what);
                VkDeviceSize range = b.size ? std::min<VkDeviceSize>(b.size, r.bytesToEnd) : r.bytesToEnd;
                if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER)
                    range = std::min<VkDeviceSize>(range, limits.maxUniformBufferRange);
                w.buffer = {r.buffer, r.offset, range};
                break;
            }
        }
        writes.push_back(w);
    }
    if (aovValues > 0) {
        bound->aovBuffer = Buffer(context, aovValues * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryLocation::Host);
        std::memset(bound->aovBuffer.mapped(), 0xFF, bound->aovBuffer.size());
        DescriptorWrite w;
        w.binding = kAovBinding;
        w.buffer = {bound->aovBuffer.handle(), 0, VK_WHOLE_SIZE};
        writes.push_back(w);
    }
    bound->sets = std::make_unique<DescriptorSets>(context, writes);
    return bound;
}

namespace {

// Records `work` between two timestamps where the queue has them, with the barriers that order it after the uploads
// and AS builds and before the read-back; submits and waits. Returns the GPU time of `work` (the wall time of the
// submission where the queue has no timestamps).
double submitTimed(const VulkanContext& context, VkPipelineStageFlags shaderStages,
                   const std::function<void(VkCommandBuffer)>& work) {
    const VulkanFunctions& f = context.vk();
    const RayTracingLimits& limits = context.limits();
    VkQueryPool queries = VK_NULL_HANDLE;
    if (limits.timestampPeriod > 0.0f) {
        auto info = vkStruct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
        info.queryType = VK_QUERY_TYPE_TIMESTAMP;
        info.queryCount = 2;
        REFRAY_VK(f.vkCreateQueryPool(context.device(), &info, nullptr, &queries));
    }
    const auto started = std::chrono::steady_clock::now();
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
                                   shaderStages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
            if (queries) {
                f.vkCmdResetQueryPool(commands, queries, 0, 2);
                f.vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
            }
            work(commands);
            if (queries) f.vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
            auto after = vkStruct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
            after.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            after.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
            f.vkCmdPipelineBarrier(commands, shaderStages, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0,
                                   1, &after, 0, nullptr, 0, nullptr);
        });
    } catch (...) {
        if (queries) f.vkDestroyQueryPool(context.device(), queries, nullptr);
        throw;
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (queries) {
        uint64_t ticks[2] = {0, 0};
        const VkResult r = f.vkGetQueryPoolResults(context.device(), queries, 0, 2, sizeof ticks, ticks, sizeof ticks[0],
                                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
        if (r == VK_SUCCESS && ticks[1] >= ticks[0])
            seconds = double(ticks[1] - ticks[0]) * double(limits.timestampPeriod) * 1e-9;
        f.vkDestroyQueryPool(context.device(), queries, nullptr);
    }
    return seconds;
}

// The AOV buffer's values (kAovValuesPerPixel per launch) as the five maps of `aov`.
void readAov(const Buffer& buffer, uint64_t launches, AovPixels& aov) {
    std::vector<uint32_t> values(launches * kAovValuesPerPixel);
    std::memcpy(values.data(), buffer.mapped(), values.size() * 4);
    std::vector<uint32_t>* columns[kAovValuesPerPixel] = {&aov.record, &aov.instanceIndex, &aov.instanceID,
                                                         &aov.geometryIndex, &aov.primitiveIndex};
    for (uint32_t k = 0; k < kAovValuesPerPixel; ++k) {
        columns[k]->resize(launches);
        for (uint64_t i = 0; i < launches; ++i) (*columns[k])[i] = values[i * kAovValuesPerPixel + k];
    }
}

}  // namespace

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

    // The pipeline's shape, one group per state-object entry; every module is read and checked against the device
    // first, so a shader the device cannot run (ray queries) is refused before any upload.
    std::optional<AovShaders> aovShaders;
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
    for (const PipelineStage& stage : shape.stages) {
        const std::string_view extension = stageExtension(stage.stage);
        requireDeviceSupport(context, inspectSpirv(readSpirvModule(stage.spirv, stage.exportName, extension),
                                                   stage.spirv.string()),
                             stage.exportName, extension, stage.spirv);
    }

    // Global root arguments -> resources and descriptor sets.
    const uint64_t launches = uint64_t(desc.Width) * desc.Height * desc.Depth;
    const std::unique_ptr<BoundGlobals> bound = bindGlobals(device, *globals, aov ? launches * kAovValuesPerPixel : 0);

    ShaderTableTranslation translation;
    translation.baseAlignment = limits.shaderGroupBaseAlignment;
    translation.handleAlignment = limits.shaderGroupHandleAlignment;
    translation.appendHitGroupRecordIndex = aov != nullptr;
    translation.deviceAddress = [&](uint64_t address, std::string_view what) {
        return bound->addresses.translate(address, 8, what);
    };
    RayTracingPipeline rayTracingPipeline(context, shape, bound->sets->pipelineLayout(), options_.traceRay,
                                          recordIndexOffset);

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

    // Trace.
    const DescriptorSets& sets = *bound->sets;
    dxr::DispatchResult result;
    result.seconds = submitTimed(context, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, [&](VkCommandBuffer commands) {
        f.vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, rayTracingPipeline.handle());
        if (!sets.sets().empty())
            f.vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, sets.pipelineLayout(), 0,
                                      uint32_t(sets.sets().size()), sets.sets().data(), 0, nullptr);
        f.vkCmdTraceRaysKHR(commands, &rayGen, &miss, &hit, &callable, desc.Width, desc.Height, desc.Depth);
    });

    // Read back: every render target, and the AOV values.
    for (auto& [image, storage] : bound->images) storage->download(*image);
    if (aov) {
        aov->width = desc.Width;
        aov->height = desc.Height * desc.Depth;
        aov->inlineQuery = false;
        readAov(bound->aovBuffer, launches, *aov);
    }
    return result;
}

dxr::DispatchResult VulkanBackend::dispatchCompute(dxr::Device& device, const ComputeDispatch& dispatch,
                                                   const dxr::GlobalRootArguments* globals) {
    return runCompute(device, dispatch, globals, nullptr);
}

AovPixels VulkanBackend::dispatchComputeAov(dxr::Device& device, const ComputeDispatch& dispatch,
                                            const dxr::GlobalRootArguments* globals) {
    AovPixels aov;
    runCompute(device, dispatch, globals, &aov);
    return aov;
}

dxr::DispatchResult VulkanBackend::runCompute(dxr::Device& device, const ComputeDispatch& dispatch,
                                              const dxr::GlobalRootArguments* globals, AovPixels* aov) {
    const VulkanContext& context = *context_;
    const VulkanFunctions& f = context.vk();
    const RayTracingLimits& limits = context.limits();
    REFRAY_CHECK(globals, "the Vulkan back end needs the global root arguments (the render target, the TLAS, ...)");
    for (int axis = 0; axis < 3; ++axis) {
        REFRAY_CHECK(dispatch.groups[axis] > 0 && dispatch.numThreads[axis] > 0,
                     "Dispatch of " << dispatch.groups[0] << "x" << dispatch.groups[1] << "x" << dispatch.groups[2]
                                    << " thread groups of " << dispatch.numThreads[0] << "x" << dispatch.numThreads[1]
                                    << "x" << dispatch.numThreads[2] << " threads ('" << dispatch.exportName << "')");
        REFRAY_CHECK(dispatch.groups[axis] <= limits.maxComputeWorkGroupCount[axis],
                     "Dispatch of " << dispatch.groups[0] << "x" << dispatch.groups[1] << "x" << dispatch.groups[2]
                                    << " thread groups: the device '" << context.info().name
                                    << "' allows at most " << limits.maxComputeWorkGroupCount[axis] << " along "
                                    << "XYZ"[axis]);
    }

    // The compute pipeline first: a shader the device cannot run (ray queries) is refused before any upload.
    const std::filesystem::path spirv =
        computeSpirvPath(options_.spirvDirectory, options_.library, dispatch.exportName, aov != nullptr);
    ComputeShaderModule module(context, spirv, dispatch.exportName, dispatch.numThreads);

    const uint64_t threads = uint64_t(dispatch.groups[0]) * dispatch.numThreads[0] * dispatch.groups[1] *
                             dispatch.numThreads[1] * dispatch.groups[2] * dispatch.numThreads[2];
    const std::unique_ptr<BoundGlobals> bound = bindGlobals(device, *globals, aov ? threads * kAovValuesPerPixel : 0);
    ComputePipeline pipeline(context, module, bound->sets->pipelineLayout(), options_.traceRay);

    const DescriptorSets& sets = *bound->sets;
    dxr::DispatchResult result;
    result.seconds = submitTimed(context, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, [&](VkCommandBuffer commands) {
        f.vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.handle());
        if (!sets.sets().empty())
            f.vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, sets.pipelineLayout(), 0,
                                      uint32_t(sets.sets().size()), sets.sets().data(), 0, nullptr);
        f.vkCmdDispatch(commands, dispatch.groups[0], dispatch.groups[1], dispatch.groups[2]);
    });

    for (auto& [image, storage] : bound->images) storage->download(*image);
    if (aov) {
        aov->width = dispatch.groups[0] * dispatch.numThreads[0];
        aov->height = dispatch.groups[1] * dispatch.numThreads[1] * dispatch.groups[2] * dispatch.numThreads[2];
        aov->inlineQuery = true;
        readAov(bound->aovBuffer, threads, *aov);
        // Thread (x, y) is pixel (x, y): with one render target, the grid is cropped to it (the threads past its
        // edge return without tracing).
        if (bound->images.size() == 1) {
            const Image& target = *bound->images.begin()->first;
            const uint32_t planeHeight = dispatch.groups[1] * dispatch.numThreads[1];
            if (target.width() <= aov->width && target.height() <= planeHeight) {
                for (std::vector<uint32_t>* column : {&aov->record, &aov->instanceIndex, &aov->instanceID,
                                                      &aov->geometryIndex, &aov->primitiveIndex}) {
                    std::vector<uint32_t> cropped(size_t(target.width()) * target.height());
                    for (uint32_t y = 0; y < target.height(); ++y)
                        std::copy_n(column->begin() + size_t(y) * aov->width, target.width(),
                                    cropped.begin() + size_t(y) * target.width());
                    *column = std::move(cropped);
                }
                aov->width = target.width();
                aov->height = target.height();
            }
        }
    }
    return result;
}

}  // namespace refray::gpu
