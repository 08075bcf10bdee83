// DXR 1.1 inline ray tracing on Mesa's lavapipe (a CPU Vulkan driver with VK_KHR_ray_query, not a GPU): the two
// scenes that trace with RayQuery, rendered through `refray render --device vulkan --vulkan-device llvmpipe` with the
// GLSL ports of gpu/shaders/d3d12-procedural-geometry/ (MyClosestHitShader_*_InlineShadow.rchit,
// InlineAmbientOcclusionCS.comp) and compared with refray (docs/gpu-crosscheck.md, "Inline ray tracing on lavapipe"):
//   - d3d12-procedural-geometry-inline, whose shadow rays are ray queries from the closest hits, renders the same
//     image as d3d12-procedural-geometry, whose shadow rays are TraceRay calls, bit for bit;
//   - the compute scene renders through vkCmdDispatch, and has no record map (a query reads no shader record);
//   - both scenes have envelope goldens, so that EveryGolden/LavapipeGoldens (their renders pass them),
//     EveryGolden/LavapipeDiscrimination and EverySettingAndLesson/LavapipeMaps (their committed index maps equal
//     refray's wherever the same object was hit; for the compute scene each thread's first query's) run them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>

#include "core/image.h"
#include "tests/lavapipe/lavapipe_support.h"
#include "tests/test_output.h"
#include "tests/tools/cli_run.h"
#include "verify/golden.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
using testing::onLavapipe;
using testing::runRefray;
using testing::shellPath;

const fs::path kRoot = REFRAY_SOURCE_DIR;
const fs::path kGoldens = kRoot / "tests/golden";
const char* const kInlineShadowScene = "scenes/d3d12-procedural-geometry-inline.json";
const char* const kTraceRayScene = "scenes/d3d12-procedural-geometry.json";
const char* const kComputeScene = "scenes/inline-ambient-occlusion.json";

// Renders `scene` (relative to the repository) on lavapipe; returns the image, or fails the test.
Image renderOnLavapipe(const std::string& scene, const std::string& arguments, const fs::path& out) {
    const testing::CliRun run =
        runRefray("render " + shellPath(kRoot / scene) + arguments + onLavapipe() + " -o " + shellPath(out));
    EXPECT_EQ(run.status, 0) << scene << arguments << ": " << run.output;
    if (run.status != 0) return Image();
    return readImage(out.string());
}

// The golden settings of one scene: camera default, 320x180, as the golden manifest's entries are.
const std::string kGoldenSetting = " --camera default --time 0 --size 320x180";

TEST(LavapipeInline, InlineShadowSceneEqualsTheTraceRaySceneBitForBit) {
    REFRAY_REQUIRE_LAVAPIPE();
    const fs::path dir = testing::testOutputDirectory("lavapipe");
    const Image inlineImage = renderOnLavapipe(kInlineShadowScene, kGoldenSetting, dir / "inline-shadows.exr");
    const Image traceRayImage = renderOnLavapipe(kTraceRayScene, kGoldenSetting, dir / "traceray-shadows.exr");
    ASSERT_FALSE(inlineImage.empty());
    ASSERT_FALSE(traceRayImage.empty());
    ASSERT_EQ(inlineImage.width(), traceRayImage.width());
    ASSERT_EQ(inlineImage.height(), traceRayImage.height());
    // The inline scene's shaders trace inline (the Vulkan back end would have refused them otherwise) and its image
    // metadata names lavapipe.
    EXPECT_NE(inlineImage.metadata.at("gpu").find("llvmpipe"), std::string::npos);
    // Bit for bit: the primary and reflection rays are the same TraceRay calls, and the shadow ray's answer ("hit or
    // not") comes from the same candidates, the same intersection code and the same extent ([0, 10000] until a
    // commit ends the search) in both, so not one float may differ.
    uint64_t differing = 0;
    std::string first;
    for (uint32_t y = 0; y < inlineImage.height(); ++y)
        for (uint32_t x = 0; x < inlineImage.width(); ++x) {
            const vec4 a = inlineImage.at(x, y), b = traceRayImage.at(x, y);
            if (std::memcmp(&a, &b, sizeof a) == 0) continue;
            if (differing++ == 0) {  // (a stream: GCC 12 warns falsely, -Wrestrict, on a chain of string + at -O3)
                std::ostringstream where;
                where << "(" << x << "," << y << ") inline " << a.x << " " << a.y << " " << a.z << ", TraceRay " << b.x
                      << " " << b.y << " " << b.z;
                first = where.str();
            }
        }
    std::printf("inline-shadow vs TraceRay-shadow scene on lavapipe: %llu of %u pixels differ\n",
                (unsigned long long)differing, inlineImage.width() * inlineImage.height());
    EXPECT_EQ(differing, 0u) << "first: " << first;
}

TEST(LavapipeInline, TheComputeSceneRendersThroughVkCmdDispatch) {
    REFRAY_REQUIRE_LAVAPIPE();
    const fs::path out = testing::testOutputDirectory("lavapipe") / "inline-ambient-occlusion.exr";
    const Image image = renderOnLavapipe(kComputeScene, kGoldenSetting, out);
    ASSERT_FALSE(image.empty());
    EXPECT_EQ(image.metadata.at("device"), "vulkan");
    EXPECT_NE(image.metadata.at("gpu").find("llvmpipe"), std::string::npos);
    // Ambient occlusion: grey levels k/8 where a surface was hit, the background colour elsewhere; both occur.
    uint64_t occluded = 0, open = 0, background = 0, other = 0;
    for (const vec4& p : image.pixels()) {
        if (p == vec4(0.8f, 0.9f, 1.0f, 1.0f)) {
            ++background;
            continue;
        }
        const float k = p.x * 8.0f;
        if (p.x != p.y || p.x != p.z || p.w != 1.0f || k != std::floor(k) || k < 0.0f || k > 8.0f) ++other;
        else if (k < 8.0f) ++occluded;
        else ++open;
    }
    std::printf("inline-ambient-occlusion on lavapipe: %llu occluded, %llu open, %llu background pixels\n",
                (unsigned long long)occluded, (unsigned long long)open, (unsigned long long)background);
    EXPECT_EQ(other, 0u) << "every pixel is k/8 grey or the background";
    EXPECT_GT(occluded, 0u);
    EXPECT_GT(background, 0u);
}

TEST(LavapipeInline, TheComputeScenesRecordMapIsRefused) {
    REFRAY_REQUIRE_LAVAPIPE();
    const fs::path out = testing::testOutputDirectory("lavapipe") / "inline-ambient-occlusion.record.exr";
    fs::remove(out);
    const testing::CliRun run = runRefray("render " + shellPath(kRoot / kComputeScene) +
                                          " --size 32x18 --aov record" + onLavapipe() + " -o " + shellPath(out));
    EXPECT_EQ(run.status, 2) << run.output;
    EXPECT_TRUE(testing::contains(run.output, "InlineAmbientOcclusionCS")) << run.output;
    EXPECT_FALSE(fs::exists(out));
}

// ---- The envelope goldens of both scenes are in the manifest, so the EveryGolden and EverySettingAndLesson tests of
// lavapipe_crosscheck_test.cpp render them on lavapipe, judge them (compare --golden tests/golden/<name>.envelope.exr)
// and compare their maps. The goldens themselves come from `refray golden update` (docs/golden-format.md).

TEST(LavapipeInline, BothInlineScenesHaveEnvelopeGoldensThatTheLavapipeTestsRun) {
    REFRAY_REQUIRE_LAVAPIPE();
    const GoldenSet manifest = readGoldenManifest(kGoldens / "goldens.json");
    for (const char* scene : {kInlineShadowScene, kComputeScene}) {
        const auto it = std::find_if(manifest.entries.begin(), manifest.entries.end(),
                                     [&](const GoldenEntry& g) { return g.scene == scene; });
        ASSERT_NE(it, manifest.entries.end())
            << "tests/golden/goldens.json has no golden of " << scene
            << ", so LavapipeGoldens and LavapipeMaps do not run it; generate it with refray golden update";
        EXPECT_TRUE(fs::exists(kGoldens / it->envelope)) << (kGoldens / it->envelope);
    }
}

}  // namespace
}  // namespace refray::scenes
