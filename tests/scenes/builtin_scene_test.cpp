// End to end: the built-in scene through real tables, Embree and DispatchRays.
#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "scenes/builtin_scene.h"

namespace refray::scenes {

namespace {
RenderResult renderWith(uint32_t threads, uint32_t width = 96, uint32_t height = 64) {
    BuiltinScene scene;
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.threads = threads;
    return scene.render(settings);
}
}  // namespace

TEST(BuiltinScene, RendersPlaneSphereShadowAndSky) {
    const RenderResult r = renderWith(2);
    const auto& st = r.dispatch.stats;
    EXPECT_EQ(st.invocationsOf(dxr::ShaderStage::RayGeneration), 96u * 64u);
    ASSERT_GE(st.raysPerDepth.size(), 3u);
    EXPECT_EQ(st.raysPerDepth[1], 96u * 64u);  // one primary ray per pixel
    EXPECT_GT(st.raysPerDepth[2], 0u);         // shadow and reflection rays
    EXPECT_GT(st.invocationsOf(dxr::ShaderStage::Intersection), 0u);
    EXPECT_GT(st.invocationsOf(dxr::ShaderStage::ClosestHit), 0u);
    EXPECT_TRUE(r.dispatch.diagnostics.empty());
    // The sky at the top row, the plane at the bottom row, the red sphere in the middle.
    const vec4 sky = r.image.at(48, 0), plane = r.image.at(48, 63), sphere = r.image.at(46, 26);
    EXPECT_GT(sky.b, sky.r);
    EXPECT_GT(plane.r, 0.05f);
    EXPECT_GT(sphere.r, 1.5f * sphere.g) << sphere.r << " " << sphere.g;
    std::set<float> distinct;
    for (const vec4& p : r.image.pixels()) distinct.insert(p.r);
    EXPECT_GT(distinct.size(), 50u);
}

TEST(BuiltinScene, DeterministicAcrossThreadCounts) {
    const RenderResult one = renderWith(1), two = renderWith(2);
    ASSERT_EQ(one.image.pixels().size(), two.image.pixels().size());
    EXPECT_EQ(std::memcmp(one.image.pixels().data(), two.image.pixels().data(), one.image.pixels().size() * sizeof(vec4)), 0);
    EXPECT_EQ(one.dispatch.stats.raysTraced, two.dispatch.stats.raysTraced);
}

TEST(BuiltinScene, AdversarialOrderDoesNotChangeAnOrderIndependentScene) {
    BuiltinScene scene;
    RenderSettings settings;
    settings.width = 64;
    settings.height = 48;
    const RenderResult ordered = scene.render(settings);
    settings.order = dxr::TraversalOrder::Adversarial;
    settings.adversarialSeed = 7;
    const RenderResult adversarial = scene.render(settings);
    EXPECT_EQ(std::memcmp(ordered.image.pixels().data(), adversarial.image.pixels().data(),
                          ordered.image.pixels().size() * sizeof(vec4)),
              0);
}

}  // namespace refray::scenes
