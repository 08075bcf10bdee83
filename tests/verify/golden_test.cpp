// The golden set (tests/golden/goldens.json): every scene file x camera re-rendered and compared with the shared
// comparator (core/compare.h), masked pixels reported apart. On failure the actual image, the expected one and
// the diff heat map are written to the test output directory. Goldens change only through `refray golden update`.
// Monte Carlo scenes have statistical goldens instead (statistical_golden_test.cpp).
#include <gtest/gtest.h>

#include <filesystem>

#include "core/compare.h"
#include "core/hash.h"
#include "verify/golden.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;

const fs::path kGoldenDirectory = fs::path(REFRAY_SOURCE_DIR) / "tests" / "golden";

std::vector<GoldenEntry> goldenEntries() {
    try {
        return readGoldenManifest(kGoldenDirectory / "goldens.json").entries;
    } catch (const Error&) {
        return {};  // reported by GoldenSet.ManifestCoversEveryCamera
    }
}

}  // namespace

// What gtest prints for a parameter: the golden's name, not its bytes.
void PrintTo(const GoldenEntry& entry, std::ostream* os) { *os << entry.name; }

namespace {

class Golden : public ::testing::TestWithParam<GoldenEntry> {};

TEST_P(Golden, MatchesTheReRender) {
    const GoldenEntry& golden = GetParam();
    const fs::path scenePath = fs::path(REFRAY_SOURCE_DIR) / golden.scene;
    ASSERT_EQ(sha256HexOfFile(scenePath), golden.sceneSha256)
        << golden.scene << " changed since its goldens were made; review the change and run `refray golden update`";

    Scene scene(loadSceneFile(scenePath));
    const RenderResult actual = scene.render(goldenSettings(golden, 2));
    const Image expected = readImage((kGoldenDirectory / golden.image).string());
    const Image mask = readImage((kGoldenDirectory / golden.mask).string());
    const CompareResult result = compareImages(expected, actual.image, CompareThresholds::golden(), &mask);
    EXPECT_EQ(result.maskedPixels, golden.orderDependentPixels);
    if (result.verdict == CompareVerdict::Pass) return;

    const fs::path out = fs::path(REFRAY_TEST_OUTPUT_DIR) / "golden";
    fs::create_directories(out);
    writeImage((out / (golden.name + ".actual.exr")).string(), actual.image);
    writeImage((out / (golden.name + ".expected.exr")).string(), expected);
    writeImage((out / (golden.name + ".diff.png")).string(), result.diffImage);
    ADD_FAILURE() << golden.name << ": " << toString(result.verdict) << "\n"
                  << result.describe() << "  actual, expected and diff written to " << out.string();
}

std::string goldenName(const ::testing::TestParamInfo<GoldenEntry>& info) {
    std::string name = info.param.name;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

INSTANTIATE_TEST_SUITE_P(EveryCamera, Golden, ::testing::ValuesIn(goldenEntries()), goldenName);

TEST(GoldenSet, ManifestCoversEveryCameraOfEverySceneFile) {
    const GoldenSet set = readGoldenManifest(kGoldenDirectory / "goldens.json");
    size_t cameras = 0;
    for (const auto& f : fs::directory_iterator(fs::path(REFRAY_SOURCE_DIR) / "scenes")) {
        if (f.path().extension() != ".json") continue;
        const SceneDesc desc = loadSceneFile(f.path());
        if (isMonteCarlo(desc)) continue;  // statistical goldens (statistical_golden_test.cpp)
        for (const CameraDesc& c : desc.cameras) {
            ++cameras;
            bool found = false;
            for (const GoldenEntry& e : set.entries) found = found || (e.name == desc.name + "." + c.name);
            EXPECT_TRUE(found) << desc.name << "." << c.name << " has no golden; run `refray golden update`";
        }
    }
    EXPECT_EQ(set.entries.size(), cameras);
    for (const GoldenEntry& e : set.entries) {
        EXPECT_TRUE(fs::exists(kGoldenDirectory / e.image)) << e.image;
        EXPECT_TRUE(fs::exists(kGoldenDirectory / e.mask)) << e.mask;
    }
    // Statistical goldens name a Monte Carlo scene's camera and have their statistics image.
    for (const StatisticalGoldenEntry& e : set.statistical) {
        const SceneDesc desc = loadSceneFile(fs::path(REFRAY_SOURCE_DIR) / e.scene);
        EXPECT_TRUE(isMonteCarlo(desc)) << e.name << ": threshold goldens cover deterministic scenes";
        EXPECT_EQ(e.name, desc.name + "." + desc.camera(e.camera).name);
        EXPECT_TRUE(fs::exists(kGoldenDirectory / e.image)) << e.image;
    }
}

}  // namespace
}  // namespace refray::scenes
