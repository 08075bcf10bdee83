#include "gpu/vulkan_pipeline.h"

#include <fstream>
#include <map>

#include "core/error.h"

namespace refray::gpu {

using dxr::ShaderStage;

std::string_view stageExtension(ShaderStage stage) {
    switch (stage) {
        case ShaderStage::RayGeneration: return "rgen";
        case ShaderStage::Intersection: return "rint";
        case ShaderStage::AnyHit: return "rahit";
        case ShaderStage::ClosestHit: return "rchit";
        case ShaderStage::Miss: return "rmiss";
        case ShaderStage::Callable: return "rcall";
        case ShaderStage::Compute: return "comp";
    }
    return "";
}

VkShaderStageFlagBits translateStage(ShaderStage stage) {
    switch (stage) {
        case ShaderStage::RayGeneration: return VK_SHADER_STAGE_RAYGEN_BIT_KHR;
        case ShaderStage::Intersection: return VK_SHADER_STAGE_INTERSECTION_BIT_KHR;
        case ShaderStage::AnyHit: return VK_SHADER_STAGE_ANY_HIT_BIT_KHR;
        case ShaderStage::ClosestHit: return VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
        case ShaderStage::Miss: return VK_SHADER_STAGE_MISS_BIT_KHR;
        case ShaderStage::Callable: return VK_SHADER_STAGE_CALLABLE_BIT_KHR;
        case ShaderStage::Compute: return VK_SHADER_STAGE_COMPUTE_BIT;
    }
    return VK_SHADER_STAGE_RAYGEN_BIT_KHR;
}

std::filesystem::path spirvPath(const std::filesystem::path& spirvDirectory, const std::string& library,
                                const std::string& exportName, ShaderStage stage) {
    return spirvDirectory / library / (exportName + "." + std::string(stageExtension(stage)) + ".spv");
}

PipelineShape describePipeline(const dxr::StateObject& stateObject, const std::filesystem::path& spirvDirectory,
                               const std::string& library, const AovShaders* aov) {
    PipelineShape shape;
    shape.maxRecursionDepth = stateObject.maxTraceRecursionDepth();
    shape.pipelineFlags = stateObject.pipelineFlags();
    std::map<std::string, uint32_t> stageIndex;  // by file, so each module is loaded once
    const auto stageOf = [&](const std::string& exportName, ShaderStage stage, std::filesystem::path file,
                             bool aovClosestHit = false) {
        const std::string key = file.string();
        if (auto it = stageIndex.find(key); it != stageIndex.end()) return it->second;
        const uint32_t index = uint32_t(shape.stages.size());
        shape.stages.push_back({exportName, stage, std::move(file), aovClosestHit});
        stageIndex.emplace(key, index);
        return index;
    };
    const auto exportStage = [&](const dxr::ShaderExport* e) {
        if (!e) return uint32_t(VK_SHADER_UNUSED_KHR);
        return stageOf(e->name, e->stage, spirvPath(spirvDirectory, library, e->name, e->stage));
    };

    for (const dxr::ProgramEntry& entry : stateObject.entries()) {
        PipelineGroup group;
        group.name = entry.name;
        switch (entry.kind) {
            case dxr::ProgramEntry::Kind::RayGeneration:
            case dxr::ProgramEntry::Kind::Callable:
                group.general = exportStage(entry.shader);
                break;
            case dxr::ProgramEntry::Kind::Miss:
                group.general = aov ? stageOf("AOV miss", ShaderStage::Miss, aov->miss) : exportStage(entry.shader);
                break;
            case dxr::ProgramEntry::Kind::HitGroup:
                group.type = entry.hitGroupType == dxr::HitGroupType::Triangles
                                 ? VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR
                                 : VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
                group.closestHit = aov ? stageOf("AOV closest hit", ShaderStage::ClosestHit, aov->closestHit, true)
                                       : exportStage(entry.closestHit);
                group.anyHit = exportStage(entry.anyHit);
                group.intersection = exportStage(entry.intersection);
                break;
        }
        shape.groups.push_back(group);
    }
    return shape;
}

std::vector<uint32_t> readSpirvModule(const std::filesystem::path& file, const std::string& exportName,
                                      std::string_view stage) {
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    REFRAY_CHECK(in, "no SPIR-V for export '" << exportName << "' (" << stage << "): expected " << file.string()
                                              << " (compiled from its GLSL port gpu/shaders/<library>/" << exportName
                                              << "." << stage
                                              << "; give --spirv-dir or REFRAY_SPIRV_DIR if the .spv files are "
                                                 "elsewhere)");
    const std::streamsize size = in.tellg();
    REFRAY_CHECK(size > 0 && size % 4 == 0,
                 file.string() << " (export '" << exportName << "') is not a SPIR-V module: " << size << " bytes");
    std::vector<uint32_t> words(size_t(size) / 4);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(words.data()), size);
    REFRAY_CHECK(words[0] == 0x07230203u,
                 file.string() << " (export '" << exportName << "') does not start with the SPIR-V magic number");
    return words;
}

SpirvFacts inspectSpirv(const std::vector<uint32_t>& words, const std::string& what) {
    // SPIR-V 1.6 section 2.3: a 5-word header, then instructions whose first word is (word count << 16) | opcode.
    constexpr uint32_t kOpExecutionMode = 16, kOpCapability = 17, kOpFunction = 54;
    constexpr uint32_t kCapabilityRayQueryKHR = 4472, kExecutionModeLocalSize = 17;
    REFRAY_CHECK(words.size() >= 5 && words[0] == 0x07230203u, what << " is not a SPIR-V module");
    SpirvFacts facts;
    for (size_t i = 5; i < words.size();) {
        const uint32_t count = words[i] >> 16, opcode = words[i] & 0xFFFFu;
        REFRAY_CHECK(count > 0 && i + count <= words.size(),
                     what << ": SPIR-V instruction at word " << i << " runs past the module's end");
        if (opcode == kOpCapability && count >= 2 && words[i + 1] == kCapabilityRayQueryKHR) facts.rayQuery = true;
        if (opcode == kOpExecutionMode && count >= 6 && words[i + 2] == kExecutionModeLocalSize)
            facts.localSize = std::array<uint32_t, 3>{words[i + 3], words[i + 4], words[i + 5]};
        if (opcode == kOpFunction) break;  // capabilities and execution modes precede every function
        i += count;
    }
    return facts;
}

std::string deviceRefusal(const DeviceInfo& device, bool deviceHasRayQuery, const SpirvFacts& facts,
                          const std::string& exportName, std::string_view stage, const std::filesystem::path& file) {
    if (!facts.rayQuery || deviceHasRayQuery) return "";
    return "export '" + exportName + "' (" + std::string(stage) + ", " + file.string() +
           ") traces inline (its SPIR-V declares the RayQueryKHR capability, GL_EXT_ray_query), but the Vulkan device " +
           std::to_string(device.index) + " '" + device.name + "' (" + device.driverName + " " + device.driverVersion +
           ") does not offer VK_KHR_ray_query with the rayQuery feature. Scenes that trace inline need a device with "
           "ray queries: 'refray devices' lists which have them (Mesa's lavapipe does: --vulkan-device llvmpipe)";
}

void requireDeviceSupport(const VulkanContext& context, const SpirvFacts& facts, const std::string& exportName,
                          std::string_view stage, const std::filesystem::path& file) {
    const std::string refusal = deviceRefusal(context.info(), context.limits().rayQuery, facts, exportName, stage, file);
    if (!refusal.empty()) throw Error(refusal);
}

std::filesystem::path computeSpirvPath(const std::filesystem::path& spirvDirectory, const std::string& library,
                                       const std::string& exportName, bool aov) {
    return spirvDirectory / library / (exportName + (aov ? ".aov.comp.spv" : ".comp.spv"));
}

ComputeShaderModule::ComputeShaderModule(const VulkanContext& context, const std::filesystem::path& file_,
                                         const std::string& exportName_, const std::array<uint32_t, 3>& numThreads)
    : file(file_), exportName(exportName_), words(readSpirvModule(file, exportName, "comp")),
      facts(inspectSpirv(words, file.string())) {
    REFRAY_CHECK(facts.localSize, file.string() << " (export '" << exportName
                                                << "') declares no LocalSize: is it a compute shader?");
    const std::array<uint32_t, 3>& local = *facts.localSize;
    REFRAY_CHECK(local == numThreads, file.string() << " (export '" << exportName << "') has local_size " << local[0]
                                                    << "x" << local[1] << "x" << local[2]
                                                    << ", but the export's [numthreads] is " << numThreads[0] << "x"
                                                    << numThreads[1] << "x" << numThreads[2]);
    requireDeviceSupport(context, facts, exportName, "comp", file);
}

ComputePipeline::ComputePipeline(const VulkanContext& context, const ComputeShaderModule& module,
                                 VkPipelineLayout layout, const std::vector<TraceRayConstants>& traceRay)
    : context_(context) {
    const VulkanFunctions& f = context.vk();
    auto moduleInfo = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    moduleInfo.codeSize = module.words.size() * 4;
    moduleInfo.pCode = module.words.data();
    VkShaderModule shader = VK_NULL_HANDLE;
    REFRAY_VK(f.vkCreateShaderModule(context.device(), &moduleInfo, nullptr, &shader));
    const SpecializationData constants = specializationData(traceRay);
    const VkSpecializationInfo specialization = constants.info();
    auto info = vkStruct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage = vkStruct<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = shader;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = &specialization;
    info.layout = layout;
    const VkResult result = f.vkCreateComputePipelines(context.device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
    f.vkDestroyShaderModule(context.device(), shader, nullptr);
    REFRAY_CHECK(result == VK_SUCCESS, "Vulkan: vkCreateComputePipelines for export '"
                                           << module.exportName << "' (" << module.file.string() << ") returned "
                                           << resultName(result));
}

ComputePipeline::~ComputePipeline() {
    if (pipeline_) context_.vk().vkDestroyPipeline(context_.device(), pipeline_, nullptr);
}

std::optional<uint32_t> SpecializationData::valueOf(uint32_t constantId) const {
    for (size_t i = 0; i < entries.size(); ++i)
        if (entries[i].constantID == constantId) return values[entries[i].offset / sizeof(uint32_t)];
    return std::nullopt;
}

VkSpecializationInfo SpecializationData::info() const {
    return {uint32_t(entries.size()), entries.data(), values.size() * sizeof(uint32_t), values.data()};
}

SpecializationData specializationData(const std::vector<TraceRayConstants>& traceRay, uint32_t recordIndexOffset) {
    SpecializationData out;
    const auto add = [&](uint32_t constantId, uint32_t value) {
        out.entries.push_back({constantId, uint32_t(out.values.size() * sizeof(uint32_t)), sizeof(uint32_t)});
        out.values.push_back(value);
    };
    add(kRecordIndexOffsetConstantId, recordIndexOffset);
    for (uint32_t r = 0; r < traceRay.size(); ++r) {
        const TraceRayConstants& t = traceRay[r];
        add(traceRayConstantId(r, TraceRayField::RayContribution), t.rayContribution);
        add(traceRayConstantId(r, TraceRayField::Multiplier), t.multiplier);
        add(traceRayConstantId(r, TraceRayField::MissShaderIndex), t.missShaderIndex);
        add(traceRayConstantId(r, TraceRayField::InstanceInclusionMask), t.instanceInclusionMask);
    }
    return out;
}

RayTracingPipeline::RayTracingPipeline(const VulkanContext& context, const PipelineShape& shape, VkPipelineLayout layout,
                                       const std::vector<TraceRayConstants>& traceRay, uint32_t recordIndexOffset)
    : context_(context) {
    const VulkanFunctions& f = context.vk();
    const RayTracingLimits& limits = context.limits();
    REFRAY_CHECK(shape.maxRecursionDepth <= limits.maxRayRecursionDepth,
                 "the state object's MaxTraceRecursionDepth " << shape.maxRecursionDepth
                                                               << " is more than the device's maxRayRecursionDepth "
                                                               << limits.maxRayRecursionDepth);
    REFRAY_CHECK(limits.shaderGroupHandleSize == sizeof(GroupHandle),
                 "the device's shaderGroupHandleSize is " << limits.shaderGroupHandleSize
                                                          << " bytes; refray's records keep DXR's layout, which needs "
                                                             "32 (the DXR shader identifier size)");

    // Modules, in stage order.
    std::vector<VkShaderModule> modules;
    const auto destroyModules = [&] {
        for (VkShaderModule m : modules) f.vkDestroyShaderModule(context.device(), m, nullptr);
    };
    try {
        for (const PipelineStage& stage : shape.stages) {
            const std::vector<uint32_t> words = readSpirvModule(stage.spirv, stage.exportName, stageExtension(stage.stage));
            requireDeviceSupport(context, inspectSpirv(words, stage.spirv.string()), stage.exportName,
                                 stageExtension(stage.stage), stage.spirv);
            auto info = vkStruct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
            info.codeSize = words.size() * 4;
            info.pCode = words.data();
            VkShaderModule module = VK_NULL_HANDLE;
            REFRAY_VK(f.vkCreateShaderModule(context.device(), &info, nullptr, &module));
            modules.push_back(module);
        }

        // Every stage gets the same constants; each module reads the ids it declares.
        const SpecializationData constants = specializationData(traceRay, recordIndexOffset);
        const VkSpecializationInfo specialization = constants.info();
        std::vector<VkPipelineShaderStageCreateInfo> stages;
        for (size_t i = 0; i < shape.stages.size(); ++i) {
            auto s = vkStruct<VkPipelineShaderStageCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
            s.stage = translateStage(shape.stages[i].stage);
            s.module = modules[i];
            s.pName = "main";
            s.pSpecializationInfo = &specialization;
            stages.push_back(s);
        }
        std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups;
        for (const PipelineGroup& g : shape.groups) {
            auto info = vkStruct<VkRayTracingShaderGroupCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR);
            info.type = g.type;
            info.generalShader = g.general;
            info.closestHitShader = g.closestHit;
            info.anyHitShader = g.anyHit;
            info.intersectionShader = g.intersection;
            groups.push_back(info);
        }

        auto info = vkStruct<VkRayTracingPipelineCreateInfoKHR>(VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR);
        // PIPELINE_FLAG_SKIP_TRIANGLES / SKIP_PROCEDURAL_PRIMITIVES: refray sets them only where no ray reaches
        // that geometry type, so without rayTraversalPrimitiveCulling they are dropped without changing a result.
        if (limits.rayTraversalPrimitiveCulling) {
            if (shape.pipelineFlags & dxr::PIPELINE_FLAG_SKIP_TRIANGLES)
                info.flags |= VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR;
            if (shape.pipelineFlags & dxr::PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES)
                info.flags |= VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR;
        }
        info.stageCount = uint32_t(stages.size());
        info.pStages = stages.data();
        info.groupCount = uint32_t(groups.size());
        info.pGroups = groups.data();
        info.maxPipelineRayRecursionDepth = shape.maxRecursionDepth;
        info.layout = layout;
        REFRAY_VK(f.vkCreateRayTracingPipelinesKHR(context.device(), VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &info, nullptr,
                                                   &pipeline_));
    } catch (...) {
        destroyModules();
        throw;
    }
    destroyModules();

    handles_.resize(shape.groups.size());
    if (!handles_.empty())
        REFRAY_VK(f.vkGetRayTracingShaderGroupHandlesKHR(context.device(), pipeline_, 0, uint32_t(handles_.size()),
                                                         handles_.size() * sizeof(GroupHandle), handles_.data()));
}

RayTracingPipeline::~RayTracingPipeline() {
    if (pipeline_) context_.vk().vkDestroyPipeline(context_.device(), pipeline_, nullptr);
}

}  // namespace refray::gpu
