// core/regional_count_test.cpp: the regional, directional count test of envelope goldens (issue 27).
#include <gtest/gtest.h>

#include <bit>
#include <filesystem>

#include "core/envelope.h"
#include "core/regional_count_test.h"

namespace refray {
namespace {

constexpr uint32_t kW = 120, kH = 80;

Image flat() { return Image(kW, kH, vec4(100.0f / 255.0f, 0.5f, 0.5f, 1.0f)); }

// A legal render: `moves` pixels scattered over the image (a fixed linear congruential sequence from `seed`), each
// three steps up or down.
Image scattered(uint32_t seed, uint32_t moves) {
    Image image = flat();
    uint64_t state = seed * 2654435761u + 12345u;
    const auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return uint32_t(state >> 33);
    };
    for (uint32_t m = 0; m < moves; ++m) {
        const uint32_t x = next() % kW, y = next() % kH;
        image.at(x, y).r = float(next() % 2 ? 103 : 97) / 255.0f;
    }
    return image;
}

// Two objects, the left and right halves of the image; K = 8 legal renders moving 20 pixels each.
Envelope twoObjectEnvelope() {
    std::vector<Image> renders;
    for (uint32_t k = 1; k <= 8; ++k) renders.push_back(scattered(k, 20));
    std::vector<const Image*> pointers;
    for (const Image& r : renders) pointers.push_back(&r);
    ObjectMap objects;
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) objects.ids.push_back(x < kW / 2 ? 0 : 1);
    objects.names = {{0, "object 'left'"}, {1, "object 'right'"}};
    return makeEnvelope(flat(), pointers, 8, nullptr, &objects);
}

TEST(RegionalCountTest, TileSizesAreFractionsOfTheWidth) {
    EXPECT_EQ(regionalTileSizes(640), (std::vector<uint32_t>{16, 32, 64}));
    EXPECT_EQ(regionalTileSizes(320), (std::vector<uint32_t>{8, 16, 32}));
    EXPECT_EQ(regionalTileSizes(20), (std::vector<uint32_t>{2}));
}

TEST(RegionalCountTest, LeaveOneOutFlagsHaveADirection) {
    const Envelope e = twoObjectEnvelope();
    uint64_t up = 0, down = 0;
    for (size_t i = 0; i < e.objects.ids.size(); ++i) {
        up += std::popcount(e.leaveOneOutFlags[int(FlagFamily::StableUp)][i]);
        down += std::popcount(e.leaveOneOutFlags[int(FlagFamily::StableDown)][i]);
    }
    uint64_t moved = 0;
    for (uint64_t c : e.stableMovesLeaveOneOut) moved += c;
    EXPECT_EQ(up + down, moved);  // every leave-one-out stable move is flagged once, up or down
    EXPECT_GT(up, 40u);
    EXPECT_GT(down, 40u);
}

// A bug that moves fewer pixels than the whole-image budget allows, all of them down in one small area, fails the
// regional test, which names the object and the tile; a ninth legal render, scattered as the others, passes.
TEST(RegionalCountTest, ConcentratedDamageFailsWhereScatteredMovesPass) {
    const Envelope e = twoObjectEnvelope();
    Image bug = flat();
    for (uint32_t y = 40; y < 45; ++y)
        for (uint32_t x = 90; x < 96; ++x) bug.at(x, y).r = 96.0f / 255.0f;
    const EnvelopeJudgement j = judgeEnvelope(e, bug, {});
    EXPECT_LE(j.stableOutside, j.stableBudget) << j.describe();  // the whole-image count lets it pass
    ASSERT_TRUE(j.regional.available);
    ASSERT_TRUE(j.regional.failed()) << j.describe();
    EXPECT_EQ(j.verdict, CompareVerdict::Fail);
    const RegionalFinding& worst = j.regional.failing.front();
    EXPECT_EQ(worst.family, FlagFamily::StableDown);
    EXPECT_EQ(worst.objectName, "object 'right'");
    EXPECT_GE(worst.x1, 90u);
    EXPECT_LE(worst.x0, 95u);
    EXPECT_EQ(worst.legal.size(), 8u);
    EXPECT_LT(worst.adjustedP, 1e-3);
    const std::string text = j.describe();
    EXPECT_NE(text.find("stable pixels moved down, object 'right', "), std::string::npos) << text;
    EXPECT_NE(text.find("legal renders:"), std::string::npos) << text;
    // Outlined on the heat map.
    EXPECT_EQ(j.heatMap.at(worst.x0, worst.y0), vec4(0.0f, 1.0f, 1.0f, 1.0f));

    const EnvelopeJudgement legal = judgeEnvelope(e, scattered(9, 20), {});
    EXPECT_TRUE(legal.regional.available);
    EXPECT_FALSE(legal.regional.failed()) << legal.describe();
    EXPECT_GT(legal.regional.smallestAdjustedP, 1e-3);
    EXPECT_NE(legal.verdict, CompareVerdict::Fail) << legal.describe();
}

// Legal flags scattered one by one calibrate clusters of about one pixel, and no heterogeneity below 1.
TEST(RegionalCountTest, CalibratesClusterSizeFromTheRendersFlags) {
    const Envelope e = twoObjectEnvelope();
    const auto calibration = calibrateRegions(e);
    ASSERT_EQ(calibration.size(), 2u);
    for (const auto& [id, families] : calibration)
        for (const RegionalCalibration& c : families) {
            EXPECT_GE(c.clusterSize, 1.0);
            EXPECT_LT(c.clusterSize, 3.0);  // scattered single pixels: clusters of about one
            EXPECT_GE(c.heterogeneity, 1.0);
        }
}

// An envelope without the regional planes is written as refray-envelope/1, loads, and is judged by the whole-image
// counts alone, which the report says.
TEST(RegionalCountTest, AnOlderEnvelopeIsJudgedByTheWholeImageCounts) {
    Envelope e = twoObjectEnvelope();
    const std::filesystem::path dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / "regional";
    std::filesystem::create_directories(dir);
    const std::string current = (dir / "v2.envelope.exr").string();
    writeEnvelope(current, e);
    const Envelope read = readEnvelope(current);
    EXPECT_EQ(read.format, kEnvelopeFormat);
    EXPECT_EQ(read.objects.ids, e.objects.ids);
    EXPECT_EQ(read.objects.names, e.objects.names);
    for (int f = 0; f < kFlagFamilies; ++f) EXPECT_EQ(read.leaveOneOutFlags[f], e.leaveOneOutFlags[f]);

    for (auto& flags : e.leaveOneOutFlags) flags.clear();
    e.objects = {};
    const std::string older = (dir / "v1.envelope.exr").string();
    writeEnvelope(older, e);
    const Envelope v1 = readEnvelope(older);
    EXPECT_EQ(v1.format, kEnvelopeFormatV1);
    Image bug = flat();
    for (uint32_t y = 40; y < 45; ++y)
        for (uint32_t x = 90; x < 96; ++x) bug.at(x, y).r = 96.0f / 255.0f;
    const EnvelopeJudgement j = judgeEnvelope(v1, bug, {});
    EXPECT_FALSE(j.regional.available);
    EXPECT_NE(j.verdict, CompareVerdict::Fail);
    EXPECT_NE(j.describe().find("regional        not judged: this envelope (refray-envelope/1)"), std::string::npos)
        << j.describe();
}

}  // namespace
}  // namespace refray
