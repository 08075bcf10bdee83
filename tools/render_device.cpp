#include "tools/render_device.h"

#include <filesystem>

#include "core/error.h"

#ifdef REFRAY_HAVE_VULKAN
#include "gpu/vulkan_dispatch.h"
#endif

namespace refray::tools {

RenderDevice makeRenderDevice(const std::string& device, const std::string& library, const std::string& spirvDirectory) {
    REFRAY_CHECK(device == "cpu" || device == "vulkan", "--device expects 'cpu' or 'vulkan', got '" << device << "'");
    RenderDevice out;
    if (device == "cpu") {
        REFRAY_CHECK(spirvDirectory.empty(), "--spirv-dir is for --device vulkan");
        return out;
    }
#ifdef REFRAY_HAVE_VULKAN
    gpu::VulkanBackendOptions options;
    options.library = library;
    options.spirvDirectory = spirvDirectory.empty()
                                 ? gpu::defaultSpirvDirectory(std::filesystem::read_symlink("/proc/self/exe"))
                                 : std::filesystem::path(spirvDirectory);
    auto backend = std::make_shared<gpu::VulkanBackend>(options);
    gpu::VulkanBackend* raw = backend.get();
    out.backend = [raw](dxr::Device& d, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& pipeline,
                        const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions& dispatchOptions) {
        return raw->dispatchRays(d, desc, pipeline, globals, dispatchOptions);
    };
    const gpu::DeviceInfo& info = backend->deviceInfo();
    out.provenance["device"] = "vulkan";
    out.provenance["gpu"] = info.name;
    out.provenance["gpu_driver"] = info.driverName + " " + info.driverVersion;
    out.provenance["vulkan_api"] = info.apiVersion;
    out.provenance["spirv_dir"] = options.spirvDirectory.string();
    out.state = backend;
    return out;
#else
    (void)library;
    throw Error("--device vulkan: this refray was built without the Vulkan back end (configure found no "
                "libvulkan-dev, glslang-tools or spirv-tools, or REFRAY_VULKAN=OFF)");
#endif
}

void checkVulkanSettings(const scenes::RenderSettings& settings) {
    REFRAY_CHECK(settings.precision == procedural::Precision::Float,
                 "--device vulkan runs the GLSL ports, which are float only; drop --precision double");
    REFRAY_CHECK(settings.accuracy.isDefault(),
                 "--device vulkan runs the GLSL ports with the HLSL's constants; --knob is the emulator's");
    REFRAY_CHECK(settings.order == dxr::TraversalOrder::Ordered,
                 "--device vulkan: the GPU traverses in its own order; --order adversarial is the emulator's");
}

RenderDevice useRenderDevice(const std::string& device, const std::string& library, const std::string& spirvDirectory,
                             scenes::RenderSettings& settings) {
    if (device == "vulkan") checkVulkanSettings(settings);
    RenderDevice out = makeRenderDevice(device, library, spirvDirectory);
    settings.backend = out.backend;
    return out;
}

}  // namespace refray::tools
