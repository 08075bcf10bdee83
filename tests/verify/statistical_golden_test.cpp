// The statistical goldens of tests/golden/goldens.json (verify/golden.h): each Monte Carlo golden re-rendered with
// other seeds passes `compare --statistical` (core/statistical_compare.h) against its statistics image, and for the
// Cornell box a render whose red wall reflects 10 % less fails it, so the golden can see such a change. How the
// size, spp and batches were chosen: docs/compare.md, "The Cornell box golden".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/hash.h"
#include "core/image.h"
#include "core/statistical_compare.h"
#include "verify/golden.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"
#include "tests/test_output.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = REFRAY_SOURCE_DIR;
const fs::path kGoldenDirectory = kRoot / "tests" / "golden";
// The re-renders' first seed: far from the goldens' own (seed .. seed + batches - 1), so the batches are independent.
constexpr uint32_t kOtherSeeds = 1000;

std::vector<StatisticalGoldenEntry> statisticalEntries() {
    try {
        return readGoldenManifest(kGoldenDirectory / "goldens.json").statistical;
    } catch (const Error&) {
        return {};  // reported by GoldenSet.ManifestCoversEveryCameraOfEverySceneFile
    }
}

StatisticalGoldenEntry entryNamed(const std::string& name) {
    for (const StatisticalGoldenEntry& e : statisticalEntries())
        if (e.name == name) return e;
    throw Error("no statistical golden " + name + " in tests/golden/goldens.json");
}

// The golden's statistics image, checked against its entry.
StatisticsImage readGolden(const StatisticalGoldenEntry& golden) {
    StatisticsImage reference = readStatisticsImage((kGoldenDirectory / golden.image).string());
    EXPECT_EQ(reference.batches, golden.batches) << golden.image;
    EXPECT_EQ(reference.width(), golden.width) << golden.image;
    EXPECT_EQ(reference.height(), golden.height) << golden.image;
    EXPECT_EQ(reference.mean.metadata["spp"], std::to_string(golden.spp)) << golden.image;
    EXPECT_EQ(reference.mean.metadata["statistics_seeds"],
              std::to_string(golden.seed) + ".." + std::to_string(golden.seed + golden.batches - 1))
        << golden.image;
    return reference;
}

// Compares, and on failure writes the candidate and the failure map to the test output directory.
StatisticalCompareResult compareWithGolden(const StatisticalGoldenEntry& golden, const StatisticsImage& candidate,
                                           const std::string& label) {
    const StatisticalCompareResult result = compareStatistics(readGolden(golden), candidate);
    if (result.verdict != CompareVerdict::Pass) {
        const fs::path out = fs::path(REFRAY_TEST_OUTPUT_DIR) / "statistical-golden";
        fs::create_directories(out);
        writeStatisticsImage((out / (golden.name + "." + label + ".exr")).string(), candidate);
        writeImage((out / (golden.name + "." + label + ".map.png")).string(), result.failureMap);
    }
    return result;
}

}  // namespace

void PrintTo(const StatisticalGoldenEntry& entry, std::ostream* os) { *os << entry.name; }

namespace {

class StatisticalGolden : public ::testing::TestWithParam<StatisticalGoldenEntry> {};

TEST_P(StatisticalGolden, OtherSeedsPass) {
    const StatisticalGoldenEntry& golden = GetParam();
    const fs::path scenePath = kRoot / golden.scene;
    ASSERT_EQ(sha256HexOfFile(scenePath), golden.sceneSha256)
        << golden.scene << " changed since its golden was made; review the change and run `refray golden update`";
    Scene scene(loadSceneFile(scenePath));
    const StatisticsImage candidate = renderStatistics(scene, golden, golden.seed + kOtherSeeds, golden.batches, 2);
    const StatisticalCompareResult result = compareWithGolden(golden, candidate, "other-seeds");
    EXPECT_EQ(result.verdict, CompareVerdict::Pass) << golden.name << "\n" << result.describe();
}

std::string goldenName(const ::testing::TestParamInfo<StatisticalGoldenEntry>& info) {
    std::string name = info.param.name;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

INSTANTIATE_TEST_SUITE_P(EveryEntry, StatisticalGolden, ::testing::ValuesIn(statisticalEntries()), goldenName);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(StatisticalGolden);

// The manifest keeps statistical entries through a write and a read (refray golden update rewrites it).
TEST(StatisticalGoldenManifest, RoundTrips) {
    GoldenSet set = readGoldenManifest(kGoldenDirectory / "goldens.json");
    ASSERT_FALSE(set.statistical.empty());
    const fs::path copy = refray::testing::testOutputDirectory("manifest") / "goldens-round-trip.json";
    writeGoldenManifest(copy, set);
    const GoldenSet again = readGoldenManifest(copy);
    ASSERT_EQ(again.entries.size(), set.entries.size());
    ASSERT_EQ(again.statistical.size(), set.statistical.size());
    const StatisticalGoldenEntry &a = set.statistical[0], &b = again.statistical[0];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.sceneSha256, a.sceneSha256);
    EXPECT_EQ(b.width, a.width);
    EXPECT_EQ(b.spp, a.spp);
    EXPECT_EQ(b.batches, a.batches);
    EXPECT_EQ(b.seed, a.seed);
    EXPECT_EQ(b.image, a.image);
    // The file as committed is what the writer writes.
    EXPECT_EQ(testing::readText(copy.string()), testing::readText((kGoldenDirectory / "goldens.json").string()));
}

// `refray golden update` makes threshold goldens of deterministic scenes only, and keeps the statistical entries of
// the manifest, re-rendered with their own settings.
TEST(StatisticalGoldenManifest, UpdateKeepsAndRendersStatisticalEntries) {
    const fs::path root = fs::path(REFRAY_TEST_OUTPUT_DIR) / "golden-update";
    fs::remove_all(root);
    fs::create_directories(root / "scenes" / "cornell-box");
    fs::create_directories(root / "golden");
    for (const char* file : {"d3d12-procedural-geometry.json", "cornell-box.json", "cornell-box/cornell-box.obj",
                             "cornell-box/cornell-box.mtl"})
        fs::copy_file(kRoot / "scenes" / file, root / "scenes" / file);
    GoldenSet before;
    StatisticalGoldenEntry entry;
    entry.name = "cornell-box.default";
    entry.scene = "scenes/cornell-box.json";
    entry.sceneSha256 = "stale";
    entry.camera = "default";
    entry.width = entry.height = 6;
    entry.spp = 2;
    entry.batches = 3;
    entry.seed = 5;
    entry.image = "cornell.stats.exr";
    before.statistical.push_back(entry);
    writeGoldenManifest(root / "golden" / "goldens.json", before);

    GoldenUpdateOptions options;
    options.repositoryRoot = root;
    options.goldenDirectory = root / "golden";
    options.width = 16;
    options.height = 9;
    options.orders = 1;
    options.threads = 2;
    options.refrayCommit = "test";
    const GoldenSet set = updateGoldens(options);

    ASSERT_EQ(set.entries.size(), 1u);  // the D3D12 scene's one camera; the Cornell box has no threshold golden
    EXPECT_EQ(set.entries[0].name, "d3d12-procedural-geometry.default");
    ASSERT_EQ(set.statistical.size(), 1u);
    EXPECT_EQ(set.statistical[0].sceneSha256, sha256HexOfFile(root / "scenes" / "cornell-box.json"));
    EXPECT_EQ(set.statistical[0].refrayCommit, "test");
    const StatisticsImage stats = readStatisticsImage((root / "golden" / "cornell.stats.exr").string());
    EXPECT_EQ(stats.batches, 3u);
    EXPECT_EQ(stats.width(), 6u);
    EXPECT_EQ(stats.mean.metadata.at("statistics_seeds"), "5..7");
    EXPECT_EQ(readGoldenManifest(root / "golden" / "goldens.json").statistical.size(), 1u);
}

// The power check: the Cornell box with the red wall's Kd scaled by 0.9 (a patched copy of the MTL beside a copy of
// the scene file) fails against the golden.
TEST(StatisticalGoldenPower, CornellBoxWithADarkerRedWallFails) {
    const StatisticalGoldenEntry golden = entryNamed("cornell-box.default");
    const fs::path copy = fs::path(REFRAY_TEST_OUTPUT_DIR) / "darker-red-wall";
    fs::create_directories(copy / "cornell-box");
    fs::copy_file(kRoot / "scenes" / "cornell-box.json", copy / "cornell-box.json", fs::copy_options::overwrite_existing);
    fs::copy_file(kRoot / "scenes" / "cornell-box" / "cornell-box.obj", copy / "cornell-box" / "cornell-box.obj",
                  fs::copy_options::overwrite_existing);
    const std::string mtl = testing::readText((kRoot / "scenes" / "cornell-box" / "cornell-box.mtl").string());
    std::ofstream(copy / "cornell-box" / "cornell-box.mtl", std::ios::binary)
        << testing::edited(mtl, "newmtl red\nKd 0.63 0.065 0.05", "newmtl red\nKd 0.567 0.0585 0.045");

    Scene scene(loadSceneFile(copy / "cornell-box.json"));
    const StatisticsImage candidate = renderStatistics(scene, golden, golden.seed + 2 * kOtherSeeds, golden.batches, 2);
    const StatisticalCompareResult result = compareWithGolden(golden, candidate, "darker-red-wall");
    EXPECT_EQ(result.verdict, CompareVerdict::Fail) << result.describe();
}

}  // namespace
}  // namespace refray::scenes
