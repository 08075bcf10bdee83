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
    std::string type;           // "discrete GPU", "integrated GPU", "virtual GPU", "CPU" (lavapipe), "other"
    std::string mesaVersion;    // "25.0.7" when the driver is Mesa's (driverInfo "Mesa 25.0.7 ..."), else empty
    uint32_t index = 0;         // its position in vkEnumeratePhysicalDevices
};

// One physical device as `refray devices` lists it: what it is and whether refray can ray trace on it.
struct PhysicalDeviceSummary {
    uint32_t index = 0;
    std::string name, type, driverName, driverInfo, apiVersion;
    bool cpu = false;                   // VK_PHYSICAL_DEVICE_TYPE_CPU: a software driver such as lavapipe, not a GPU
    bool rayTracing = false;            // qualifies for refray's back end (requiredDeviceExtensions + features)
    bool rayQuery = false;              // offers VK_KHR_ray_query with the rayQuery feature
    std::vector<std::string> missing;   // what it lacks for ray tracing (empty when rayTracing)
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
    // Texture2D arrays indexed per ray (`Texture2D t[] : register(t0, space5)`, GLSL `texture2D t[]` with
    // nonuniformEXT): runtimeDescriptorArray, shaderSampledImageArrayNonUniformIndexing and dynamic indexing.
    bool sampledImageArrays = false;
    uint32_t maxBoundDescriptorSets = 4;  // one set per register space in use (CONTRACT.md)
    // Inline ray tracing (DXR 1.1 RayQuery, GLSL GL_EXT_ray_query): VK_KHR_ray_query with the rayQuery feature,
    // enabled where the device has both. A shader module that declares the RayQueryKHR capability is refused
    // without them (gpu/vulkan_pipeline.h, requireDeviceSupport).
    bool rayQuery = false;
    uint32_t maxComputeWorkGroupCount[3] = {65535, 65535, 65535};
};

// What a device needs for refray's back end, and why each item is there. The error for a machine without such a
// device lists every device with what it lacks.
//   Vulkan 1.2                      buffer device addresses and SPIR-V 1.4 in core
//   VK_KHR_ray_tracing_pipeline     raygen/miss/hit groups, shader binding tables, vkCmdTraceRaysKHR
//   VK_KHR_acceleration_structure   BLAS/TLAS (and its dependency VK_KHR_deferred_host_operations)
//   bufferDeviceAddress             SBT and AS inputs by address; root descriptors become device addresses
//   scalarBlockLayout, shaderInt64  the shaders' layout(scalar) blocks and uint64_t root descriptors
// Optional, enabled where the device has it: VK_KHR_ray_query with the rayQuery feature (RayTracingLimits::rayQuery),
// which the shaders that trace inline need (the lent NVIDIA H100's driver offers ray-tracing pipelines without it;
// Mesa's lavapipe has it).
std::vector<std::string> requiredDeviceExtensions();

struct VulkanContextOptions {
    // false: any Vulkan 1.2 device with bufferDeviceAddress, without the ray-tracing extensions (the entry points of
    // VK_KHR_ray_tracing_pipeline and VK_KHR_acceleration_structure stay null). For testing buffers, images and
    // descriptor sets on a software device such as lavapipe (tests/gpu/vulkan_memory_test.cpp).
    bool rayTracing = true;
    // Which physical device: empty picks a hardware ray-tracing device when there is one, else a software one (Mesa's
    // lavapipe); digits pick vkEnumeratePhysicalDevices' index; anything else the first device whose name or driver
    // name contains it, case-insensitively ("llvmpipe", "H100"). A device that matches but cannot ray trace, or a
    // selector that matches none, throws refray::Error listing every device. `refray render --vulkan-device`.
    std::string device;
};

// Every Vulkan physical device the loader sees, with what each lacks for refray's ray-tracing back end
// (`refray devices`). Throws refray::Error when there is no loader or no driver (the same messages as VulkanContext).
std::vector<PhysicalDeviceSummary> listVulkanDevices();

// The device `selector` picks among `devices` by the rule of VulkanContextOptions::device (for ray tracing), or
// throws refray::Error saying why none qualifies. A pure function, tested without a GPU.
uint32_t chooseRayTracingDevice(const std::vector<PhysicalDeviceSummary>& devices, const std::string& selector);

class VulkanContext {
public:
    // Opens the loader, makes an instance and a device on the first physical device that has everything above.
    // Throws refray::Error saying exactly what is missing: the loader, a driver, a physical device, or a device
    // with ray tracing (naming each device and what it lacks).
    explicit VulkanContext(const VulkanContextOptions& options = {});
    // An instance only, for listing its devices.
    struct InstanceOnly {};
    explicit VulkanContext(InstanceOnly);
    std::vector<PhysicalDeviceSummary> summaries() const;
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
