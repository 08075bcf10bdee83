// `refray render --batches K` and `refray compare --statistical` as a user runs them:
// statistics images from the renderer, the verdicts, exit codes, the failure map and the
// errors for files that are no statistics images.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "core/image.h"
#include "core/statistical_compare.h"
#include "tests/tools/cli_run.h"

namespace {

using refray::Image;
using refray::StatisticsImage;
using refray::vec3;
using refray::vec4;
using refray::testing::CliRun;

const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

CliRun run(const std::string& arguments) { return refray::testing::runRefray(arguments); }

std::string directory(const std::string& name) { return refray::testing::freshDirectory("statistical", name); }

using refray::testing::contains;

// A statistics image of a noisy render: K batches of 0.5 + 0.1 N(0, 1) per channel, plus
// `shift` in the 6x6 block at (8, 4).
StatisticsImage noisy(uint32_t batches, uint32_t seed, double shift = 0.0) {
    std::mt19937 generator(seed);
    std::normal_distribution<double> gaussian(0.0, 1.0);
    refray::StatisticsAccumulator accumulator;
    for (uint32_t k = 0; k < batches; ++k) {
        Image batch(24, 16);
        for (uint32_t y = 0; y < batch.height(); ++y)
            for (uint32_t x = 0; x < batch.width(); ++x) {
                const bool block = x >= 8 && x < 14 && y >= 4 && y < 10;
                for (int c = 0; c < 3; ++c) batch.at(x, y)[c] = float(0.5 + (block ? shift : 0.0) + 0.1 * gaussian(generator));
                batch.at(x, y).a = 1.0f;
            }
        accumulator.add(batch);
    }
    return accumulator.finish();
}

}  // namespace

TEST(StatisticalCompareCli, BatchesOfTheBuiltinSceneCompareExactlyWithThemselves) {
    const std::string dir = directory("builtin");
    const std::string stats = dir + "/ref.exr";
    const CliRun render = run("render builtin --size 16x9 --batches 2 -o " + stats);
    ASSERT_EQ(render.status, 0) << render.output;
    EXPECT_TRUE(contains(render.output, "batch 1/2 (seed 0)")) << render.output;
    EXPECT_TRUE(contains(render.output, "batch 2/2 (seed 1)")) << render.output;
    EXPECT_TRUE(contains(render.output, "the variance is 0 everywhere")) << render.output;

    const StatisticsImage s = refray::readStatisticsImage(stats);
    EXPECT_EQ(s.batches, 2u);
    EXPECT_EQ(s.width(), 16u);
    EXPECT_EQ(s.height(), 9u);
    EXPECT_EQ(s.mean.metadata.at("scene"), "builtin");
    EXPECT_EQ(s.mean.metadata.at("seed"), "0");
    EXPECT_EQ(s.mean.metadata.at("statistics_seeds"), "0..1");
    for (const vec3& v : s.varianceOfMean) EXPECT_EQ(v, vec3(0.0f));
    // The mean is the render itself (the scene is deterministic).
    const std::string plain = dir + "/plain.exr";
    ASSERT_EQ(run("render builtin --size 16x9 -o " + plain).status, 0);
    EXPECT_EQ(refray::readImage(plain).pixels(), s.mean.pixels());

    const std::string map = dir + "/map.png";
    const CliRun compare = run("compare --statistical " + stats + " " + stats + " --map " + map);
    EXPECT_EQ(compare.status, 0) << compare.output;
    EXPECT_TRUE(contains(compare.output, "432 pixel-channel tests")) << compare.output;
    EXPECT_TRUE(contains(compare.output, "this is an exact comparison")) << compare.output;
    EXPECT_TRUE(contains(compare.output, "verdict         PASS")) << compare.output;
    const Image written = refray::readImage(map);
    EXPECT_EQ(written.width(), 16u);
    for (const vec4& p : written.pixels()) EXPECT_EQ(p, vec4(0.0f, 0.0f, 0.0f, 1.0f));
}

TEST(StatisticalCompareCli, BatchesOfAReferenceSceneRecordTheirSeeds) {
    const std::string dir = directory("d3d12");
    const std::string stats = dir + "/ref.exr";
    const CliRun render = run("render " + kD3D12 + " --size 16x9 --batches 3 --seed 7 -o " + stats + " --stats");
    ASSERT_EQ(render.status, 0) << render.output;
    EXPECT_TRUE(contains(render.output, "batch 3/3 (seed 9)")) << render.output;
    EXPECT_TRUE(contains(render.output, "stats of the last batch (seed 9)")) << render.output;
    const StatisticsImage s = refray::readStatisticsImage(stats);
    EXPECT_EQ(s.batches, 3u);
    EXPECT_EQ(s.mean.metadata.at("seed"), "7");
    EXPECT_EQ(s.mean.metadata.at("statistics_seeds"), "7..9");
    EXPECT_EQ(s.mean.metadata.at(refray::kStatisticsBatchesKey), "3");
    EXPECT_TRUE(s.mean.metadata.count("scene_sha256")) << "the provenance of the first batch is kept";
    EXPECT_EQ(run("compare --statistical " + stats + " " + stats).status, 0);

    // --seed alone sets the render's seed, recorded in the metadata.
    const std::string seeded = dir + "/seeded.exr";
    ASSERT_EQ(run("render " + kD3D12 + " --size 16x9 --seed 9 -o " + seeded).status, 0);
    EXPECT_EQ(refray::readImage(seeded).metadata.at("seed"), "9");
}

TEST(StatisticalCompareCli, APlainImageIsAClearError) {
    const std::string dir = directory("plain");
    const std::string stats = dir + "/ref.exr", png = dir + "/mine.png";
    ASSERT_EQ(run("render builtin --size 16x9 --batches 2 -o " + stats).status, 0);
    ASSERT_EQ(run("render builtin --size 16x9 -o " + png).status, 0);
    const CliRun r = run("compare --statistical " + stats + " " + png);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "'" + png + "' is not a statistics image: it has no variance channels var.R, var.G, "
                                               "var.B"))
        << r.output;
    EXPECT_TRUE(contains(r.output, "--batches K")) << r.output;
    const CliRun missing = run("compare --statistical " + dir + "/absent.exr " + stats);
    EXPECT_EQ(missing.status, 4) << missing.output;
    EXPECT_TRUE(contains(missing.output, "absent.exr': no such file")) << missing.output;
}

TEST(StatisticalCompareCli, DifferentSizesAreAMismatch) {
    const std::string dir = directory("sizes");
    ASSERT_EQ(run("render builtin --size 16x9 --batches 2 -o " + dir + "/a.exr").status, 0);
    ASSERT_EQ(run("render builtin --size 8x9 --batches 2 -o " + dir + "/b.exr").status, 0);
    const CliRun r = run("compare --statistical " + dir + "/a.exr " + dir + "/b.exr --map " + dir + "/map.png");
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "size mismatch: the reference is 16x9, the candidate 8x9")) << r.output;
    EXPECT_TRUE(contains(r.output, "verdict         MISMATCH")) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/map.png"));
}

TEST(StatisticalCompareCli, NoisyRendersPassUnlessTheExpectationMoves) {
    const std::string dir = directory("noisy");
    const std::string reference = dir + "/ref.exr", same = dir + "/same.exr", shifted = dir + "/shifted.exr";
    refray::writeStatisticsImage(reference, noisy(16, 1));
    refray::writeStatisticsImage(same, noisy(8, 2));
    // 0.4 is about 9 standard errors of the difference (0.1 · √(1/16 + 1/8) = 0.043).
    refray::writeStatisticsImage(shifted, noisy(8, 2, 0.4));

    const CliRun pass = run("compare --statistical " + reference + " " + same + " --correction bonferroni --alpha 0.05");
    EXPECT_EQ(pass.status, 0) << pass.output;
    EXPECT_TRUE(contains(pass.output, "alpha           0.05 for the whole image; bonferroni-corrected: ")) << pass.output;
    EXPECT_TRUE(contains(pass.output, "batches         reference 16, candidate 8")) << pass.output;

    const std::string map = dir + "/map.png";
    const CliRun fail = run("compare --statistical " + reference + " " + shifted + " --map " + map);
    EXPECT_EQ(fail.status, 2) << fail.output;
    EXPECT_TRUE(contains(fail.output, "verdict         FAILURE")) << fail.output;
    EXPECT_TRUE(contains(fail.output, "wrote " + map)) << fail.output;
    const Image m = refray::readImage(map);
    uint32_t redInside = 0, redOutside = 0;
    for (uint32_t y = 0; y < m.height(); ++y)
        for (uint32_t x = 0; x < m.width(); ++x)
            if (m.at(x, y) == vec4(1.0f, 0.0f, 0.0f, 1.0f)) (x >= 8 && x < 14 && y >= 4 && y < 10 ? redInside : redOutside)++;
    EXPECT_EQ(redOutside, 0u);
    EXPECT_GE(redInside, 30u);
}

TEST(StatisticalCompareCli, OptionErrorsAreClear) {
    const std::string dir = directory("options");
    const CliRun png = run("render builtin --size 8x8 --batches 2 -o " + dir + "/stats.png");
    EXPECT_EQ(png.status, 2) << png.output;
    EXPECT_TRUE(contains(png.output, "give -o a name ending in .exr, got '" + dir + "/stats.png'")) << png.output;

    const CliRun one = run("render builtin --size 8x8 --batches 1 -o " + dir + "/stats.exr");
    EXPECT_EQ(one.status, 2) << one.output;
    EXPECT_TRUE(contains(one.output, "--batches needs at least 2 renders")) << one.output;

    const CliRun aov = run("render " + kD3D12 + " --size 8x8 --batches 2 --aov record -o " + dir + "/stats.exr");
    EXPECT_EQ(aov.status, 2) << aov.output;
    EXPECT_TRUE(contains(aov.output, "--aov and --order-check are separate renders")) << aov.output;

    ASSERT_EQ(run("render builtin --size 8x8 --batches 2 -o " + dir + "/stats.exr").status, 0);
    const std::string stats = dir + "/stats.exr";
    const CliRun golden = run("compare --statistical --golden " + stats + " " + stats);
    EXPECT_NE(golden.status, 0) << golden.output;
    EXPECT_TRUE(contains(golden.output, "cannot be combined with --golden")) << golden.output;
    const CliRun alpha = run("compare --alpha 0.1 " + stats + " " + stats);
    EXPECT_NE(alpha.status, 0) << alpha.output;
    EXPECT_TRUE(contains(alpha.output, "--alpha: needs --statistical")) << alpha.output;
    const CliRun badAlpha = run("compare --statistical --alpha 1.5 " + stats + " " + stats);
    EXPECT_NE(badAlpha.status, 0) << badAlpha.output;
    EXPECT_TRUE(contains(badAlpha.output, "between 0 and 1")) << badAlpha.output;
}
