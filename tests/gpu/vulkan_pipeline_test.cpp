#include "gpu/vulkan_pipeline.h"

#include <gtest/gtest.h>

#include <set>

#include "gpu_test_support.h"

namespace refray::gpu {
namespace {

using namespace refray::gpu::testing;

// One group per state-object entry, in entry order, with the entry's shaders as stages loaded from
// <dir>/<library>/<Export>.<stage>.spv.
void expectShapeOf(const dxr::StateObject& so, const std::string& library) {
    const PipelineShape shape = describePipeline(so, REFRAY_SPIRV_DIR, library);
    ASSERT_EQ(shape.groups.size(), so.entries().size());
    EXPECT_EQ(shape.maxRecursionDepth, so.maxTraceRecursionDepth());
    std::set<std::string> files;
    for (const PipelineStage& s : shape.stages) {
        EXPECT_TRUE(files.insert(s.spirv.string()).second) << "loaded twice: " << s.spirv;
        EXPECT_EQ(s.spirv, spirvPath(REFRAY_SPIRV_DIR, library, s.exportName, s.stage));
        // Every export the reference pipelines use has a compiled GLSL port.
        EXPECT_TRUE(std::filesystem::exists(s.spirv)) << "no SPIR-V for export '" << s.exportName << "': " << s.spirv;
    }
    const auto stageName = [&](uint32_t index) {
        return index == VK_SHADER_UNUSED_KHR ? std::string() : shape.stages.at(index).exportName;
    };
    for (size_t i = 0; i < shape.groups.size(); ++i) {
        const dxr::ProgramEntry& e = so.entries()[i];
        const PipelineGroup& g = shape.groups[i];
        SCOPED_TRACE(e.name);
        EXPECT_EQ(g.name, e.name);
        if (e.kind == dxr::ProgramEntry::Kind::HitGroup) {
            EXPECT_EQ(g.type, e.hitGroupType == dxr::HitGroupType::Triangles
                                  ? VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR
                                  : VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR);
            EXPECT_EQ(stageName(g.closestHit), e.closestHit ? e.closestHit->name : "");
            EXPECT_EQ(stageName(g.anyHit), e.anyHit ? e.anyHit->name : "");
            EXPECT_EQ(stageName(g.intersection), e.intersection ? e.intersection->name : "");
            EXPECT_EQ(g.general, VK_SHADER_UNUSED_KHR);
        } else {
            EXPECT_EQ(g.type, VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR);
            EXPECT_EQ(stageName(g.general), e.shader->name);
        }
    }
}

TEST(VulkanPipeline, ReferenceScenePipelinesHaveAGroupPerEntryAndAPortPerExport) {
    for (const char* file : {"proceduray-mandel-julia-pac.json", "d3d12-procedural-geometry.json"}) {
        SCOPED_TRACE(file);
        std::unique_ptr<scenes::Scene> scene = scenes::loadScene(sceneFile(file));
        expectShapeOf(*scene->pipeline(procedural::Precision::Float), scene->desc().shaderLibrary);
    }
    scenes::BuiltinScene builtin;
    expectShapeOf(*builtin.pipeline(), "builtin");
}

TEST(VulkanPipeline, SpirvPathFollowsTheContract) {
    EXPECT_EQ(spirvPath("/s", "proceduray", "Intersection_Julia", dxr::ShaderStage::Intersection),
              std::filesystem::path("/s/proceduray/Intersection_Julia.rint.spv"));
    EXPECT_EQ(stageExtension(dxr::ShaderStage::ClosestHit), "rchit");
    EXPECT_EQ(stageExtension(dxr::ShaderStage::AnyHit), "rahit");
    EXPECT_EQ(stageExtension(dxr::ShaderStage::Miss), "rmiss");
    EXPECT_EQ(stageExtension(dxr::ShaderStage::RayGeneration), "rgen");
}

TEST(VulkanPipeline, AovShadersReplaceEveryClosestHitAndMissButKeepIntersections) {
    std::unique_ptr<scenes::Scene> scene = scenes::loadScene(sceneFile("proceduray-mandel-julia-pac.json"));
    const dxr::StateObject& so = *scene->pipeline(procedural::Precision::Float);
    const AovShaders aov{"/aov/ClosestHit_AOV.rchit.spv", "/aov/Miss_AOV.rmiss.spv", 48};
    const PipelineShape shape = describePipeline(so, "/s", "proceduray", &aov);
    for (size_t i = 0; i < shape.groups.size(); ++i) {
        const dxr::ProgramEntry& e = so.entries()[i];
        const PipelineGroup& g = shape.groups[i];
        if (e.kind == dxr::ProgramEntry::Kind::HitGroup) {
            ASSERT_NE(g.closestHit, VK_SHADER_UNUSED_KHR) << e.name;
            EXPECT_EQ(shape.stages[g.closestHit].spirv, aov.closestHit);
            EXPECT_TRUE(shape.stages[g.closestHit].aovClosestHit);
            if (e.intersection) {
                EXPECT_EQ(shape.stages[g.intersection].exportName, e.intersection->name);
            }
        } else if (e.kind == dxr::ProgramEntry::Kind::Miss) {
            EXPECT_EQ(shape.stages[g.general].spirv, aov.miss);
        }
    }
}

}  // namespace
}  // namespace refray::gpu
