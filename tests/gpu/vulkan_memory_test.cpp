#include "gpu/vulkan_memory.h"

#include <gtest/gtest.h>

#include <memory>

#include "core/error.h"
#include "gpu/vulkan_descriptor_sets.h"

// These tests need a Vulkan driver but no ray tracing (a software device such as Mesa's lavapipe will do:
// VK_ICD_FILENAMES=.../lvp_icd.x86_64.json); without one they are skipped. REFRAY_VULKAN_VALIDATION=1 adds the
// Khronos validation layer where it is installed.

namespace refray::gpu {
namespace {

class VulkanMemory : public ::testing::Test {
protected:
    void SetUp() override {
        try {
            context = std::make_unique<VulkanContext>(VulkanContextOptions{false, {}});
        } catch (const Error& e) {
            GTEST_SKIP() << "no Vulkan device here: " << e.what();
        }
    }
    std::unique_ptr<VulkanContext> context;
};

TEST_F(VulkanMemory, AddressesInsideAnEmulatorBufferKeepTheirOffset) {
    dxr::GpuMemory memory;
    const std::vector<uint32_t> a(16, 1), b(64, 2);
    memory.upload(a, "a");
    const dxr::GpuVirtualAddress vb = memory.upload(b, "b");
    AddressMap map(*context, memory);
    const AddressMap::Resolved base = map.resolve(vb, 4, "b");
    const AddressMap::Resolved inside = map.resolve(vb + 40, 8, "b + 40");
    EXPECT_EQ(inside.buffer, base.buffer);  // uploaded once
    EXPECT_EQ(inside.offset, 40u);
    EXPECT_EQ(inside.address, base.address + 40);
    EXPECT_EQ(inside.bytesToEnd, b.size() * 4 - 40);
    EXPECT_NE(base.address, 0u);
    EXPECT_THROW(map.resolve(vb + b.size() * 4, 4, "past b"), Error);
}

TEST_F(VulkanMemory, AStorageImageRoundTripsItsPixels) {
    Image in(7, 5), out(7, 5);
    for (uint32_t y = 0; y < 5; ++y)
        for (uint32_t x = 0; x < 7; ++x) in.at(x, y) = vec4(float(x), float(y), 0.5f, -1.0f);
    StorageImage image(*context, 7, 5);
    image.upload(in);
    image.download(out);
    EXPECT_EQ(out.pixels(), in.pixels());
}

TEST_F(VulkanMemory, DescriptorSetsCoverEveryRegisterSpaceUpToTheHighest) {
    dxr::GpuMemory memory;
    const std::vector<float> data(256, 1.0f);
    const dxr::GpuVirtualAddress va = memory.upload(data, "data");
    AddressMap map(*context, memory);
    const AddressMap::Resolved r = map.resolve(va, 4, "data");
    StorageImage image(*context, 4, 4);
    image.upload(Image(4, 4));
    std::vector<DescriptorWrite> writes(3);
    writes[0].binding = 200;
    writes[0].type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    writes[0].imageView = image.view();
    writes[1].binding = 0;
    writes[1].type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    writes[1].buffer = {r.buffer, 0, 256};
    writes[2].set = 2;  // space2; set 1 stays empty
    writes[2].binding = 103;
    writes[2].buffer = {r.buffer, 0, VK_WHOLE_SIZE};
    const DescriptorSets sets(*context, writes);
    EXPECT_EQ(sets.sets().size(), 3u);
    EXPECT_NE(sets.pipelineLayout(), VkPipelineLayout(VK_NULL_HANDLE));
}

}  // namespace
}  // namespace refray::gpu
