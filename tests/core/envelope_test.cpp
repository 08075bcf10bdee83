// core/envelope.cpp: making an envelope from renders, its EXR form, and judging a candidate against it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/envelope.h"
#include "core/error.h"

namespace refray {
namespace {

Image flat(uint32_t w, uint32_t h, int code) { return Image(w, h, vec4(float(code) / 255.0f, 0.5f, 0.5f, 1.0f)); }

// 10x10, nominal code 100; pixel (0,0) of every variant moves by `spread` steps, the rest by nothing.
Envelope twoClassEnvelope(int spread, uint32_t k = 8) {
    const Image nominal = flat(10, 10, 100);
    std::vector<Image> variants(k, nominal);
    for (uint32_t i = 0; i < k; ++i) variants[i].at(0, 0).r = float(100 + (i % 2 ? spread : -spread)) / 255.0f;
    std::vector<const Image*> pointers;
    for (const Image& v : variants) pointers.push_back(&v);
    return makeEnvelope(nominal, pointers, k, nullptr);
}

TEST(Envelope, ContainsTheNominalAndClassifies) {
    const Envelope e = twoClassEnvelope(5);
    EXPECT_EQ(e.variants, 9u);
    EXPECT_EQ(e.pixelClass[0], PixelClass::Sensitive);
    EXPECT_EQ(e.lo[0][0], 95);
    EXPECT_EQ(e.hi[0][0], 105);
    EXPECT_EQ(e.sensitivePixels(), 1u);
    for (size_t i = 0; i < e.lo.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            EXPECT_LE(e.lo[i][c], floatToUnorm8(e.nominal.pixels()[i][c]));
            EXPECT_GE(e.hi[i][c], floatToUnorm8(e.nominal.pixels()[i][c]));
        }
    EXPECT_EQ(twoClassEnvelope(1).pixelClass[0], PixelClass::Stable);  // one step is stable
}

TEST(Envelope, JudgesStablePixelsByCountAndSensitiveOnesAgainstTheirBounds) {
    const Envelope e = twoClassEnvelope(5);
    Image c = e.nominal;
    c.at(0, 0).r = 106.0f / 255.0f;  // sensitive: hi + 1 allowed
    c.at(5, 5).r = 101.0f / 255.0f;  // stable: one step allowed
    EXPECT_EQ(judgeEnvelope(e, c, {}).verdict, CompareVerdict::Pass);
    c.at(5, 5).r = 102.0f / 255.0f;  // a stable pixel two steps off: within the budget, but no render did it
    EnvelopeJudgement j = judgeEnvelope(e, c, {});
    EXPECT_EQ(j.verdict, CompareVerdict::Warn);
    EXPECT_EQ(j.stableOutside, 1u);
    EXPECT_EQ(j.expectedStableOutside, 0.0);
    // No leave-one-out render moved a stable pixel (T = 0): y = 3 clusters, since (1/9)^3 > 1e-3 >= (1/9)^4.
    EXPECT_EQ(j.stableBudget, 27u);
    ASSERT_EQ(j.outside.size(), 1u);
    EXPECT_EQ(j.outside[0].x, 5u);
    EXPECT_EQ(j.outside[0].steps, 1);
    EXPECT_EQ(j.heatMap.at(5, 5), vec4(1.0f, 0.0f, 0.0f, 1.0f));
    // 28 stable pixels moved ((5, 5) and 27 more): more than a correct candidate may, at the false-alarm rate 1e-3.
    for (uint32_t i = 0; i < 27; ++i) c.at(1 + i % 9, 1 + i / 9).r = 103.0f / 255.0f;
    j = judgeEnvelope(e, c, {});
    EXPECT_EQ(j.stableOutside, 28u);
    EXPECT_EQ(j.verdict, CompareVerdict::Fail);
    EXPECT_NE(j.describe().find("28 stable pixels moved, more than 27 allowed"), std::string::npos) << j.describe();
}

// c_i: the pixels that perturbed render i alone moves (stable over the nominal and every other render); a pixel two
// renders move counts for neither, an order-dependent pixel for none, a non-perturbed variant's move for none.
TEST(Envelope, CalibratesTheStableBudgetByLeaveOneOut) {
    const Image nominal = flat(20, 20, 100);
    std::vector<Image> variants(4, nominal);  // 3 perturbed + double
    for (uint32_t i = 0; i < 30; ++i) variants[0].at(i % 20, i / 20).r = 103.0f / 255.0f;  // 30 by render 0 alone
    variants[1].at(0, 10).b = 0.2f;                                                          // 1 by render 1 alone
    variants[1].at(1, 10).r = variants[2].at(1, 10).r = 0.9f;                                // 2 renders: none
    variants[3].at(2, 10).r = 0.9f;                                                          // double: none
    variants[2].at(3, 10).r = 0.9f;                                                          // order-dependent
    Image mask(20, 20, vec4(0.0f, 0.0f, 0.0f, 1.0f));
    mask.at(3, 10) = vec4(1.0f);
    std::vector<const Image*> pointers;
    for (const Image& v : variants) pointers.push_back(&v);
    const Envelope e = makeEnvelope(nominal, pointers, 3, &mask);
    EXPECT_EQ(e.stableMovesLeaveOneOut, (std::vector<uint64_t>{30, 1, 0}));
    // The c_i scatter more than 9-pixel clusters allow: mean 31/3, sample variance 290.3, so clusters of
    // ceil(290.3 / 10.33) = 29; T = ceil(30/29) + ceil(1/29) = 3 clusters; p = 1/4: the largest y with
    // P(Binomial(y + 3, 1/4) >= y) > 1e-3 is 8, so 8 x 29 pixels.
    EXPECT_EQ(leaveOneOutClusterSize(e.stableMovesLeaveOneOut, {}), 29u);
    EXPECT_EQ(stableBudget(e, {}), 232u);
    // Counts as even as Poisson 9-pixel clusters keep the cluster size of the options.
    Envelope even = e;
    even.stableMovesLeaveOneOut = {20, 21, 22};
    EXPECT_EQ(leaveOneOutClusterSize(even.stableMovesLeaveOneOut, {}), 9u);

    const std::filesystem::path dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / "envelope";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "loo.envelope.exr").string();
    writeEnvelope(path, e);
    EXPECT_EQ(readEnvelope(path).stableMovesLeaveOneOut, e.stableMovesLeaveOneOut);
}

TEST(Envelope, SensitivePixelsOutsideAreCountedAgainstTheBinomialBudget) {
    const Envelope e = twoClassEnvelope(5);
    Image c = e.nominal;
    c.at(0, 0).r = 120.0f / 255.0f;
    const EnvelopeJudgement j = judgeEnvelope(e, c, {});
    EXPECT_EQ(j.sensitiveOutside, 1u);
    EXPECT_EQ(j.outside[0].steps, 14);
    EXPECT_NEAR(j.outsideProbability, 2.0 / 9.0, 1e-12);
    EXPECT_EQ(j.sensitiveBudget, 1u);  // one cluster, capped at the sensitive pixels
    EXPECT_EQ(j.verdict, CompareVerdict::Warn);  // within the budget, above the expected 2/9 pixel
}

// s_i: the sensitive pixels where perturbed render i lies more than one step outside the bounds of every other render
// (the nominal and the non-perturbed variants included), as a candidate is judged; the sensitive budget is the larger
// of the binomial one and the leave-one-out one, capped at the sensitive pixels.
TEST(Envelope, CalibratesTheSensitiveBudgetByLeaveOneOut) {
    const Image nominal = flat(20, 20, 100);
    std::vector<Image> variants(4, nominal);  // 3 perturbed + double
    for (uint32_t i = 0; i < 40; ++i) {
        variants[0].at(i % 20, i / 20).r = 150.0f / 255.0f;  // far above the others
        variants[1].at(i % 20, i / 20).r = 95.0f / 255.0f;   // below the others by more than one step
        variants[2].at(i % 20, i / 20).r = 105.0f / 255.0f;  // inside [95, 150]
    }
    variants[3].at(0, 10).r = 110.0f / 255.0f;  // the double render alone: sensitive, but no perturbed render outside
    std::vector<const Image*> pointers;
    for (const Image& v : variants) pointers.push_back(&v);
    const Envelope e = makeEnvelope(nominal, pointers, 3, nullptr);
    EXPECT_EQ(e.sensitivePixels(), 41u);
    EXPECT_EQ(e.sensitiveOutsideLeaveOneOut, (std::vector<uint64_t>{40, 40, 0}));
    const EnvelopeJudgement j = judgeEnvelope(e, nominal, {});
    EXPECT_EQ(j.sensitiveBudget, std::min<uint64_t>(41, leaveOneOutBudget(e.sensitiveOutsideLeaveOneOut, {})));
    EXPECT_NEAR(j.expectedOutside, 80.0 / 3.0, 1e-9);  // the leave-one-out mean exceeds 41 x 2/4

    const std::filesystem::path dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / "envelope";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "sensitive-loo.envelope.exr").string();
    writeEnvelope(path, e);
    EXPECT_EQ(readEnvelope(path).sensitiveOutsideLeaveOneOut, e.sensitiveOutsideLeaveOneOut);
}

TEST(Envelope, NaNAlwaysFailsAndOrderPixelsAreReportedApart) {
    const Image nominal = flat(4, 4, 50);
    Image mask(4, 4, vec4(0.0f, 0.0f, 0.0f, 1.0f));
    mask.at(1, 1) = vec4(1.0f);
    const Envelope e = makeEnvelope(nominal, {}, 0, &mask);
    Image c = nominal;
    c.at(1, 1).r = 0.9f;
    EnvelopeJudgement j = judgeEnvelope(e, c, {});
    EXPECT_EQ(j.orderOutside, 1u);
    EXPECT_EQ(j.verdict, CompareVerdict::Pass);
    c.at(1, 1).g = std::numeric_limits<float>::quiet_NaN();
    j = judgeEnvelope(e, c, {});
    EXPECT_EQ(j.nonFinite, 1u);
    EXPECT_EQ(j.verdict, CompareVerdict::Fail);
    EXPECT_EQ(judgeEnvelope(e, flat(5, 4, 50), {}).verdict, CompareVerdict::Mismatch);
}

TEST(Envelope, RoundTripsThroughExrAndRefusesCorruptedFiles) {
    const std::filesystem::path dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / "envelope";
    std::filesystem::create_directories(dir);
    Envelope e = twoClassEnvelope(5);
    e.provenance["scene_sha256"] = "abc";
    const std::string path = (dir / "e.envelope.exr").string();
    writeEnvelope(path, e);
    EXPECT_TRUE(isEnvelopeFile(path));
    const Envelope back = readEnvelope(path);
    EXPECT_EQ(back.lo, e.lo);
    EXPECT_EQ(back.hi, e.hi);
    EXPECT_EQ(back.pixelClass, e.pixelClass);
    EXPECT_EQ(back.perturbedRenders, 8u);
    EXPECT_EQ(back.provenance.at("scene_sha256"), "abc");

    e.lo[3][1] = 200;  // the nominal (code 128) below its lower bound
    writeEnvelope(path, e);
    try {
        readEnvelope(path);
        ADD_FAILURE() << "a corrupted envelope was read";
    } catch (const Error& error) {
        EXPECT_NE(std::string(error.what()).find("is corrupted at (3, 0)"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
    }
    std::ofstream(path, std::ios::binary) << "not an EXR";
    EXPECT_THROW(readEnvelope(path), Error);
}

}  // namespace
}  // namespace refray
