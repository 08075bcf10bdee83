#include "core/regional_count_test.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <unordered_map>

#include <boost/math/distributions/binomial.hpp>

#include "core/envelope.h"

namespace refray {

namespace {

// Below this many leave-one-out flags in one object and family, the object's own cluster size and heterogeneity
// rest on too little; the image's (every object pooled) and the largest object's heterogeneity are used where larger.
constexpr uint64_t kSparseFlagsPerRender = 3;

struct Cell {
    uint32_t object = 0;    // dense object index
    uint32_t tileSize = 0;  // 0: the whole object
    uint32_t x0 = UINT32_MAX, y0 = UINT32_MAX, x1 = 0, y1 = 0;
    std::array<uint64_t, 2> classPixels{};  // stable, sensitive
};

bool isSensitiveFamily(int f) { return f >= 2; }

// P(Binomial(n, q) >= y).
double upperTail(uint64_t y, uint64_t n, double q) {
    if (y == 0) return 1.0;
    if (y > n) return 0.0;
    if (q >= 1.0) return 1.0;
    const boost::math::binomial_distribution<double> binomial(double(n), q);
    return boost::math::cdf(boost::math::complement(binomial, double(y - 1)));
}

// Findings in the order a report names them: the smallest p first; of equal p, the smallest region (a tile before
// its whole object), which says best where the damage is.
bool moreSpecific(const RegionalFinding& a, const RegionalFinding& b) {
    if (a.p != b.p) return a.p < b.p;
    const uint32_t sa = a.tileSize ? a.tileSize : UINT32_MAX, sb = b.tileSize ? b.tileSize : UINT32_MAX;
    return sa < sb;
}

uint64_t clusters(uint64_t pixels, double m) { return uint64_t(std::ceil(double(pixels) / m - 1e-9)); }

}  // namespace

std::string_view familyName(FlagFamily family) {
    static constexpr std::string_view names[] = {"stable-up", "stable-down", "sensitive-above", "sensitive-below"};
    return names[int(family)];
}

std::string_view familyWords(FlagFamily family) {
    static constexpr std::string_view words[] = {"stable pixels moved up", "stable pixels moved down",
                                                 "sensitive pixels above their envelope",
                                                 "sensitive pixels below their envelope"};
    return words[int(family)];
}

std::vector<uint32_t> regionalTileSizes(uint32_t width) {
    std::vector<uint32_t> sizes;
    for (uint32_t parts : {40u, 20u, 10u}) {
        const uint32_t s = std::max(2u, width / parts);
        if (std::find(sizes.begin(), sizes.end(), s) == sizes.end()) sizes.push_back(s);
    }
    return sizes;
}

std::string RegionalFinding::describe() const {
    std::ostringstream out;
    out << familyWords(family) << ", " << objectName << ", ";
    if (tileSize == 0) out << "the whole object, at (" << x0 << ", " << y0 << ")-(" << x1 << ", " << y1 << ")";
    else out << "tile at (" << x0 << ", " << y0 << ")-(" << x1 << ", " << y1 << ")";
    out << ": " << candidate << " pixels; the " << legal.size() << " legal renders:";
    for (uint64_t c : legal) out << ' ' << c;
    char numbers[160];
    std::snprintf(numbers, sizeof numbers, " (p %.3g, adjusted %.3g; clusters of %.1f pixels, heterogeneity %.2f)", p,
                  adjustedP, clusterSize, heterogeneity);
    out << numbers;
    return out.str();
}

namespace {

// The pixels' objects as dense indices 0..objects-1 (ids sorted), with each index's id.
struct DenseObjects {
    std::vector<uint32_t> index;  // per pixel
    std::vector<int32_t> ids;
};

DenseObjects denseObjects(const Envelope& e) {
    DenseObjects d;
    const size_t n = size_t(e.width()) * e.height();
    d.index.assign(n, 0);
    if (e.objects.ids.size() != n) {
        d.ids = {0};
        return d;
    }
    d.ids = e.objects.ids;
    std::sort(d.ids.begin(), d.ids.end());
    d.ids.erase(std::unique(d.ids.begin(), d.ids.end()), d.ids.end());
    for (size_t i = 0; i < n; ++i)
        d.index[i] = uint32_t(std::lower_bound(d.ids.begin(), d.ids.end(), e.objects.ids[i]) - d.ids.begin());
    return d;
}

std::string objectName(const Envelope& e, int32_t id) {
    const auto found = e.objects.names.find(id);
    if (found != e.objects.names.end()) return found->second;
    if (e.objects.ids.empty()) return "the image";
    return id < 0 ? "the background" : "object " + std::to_string(id);
}

// Order-dependent pixels are judged apart; a flag elsewhere counts. (A render's leave-one-out stable flags lie on
// pixels sensitive in the full envelope, since that render moved them: the class is the one the render was judged by.)
bool judged(const Envelope& e, size_t i) { return !e.orderDependent[i]; }

// Every region: for each tiling (size, offset) the non-empty (tile, object) cells, then each whole object; and per
// pixel, the region of each tiling it lies in.
struct Regions {
    std::vector<Cell> cells;
    std::vector<std::vector<uint32_t>> cellOf;  // per tiling (the whole-object one last), per pixel
};

Regions makeRegions(const Envelope& e, const DenseObjects& objects) {
    Regions r;
    const uint32_t w = e.width(), h = e.height();
    const size_t n = size_t(w) * h;
    std::vector<std::pair<uint32_t, uint32_t>> tilings;  // size, offset
    for (uint32_t s : regionalTileSizes(w)) {
        tilings.push_back({s, 0});
        tilings.push_back({s, s / 2});
    }
    tilings.push_back({0, 0});
    const uint64_t count = objects.ids.size();
    for (const auto& [size, offset] : tilings) {
        std::unordered_map<uint64_t, uint32_t> index;
        std::vector<uint32_t> cellOf(n);
        const uint64_t tilesX = size ? (w + offset) / size + 1 : 1;
        for (size_t i = 0; i < n; ++i) {
            const uint32_t x = uint32_t(i % w), y = uint32_t(i / w);
            const uint64_t tile = size ? uint64_t((y + offset) / size) * tilesX + (x + offset) / size : 0;
            const uint64_t key = tile * count + objects.index[i];
            auto [it, added] = index.try_emplace(key, uint32_t(r.cells.size()));
            if (added) {
                Cell c;
                c.object = objects.index[i];
                c.tileSize = size;
                r.cells.push_back(c);
            }
            Cell& c = r.cells[it->second];
            c.x0 = std::min(c.x0, x);
            c.y0 = std::min(c.y0, y);
            c.x1 = std::max(c.x1, x);
            c.y1 = std::max(c.y1, y);
            if (!e.orderDependent[i]) ++c.classPixels[e.pixelClass[i] == PixelClass::Sensitive ? 1 : 0];
            cellOf[i] = it->second;
        }
        r.cellOf.push_back(std::move(cellOf));
    }
    return r;
}

// counts[(cell * families + f) * (K + 1) + i]: render i's leave-one-out flags (i < K) or the candidate's (i = K).
std::vector<uint64_t> regionCounts(const Envelope& e, const Regions& regions, const std::vector<int8_t>* candidate) {
    const uint32_t k = e.perturbedRenders;
    std::vector<uint64_t> counts(regions.cells.size() * kFlagFamilies * (k + 1), 0);
    const size_t n = size_t(e.width()) * e.height();
    for (size_t i = 0; i < n; ++i)
        for (int f = 0; f < kFlagFamilies; ++f) {
            const uint32_t bits = e.leaveOneOutFlags[f][i];
            const bool flagged = candidate && (*candidate)[i] == f;
            if (!bits && !flagged) continue;
            if (!judged(e, i)) continue;
            for (const auto& cellOf : regions.cellOf) {
                uint64_t* c = &counts[(size_t(cellOf[i]) * kFlagFamilies + f) * (k + 1)];
                for (uint32_t r = 0; r < k; ++r)
                    if (bits & (1u << r)) ++c[r];
                if (flagged) ++c[k];
            }
        }
    return counts;
}

// Sum of s^2 and of s over the 8-connected components of render r's flags in family f, each component kept inside
// one object, added per object.
void addComponents(const Envelope& e, const DenseObjects& objects, int f, uint32_t r, std::vector<double>& sumSquares,
                   std::vector<double>& sums) {
    const uint32_t w = e.width(), h = e.height();
    const size_t n = size_t(w) * h;
    const auto flagged = [&](size_t i) { return (e.leaveOneOutFlags[f][i] >> r & 1u) && judged(e, i); };
    std::vector<char> seen(n, 0);
    std::vector<size_t> stack;
    for (size_t start = 0; start < n; ++start) {
        if (seen[start] || !flagged(start)) continue;
        const uint32_t object = objects.index[start];
        uint64_t size = 0;
        seen[start] = 1;
        stack.push_back(start);
        while (!stack.empty()) {
            const size_t i = stack.back();
            stack.pop_back();
            ++size;
            const int x = int(i % w), y = int(i / w);
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= int(w) || ny >= int(h)) continue;
                    const size_t j = size_t(ny) * w + size_t(nx);
                    if (seen[j] || objects.index[j] != object || !flagged(j)) continue;
                    seen[j] = 1;
                    stack.push_back(j);
                }
        }
        sumSquares[object] += double(size) * double(size);
        sums[object] += double(size);
    }
}

struct Calibrated {
    std::vector<std::array<RegionalCalibration, kFlagFamilies>> byObject;  // dense object index
    std::array<std::vector<uint64_t>, kFlagFamilies> totals;                 // per render, the whole image
};

Calibrated calibrate(const Envelope& e, const DenseObjects& objects, const Regions& regions,
                     const std::vector<uint64_t>& counts) {
    const uint32_t k = e.perturbedRenders;
    const size_t count = objects.ids.size();
    Calibrated out;
    out.byObject.resize(count);
    for (int f = 0; f < kFlagFamilies; ++f) {
        out.totals[f].assign(k, 0);
        // Connected components, per object and pooled over the image.
        std::vector<double> sumSquares(count, 0.0), sums(count, 0.0);
        for (uint32_t r = 0; r < k; ++r) addComponents(e, objects, f, r, sumSquares, sums);
        // The dispersion of the K counts within each tile (across renders, so that where the flags fall in the object
        // does not count), pooled over the object's tiles of one size; the largest over the sizes.
        std::map<uint32_t, std::vector<std::pair<double, double>>> dispersion;  // size -> per object (num, den)
        std::vector<std::vector<uint64_t>> whole(count, std::vector<uint64_t>(k, 0));
        for (size_t c = 0; c < regions.cells.size(); ++c) {
            const Cell& cell = regions.cells[c];
            const uint64_t* counted = &counts[(c * kFlagFamilies + f) * (k + 1)];
            if (cell.tileSize == 0) {
                for (uint32_t r = 0; r < k; ++r) {
                    whole[cell.object][r] = counted[r];
                    out.totals[f][r] += counted[r];
                }
                continue;
            }
            double mean = 0;
            for (uint32_t r = 0; r < k; ++r) mean += double(counted[r]);
            mean /= double(k);
            if (mean == 0) continue;
            double squares = 0;
            for (uint32_t r = 0; r < k; ++r) squares += (double(counted[r]) - mean) * (double(counted[r]) - mean);
            auto& pooled = dispersion[cell.tileSize];
            pooled.resize(count, {0.0, 0.0});
            pooled[cell.object].first += squares;
            pooled[cell.object].second += double(k - 1) * mean;
        }
        // The image's own terms, for objects with too few flags.
        double imageSquares = 0, imageSums = 0, imageDispersion = 0;
        for (size_t o = 0; o < count; ++o) {
            imageSquares += sumSquares[o];
            imageSums += sums[o];
        }
        for (const auto& [size, pooled] : dispersion) {
            double num = 0, den = 0;
            for (const auto& [a, b] : pooled) {
                num += a;
                den += b;
            }
            if (den > 0) imageDispersion = std::max(imageDispersion, num / den);
        }
        const double imageCluster = std::max({1.0, imageSums > 0 ? imageSquares / imageSums : 0.0, imageDispersion});
        double totalMean = 0;
        for (uint64_t t : out.totals[f]) totalMean += double(t);
        totalMean /= double(k);
        double largestHeterogeneity = 1;
        for (size_t o = 0; o < count; ++o) {
            RegionalCalibration& c = out.byObject[o][f];
            c.componentCluster = sums[o] > 0 ? sumSquares[o] / sums[o] : 0.0;
            for (const auto& [size, pooled] : dispersion)
                if (pooled[o].second > 0) c.tileDispersion = std::max(c.tileDispersion, pooled[o].first / pooled[o].second);
            c.clusterSize = std::max({1.0, c.componentCluster, c.tileDispersion});
            for (uint64_t v : whole[o]) c.flags += v;
            // Heterogeneity: each render's count in the object relative to its own total (the test scales by the
            // totals), and the part of their spread that m-pixel clusters of one rate do not explain.
            std::vector<double> relative;
            for (uint32_t r = 0; r < k; ++r)
                relative.push_back(out.totals[f][r] > 0 ? double(whole[o][r]) * totalMean / double(out.totals[f][r])
                                                        : double(whole[o][r]));
            double mean = 0, variance = 0;
            for (double v : relative) mean += v;
            mean /= double(k);
            for (double v : relative) variance += (v - mean) * (v - mean);
            variance /= double(k - 1);
            if (mean > 0) {
                const double excess = std::max(0.0, variance - c.clusterSize * mean) / (mean * mean);
                c.heterogeneity = 1.0 + 2.0 * std::sqrt(excess);
            }
            if (c.flags >= kSparseFlagsPerRender * k) largestHeterogeneity = std::max(largestHeterogeneity, c.heterogeneity);
        }
        for (size_t o = 0; o < count; ++o) {
            RegionalCalibration& c = out.byObject[o][f];
            if (c.flags >= kSparseFlagsPerRender * k) continue;
            c.clusterSize = std::max(c.clusterSize, imageCluster);
            c.heterogeneity = std::max(c.heterogeneity, largestHeterogeneity);
        }
    }
    return out;
}

std::string whyUnavailable(const Envelope& e) {
    if (e.leaveOneOutFlags[0].empty() && e.perturbedRenders > kMaxRegionalRenders)
        return "the envelope's K = " + std::to_string(e.perturbedRenders) + " perturbed renders are more than the " +
               std::to_string(kMaxRegionalRenders) + " the regional test keeps flags for: judged by the whole-image "
               "counts only";
    if (e.leaveOneOutFlags[0].empty())
        return "this envelope (" + e.format + ") carries no leave-one-out flags: judged by the whole-image counts only; "
               "remake it with 'refray golden update' or 'refray golden make' for the regional test";
    if (e.perturbedRenders < 2) return "the regional test needs K >= 2 perturbed renders";
    return "";
}

}  // namespace

std::map<int32_t, std::array<RegionalCalibration, kFlagFamilies>> calibrateRegions(const Envelope& e) {
    std::map<int32_t, std::array<RegionalCalibration, kFlagFamilies>> out;
    if (!whyUnavailable(e).empty()) return out;
    const DenseObjects objects = denseObjects(e);
    const Regions regions = makeRegions(e, objects);
    const Calibrated c = calibrate(e, objects, regions, regionCounts(e, regions, nullptr));
    for (size_t o = 0; o < objects.ids.size(); ++o) out[objects.ids[o]] = c.byObject[o];
    return out;
}

RegionalJudgement judgeRegions(const Envelope& e, const std::vector<int8_t>& candidateFlags,
                               const RegionalOptions& options) {
    RegionalJudgement j;
    j.falseAlarm = options.falseAlarm;
    j.unavailable = whyUnavailable(e);
    if (!j.unavailable.empty()) return j;
    j.available = true;
    const uint32_t k = e.perturbedRenders;
    const DenseObjects objects = denseObjects(e);
    const Regions regions = makeRegions(e, objects);
    const std::vector<uint64_t> counts = regionCounts(e, regions, &candidateFlags);
    const Calibrated calibrated = calibrate(e, objects, regions, counts);
    j.objects = objects.ids.size();
    j.regions = regions.cells.size();
    for (const Cell& c : regions.cells)
        for (int f = 0; f < kFlagFamilies; ++f)
            if (isSensitiveFamily(f) ? c.classPixels[1] > 0 : c.classPixels[0] + c.classPixels[1] > 0) ++j.tests;

    // The exposures: a render's whole-image count of the family. The candidate's is floored at the average legal
    // render's, so that a candidate flagging fewer pixels than the renders overall is not judged as if each of its
    // flags were rarer than theirs.
    std::array<uint64_t, kFlagFamilies> candidateTotal{};
    for (size_t i = 0; i < candidateFlags.size(); ++i)
        if (candidateFlags[i] >= 0 && judged(e, i)) ++candidateTotal[size_t(candidateFlags[i])];
    std::vector<RegionalFinding> findings;
    for (size_t c = 0; c < regions.cells.size(); ++c) {
        const Cell& cell = regions.cells[c];
        for (int f = 0; f < kFlagFamilies; ++f) {
            const uint64_t* counted = &counts[(c * kFlagFamilies + f) * (k + 1)];
            if (counted[k] == 0) continue;
            const RegionalCalibration& cal = calibrated.byObject[cell.object][f];
            double legalTotal = 0;
            for (uint64_t t : calibrated.totals[f]) legalTotal += double(t);
            const double candidateExposure = std::max(double(candidateTotal[f]), legalTotal / double(k));
            const double h = cal.heterogeneity;
            const double share = legalTotal > 0 ? h * candidateExposure / (h * candidateExposure + legalTotal)
                                                : h / (h + double(k));
            const double m = cal.clusterSize;
            const uint64_t y = clusters(counted[k], m);
            uint64_t t = 0;
            for (uint32_t r = 0; r < k; ++r) t += clusters(counted[r], m);
            RegionalFinding finding;
            finding.p = upperTail(y, y + t, share);
            finding.adjustedP = std::min(1.0, finding.p * double(j.tests));
            finding.family = FlagFamily(f);
            finding.object = objects.ids[cell.object];
            finding.objectName = objectName(e, finding.object);
            finding.tileSize = cell.tileSize;
            finding.x0 = cell.x0;
            finding.y0 = cell.y0;
            finding.x1 = cell.x1;
            finding.y1 = cell.y1;
            finding.pixels = cell.classPixels[isSensitiveFamily(f) ? 1 : 0];
            finding.candidate = counted[k];
            finding.legal.assign(counted, counted + k);
            finding.clusterSize = m;
            finding.heterogeneity = h;
            finding.share = share;
            if (j.closest.candidate == 0 || moreSpecific(finding, j.closest)) {
                j.closest = finding;
                j.smallestAdjustedP = finding.adjustedP;
            }
            if (finding.adjustedP < options.falseAlarm) j.failing.push_back(finding);
        }
    }
    std::stable_sort(j.failing.begin(), j.failing.end(), moreSpecific);
    return j;
}

}  // namespace refray
