// The Vulkan loader, opened at run time (dlopen of libvulkan.so.1), and the entry points the back end calls.
//
// refray links no Vulkan library: a machine without the loader still runs every CPU command, and
// `--device vulkan` reports what is missing instead of failing to start.
#pragma once

#include <string>

#include "gpu/vulkan_api.h"

namespace refray::gpu {

// Every entry point, one member per function, named as in the Vulkan headers.
#define REFRAY_VULKAN_GLOBAL_FUNCTIONS(X) \
    X(vkCreateInstance)                   \
    X(vkEnumerateInstanceVersion)         \
    X(vkEnumerateInstanceLayerProperties) \
    X(vkEnumerateInstanceExtensionProperties)

#define REFRAY_VULKAN_INSTANCE_FUNCTIONS(X)      \
    X(vkDestroyInstance)                         \
    X(vkEnumeratePhysicalDevices)                \
    X(vkGetPhysicalDeviceProperties)             \
    X(vkGetPhysicalDeviceProperties2)            \
    X(vkGetPhysicalDeviceFeatures2)              \
    X(vkGetPhysicalDeviceQueueFamilyProperties)  \
    X(vkGetPhysicalDeviceMemoryProperties)       \
    X(vkGetPhysicalDeviceFormatProperties)       \
    X(vkEnumerateDeviceExtensionProperties)      \
    X(vkCreateDevice)                            \
    X(vkGetDeviceProcAddr)

#define REFRAY_VULKAN_DEVICE_FUNCTIONS(X)            \
    X(vkDestroyDevice)                               \
    X(vkGetDeviceQueue)                              \
    X(vkDeviceWaitIdle)                              \
    X(vkCreateCommandPool)                           \
    X(vkDestroyCommandPool)                          \
    X(vkAllocateCommandBuffers)                      \
    X(vkFreeCommandBuffers)                          \
    X(vkBeginCommandBuffer)                          \
    X(vkEndCommandBuffer)                            \
    X(vkQueueSubmit)                                 \
    X(vkCreateFence)                                 \
    X(vkDestroyFence)                                \
    X(vkWaitForFences)                               \
    X(vkCreateBuffer)                                \
    X(vkDestroyBuffer)                               \
    X(vkGetBufferMemoryRequirements)                 \
    X(vkAllocateMemory)                              \
    X(vkFreeMemory)                                  \
    X(vkBindBufferMemory)                            \
    X(vkMapMemory)                                   \
    X(vkUnmapMemory)                                 \
    X(vkGetBufferDeviceAddress)                      \
    X(vkCreateImage)                                 \
    X(vkDestroyImage)                                \
    X(vkGetImageMemoryRequirements)                  \
    X(vkBindImageMemory)                             \
    X(vkCreateImageView)                             \
    X(vkDestroyImageView)                            \
    X(vkCreateSampler)                               \
    X(vkDestroySampler)                              \
    X(vkCmdCopyBuffer)                               \
    X(vkCmdCopyBufferToImage)                        \
    X(vkCmdCopyImageToBuffer)                        \
    X(vkCmdPipelineBarrier)                          \
    X(vkCreateShaderModule)                          \
    X(vkDestroyShaderModule)                         \
    X(vkCreateDescriptorSetLayout)                   \
    X(vkDestroyDescriptorSetLayout)                  \
    X(vkCreatePipelineLayout)                        \
    X(vkDestroyPipelineLayout)                       \
    X(vkCreateDescriptorPool)                        \
    X(vkDestroyDescriptorPool)                       \
    X(vkAllocateDescriptorSets)                      \
    X(vkUpdateDescriptorSets)                        \
    X(vkDestroyPipeline)                             \
    X(vkCmdBindPipeline)                             \
    X(vkCmdBindDescriptorSets)                       \
    X(vkCreateQueryPool)                             \
    X(vkDestroyQueryPool)                            \
    X(vkCmdResetQueryPool)                           \
    X(vkCmdWriteTimestamp)                           \
    X(vkGetQueryPoolResults)                         \
    X(vkCreateComputePipelines)                      \
    X(vkCmdDispatch)

#define REFRAY_VULKAN_RAY_TRACING_FUNCTIONS(X)       \
    X(vkCreateAccelerationStructureKHR)              \
    X(vkDestroyAccelerationStructureKHR)             \
    X(vkGetAccelerationStructureBuildSizesKHR)       \
    X(vkCmdBuildAccelerationStructuresKHR)           \
    X(vkGetAccelerationStructureDeviceAddressKHR)    \
    X(vkCreateRayTracingPipelinesKHR)                \
    X(vkGetRayTracingShaderGroupHandlesKHR)          \
    X(vkCmdTraceRaysKHR)

#define REFRAY_VULKAN_DECLARE(name) PFN_##name name = nullptr;

struct VulkanFunctions {
    PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
    REFRAY_VULKAN_GLOBAL_FUNCTIONS(REFRAY_VULKAN_DECLARE)
    REFRAY_VULKAN_INSTANCE_FUNCTIONS(REFRAY_VULKAN_DECLARE)
    REFRAY_VULKAN_DEVICE_FUNCTIONS(REFRAY_VULKAN_DECLARE)
    REFRAY_VULKAN_RAY_TRACING_FUNCTIONS(REFRAY_VULKAN_DECLARE)
};

// The shared library that holds the loader. Opens `REFRAY_VULKAN_LOADER` when that variable is set (a path or a
// soname), else libvulkan.so.1. Throws refray::Error "no Vulkan loader: ..." when it cannot be opened or has no
// vkGetInstanceProcAddr.
class VulkanLoader {
public:
    VulkanLoader();
    ~VulkanLoader();
    VulkanLoader(const VulkanLoader&) = delete;
    VulkanLoader& operator=(const VulkanLoader&) = delete;

    // The global entry points are loaded; instance and device ones follow loadInstance / loadDevice.
    VulkanFunctions& functions() { return functions_; }
    const VulkanFunctions& functions() const { return functions_; }
    void loadInstance(VkInstance instance);
    // Throws refray::Error naming the first device entry point the driver does not provide; the ray-tracing ones
    // only when `rayTracing`.
    void loadDevice(VkDevice device, bool rayTracing = true);
    // What was opened: the file name given to dlopen.
    const std::string& libraryName() const { return name_; }

private:
    void* handle_ = nullptr;
    std::string name_;
    VulkanFunctions functions_;
};

}  // namespace refray::gpu
