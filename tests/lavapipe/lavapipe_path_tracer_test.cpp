// The dxr-path-tracer library on lavapipe (a CPU Vulkan driver, not a GPU): each Monte Carlo scene with a statistical
// golden in tests/golden/goldens.json, rendered as a user would (`refray render SCENE --device vulkan --batches K
// --seed S`) through the Vulkan back end's texture arrays, static sampler and the GLSL port
// gpu/shaders/dxr-path-tracer/, and judged with `refray compare --statistical` against the CPU emulator's golden
// (docs/path-tracer.md, "On Vulkan"). The seeds are not the golden's, so the two statistics images are independent.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/image.h"
#include "core/statistical_compare.h"
#include "tests/lavapipe/lavapipe_support.h"
#include "tests/test_output.h"
#include "tests/tools/cli_run.h"
#include "verify/golden.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
using testing::onLavapipe;
using testing::shellPath;
using testing::runRefray;

const fs::path kRoot = REFRAY_SOURCE_DIR;
const fs::path kGoldens = kRoot / "tests/golden";
// The candidate's first seed: the goldens use seed .. seed + batches - 1 (0..15), so 100.. gives other batches.
constexpr uint32_t kCandidateSeed = 100;


StatisticalGoldenEntry statisticalGolden(const std::string& name) {
    for (const StatisticalGoldenEntry& e : readGoldenManifest(kGoldens / "goldens.json").statistical)
        if (e.name == name) return e;
    throw Error("no statistical golden '" + name + "' in tests/golden/goldens.json");
}

// Renders the golden's scene with its settings on lavapipe and compares it with the golden as `refray compare
// --statistical` does; the candidate and the verdict are left in the test output directory.
void expectLavapipePassesStatisticalGolden(const std::string& name) {
    const StatisticalGoldenEntry golden = statisticalGolden(name);
    const fs::path out = testing::testOutputDirectory("lavapipe") / (golden.name + ".lavapipe.stats.exr");
    fs::remove(out);
    const std::string size = std::to_string(golden.width) + "x" + std::to_string(golden.height);
    const testing::CliRun render =
        runRefray("render " + shellPath(kRoot / golden.scene) + " --camera " + golden.camera + " --size " + size +
                  " --spp " + std::to_string(golden.spp) + " --batches " + std::to_string(golden.batches) +
                  " --seed " + std::to_string(kCandidateSeed) + onLavapipe() + " -o " + shellPath(out));
    ASSERT_EQ(render.status, 0) << render.output;

    // The statistics image is lavapipe's: its provenance says so.
    const StatisticsImage candidate = readStatisticsImage(out.string());
    EXPECT_EQ(candidate.batches, golden.batches);
    EXPECT_EQ(candidate.mean.metadata.at("device"), "vulkan");
    EXPECT_NE(candidate.mean.metadata.at("gpu").find("llvmpipe"), std::string::npos) << candidate.mean.metadata.at("gpu");

    // The user's command and its exit status: 0 pass, 1 fail.
    const testing::CliRun compare =
        runRefray("compare --statistical " + shellPath(kGoldens / golden.image) + " " + shellPath(out));
    std::printf("%s", compare.output.c_str());
    EXPECT_EQ(compare.status, 0) << golden.name << ": lavapipe's statistics image " << out.string()
                                 << " differs from the golden beyond the noise\n"
                                 << compare.output;
    // And the library call behind it, for its numbers.
    const StatisticalCompareResult result =
        compareStatistics(readStatisticsImage((kGoldens / golden.image).string()), candidate);
    EXPECT_EQ(result.verdict, CompareVerdict::Pass) << result.describe();
}

TEST(LavapipePathTracer, CornellBoxPassesItsStatisticalGolden) {
    REFRAY_REQUIRE_LAVAPIPE();
    expectLavapipePassesStatisticalGolden("cornell-box.default");
}

// The room samples its diffuse textures and normal maps (unbounded Texture2D arrays, the static sampler): a V flip or
// a missing normal map on the GPU fails this golden (docs/compare.md, "The textured room golden").
TEST(LavapipePathTracer, TexturedRoomPassesItsStatisticalGolden) {
    REFRAY_REQUIRE_LAVAPIPE();
    expectLavapipePassesStatisticalGolden("textured-room.default");
}

}  // namespace
}  // namespace refray::scenes
