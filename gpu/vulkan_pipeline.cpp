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

namespace {

std::vector<uint32_t> readSpirv(const PipelineStage& stage) {
    std::ifstream file(stage.spirv, std::ios::binary | std::ios::ate);
    REFRAY_CHECK(file, "no SPIR-V for export '" << stage.exportName << "' (" << stageExtension(stage.stage)
                                                << "): expected " << stage.spirv.string()
                                                << " (compiled from its GLSL port gpu/shaders/<library>/"
                                                << stage.exportName << "." << stageExtension(stage.stage)
                                                << "; give --spirv-dir or REFRAY_SPIRV_DIR if the .spv files are "
                                                   "elsewhere)");
    const std::streamsize size = file.tellg();
    REFRAY_CHECK(size > 0 && size % 4 == 0, stage.spirv.string() << " (export '" << stage.exportName
                                                                 << "') is not a SPIR-V module: " << size << " bytes");
    std::vector<uint32_t> words(size_t(size) / 4);
    file.seekg(0);
    file.read(reinterpret_cast<char*>(words.data()), size);
    REFRAY_CHECK(words[0] == 0x07230203u, stage.spirv.string() << " (export '" << stage.exportName
                                                               << "') does not start with the SPIR-V magic number");
    return words;
}

}  // namespace

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
            const std::vector<uint32_t> words = readSpirv(stage);
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
