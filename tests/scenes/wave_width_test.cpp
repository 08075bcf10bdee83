// The wave executor (docs/emulator.md, "Waves") on every scene file: the image, bit for bit, and the counts of rays,
// candidates and shader invocations are the same for every wave width (1 included), thread count and traversal
// order, in float, double and perturbed arithmetic. A lane's result may depend on nothing but its own ray: not on
// the lanes beside it, nor on how many there are.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "scenes/scene.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {
namespace {

const std::string kSourceDir = REFRAY_SOURCE_DIR;

struct Variant {
    uint32_t waveWidth;
    uint32_t threads;
};

void expectSameStats(const dxr::DispatchStats& a, const dxr::DispatchStats& b) {
    EXPECT_EQ(a.raysTraced, b.raysTraced);
    EXPECT_EQ(a.candidates, b.candidates);
    EXPECT_EQ(a.rayQueries, b.rayQueries);
    for (size_t s = 0; s < a.invocations.size(); ++s) EXPECT_EQ(a.invocations[s], b.invocations[s]) << "stage " << s;
}

// Renders `file` with `settings` at every wave width and thread count of the list and compares each with the first.
void expectSameForEveryWidth(const std::string& file, RenderSettings settings) {
    SCOPED_TRACE(file);
    Scene scene(loadSceneFile(kSourceDir + "/scenes/" + file));
    settings.width = 40;
    settings.height = 24;
    settings.waveWidth = 32;  // the default
    settings.threads = 1;
    const RenderResult reference = scene.render(settings);
    for (const Variant v : {Variant{1, 1}, Variant{3, 2}, Variant{8, 1}, Variant{16, 2}}) {
        SCOPED_TRACE("wave width " + std::to_string(v.waveWidth) + ", " + std::to_string(v.threads) + " threads");
        settings.waveWidth = v.waveWidth;
        settings.threads = v.threads;
        const RenderResult r = scene.render(settings);
        ASSERT_EQ(reference.image.pixels().size(), r.image.pixels().size());
        EXPECT_EQ(std::memcmp(reference.image.pixels().data(), r.image.pixels().data(),
                              r.image.pixels().size() * sizeof(vec4)),
                  0);
        expectSameStats(reference.dispatch.stats, r.dispatch.stats);
    }
}

class WaveWidth : public ::testing::TestWithParam<std::string> {};

TEST_P(WaveWidth, SameImageAndCountsForEveryWidth) { expectSameForEveryWidth(GetParam(), RenderSettings{}); }

INSTANTIATE_TEST_SUITE_P(EveryScene, WaveWidth,
                         ::testing::Values("d3d12-procedural-geometry.json", "proceduray-mandel-julia-pac.json",
                                           "d3d12-procedural-geometry-inline.json", "inline-ambient-occlusion.json",
                                           "cornell-box.json", "textured-room.json"),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                             std::string name = param.param.substr(0, param.param.find('.'));
                             for (char& c : name)
                                 if (c == '-') c = '_';
                             return name;
                         });

TEST(WaveWidthArithmetic, DoublePrecisionIsTheSameForEveryWidth) {
    RenderSettings settings;
    settings.precision = procedural::Precision::Double;
    expectSameForEveryWidth("d3d12-procedural-geometry.json", settings);
    expectSameForEveryWidth("proceduray-mandel-julia-pac.json", settings);
}

TEST(WaveWidthArithmetic, PerturbedArithmeticIsTheSameForEveryWidth) {
    RenderSettings settings;
    settings.perturbation = procedural::Perturbation{};
    settings.perturbation->seed = 7;
    expectSameForEveryWidth("d3d12-procedural-geometry.json", settings);
    expectSameForEveryWidth("proceduray-mandel-julia-pac.json", settings);
}

TEST(WaveWidthOrder, AdversarialOrderIsTheSameForEveryWidth) {
    RenderSettings settings;
    settings.order = dxr::TraversalOrder::Adversarial;
    settings.adversarialSeed = 11;
    expectSameForEveryWidth("d3d12-procedural-geometry.json", settings);
    expectSameForEveryWidth("proceduray-mandel-julia-pac.json", settings);
}

}  // namespace
}  // namespace refray::scenes
