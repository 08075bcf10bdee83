// DispatchRays on a Vulkan ray-tracing device: the DXR state refray built on dxr::Device — its buffers, BLAS/TLAS,
// state object, shader tables and global root arguments — translated to Vulkan and traced with
// vkCmdTraceRaysKHR. Mirrors dxr::Device::dispatchRays, so a scene renders through either without a second
// scene builder (scenes/render_settings.h, RenderSettings::backend).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "emulator/device.h"
#include "gpu/vulkan_context.h"
#include "gpu/vulkan_pipeline.h"

namespace refray::gpu {

struct VulkanBackendOptions {
    // Holds <library>/<Export>.<stage>.spv for every export (the build's <build>/gpu/shaders).
    std::filesystem::path spirvDirectory;
    // The shader library the state objects come from: the folder of their SPIR-V ("proceduray",
    // "d3d12-procedural-geometry", "builtin").
    std::string library;
    // What the library's shaders pass to TraceRay for each ray type: the scene's effective arguments (its library's
    // defaults with each ray type's "traceRay" applied), which the GLSL ports read as specialization constants.
    // The host (tools/device_trace_ray.h) fills them in; a dispatch with none refuses to run.
    std::vector<TraceRayConstants> traceRay;
    // Which Vulkan device (VulkanContextOptions::device): empty for a hardware one when there is one, else lavapipe.
    std::string device;
};

// What an AOV dispatch reports per launch index (row-major), each kAovMiss where the primary ray missed.
// A compute dispatch (inlineQuery) reports each thread's first ray query instead: thread (x, y) is pixel (x, y),
// cropped to the render target where the dispatch binds one (else the whole thread grid, width = groups x
// numThreads along X).
struct AovPixels {
    static constexpr uint32_t kAovMiss = 0xFFFFFFFFu;
    uint32_t width = 0, height = 0;
    bool inlineQuery = false;             // a compute dispatch: no shader table, so no record
    // DispatchRays: the hit-group record the committed hit used (its own index). Dispatch: the first query's
    // committed status (COMMITTED_TRIANGLE_HIT 1, COMMITTED_PROCEDURAL_PRIMITIVE_HIT 2).
    std::vector<uint32_t> record;
    std::vector<uint32_t> instanceIndex;  // gl_InstanceID (DXR InstanceIndex())
    std::vector<uint32_t> instanceID;     // gl_InstanceCustomIndexEXT (DXR InstanceID())
    std::vector<uint32_t> geometryIndex;  // gl_GeometryIndexEXT
    std::vector<uint32_t> primitiveIndex; // gl_PrimitiveID
};

// One compute dispatch (DXR Dispatch of a compute shader): the export, its [numthreads] and the thread-group counts.
struct ComputeDispatch {
    std::string exportName;
    std::array<uint32_t, 3> numThreads{1, 1, 1};
    std::array<uint32_t, 3> groups{1, 1, 1};  // ThreadGroupCountX, Y, Z
};

class VulkanBackend {
public:
    // Makes the Vulkan device; throws refray::Error saying what is missing (vulkan_context.h).
    explicit VulkanBackend(VulkanBackendOptions options);
    ~VulkanBackend();

    const DeviceInfo& deviceInfo() const { return context_->info(); }
    const VulkanContext& context() const { return *context_; }

    // The same arguments as dxr::Device::dispatchRays. Renders on the GPU; each Image bound as a UAV in the
    // global root arguments' descriptor heap receives what the shaders wrote. DispatchResult::seconds is the GPU
    // time of vkCmdTraceRaysKHR (timestamps; the wall time of the submission where the queue has none); stats and
    // diagnostics stay empty. Options the GPU cannot honour (a launch region, a trace observer, an adversarial
    // order) throw refray::Error.
    dxr::DispatchResult dispatchRays(dxr::Device& device, const dxr::DispatchRaysDesc& desc,
                                     const dxr::StateObjectPtr& pipeline, const dxr::GlobalRootArguments* globals,
                                     const dxr::DispatchOptions& options = {});

    // The AOV dispatch (docs/vulkan-backend.md, "AOVs"): the same translation with every closest-hit shader
    // replaced by gpu/shaders/aov/ClosestHit_AOV.rchit and every miss shader by Miss_AOV.rmiss; returns what the
    // closest hit saw for each launch index's primary ray.
    AovPixels dispatchAov(dxr::Device& device, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& pipeline,
                          const dxr::GlobalRootArguments* globals);

    // Dispatch of a compute shader: the same translation of the global root arguments (one descriptor set layout,
    // the binding contract of gpu/shaders/CONTRACT.md), a compute pipeline from <library>/<Export>.comp.spv and
    // vkCmdDispatch with the group counts; each render target is read back as dispatchRays does. DispatchResult::seconds
    // is the GPU time of vkCmdDispatch. Throws refray::Error when the module is missing, its local size is not the
    // export's [numthreads], or it traces inline on a device without ray queries (naming the device).
    dxr::DispatchResult dispatchCompute(dxr::Device& device, const ComputeDispatch& dispatch,
                                        const dxr::GlobalRootArguments* globals);
    // The same arguments as dxr::Device::dispatch: the state object's compute export `desc.ComputeShader` (its
    // [numthreads]) and the group counts, run by dispatchCompute. Options the GPU cannot honour throw, as for
    // dispatchRays; an export the state object does not have throws refray::Error.
    dxr::DispatchResult dispatch(dxr::Device& device, const dxr::DispatchDesc& desc, const dxr::StateObjectPtr& pipeline,
                                 const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions& options = {});
    // dispatch's AOV: each thread's first ray query (dispatchComputeAov).
    AovPixels dispatchAov(dxr::Device& device, const dxr::DispatchDesc& desc, const dxr::StateObjectPtr& pipeline,
                          const dxr::GlobalRootArguments* globals);
    // The compute AOV dispatch: <Export>.aov.comp.spv, which records each thread's first ray query's committed hit
    // (gpu/shaders/common/d3d12_ray_query.glsl, REFRAY_AOV_FIRST_QUERY).
    AovPixels dispatchComputeAov(dxr::Device& device, const ComputeDispatch& dispatch,
                                 const dxr::GlobalRootArguments* globals);

private:
    ComputeDispatch computeDispatchOf(const dxr::DispatchDesc& desc, const dxr::StateObjectPtr& pipeline) const;
    struct BoundGlobals;
    std::unique_ptr<BoundGlobals> bindGlobals(dxr::Device& device, const dxr::GlobalRootArguments& globals,
                                              uint64_t aovValues) const;
    dxr::DispatchResult run(dxr::Device& device, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& pipeline,
                            const dxr::GlobalRootArguments* globals, AovPixels* aov);
    dxr::DispatchResult runCompute(dxr::Device& device, const ComputeDispatch& dispatch,
                                   const dxr::GlobalRootArguments* globals, AovPixels* aov);

    VulkanBackendOptions options_;
    std::unique_ptr<VulkanContext> context_;
};

// Where the SPIR-V lives when no --spirv-dir is given: $REFRAY_SPIRV_DIR, else the first of
// <exe dir>/../gpu/shaders (the build tree) and <exe dir>/shaders (tools/gpu_bundle.sh's layout) that exists,
// else the build tree's path (so the error names it).
std::filesystem::path defaultSpirvDirectory(const std::filesystem::path& executable);

}  // namespace refray::gpu
