// `refray render --device cpu|vulkan`: where DispatchRays runs. The scene is built on the emulator's dxr::Device
// either way; with `vulkan` its DXR state is translated to Vulkan and traced on the GPU (gpu/vulkan_dispatch.h).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "inspect/index_map.h"
#include "scenes/render_settings.h"
#include "scenes/scene_desc.h"

namespace refray::tools {

struct RenderDevice {
    scenes::DispatchBackend backend;                // empty: the emulator
    scenes::ComputeBackend computeBackend;          // Dispatch of a compute scene; empty: the emulator
    std::map<std::string, std::string> provenance;  // image metadata: device, gpu, gpu_driver, vulkan_api
    std::shared_ptr<void> state;                    // keeps the back end alive while `backend` is in use
    // `--aov` on the device (empty: the emulator's trace): the AOV dispatch for `backend`'s arguments, each launch
    // index's primary hit as the device reports it (docs/vulkan-backend.md, "AOVs").
    std::function<std::vector<scenes::PrimaryHit>(dxr::Device&, const dxr::DispatchRaysDesc&, const dxr::StateObjectPtr&,
                                                  const dxr::GlobalRootArguments*)>
        aov;
    // The same for a compute scene (Dispatch): each thread's first ray query's committed hit (docs/vulkan-backend.md,
    // "AOVs"). A query has no shader table, so the hits carry no record.
    std::function<std::vector<scenes::PrimaryHit>(dxr::Device&, const dxr::DispatchDesc&, const dxr::StateObjectPtr&,
                                                  const dxr::GlobalRootArguments*)>
        computeAov;
};

// `device` is "cpu" or "vulkan"; `library` the scene's shader library (the SPIR-V folder); `scene` the scene file's
// description (nullptr: the built-in scene), whose ray types' TraceRay arguments the GLSL ports receive as
// specialization constants (tools/device_trace_ray.h); `spirvDirectory` the --spirv-dir option (empty:
// REFRAY_SPIRV_DIR or next to the executable). Throws refray::Error when the device is unknown, when this refray was
// built without the Vulkan back end, when the TraceRay arguments cannot be determined, or when no ray-tracing device
// is found (the message says what is missing). `vulkanDevice` is the --vulkan-device option (empty:
// $REFRAY_VULKAN_DEVICE, else a hardware ray-tracing device when there is one and Mesa's lavapipe otherwise;
// gpu::VulkanContextOptions::device).
RenderDevice makeRenderDevice(const std::string& device, const std::string& library, const scenes::SceneDesc* scene,
                              const std::string& spirvDirectory, const std::string& vulkanDevice = "");

// makeRenderDevice, and for `vulkan` checkVulkanSettings(settings); sets settings.backend and settings.computeBackend.
RenderDevice useRenderDevice(const std::string& device, const std::string& library, const scenes::SceneDesc* scene,
                             const std::string& spirvDirectory, const std::string& vulkanDevice,
                             scenes::RenderSettings& settings);

// `refray devices [--json]`: every Vulkan device the loader sees, whether refray can ray trace on it (and what it
// lacks), whether it has ray queries, and which one `--device vulkan` takes. Returns the exit status: 0 when at least
// one device can ray trace, 2 when none can or there is no loader or driver (the message says what is missing).
int listDevices(bool json);

// `refray render --aov KIND`: the index map of each pixel's primary ray, from the emulator's trace
// (scenes::renderIndexMap) or, on a device with `aov`, from its AOV dispatch. The device reports the record index it
// chose, InstanceIndex, GeometryIndex and PrimitiveIndex; R, M and the miss index in the labels are the scene's
// first ray type's (the one every ray-generation shader traces), so the two maps have the same values, colours and
// legend wherever they agree. `depth` needs the emulator's trace. The map's metadata carries the device's provenance.
scenes::IndexMap renderDeviceIndexMap(const RenderDevice& device, scenes::Scene& scene,
                                      const scenes::RenderSettings& settings, scenes::IndexMapKind kind);

// The Vulkan back end renders the shaders as the GLSL ports wrote them: float, the HLSL's constants, ordered
// traversal, whole images. Throws refray::Error naming the first option that asks for more.
void checkVulkanSettings(const scenes::RenderSettings& settings);

}  // namespace refray::tools
