// The image comparator: one for the golden tests, `refray compare` and batch tools.
// Verdicts follow OpenImageIO's idiff (same thresholds, same ladder, same exit codes);
// the report adds LDR-FLIP (core/flip.h). docs/compare.md explains every number.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/flip.h"
#include "core/image.h"

namespace refray {

// idiff's ladder; the value is `refray compare`'s exit code (4, a file error, is the
// command's own). Ordered: a lower verdict is a better match.
enum class CompareVerdict { Pass = 0, Warn = 1, Fail = 2, Mismatch = 3 };

// "PASS", "WARNING", "FAILURE", "MISMATCH".
std::string_view toString(CompareVerdict verdict);

// idiff's thresholds, with idiff's defaults. A pixel "fails" when any compared channel
// differs by more than `fail` (absolute), and "warns" likewise with `warn`. The image
//   fails  when more than failPercent % of the compared pixels fail, or any channel
//          differs by more than hardFail, or any compared value is NaN or infinite;
//   warns  (when it does not fail) when more than warnPercent % of them warn, or any
//          channel differs by more than hardWarn;
//   passes otherwise.
// Percentages are of the pixels outside the mask.
struct CompareThresholds {
    double fail = 1e-6;
    double failPercent = 0.0;
    double hardFail = std::numeric_limits<double>::infinity();
    double warn = 1e-6;
    double warnPercent = 0.0;
    double hardWarn = std::numeric_limits<double>::infinity();
    bool includeAlpha = false;  // RGB only by default: DXR samples' alpha means nothing

    // The profile for a GPU render against a refray golden PNG (both R8G8B8A8_UNORM):
    // fail 0.005 and warn 0.005, i.e. between one UNORM step (1/255 = 0.0039, which
    // D3D's float->UNORM conversion tolerance already allows) and two (0.0078);
    // failPercent 0.1: up to 0.1 % of pixels may be off by more (GPU transcendentals,
    // ray-marching step counts), which still warns; hardFail and hardWarn stay
    // infinite (a silhouette pixel may flip completely). `refray compare --golden`.
    static CompareThresholds golden();
};

// What the diff image shows.
enum class DiffMode {
    Flip,           // the LDR-FLIP error map through magma() (default)
    AbsoluteError,  // the largest compared channel's |difference| x scale, through magma()
};

struct CompareOptions {
    double pixelsPerDegree = kFlipDefaultPixelsPerDegree;  // FLIP's observer
    DiffMode diffMode = DiffMode::Flip;
    float absoluteErrorScale = 1.0f;  // DiffMode::AbsoluteError only
};

// Where the largest error is. Channel 0..3 is R, G, B, A.
struct PixelError {
    double value = 0.0;  // +infinity when a value there is NaN or infinite
    uint32_t x = 0, y = 0;
    int channel = 0;
};

struct CompareResult {
    CompareVerdict verdict = CompareVerdict::Pass;
    std::string mismatch;  // why the verdict is Mismatch (names both sizes); else empty
    CompareThresholds thresholds;  // the ones the verdict used

    uint32_t width = 0, height = 0;
    uint64_t comparedPixels = 0;  // pixels outside the mask (a NaN is never masked)

    // Over the compared pixels and channels. Mean, RMS and PSNR leave out non-finite
    // values (nonFinitePixels counts them); PSNR is 20 log10(1 / RMSE), +inf when equal.
    PixelError maxError;  // first in scan order (y, then x, then channel) among equals
    double meanAbsError = 0.0, rmse = 0.0, psnr = 0.0;
    uint64_t failingPixels = 0, warningPixels = 0;
    uint64_t nonFinitePixels = 0;  // pixels with a NaN or infinity in a compared channel of either image

    // Masked pixels: counted apart, never in the verdict.
    uint64_t maskedPixels = 0;
    PixelError maskedMaxError;

    FlipStats flip;   // LDR-FLIP over the compared pixels (informative: not in the verdict)
    Image diffImage;  // per CompareOptions::diffMode; empty for a mismatch

    double failingPercent() const;
    double warningPercent() const;

    // A multi-line human report (idiff's numbers, FLIP, mask, verdict), each line
    // indented by two spaces and ended by a newline.
    std::string describe() const;
};

// Compares `candidate` against `reference` (both as readImage returns them). `mask`,
// when given, marks order-dependent pixels: any non-zero RGB value excludes that pixel
// from the verdict and reports it apart. Different sizes (images or mask) give the
// verdict Mismatch with a message, not an exception. Deterministic (single-threaded).
// Throws refray::Error for negative thresholds or a non-positive pixelsPerDegree.
CompareResult compareImages(const Image& reference, const Image& candidate, const CompareThresholds& thresholds,
                            const Image* mask = nullptr, const CompareOptions& options = {});

// The references a candidate may match: `path` itself (when it exists) followed by its
// platform variants, the files beside it named <stem>-<anything><extension>, sorted by
// name. A variant that is the file `candidate` (say golden-mine.png beside golden.png)
// is left out, so a render saved beside its golden never matches itself. Throws
// refray::Error naming `path` when there is none of them.
std::vector<std::string> referenceVariants(const std::string& path, const std::string& candidate = {});

// The index of the best of several results: the lowest verdict, then the fewest
// failing pixels, then the lowest mean error, then the first. Empty -> 0.
size_t bestMatch(const std::vector<CompareResult>& results);

// A candidate against a reference and its variants (see referenceVariants).
struct ReferenceComparison {
    std::vector<std::string> references;  // the variants, in referenceVariants' order
    std::vector<CompareResult> results;   // one per reference
    size_t best = 0;                      // bestMatch(results)

    const CompareResult& bestResult() const { return results[best]; }
    CompareVerdict verdict() const { return results[best].verdict; }
};

// Reads every variant of `referencePath` and compares `candidate` against each. Throws
// refray::Error naming the file when a reference cannot be read.
ReferenceComparison compareToReference(const std::string& referencePath, const Image& candidate,
                                       const CompareThresholds& thresholds, const Image* mask = nullptr,
                                       const CompareOptions& options = {});

}  // namespace refray
