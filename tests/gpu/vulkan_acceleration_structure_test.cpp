#include "gpu/vulkan_acceleration_structure.h"

#include <gtest/gtest.h>

#include <cstring>

#include "gpu_test_support.h"

namespace refray::gpu {
namespace {

using namespace refray::gpu::testing;

void expectSameInstance(const dxr::InstanceDesc& dxr, const VkAccelerationStructureInstanceKHR& vk, uint64_t reference) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) EXPECT_EQ(vk.transform.matrix[r][c], dxr.Transform[r][c]) << r << "," << c;
    EXPECT_EQ(vk.instanceCustomIndex, dxr.InstanceID);
    EXPECT_EQ(vk.mask, dxr.InstanceMask);
    EXPECT_EQ(vk.instanceShaderBindingTableRecordOffset, dxr.InstanceContributionToHitGroupIndex);
    EXPECT_EQ(vk.flags, dxr.Flags);
    EXPECT_EQ(vk.accelerationStructureReference, reference);
}

TEST(VulkanAccelerationStructure, InstanceDescFieldsKeepTheirBitsAtTheirWidths) {
    const Matrix3x4 transform = Matrix3x4::translation(vec3(1.5f, -2.0f, 3.25f));
    const uint32_t flags = dxr::INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE | dxr::INSTANCE_FLAG_FORCE_OPAQUE;
    const dxr::InstanceDesc d = dxr::makeInstanceDesc(transform, 0xFFFFFF, 0x80, 0xABCDEF, flags, 0x10000);
    const VkAccelerationStructureInstanceKHR vk = translateInstance(d, 0x123456789ABCull);
    expectSameInstance(d, vk, 0x123456789ABCull);
    EXPECT_EQ(vk.instanceCustomIndex, 0xFFFFFFu);
    EXPECT_EQ(vk.instanceShaderBindingTableRecordOffset, 0xABCDEFu);
    EXPECT_EQ(vk.flags, VK_GEOMETRY_INSTANCE_TRIANGLE_FLIP_FACING_BIT_KHR | VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR);
    // Both structs are 64 bytes with the same field order: the first 56 bytes are equal bit for bit.
    static_assert(sizeof(vk) == sizeof(d));
    EXPECT_EQ(std::memcmp(&vk, &d, 56), 0);
}

TEST(VulkanAccelerationStructure, FlagsTranslateOneToOne) {
    EXPECT_EQ(translateGeometryFlags(dxr::GEOMETRY_FLAG_OPAQUE | dxr::GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION),
              VkGeometryFlagsKHR(VK_GEOMETRY_OPAQUE_BIT_KHR | VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR));
    EXPECT_EQ(translateBuildFlags(dxr::BUILD_FLAG_PREFER_FAST_TRACE | dxr::BUILD_FLAG_PERFORM_UPDATE),
              VkBuildAccelerationStructureFlagsKHR(VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR));
    EXPECT_EQ(translateVertexFormat(dxr::Format::R32G32B32_FLOAT), VK_FORMAT_R32G32B32_SFLOAT);
    EXPECT_EQ(translateVertexFormat(dxr::Format::R16G16B16A16_SNORM), VK_FORMAT_R16G16B16A16_SNORM);
    EXPECT_EQ(translateVertexFormat(dxr::Format::R16_UINT), std::nullopt);
    EXPECT_EQ(translateIndexFormat(dxr::Format::R16_UINT), VK_INDEX_TYPE_UINT16);
    EXPECT_EQ(translateIndexFormat(dxr::Format::R32_UINT), VK_INDEX_TYPE_UINT32);
    EXPECT_EQ(translateIndexFormat(dxr::Format::UNKNOWN), VK_INDEX_TYPE_NONE_KHR);
}

class ReferenceSceneInstances : public ::testing::TestWithParam<std::string> {};

TEST_P(ReferenceSceneInstances, EveryInstanceKeepsItsTransformIDMaskContributionAndFlags) {
    std::unique_ptr<scenes::Scene> scene = scenes::loadScene(sceneFile(GetParam()));
    const dxr::TopLevelAS* tlas = scene->device().findTopLevelAS(scene->tlas());
    ASSERT_TRUE(tlas);
    std::map<const dxr::BottomLevelAS*, uint64_t> references;
    const auto instances = translateInstances(*tlas, [&](const dxr::BottomLevelAS& blas) {
        return references.emplace(&blas, 0x1000 * (references.size() + 1)).first->second;
    });
    ASSERT_EQ(instances.size(), scene->desc().instances.size());
    for (size_t i = 0; i < instances.size(); ++i) {
        SCOPED_TRACE(scene->desc().instances[i].name);
        const dxr::BuiltInstance& built = tlas->instances()[i];
        expectSameInstance(built.desc, instances[i], references.at(built.blas));
        EXPECT_EQ(instances[i].instanceShaderBindingTableRecordOffset, scene->desc().instances[i].contribution);
    }
}

INSTANTIATE_TEST_SUITE_P(ReferenceScenes, ReferenceSceneInstances,
                         ::testing::Values("proceduray-mandel-julia-pac.json", "d3d12-procedural-geometry.json"),
                         sceneTestName);

TEST(VulkanAccelerationStructure, AnInactiveInstanceGetsReferenceZero) {
    dxr::Device device;
    const std::vector<vec3> vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    dxr::GeometryDesc g;
    g.Triangles.VertexCount = 3;
    g.Triangles.VertexBuffer = {device.memory().upload(vertices, "vertices"), sizeof(vec3)};
    const dxr::GpuVirtualAddress blas = device.buildBottomLevelAS({dxr::BUILD_FLAG_NONE, {g}});
    const std::vector<dxr::InstanceDesc> descs = {
        dxr::makeInstanceDesc(Matrix3x4::identity(), 7, 0xFF, 1, 0, blas),
        dxr::makeInstanceDesc(Matrix3x4::identity(), 8, 0x01, 2, 0, 0),  // INST-6: inactive
    };
    const dxr::GpuVirtualAddress tlas = device.buildTopLevelAS(
        {dxr::BUILD_FLAG_NONE, 2, dxr::ElementsLayout::Array, device.memory().upload(descs, "instances")});
    const auto instances = translateInstances(*device.findTopLevelAS(tlas), [](const dxr::BottomLevelAS&) { return 0xB1A5ull; });
    ASSERT_EQ(instances.size(), 2u);
    expectSameInstance(descs[0], instances[0], 0xB1A5);
    expectSameInstance(descs[1], instances[1], 0);
}

}  // namespace
}  // namespace refray::gpu
