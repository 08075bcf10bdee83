// The traversal shortcuts on the reference scenes (DispatchOptions::specialise): the same image, bit for bit,
// and the same shader invocations as gathering every candidate; every ray takes the bounded gather (the ports'
// intersection shaders run in record groups, which the occlusion query cannot give them). With the shortcuts, the ports'
// intersection shaders also return from a ReportHit that ends the search (ReportHitEnd::Return) instead of unwinding,
// so this also checks the ports keep that promise.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "scenes/scene.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {
namespace {

const std::string kSourceDir = REFRAY_SOURCE_DIR;

void expectSameRender(const std::string& file, uint32_t shadowMissIndex) {
    SCOPED_TRACE(file);
    Scene scene(loadSceneFile(kSourceDir + "/scenes/" + file));
    RenderSettings settings;
    settings.width = 48;
    settings.height = 27;
    settings.specialise = false;
    const RenderResult all = scene.render(settings);
    settings.specialise = true;
    const RenderResult fast = scene.render(settings);

    ASSERT_EQ(all.image.pixels().size(), fast.image.pixels().size());
    EXPECT_EQ(std::memcmp(all.image.pixels().data(), fast.image.pixels().data(), all.image.pixels().size() * sizeof(vec4)), 0);
    const dxr::DispatchStats& a = all.dispatch.stats;
    const dxr::DispatchStats& f = fast.dispatch.stats;
    EXPECT_EQ(a.raysTraced, f.raysTraced);
    // The ports' intersection shaders run in record groups (emulator/intersection_wave.h), so no ray takes the
    // occlusion query (it runs candidates inside Embree's traversal, one ray at a time): the bounded gather meets the
    // boxes in the same order as gathering all, and every shader runs as often.
    for (dxr::ShaderStage stage : {dxr::ShaderStage::RayGeneration, dxr::ShaderStage::Intersection,
                                   dxr::ShaderStage::ClosestHit, dxr::ShaderStage::Miss})
        EXPECT_EQ(a.invocationsOf(stage), f.invocationsOf(stage)) << dxr::toString(stage);
    EXPECT_LE(f.candidates, a.candidates);

    EXPECT_EQ(a.raysPerGatherMode[0], a.raysTraced);
    uint64_t shadowRays = 0;
    for (const dxr::RayTypeCounts& t : f.raysPerType)
        if (t.key.missShaderIndex == shadowMissIndex) shadowRays += t.total();
    EXPECT_GT(shadowRays, 0u);
    EXPECT_EQ(f.raysPerGatherMode[2], 0u);
    EXPECT_EQ(f.raysPerGatherMode[1], f.raysTraced);
}

TEST(TraversalShortcutsScenes, D3D12RendersTheSameImage) { expectSameRender("d3d12-procedural-geometry.json", 1); }

TEST(TraversalShortcutsScenes, ProcedurayRendersTheSameImage) { expectSameRender("proceduray-mandel-julia-pac.json", 1); }

}  // namespace
}  // namespace refray::scenes
