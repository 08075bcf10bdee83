// The Vulkan instance and the ray-tracing device: which physical device is chosen, what it must support, and
// one queue to submit to. Constructing a VulkanContext is where `--device vulkan` finds out what is missing.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gpu/vulkan_loader.h"

namespace refray::gpu {

// Provenance of a GPU render (written into the image's metadata).
struct DeviceInfo {
    std::string name;           // VkPhysicalDeviceProperties::deviceName, "NVIDIA H100 80GB HBM3"
    std::string driverName;     // VkPhysicalDeviceDriverProperties::driverName, "NVIDIA"
    std::string driverVersion;  // driverInfo when the driver gives one ("580.159.04"), else the decoded number
    std::string apiVersion;     // the device's Vulkan API version, "1.4.312"
    std::string loader;         // the loader library that was opened
};

// The limits of VK_KHR_ray_tracing_pipeline and VK_KHR_acceleration_structure the translation depends on.
struct RayTracingLimits {
    uint32_t shaderGroupHandleSize = 32;
    uint32_t shaderGroupHandleAlignment = 32;
    uint32_t shaderGroupBaseAlignment = 64;
    uint32_t maxRayRecursionDepth = 1;
    uint32_t maxShaderGroupStride = 4096;
    uint32_t minAccelerationStructureScratchOffsetAlignment = 256;
    uint32_t maxUniformBufferRange = 65536;
    float timestampPeriod = 0.0f;  // nanoseconds per timestamp tick; 0: no timestamps on the queue
    bool rayTraversalPrimitiveCulling = false;  // SKIP_TRIANGLES / SKIP_AABBS ray and pipeline flags
};

// What a device needs for refray's back end, and why each item is there. The error for a machine without such a
// device lists every device with what it lacks.
//   Vulkan 1.2                      buffer device addresses and SPIR-V 1.4 in core
//   VK_KHR_ray_tracing_pipeline     raygen/miss/hit groups, shader binding tables, vkCmdTraceRaysKHR
//   VK_KHR_acceleration_structure   BLAS/TLAS (and its dependency VK_KHR_deferred_host_operations)
//   bufferDeviceAddress             SBT and AS inputs by address; root descriptors become device addresses
//   scalarBlockLayout, shaderInt64  the shaders' layout(scalar) blocks and uint64_t root descriptors
std::vector<std::string> requiredDeviceExtensions();

struct VulkanContextOptions {
    // false: any Vulkan 1.2 device with bufferDeviceAddress, without the ray-tracing extensions (the entry points of
    // VK_KHR_ray_tracing_pipeline and VK_KHR_acceleration_structure stay null). For testing buffers, images and
    // descriptor sets on a software device such as lavapipe (tests/gpu/vulkan_memory_test.cpp).
    bool rayTracing = true;
};

class VulkanContext {
public:
    // Opens the loader, makes an instance and a device on the first physical device that has everything above.
    // Throws refray::Error saying exactly what is missing: the loader, a driver, a physical device, or a device
    // with ray tracing (naming each device and what it lacks).
    explicit VulkanContext(const VulkanContextOptions& options = {});
    ~VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;

    const VulkanFunctions& vk() const { return loader_.functions(); }
    VkDevice device() const { return device_; }
    VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
    VkQueue queue() const { return queue_; }
    const DeviceInfo& info() const { return info_; }
    const RayTracingLimits& limits() const { return limits_; }

    // A memory type index with all of `flags` among `typeBits`; throws when there is none.
    uint32_t memoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const;
    // Records a primary command buffer with `record`, submits it and waits for it to finish.
    void submitAndWait(const std::function<void(VkCommandBuffer)>& record) const;

private:
    void createInstance();
    void chooseDevice();
    void createDevice();

    VulkanContextOptions options_;
    VulkanLoader loader_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    uint32_t queueFamily_ = 0;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkCommandPool commandPool_ = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory_{};
    DeviceInfo info_;
    RayTracingLimits limits_;
};

}  // namespace refray::gpu
