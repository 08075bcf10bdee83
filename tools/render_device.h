// `refray render --device cpu|vulkan`: where DispatchRays runs. The scene is built on the emulator's dxr::Device
// either way; with `vulkan` its DXR state is translated to Vulkan and traced on the GPU (gpu/vulkan_dispatch.h).
#pragma once

#include <map>
#include <memory>
#include <string>

#include "scenes/render_settings.h"

namespace refray::tools {

struct RenderDevice {
    scenes::DispatchBackend backend;                // empty: the emulator
    std::map<std::string, std::string> provenance;  // image metadata: device, gpu, gpu_driver, vulkan_api
    std::shared_ptr<void> state;                    // keeps the back end alive while `backend` is in use
};

// `device` is "cpu" or "vulkan"; `library` the scene's shader library (the SPIR-V folder); `spirvDirectory` the
// --spirv-dir option (empty: REFRAY_SPIRV_DIR or next to the executable). Throws refray::Error when the device is
// unknown, when this refray was built without the Vulkan back end, or when no ray-tracing device is found (the
// message says what is missing).
RenderDevice makeRenderDevice(const std::string& device, const std::string& library, const std::string& spirvDirectory);

// makeRenderDevice, and for `vulkan` checkVulkanSettings(settings); sets settings.backend.
RenderDevice useRenderDevice(const std::string& device, const std::string& library, const std::string& spirvDirectory,
                             scenes::RenderSettings& settings);

// The Vulkan back end renders the shaders as the GLSL ports wrote them: float, the HLSL's constants, ordered
// traversal, whole images. Throws refray::Error naming the first option that asks for more.
void checkVulkanSettings(const scenes::RenderSettings& settings);

}  // namespace refray::tools
