// DispatchRays on a Vulkan ray-tracing device: the DXR state refray built on dxr::Device — its buffers, BLAS/TLAS,
// state object, shader tables and global root arguments — translated to Vulkan and traced with
// vkCmdTraceRaysKHR. Mirrors dxr::Device::dispatchRays, so a scene renders through either without a second
// scene builder (scenes/render_settings.h, RenderSettings::backend).
#pragma once

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
struct AovPixels {
    static constexpr uint32_t kAovMiss = 0xFFFFFFFFu;
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> record;         // the hit-group record the committed hit used (its own index)
    std::vector<uint32_t> instanceIndex;  // gl_InstanceID (DXR InstanceIndex())
    std::vector<uint32_t> instanceID;     // gl_InstanceCustomIndexEXT (DXR InstanceID())
    std::vector<uint32_t> geometryIndex;  // gl_GeometryIndexEXT
    std::vector<uint32_t> primitiveIndex; // gl_PrimitiveID
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

private:
    struct Run;
    dxr::DispatchResult run(dxr::Device& device, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& pipeline,
                            const dxr::GlobalRootArguments* globals, AovPixels* aov);

    VulkanBackendOptions options_;
    std::unique_ptr<VulkanContext> context_;
};

// Where the SPIR-V lives when no --spirv-dir is given: $REFRAY_SPIRV_DIR, else the first of
// <exe dir>/../gpu/shaders (the build tree) and <exe dir>/shaders (tools/gpu_bundle.sh's layout) that exists,
// else the build tree's path (so the error names it).
std::filesystem::path defaultSpirvDirectory(const std::filesystem::path& executable);

}  // namespace refray::gpu
