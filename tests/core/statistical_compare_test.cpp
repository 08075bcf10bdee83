// Statistical comparison of noisy renders: the t distribution, Welch's test, the
// multiple-comparison corrections, statistics images and their files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "core/error.h"
#include "core/image.h"
#include "core/statistical_compare.h"
#include "tests/error_of.h"

using namespace refray;

namespace {

std::string freshDirectory(const std::string& name) {
    const std::filesystem::path dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / "statistical" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

// A noisy "render" of a fixed scene: each pixel-channel's expectation and noise level vary
// over the image (as a Monte Carlo render's do).
double expectation(uint32_t x, uint32_t y, int c) { return 0.2 + 0.6 * double((x * 7 + y * 3 + c * 5) % 17) / 16.0; }
double noiseSigma(uint32_t x, uint32_t y, int c) { return 0.02 + 0.08 * double((x + 2 * y + c) % 5) / 4.0; }

struct Shift {
    uint32_t x0 = 0, y0 = 0, size = 0;  // a size x size block
    double sigmas = 0.0;                // added to the expectation of every channel there, in units of its noise
};

bool inside(const Shift& s, uint32_t x, uint32_t y) { return x >= s.x0 && x < s.x0 + s.size && y >= s.y0 && y < s.y0 + s.size; }

// K batches of the noisy render, each expectation + sigma · N(0, 1) from a seeded mt19937.
StatisticsImage noisyStatistics(uint32_t width, uint32_t height, uint32_t batches, uint32_t seed, const Shift& shift = {}) {
    std::mt19937 generator(seed);
    std::normal_distribution<double> gaussian(0.0, 1.0);
    StatisticsAccumulator accumulator;
    for (uint32_t k = 0; k < batches; ++k) {
        Image batch(width, height);
        for (uint32_t y = 0; y < height; ++y)
            for (uint32_t x = 0; x < width; ++x) {
                vec4& p = batch.at(x, y);
                for (int c = 0; c < 3; ++c)
                    p[c] = float(expectation(x, y, c) +
                                 noiseSigma(x, y, c) * ((inside(shift, x, y) ? shift.sigmas : 0.0) + gaussian(generator)));
                p.a = 1.0f;
            }
        accumulator.add(batch);
    }
    return accumulator.finish();
}

// A statistics image of a constant colour with a constant variance of the mean.
StatisticsImage constantStatistics(uint32_t width, uint32_t height, vec3 mean, vec3 variance, uint32_t batches) {
    StatisticsImage s;
    s.mean = Image(width, height, vec4(mean, 1.0f));
    s.varianceOfMean.assign(size_t(width) * height, variance);
    s.batches = batches;
    return s;
}

// An EXR written directly, to make files writeStatisticsImage refuses to write.
void writeRawExr(const std::string& path, const std::vector<std::string>& channels,
                 const std::vector<std::pair<std::string, std::string>>& attributes) {
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(2, 2, int(channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = channels;
    for (const auto& [name, value] : attributes) spec.attribute(name, value);
    ASSERT_TRUE(out->open(path, spec));
    const std::vector<float> data(4 * channels.size(), 0.25f);
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, data.data()));
    ASSERT_TRUE(out->close());
}

using refray::testing::errorOf;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// ---- The t distribution ---------------------------------------------------------------

TEST(StudentT, IncompleteBetaMatchesClosedForms) {
    // I_x(a, 1) = x^a; I_x(1, b) = 1 − (1 − x)^b; I_x(1/2, 1/2) = (2/π) asin(√x); I_½(a, a) = ½.
    for (double x : {0.0, 0.01, 0.3, 0.5, 0.77, 0.999, 1.0}) {
        EXPECT_NEAR(regularizedIncompleteBeta(3.5, 1.0, x), std::pow(x, 3.5), 1e-13) << x;
        EXPECT_NEAR(regularizedIncompleteBeta(1.0, 4.25, x), 1.0 - std::pow(1.0 - x, 4.25), 1e-13) << x;
        EXPECT_NEAR(regularizedIncompleteBeta(0.5, 0.5, x), 2.0 / M_PI * std::asin(std::sqrt(x)), 1e-13) << x;
    }
    for (double a : {0.5, 3.0, 40.0, 1000.0}) EXPECT_NEAR(regularizedIncompleteBeta(a, a, 0.5), 0.5, 1e-12) << a;
    // High-precision reference values (30-digit evaluations).
    EXPECT_NEAR(regularizedIncompleteBeta(2.5, 3.5, 0.3), 0.29675298929566637832, 1e-13);
    EXPECT_NEAR(regularizedIncompleteBeta(100.0, 150.0, 0.41), 0.62936566529306553957, 1e-11);
    EXPECT_TRUE(contains(errorOf([] { regularizedIncompleteBeta(1.0, 1.0, 1.5); }), "0 <= x <= 1"));
    EXPECT_TRUE(contains(errorOf([] { regularizedIncompleteBeta(0.0, 1.0, 0.5); }), "a > 0"));
}

TEST(StudentT, TwoSidedPValuesMatchKnownValues) {
    // The textbook value: t = 2.0 with 10 degrees of freedom.
    EXPECT_NEAR(studentTTwoSidedP(2.0, 10.0), 0.0734, 5e-5);
    EXPECT_NEAR(studentTTwoSidedP(2.0, 10.0), 0.073388034770740366, 1e-13);
    // The 5 % critical value of a t-table at 30 degrees of freedom.
    EXPECT_NEAR(studentTTwoSidedP(2.042, 30.0), 0.05, 1e-4);
    // High-precision reference values, far tails and non-integer df included.
    EXPECT_NEAR(studentTTwoSidedP(3.0, 5.0), 0.030099247897462574, 1e-13);
    EXPECT_NEAR(studentTTwoSidedP(0.5, 2.5), 0.65769791986971469, 1e-13);
    EXPECT_NEAR(studentTTwoSidedP(0.01, 10.0), 0.99221797499097142, 1e-13);
    EXPECT_NEAR(studentTTwoSidedP(10.0, 3.0) / 0.0021283990584141501, 1.0, 1e-11);
    EXPECT_NEAR(studentTTwoSidedP(6.0, 20.0) / 7.2436999304165708e-6, 1.0, 1e-11);
    EXPECT_NEAR(studentTTwoSidedP(40.0, 4.0) / 2.3340163226012686e-6, 1.0, 1e-11);
    // Symmetric in t; 1 at t = 0; 0 for an infinite t.
    EXPECT_EQ(studentTTwoSidedP(-3.0, 5.0), studentTTwoSidedP(3.0, 5.0));
    EXPECT_DOUBLE_EQ(studentTTwoSidedP(0.0, 7.0), 1.0);
    EXPECT_EQ(studentTTwoSidedP(INFINITY, 7.0), 0.0);
    EXPECT_TRUE(std::isnan(studentTTwoSidedP(NAN, 7.0)));
    EXPECT_TRUE(contains(errorOf([] { studentTTwoSidedP(1.0, 0.0); }), "degrees of freedom > 0"));
}

TEST(StudentT, CdfMatchesClosedFormsForOneAndTwoDegreesOfFreedom) {
    // df = 1 is the Cauchy distribution: ½ + atan(t)/π. df = 2: ½ + t / (2 √(2 + t²)).
    for (double t : {-30.0, -2.5, -1.0, -0.1, 0.0, 0.3, 1.0, 4.0, 100.0}) {
        EXPECT_NEAR(studentTCdf(t, 1.0), 0.5 + std::atan(t) / M_PI, 1e-13) << t;
        EXPECT_NEAR(studentTCdf(t, 2.0), 0.5 + t / (2.0 * std::sqrt(2.0 + t * t)), 1e-13) << t;
    }
}

TEST(StudentT, LargeDegreesOfFreedomApproachTheNormal) {
    const auto normalP = [](double t) { return std::erfc(std::fabs(t) / std::sqrt(2.0)); };
    // At 10^6 degrees of freedom: the exact value is 0.049996067585 (the normal's 0.049995790).
    EXPECT_NEAR(studentTTwoSidedP(1.96, 1e6), 0.049996067585269791, 1e-10);
    double previous = 1.0;
    for (double df : {10.0, 100.0, 1e3, 1e4, 1e5, 1e6}) {
        const double gap = std::fabs(studentTTwoSidedP(3.0, df) - normalP(3.0));
        EXPECT_LT(gap, previous) << df;  // the heavier tails shrink towards the normal's
        previous = gap;
    }
    EXPECT_LT(previous, 1e-7);
    // Many degrees of freedom keep their digits (high-precision reference values).
    EXPECT_NEAR(studentTTwoSidedP(3.0, 1998.0) / 0.0027331772521444785427, 1.0, 1e-12);  // ln Γ directly
    EXPECT_NEAR(studentTTwoSidedP(3.0, 2000.0) / 0.0027331437620327993932, 1.0, 1e-12);  // Stirling's series
    EXPECT_NEAR(studentTTwoSidedP(0.2, 5000.0), 0.84148871460050586366, 1e-13);
    // The relative error grows as about 1e-17·df.
    EXPECT_NEAR(studentTTwoSidedP(2.5, 1e7) / 0.012419346536578470167, 1.0, 1e-9);
    EXPECT_NEAR(studentTTwoSidedP(6.0, 1e7) / 1.9732427333677835118e-9, 1.0, 1e-9);
    EXPECT_NEAR(studentTTwoSidedP(6.0, 1e9) / 1.9731759644984918864e-9, 1.0, 1e-7);
    // Beyond 1e10 (and at infinity) the normal is used, which is closer there.
    EXPECT_NEAR(studentTTwoSidedP(3.0, 1e12) / 0.0026997960633266667795, 1.0, 1e-10);
    EXPECT_NEAR(studentTCdf(-1.0, 1e16), 0.5 * normalP(1.0), 1e-16);
    EXPECT_DOUBLE_EQ(studentTTwoSidedP(2.0, INFINITY), normalP(2.0));  // within 4 ulps: -O3 may fold the lambda differently
}

// ---- Welch's test -----------------------------------------------------------------------

TEST(Welch, DegreesOfFreedom) {
    // (1 + 4)² / (1/9 + 16/4) = 225/37.
    EXPECT_NEAR(welchDegreesOfFreedom(1.0, 10, 4.0, 5), 225.0 / 37.0, 1e-12);
    // Equal variances and counts: 2(n − 1), the pooled test's.
    EXPECT_NEAR(welchDegreesOfFreedom(0.3, 8, 0.3, 8), 14.0, 1e-12);
    // Variance on one side only: that side's n − 1.
    EXPECT_NEAR(welchDegreesOfFreedom(0.0, 16, 2.0, 4), 3.0, 1e-12);
    EXPECT_TRUE(std::isnan(welchDegreesOfFreedom(0.0, 16, 0.0, 4)));
    EXPECT_TRUE(contains(errorOf([] { welchDegreesOfFreedom(1.0, 1, 1.0, 4); }), "at least 2 samples"));
}

TEST(Welch, TestStatisticAndPValue) {
    const WelchTest w = welchTTest(1.5, 0.09, 10, 1.0, 0.16, 5);
    EXPECT_NEAR(w.t, 0.5 / std::sqrt(0.25), 1e-12);
    EXPECT_NEAR(w.df, 0.0625 / (0.0081 / 9.0 + 0.0256 / 4.0), 1e-12);
    EXPECT_NEAR(w.p, studentTTwoSidedP(1.0, w.df), 1e-15);
    EXPECT_FALSE(w.exact);
    EXPECT_EQ(welchTTest(1.0, 0.16, 5, 1.5, 0.09, 10).p, w.p);  // symmetric
}

TEST(Welch, ZeroVarianceOnBothSidesIsAnExactComparison) {
    const WelchTest equal = welchTTest(0.25, 0.0, 4, 0.25, 0.0, 16);
    EXPECT_TRUE(equal.exact);
    EXPECT_EQ(equal.p, 1.0);
    const WelchTest unequal = welchTTest(0.25, 0.0, 4, 0.2500001, 0.0, 16);
    EXPECT_TRUE(unequal.exact);
    EXPECT_EQ(unequal.p, 0.0);
    EXPECT_TRUE(std::isinf(unequal.t));
}

TEST(Welch, NonFiniteInputGivesNaN) {
    EXPECT_TRUE(std::isnan(welchTTest(NAN, 0.1, 4, 0.0, 0.1, 4).p));
    EXPECT_TRUE(std::isnan(welchTTest(0.0, 0.1, 4, INFINITY, 0.1, 4).p));
    EXPECT_TRUE(std::isnan(welchTTest(0.0, NAN, 4, 0.0, 0.1, 4).p));
}

// ---- Corrections ------------------------------------------------------------------------

TEST(Correction, SidakAndBonferroniThresholds) {
    using C = MultipleComparisonCorrection;
    EXPECT_DOUBLE_EQ(correctedThreshold(0.01, 1, C::Sidak), 0.01);
    EXPECT_DOUBLE_EQ(correctedThreshold(0.01, 1, C::Bonferroni), 0.01);
    EXPECT_DOUBLE_EQ(correctedThreshold(0.01, 1000, C::Bonferroni), 1e-5);
    EXPECT_NEAR(correctedThreshold(0.01, 1000, C::Sidak) / (1.0 - std::pow(0.99, 1e-3)), 1.0, 1e-9);
    EXPECT_NEAR(correctedThreshold(0.01, 1000, C::Sidak), 1.00503e-5, 1e-10);
    // Šidák is the exact level for independent tests and a little above Bonferroni's.
    for (uint64_t n : {2ull, 3ull, 100ull, 2764800ull}) {
        const double sidak = correctedThreshold(0.05, n, C::Sidak);
        EXPECT_GT(sidak, correctedThreshold(0.05, n, C::Bonferroni)) << n;
        EXPECT_NEAR(1.0 - std::pow(1.0 - sidak, double(n)), 0.05, 1e-9) << n;
    }
    EXPECT_TRUE(contains(errorOf([] { correctedThreshold(1.0, 10, C::Sidak); }), "between 0 and 1"));
    EXPECT_TRUE(contains(errorOf([] { correctedThreshold(0.01, 0, C::Sidak); }), "at least one test"));
    EXPECT_EQ(toString(C::Sidak), "sidak");
    EXPECT_EQ(toString(C::Bonferroni), "bonferroni");
}

TEST(Correction, APValueBetweenTheThresholdsFailsUnderSidakOnly) {
    // One pixel: 3 tests. With n = 2 batches per side and equal variances df = 2, where the
    // two-sided p is 1 − t / √(2 + t²); pick t for a p halfway between the two thresholds.
    const double sidak = correctedThreshold(0.01, 3, MultipleComparisonCorrection::Sidak);
    const double bonferroni = correctedThreshold(0.01, 3, MultipleComparisonCorrection::Bonferroni);
    const double p = 0.5 * (sidak + bonferroni);
    const double t = std::sqrt(2.0) * (1.0 - p) / std::sqrt(1.0 - (1.0 - p) * (1.0 - p));
    const StatisticsImage reference = constantStatistics(1, 1, vec3(0.0f), vec3(0.5f), 2);
    const StatisticsImage candidate = constantStatistics(1, 1, vec3(float(t), 0.0f, 0.0f), vec3(0.5f), 2);
    StatisticalCompareOptions options;
    const StatisticalCompareResult s = compareStatistics(reference, candidate, options);
    EXPECT_NEAR(s.smallest.test.p, p, 1e-6 * p);
    EXPECT_EQ(s.verdict, CompareVerdict::Fail);
    EXPECT_DOUBLE_EQ(s.threshold, sidak);
    options.correction = MultipleComparisonCorrection::Bonferroni;
    const StatisticalCompareResult b = compareStatistics(reference, candidate, options);
    EXPECT_EQ(b.verdict, CompareVerdict::Pass) << b.describe();
    EXPECT_DOUBLE_EQ(b.threshold, bonferroni);
    EXPECT_TRUE(contains(b.describe(), "bonferroni-corrected"));
}

// ---- Statistics images ------------------------------------------------------------------

TEST(StatisticsImage, MeanAndVarianceOfTheMean) {
    std::vector<Image> batches;
    for (float v : {1.0f, 2.0f, 4.0f, 5.0f}) {
        Image b(2, 1, vec4(v, 2.0f * v, 3.0f, 0.5f * v));
        b.metadata["scene"] = "s" + std::to_string(int(v));
        batches.push_back(b);
    }
    const StatisticsImage s = computeStatistics(batches);
    EXPECT_EQ(s.batches, 4u);
    // Mean 3; unbiased sample variance (4 + 1 + 1 + 4) / 3 = 10/3; of the mean 10/12.
    EXPECT_FLOAT_EQ(s.mean.at(1, 0).r, 3.0f);
    EXPECT_FLOAT_EQ(s.mean.at(1, 0).g, 6.0f);
    EXPECT_FLOAT_EQ(s.mean.at(1, 0).a, 1.5f);
    EXPECT_FLOAT_EQ(s.variance(1, 0).r, 10.0f / 12.0f);
    EXPECT_FLOAT_EQ(s.variance(1, 0).g, 40.0f / 12.0f);
    EXPECT_EQ(s.variance(1, 0).b, 0.0f);  // identical batches: exactly 0
    EXPECT_EQ(s.mean.metadata.at("scene"), "s1");  // the first batch's provenance
    EXPECT_EQ(s.mean.metadata.at(kStatisticsBatchesKey), "4");
}

TEST(StatisticsImage, BadBatchesAreErrors) {
    StatisticsAccumulator one;
    one.add(Image(4, 4));
    EXPECT_TRUE(contains(errorOf([&] { one.finish(); }), "at least 2"));
    EXPECT_TRUE(contains(errorOf([&] { one.add(Image(4, 5)); }), "batch 2 is 4x5, the first batch 4x4"));
}

TEST(StatisticsImage, FileRoundTripKeepsEverything) {
    const std::string dir = freshDirectory("round-trip");
    StatisticsImage s = noisyStatistics(13, 7, 5, 42);
    s.mean.metadata["scene"] = "noisy";
    s.mean.metadata["seed"] = "42";
    s.mean.at(3, 2).a = 0.25f;
    const std::string path = dir + "/stats.exr";
    writeStatisticsImage(path, s);
    const StatisticsImage r = readStatisticsImage(path);
    EXPECT_EQ(r.batches, 5u);
    ASSERT_EQ(r.width(), 13u);
    ASSERT_EQ(r.height(), 7u);
    for (size_t i = 0; i < s.mean.pixels().size(); ++i) {
        EXPECT_EQ(r.mean.pixels()[i], s.mean.pixels()[i]) << i;
        EXPECT_EQ(r.varianceOfMean[i], s.varianceOfMean[i]) << i;
    }
    EXPECT_EQ(r.mean.metadata.at("scene"), "noisy");
    EXPECT_EQ(r.mean.metadata.at("seed"), "42");
    EXPECT_EQ(r.mean.metadata.at(kStatisticsBatchesKey), "5");
    // Any image reader sees the mean.
    const Image plain = readImage(path);
    for (size_t i = 0; i < s.mean.pixels().size(); ++i) EXPECT_EQ(plain.pixels()[i], s.mean.pixels()[i]) << i;
}

TEST(StatisticsImage, BadFilesAreClearErrors) {
    const std::string dir = freshDirectory("bad-files");
    // A plain image: no variance channels.
    const std::string png = dir + "/plain.png";
    writeImage(png, Image(4, 4, vec4(0.5f)));
    const std::string plain = errorOf([&] { readStatisticsImage(png); });
    EXPECT_TRUE(contains(plain, "'" + png + "' is not a statistics image: it has no variance channels var.R, var.G, "
                                            "var.B (it has R, G, B, A)"))
        << plain;
    EXPECT_TRUE(contains(plain, "--batches K")) << plain;
    // Variance channels, but no batch count.
    const std::string noCount = dir + "/no-count.exr";
    writeRawExr(noCount, {"R", "G", "B", "A", "var.R", "var.G", "var.B"}, {});
    const std::string missing = errorOf([&] { readStatisticsImage(noCount); });
    EXPECT_TRUE(contains(missing, "'" + noCount + "' has the variance channels but no metadata refray:statistics_batches"))
        << missing;
    // One batch.
    const std::string oneBatch = dir + "/one-batch.exr";
    writeRawExr(oneBatch, {"R", "G", "B", "var.R", "var.G", "var.B"}, {{"refray:statistics_batches", "1"}});
    const std::string one = errorOf([&] { readStatisticsImage(oneBatch); });
    EXPECT_TRUE(contains(one, "'" + oneBatch + "' was estimated from 1 batch; a variance needs at least 2")) << one;
    // Missing colour.
    const std::string noColour = dir + "/no-colour.exr";
    writeRawExr(noColour, {"Y", "var.R", "var.G", "var.B"}, {{"refray:statistics_batches", "4"}});
    EXPECT_TRUE(contains(errorOf([&] { readStatisticsImage(noColour); }), "lacks the mean's R, G, B channels"));
    // Not there.
    EXPECT_TRUE(contains(errorOf([&] { readStatisticsImage(dir + "/absent.exr"); }), "absent.exr': no such file"));
    // Writing needs EXR and two batches.
    const StatisticsImage s = noisyStatistics(4, 4, 2, 1);
    EXPECT_TRUE(contains(errorOf([&] { writeStatisticsImage(dir + "/s.png", s); }), "a file name ending in .exr"));
}

// ---- The comparison ---------------------------------------------------------------------

TEST(StatisticalCompare, SameDistributionPassesAtTheRateAlphaPromises) {
    // 50 independent trials of a 32x32 image (3072 tests each) whose reference and candidate
    // come from the same distribution. Under the null hypothesis each trial fails with
    // probability alpha = 0.01 (about 0.5 of 50; 4 or more has probability 0.0016), and the
    // uncorrected count below alpha is about alpha·N per trial.
    const int trials = 50;
    int failures = 0;
    uint64_t belowAlpha = 0, tests = 0;
    for (int trial = 0; trial < trials; ++trial) {
        const StatisticsImage reference = noisyStatistics(32, 32, 16, 1000 + trial);
        const StatisticsImage candidate = noisyStatistics(32, 32, 8, 5000 + trial);
        const StatisticalCompareResult r = compareStatistics(reference, candidate);
        EXPECT_EQ(r.tests, 3072u);
        failures += r.verdict == CompareVerdict::Fail;
        belowAlpha += r.belowAlpha;
        tests += r.tests;
    }
    EXPECT_LE(failures, 3);
    const double rate = double(belowAlpha) / double(tests);
    EXPECT_GT(rate, 0.008);
    EXPECT_LT(rate, 0.012);
}

TEST(StatisticalCompare, AShiftedBlockFailsAndTheMapMarksIt) {
    // A 10x10 block whose expectation moves by 8 standard errors of the difference of the means.
    const uint32_t referenceBatches = 16, candidateBatches = 8;
    const Shift shift{20, 15, 10, 8.0 * std::sqrt(1.0 / referenceBatches + 1.0 / candidateBatches)};

    const StatisticsImage reference = noisyStatistics(48, 40, referenceBatches, 7);
    StatisticsImage candidate = noisyStatistics(48, 40, candidateBatches, 8, shift);
    const StatisticalCompareResult r = compareStatistics(reference, candidate);
    EXPECT_EQ(r.verdict, CompareVerdict::Fail) << r.describe();
    EXPECT_TRUE(inside(shift, r.smallest.x, r.smallest.y)) << r.describe();
    EXPECT_LT(r.smallest.test.p, r.threshold);

    // The map: red where failing, only inside the block, and at most dark grey elsewhere.
    uint32_t redInside = 0, redOutside = 0;
    for (uint32_t y = 0; y < r.failureMap.height(); ++y)
        for (uint32_t x = 0; x < r.failureMap.width(); ++x) {
            const vec4 c = r.failureMap.at(x, y);
            const bool red = c == vec4(1.0f, 0.0f, 0.0f, 1.0f);
            if (red) (inside(shift, x, y) ? redInside : redOutside) += 1;
            else EXPECT_TRUE(c.r == c.g && c.g == c.b && c.r <= 0.6f) << x << ", " << y;
        }
    EXPECT_EQ(redOutside, 0u);
    EXPECT_GE(redInside, 50u);
    EXPECT_EQ(redInside, r.failingPixels);

    // Without the shift the same seeds pass.
    EXPECT_EQ(compareStatistics(reference, noisyStatistics(48, 40, candidateBatches, 8)).verdict, CompareVerdict::Pass);
}

TEST(StatisticalCompare, DeterministicRendersCompareExactly) {
    const StatisticsImage reference = constantStatistics(4, 3, vec3(0.5f, 0.25f, 1.0f), vec3(0.0f), 2);
    StatisticsImage candidate = reference;
    candidate.batches = 16;
    StatisticalCompareResult same = compareStatistics(reference, candidate);
    EXPECT_EQ(same.verdict, CompareVerdict::Pass);
    EXPECT_TRUE(same.allExact());
    EXPECT_TRUE(contains(same.describe(), "this is an exact comparison")) << same.describe();
    candidate.mean.at(2, 1).g += 1e-6f;
    const StatisticalCompareResult different = compareStatistics(reference, candidate);
    EXPECT_EQ(different.verdict, CompareVerdict::Fail);
    EXPECT_EQ(different.failingTests, 1u);
    EXPECT_EQ(different.smallest.x, 2u);
    EXPECT_EQ(different.smallest.y, 1u);
    EXPECT_EQ(different.smallest.channel, 1);
    EXPECT_EQ(different.smallest.test.p, 0.0);
    EXPECT_TRUE(contains(different.describe(), "smallest p      0 at (2, 1) channel G")) << different.describe();
}

TEST(StatisticalCompare, NonFiniteValuesFailAndAreReported) {
    StatisticsImage reference = noisyStatistics(8, 8, 4, 3);
    StatisticsImage candidate = reference;
    candidate.mean.at(5, 6).b = NAN;
    reference.varianceOfMean[size_t(1) * 8 + 2].r = INFINITY;
    const StatisticalCompareResult r = compareStatistics(reference, candidate);
    EXPECT_EQ(r.verdict, CompareVerdict::Fail);
    EXPECT_EQ(r.nonFiniteTests, 2u);
    EXPECT_EQ(r.failingTests, 2u);
    EXPECT_EQ(r.failingPixels, 2u);
    EXPECT_EQ(r.firstNonFinite.x, 2u);
    EXPECT_EQ(r.firstNonFinite.y, 1u);
    EXPECT_EQ(r.failureMap.at(5, 6), vec4(1.0f, 0.0f, 1.0f, 1.0f));
    EXPECT_TRUE(contains(r.describe(), "non-finite      2 tests hold NaN or infinity (always a failure), the first at "
                                       "(2, 1) channel R"))
        << r.describe();
}

TEST(StatisticalCompare, SizeMismatchAndBadOptions) {
    const StatisticsImage a = noisyStatistics(8, 8, 4, 3);
    const StatisticsImage b = noisyStatistics(8, 9, 4, 3);
    const StatisticalCompareResult r = compareStatistics(a, b);
    EXPECT_EQ(r.verdict, CompareVerdict::Mismatch);
    EXPECT_EQ(r.mismatch, "size mismatch: the reference is 8x8, the candidate 8x9");
    EXPECT_TRUE(r.failureMap.empty());
    StatisticalCompareOptions options;
    options.alpha = 0.0;
    EXPECT_TRUE(contains(errorOf([&] { compareStatistics(a, a, options); }), "alpha must lie between 0 and 1"));
    StatisticsImage one = a;
    one.batches = 1;
    EXPECT_TRUE(contains(errorOf([&] { compareStatistics(a, one); }), "candidate statistics were estimated from 1 batch"));
}

TEST(StatisticalCompare, ReportNamesEveryNumber) {
    const StatisticalCompareResult r = compareStatistics(noisyStatistics(10, 10, 4, 1), noisyStatistics(10, 10, 4, 2));
    const std::string text = r.describe();
    for (const char* line : {"size            10x10, RGB tested: 300 pixel-channel tests", "batches         reference 4, candidate 4",
                             "alpha           0.01 for the whole image; sidak-corrected: ", "smallest p      ",
                             "below alpha     ", "(about 3 expected when the images agree)", "failing         ",
                             "verdict         PASS"})
        EXPECT_TRUE(contains(text, line)) << line << "\n" << text;
}
