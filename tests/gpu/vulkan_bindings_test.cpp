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

// The path tracer's scenes: six structured buffers in spaces 1..4 and 7, two unbounded Texture2D ranges (spaces 5 and
// 6) and the static sampler s0. An unbounded range is one arrayed binding over the heap's run of Texture2D
// descriptors from its start, so the diffuse array reaches into the normal maps after it (D3D12's unbounded range
// does too); its first elements are the diffuse textures in MaterialGPU's order.
TEST(VulkanBindings, PathTracerScenesBindTextureArraysAndTheStaticSampler) {
    for (const char* file : {"textured-room.json", "cornell-box.json"}) {
        SCOPED_TRACE(file);
        std::unique_ptr<scenes::Scene> scene = scenes::loadScene(sceneFile(file));
        const auto& models = scene->desc().modelBuffers;
        CapturedDispatch captured;
        std::vector<DescriptorBinding> bindings;
        std::vector<std::string> diffusePaths, normalPaths;  // what the two arrays hold, as file names
        captured.inspect = [&](CapturedDispatch& c) {
            bindings = translateGlobalBindings(*c.globals, *c.device);
            for (auto [set, paths] : {std::pair{5u, &diffusePaths}, std::pair{6u, &normalPaths}})
                if (const DescriptorBinding* b = find(bindings, set, 100))
                    for (const dxr::Texture2D* t : b->textures) paths->push_back(t ? t->path() : "(null)");
        };
        scenes::RenderSettings settings;
        settings.width = 4, settings.height = 2;
        settings.spp = 1;
        settings.backend = recorder(captured);
        scene->render(settings);
        ASSERT_TRUE(captured.globals);
        EXPECT_EQ(bindings.size(), 12u);  // u0, t0, b0, six buffers, two texture arrays, s0
        for (auto [set, binding] : {std::pair{1u, 100u}, {2u, 100u}, {3u, 100u}, {3u, 101u}, {4u, 100u}, {7u, 100u}}) {
            const DescriptorBinding* b = find(bindings, set, binding);
            ASSERT_TRUE(b) << "set " << set << " binding " << binding;
            EXPECT_EQ(b->type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) << b->what;
        }
        const DescriptorBinding* sampler = find(bindings, 0, 300);
        ASSERT_TRUE(sampler);
        EXPECT_EQ(sampler->type, VK_DESCRIPTOR_TYPE_SAMPLER);
        EXPECT_TRUE(sampler->staticSampler);
        EXPECT_EQ(sampler->sampler.Filter, dxr::FILTER_ANISOTROPIC);
        EXPECT_EQ(sampler->sampler.AddressU, dxr::TEXTURE_ADDRESS_MODE_WRAP);

        // Diffuse textures, then the normal maps (or one null descriptor for a list without textures).
        std::vector<std::string> expectedNormal;
        for (const auto& path : models.normalTextures) expectedNormal.push_back(path.string());
        if (expectedNormal.empty()) expectedNormal = {"(null)"};
        std::vector<std::string> expectedDiffuse;
        for (const auto& path : models.diffuseTextures) expectedDiffuse.push_back(path.string());
        if (expectedDiffuse.empty()) expectedDiffuse = {"(null)"};
        expectedDiffuse.insert(expectedDiffuse.end(), expectedNormal.begin(), expectedNormal.end());
        for (uint32_t set : {5u, 6u}) {
            const DescriptorBinding* b = find(bindings, set, 100);
            ASSERT_TRUE(b) << "set " << set;
            EXPECT_EQ(b->type, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE);
            EXPECT_EQ(b->resource, Resource::SampledImages);
        }
        EXPECT_EQ(diffusePaths, expectedDiffuse);
        EXPECT_EQ(normalPaths, expectedNormal);
    }
    // The room has textures at all (so the test above compares real lists).
    EXPECT_GE(scenes::loadScene(sceneFile("textured-room.json"))->desc().modelBuffers.diffuseTextures.size(), 2u);
}

// An unbounded range whose first descriptor is no Texture2D (here a buffer) is refused, naming the register.
TEST(VulkanBindings, AnUnboundedRangeOfBuffersIsRefusedWithTheRegister) {
    dxr::Device device;
    dxr::RootSignatureDesc desc;
    desc.name = "Global";
    desc.parameters = {dxr::RootParameter::table(
        {dxr::DescriptorRange{dxr::DescriptorRangeType::SRV, dxr::kDescriptorRangeUnbounded, 3, 2, 0}})};
    dxr::GlobalRootArguments globals(dxr::RootSignature::create(desc));
    dxr::DescriptorHeap& heap = device.createDescriptorHeap(2, "heap");
    heap.setBuffer(0, dxr::DescriptorRangeType::SRV, dxr::BufferView{});
    globals.setDescriptor(0, heap.gpuHandle(0));
    try {
        translateGlobalBindings(globals, device);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("t3.., space2"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("Texture2D SRVs only"), std::string::npos) << e.what();
    }
}

// A static sampler Vulkan cannot express (MIRROR_ONCE) is refused by the translation, naming the register.
TEST(VulkanBindings, AStaticSamplerVulkanCannotExpressIsRefusedWithTheRegister) {
    dxr::Device device;
    dxr::RootSignatureDesc desc;
    desc.name = "Global";
    dxr::StaticSamplerDesc sampler;
    sampler.AddressV = dxr::TEXTURE_ADDRESS_MODE_MIRROR_ONCE;
    sampler.ShaderRegister = 4;
    sampler.RegisterSpace = 1;
    desc.staticSamplers = {sampler};
    dxr::GlobalRootArguments globals(dxr::RootSignature::create(desc));
    try {
        translateGlobalBindings(globals, device);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("s4, space1"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("AddressV is MIRROR_ONCE"), std::string::npos) << e.what();
    }
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
