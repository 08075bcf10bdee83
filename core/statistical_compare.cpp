#include "core/statistical_compare.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <boost/math/distributions/students_t.hpp>
#include <boost/math/special_functions/beta.hpp>

#include "core/error.h"
#include "core/image_file.h"

namespace refray {

namespace {

constexpr const char kChannelNames[] = "RGB";
constexpr const char* kMetadataPrefix = "refray:";  // as core/image.cpp writes metadata
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

std::string sizeText(uint32_t width, uint32_t height) { return std::to_string(width) + "x" + std::to_string(height); }

bool endsWithExr(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".exr";
}

// ---- Report helpers --------------------------------------------------------------------

void describeSide(std::ostream& out, const char* name, double mean, double variance) {
    out << name << " " << mean;
    if (variance > 0.0) out << " +/- " << std::sqrt(variance);
    else out << " (no variance)";
}

void describeLocation(std::ostream& out, const PixelTest& t) {
    out << "(" << t.x << ", " << t.y << ") channel " << kChannelNames[t.channel];
}

// ---- Reading ---------------------------------------------------------------------------

std::string channelList(const OIIO::ImageSpec& spec) {
    std::string list;
    for (const std::string& name : spec.channelnames) list += (list.empty() ? "" : ", ") + name;
    return list;
}

uint32_t parseBatches(const std::string& path, const std::map<std::string, std::string>& metadata) {
    const auto found = metadata.find(kStatisticsBatchesKey);
    REFRAY_CHECK(found != metadata.end(),
                 "'" << path << "' has the variance channels but no metadata " << kMetadataPrefix << kStatisticsBatchesKey
                     << " (the number of batches its variance was estimated from); write it with "
                        "writeStatisticsImage or 'refray render ... --batches K'");
    const std::string& text = found->second;
    char* end = nullptr;
    const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
    REFRAY_CHECK(!text.empty() && *end == '\0' && std::isdigit((unsigned char)text[0]) && value <= 0xFFFFFFFFull,
                 "'" << path << "': " << kMetadataPrefix << kStatisticsBatchesKey << " must be a whole number, got '"
                     << text << "'");
    REFRAY_CHECK(value >= 2, "'" << path << "' was estimated from " << value
                                 << " batch; a variance needs at least 2 independent batches (render with --batches 2 "
                                    "or more)");
    return uint32_t(value);
}

}  // namespace

// ---- Statistics images -------------------------------------------------------------------

void StatisticsAccumulator::add(const Image& batch) {
    REFRAY_CHECK(!batch.empty(), "statistics: batch " << batches_ + 1 << " is an empty image");
    if (batches_ == 0) {
        width_ = batch.width();
        height_ = batch.height();
        mean_.assign(size_t(width_) * height_ * 4, 0.0);
        squaredDiffs_.assign(size_t(width_) * height_ * 3, 0.0);
        metadata_ = batch.metadata;
    }
    REFRAY_CHECK(batch.width() == width_ && batch.height() == height_,
                 "statistics: batch " << batches_ + 1 << " is " << sizeText(batch.width(), batch.height())
                                      << ", the first batch " << sizeText(width_, height_));
    ++batches_;
    // Welford's update: the running mean, and M2 = the sum of squared differences from it.
    const double k = double(batches_);
    const std::vector<vec4>& pixels = batch.pixels();
    for (size_t i = 0; i < pixels.size(); ++i) {
        for (int c = 0; c < 4; ++c) {
            const double value = pixels[i][c];
            double& mean = mean_[i * 4 + c];
            const double delta = value - mean;
            mean += delta / k;
            if (c < 3) squaredDiffs_[i * 3 + c] += delta * (value - mean);
        }
    }
}

StatisticsImage StatisticsAccumulator::finish() const {
    REFRAY_CHECK(batches_ >= 2, "statistics: " << batches_
                                               << " batch given; estimating a variance needs at least 2 independent "
                                                  "renders (batches)");
    StatisticsImage stats;
    stats.batches = batches_;
    stats.mean = Image(width_, height_);
    stats.mean.metadata = metadata_;
    stats.mean.metadata[kStatisticsBatchesKey] = std::to_string(batches_);
    stats.varianceOfMean.resize(size_t(width_) * height_);
    // The unbiased sample variance M2 / (K − 1), divided by K: the variance of the mean.
    const double scale = 1.0 / (double(batches_ - 1) * double(batches_));
    for (size_t i = 0; i < stats.varianceOfMean.size(); ++i) {
        for (int c = 0; c < 4; ++c) stats.mean.pixels()[i][c] = float(mean_[i * 4 + c]);
        for (int c = 0; c < 3; ++c) stats.varianceOfMean[i][c] = float(squaredDiffs_[i * 3 + c] * scale);
    }
    return stats;
}

StatisticsImage computeStatistics(const std::vector<Image>& batches) {
    StatisticsAccumulator accumulator;
    for (const Image& batch : batches) accumulator.add(batch);
    return accumulator.finish();
}

void writeStatisticsImage(const std::string& path, const StatisticsImage& stats) {
    REFRAY_CHECK(endsWithExr(path), "cannot write the statistics image '"
                                        << path << "': it needs OpenEXR (a file name ending in .exr) to hold the "
                                                   "float mean and variance channels");
    REFRAY_CHECK(!stats.mean.empty(), "cannot write '" << path << "': the statistics image is empty");
    REFRAY_CHECK(stats.varianceOfMean.size() == stats.mean.pixels().size(),
                 "cannot write '" << path << "': " << stats.varianceOfMean.size() << " variances for "
                                  << stats.mean.pixels().size() << " pixels");
    REFRAY_CHECK(stats.batches >= 2, "cannot write '" << path << "': " << stats.batches
                                                      << " batch; a statistics image needs at least 2");

    OIIO::ImageSpec spec(int(stats.width()), int(stats.height()), 7, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "A", kVarianceChannelNames[0], kVarianceChannelNames[1], kVarianceChannelNames[2]};
    spec.alpha_channel = 3;
    for (const auto& [key, value] : stats.mean.metadata) spec.attribute(kMetadataPrefix + key, value);
    spec.attribute(std::string(kMetadataPrefix) + kStatisticsBatchesKey, std::to_string(stats.batches));
    spec.attribute("compression", "zip");
    spec.attribute("oiio:UnassociatedAlpha", 1);

    std::vector<float> data(stats.mean.pixels().size() * 7);
    for (size_t i = 0; i < stats.mean.pixels().size(); ++i) {
        for (int c = 0; c < 4; ++c) data[i * 7 + c] = stats.mean.pixels()[i][c];
        for (int c = 0; c < 3; ++c) data[i * 7 + 4 + c] = stats.varianceOfMean[i][c];
    }
    writeImageFile(path, spec, OIIO::TypeDesc::FLOAT, data.data());
}

StatisticsImage readStatisticsImage(const std::string& path) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = openImageFile(path, "statistics image", config);
    const OIIO::ImageSpec& spec = in->spec();

    // Channels by name: OpenEXR stores them sorted, not in the order written.
    int colour[4], variance[3];
    for (int c = 0; c < 4; ++c) colour[c] = spec.channelindex(std::string(1, "RGBA"[c]));
    for (int c = 0; c < 3; ++c) variance[c] = spec.channelindex(kVarianceChannelNames[c]);
    REFRAY_CHECK(colour[0] >= 0 && colour[1] >= 0 && colour[2] >= 0,
                 "'" << path << "' is not a statistics image: it lacks the mean's R, G, B channels (it has "
                     << channelList(spec) << ")");
    REFRAY_CHECK(variance[0] >= 0 && variance[1] >= 0 && variance[2] >= 0,
                 "'" << path << "' is not a statistics image: it has no variance channels " << kVarianceChannelNames[0]
                     << ", " << kVarianceChannelNames[1] << ", " << kVarianceChannelNames[2] << " (it has "
                     << channelList(spec)
                     << "); a statistical comparison needs the mean and variance of several independent renders: "
                        "make one with 'refray render SCENE --batches K -o FILE.exr'");

    std::map<std::string, std::string> metadata;
    const std::string prefix = kMetadataPrefix;
    for (const auto& attribute : spec.extra_attribs) {
        const std::string name = attribute.name().string();
        if (name.rfind(prefix, 0) == 0) metadata[name.substr(prefix.size())] = attribute.get_string();
    }
    const uint32_t batches = parseBatches(path, metadata);

    const int channels = spec.nchannels;
    std::vector<float> data(size_t(spec.width) * spec.height * channels);
    REFRAY_CHECK(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()),
                 "cannot read pixels of '" << path << "': " << in->geterror());

    StatisticsImage stats;
    stats.batches = batches;
    stats.mean = Image(uint32_t(spec.width), uint32_t(spec.height));
    stats.mean.metadata = std::move(metadata);
    stats.varianceOfMean.resize(stats.mean.pixels().size());
    for (size_t i = 0; i < stats.varianceOfMean.size(); ++i) {
        const float* p = &data[i * channels];
        stats.mean.pixels()[i] = vec4(p[colour[0]], p[colour[1]], p[colour[2]], colour[3] >= 0 ? p[colour[3]] : 1.0f);
        for (int c = 0; c < 3; ++c) {
            const float v = p[variance[c]];
            REFRAY_CHECK(!(v < 0.0f), "'" << path << "' holds a negative variance, " << v << ", at ("
                                          << i % uint32_t(spec.width) << ", " << i / uint32_t(spec.width)
                                          << ") channel " << kVarianceChannelNames[c]);
            stats.varianceOfMean[i][c] = v;
        }
    }
    return stats;
}

// ---- The t-test -------------------------------------------------------------------------

double regularizedIncompleteBeta(double a, double b, double x) {
    REFRAY_CHECK(a > 0.0 && b > 0.0 && x >= 0.0 && x <= 1.0,
                 "the incomplete beta function needs a > 0, b > 0 and 0 <= x <= 1, got a = " << a << ", b = " << b
                                                                                            << ", x = " << x);
    return boost::math::ibeta(a, b, x);
}

namespace {

boost::math::students_t tDistribution(double df) {
    REFRAY_CHECK(df > 0.0, "the t distribution needs degrees of freedom > 0, got " << df);
    return boost::math::students_t(df);
}

}  // namespace

double studentTTwoSidedP(double t, double df) {
    if (std::isnan(t) || std::isnan(df)) return kNaN;
    // The upper tail directly: 1 − cdf would lose the small p-values the test turns on.
    return 2.0 * boost::math::cdf(boost::math::complement(tDistribution(df), std::fabs(t)));
}

double studentTCdf(double t, double df) {
    if (std::isnan(t) || std::isnan(df)) return kNaN;
    return boost::math::cdf(tDistribution(df), t);
}

double welchDegreesOfFreedom(double v1, uint32_t n1, double v2, uint32_t n2) {
    REFRAY_CHECK(n1 >= 2 && n2 >= 2, "Welch's degrees of freedom need at least 2 samples per side, got " << n1
                                                                                                        << " and " << n2);
    if (v1 == 0.0 && v2 == 0.0) return kNaN;
    const double sum = v1 + v2;
    return sum * sum / (v1 * v1 / double(n1 - 1) + v2 * v2 / double(n2 - 1));
}

WelchTest welchTTest(double m1, double v1, uint32_t n1, double m2, double v2, uint32_t n2) {
    REFRAY_CHECK(n1 >= 2 && n2 >= 2, "Welch's t-test needs at least 2 batches per side, got " << n1 << " and " << n2);
    WelchTest r;
    if (!std::isfinite(m1) || !std::isfinite(m2) || !std::isfinite(v1) || !std::isfinite(v2)) {
        r.t = r.df = r.p = kNaN;
        return r;
    }
    REFRAY_CHECK(v1 >= 0.0 && v2 >= 0.0, "Welch's t-test: a variance is negative (" << v1 << ", " << v2 << ")");
    const double variance = v1 + v2;
    if (variance == 0.0) {
        // Deterministic on both sides: the means are the expectations.
        r.exact = true;
        r.df = kNaN;
        r.t = m1 == m2 ? 0.0 : std::copysign(kInfinity, m1 - m2);
        r.p = m1 == m2 ? 1.0 : 0.0;
        return r;
    }
    r.t = (m1 - m2) / std::sqrt(variance);
    r.df = welchDegreesOfFreedom(v1, n1, v2, n2);
    r.p = studentTTwoSidedP(r.t, r.df);
    return r;
}

// ---- The image comparison ----------------------------------------------------------------

std::string_view toString(MultipleComparisonCorrection correction) {
    switch (correction) {
        case MultipleComparisonCorrection::Sidak: return "sidak";
        case MultipleComparisonCorrection::Bonferroni: return "bonferroni";
    }
    return "?";
}

double correctedThreshold(double alpha, uint64_t tests, MultipleComparisonCorrection correction) {
    REFRAY_CHECK(alpha > 0.0 && alpha < 1.0, "the significance level alpha must lie between 0 and 1, got " << alpha);
    REFRAY_CHECK(tests >= 1, "a multiple-comparison correction needs at least one test");
    if (correction == MultipleComparisonCorrection::Bonferroni) return alpha / double(tests);
    // 1 − (1 − alpha)^(1/N), without losing digits to the subtraction from 1.
    return -std::expm1(std::log1p(-alpha) / double(tests));
}

StatisticalCompareResult compareStatistics(const StatisticsImage& reference, const StatisticsImage& candidate,
                                           const StatisticalCompareOptions& options) {
    REFRAY_CHECK(options.alpha > 0.0 && options.alpha < 1.0,
                 "the significance level alpha must lie between 0 and 1, got " << options.alpha);
    REFRAY_CHECK(reference.batches >= 2, "the reference statistics were estimated from " << reference.batches
                                                                                         << " batch; at least 2 needed");
    REFRAY_CHECK(candidate.batches >= 2, "the candidate statistics were estimated from " << candidate.batches
                                                                                         << " batch; at least 2 needed");
    REFRAY_CHECK(reference.varianceOfMean.size() == reference.mean.pixels().size() &&
                     candidate.varianceOfMean.size() == candidate.mean.pixels().size(),
                 "a statistics image needs one variance per pixel");

    StatisticalCompareResult result;
    result.options = options;
    result.width = reference.width();
    result.height = reference.height();
    result.referenceBatches = reference.batches;
    result.candidateBatches = candidate.batches;
    if (candidate.width() != reference.width() || candidate.height() != reference.height()) {
        result.verdict = CompareVerdict::Mismatch;
        result.mismatch = "size mismatch: the reference is " + sizeText(reference.width(), reference.height()) +
                          ", the candidate " + sizeText(candidate.width(), candidate.height());
        return result;
    }
    result.tests = uint64_t(result.width) * result.height * 3;
    REFRAY_CHECK(result.tests > 0, "the statistics images are empty");
    result.threshold = correctedThreshold(options.alpha, result.tests, options.correction);
    result.smallest.test.p = kInfinity;
    result.failureMap = Image(result.width, result.height, vec4(0.0f, 0.0f, 0.0f, 1.0f));
    const double logThreshold = std::log10(result.threshold);

    for (uint32_t y = 0; y < result.height; ++y) {
        for (uint32_t x = 0; x < result.width; ++x) {
            const vec4& m1 = reference.mean.at(x, y);
            const vec4& m2 = candidate.mean.at(x, y);
            const vec3& v1 = reference.variance(x, y);
            const vec3& v2 = candidate.variance(x, y);
            bool failing = false, nonFinite = false;
            double pixelP = 1.0;
            for (int c = 0; c < 3; ++c) {
                PixelTest t;
                t.x = x, t.y = y, t.channel = c;
                t.referenceMean = m1[c], t.referenceVariance = v1[c];
                t.candidateMean = m2[c], t.candidateVariance = v2[c];
                t.test = welchTTest(m1[c], v1[c], reference.batches, m2[c], v2[c], candidate.batches);
                if (std::isnan(t.test.p)) {
                    if (result.nonFiniteTests++ == 0) result.firstNonFinite = t;
                    ++result.failingTests;
                    nonFinite = true;
                    continue;
                }
                if (t.test.exact) ++result.exactTests;
                if (t.test.p < result.threshold) ++result.failingTests, failing = true;
                if (t.test.p < options.alpha) ++result.belowAlpha;
                if (t.test.p < result.smallest.test.p) result.smallest = t;
                pixelP = std::min(pixelP, t.test.p);
            }
            if (failing || nonFinite) ++result.failingPixels;
            vec4& shown = result.failureMap.at(x, y);
            if (nonFinite) shown = vec4(1.0f, 0.0f, 1.0f, 1.0f);
            else if (failing) shown = vec4(1.0f, 0.0f, 0.0f, 1.0f);
            else shown = vec4(vec3(float(0.6 * std::min(1.0, std::log10(pixelP) / logThreshold))), 1.0f);
        }
    }
    result.verdict = result.failingTests > 0 ? CompareVerdict::Fail : CompareVerdict::Pass;
    return result;
}

std::string StatisticalCompareResult::describe() const {
    std::ostringstream out;
    out.precision(6);
    if (verdict == CompareVerdict::Mismatch) {
        out << "  " << mismatch << "\n  verdict         " << toString(verdict) << "\n";
        return out.str();
    }
    out << "  size            " << sizeText(width, height) << ", RGB tested: " << tests << " pixel-channel tests\n";
    out << "  batches         reference " << referenceBatches << ", candidate " << candidateBatches << "\n";
    out << "  alpha           " << options.alpha << " for the whole image; " << toString(options.correction)
        << "-corrected: " << threshold << " per test\n";
    out << "  smallest p      ";
    if (std::isinf(smallest.test.p)) {
        out << "none (every test is non-finite)\n";
    } else {
        out << smallest.test.p << " at ";
        describeLocation(out, smallest);
        out << ": ";
        describeSide(out, "reference", smallest.referenceMean, smallest.referenceVariance);
        out << ", ";
        describeSide(out, "candidate", smallest.candidateMean, smallest.candidateVariance);
        if (smallest.test.exact) out << " (compared exactly)\n";
        else out << " (mean +/- standard error), t = " << smallest.test.t << ", df = " << smallest.test.df << "\n";
    }
    out << "  below alpha     " << belowAlpha << " tests with p < " << options.alpha << " uncorrected";
    if (!allExact()) out << " (about " << expectedBelowAlpha() << " expected when the images agree)";
    out << "\n";
    if (exactTests) out << "  exact tests     " << exactTests << " without variance on either side, compared exactly\n";
    if (nonFiniteTests) {
        out << "  non-finite      " << nonFiniteTests << " tests hold NaN or infinity (always a failure), the first at ";
        describeLocation(out, firstNonFinite);
        out << "\n";
    }
    out << "  failing         " << failingTests << " tests in " << failingPixels << " pixels below " << threshold << "\n";
    if (allExact())
        out << "  note            no variance anywhere (deterministic renders): this is an exact comparison, any "
               "difference fails\n";
    out << "  verdict         " << toString(verdict);
    if (verdict == CompareVerdict::Pass)
        out << " (no pixel-channel differs by more than the noise explains at alpha " << options.alpha << ")\n";
    else
        out << " (" << failingTests << " pixel-channel" << (failingTests == 1 ? " differs" : "s differ")
            << " beyond what the noise explains at alpha " << options.alpha << ")\n";
    return out.str();
}

}  // namespace refray
