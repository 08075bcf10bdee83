#include "gpu/vulkan_bindings.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "gpu_test_support.h"

namespace refray::gpu {
namespace {

using namespace refray::gpu::testing;
using Resource = DescriptorBinding::Resource;

const DescriptorBinding* find(const std::vector<DescriptorBinding>& bindings, uint32_t set, uint32_t binding) {
    for (const DescriptorBinding& b : bindings)
        if (b.set == set && b.binding == binding) return &b;
    return nullptr;
}

void expectBinding(const std::vector<DescriptorBinding>& bindings, uint32_t binding, VkDescriptorType type, Resource resource) {
    const DescriptorBinding* b = find(bindings, 0, binding);
    ASSERT_TRUE(b) << "binding " << binding;
    EXPECT_EQ(b->type, type) << b->what;
    EXPECT_EQ(b->resource, resource) << b->what;
}

// Both reference scenes bind u0 (the render target), t0 (the TLAS), b0 (scene constants), t3 (a structured buffer)
// and the t1..t2 table of index and vertex buffers.
TEST(VulkanBindings, ReferenceScenesBindByRegisterPlusShift) {
    for (const char* file : {"proceduray-mandel-julia-pac.json", "d3d12-procedural-geometry.json"}) {
        SCOPED_TRACE(file);
        std::unique_ptr<scenes::Scene> scene = scenes::loadScene(sceneFile(file));
        CapturedDispatch captured;
        std::vector<DescriptorBinding> bindings;
        uint32_t targetWidth = 0, targetHeight = 0;
        captured.inspect = [&](CapturedDispatch& c) {
            bindings = translateGlobalBindings(*c.globals, *c.device);
            if (const DescriptorBinding* target = find(bindings, 0, 200); target && target->image) {
                targetWidth = target->image->width();
                targetHeight = target->image->height();
            }
        };
        scenes::RenderSettings settings;
        settings.width = 4, settings.height = 2;
        settings.backend = recorder(captured);
        scene->render(settings);
        ASSERT_TRUE(captured.globals);
        EXPECT_EQ(bindings.size(), 6u);
        expectBinding(bindings, 200, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, Resource::StorageImage);
        expectBinding(bindings, 100, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, Resource::AccelerationStructure);
        expectBinding(bindings, 0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, Resource::Buffer);
        expectBinding(bindings, 103, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, Resource::Buffer);
        expectBinding(bindings, 101, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, Resource::Buffer);
        expectBinding(bindings, 102, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, Resource::Buffer);
        ASSERT_TRUE(find(bindings, 0, 100));
        EXPECT_EQ(find(bindings, 0, 100)->address, scene->tlas());
        EXPECT_EQ(targetWidth, 4u);  // the render target the shaders write
        EXPECT_EQ(targetHeight, 2u);
        EXPECT_GT(find(bindings, 0, 102)->size, 0u);  // a table view keeps its size
    }
}

TEST(VulkanBindings, BuiltinSceneBindsTheSameRegisters) {
    scenes::BuiltinScene scene;
    CapturedDispatch captured;
    std::vector<DescriptorBinding> bindings;
    captured.inspect = [&](CapturedDispatch& c) { bindings = translateGlobalBindings(*c.globals, *c.device); };
    scenes::RenderSettings settings;
    settings.width = 4, settings.height = 2;
    settings.backend = recorder(captured);
    scene.render(settings);
    ASSERT_TRUE(captured.globals);
    EXPECT_EQ(bindings.size(), 3u);
    expectBinding(bindings, 200, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, Resource::StorageImage);
    expectBinding(bindings, 100, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, Resource::AccelerationStructure);
    expectBinding(bindings, 0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, Resource::Buffer);
}

TEST(VulkanBindings, GlobalRootConstantsAreRefusedWithTheRegister) {
    dxr::Device device;
    dxr::RootSignatureDesc desc;
    desc.name = "Global";
    desc.parameters = {dxr::RootParameter::constants(4, 2, 1)};
    dxr::GlobalRootArguments globals(dxr::RootSignature::create(desc));
    try {
        translateGlobalBindings(globals, device);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("b2"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("global root constants"), std::string::npos) << e.what();
    }
}

TEST(VulkanBindings, ShiftsFollowDxcsConvention) {
    EXPECT_EQ(bindingShift(dxr::DescriptorRangeType::CBV), 0u);
    EXPECT_EQ(bindingShift(dxr::DescriptorRangeType::SRV), 100u);
    EXPECT_EQ(bindingShift(dxr::DescriptorRangeType::UAV), 200u);
    EXPECT_EQ(bindingShift(dxr::DescriptorRangeType::Sampler), 300u);
}

}  // namespace
}  // namespace refray::gpu
