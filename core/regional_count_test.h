// The regional, directional count test of envelope goldens (issue 27; docs/compare.md, "The regional count test"):
// where and which way a candidate's flagged pixels lie, against where and which way the K perturbed renders' own
// leave-one-out flags lie. A bug that moves fewer pixels than a legal GPU does overall, but all of them one way on
// one object, fails here although the whole-image counts of core/envelope.h let it pass.
//
//     std::vector<int8_t> flags = ...;  // per pixel: a FlagFamily, or kNoFlag
//     RegionalJudgement r = judgeRegions(envelope, flags, {});
//     if (r.failed()) std::cerr << r.failing.front().describe(envelope.perturbedRenders);
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace refray {

struct Envelope;

// A flag's class and direction: a stable pixel moved more than one step up or down from the nominal's code, a
// sensitive pixel more than one step above or below its [lo, hi]. The direction is that of the channel furthest out.
enum class FlagFamily : uint8_t { StableUp = 0, StableDown = 1, SensitiveAbove = 2, SensitiveBelow = 3 };
inline constexpr int kFlagFamilies = 4;
inline constexpr int8_t kNoFlag = -1;
// "stable-up", ... (file and table names); "stable pixels moved up", ... (reports).
std::string_view familyName(FlagFamily family);
std::string_view familyWords(FlagFamily family);
// The family of a flag by class and direction.
inline FlagFamily flagFamily(bool sensitive, bool up) {
    return FlagFamily((sensitive ? 2 : 0) + (up ? 0 : 1));
}

// The nominal's objects: per pixel (row-major) the object its primary ray hit, as an id (instance x geometry,
// objectId below), -1 for a miss (the background is one object more), with each id's name.
struct ObjectMap {
    std::vector<int32_t> ids;
    std::map<int32_t, std::string> names;
};
// The id of geometry `geometryIndex` of instance `instanceIndex` (exact in a float channel: below 2^24).
inline constexpr int32_t kMaxObjectGeometries = 4096;
inline int32_t objectId(uint32_t instanceIndex, uint32_t geometryIndex) {
    return int32_t(instanceIndex) * kMaxObjectGeometries + int32_t(geometryIndex);
}

// The leave-one-out flags of an envelope: per family, per pixel, bit i set when perturbed render i + 1, judged
// against the envelope of the nominal and every other render, flags the pixel in that family. K <= 24, so that a
// mask is exact in a float channel.
inline constexpr uint32_t kMaxRegionalRenders = 24;
using LeaveOneOutFlags = std::array<std::vector<uint32_t>, kFlagFamilies>;

struct RegionalOptions {
    double falseAlarm = 1e-3;  // for the image, after Bonferroni over every region and family
};

// One region and family: the candidate's flagged pixels there against each leave-one-out render's.
struct RegionalFinding {
    FlagFamily family = FlagFamily::StableUp;
    int32_t object = -1;
    std::string objectName;
    uint32_t tileSize = 0;              // 0: the whole object
    uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the region's bounding box, inclusive
    uint64_t pixels = 0;                // the region's pixels of the family's class
    uint64_t candidate = 0;             // the candidate's flagged pixels in the region
    std::vector<uint64_t> legal;        // each perturbed render's, by leave-one-out
    double clusterSize = 1;             // m: legal flags come in clusters of about m pixels (this object, family)
    double heterogeneity = 1;           // h: how much more one legal render may flag this object than the average
    double share = 0;                   // the candidate's share of the clusters under the null hypothesis
    double p = 1, adjustedP = 1;        // adjusted: times the number of tests (Bonferroni), at most 1
    // "stable pixels moved down, object 'cog', tile at (x, y)-(x2, y2): 71 pixels; the K legal renders: 2 2 1 ..."
    std::string describe() const;
};

struct RegionalJudgement {
    bool available = false;
    std::string unavailable;     // why the test did not run (an envelope of refray-envelope/1, K < 2, ...)
    double falseAlarm = 1e-3;
    uint64_t objects = 0, regions = 0, tests = 0;
    double smallestAdjustedP = 1;
    RegionalFinding closest;               // the region and family of the smallest p (candidate > 0), if any
    std::vector<RegionalFinding> failing;  // adjusted p below the false alarm, smallest first
    bool failed() const { return !failing.empty(); }
};

// The calibration of one object and family from the leave-one-out flags alone.
struct RegionalCalibration {
    double clusterSize = 1;         // max(1, size-biased mean component size, dispersion of tile counts)
    double componentCluster = 0;    // sum of s^2 / sum of s over the 8-connected components of the K renders' flags
    double tileDispersion = 0;      // pooled variance/mean of the K counts in the object's tiles
    double heterogeneity = 1;       // 1 + 2 sd of the renders' relative rates beyond the cluster Poisson variance
    uint64_t flags = 0;             // the K renders' flags in the object, family
};
// Per object id and family.
std::map<int32_t, std::array<RegionalCalibration, kFlagFamilies>> calibrateRegions(const Envelope& envelope);

// The tile sizes for an image `width` pixels wide: W/40, W/20 and W/10 (at least 2, without repeats).
std::vector<uint32_t> regionalTileSizes(uint32_t width);

// Judges the candidate's per-pixel flags (a FlagFamily as int8_t, or kNoFlag) against the envelope's leave-one-out
// flags. Unavailable (no failure) for an envelope without them.
RegionalJudgement judgeRegions(const Envelope& envelope, const std::vector<int8_t>& candidateFlags,
                               const RegionalOptions& options);

}  // namespace refray
