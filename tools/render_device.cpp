#include "tools/render_device.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>

#include "core/error.h"
#include "core/json_writer.h"

#ifdef REFRAY_HAVE_VULKAN
#include "gpu/vulkan_dispatch.h"
#include "tools/device_trace_ray.h"
#endif

namespace refray::tools {

namespace {

std::string vulkanDeviceSelector(const std::string& option) {
    if (!option.empty()) return option;
    const char* env = std::getenv("REFRAY_VULKAN_DEVICE");
    return env ? env : "";
}

#ifdef REFRAY_HAVE_VULKAN
// The device's AOV values as primary hits. A compute dispatch's come from ray queries, which use no shader table:
// they carry no record (RQ-31), and a compute scene has no record or hit-group map (inspect/index_map.h).
std::vector<scenes::PrimaryHit> primaryHitsOf(const gpu::AovPixels& aov) {
    std::vector<scenes::PrimaryHit> hits(aov.record.size());
    for (size_t i = 0; i < hits.size(); ++i) {
        scenes::PrimaryHit& h = hits[i];
        h.traced = true;
        h.hit = aov.record[i] != gpu::AovPixels::kAovMiss;
        if (!h.hit) continue;
        if (!aov.inlineQuery) h.record = aov.record[i];
        h.instanceIndex = aov.instanceIndex[i];
        h.geometryIndex = aov.geometryIndex[i];
        h.primitiveIndex = aov.primitiveIndex[i];
        h.instanceID = aov.instanceID[i];
    }
    return hits;
}
#endif

}  // namespace

RenderDevice makeRenderDevice(const std::string& device, const std::string& library, const scenes::SceneDesc* scene,
                              const std::string& spirvDirectory, const std::string& vulkanDevice) {
    REFRAY_CHECK(device == "cpu" || device == "vulkan", "--device expects 'cpu' or 'vulkan', got '" << device << "'");
    RenderDevice out;
    if (device == "cpu") {
        REFRAY_CHECK(spirvDirectory.empty(), "--spirv-dir is for --device vulkan");
        REFRAY_CHECK(vulkanDevice.empty(), "--vulkan-device is for --device vulkan");
        return out;
    }
#ifdef REFRAY_HAVE_VULKAN
    gpu::VulkanBackendOptions options;
    options.library = library;
    options.device = vulkanDeviceSelector(vulkanDevice);
    options.traceRay = deviceTraceRayConstants(library, scene);
    options.spirvDirectory = spirvDirectory.empty()
                                 ? gpu::defaultSpirvDirectory(std::filesystem::read_symlink("/proc/self/exe"))
                                 : std::filesystem::path(spirvDirectory);
    auto backend = std::make_shared<gpu::VulkanBackend>(options);
    gpu::VulkanBackend* raw = backend.get();
    out.backend = [raw](dxr::Device& d, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& pipeline,
                        const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions& dispatchOptions) {
        return raw->dispatchRays(d, desc, pipeline, globals, dispatchOptions);
    };
    out.computeBackend = [raw](dxr::Device& d, const dxr::DispatchDesc& desc, const dxr::StateObjectPtr& pipeline,
                               const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions& dispatchOptions) {
        return raw->dispatch(d, desc, pipeline, globals, dispatchOptions);
    };
    const gpu::DeviceInfo& info = backend->deviceInfo();
    out.aov = [raw](dxr::Device& d, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& pipeline,
                    const dxr::GlobalRootArguments* globals) {
        return primaryHitsOf(raw->dispatchAov(d, desc, pipeline, globals));
    };
    out.computeAov = [raw](dxr::Device& d, const dxr::DispatchDesc& desc, const dxr::StateObjectPtr& pipeline,
                           const dxr::GlobalRootArguments* globals) {
        return primaryHitsOf(raw->dispatchAov(d, desc, pipeline, globals));
    };
    out.provenance["device"] = "vulkan";
    out.provenance["gpu"] = info.name;
    out.provenance["gpu_driver"] = info.driverName + " " + info.driverVersion;
    out.provenance["vulkan_device_type"] = info.type;  // "CPU" for lavapipe: a software driver, not a GPU
    out.provenance["vulkan_device_index"] = std::to_string(info.index);
    if (!info.mesaVersion.empty()) out.provenance["mesa_version"] = info.mesaVersion;
    out.provenance["vulkan_api"] = info.apiVersion;
    out.provenance["spirv_dir"] = options.spirvDirectory.string();
    out.state = backend;
    return out;
#else
    (void)library, (void)scene, (void)vulkanDevice;
    throw Error("--device vulkan: this refray was built without the Vulkan back end (configure found no "
                "libvulkan-dev, glslang-tools or spirv-tools, or REFRAY_VULKAN=OFF)");
#endif
}

scenes::IndexMap renderDeviceIndexMap(const RenderDevice& device, scenes::Scene& scene,
                                      const scenes::RenderSettings& settings, scenes::IndexMapKind kind) {
    if (!device.aov) return scenes::renderIndexMap(scene, settings, kind);
    REFRAY_CHECK(kind != scenes::IndexMapKind::Depth,
                 "--aov depth needs the emulator's trace of every ray; the device's AOV dispatch sees only primary rays");
    REFRAY_CHECK(settings.spp == 1, "index maps show the GPU's one primary ray per pixel; --aov needs --spp 1");
    const scenes::SceneDesc& desc = scene.desc();
    REFRAY_CHECK(!desc.rayTypes.empty(), "scene '" << desc.name << "' has no ray types to trace");
    std::vector<scenes::PrimaryHit> hits;
    scenes::RenderSettings s = settings;
    s.backend = [&](dxr::Device& d, const dxr::DispatchRaysDesc& desc_, const dxr::StateObjectPtr& pipeline,
                    const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions&) {
        hits = device.aov(d, desc_, pipeline, globals);
        return dxr::DispatchResult{};
    };
    // A compute scene: each thread's first ray query (its primary ray).
    s.computeBackend = [&](dxr::Device& d, const dxr::DispatchDesc& desc_, const dxr::StateObjectPtr& pipeline,
                           const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions&) {
        REFRAY_CHECK(device.computeAov, "--aov: this device has no compute AOV dispatch");
        hits = device.computeAov(d, desc_, pipeline, globals);
        return dxr::DispatchResult{};
    };
    scenes::RenderResult rendered = scene.render(s);
    // The primary ray's TraceRay arguments: the first ray type's.
    const scenes::RayTypeDesc& primary = desc.rayTypes.front();
    uint64_t otherInstanceIDs = 0;  // pixels whose InstanceID() is not the scene's for their InstanceIndex()
    for (scenes::PrimaryHit& h : hits) {
        h.rayContribution = primary.rayContribution;
        h.multiplier = primary.multiplier;
        h.missShaderIndex = primary.missShaderIndex;
        if (h.hit && h.instanceID && h.instanceIndex < desc.instances.size() &&
            (*h.instanceID & 0xFFFFFFu) != (desc.instances[h.instanceIndex].instanceID & 0xFFFFFFu))
            ++otherInstanceIDs;
    }
    scenes::IndexMap map = scenes::indexMapOf(desc, settings.width, settings.height, kind, hits);
    if (otherInstanceIDs > 0)
        std::fprintf(stderr, "refray: warning: on %llu pixels the device's InstanceID() is not the scene's InstanceID "
                             "of the InstanceIndex() it reports\n",
                     (unsigned long long)otherInstanceIDs);
    map.map.metadata = std::move(rendered.image.metadata);
    map.map.metadata["aov"] = scenes::indexMapKindNames()[size_t(kind)];
    for (const auto& [key, value] : device.provenance) map.map.metadata[key] = value;
    map.map.metadata["aov_instance_id_mismatches"] = std::to_string(otherInstanceIDs);
    return map;
}

void checkVulkanSettings(const scenes::RenderSettings& settings) {
    REFRAY_CHECK(settings.precision == procedural::Precision::Float,
                 "--device vulkan runs the GLSL ports, which are float only; drop --precision double");
    REFRAY_CHECK(settings.accuracy.isDefault(),
                 "--device vulkan runs the GLSL ports with the HLSL's constants; --knob is the emulator's");
    REFRAY_CHECK(settings.order == dxr::TraversalOrder::Ordered,
                 "--device vulkan: the GPU traverses in its own order; --order adversarial is the emulator's");
}

RenderDevice useRenderDevice(const std::string& device, const std::string& library, const scenes::SceneDesc* scene,
                             const std::string& spirvDirectory, const std::string& vulkanDevice,
                             scenes::RenderSettings& settings) {
    if (device == "vulkan") checkVulkanSettings(settings);
    RenderDevice out = makeRenderDevice(device, library, scene, spirvDirectory, vulkanDevice);
    settings.backend = out.backend;
    settings.computeBackend = out.computeBackend;
    return out;
}

int listDevices(bool json) {
#ifdef REFRAY_HAVE_VULKAN
    const std::vector<gpu::PhysicalDeviceSummary> devices = gpu::listVulkanDevices();
    std::optional<uint32_t> chosen;
    std::string why;
    try {
        chosen = gpu::chooseRayTracingDevice(devices, vulkanDeviceSelector(""));
    } catch (const Error& e) {
        why = e.what();
    }
    if (json) {
        json::Writer w;
        w.beginObject().member("format", "refray-devices/1").key("devices").beginArray();
        for (const gpu::PhysicalDeviceSummary& d : devices) {
            w.beginObject()
                .member("index", d.index)
                .member("name", d.name)
                .member("type", d.type)
                .member("software", d.cpu)
                .member("driver", d.driverName)
                .member("driverInfo", d.driverInfo)
                .member("vulkanApi", d.apiVersion)
                .member("rayTracing", d.rayTracing)
                .member("rayQuery", d.rayQuery)
                .member("default", chosen && *chosen == d.index)
                .key("lacks")
                .beginArray(json::Writer::Layout::Inline);
            for (const std::string& m : d.missing) w.value(m);
            w.endArray().endObject();
        }
        w.endArray().endObject();
        std::printf("%s\n", w.text().c_str());
    } else {
        std::printf("%-5s %-40s %-14s %-12s %-8s %-9s %s\n", "index", "device", "type", "driver", "Vulkan", "rayQuery",
                    "ray tracing");
        for (const gpu::PhysicalDeviceSummary& d : devices) {
            std::string rt = d.rayTracing ? "yes" : "no: lacks ";
            if (!d.rayTracing)
                for (size_t i = 0; i < d.missing.size(); ++i) rt += (i ? ", " : "") + d.missing[i];
            if (chosen && *chosen == d.index) rt += "   <- --device vulkan";
            std::printf("%-5u %-40s %-14s %-12s %-8s %-9s %s\n", d.index, d.name.c_str(), d.type.c_str(),
                        d.driverName.c_str(), d.apiVersion.c_str(), d.rayQuery ? "yes" : "no", rt.c_str());
        }
        for (const gpu::PhysicalDeviceSummary& d : devices)
            if (d.cpu) std::printf("device %u (%s, %s) is a CPU driver, not a GPU\n", d.index, d.name.c_str(), d.driverInfo.c_str());
    }
    if (!chosen) {
        std::fprintf(stderr, "refray: %s\n", why.c_str());
        return 2;
    }
    return 0;
#else
    (void)json;
    throw Error("refray devices: this refray was built without the Vulkan back end (configure found no "
                "libvulkan-dev, glslang-tools or spirv-tools, or REFRAY_VULKAN=OFF)");
#endif
}

}  // namespace refray::tools
