// Tests scenes/scene.cpp: the reference scene files built into DXR objects and rendered end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "core/error.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";
const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

RenderSettings small(uint32_t threads = 2) {
    RenderSettings s;
    s.width = 48;
    s.height = 27;
    s.threads = threads;
    return s;
}

bool sameBytes(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(vec4)) == 0;
}

size_t nonFinitePixels(const Image& image) {
    size_t n = 0;
    for (const vec4& p : image.pixels())
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.w)) ++n;
    return n;
}

TEST(Scene, HitGroupTablesHaveTheSamplesStride) {
    // Both samples: 32-byte identifier + 56 bytes of procedural arguments, rounded up to 96 (REC-3).
    for (const std::string& path : {kProceduray, kD3D12}) {
        auto scene = loadScene(path);
        EXPECT_EQ(scene->tables(procedural::Precision::Float).HitGroupTable.StrideInBytes, 96u) << path;
        EXPECT_EQ(scene->tables(procedural::Precision::Float).MissShaderTable.StrideInBytes, 32u) << path;
    }
    // The table ends at the last record's last byte: 9·96 + 88 and 21·96 + 88 (the D3D12 sample allocates 22·96).
    EXPECT_EQ(loadScene(kProceduray)->tables(procedural::Precision::Float).HitGroupTable.SizeInBytes, 952u);
    EXPECT_EQ(loadScene(kD3D12)->tables(procedural::Precision::Float).HitGroupTable.SizeInBytes, 2104u);
}

TEST(Scene, RendersAreIndependentOfThreadCount) {
    for (const std::string& path : {kProceduray, kD3D12}) {
        auto scene = loadScene(path);
        const RenderResult one = scene->render(small(1));
        const RenderResult two = scene->render(small(2));
        EXPECT_TRUE(sameBytes(one.image, two.image)) << path;
        EXPECT_EQ(nonFinitePixels(one.image), 0u) << path;
        EXPECT_TRUE(one.dispatch.diagnostics.empty()) << path;
        EXPECT_EQ(one.dispatch.stats.raysPerDepth.at(1), 48u * 27u);
    }
}

TEST(Scene, EveryCameraAndCanonicalTimeRendersFiniteValues) {
    for (const std::string& path : {kProceduray, kD3D12}) {
        auto scene = loadScene(path);
        for (const CameraDesc& camera : scene->desc().cameras)
            for (float time : scene->desc().canonicalTimes) {
                RenderSettings s = small();
                s.camera = camera.name;
                s.time = time;
                const RenderResult r = scene->render(s);
                EXPECT_EQ(nonFinitePixels(r.image), 0u) << path << " " << camera.name << " t=" << time;
                EXPECT_EQ(r.image.metadata.at("camera"), camera.name);
            }
    }
}

TEST(Scene, TimeChangesTheProceduraySceneAndIsRecorded) {
    auto scene = loadScene(kProceduray);
    RenderSettings s = small();
    s.camera = "mandelbulb";
    s.time = 0.0f;
    const RenderResult t0 = scene->render(s);
    s.time.reset();
    const RenderResult t1 = scene->render(s);
    EXPECT_FALSE(sameBytes(t0.image, t1.image));  // 4 vs 129 Mandelbulb steps (§1.9)
    EXPECT_EQ(t0.image.metadata.at("time"), "0");
    EXPECT_EQ(t1.image.metadata.at("time"), "15.8429795");
    EXPECT_EQ(t1.image.metadata.at("scene_sha256"), scene->desc().fileHash);
    EXPECT_EQ(t1.image.metadata.at("precision"), "float");
}

TEST(Scene, DoublePrecisionAndSupersamplingRender) {
    auto scene = loadScene(kD3D12);
    RenderSettings s = small();
    const RenderResult reference = scene->render(s);
    s.precision = procedural::Precision::Double;
    const RenderResult twice = scene->render(s);
    EXPECT_EQ(nonFinitePixels(twice.image), 0u);
    EXPECT_EQ(twice.image.metadata.at("precision"), "double");
    s.precision = procedural::Precision::Float;
    s.spp = 4;
    const RenderResult ss = scene->render(s);
    EXPECT_EQ(ss.image.width(), 48u);
    EXPECT_EQ(ss.dispatch.stats.raysPerDepth.at(1), 4u * 48u * 27u);
    EXPECT_FALSE(sameBytes(reference.image, ss.image));
    s.spp = 3;
    try {
        scene->render(s);
        FAIL() << "spp 3 must be refused";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--spp must be a square number"), std::string::npos) << e.what();
    }
}

TEST(Scene, UnknownCameraListsTheCameras) {
    auto scene = loadScene(kProceduray);
    RenderSettings s = small();
    s.camera = "mandlebulb";
    try {
        scene->render(s);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("has no camera 'mandlebulb' (did you mean 'mandelbulb'?); its cameras: "
                                             "overview, julia, mandelbulb, sample-default"),
                  std::string::npos)
            << e.what();
    }
}

TEST(Scene, ProcedurayOverviewShowsTheSceneContent) {
    // Camera A at 1280x720 scaled down: sky at the top centre, the Julia floor at the bottom, a Pac-man left of
    // centre (yellow: red and green above blue).
    auto scene = loadScene(kProceduray);
    RenderSettings s;
    s.width = 160;
    s.height = 90;
    const RenderResult r = scene->render(s);
    const vec4 sky = r.image.at(80, 5);
    EXPECT_NEAR(sky.r, 0.6f, 1e-6f);  // BackgroundColor (0.6, 0.7, 0.9)
    EXPECT_NEAR(sky.b, 0.9f, 1e-6f);
    size_t yellow = 0;
    for (uint32_t y = 30; y < 70; ++y)
        for (uint32_t x = 40; x < 90; ++x) {
            const vec4 p = r.image.at(x, y);
            if (p.r > 0.3f && p.g > 0.3f && p.b < 0.5f * p.r) ++yellow;
        }
    EXPECT_GT(yellow, 200u);
}

// The D3D12 scene with a "traceRay" object on each ray type (docs/scene-format.md).
std::unique_ptr<Scene> d3d12SceneWithTraceRay(const std::string& radiance, const std::string& shadow) {
    std::string radianceType = "\"payload\": \"RayPayload\", \"traceRay\": ";
    radianceType += radiance;
    radianceType += "}";
    std::string shadowType = "\"payload\": \"ShadowRayPayload\", \"traceRay\": ";
    shadowType += shadow;
    shadowType += "}";
    std::string text = testing::readText(kD3D12);
    text = testing::edited(text, "\"payload\": \"RayPayload\"}", radianceType);
    text = testing::edited(text, "\"payload\": \"ShadowRayPayload\"}", shadowType);
    return std::make_unique<Scene>(parseScene(text, "d3d12-trace-ray.json"));
}

// The scene file's TraceRay arguments reach the shaders. Spelling out the HLSL's own values renders the file's image
// bit for bit; the tutorial's lesson "a multiplier of 1 with two ray types" (I = r + G + C) sends the rays that hit
// the AABB geometries to other geometries' records, which stay inside the table, and renders a different image.
TEST(Scene, TraceRayArgumentsOfTheSceneFileReachTheShaders) {
    RenderSettings s = small();
    s.width = 64;
    s.height = 36;
    const RenderResult reference = loadScene(kD3D12)->render(s);

    const RenderResult spelledOut =
        d3d12SceneWithTraceRay(
            R"({"rayContribution": 0, "multiplier": 2, "missShaderIndex": 0, "instanceInclusionMask": 4294967295})",
            R"({"rayContribution": 1, "multiplier": 2, "missShaderIndex": 1, "instanceInclusionMask": 4294967295})")
            ->render(s);
    EXPECT_TRUE(sameBytes(reference.image, spelledOut.image));

    const RenderResult lesson = d3d12SceneWithTraceRay(R"({"multiplier": 1})", R"({"multiplier": 1})")->render(s);
    EXPECT_FALSE(sameBytes(reference.image, lesson.image));
    EXPECT_EQ(nonFinitePixels(lesson.image), 0u);
    EXPECT_TRUE(lesson.dispatch.diagnostics.empty());  // wrong records, but valid ones
}

// Perturbed renders (procedural/math/perturbed.h): a seed picks one GPU, whose image is the same at any thread count;
// another seed is another GPU; the nominal image is the same before and after them.
TEST(Scene, PerturbedRendersDependOnTheSeedAlone) {
    for (const std::string& path : {kProceduray, kD3D12}) {
        auto scene = loadScene(path);
        const RenderResult nominal = scene->render(small());
        RenderSettings s = small(1);
        s.perturbation = procedural::Perturbation{1};
        const RenderResult one = scene->render(s);
        s.threads = 2;
        const RenderResult two = scene->render(s);
        s.perturbation->seed = 2;
        const RenderResult other = scene->render(s);
        EXPECT_TRUE(sameBytes(one.image, two.image)) << path;
        EXPECT_FALSE(sameBytes(one.image, other.image)) << path;
        EXPECT_FALSE(sameBytes(one.image, nominal.image)) << path;
        EXPECT_EQ(nonFinitePixels(one.image), 0u) << path;
        EXPECT_TRUE(one.dispatch.diagnostics.empty()) << path;
        EXPECT_EQ(one.image.metadata.at("perturbation"),
                  "seed 1, contraction mixed, denormals flush (variation model v1)");
        EXPECT_EQ(nominal.image.metadata.count("perturbation"), 0u);
        EXPECT_TRUE(sameBytes(scene->render(small()).image, nominal.image)) << path;
    }
}

TEST(Scene, PerturbedDoublePrecisionIsRefused) {
    auto scene = loadScene(kD3D12);
    RenderSettings s = small();
    s.precision = procedural::Precision::Double;
    s.perturbation = procedural::Perturbation{3};
    try {
        scene->render(s);
        FAIL() << "a perturbed double render must be refused";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "a perturbed render perturbs the GPU's float arithmetic; --perturb cannot be combined "
                               "with --precision double");
    }
}

}  // namespace
}  // namespace refray::scenes
