// Ray queries on the Vulkan back end without a GPU: which compiled ports trace inline (their SPIR-V declares
// RayQueryKHR), the compute module's local size, and the message for a device without VK_KHR_ray_query (the lent
// NVIDIA H100's driver offers ray-tracing pipelines but no ray queries; docs/vulkan-backend.md, "Ray queries").
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/error.h"
#include "gpu/vulkan_context.h"
#include "gpu/vulkan_pipeline.h"

namespace refray::gpu {
namespace {

namespace fs = std::filesystem;
const fs::path kSpirv = REFRAY_SPIRV_DIR;

SpirvFacts factsOf(const std::string& library, const std::string& file) {
    const fs::path path = kSpirv / library / file;
    return inspectSpirv(readSpirvModule(path, file, "test"), path.string());
}

TEST(VulkanRayQuery, ThePortsThatTraceInlineDeclareRayQueriesAndNoOtherDoes) {
    for (const char* file : {"MyClosestHitShader_Triangle_InlineShadow.rchit.spv",
                             "MyClosestHitShader_AABB_InlineShadow.rchit.spv", "InlineAmbientOcclusionCS.comp.spv",
                             "InlineAmbientOcclusionCS.aov.comp.spv"})
        EXPECT_TRUE(factsOf("d3d12-procedural-geometry", file).rayQuery) << file;
    // Every other module of every library traces with TraceRay only, so any ray-tracing device runs it.
    size_t others = 0;
    for (const auto& entry : fs::recursive_directory_iterator(kSpirv)) {
        const std::string name = entry.path().filename().string();
        if (entry.path().extension() != ".spv" || name.find("Inline") != std::string::npos) continue;
        ++others;
        EXPECT_FALSE(inspectSpirv(readSpirvModule(entry.path(), name, "test"), name).rayQuery) << entry.path();
    }
    EXPECT_GT(others, 20u);
}

TEST(VulkanRayQuery, TheComputeModulesLocalSizeIsTheExportsNumthreads) {
    for (const bool aov : {false, true}) {
        const fs::path path = computeSpirvPath(kSpirv, "d3d12-procedural-geometry", "InlineAmbientOcclusionCS", aov);
        EXPECT_EQ(path.filename(), aov ? "InlineAmbientOcclusionCS.aov.comp.spv" : "InlineAmbientOcclusionCS.comp.spv");
        const SpirvFacts facts = inspectSpirv(readSpirvModule(path, "InlineAmbientOcclusionCS", "comp"), path.string());
        ASSERT_TRUE(facts.localSize) << path;
        EXPECT_EQ(*facts.localSize, (std::array<uint32_t, 3>{8, 8, 1})) << "[numthreads(8, 8, 1)]";
    }
    // A ray-tracing stage has no local size.
    EXPECT_FALSE(factsOf("d3d12-procedural-geometry", "MyRaygenShader.rgen.spv").localSize);
}

TEST(VulkanRayQuery, ADeviceWithoutRayQueriesIsNamedWithWhatItLacks) {
    DeviceInfo h100;
    h100.name = "NVIDIA H100 80GB HBM3";
    h100.driverName = "NVIDIA";
    h100.driverVersion = "580.159.04";
    h100.index = 0;
    SpirvFacts inlineFacts;
    inlineFacts.rayQuery = true;
    const fs::path file = "spv/d3d12-procedural-geometry/InlineAmbientOcclusionCS.comp.spv";
    const std::string refusal = deviceRefusal(h100, false, inlineFacts, "InlineAmbientOcclusionCS", "comp", file);
    for (const char* part : {"export 'InlineAmbientOcclusionCS' (comp, spv/d3d12-procedural-geometry/"
                             "InlineAmbientOcclusionCS.comp.spv) traces inline",
                             "device 0 'NVIDIA H100 80GB HBM3' (NVIDIA 580.159.04)", "VK_KHR_ray_query",
                             "rayQuery feature", "refray devices", "--vulkan-device llvmpipe"})
        EXPECT_NE(refusal.find(part), std::string::npos) << part << "\n" << refusal;
    EXPECT_EQ(deviceRefusal(h100, true, inlineFacts, "InlineAmbientOcclusionCS", "comp", file), "");
    EXPECT_EQ(deviceRefusal(h100, false, SpirvFacts{}, "MyRaygenShader", "rgen", file), "") << "no ray queries used";
}

TEST(VulkanRayQuery, WordsThatAreNotSpirvAreRefused) {
    EXPECT_THROW(inspectSpirv({1, 2, 3}, "three words"), Error);
    std::vector<uint32_t> truncated = {0x07230203u, 0x00010500u, 0, 100, 0, (5u << 16) | 17u, 4472u};
    EXPECT_THROW(inspectSpirv(truncated, "truncated"), Error);
    truncated.resize(5 + 5, 0);
    truncated[5] = (2u << 16) | 17u;  // OpCapability RayQueryKHR
    truncated[6] = 4472u;
    truncated[7] = (2u << 16) | 17u;  // OpCapability Shader
    truncated[8] = 1u;
    truncated[9] = (1u << 16) | 54u;  // stops at the first OpFunction
    EXPECT_TRUE(inspectSpirv(truncated, "capabilities").rayQuery);
}

}  // namespace
}  // namespace refray::gpu
