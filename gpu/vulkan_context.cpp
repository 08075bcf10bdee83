#include "gpu/vulkan_context.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace refray::gpu {

namespace {

std::string versionText(uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

// NVIDIA packs its driver version as 10.8.8.6 bits; other vendors use the Vulkan encoding.
std::string driverVersionText(uint32_t vendorID, uint32_t v) {
    if (vendorID == 0x10DE)
        return std::to_string(v >> 22) + "." + std::to_string((v >> 14) & 0xFF) + "." + std::to_string((v >> 6) & 0xFF);
    return versionText(v);
}

std::string deviceTypeName(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
        default: return "other";
    }
}

// "25.0.7" from Mesa's driverInfo ("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"); empty for other drivers.
std::string mesaVersionOf(const std::string& driverInfo) {
    const size_t at = driverInfo.find("Mesa ");
    if (at == std::string::npos) return "";
    size_t end = at + 5;
    while (end < driverInfo.size() && (std::isdigit((unsigned char)driverInfo[end]) || driverInfo[end] == '.')) ++end;
    return driverInfo.substr(at + 5, end - at - 5);
}

// The features refray's shaders and host need, chained for vkGetPhysicalDeviceFeatures2 and vkCreateDevice.
struct FeatureChain {
    VkPhysicalDeviceFeatures2 base = vkStruct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
    VkPhysicalDeviceVulkan12Features vulkan12 =
        vkStruct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accelerationStructure =
        vkStruct<VkPhysicalDeviceAccelerationStructureFeaturesKHR>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR);
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rayTracingPipeline =
        vkStruct<VkPhysicalDeviceRayTracingPipelineFeaturesKHR>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR);

    FeatureChain() {
        base.pNext = &vulkan12;
        vulkan12.pNext = &accelerationStructure;
        accelerationStructure.pNext = &rayTracingPipeline;
    }
    FeatureChain(const FeatureChain&) = delete;
    FeatureChain& operator=(const FeatureChain&) = delete;
};

std::vector<VkExtensionProperties> deviceExtensions(const VulkanFunctions& vk, VkPhysicalDevice device) {
    uint32_t count = 0;
    vk.vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vk.vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
    extensions.resize(count);
    return extensions;
}

bool hasExtension(const std::vector<VkExtensionProperties>& extensions, const std::string& name) {
    return std::any_of(extensions.begin(), extensions.end(),
                       [&](const VkExtensionProperties& e) { return name == e.extensionName; });
}

// VK_KHR_ray_query with the rayQuery feature: what a shader that traces inline needs (RayTracingLimits::rayQuery).
bool deviceHasRayQueries(const VulkanFunctions& vk, VkPhysicalDevice device) {
    VkPhysicalDeviceProperties properties;
    vk.vkGetPhysicalDeviceProperties(device, &properties);
    if (properties.apiVersion < VK_API_VERSION_1_2 ||
        !hasExtension(deviceExtensions(vk, device), VK_KHR_RAY_QUERY_EXTENSION_NAME))
        return false;
    auto rayQuery = vkStruct<VkPhysicalDeviceRayQueryFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
    auto base = vkStruct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &rayQuery);
    vk.vkGetPhysicalDeviceFeatures2(device, &base);
    return rayQuery.rayQuery == VK_TRUE;
}

int64_t computeQueueFamily(const VulkanFunctions& vk, VkPhysicalDevice device) {
    uint32_t count = 0;
    vk.vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vk.vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    for (uint32_t i = 0; i < count; ++i)
        if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return i;
    return -1;
}

// What `device` lacks of the requirements (empty: it qualifies).
std::vector<std::string> missingRequirements(const VulkanFunctions& vk, VkPhysicalDevice device, bool rayTracing) {
    std::vector<std::string> missing;
    VkPhysicalDeviceProperties properties;
    vk.vkGetPhysicalDeviceProperties(device, &properties);
    if (properties.apiVersion < VK_API_VERSION_1_2)
        missing.push_back("Vulkan 1.2 (the device offers " + versionText(properties.apiVersion) + ")");
    const std::vector<VkExtensionProperties> extensions = deviceExtensions(vk, device);
    bool allExtensions = rayTracing;
    for (const std::string& name : rayTracing ? requiredDeviceExtensions() : std::vector<std::string>{})
        if (!hasExtension(extensions, name)) {
            missing.push_back(name);
            allExtensions = false;
        }
    if (properties.apiVersion >= VK_API_VERSION_1_2 && allExtensions) {
        FeatureChain features;
        vk.vkGetPhysicalDeviceFeatures2(device, &features.base);
        if (!features.vulkan12.bufferDeviceAddress) missing.push_back("the bufferDeviceAddress feature");
        if (!features.vulkan12.scalarBlockLayout) missing.push_back("the scalarBlockLayout feature");
        if (!features.base.features.shaderInt64) missing.push_back("the shaderInt64 feature");
        if (!features.accelerationStructure.accelerationStructure)
            missing.push_back("the accelerationStructure feature");
        if (!features.rayTracingPipeline.rayTracingPipeline) missing.push_back("the rayTracingPipeline feature");
    } else if (properties.apiVersion >= VK_API_VERSION_1_2 && (!rayTracing || !allExtensions)) {
        auto vulkan12 = vkStruct<VkPhysicalDeviceVulkan12Features>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
        auto base = vkStruct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &vulkan12);
        vk.vkGetPhysicalDeviceFeatures2(device, &base);
        if (!vulkan12.bufferDeviceAddress) missing.push_back("the bufferDeviceAddress feature");
        if (!rayTracing && !vulkan12.scalarBlockLayout) missing.push_back("the scalarBlockLayout feature");
    }
    if (computeQueueFamily(vk, device) < 0) missing.push_back("a compute queue");
    return missing;
}

std::string joinedList(const std::vector<std::string>& items) {
    std::string out;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i) out += i + 1 == items.size() ? " and " : ", ";
        out += items[i];
    }
    return out;
}

}  // namespace

std::vector<std::string> requiredDeviceExtensions() {
    return {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
            VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
}

VulkanContext::VulkanContext(const VulkanContextOptions& options) : options_(options) {
    createInstance();
    chooseDevice();
    createDevice();
}

VulkanContext::VulkanContext(InstanceOnly) { createInstance(); }

std::vector<PhysicalDeviceSummary> listVulkanDevices() { return VulkanContext(VulkanContext::InstanceOnly{}).summaries(); }

VulkanContext::~VulkanContext() {
    const VulkanFunctions& f = vk();
    if (device_) {
        f.vkDeviceWaitIdle(device_);
        if (commandPool_) f.vkDestroyCommandPool(device_, commandPool_, nullptr);
        f.vkDestroyDevice(device_, nullptr);
    }
    if (instance_) f.vkDestroyInstance(instance_, nullptr);
}

void VulkanContext::createInstance() {
    const VulkanFunctions& f = vk();
    uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (f.vkEnumerateInstanceVersion) f.vkEnumerateInstanceVersion(&loaderVersion);
    REFRAY_CHECK(loaderVersion >= VK_API_VERSION_1_2,
                 "the Vulkan loader " << loader_.libraryName() << " supports Vulkan " << versionText(loaderVersion)
                                      << "; refray's ray-tracing back end needs 1.2 or newer (libvulkan1 1.2+)");

    // REFRAY_VULKAN_VALIDATION=1 turns on the Khronos validation layer where it is installed.
    std::vector<const char*> layers;
    const char* validation = std::getenv("REFRAY_VULKAN_VALIDATION");
    if (validation && std::string(validation) == "1") {
        uint32_t count = 0;
        f.vkEnumerateInstanceLayerProperties(&count, nullptr);
        std::vector<VkLayerProperties> available(count);
        f.vkEnumerateInstanceLayerProperties(&count, available.data());
        const char* name = "VK_LAYER_KHRONOS_validation";
        REFRAY_CHECK(std::any_of(available.begin(), available.begin() + count,
                                 [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; }),
                     "REFRAY_VULKAN_VALIDATION=1 asks for " << name << ", which is not installed (vulkan-validationlayers)");
        layers.push_back(name);
    }

    auto app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "refray";
    app.pEngineName = "refray";
    app.apiVersion = VK_API_VERSION_1_2;
    auto info = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    info.pApplicationInfo = &app;
    info.enabledLayerCount = uint32_t(layers.size());
    info.ppEnabledLayerNames = layers.data();
    const VkResult result = f.vkCreateInstance(&info, nullptr, &instance_);
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
        throw Error("no Vulkan driver: the loader " + loader_.libraryName() +
                    " is present but vkCreateInstance returned " + resultName(result) +
                    ", so it found no usable driver (ICD). On an NVIDIA machine the ICD also needs the glvnd libraries "
                    "libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 (tools/gpu_run.sh unpacks them); "
                    "VK_LOADER_DEBUG=driver shows where the loader looked");
    REFRAY_CHECK(result == VK_SUCCESS, "Vulkan: vkCreateInstance returned " << resultName(result));
    loader_.loadInstance(instance_);
}

std::vector<PhysicalDeviceSummary> VulkanContext::summaries() const {
    const VulkanFunctions& f = vk();
    uint32_t count = 0;
    REFRAY_VK(f.vkEnumeratePhysicalDevices(instance_, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    REFRAY_VK(f.vkEnumeratePhysicalDevices(instance_, &count, devices.data()));
    std::vector<PhysicalDeviceSummary> out;
    for (uint32_t i = 0; i < count; ++i) {
        auto driver = vkStruct<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
        auto properties = vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver);
        f.vkGetPhysicalDeviceProperties(devices[i], &properties.properties);
        if (properties.properties.apiVersion >= VK_API_VERSION_1_2) f.vkGetPhysicalDeviceProperties2(devices[i], &properties);
        const VkPhysicalDeviceProperties& p = properties.properties;
        PhysicalDeviceSummary d;
        d.index = i;
        d.name = p.deviceName;
        d.type = deviceTypeName(p.deviceType);
        d.cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        d.driverName = driver.driverName;
        d.driverInfo = driver.driverInfo[0] ? std::string(driver.driverInfo) : driverVersionText(p.vendorID, p.driverVersion);
        d.apiVersion = versionText(p.apiVersion);
        d.missing = missingRequirements(f, devices[i], true);
        d.rayTracing = d.missing.empty();
        d.rayQuery = deviceHasRayQueries(f, devices[i]);
        out.push_back(std::move(d));
    }
    return out;
}

void VulkanContext::chooseDevice() {
    const VulkanFunctions& f = vk();
    uint32_t count = 0;
    REFRAY_VK(f.vkEnumeratePhysicalDevices(instance_, &count, nullptr));
    REFRAY_CHECK(count > 0, "no Vulkan physical device: the loader " << loader_.libraryName()
                                                                     << " and a driver are present, but the driver "
                                                                        "reports no device (is the GPU visible to this "
                                                                        "process? nvidia-smi; for a CPU driver: bash "
                                                                        "tools/setup.sh installs Mesa's lavapipe)");
    std::vector<VkPhysicalDevice> devices(count);
    REFRAY_VK(f.vkEnumeratePhysicalDevices(instance_, &count, devices.data()));

    uint32_t chosen = 0;
    if (options_.rayTracing) {
        chosen = chooseRayTracingDevice(summaries(), options_.device);
    } else {
        // Buffers and images only (tests): the first device with Vulkan 1.2 and buffer device addresses.
        std::ostringstream report;
        int best = -1;
        for (uint32_t i = 0; i < count && best < 0; ++i) {
            VkPhysicalDeviceProperties properties;
            f.vkGetPhysicalDeviceProperties(devices[i], &properties);
            const std::vector<std::string> missing = missingRequirements(f, devices[i], false);
            if (missing.empty()) best = int(i);
            else report << "\n  device " << i << " '" << properties.deviceName << "' lacks " << joinedList(missing);
        }
        REFRAY_CHECK(best >= 0, "no Vulkan 1.2 device with buffer device addresses:" << report.str());
        chosen = uint32_t(best);
    }
    physicalDevice_ = devices[chosen];
    info_.index = chosen;
    queueFamily_ = uint32_t(computeQueueFamily(f, physicalDevice_));
}

uint32_t chooseRayTracingDevice(const std::vector<PhysicalDeviceSummary>& devices, const std::string& selector) {
    const auto listing = [&] {
        std::ostringstream report;
        for (const PhysicalDeviceSummary& d : devices) {
            report << "\n  device " << d.index << " '" << d.name << "' (" << d.type << ", " << d.driverName << ")";
            if (d.rayTracing) report << ": ray tracing";
            else report << " lacks " << joinedList(d.missing);
        }
        return report.str();
    };
    const std::string requirement = "refray needs " + joinedList(requiredDeviceExtensions()) +
                                    " with the bufferDeviceAddress, scalarBlockLayout, shaderInt64, "
                                    "accelerationStructure and rayTracingPipeline features (Vulkan 1.2)";
    if (!selector.empty()) {
        const bool isIndex = std::all_of(selector.begin(), selector.end(), [](unsigned char c) { return std::isdigit(c); });
        const auto lower = [](std::string t) {
            std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return char(std::tolower(c)); });
            return t;
        };
        for (const PhysicalDeviceSummary& d : devices) {
            const bool match = isIndex ? std::to_string(d.index) == selector
                                       : lower(d.name).find(lower(selector)) != std::string::npos ||
                                             lower(d.driverName).find(lower(selector)) != std::string::npos;
            if (!match) continue;
            if (!d.rayTracing)
                throw Error("the Vulkan device '" + selector + "' selects device " + std::to_string(d.index) + " '" +
                            d.name + "', which cannot ray trace: it lacks " + joinedList(d.missing) + "; " +
                            requirement + "." + listing());
            return d.index;
        }
        throw Error("no Vulkan device matches '" + selector + "' (an index, or part of a device or driver name; "
                    "'refray devices' lists them):" + listing());
    }
    // A hardware device first (discrete, then integrated, then virtual or other), a CPU driver (lavapipe) last.
    const auto rank = [](const PhysicalDeviceSummary& d) {
        if (d.cpu) return 4;
        if (d.type == "discrete GPU") return 0;
        if (d.type == "integrated GPU") return 1;
        if (d.type == "virtual GPU") return 2;
        return 3;
    };
    int best = -1;
    for (const PhysicalDeviceSummary& d : devices)
        if (d.rayTracing && (best < 0 || rank(d) < rank(devices[size_t(best)]))) best = int(&d - devices.data());
    if (best < 0)
        throw Error("no Vulkan device with ray tracing: " + requirement + "." + listing() +
                    "\n  (bash tools/setup.sh, as root, installs Mesa's lavapipe, a CPU driver that ray traces)");
    return devices[size_t(best)].index;
}

void VulkanContext::createDevice() {
    const VulkanFunctions& f = vk();

    // Properties: provenance and the ray-tracing limits.
    auto rayTracing = vkStruct<VkPhysicalDeviceRayTracingPipelinePropertiesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR);
    auto accelerationStructure = vkStruct<VkPhysicalDeviceAccelerationStructurePropertiesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR, &rayTracing);
    auto driver = vkStruct<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES,
                                                             options_.rayTracing ? &accelerationStructure : nullptr);
    auto properties = vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver);
    f.vkGetPhysicalDeviceProperties2(physicalDevice_, &properties);
    const VkPhysicalDeviceProperties& p = properties.properties;
    info_.name = p.deviceName;
    info_.driverName = driver.driverName;
    info_.driverVersion = driver.driverInfo[0] ? std::string(driver.driverInfo) : driverVersionText(p.vendorID, p.driverVersion);
    info_.apiVersion = versionText(p.apiVersion);
    info_.loader = loader_.libraryName();
    info_.type = deviceTypeName(p.deviceType);
    info_.mesaVersion = mesaVersionOf(info_.driverVersion);
    limits_.shaderGroupHandleSize = rayTracing.shaderGroupHandleSize;
    limits_.shaderGroupHandleAlignment = rayTracing.shaderGroupHandleAlignment;
    limits_.shaderGroupBaseAlignment = rayTracing.shaderGroupBaseAlignment;
    limits_.maxRayRecursionDepth = rayTracing.maxRayRecursionDepth;
    limits_.maxShaderGroupStride = rayTracing.maxShaderGroupStride;
    limits_.minAccelerationStructureScratchOffsetAlignment =
        accelerationStructure.minAccelerationStructureScratchOffsetAlignment;
    limits_.maxUniformBufferRange = p.limits.maxUniformBufferRange;
    limits_.maxBoundDescriptorSets = p.limits.maxBoundDescriptorSets;
    for (int axis = 0; axis < 3; ++axis) limits_.maxComputeWorkGroupCount[axis] = p.limits.maxComputeWorkGroupCount[axis];
    f.vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memory_);

    uint32_t familyCount = 0;
    f.vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    f.vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice_, &familyCount, families.data());
    if (families[queueFamily_].timestampValidBits > 0 && p.limits.timestampComputeAndGraphics)
        limits_.timestampPeriod = p.limits.timestampPeriod;

    // Features: the required ones, plus primitive culling where the device has it, plus ray queries where the
    // device offers VK_KHR_ray_query (its feature struct is chained only then).
    const bool rayQueryExtension =
        options_.rayTracing && hasExtension(deviceExtensions(f, physicalDevice_), VK_KHR_RAY_QUERY_EXTENSION_NAME);
    FeatureChain available;
    if (!options_.rayTracing) available.vulkan12.pNext = nullptr;  // no ray-tracing feature structs
    auto availableRayQuery =
        vkStruct<VkPhysicalDeviceRayQueryFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
    if (rayQueryExtension) available.rayTracingPipeline.pNext = &availableRayQuery;
    f.vkGetPhysicalDeviceFeatures2(physicalDevice_, &available.base);
    limits_.rayQuery = rayQueryExtension && availableRayQuery.rayQuery == VK_TRUE;
    limits_.rayTraversalPrimitiveCulling = available.rayTracingPipeline.rayTraversalPrimitiveCulling == VK_TRUE;
    FeatureChain enabled;
    if (!options_.rayTracing) enabled.vulkan12.pNext = nullptr;
    enabled.base.features.shaderInt64 = available.base.features.shaderInt64;
    enabled.vulkan12.bufferDeviceAddress = VK_TRUE;
    enabled.vulkan12.scalarBlockLayout = VK_TRUE;
    enabled.accelerationStructure.accelerationStructure = VK_TRUE;
    enabled.rayTracingPipeline.rayTracingPipeline = VK_TRUE;
    enabled.rayTracingPipeline.rayTraversalPrimitiveCulling = available.rayTracingPipeline.rayTraversalPrimitiveCulling;
    // Texture arrays (unbounded Texture2D ranges) where the device has them; a dispatch that binds one refuses
    // to run without them (gpu/vulkan_dispatch.cpp).
    limits_.sampledImageArrays = available.base.features.shaderSampledImageArrayDynamicIndexing &&
                                 available.vulkan12.runtimeDescriptorArray &&
                                 available.vulkan12.shaderSampledImageArrayNonUniformIndexing;
    enabled.base.features.shaderSampledImageArrayDynamicIndexing = limits_.sampledImageArrays;
    enabled.vulkan12.runtimeDescriptorArray = limits_.sampledImageArrays;
    enabled.vulkan12.shaderSampledImageArrayNonUniformIndexing = limits_.sampledImageArrays;
    auto enabledRayQuery =
        vkStruct<VkPhysicalDeviceRayQueryFeaturesKHR>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR);
    enabledRayQuery.rayQuery = VK_TRUE;
    if (limits_.rayQuery) enabled.rayTracingPipeline.pNext = &enabledRayQuery;

    const float priority = 1.0f;
    auto queue = vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue.queueFamilyIndex = queueFamily_;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    std::vector<std::string> extensionNames =
        options_.rayTracing ? requiredDeviceExtensions() : std::vector<std::string>{};
    if (limits_.rayQuery) extensionNames.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
    std::vector<const char*> extensions;
    for (const std::string& e : extensionNames) extensions.push_back(e.c_str());
    auto info = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    info.pNext = &enabled.base;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue;
    info.enabledExtensionCount = uint32_t(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    REFRAY_VK(f.vkCreateDevice(physicalDevice_, &info, nullptr, &device_));
    loader_.loadDevice(device_, options_.rayTracing);
    f.vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

    auto pool = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    pool.queueFamilyIndex = queueFamily_;
    REFRAY_VK(f.vkCreateCommandPool(device_, &pool, nullptr, &commandPool_));
}

uint32_t VulkanContext::memoryType(uint32_t typeBits, VkMemoryPropertyFlags flags) const {
    for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags) return i;
    throw Error("the Vulkan device has no memory type with property flags 0x" + [&] {
        std::ostringstream s;
        s << std::hex << flags;
        return s.str();
    }() + " for this resource");
}

void VulkanContext::submitAndWait(const std::function<void(VkCommandBuffer)>& record) const {
    const VulkanFunctions& f = vk();
    auto allocate = vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    allocate.commandPool = commandPool_;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    REFRAY_VK(f.vkAllocateCommandBuffers(device_, &allocate, &commands));
    VkFence fence = VK_NULL_HANDLE;
    try {
        auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        REFRAY_VK(f.vkBeginCommandBuffer(commands, &begin));
        record(commands);
        REFRAY_VK(f.vkEndCommandBuffer(commands));
        auto fenceInfo = vkStruct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
        REFRAY_VK(f.vkCreateFence(device_, &fenceInfo, nullptr, &fence));
        auto submit = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &commands;
        REFRAY_VK(f.vkQueueSubmit(queue_, 1, &submit, fence));
        REFRAY_VK(f.vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX));
    } catch (...) {
        if (fence) f.vkDestroyFence(device_, fence, nullptr);
        f.vkFreeCommandBuffers(device_, commandPool_, 1, &commands);
        throw;
    }
    f.vkDestroyFence(device_, fence, nullptr);
    f.vkFreeCommandBuffers(device_, commandPool_, 1, &commands);
}

}  // namespace refray::gpu
