// The image comparator: idiff's verdict ladder, the numbers, the mask and reference variants.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/compare.h"
#include "core/error.h"
#include "core/random.h"

using namespace refray;

namespace {

Image noiseImage(uint32_t width, uint32_t height, uint32_t seed) {
    Image image(width, height);
    Random random(0, 0, 0, seed);
    for (vec4& p : image.pixels()) p = vec4(random.nextFloat(), random.nextFloat(), random.nextFloat(), 1.0f);
    return image;
}

// An image as read from an 8-bit PNG: every value a multiple of 1/255.
Image unormImage(uint32_t width, uint32_t height) {
    Image image(width, height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x)
            image.at(x, y) = vec4(float((x * 7 + y) % 200 + 20) / 255.0f, float((y * 5) % 200 + 20) / 255.0f,
                                  float((x + y) % 200 + 20) / 255.0f, 1.0f);
    return image;
}

std::string freshDirectory(const std::string& name) {
    const std::filesystem::path dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

void touch(const std::string& path) { std::ofstream(path) << "x"; }

}  // namespace

TEST(Compare, IdenticalImagesPass) {
    const Image image = noiseImage(32, 24, 1);
    const CompareResult r = compareImages(image, image, {});
    EXPECT_EQ(r.verdict, CompareVerdict::Pass);
    EXPECT_EQ(r.maxError.value, 0.0);
    EXPECT_EQ(r.failingPixels, 0u);
    EXPECT_EQ(r.comparedPixels, 32u * 24u);
    EXPECT_TRUE(std::isinf(r.psnr));
    EXPECT_EQ(r.flip.max, 0.0);
    EXPECT_EQ(r.diffImage.width(), 32u);
    EXPECT_NE(r.describe().find("verdict         PASS"), std::string::npos) << r.describe();
}

TEST(Compare, OnePixelOffByHalfFailsAndNamesThePixel) {
    const Image reference = noiseImage(16, 12, 2);
    Image candidate = reference;
    candidate.at(5, 7).g += 0.5f;
    const CompareResult r = compareImages(reference, candidate, {});
    EXPECT_EQ(r.verdict, CompareVerdict::Fail);
    EXPECT_NEAR(r.maxError.value, 0.5, 1e-6);
    EXPECT_EQ(r.maxError.x, 5u);
    EXPECT_EQ(r.maxError.y, 7u);
    EXPECT_EQ(r.maxError.channel, 1);
    EXPECT_EQ(r.failingPixels, 1u);
    EXPECT_EQ(r.warningPixels, 1u);
    EXPECT_GT(r.flip.max, 0.1);
    EXPECT_NE(r.describe().find("at (5, 7) channel G"), std::string::npos) << r.describe();
    EXPECT_NE(r.describe().find("FAILURE"), std::string::npos);
}

TEST(Compare, ErrorBetweenWarnAndFailWarns) {
    const Image reference = noiseImage(16, 16, 3);
    Image candidate = reference;
    candidate.at(1, 2).r += 0.01f;
    CompareThresholds t;
    t.fail = 0.1;
    t.warn = 0.001;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Warn);
    t.warn = 0.02;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Pass);
}

TEST(Compare, FailPercentAllowsSomePixelsAndHardFailOverridesIt) {
    const Image reference(10, 10, vec4(0.5f));  // 100 pixels
    Image candidate = reference;
    candidate.at(9, 9).b = 1.0f;
    CompareThresholds t;
    t.failPercent = 1.0;  // 1 pixel of 100 is not more than 1 %
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Warn);
    t.warnPercent = 1.0;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Pass);
    t.hardWarn = 0.25;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Warn);
    t.hardFail = 0.25;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Fail);
    t = {};
    t.failPercent = 0.5;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Fail);
}

TEST(Compare, NaNOrInfinityFailsWhateverTheThresholds) {
    const Image reference = noiseImage(8, 8, 4);
    CompareThresholds generous;
    generous.fail = generous.warn = 10.0;
    generous.failPercent = generous.warnPercent = 100.0;
    for (const float bad : {std::nanf(""), INFINITY, -INFINITY}) {
        Image candidate = reference;
        candidate.at(3, 4).b = bad;
        const CompareResult r = compareImages(reference, candidate, generous);
        EXPECT_EQ(r.verdict, CompareVerdict::Fail) << bad;
        EXPECT_TRUE(std::isinf(r.maxError.value));
        EXPECT_EQ(r.maxError.x, 3u);
        EXPECT_EQ(r.maxError.y, 4u);
        EXPECT_EQ(r.maxError.channel, 2);
        EXPECT_EQ(r.nonFinitePixels, 1u);
        EXPECT_TRUE(std::isfinite(r.meanAbsError));
        EXPECT_NE(r.describe().find("NaN or infinity"), std::string::npos);
    }
    Image badReference = reference;
    badReference.at(0, 0).r = std::nanf("");
    EXPECT_EQ(compareImages(badReference, badReference, generous).verdict, CompareVerdict::Fail);
}

TEST(Compare, AlphaIsComparedOnlyWhenAsked) {
    const Image reference = noiseImage(8, 8, 5);
    Image candidate = reference;
    candidate.at(2, 3).a = 0.0f;
    CompareThresholds t;
    EXPECT_EQ(compareImages(reference, candidate, t).verdict, CompareVerdict::Pass);
    t.includeAlpha = true;
    const CompareResult r = compareImages(reference, candidate, t);
    EXPECT_EQ(r.verdict, CompareVerdict::Fail);
    EXPECT_EQ(r.maxError.channel, 3);
    candidate.at(2, 3).a = std::nanf("");  // a NaN in an ignored channel is ignored
    EXPECT_EQ(compareImages(reference, candidate, {}).verdict, CompareVerdict::Pass);
}

TEST(Compare, SizeMismatchNamesBothSizes) {
    const CompareResult r = compareImages(Image(64, 36), Image(32, 18), {});
    EXPECT_EQ(r.verdict, CompareVerdict::Mismatch);
    EXPECT_NE(r.mismatch.find("64x36"), std::string::npos) << r.mismatch;
    EXPECT_NE(r.mismatch.find("32x18"), std::string::npos) << r.mismatch;
    EXPECT_TRUE(r.diffImage.empty());
    EXPECT_NE(r.describe().find("MISMATCH"), std::string::npos);
}

TEST(Compare, MaskedPixelsAreReportedApartAndDoNotFail) {
    const Image reference = noiseImage(12, 10, 6);
    Image candidate = reference, mask(12, 10, vec4(0.0f, 0.0f, 0.0f, 1.0f));
    candidate.at(4, 6).r += 0.5f;
    candidate.at(7, 1).g += 0.25f;
    mask.at(4, 6) = vec4(1.0f);
    mask.at(7, 1) = vec4(0.0f, 0.0f, 1.0f / 255.0f, 0.0f);
    const CompareResult r = compareImages(reference, candidate, {}, &mask);
    EXPECT_EQ(r.verdict, CompareVerdict::Pass);
    EXPECT_EQ(r.maskedPixels, 2u);
    EXPECT_EQ(r.comparedPixels, 118u);
    EXPECT_NEAR(r.maskedMaxError.value, 0.5, 1e-6);
    EXPECT_EQ(r.maskedMaxError.x, 4u);
    EXPECT_EQ(r.maskedMaxError.y, 6u);
    EXPECT_EQ(r.maxError.value, 0.0);
    EXPECT_EQ(r.flip.pixels, 118u);
    EXPECT_NE(r.describe().find("masked pixels   2"), std::string::npos) << r.describe();

    // Without the mask the same pair fails; a NaN is never masked.
    EXPECT_EQ(compareImages(reference, candidate, {}).verdict, CompareVerdict::Fail);
    candidate.at(4, 6).r = std::nanf("");
    EXPECT_EQ(compareImages(reference, candidate, {}, &mask).verdict, CompareVerdict::Fail);

    const Image wrongMask(5, 5);
    const CompareResult m = compareImages(reference, candidate, {}, &wrongMask);
    EXPECT_EQ(m.verdict, CompareVerdict::Mismatch);
    EXPECT_NE(m.mismatch.find("5x5"), std::string::npos);
    EXPECT_NE(m.mismatch.find("12x10"), std::string::npos);
}

TEST(Compare, MeanRMSAndPSNRAreIdiffs) {
    const Image reference(2, 1, vec4(0.2f, 0.2f, 0.2f, 1.0f));
    Image candidate = reference;
    candidate.at(1, 0).r = 0.5f;  // one error of 0.3 among 6 compared values
    const CompareResult r = compareImages(reference, candidate, {});
    EXPECT_NEAR(r.meanAbsError, 0.3 / 6.0, 1e-7);
    EXPECT_NEAR(r.rmse, std::sqrt(0.09 / 6.0), 1e-7);
    EXPECT_NEAR(r.psnr, 20.0 * std::log10(1.0 / std::sqrt(0.09 / 6.0)), 1e-5);
    EXPECT_NEAR(r.failingPercent(), 50.0, 1e-9);
}

TEST(Compare, MaxErrorIsTheFirstInScanOrderAmongEquals) {
    const Image reference(6, 6, vec4(0.5f));
    Image candidate = reference;
    candidate.at(4, 1).b = 0.75f;
    candidate.at(1, 3).r = 0.75f;
    candidate.at(2, 1).g = 0.25f;
    const CompareResult r = compareImages(reference, candidate, {});
    EXPECT_EQ(r.maxError.x, 2u);
    EXPECT_EQ(r.maxError.y, 1u);
    EXPECT_EQ(r.maxError.channel, 1);
}

TEST(Compare, GoldenProfileAcceptsOneUnormStepAndFewLargerDifferences) {
    const CompareThresholds golden = CompareThresholds::golden();
    const Image reference = unormImage(100, 100);  // 10000 pixels: 0.1 % is 10
    Image oneStep = reference;
    for (vec4& p : oneStep.pixels()) p.r += 1.0f / 255.0f;
    EXPECT_EQ(compareImages(reference, oneStep, golden).verdict, CompareVerdict::Pass);

    Image fewTwoSteps = reference;
    for (uint32_t i = 0; i < 10; ++i) fewTwoSteps.at(i * 9, i * 3).g += 2.0f / 255.0f;
    EXPECT_EQ(compareImages(reference, fewTwoSteps, golden).verdict, CompareVerdict::Warn);

    Image manyTwoSteps = reference;
    for (uint32_t i = 0; i < 11; ++i) manyTwoSteps.at(i * 9, i * 3).g += 2.0f / 255.0f;
    EXPECT_EQ(compareImages(reference, manyTwoSteps, golden).verdict, CompareVerdict::Fail);

    // idiff's defaults are strict: one step fails.
    EXPECT_EQ(compareImages(reference, oneStep, {}).verdict, CompareVerdict::Fail);
}

TEST(Compare, DiffImageShowsWhereTheImagesDiffer) {
    const Image reference(40, 40, vec4(0.4f, 0.4f, 0.4f, 1.0f));
    Image candidate = reference;
    candidate.at(30, 10) = vec4(1.0f, 0.0f, 0.0f, 1.0f);
    const CompareResult flip = compareImages(reference, candidate, {});
    const auto brightness = [](const vec4& p) { return p.r + p.g + p.b; };
    EXPECT_GT(brightness(flip.diffImage.at(30, 10)), brightness(flip.diffImage.at(5, 35)) + 0.5f);
    EXPECT_EQ(flip.diffImage.at(5, 35), vec4(magma(0.0f), 1.0f));

    CompareOptions abs;
    abs.diffMode = DiffMode::AbsoluteError;
    abs.absoluteErrorScale = 0.5f;
    const CompareResult a = compareImages(reference, candidate, {}, nullptr, abs);
    const vec3 expected = magma(0.6f * 0.5f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.diffImage.at(30, 10)[c], expected[c], 1e-5) << c;
    EXPECT_EQ(a.diffImage.at(29, 10), vec4(magma(0.0f), 1.0f));
}

TEST(Compare, IsDeterministic) {
    const Image reference = noiseImage(50, 40, 8), candidate = noiseImage(50, 40, 9);
    const CompareResult a = compareImages(reference, candidate, {}), b = compareImages(reference, candidate, {});
    EXPECT_EQ(a.meanAbsError, b.meanAbsError);
    EXPECT_EQ(a.rmse, b.rmse);
    EXPECT_EQ(a.flip.mean, b.flip.mean);
    EXPECT_EQ(a.diffImage.pixels(), b.diffImage.pixels());
}

TEST(Compare, NegativeThresholdsAreAnError) {
    CompareThresholds t;
    t.failPercent = -1.0;
    try {
        compareImages(Image(2, 2), Image(2, 2), t);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--failpercent must be >= 0"), std::string::npos) << e.what();
    }
}

TEST(Compare, ReferenceVariantsAreTheFileThenStemDashAnythingSorted) {
    const std::string dir = freshDirectory("variants");
    for (const char* name : {"ref.png", "ref-gpu-b.png", "ref-gpu-a.png", "ref-x.exr", "refother.png", "ref.png.bak"})
        touch(dir + "/" + name);
    const std::vector<std::string> v = referenceVariants(dir + "/ref.png");
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(v[0], dir + "/ref.png");
    EXPECT_EQ(v[1], dir + "/ref-gpu-a.png");
    EXPECT_EQ(v[2], dir + "/ref-gpu-b.png");

    // The candidate is never its own variant.
    const std::vector<std::string> withoutCandidate = referenceVariants(dir + "/ref.png", dir + "/ref-gpu-a.png");
    ASSERT_EQ(withoutCandidate.size(), 2u);
    EXPECT_EQ(withoutCandidate[1], dir + "/ref-gpu-b.png");

    std::filesystem::remove(dir + "/ref.png");
    EXPECT_EQ(referenceVariants(dir + "/ref.png").size(), 2u);
    try {
        referenceVariants(dir + "/missing.png");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(dir + "/missing.png"), std::string::npos) << e.what();
    }
}

TEST(Compare, BestMatchPrefersTheLowestVerdictThenFewestFailures) {
    std::vector<CompareResult> results(4);
    results[0].verdict = CompareVerdict::Mismatch;
    results[1].verdict = CompareVerdict::Fail;
    results[1].failingPixels = 9;
    results[2].verdict = CompareVerdict::Fail;
    results[2].failingPixels = 3;
    results[3].verdict = CompareVerdict::Fail;
    results[3].failingPixels = 3;
    EXPECT_EQ(bestMatch(results), 2u);
    results[3].verdict = CompareVerdict::Warn;
    EXPECT_EQ(bestMatch(results), 3u);
    EXPECT_EQ(bestMatch({}), 0u);
}

TEST(Compare, TheSecondVariantMatchingPasses) {
    const std::string dir = freshDirectory("second-variant");
    const Image candidate = noiseImage(16, 16, 10);
    Image other = candidate;
    other.at(3, 3).r = other.at(3, 3).r > 0.5f ? 0.0f : 1.0f;
    writeImage(dir + "/golden.png", other);
    writeImage(dir + "/golden-gpu.png", candidate);
    const ReferenceComparison c = compareToReference(dir + "/golden.png", readImage(dir + "/golden-gpu.png"), {});
    ASSERT_EQ(c.references.size(), 2u);
    EXPECT_EQ(c.results[0].verdict, CompareVerdict::Fail);
    EXPECT_EQ(c.best, 1u);
    EXPECT_EQ(c.verdict(), CompareVerdict::Pass);
    EXPECT_EQ(c.references[c.best], dir + "/golden-gpu.png");
}

TEST(Compare, WhenNoVariantMatchesTheBestIsReported) {
    const std::string dir = freshDirectory("no-variant");
    const Image candidate = unormImage(16, 16);
    Image threeOff = candidate, oneOff = candidate;
    for (uint32_t i = 0; i < 3; ++i) threeOff.at(i, i).r = 1.0f;
    oneOff.at(5, 5).g = 0.0f;
    writeImage(dir + "/golden.png", threeOff);
    writeImage(dir + "/golden-alt.png", oneOff);
    const ReferenceComparison c = compareToReference(dir + "/golden.png", candidate, {});
    EXPECT_EQ(c.best, 1u);
    EXPECT_EQ(c.verdict(), CompareVerdict::Fail);
    EXPECT_EQ(c.bestResult().failingPixels, 1u);
    EXPECT_EQ(c.bestResult().maxError.x, 5u);
}
