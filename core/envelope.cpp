#include "core/envelope.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <boost/math/distributions/binomial.hpp>

#include "core/error.h"
#include "core/image_file.h"

namespace refray {

namespace {

constexpr const char* kMetadataPrefix = "refray:";
constexpr const char* kFormatKey = "envelope_format";
constexpr const char* kPerturbedKey = "envelope_perturbed_renders";
constexpr const char* kVariantsKey = "envelope_variants";
constexpr const char* kStableMovesKey = "envelope_stable_moves_loo";
constexpr const char* kSensitiveOutsideKey = "envelope_sensitive_outside_loo";

std::string countList(const std::vector<uint64_t>& counts) {
    std::string list;
    for (uint64_t c : counts) {
        if (!list.empty()) list += ' ';
        list += std::to_string(c);
    }
    return list;
}
constexpr const char kChannelLetters[] = "RGB";
const std::vector<std::string> kChannelNames = {"R",    "G",    "B",    "A",     "lo.R", "lo.G",
                                                "lo.B", "hi.R", "hi.G", "hi.B",  "class", "order"};
// refray-envelope/2: the regional count test's planes (where K <= kMaxRegionalRenders).
const std::vector<std::string> kRegionalChannelNames = {"object", "loo.stableUp", "loo.stableDown",
                                                        "loo.sensitiveAbove", "loo.sensitiveBelow"};
constexpr const char* kObjectsKey = "envelope_objects";

// "id=name" per object, one a line.
std::string objectNameList(const std::map<int32_t, std::string>& names) {
    std::string list;
    for (const auto& [id, name] : names) {
        if (!list.empty()) list += '\n';
        list += std::to_string(id) + "=" + name;
    }
    return list;
}

std::string sizeText(uint32_t w, uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

int code(float v) { return floatToUnorm8(v); }

}  // namespace

uint64_t Envelope::sensitivePixels() const {
    return uint64_t(std::count(pixelClass.begin(), pixelClass.end(), PixelClass::Sensitive));
}

Envelope makeEnvelope(const Image& nominal, const std::vector<const Image*>& variants, uint32_t perturbedRenders,
                      const Image* orderMask, const ObjectMap* objects) {
    REFRAY_CHECK(!nominal.empty(), "an envelope needs a nominal render");
    REFRAY_CHECK(perturbedRenders <= variants.size(),
                 perturbedRenders << " perturbed renders named but only " << variants.size() << " variants given");
    const uint32_t w = nominal.width(), h = nominal.height();
    for (const Image* v : variants)
        REFRAY_CHECK(v && v->width() == w && v->height() == h,
                     "a variant of " << (v ? sizeText(v->width(), v->height()) : "no image") << " for a nominal of "
                                     << sizeText(w, h));
    if (orderMask)
        REFRAY_CHECK(orderMask->width() == w && orderMask->height() == h,
                     "an order mask of " << sizeText(orderMask->width(), orderMask->height()) << " for a nominal of "
                                         << sizeText(w, h));
    if (objects)
        REFRAY_CHECK(objects->ids.size() == size_t(w) * h,
                     "an object map of " << objects->ids.size() << " pixels for a nominal of " << sizeText(w, h));
    Envelope e;
    e.nominal = nominal;
    e.perturbedRenders = perturbedRenders;
    e.variants = uint32_t(variants.size()) + 1;
    const size_t n = size_t(w) * h;
    e.lo.resize(n);
    e.hi.resize(n);
    e.pixelClass.assign(n, PixelClass::Stable);
    e.orderDependent.assign(n, 0);
    e.stableMovesLeaveOneOut.assign(perturbedRenders, 0);
    e.sensitiveOutsideLeaveOneOut.assign(perturbedRenders, 0);
    const bool regional = perturbedRenders <= kMaxRegionalRenders;
    if (regional) {
        if (objects) e.objects = *objects;
        else {
            e.objects.ids.assign(n, 0);
            e.objects.names[0] = "the image";
        }
        for (auto& flags : e.leaveOneOutFlags) flags.assign(n, 0);
    }
    const size_t renders = variants.size() + 1;  // index 0: the nominal
    std::vector<std::array<int, kEnvelopeChannels>> codes(renders);
    for (size_t i = 0; i < n; ++i) {
        for (size_t r = 0; r < renders; ++r) {
            const vec4& v = r == 0 ? nominal.pixels()[i] : variants[r - 1]->pixels()[i];
            for (int c = 0; c < kEnvelopeChannels; ++c) codes[r][c] = code(v[c]);
        }
        // Which renders move this pixel by more than one step in some channel: the leave-one-out calibration counts,
        // for perturbed render r, the pixels that r alone moves (stable over the nominal and every other render).
        // The mover's direction is that of its channel furthest from the nominal, as a candidate's flag's is.
        size_t movers = 0, mover = 0;
        bool moverUp = false;
        for (size_t r = 1; r < renders; ++r) {
            int furthest = 0;
            for (int c = 0; c < kEnvelopeChannels; ++c) {
                const int d = codes[r][c] - codes[0][c];
                if ((d > 1 || d < -1) && std::abs(d) > std::abs(furthest)) furthest = d;
            }
            if (furthest == 0) continue;
            ++movers;
            mover = r - 1;
            moverUp = furthest > 0;
        }
        for (int c = 0; c < kEnvelopeChannels; ++c) {
            const int q = codes[0][c];
            int lo = q, hi = q;
            for (size_t r = 1; r < renders; ++r) {
                lo = std::min(lo, codes[r][c]);
                hi = std::max(hi, codes[r][c]);
            }
            e.lo[i][c] = uint8_t(lo);
            e.hi[i][c] = uint8_t(hi);
            if (lo < q - 1 || hi > q + 1) e.pixelClass[i] = PixelClass::Sensitive;
        }
        if (orderMask) {
            const vec4& m = orderMask->pixels()[i];
            e.orderDependent[i] = (m.r != 0.0f || m.g != 0.0f || m.b != 0.0f) ? 1 : 0;
        }
        if (e.orderDependent[i]) continue;
        if (movers == 1 && mover < perturbedRenders) {
            ++e.stableMovesLeaveOneOut[mover];
            // Such a pixel is sensitive in the full envelope (render i moved it), but for render i, as a candidate
            // the envelope has not seen, it is a stable pixel moved: the regional test's stable flags are these.
            if (regional) e.leaveOneOutFlags[int(flagFamily(false, moverUp))][i] |= 1u << mover;
        }
        if (e.pixelClass[i] != PixelClass::Sensitive) continue;
        // The sensitive calibration: perturbed render r against the envelope of every other render, judged as a
        // candidate is (one step of slack beyond the bounds).
        for (uint32_t r = 0; r < perturbedRenders; ++r) {
            int furthest = 0;  // signed steps outside, of the channel furthest out
            for (int c = 0; c < kEnvelopeChannels; ++c) {
                int lo = INT_MAX, hi = INT_MIN;
                for (size_t o = 0; o < renders; ++o) {
                    if (o == r + 1) continue;
                    lo = std::min(lo, codes[o][c]);
                    hi = std::max(hi, codes[o][c]);
                }
                const int q = codes[r + 1][c];
                const int steps = q < lo - 1 ? q - (lo - 1) : q > hi + 1 ? q - (hi + 1) : 0;
                if (std::abs(steps) > std::abs(furthest)) furthest = steps;
            }
            if (furthest == 0) continue;
            ++e.sensitiveOutsideLeaveOneOut[r];
            if (regional) e.leaveOneOutFlags[int(flagFamily(true, furthest > 0))][i] |= 1u << r;
        }
    }
    return e;
}

void writeEnvelope(const std::string& path, const Envelope& e) {
    const size_t n = e.nominal.pixels().size();
    REFRAY_CHECK(n > 0 && e.lo.size() == n && e.hi.size() == n && e.pixelClass.size() == n &&
                     e.orderDependent.size() == n,
                 "cannot write the envelope '" << path << "': its planes do not match its " << sizeText(e.width(), e.height())
                                               << " nominal");
    const bool regional = !e.leaveOneOutFlags[0].empty();
    if (regional)
        for (const auto& flags : e.leaveOneOutFlags)
            REFRAY_CHECK(flags.size() == n && e.objects.ids.size() == n,
                         "cannot write the envelope '" << path << "': its regional planes do not match its "
                                                       << sizeText(e.width(), e.height()) << " nominal");
    std::vector<std::string> names = kChannelNames;
    if (regional) names.insert(names.end(), kRegionalChannelNames.begin(), kRegionalChannelNames.end());
    const int channels = int(names.size());
    OIIO::ImageSpec spec(int(e.width()), int(e.height()), channels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.alpha_channel = 3;
    for (const auto& [key, value] : e.nominal.metadata) spec.attribute(kMetadataPrefix + key, value);
    for (const auto& [key, value] : e.provenance) spec.attribute(kMetadataPrefix + key, value);
    // Without the regional planes the file holds exactly what version 1 does, and says so.
    spec.attribute(std::string(kMetadataPrefix) + kFormatKey, std::string(regional ? kEnvelopeFormat : kEnvelopeFormatV1));
    spec.attribute(std::string(kMetadataPrefix) + kPerturbedKey, std::to_string(e.perturbedRenders));
    spec.attribute(std::string(kMetadataPrefix) + kVariantsKey, std::to_string(e.variants));
    if (!e.stableMovesLeaveOneOut.empty())
        spec.attribute(std::string(kMetadataPrefix) + kStableMovesKey, countList(e.stableMovesLeaveOneOut));
    if (!e.sensitiveOutsideLeaveOneOut.empty())
        spec.attribute(std::string(kMetadataPrefix) + kSensitiveOutsideKey, countList(e.sensitiveOutsideLeaveOneOut));
    if (regional) spec.attribute(std::string(kMetadataPrefix) + kObjectsKey, objectNameList(e.objects.names));
    spec.attribute("compression", "zip");
    spec.attribute("oiio:UnassociatedAlpha", 1);
    std::vector<float> data(n * channels);
    for (size_t i = 0; i < n; ++i) {
        float* p = &data[i * channels];
        for (int c = 0; c < 4; ++c) p[c] = e.nominal.pixels()[i][c];
        for (int c = 0; c < 3; ++c) {
            p[4 + c] = float(e.lo[i][c]) / 255.0f;
            p[7 + c] = float(e.hi[i][c]) / 255.0f;
        }
        p[10] = float(uint8_t(e.pixelClass[i]));
        p[11] = float(e.orderDependent[i]);
        if (!regional) continue;
        p[12] = float(e.objects.ids[i]);
        for (int f = 0; f < kFlagFamilies; ++f) p[13 + f] = float(e.leaveOneOutFlags[f][i]);
    }
    writeImageFile(path, spec, OIIO::TypeDesc::FLOAT, data.data());
}

namespace {

std::unique_ptr<OIIO::ImageInput> openEnvelope(const std::string& path) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    return openImageFile(path, "the envelope", config);
}

}  // namespace

bool isEnvelopeFile(const std::string& path) {
    if (std::filesystem::is_directory(path)) return false;
    return openEnvelope(path)->spec().channelindex("lo.R") >= 0;
}

Envelope readEnvelope(const std::string& path) {
    auto in = openEnvelope(path);
    const OIIO::ImageSpec& spec = in->spec();
    REFRAY_CHECK(spec.width > 0 && spec.height > 0, "the envelope '" << path << "' has no pixels");
    int index[12];
    for (size_t c = 0; c < kChannelNames.size(); ++c) index[c] = spec.channelindex(kChannelNames[c]);
    REFRAY_CHECK(index[4] >= 0,
                 "'" << path << "' is not an envelope golden (no lo.R channel): a plain image; compare it with "
                                "'refray compare REFERENCE CANDIDATE', or make an envelope with 'refray golden make'");
    std::map<std::string, std::string> metadata;
    const std::string prefix = kMetadataPrefix;
    for (const auto& attribute : spec.extra_attribs) {
        const std::string name = attribute.name().string();
        if (name.rfind(prefix, 0) == 0) metadata[name.substr(prefix.size())] = attribute.get_string();
    }
    const auto format = metadata.find(kFormatKey);
    REFRAY_CHECK(format != metadata.end() && (format->second == kEnvelopeFormat || format->second == kEnvelopeFormatV1),
                 "the envelope '" << path << "' is of format '"
                                  << (format == metadata.end() ? std::string("none") : format->second)
                                  << "', this refray reads '" << kEnvelopeFormat
                                  << "'; remake it with 'refray golden update' or 'refray golden make'");
    for (size_t c = 0; c < kChannelNames.size(); ++c)
        REFRAY_CHECK(index[c] >= 0 || c == 3,
                     "the envelope '" << path << "' is corrupted: it lacks the channel " << kChannelNames[c]);
    Envelope e;
    e.format = format->second;
    int regionalIndex[5];
    for (size_t c = 0; c < kRegionalChannelNames.size(); ++c) regionalIndex[c] = spec.channelindex(kRegionalChannelNames[c]);
    // Version 2 holds every regional plane or (K > kMaxRegionalRenders) none; version 1 none.
    const bool regional = e.format == kEnvelopeFormat && regionalIndex[0] >= 0;
    for (size_t c = 0; regional && c < kRegionalChannelNames.size(); ++c)
        REFRAY_CHECK(regionalIndex[c] >= 0,
                     "the envelope '" << path << "' is corrupted: it lacks the channel " << kRegionalChannelNames[c]);
    try {
        e.perturbedRenders = uint32_t(std::stoul(metadata.at(kPerturbedKey)));
        e.variants = uint32_t(std::stoul(metadata.at(kVariantsKey)));
        for (const auto& [key, counts] : {std::pair{kStableMovesKey, &e.stableMovesLeaveOneOut},
                                          std::pair{kSensitiveOutsideKey, &e.sensitiveOutsideLeaveOneOut}}) {
            const auto found = metadata.find(key);
            if (found == metadata.end()) continue;
            std::istringstream list(found->second);
            for (uint64_t c; list >> c;) counts->push_back(c);
            REFRAY_CHECK(list.eof() && counts->size() == e.perturbedRenders,
                         "the envelope '" << path << "' is corrupted: refray:" << key << " = '" << found->second
                                          << "' is not " << e.perturbedRenders << " counts");
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception&) {
        REFRAY_CHECK(false, "the envelope '" << path << "' is corrupted: no readable refray:" << kPerturbedKey << " or refray:"
                                     << kVariantsKey);
    }
    const int channels = spec.nchannels;
    const size_t n = size_t(spec.width) * spec.height;
    std::vector<float> data(n * channels);
    REFRAY_CHECK(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()),
                 "the envelope '" << path << "' is corrupted: cannot read its pixels: " << in->geterror());
    e.nominal = Image(uint32_t(spec.width), uint32_t(spec.height));
    e.lo.resize(n);
    e.hi.resize(n);
    e.pixelClass.resize(n);
    e.orderDependent.resize(n);
    for (const auto& [key, value] : metadata)
        if (key != kFormatKey && key != kPerturbedKey && key != kVariantsKey && key != kStableMovesKey &&
            key != kSensitiveOutsideKey && key != kObjectsKey)
            e.provenance[key] = value;
    const auto fail = [&](size_t i, const std::string& what) {
        REFRAY_CHECK(false, "the envelope '" << path << "' is corrupted at (" << i % uint32_t(spec.width) << ", "
                                     << i / uint32_t(spec.width) << "): " << what);
    };
    const auto asCode = [&](size_t i, float v, const std::string& channel) {
        const float scaled = v * 255.0f;
        if (!(scaled >= 0.0f && scaled <= 255.0f) || std::fabs(scaled - std::round(scaled)) > 1e-3f)
            fail(i, channel + " = " + std::to_string(v) + " is no UNORM8 value (code/255)");
        return int(std::lround(scaled));
    };
    if (regional) {
        REFRAY_CHECK(e.perturbedRenders <= kMaxRegionalRenders,
                     "the envelope '" << path << "' is corrupted: leave-one-out flags of " << e.perturbedRenders
                                      << " perturbed renders (at most " << kMaxRegionalRenders << ")");
        e.objects.ids.resize(n);
        for (auto& flags : e.leaveOneOutFlags) flags.resize(n);
        const auto names = metadata.find(kObjectsKey);
        if (names != metadata.end()) {
            std::istringstream lines(names->second);
            for (std::string line; std::getline(lines, line);) {
                const size_t eq = line.find('=');
                REFRAY_CHECK(eq != std::string::npos && eq > 0,
                             "the envelope '" << path << "' is corrupted: refray:" << kObjectsKey << " has the line '"
                                              << line << "' (id=name)");
                try {
                    e.objects.names[int32_t(std::stol(line.substr(0, eq)))] = line.substr(eq + 1);
                } catch (const std::exception&) {
                    REFRAY_CHECK(false, "the envelope '" << path << "' is corrupted: refray:" << kObjectsKey
                                                         << " has the line '" << line << "' (id=name)");
                }
            }
        }
    }
    const uint64_t renderBits = e.perturbedRenders >= 32 ? ~0ull : (1ull << e.perturbedRenders) - 1;
    for (size_t i = 0; i < n; ++i) {
        const float* p = &data[i * channels];
        if (regional) {
            const float id = p[regionalIndex[0]];
            if (!(id >= -1.0f && id < 16777216.0f) || id != std::floor(id))
                fail(i, "object = " + std::to_string(id) + " is no object id");
            e.objects.ids[i] = int32_t(id);
            for (int f = 0; f < kFlagFamilies; ++f) {
                const float bits = p[regionalIndex[1 + f]];
                if (!(bits >= 0.0f && bits < 16777216.0f) || bits != std::floor(bits) || (uint64_t(bits) & ~renderBits))
                    fail(i, kRegionalChannelNames[1 + f] + " = " + std::to_string(bits) + " is no mask of " +
                                std::to_string(e.perturbedRenders) + " perturbed renders");
                e.leaveOneOutFlags[f][i] = uint32_t(bits);
            }
        }
        e.nominal.pixels()[i] = vec4(p[index[0]], p[index[1]], p[index[2]], index[3] >= 0 ? p[index[3]] : 1.0f);
        for (int c = 0; c < 3; ++c) {
            const int lo = asCode(i, p[index[4 + c]], kChannelNames[4 + c]);
            const int hi = asCode(i, p[index[7 + c]], kChannelNames[7 + c]);
            const int q = code(e.nominal.pixels()[i][c]);
            if (!(lo <= q && q <= hi))
                fail(i, "the nominal " + std::string(1, kChannelLetters[c]) + " (code " + std::to_string(q) +
                            ") lies outside its bounds [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
            e.lo[i][c] = uint8_t(lo);
            e.hi[i][c] = uint8_t(hi);
        }
        const float cls = p[index[10]], order = p[index[11]];
        if (cls != 0.0f && cls != 1.0f) fail(i, "class = " + std::to_string(cls) + " (0 stable, 1 sensitive)");
        if (order != 0.0f && order != 1.0f) fail(i, "order = " + std::to_string(order) + " (0 or 1)");
        e.pixelClass[i] = cls == 1.0f ? PixelClass::Sensitive : PixelClass::Stable;
        e.orderDependent[i] = order == 1.0f ? 1 : 0;
    }
    e.nominal.metadata = e.provenance;
    return e;
}

namespace {

// The failing regions' bounding boxes, outlined in cyan on the heat map (the most significant few).
void outlineRegions(Image& heatMap, const RegionalJudgement& regional) {
    constexpr size_t kOutlined = 3;
    const vec4 cyan(0.0f, 1.0f, 1.0f, 1.0f);
    for (size_t k = 0; k < std::min(kOutlined, regional.failing.size()); ++k) {
        const RegionalFinding& f = regional.failing[k];
        for (uint32_t x = f.x0; x <= f.x1; ++x) heatMap.at(x, f.y0) = heatMap.at(x, f.y1) = cyan;
        for (uint32_t y = f.y0; y <= f.y1; ++y) heatMap.at(f.x0, y) = heatMap.at(f.x1, y) = cyan;
    }
}

}  // namespace

uint64_t leaveOneOutClusterSize(const std::vector<uint64_t>& counts, const EnvelopeJudgeOptions& options) {
    uint64_t cluster = std::max<uint32_t>(options.clusterSize, 1);
    if (counts.size() < 2) return cluster;
    double mean = 0, variance = 0;
    for (uint64_t c : counts) mean += double(c);
    mean /= double(counts.size());
    for (uint64_t c : counts) variance += (double(c) - mean) * (double(c) - mean);
    variance /= double(counts.size() - 1);
    // A compound Poisson count of clusters of m pixels has variance / mean = m.
    if (mean > 0) cluster = std::max<uint64_t>(cluster, uint64_t(std::ceil(variance / mean)));
    return cluster;
}

uint64_t leaveOneOutBudget(const std::vector<uint64_t>& counts, const EnvelopeJudgeOptions& options) {
    if (counts.empty()) return 0;
    const uint64_t cluster = leaveOneOutClusterSize(counts, options);
    uint64_t clusters = 0, most = 0;
    for (uint64_t c : counts) {
        clusters += (c + cluster - 1) / cluster;
        most = std::max(most, c);
    }
    // Y | Y + T ~ Binomial(Y + T, 1/(K+1)) when the candidate's clusters Y and the K renders' T are Poisson counts of
    // one rate; y is within the budget while P(Binomial(y + T, p) >= y) > falseAlarm (decreasing in y for p < 1/2).
    const double p = 1.0 / double(counts.size() + 1);
    uint64_t y = 0;
    for (;; ++y) {
        const boost::math::binomial_distribution<double> binomial(double(y + 1 + clusters), p);
        if (boost::math::cdf(boost::math::complement(binomial, double(y))) <= options.falseAlarm) break;
    }
    return std::max(y * cluster, most);
}

uint64_t stableBudget(const Envelope& envelope, const EnvelopeJudgeOptions& options) {
    return leaveOneOutBudget(envelope.stableMovesLeaveOneOut, options);
}

EnvelopeJudgement judgeEnvelope(const Envelope& e, const Image& candidate, const EnvelopeJudgeOptions& options) {
    REFRAY_CHECK(options.falseAlarm > 0.0 && options.falseAlarm < 1.0,
                 "the false-alarm probability must lie in (0, 1), not " << options.falseAlarm);
    REFRAY_CHECK(options.clusterSize >= 1, "the cluster size must be at least 1");
    EnvelopeJudgement j;
    j.width = e.width();
    j.height = e.height();
    j.perturbedRenders = e.perturbedRenders;
    if (candidate.width() != e.width() || candidate.height() != e.height()) {
        j.verdict = CompareVerdict::Mismatch;
        j.mismatch = "the candidate is " + sizeText(candidate.width(), candidate.height()) + ", the golden " +
                     sizeText(e.width(), e.height());
        return j;
    }
    const size_t n = size_t(e.width()) * e.height();
    j.pixels = n;
    j.heatMap = Image(e.width(), e.height(), vec4(0.0f, 0.0f, 0.0f, 1.0f));
    std::vector<int8_t> flags(n, kNoFlag);  // the regional test's: family by class and direction
    for (size_t i = 0; i < n; ++i) {
        const vec4& cv = candidate.pixels()[i];
        const vec4& nv = e.nominal.pixels()[i];
        const bool order = e.orderDependent[i] != 0;
        const bool sensitive = e.pixelClass[i] == PixelClass::Sensitive;
        if (order) ++j.orderPixels;
        else if (sensitive) ++j.sensitivePixels;
        else ++j.stablePixels;
        const float grey = 0.2f * (0.2126f * std::clamp(nv.r, 0.0f, 1.0f) + 0.7152f * std::clamp(nv.g, 0.0f, 1.0f) +
                                   0.0722f * std::clamp(nv.b, 0.0f, 1.0f));
        j.heatMap.pixels()[i] = vec4(grey, grey, grey, 1.0f);

        EnvelopePixel px;
        px.x = uint32_t(i % e.width());
        px.y = uint32_t(i / e.width());
        px.pixelClass = e.pixelClass[i];
        px.orderDependent = order;
        for (int c = 0; c < kEnvelopeChannels; ++c) {
            if (!std::isfinite(cv[c])) {
                px.nonFinite = true;
                px.channel = c;
                px.steps = INT_MAX;
                break;
            }
            const int q = code(cv[c]), qn = code(nv[c]);
            const int lo = sensitive ? int(e.lo[i][c]) - 1 : qn - 1;
            const int hi = sensitive ? int(e.hi[i][c]) + 1 : qn + 1;
            const int steps = q < lo ? lo - q : q > hi ? q - hi : 0;
            if (steps > px.steps) {
                px.steps = steps;
                px.channel = c;
                px.candidate = q;
                px.allowedLo = std::max(lo, 0);
                px.allowedHi = std::min(hi, 255);
            }
        }
        if (px.steps == 0) continue;
        j.maxSteps = std::max(j.maxSteps, px.steps);
        if (px.nonFinite) {
            ++j.nonFinite;
            j.heatMap.pixels()[i] = vec4(1.0f, 0.0f, 1.0f, 1.0f);
        } else if (order) {
            ++j.orderOutside;
            j.heatMap.pixels()[i] = vec4(0.2f, 0.4f, 1.0f, 1.0f);
        } else if (sensitive) {
            ++j.sensitiveOutside;
            flags[i] = int8_t(flagFamily(true, px.candidate > px.allowedHi));
            const float t = std::min(1.0f, float(px.steps) / 32.0f);
            j.heatMap.pixels()[i] = vec4(1.0f, 0.55f + 0.45f * t, 0.1f + 0.5f * t, 1.0f);
        } else {
            ++j.stableOutside;
            flags[i] = int8_t(flagFamily(false, px.candidate > px.allowedHi));
            j.heatMap.pixels()[i] = vec4(1.0f, 0.0f, 0.0f, 1.0f);
        }
        j.outside.push_back(px);
    }

    // The sensitive count test: a correct candidate exchangeable with the K perturbed renders falls outside their
    // [min, max] with probability at most 2/(K+1) per pixel; clusters of `clusterSize` pixels move together. The
    // budget is the larger of that binomial quantile and the leave-one-out calibration (docs/compare.md).
    const uint32_t k = std::max<uint32_t>(e.perturbedRenders, 1);
    j.outsideProbability = std::min(1.0, 2.0 / double(k + 1));
    j.expectedOutside = double(j.sensitivePixels) * j.outsideProbability;
    if (j.sensitivePixels > 0) {
        const double clusters = std::ceil(double(j.sensitivePixels) / options.clusterSize);
        if (j.outsideProbability >= 1.0) {
            j.sensitiveBudget = j.sensitivePixels;
        } else {
            const boost::math::binomial_distribution<double> binomial(clusters, j.outsideProbability);
            const double q = std::ceil(boost::math::quantile(boost::math::complement(binomial, options.falseAlarm)));
            j.sensitiveBudget = std::min<uint64_t>(j.sensitivePixels, uint64_t(q) * options.clusterSize);
        }
    }
    j.sensitiveBudget = std::min(j.sensitivePixels,
                                 std::max(j.sensitiveBudget, leaveOneOutBudget(e.sensitiveOutsideLeaveOneOut, options)));
    if (!e.sensitiveOutsideLeaveOneOut.empty()) {
        uint64_t total = 0;
        for (uint64_t c : e.sensitiveOutsideLeaveOneOut) total += c;
        j.expectedOutside = std::max(j.expectedOutside, double(total) / double(e.sensitiveOutsideLeaveOneOut.size()));
    }
    j.stableBudget = stableBudget(e, options);
    if (!e.stableMovesLeaveOneOut.empty()) {
        uint64_t total = 0;
        for (uint64_t c : e.stableMovesLeaveOneOut) total += c;
        j.expectedStableOutside = double(total) / double(e.stableMovesLeaveOneOut.size());
    }
    // The regional count test (core/regional_count_test.h): the verdict is the whole-image counts' OR its.
    j.regional = judgeRegions(e, flags, {options.falseAlarm});
    outlineRegions(j.heatMap, j.regional);
    if (j.nonFinite > 0 || j.stableOutside > j.stableBudget || j.sensitiveOutside > j.sensitiveBudget ||
        j.regional.failed())
        j.verdict = CompareVerdict::Fail;
    else if (double(j.sensitiveOutside) > j.expectedOutside || double(j.stableOutside) > j.expectedStableOutside)
        j.verdict = CompareVerdict::Warn;
    return j;
}

std::string EnvelopeJudgement::describe(size_t listed) const {
    std::ostringstream out;
    if (verdict == CompareVerdict::Mismatch) {
        out << "  verdict         MISMATCH (" << mismatch << ")\n";
        return out.str();
    }
    const auto pct = [&](uint64_t a, uint64_t b) {
        std::ostringstream s;
        s << a << " (" << (b ? 100.0 * double(a) / double(b) : 0.0) << "%)";
        return s.str();
    };
    out << "  size            " << width << "x" << height << ", RGB judged in UNORM8 steps (1/255)\n";
    out << "  pixels          " << stablePixels << " stable, " << sensitivePixels << " sensitive, " << orderPixels
        << " order-dependent (reported apart)\n";
    out << "  stable outside  " << pct(stableOutside, stablePixels)
        << " beyond one step of the nominal (expected " << expectedStableOutside
        << " = mean of the leave-one-out counts; allowed: " << stableBudget << ")\n";
    out << "  sensitive out   " << pct(sensitiveOutside, sensitivePixels)
        << " beyond one step outside the envelope (expected at most " << expectedOutside
        << ": the larger of " << sensitivePixels << " x 2/(K+1), K = " << perturbedRenders
        << ", and the leave-one-out mean; allowed: " << sensitiveBudget << ")\n";
    if (orderPixels) out << "  order outside   " << orderOutside << " of " << orderPixels << " (not in the verdict)\n";
    if (nonFinite) out << "  non-finite      " << nonFinite << " pixels hold NaN or infinity (always a failure)\n";
    if (!outside.empty()) {
        out << "  largest         " << (maxSteps == INT_MAX ? std::string("NaN/inf") : std::to_string(maxSteps) + " steps")
            << " outside\n";
        // The worst first, then scan order.
        std::vector<EnvelopePixel> worst = outside;
        std::stable_sort(worst.begin(), worst.end(), [](const EnvelopePixel& a, const EnvelopePixel& b) {
            const auto rank = [](const EnvelopePixel& p) {
                return p.nonFinite ? 3 : p.orderDependent ? 0 : p.pixelClass == PixelClass::Stable ? 2 : 1;
            };
            return rank(a) != rank(b) ? rank(a) > rank(b) : a.steps > b.steps;
        });
        for (size_t i = 0; i < std::min(listed, worst.size()); ++i) {
            const EnvelopePixel& p = worst[i];
            out << "    (" << p.x << ", " << p.y << ") "
                << (p.orderDependent ? "order" : p.pixelClass == PixelClass::Stable ? "stable" : "sensitive") << " "
                << kChannelLetters[p.channel] << ": ";
            if (p.nonFinite) out << "NaN or infinity\n";
            else
                out << "code " << p.candidate << ", allowed " << p.allowedLo << ".." << p.allowedHi << ", " << p.steps
                    << " steps outside\n";
        }
        if (worst.size() > listed) out << "    ... and " << worst.size() - listed << " more\n";
    }
    if (!regional.available) {
        out << "  regional        not judged: " << regional.unavailable << "\n";
    } else {
        char line[200];
        std::snprintf(line, sizeof line,
                      "  regional        %llu tests (%llu regions of %llu objects x 4 directions), smallest adjusted p %.3g"
                      " (FAILURE below %.3g)\n",
                      (unsigned long long)regional.tests, (unsigned long long)regional.regions,
                      (unsigned long long)regional.objects, regional.smallestAdjustedP, regional.falseAlarm);
        out << line;
        if (regional.closest.candidate > 0 && !regional.failed())
            out << "    closest: " << regional.closest.describe() << "\n";
        for (size_t i = 0; i < std::min<size_t>(3, regional.failing.size()); ++i)
            out << "    " << regional.failing[i].describe() << "\n";
        if (regional.failing.size() > 3) out << "    ... and " << regional.failing.size() - 3 << " more regions\n";
    }
    out << "  verdict         " << toString(verdict);
    if (verdict == CompareVerdict::Fail) {
        out << " (";
        if (nonFinite) out << "NaN or infinity; ";
        if (regional.failed()) {
            const RegionalFinding& f = regional.failing.front();
            out << f.describe() << "; ";
        }
        if (stableOutside > stableBudget)
            out << stableOutside << " stable pixels moved, more than " << stableBudget << " allowed; ";
        if (sensitiveOutside > sensitiveBudget)
            out << sensitiveOutside << " sensitive pixels outside, more than " << sensitiveBudget << " allowed; ";
        out.seekp(-2, std::ios_base::cur);
        out << ")";
    }
    out << "\n";
    return out.str();
}

}  // namespace refray
