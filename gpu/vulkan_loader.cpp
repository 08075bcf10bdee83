#include "gpu/vulkan_loader.h"

#include <dlfcn.h>

#include <cstdlib>

namespace refray::gpu {

VulkanLoader::VulkanLoader() {
    const char* overrideName = std::getenv("REFRAY_VULKAN_LOADER");
    name_ = overrideName && *overrideName ? overrideName : "libvulkan.so.1";
    handle_ = dlopen(name_.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle_) {
        const char* why = dlerror();
        throw Error("no Vulkan loader: " + name_ + " could not be opened (" + (why ? why : "no reason given") +
                    "). Install the loader (Debian/Ubuntu package libvulkan1, plus the glvnd libraries libegl1 "
                    "libglvnd0 libopengl0 libgl1 libglx0 libgles2 that the NVIDIA driver's ICD needs), or point "
                    "REFRAY_VULKAN_LOADER at libvulkan.so.1");
    }
    functions_.vkGetInstanceProcAddr =
        reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(handle_, "vkGetInstanceProcAddr"));
    if (!functions_.vkGetInstanceProcAddr) {
        dlclose(handle_);
        handle_ = nullptr;
        throw Error("no Vulkan loader: " + name_ + " was opened but exports no vkGetInstanceProcAddr");
    }
#define REFRAY_VULKAN_LOAD_GLOBAL(name) \
    functions_.name = reinterpret_cast<PFN_##name>(functions_.vkGetInstanceProcAddr(VK_NULL_HANDLE, #name));
    REFRAY_VULKAN_GLOBAL_FUNCTIONS(REFRAY_VULKAN_LOAD_GLOBAL)
#undef REFRAY_VULKAN_LOAD_GLOBAL
    REFRAY_CHECK(functions_.vkCreateInstance,
                 "no Vulkan loader: " << name_ << " provides no vkCreateInstance through vkGetInstanceProcAddr");
}

VulkanLoader::~VulkanLoader() {
    if (handle_) dlclose(handle_);
}

void VulkanLoader::loadInstance(VkInstance instance) {
#define REFRAY_VULKAN_LOAD_INSTANCE(name)                                                               \
    functions_.name = reinterpret_cast<PFN_##name>(functions_.vkGetInstanceProcAddr(instance, #name)); \
    REFRAY_CHECK(functions_.name, "the Vulkan loader " << name_ << " provides no " #name);
    REFRAY_VULKAN_INSTANCE_FUNCTIONS(REFRAY_VULKAN_LOAD_INSTANCE)
#undef REFRAY_VULKAN_LOAD_INSTANCE
}

void VulkanLoader::loadDevice(VkDevice device, bool rayTracing) {
#define REFRAY_VULKAN_LOAD_DEVICE(name)                                                              \
    functions_.name = reinterpret_cast<PFN_##name>(functions_.vkGetDeviceProcAddr(device, #name));  \
    REFRAY_CHECK(functions_.name, "the Vulkan device provides no " #name " (driver too old for Vulkan 1.2 with " \
                                  "VK_KHR_ray_tracing_pipeline and VK_KHR_acceleration_structure?)");
    REFRAY_VULKAN_DEVICE_FUNCTIONS(REFRAY_VULKAN_LOAD_DEVICE)
    if (rayTracing) {
        REFRAY_VULKAN_RAY_TRACING_FUNCTIONS(REFRAY_VULKAN_LOAD_DEVICE)
    }
#undef REFRAY_VULKAN_LOAD_DEVICE
}

}  // namespace refray::gpu
