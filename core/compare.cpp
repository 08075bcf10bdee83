#include "core/compare.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <tuple>

#include "core/error.h"

namespace refray {

namespace {

constexpr const char kChannelNames[] = "RGBA";

std::string sizeText(uint32_t width, uint32_t height) {
    return std::to_string(width) + "x" + std::to_string(height);
}

void checkThreshold(const char* name, double value) {
    REFRAY_CHECK(!std::isnan(value) && value >= 0.0, "compare: " << name << " must be >= 0, got " << value);
}

bool maskCovers(const vec4& m) { return m.r != 0.0f || m.g != 0.0f || m.b != 0.0f; }

void describeLocation(std::ostream& out, const PixelError& e) {
    out << e.value << " at (" << e.x << ", " << e.y << ") channel " << kChannelNames[e.channel];
}

}  // namespace

std::string_view toString(CompareVerdict verdict) {
    switch (verdict) {
        case CompareVerdict::Pass: return "PASS";
        case CompareVerdict::Warn: return "WARNING";
        case CompareVerdict::Fail: return "FAILURE";
        case CompareVerdict::Mismatch: return "MISMATCH";
    }
    return "?";
}

CompareThresholds CompareThresholds::golden() {
    CompareThresholds t;
    t.fail = 0.005;
    t.failPercent = 0.1;
    t.warn = 0.005;
    t.warnPercent = 0.0;
    return t;
}

double CompareResult::failingPercent() const {
    return comparedPixels ? 100.0 * double(failingPixels) / double(comparedPixels) : 0.0;
}

double CompareResult::warningPercent() const {
    return comparedPixels ? 100.0 * double(warningPixels) / double(comparedPixels) : 0.0;
}

std::string CompareResult::describe() const {
    std::ostringstream out;
    out.precision(6);
    if (verdict == CompareVerdict::Mismatch) {
        out << "  " << mismatch << "\n  verdict         " << toString(verdict) << "\n";
        return out.str();
    }
    const auto percent = [](double p) {
        std::ostringstream s;
        s.precision(3);
        s << p << "%";
        return s.str();
    };
    out << "  size            " << sizeText(width, height) << ", " << (thresholds.includeAlpha ? "RGBA" : "RGB")
        << " compared, " << comparedPixels << " pixels (" << maskedPixels << " masked)\n";
    out << "  mean error      " << meanAbsError << "\n";
    out << "  RMS error       " << rmse << "\n";
    out << "  peak SNR        " << psnr << " dB\n";
    out << "  max error       ";
    describeLocation(out, maxError);
    out << "\n";
    out << "  failing pixels  " << failingPixels << " (" << percent(failingPercent()) << ") over " << thresholds.fail
        << " (allowed: " << percent(thresholds.failPercent) << ", none over " << thresholds.hardFail << ")\n";
    out << "  warning pixels  " << warningPixels << " (" << percent(warningPercent()) << ") over " << thresholds.warn
        << " (allowed: " << percent(thresholds.warnPercent) << ", none over " << thresholds.hardWarn << ")\n";
    if (nonFinitePixels) out << "  non-finite      " << nonFinitePixels << " pixels hold NaN or infinity (always a failure)\n";
    out << "  FLIP            mean " << flip.mean << ", median " << flip.median << ", quartiles " << flip.firstQuartile
        << " / " << flip.thirdQuartile << ", max " << flip.max << "\n";
    if (maskedPixels) {
        out << "  masked pixels   " << maskedPixels << ", max error ";
        describeLocation(out, maskedMaxError);
        out << " (not in the verdict)\n";
    }
    out << "  verdict         " << toString(verdict) << "\n";
    return out.str();
}

CompareResult compareImages(const Image& reference, const Image& candidate, const CompareThresholds& thresholds,
                            const Image* mask, const CompareOptions& options) {
    checkThreshold("--fail", thresholds.fail);
    checkThreshold("--failpercent", thresholds.failPercent);
    checkThreshold("--hardfail", thresholds.hardFail);
    checkThreshold("--warn", thresholds.warn);
    checkThreshold("--warnpercent", thresholds.warnPercent);
    checkThreshold("--hardwarn", thresholds.hardWarn);
    REFRAY_CHECK(std::isfinite(options.pixelsPerDegree) && options.pixelsPerDegree > 0.0,
                 "compare: pixels per degree must be positive, got " << options.pixelsPerDegree);

    CompareResult result;
    result.thresholds = thresholds;
    result.width = reference.width();
    result.height = reference.height();

    // Sizes: a mismatch is an outcome, not an error.
    if (reference.width() != candidate.width() || reference.height() != candidate.height()) {
        result.verdict = CompareVerdict::Mismatch;
        result.mismatch = "size mismatch: reference is " + sizeText(reference.width(), reference.height()) +
                          ", candidate is " + sizeText(candidate.width(), candidate.height());
        return result;
    }
    if (mask && (mask->width() != reference.width() || mask->height() != reference.height())) {
        result.verdict = CompareVerdict::Mismatch;
        result.mismatch = "size mismatch: mask is " + sizeText(mask->width(), mask->height()) + ", images are " +
                          sizeText(reference.width(), reference.height());
        return result;
    }
    if (reference.empty()) return result;

    // Per-pixel errors, accumulated in scan order so the sums are reproducible.
    const int channels = thresholds.includeAlpha ? 4 : 3;
    const size_t count = reference.pixels().size();
    std::vector<uint8_t> compared(count, 1);
    std::vector<float> pixelError(count, 0.0f);
    double sumAbs = 0.0, sumSquared = 0.0;
    uint64_t finiteValues = 0;
    for (uint32_t y = 0; y < result.height; ++y) {
        for (uint32_t x = 0; x < result.width; ++x) {
            const size_t i = size_t(y) * result.width + x;
            const vec4& a = reference.pixels()[i];
            const vec4& b = candidate.pixels()[i];
            PixelError worst{0.0, x, y, 0};
            bool nonFinite = false;
            double pixelAbs = 0.0, pixelSquared = 0.0;
            for (int c = 0; c < channels; ++c) {
                double e;
                if (!std::isfinite(a[c]) || !std::isfinite(b[c])) {
                    nonFinite = true;
                    e = std::numeric_limits<double>::infinity();
                } else {
                    e = std::abs(double(a[c]) - double(b[c]));
                    pixelAbs += e;
                    pixelSquared += e * e;
                }
                if (e > worst.value) {
                    worst.value = e;
                    worst.channel = c;
                }
            }
            pixelError[i] = float(worst.value);

            // A NaN or infinity is a bug, not an order dependence: it is never masked.
            if (mask && !nonFinite && maskCovers(mask->pixels()[i])) {
                compared[i] = 0;
                ++result.maskedPixels;
                if (worst.value > result.maskedMaxError.value) result.maskedMaxError = worst;
                continue;
            }
            ++result.comparedPixels;
            if (worst.value > result.maxError.value) result.maxError = worst;
            sumAbs += pixelAbs;
            sumSquared += pixelSquared;
            for (int c = 0; c < channels; ++c) finiteValues += std::isfinite(a[c]) && std::isfinite(b[c]);
            if (nonFinite) ++result.nonFinitePixels;
            if (worst.value > thresholds.fail) ++result.failingPixels;
            if (worst.value > thresholds.warn) ++result.warningPixels;
        }
    }
    if (finiteValues) {
        result.meanAbsError = sumAbs / double(finiteValues);
        result.rmse = std::sqrt(sumSquared / double(finiteValues));
    }
    result.psnr = result.rmse > 0.0 ? 20.0 * std::log10(1.0 / result.rmse) : std::numeric_limits<double>::infinity();

    // idiff's ladder.
    const double pixels = double(result.comparedPixels);
    const bool fails = result.nonFinitePixels > 0 ||
                       double(result.failingPixels) > thresholds.failPercent / 100.0 * pixels ||
                       result.maxError.value > thresholds.hardFail;
    const bool warns = double(result.warningPixels) > thresholds.warnPercent / 100.0 * pixels ||
                       result.maxError.value > thresholds.hardWarn;
    result.verdict = fails ? CompareVerdict::Fail : warns ? CompareVerdict::Warn : CompareVerdict::Pass;

    // FLIP over the compared pixels (the filters see the whole image).
    const FlipMap flip = computeFlip(reference, candidate, options.pixelsPerDegree);
    result.flip = flipStatistics(flip, compared);
    if (options.diffMode == DiffMode::Flip) {
        result.diffImage = flipHeatMap(flip);
    } else {
        result.diffImage = Image(result.width, result.height);
        for (size_t i = 0; i < count; ++i)
            result.diffImage.pixels()[i] = vec4(magma(pixelError[i] * options.absoluteErrorScale), 1.0f);
    }
    return result;
}

std::vector<std::string> referenceVariants(const std::string& path, const std::string& candidate) {
    namespace fs = std::filesystem;
    const fs::path reference(path);
    std::vector<std::string> found;
    std::error_code ec;
    if (fs::is_regular_file(reference, ec)) found.push_back(path);

    const std::string prefix = reference.stem().string() + "-";
    const std::string extension = reference.extension().string();
    const fs::path directory = reference.parent_path();
    std::vector<std::string> variants;
    for (fs::directory_iterator it(directory.empty() ? fs::path(".") : directory, ec), end; !ec && it != end;
         it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() < prefix.size() + extension.size() || !name.starts_with(prefix) ||
            !name.ends_with(extension) || !it->is_regular_file(ec))
            continue;
        if (!candidate.empty() && fs::equivalent(it->path(), candidate, ec)) continue;
        variants.push_back((directory / name).string());
    }
    std::sort(variants.begin(), variants.end());
    found.insert(found.end(), variants.begin(), variants.end());
    REFRAY_CHECK(!found.empty(), "cannot read image '" << path << "': no such file (nor variants " << prefix << "*"
                                                       << extension << " beside it)");
    return found;
}

size_t bestMatch(const std::vector<CompareResult>& results) {
    const auto key = [](const CompareResult& r) { return std::tuple(r.verdict, r.failingPixels, r.meanAbsError); };
    size_t best = 0;
    for (size_t i = 1; i < results.size(); ++i)
        if (key(results[i]) < key(results[best])) best = i;
    return best;
}

ReferenceComparison compareToReference(const std::string& referencePath, const Image& candidate,
                                       const CompareThresholds& thresholds, const Image* mask,
                                       const CompareOptions& options) {
    ReferenceComparison comparison;
    comparison.references = referenceVariants(referencePath);
    for (const std::string& path : comparison.references)
        comparison.results.push_back(compareImages(readImage(path), candidate, thresholds, mask, options));
    comparison.best = bestMatch(comparison.results);
    return comparison;
}

}  // namespace refray
