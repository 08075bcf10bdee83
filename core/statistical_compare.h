// Statistical comparison of noisy (Monte Carlo) renders, as Mitsuba 3's render tests do:
// a per-pixel, per-channel Welch t-test between two "statistics images" (the mean of K
// independent renders and the estimated variance of that mean), with a correction for
// testing every pixel-channel at once. docs/compare.md, "Statistical comparison (noisy
// renders)", is the user's guide; `refray compare --statistical` the command.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/compare.h"
#include "core/image.h"

namespace refray {

// The metadata key holding the batch count K (in the file: "refray:statistics_batches").
inline constexpr const char* kStatisticsBatchesKey = "statistics_batches";
// The names of the variance channels in a statistics EXR, after R, G, B, A.
inline constexpr const char* kVarianceChannelNames[3] = {"var.R", "var.G", "var.B"};

// A render estimated from `batches` independent renders (different seeds): per pixel, the
// mean of the batches (RGBA; alpha is carried along, never tested) and the estimated
// variance of that mean (RGB): the unbiased sample variance over the batches divided by K.
struct StatisticsImage {
    Image mean;                        // its metadata is the file's (provenance, batches)
    std::vector<vec3> varianceOfMean;  // one per pixel, row-major like mean.pixels()
    uint32_t batches = 0;              // K, the number of independent renders (>= 2)

    uint32_t width() const { return mean.width(); }
    uint32_t height() const { return mean.height(); }
    const vec3& variance(uint32_t x, uint32_t y) const { return varianceOfMean[size_t(y) * mean.width() + x]; }
};

// Builds a StatisticsImage from batches added one at a time (Welford's update in double,
// in the order added: the result depends on that order only, never on threads or time),
// so K renders never have to be held in memory together.
class StatisticsAccumulator {
public:
    // Adds one batch. Throws refray::Error when its size differs from the first batch's.
    void add(const Image& batch);
    uint32_t batches() const { return batches_; }

    // The statistics of the batches added so far; the metadata is the first batch's with
    // statistics_batches = K. Throws refray::Error with fewer than 2 batches (no variance).
    StatisticsImage finish() const;

private:
    uint32_t width_ = 0, height_ = 0, batches_ = 0;
    std::vector<double> mean_;          // 4 per pixel
    std::vector<double> squaredDiffs_;  // 3 per pixel: Welford's M2
    std::map<std::string, std::string> metadata_;
};

// computeStatistics(batches): the same as adding each to a StatisticsAccumulator.
StatisticsImage computeStatistics(const std::vector<Image>& batches);

// Writes one OpenEXR file (32-bit float) with channels R, G, B, A (the mean, so any image
// viewer shows the render) and var.R, var.G, var.B (the variance of the mean), and the
// metadata (refray:statistics_batches = K, with the rest of stats.mean.metadata). Throws
// refray::Error naming `path` when it does not end in .exr or cannot be written.
void writeStatisticsImage(const std::string& path, const StatisticsImage& stats);

// Reads a file written by writeStatisticsImage. Throws refray::Error naming `path` when it
// cannot be read, lacks R, G, B or the variance channels, lacks statistics_batches, has
// K < 2, or holds a negative variance.
StatisticsImage readStatisticsImage(const std::string& path);

// ---- The t-test ----------------------------------------------------------------------

// The regularized incomplete beta function I_x(a, b), a, b > 0, x in [0, 1] (Boost.Math's
// ibeta). Throws refray::Error outside that domain.
double regularizedIncompleteBeta(double a, double b, double x);

// Student's t distribution with `df` > 0 degrees of freedom (Boost.Math's students_t): the
// CDF P(T <= t), and the two-sided p-value P(|T| >= |t|) = I_{df/(df+t²)}(df/2, 1/2), taken
// from the upper tail so that small p-values keep their relative precision (within 1e-14
// wherever the p-value is a normal double, at any df). Beyond 1/epsilon = 4.5e15 degrees of
// freedom (infinity included) both are the normal distribution's. NaN t gives NaN.
double studentTCdf(double t, double df);
double studentTTwoSidedP(double t, double df);

// Welch–Satterthwaite degrees of freedom of the difference of two means whose variances
// (of the mean) are v1 and v2, each estimated from n1, n2 >= 2 samples:
//   (v1 + v2)² / (v1²/(n1 − 1) + v2²/(n2 − 1)).
// NaN when v1 = v2 = 0 (there is nothing to estimate).
double welchDegreesOfFreedom(double v1, uint32_t n1, double v2, uint32_t n2);

struct WelchTest {
    double t = 0.0;   // (m1 − m2) / sqrt(v1 + v2); ±inf for unequal means without variance
    double df = 0.0;  // welchDegreesOfFreedom; NaN without variance
    double p = 1.0;   // two-sided
    bool exact = false;  // v1 = v2 = 0: p is 1 for equal means, 0 otherwise
};

// Welch's t-test of H0 "equal expectations" for means m1, m2 with variances of the mean v1,
// v2 from n1, n2 batches. Without variance on both sides (deterministic renders) it is an
// exact comparison: equal means pass (p = 1), unequal ones fail (p = 0). A non-finite input
// gives p = NaN (the comparison reports it as a failure).
WelchTest welchTTest(double m1, double v1, uint32_t n1, double m2, double v2, uint32_t n2);

// ---- The image comparison ------------------------------------------------------------

enum class MultipleComparisonCorrection {
    Sidak,       // alpha per test = 1 − (1 − alpha)^(1/N): exact for independent tests
    Bonferroni,  // alpha per test = alpha / N: a little stricter, valid under any dependence
};

// "sidak", "bonferroni".
std::string_view toString(MultipleComparisonCorrection correction);

// The per-test threshold that keeps the probability of any false alarm among `tests`
// independent tests at `alpha`. Throws refray::Error unless 0 < alpha < 1 and tests >= 1.
double correctedThreshold(double alpha, uint64_t tests, MultipleComparisonCorrection correction);

struct StatisticalCompareOptions {
    double alpha = 0.01;  // the probability of a false alarm for the whole image
    MultipleComparisonCorrection correction = MultipleComparisonCorrection::Sidak;
};

// One pixel-channel's test. Channel 0..2 is R, G, B.
struct PixelTest {
    uint32_t x = 0, y = 0;
    int channel = 0;
    double referenceMean = 0.0, referenceVariance = 0.0;  // variance of the mean
    double candidateMean = 0.0, candidateVariance = 0.0;
    WelchTest test;
};

struct StatisticalCompareResult {
    CompareVerdict verdict = CompareVerdict::Pass;  // Pass, Fail or Mismatch
    std::string mismatch;  // why the verdict is Mismatch (names both sizes); else empty
    StatisticalCompareOptions options;

    uint32_t width = 0, height = 0;
    uint32_t referenceBatches = 0, candidateBatches = 0;
    uint64_t tests = 0;        // N: pixel-channels tested (RGB of every pixel)
    double threshold = 0.0;    // the corrected per-test threshold
    uint64_t failingTests = 0;   // p < threshold, non-finite ones included
    uint64_t failingPixels = 0;  // pixels with a failing channel
    uint64_t belowAlpha = 0;     // p < alpha (uncorrected): about alpha·N when the images agree
    uint64_t exactTests = 0;     // tests without variance on either side (exact comparisons)
    uint64_t nonFiniteTests = 0;  // a NaN or infinity in a mean or variance of either image
    PixelTest smallest;    // the smallest finite p; the first in scan order (y, x, channel) among equals
    PixelTest firstNonFinite;  // meaningful when nonFiniteTests > 0

    // The failure map, one pixel per pixel: red (1, 0, 0) where a channel fails, magenta
    // (1, 0, 1) where a value is NaN or infinite, otherwise grey g = 0.6 · min(1, log10(p) /
    // log10(threshold)) of the pixel's smallest p (black: no evidence of a difference; 0.6:
    // at the threshold). Empty for a mismatch.
    Image failureMap;

    double expectedBelowAlpha() const { return options.alpha * double(tests); }
    bool allExact() const { return tests > 0 && exactTests == tests; }

    // A multi-line human report, each line indented by two spaces and ended by a newline.
    std::string describe() const;
};

// Tests every pixel-channel (RGB) of `candidate` against `reference` and applies the
// correction: the verdict is Fail when any p-value (or a non-finite value) is below the
// corrected threshold. Different sizes give the verdict Mismatch with a message, not an
// exception. Deterministic. Throws refray::Error for an alpha outside (0, 1) or fewer
// than 2 batches on either side.
StatisticalCompareResult compareStatistics(const StatisticsImage& reference, const StatisticsImage& candidate,
                                           const StatisticalCompareOptions& options = {});

}  // namespace refray
