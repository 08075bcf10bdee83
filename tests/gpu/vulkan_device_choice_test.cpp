// Which Vulkan device `--device vulkan` takes (gpu::chooseRayTracingDevice): a pure function of the device list,
// tested without a GPU.
#include <gtest/gtest.h>

#include "core/error.h"
#include "gpu/vulkan_context.h"
#include "tests/error_of.h"

namespace refray::gpu {
namespace {

using testing::errorOf;

PhysicalDeviceSummary device(uint32_t index, std::string name, std::string type, std::string driver, bool rayTracing) {
    PhysicalDeviceSummary d;
    d.index = index;
    d.name = std::move(name);
    d.type = std::move(type);
    d.cpu = d.type == "CPU";
    d.driverName = std::move(driver);
    d.rayTracing = rayTracing;
    if (!rayTracing) d.missing = {"VK_KHR_ray_tracing_pipeline"};
    return d;
}

const std::vector<PhysicalDeviceSummary> kMachine = {
    device(0, "llvmpipe (LLVM 15.0.6, 256 bits)", "CPU", "llvmpipe", true),
    device(1, "Intel(R) UHD Graphics 630", "integrated GPU", "Intel open-source Mesa driver", false),
    device(2, "NVIDIA H100 80GB HBM3", "discrete GPU", "NVIDIA", true),
};

TEST(VulkanDeviceChoice, AHardwareRayTracingDeviceComesBeforeLavapipe) {
    EXPECT_EQ(chooseRayTracingDevice(kMachine, ""), 2u);
}

TEST(VulkanDeviceChoice, LavapipeWhenNoHardwareDeviceRayTraces) {
    const std::vector<PhysicalDeviceSummary> noGpu = {kMachine[0], kMachine[1]};
    EXPECT_EQ(chooseRayTracingDevice(noGpu, ""), 0u);
}

TEST(VulkanDeviceChoice, AnIntegratedGpuComesBeforeACpuDriver) {
    std::vector<PhysicalDeviceSummary> devices = kMachine;
    devices[1].rayTracing = true;
    devices[1].missing.clear();
    devices.pop_back();
    EXPECT_EQ(chooseRayTracingDevice(devices, ""), 1u);
}

TEST(VulkanDeviceChoice, PickedByIndexOrByPartOfItsDeviceOrDriverName) {
    EXPECT_EQ(chooseRayTracingDevice(kMachine, "0"), 0u);
    EXPECT_EQ(chooseRayTracingDevice(kMachine, "llvmpipe"), 0u);
    EXPECT_EQ(chooseRayTracingDevice(kMachine, "LLVMPIPE"), 0u);
    EXPECT_EQ(chooseRayTracingDevice(kMachine, "h100"), 2u);
    EXPECT_EQ(chooseRayTracingDevice(kMachine, "nvidia"), 2u);
}

TEST(VulkanDeviceChoice, ASelectedDeviceThatCannotRayTraceIsRefusedSayingWhatItLacks) {
    const std::string message = errorOf([&] { chooseRayTracingDevice(kMachine, "Intel"); });
    EXPECT_NE(message.find("device 1 'Intel(R) UHD Graphics 630', which cannot ray trace"), std::string::npos) << message;
    EXPECT_NE(message.find("VK_KHR_ray_tracing_pipeline"), std::string::npos) << message;
}

TEST(VulkanDeviceChoice, ASelectorThatMatchesNothingListsEveryDevice) {
    const std::string message = errorOf([&] { chooseRayTracingDevice(kMachine, "7"); });
    EXPECT_NE(message.find("no Vulkan device matches '7'"), std::string::npos) << message;
    for (const PhysicalDeviceSummary& d : kMachine) EXPECT_NE(message.find(d.name), std::string::npos) << message;
}

TEST(VulkanDeviceChoice, NoRayTracingDeviceNamesTheInstallCommand) {
    const std::vector<PhysicalDeviceSummary> none = {kMachine[1]};
    const std::string message = errorOf([&] { chooseRayTracingDevice(none, ""); });
    EXPECT_NE(message.find("no Vulkan device with ray tracing"), std::string::npos) << message;
    EXPECT_NE(message.find("bash tools/setup.sh"), std::string::npos) << message;
    EXPECT_NE(message.find("lacks VK_KHR_ray_tracing_pipeline"), std::string::npos) << message;
}

}  // namespace
}  // namespace refray::gpu
