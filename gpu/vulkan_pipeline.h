// The state object as a Vulkan ray-tracing pipeline: one shader module per export, loaded from the compiled
// GLSL port <spirv dir>/<library>/<Export>.<stage>.spv (gpu/shaders/CONTRACT.md); a general group per ray
// generation, miss and callable export and a triangles or procedural hit group per DXR hit group, in the order of
// StateObject::entries(), so group i's handle replaces the identifier of entry i; maxPipelineRayRecursionDepth =
// the state object's MaxTraceRecursionDepth.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "emulator/state_object.h"
#include "gpu/vulkan_context.h"
#include "gpu/vulkan_shader_table.h"

namespace refray::gpu {

// "rgen", "rint", "rahit", "rchit", "rmiss", "rcall": the GLSL file extension of a stage.
std::string_view stageExtension(dxr::ShaderStage stage);
VkShaderStageFlagBits translateStage(dxr::ShaderStage stage);
// <spirvDirectory>/<library>/<exportName>.<stage>.spv
std::filesystem::path spirvPath(const std::filesystem::path& spirvDirectory, const std::string& library,
                                const std::string& exportName, dxr::ShaderStage stage);

// Shaders an AOV render puts in place of the library's (docs/vulkan-backend.md, "AOVs"): every hit group's
// closest hit and every miss shader. Intersection and any-hit shaders stay, so the same hit is committed.
struct AovShaders {
    std::filesystem::path closestHit;  // records the committed hit; traces nothing
    std::filesystem::path miss;        // does nothing
    uint32_t recordIndexOffset = 0;    // specialization constant 0 of the closest hit
};

// The TraceRay arguments the shaders pass for one ray type (DXR's RayContributionToHitGroupIndex R,
// MultiplierForGeometryContributionToHitGroupIndex M, MissShaderIndex and InstanceInclusionMask). The GLSL ports read
// them as specialization constants (docs/vulkan-backend.md, "TraceRay arguments a scene overrides become
// specialization constants"): ray type r's field f is constant_id traceRayConstantId(r, f), and a constant the host
// gives no value keeps the GLSL default, the HLSL's own argument. The scene's ray flags are not overridable (a scene
// file's "traceRay" has no flags key), so they stay the GLSL's constants.
struct TraceRayConstants {
    uint32_t rayContribution = 0;
    uint32_t multiplier = 0;
    uint32_t missShaderIndex = 0;
    uint32_t instanceInclusionMask = 0xFF;

    friend bool operator==(const TraceRayConstants&, const TraceRayConstants&) = default;
};

// constant_id = 16 * (rayType + 1) + field: ids 0..15 stay free (the AOV closest hit's record-index offset is 0).
enum class TraceRayField : uint32_t { RayContribution = 0, Multiplier = 1, MissShaderIndex = 2, InstanceInclusionMask = 3 };
inline constexpr uint32_t kTraceRayConstantStride = 16;
inline constexpr uint32_t kTraceRayFieldCount = 4;
constexpr uint32_t traceRayConstantId(uint32_t rayType, TraceRayField field) {
    return kTraceRayConstantStride * (rayType + 1) + uint32_t(field);
}
// The AOV closest hit's record-index offset (gpu/shaders/aov/ClosestHit_AOV.rchit).
inline constexpr uint32_t kRecordIndexOffsetConstantId = 0;

// The specialization data every stage of a pipeline gets: one 4-byte uint per constant, in `entries` order.
struct SpecializationData {
    std::vector<VkSpecializationMapEntry> entries;
    std::vector<uint32_t> values;
    // The value given for `constantId`, or nullopt where none is.
    std::optional<uint32_t> valueOf(uint32_t constantId) const;
    VkSpecializationInfo info() const;  // points into this object
};

// Pure: ray type r's four TraceRay arguments at traceRayConstantId(r, field), and the record-index offset at
// kRecordIndexOffsetConstantId (a map entry for an id a module does not declare changes nothing, Vulkan spec
// VkSpecializationInfo). The mask is passed whole; only its low 8 bits count (INST-4).
SpecializationData specializationData(const std::vector<TraceRayConstants>& traceRay, uint32_t recordIndexOffset = 0);

struct PipelineStage {
    std::string exportName;
    dxr::ShaderStage stage = dxr::ShaderStage::RayGeneration;
    std::filesystem::path spirv;
    bool aovClosestHit = false;  // reads the record-index offset (specialization constant 0)
};

struct PipelineGroup {
    std::string name;  // the export or hit group
    VkRayTracingShaderGroupTypeKHR type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    uint32_t general = VK_SHADER_UNUSED_KHR;  // indices into PipelineShape::stages
    uint32_t closestHit = VK_SHADER_UNUSED_KHR;
    uint32_t anyHit = VK_SHADER_UNUSED_KHR;
    uint32_t intersection = VK_SHADER_UNUSED_KHR;
};

struct PipelineShape {
    std::vector<PipelineStage> stages;  // one per export used, each once
    std::vector<PipelineGroup> groups;  // groups[i] is StateObject::entries()[i]
    uint32_t maxRecursionDepth = 1;
    uint32_t pipelineFlags = 0;  // the DXR pipeline flags (SKIP_TRIANGLES, SKIP_PROCEDURAL_PRIMITIVES)
};

// Pure: the stages and groups of `stateObject` (tests/gpu checks them without a GPU). No file is opened.
PipelineShape describePipeline(const dxr::StateObject& stateObject, const std::filesystem::path& spirvDirectory,
                               const std::string& library, const AovShaders* aov = nullptr);

// What refray needs to know about a SPIR-V module before handing it to a device.
struct SpirvFacts {
    bool rayQuery = false;  // declares the RayQueryKHR capability (GLSL GL_EXT_ray_query): it traces inline
    std::optional<std::array<uint32_t, 3>> localSize;  // a compute module's LocalSize execution mode
};
// Pure: reads the capabilities and execution modes of a module's words. Throws refray::Error for words that are not
// a SPIR-V module (`what` names it).
SpirvFacts inspectSpirv(const std::vector<uint32_t>& words, const std::string& what);

// The words of `file`, the module of export `exportName`'s `stage` ("rchit", "comp"). Throws refray::Error naming
// the export and the file when it is missing or not a SPIR-V module.
std::vector<uint32_t> readSpirvModule(const std::filesystem::path& file, const std::string& exportName,
                                      std::string_view stage);

// Pure: why `device` cannot run the module of `facts` (empty when it can): a module that traces inline needs ray
// queries (VK_KHR_ray_query with the rayQuery feature, `deviceHasRayQuery`). The message names the export, the
// file, the device and what it lacks.
std::string deviceRefusal(const DeviceInfo& device, bool deviceHasRayQuery, const SpirvFacts& facts,
                          const std::string& exportName, std::string_view stage, const std::filesystem::path& file);
// Throws refray::Error with deviceRefusal's message where it is not empty.
void requireDeviceSupport(const VulkanContext& context, const SpirvFacts& facts, const std::string& exportName,
                          std::string_view stage, const std::filesystem::path& file);

// <spirvDirectory>/<library>/<exportName>.comp.spv, or <exportName>.aov.comp.spv for refray's AOV (the same GLSL
// compiled with REFRAY_AOV_FIRST_QUERY, gpu/CMakeLists.txt).
std::filesystem::path computeSpirvPath(const std::filesystem::path& spirvDirectory, const std::string& library,
                                       const std::string& exportName, bool aov);

// A compute export's module, read and checked: its local size must be the export's [numthreads] (the GLSL port's
// `layout(local_size_x = ...)`), and a module that traces inline needs a device with ray queries.
struct ComputeShaderModule {
    ComputeShaderModule(const VulkanContext& context, const std::filesystem::path& file, const std::string& exportName,
                        const std::array<uint32_t, 3>& numThreads);
    std::filesystem::path file;
    std::string exportName;
    std::vector<uint32_t> words;
    SpirvFacts facts;
};

// A compute pipeline of one module with `layout`; the TraceRay specialization constants are given as to every
// ray-tracing stage (a compute module declares none it does not read).
class ComputePipeline {
public:
    ComputePipeline(const VulkanContext& context, const ComputeShaderModule& module, VkPipelineLayout layout,
                    const std::vector<TraceRayConstants>& traceRay);
    ~ComputePipeline();
    ComputePipeline(const ComputePipeline&) = delete;
    ComputePipeline& operator=(const ComputePipeline&) = delete;
    VkPipeline handle() const { return pipeline_; }

private:
    const VulkanContext& context_;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// The pipeline on the device, and the group handles in entry order.
class RayTracingPipeline {
public:
    // Throws refray::Error naming the export and the file when a stage's SPIR-V is missing or unreadable, or traces
    // inline on a device without ray queries (requireDeviceSupport), and when the recursion depth exceeds the
    // device's maxRayRecursionDepth.
    // `traceRay`: the TraceRay arguments of each ray type, given to every stage as specialization constants
    // (specializationData); `recordIndexOffset`: the AOV closest hit's.
    RayTracingPipeline(const VulkanContext& context, const PipelineShape& shape, VkPipelineLayout layout,
                       const std::vector<TraceRayConstants>& traceRay, uint32_t recordIndexOffset = 0);
    ~RayTracingPipeline();
    RayTracingPipeline(const RayTracingPipeline&) = delete;
    RayTracingPipeline& operator=(const RayTracingPipeline&) = delete;

    VkPipeline handle() const { return pipeline_; }
    const std::vector<GroupHandle>& groupHandles() const { return handles_; }

private:
    const VulkanContext& context_;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    std::vector<GroupHandle> handles_;
};

}  // namespace refray::gpu
