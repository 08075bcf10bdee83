// Envelope goldens (issue 17, docs/golden-format.md): what a correct GPU may legally render at each pixel, from a
// nominal render and a list of legal variants (perturbed renders, double precision, adversarial traversal orders),
// all quantised as an R8G8B8A8_UNORM target holds them; and the judgement of a candidate image against it
// (docs/compare.md, "Envelope goldens").
//
//     Envelope e = makeEnvelope(nominal, {&v1, &v2, ...}, perturbedCount, &orderMask);
//     writeEnvelope("golden.exr", e);
//     EnvelopeJudgement j = judgeEnvelope(readEnvelope("golden.exr"), candidate, {});
//     if (j.verdict != CompareVerdict::Pass) std::cerr << j.describe();
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/compare.h"
#include "core/image.h"
#include "core/regional_count_test.h"

namespace refray {

// Version 2 adds the regional count test's data (the object map and the leave-one-out flags); an envelope of
// version 1 still loads and is judged by the whole-image counts alone, which its judgement says.
inline constexpr std::string_view kEnvelopeFormat = "refray-envelope/2";
inline constexpr std::string_view kEnvelopeFormatV1 = "refray-envelope/1";

// One UNORM8 step: 1/255.
inline constexpr int kEnvelopeChannels = 3;  // R, G, B are judged; alpha means nothing in the D3D12 samples

enum class PixelClass : uint8_t { Stable = 0, Sensitive = 1 };

struct Envelope {
    Image nominal;                    // the nominal render, float, as rendered (R, G, B, A)
    std::vector<std::array<uint8_t, 3>> lo, hi;  // per pixel and channel: UNORM8 codes, min / max over every render
    std::vector<PixelClass> pixelClass;          // Stable: every render within one step of the nominal's code
    std::vector<uint8_t> orderDependent;         // 1: the pixel changes under an adversarial traversal order
    uint32_t perturbedRenders = 0;    // K: the exchangeable samples the statistic counts on (seeds 1..K)
    uint32_t variants = 0;            // every render the bounds were taken over, the nominal included
    // The leave-one-out calibration of the stable-pixel count test (docs/compare.md, "The stable count test"):
    // c_i, for perturbed render i (seeds 1..K), the pixels (order-dependent ones excepted) that are stable when the
    // class is taken over the nominal and every other render but i, and that render i moves by more than one step.
    // Empty for an envelope made before the calibration: its stable pixels get no allowance.
    std::vector<uint64_t> stableMovesLeaveOneOut;
    // s_i, for perturbed render i: the sensitive pixels (order-dependent ones excepted) where render i falls outside
    // the envelope of the nominal and every other render by more than one step, as a candidate is judged.
    std::vector<uint64_t> sensitiveOutsideLeaveOneOut;
    // The regional count test (core/regional_count_test.h): the nominal's objects, and per family and pixel which
    // perturbed renders flag it by leave-one-out. Both empty for an envelope of refray-envelope/1.
    ObjectMap objects;
    LeaveOneOutFlags leaveOneOutFlags;
    std::string format = std::string(kEnvelopeFormat);  // as read (written: always kEnvelopeFormat)
    std::map<std::string, std::string> provenance;  // settings, seeds, commit, variation model, scene SHA-256

    uint32_t width() const { return nominal.width(); }
    uint32_t height() const { return nominal.height(); }
    uint64_t sensitivePixels() const;
};

// The envelope of `nominal` and `variants` (all the same size; throws refray::Error naming the sizes otherwise):
// bounds over the nominal and every variant, quantised with floatToUnorm8. `perturbedRenders` says how many of the
// variants are the exchangeable perturbed renders (K). `orderMask` (any non-zero R, G or B) may be null. `objects`
// (the nominal's primary-ray objects) may be null: the image is then one object. The leave-one-out flags of the
// regional test are made where K <= kMaxRegionalRenders.
Envelope makeEnvelope(const Image& nominal, const std::vector<const Image*>& variants, uint32_t perturbedRenders,
                      const Image* orderMask, const ObjectMap* objects = nullptr);

// One OpenEXR file, 32-bit float channels R G B A (nominal), lo.R lo.G lo.B hi.R hi.G hi.B (code/255), class
// (0 stable, 1 sensitive), order (0/1), object (the object id) and loo.stableUp, loo.stableDown,
// loo.sensitiveAbove, loo.sensitiveBelow (bit masks of the perturbed renders), provenance as refray:* string
// attributes (docs/golden-format.md).
// Throws refray::Error naming the path.
void writeEnvelope(const std::string& path, const Envelope& envelope);
// Throws refray::Error naming the path for a missing file, a file that is no envelope (no lo.R channel: "a plain
// image"), another envelope format (refray-envelope/1 loads, without the regional data), or corrupted values (lo >
// hi, the nominal outside its bounds, class not 0/1, a flag mask with bits past K).
Envelope readEnvelope(const std::string& path);
// Whether the file is an envelope (has the lo.R channel); false for a plain image. Throws when unreadable.
bool isEnvelopeFile(const std::string& path);

struct EnvelopeJudgeOptions {
    // The false-alarm probability of the sensitive-pixel count test for one image.
    double falseAlarm = 1e-3;
    // Pixels taken as moving together (a shifted silhouette, a marched step more): the count test treats the
    // sensitive pixels as clusters of this many perfectly correlated pixels (docs/compare.md).
    uint32_t clusterSize = 9;
};

struct EnvelopePixel {
    uint32_t x = 0, y = 0;
    PixelClass pixelClass = PixelClass::Stable;
    bool orderDependent = false;
    bool nonFinite = false;
    int channel = 0;          // the channel furthest outside
    int candidate = 0;        // its UNORM8 code in the candidate
    int allowedLo = 0, allowedHi = 0;  // the codes it was allowed (stable: nominal +-1; sensitive: lo-1 .. hi+1)
    int steps = 0;            // how far outside, in UNORM8 steps (INT32_MAX for NaN/inf)
};

struct EnvelopeJudgement {
    CompareVerdict verdict = CompareVerdict::Pass;
    std::string mismatch;  // why the verdict is Mismatch
    uint32_t width = 0, height = 0;
    uint64_t pixels = 0, stablePixels = 0, sensitivePixels = 0, orderPixels = 0;  // judged pixels by class
    uint64_t stableOutside = 0, sensitiveOutside = 0, orderOutside = 0, nonFinite = 0;
    uint32_t perturbedRenders = 0;
    double outsideProbability = 0;  // per sensitive pixel, for a correct candidate: at most 2/(K+1)
    double expectedOutside = 0;     // the larger of sensitivePixels * outsideProbability and mean(s_i)
    // The most sensitive pixels outside that a correct candidate gives (1 - falseAlarm): the larger of the binomial
    // quantile (clusters of clusterSize) and leaveOneOutBudget(s_i).
    uint64_t sensitiveBudget = 0;
    double expectedStableOutside = 0;  // mean(c_i): the stable pixels a correct candidate moves, by leave-one-out
    uint64_t stableBudget = 0;      // the most stable pixels a correct candidate moves (stableBudget below)
    int maxSteps = 0;
    RegionalJudgement regional;  // the regional count test; the verdict fails where it fails
    std::vector<EnvelopePixel> outside;  // every pixel outside its allowance, in scan order (order pixels included)
    Image heatMap;  // see docs/compare.md, "Envelope goldens"; failing regions outlined in cyan
    std::string describe(size_t listed = 10) const;
};

// The cluster size of a leave-one-out count test: options.clusterSize, or the dispersion index of the counts
// (sample variance / mean: a compound Poisson count of m-pixel clusters has m) where that is larger.
uint64_t leaveOneOutClusterSize(const std::vector<uint64_t>& counts, const EnvelopeJudgeOptions& options);
// The budget of a leave-one-out count test (docs/compare.md, "The count tests"): with m = leaveOneOutClusterSize and
// T = sum over i of ceil(c_i / m) clusters moved by the K leave-one-out renders, the largest y such that
// P(Binomial(y + T, 1/(K+1)) >= y) > falseAlarm (the conditional test of a candidate's Poisson rate against the K
// renders'), in pixels (y * m), and at least max(c_i). 0 for no counts.
uint64_t leaveOneOutBudget(const std::vector<uint64_t>& counts, const EnvelopeJudgeOptions& options);
// The stable-pixel budget: leaveOneOutBudget of envelope.stableMovesLeaveOneOut.
uint64_t stableBudget(const Envelope& envelope, const EnvelopeJudgeOptions& options);

// Judges `candidate` (quantised with floatToUnorm8) against `envelope`. Never throws for a size mismatch (the
// verdict is Mismatch and `mismatch` says why).
EnvelopeJudgement judgeEnvelope(const Envelope& envelope, const Image& candidate, const EnvelopeJudgeOptions& options);

}  // namespace refray
