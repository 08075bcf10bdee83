#include "scenes/knobs.h"

#include <charconv>
#include <cmath>
#include <functional>
#include <optional>

#include "core/error.h"
#include "core/strings.h"

namespace refray::scenes {

namespace {

// How one knob reads and writes its RenderSettings field.
struct KnobAccess {
    KnobInfo info;
    std::function<void(RenderSettings&, std::string_view)> set;  // throws refray::Error for a bad value
    std::function<std::string(const RenderSettings&)> get;
    std::function<bool(const RenderSettings&)> isDefault;
};

std::string knobError(std::string_view name, std::string_view value, std::string_view expected) {
    std::string text = "knob ";
    text += name;
    text += " expects ";
    text += expected;
    text += ", got ";
    text += inQuotes(value);
    return text;
}

// A finite factor in [1e-3, 1e3].
double parseFactor(std::string_view name, std::string_view value) {
    double x = 0.0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), x);
    REFRAY_CHECK(ec == std::errc() && end == value.data() + value.size() && std::isfinite(x) && x >= 1e-3 && x <= 1e3,
                 knobError(name, value, "a factor between 0.001 and 1000"));
    return x;
}

uint32_t parseCount(std::string_view name, std::string_view value, uint32_t lo, uint32_t hi) {
    uint32_t n = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), n);
    REFRAY_CHECK(ec == std::errc() && end == value.data() + value.size() && n >= lo && n <= hi,
                 knobError(name, value, "a whole number from " + std::to_string(lo) + " to " + std::to_string(hi)));
    return n;
}

std::string factorText(double x) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, x);
    return std::string(text, end.ptr);
}

// An optional Accuracy count whose unset value means `hlslDefault`. With `keepExplicit`, a value equal to the
// default is kept as set (it overrides what a scene file's effects block says, e.g. reflectionDepth 1).
KnobAccess countKnob(KnobInfo info, std::optional<uint32_t> procedural::Accuracy::*field, uint32_t hlslDefault,
                     uint32_t lo, uint32_t hi, bool keepExplicit = false) {
    const std::string name = info.name;
    return {std::move(info),
            [=](RenderSettings& s, std::string_view v) {
                const uint32_t n = parseCount(name, v, lo, hi);
                s.accuracy.*field = n == hlslDefault && !keepExplicit ? std::nullopt : std::optional<uint32_t>(n);
            },
            [=](const RenderSettings& s) { return std::to_string((s.accuracy.*field).value_or(hlslDefault)); },
            [=](const RenderSettings& s) { return !(s.accuracy.*field).has_value(); }};
}

KnobAccess factorKnob(KnobInfo info, double procedural::Accuracy::*field) {
    const std::string name = info.name;
    return {std::move(info), [=](RenderSettings& s, std::string_view v) { s.accuracy.*field = parseFactor(name, v); },
            [=](const RenderSettings& s) { return factorText(s.accuracy.*field); },
            [=](const RenderSettings& s) { return s.accuracy.*field == 1.0; }};
}

const std::vector<KnobAccess>& knobAccess() {
    using procedural::Accuracy;
    static const std::vector<KnobAccess> all = [] {
        std::vector<KnobAccess> k;
        k.push_back(factorKnob({"steps", "multiplies every march's step limit (SDF 512, Julia 1024, Mandelbulb iMax)",
                                "factor", true},
                               &Accuracy::stepsFactor));
        k.push_back(factorKnob({"threshold", "multiplies every march's hit threshold (SDF and Mandelbulb 1e-4*t, Julia 0.00025)",
                                "factor", false},
                               &Accuracy::thresholdFactor));
        k.push_back(countKnob({"mandelbulb-iterations", "iterations of the Mandelbulb distance estimator (HLSL: 4)",
                               "count", true},
                              &Accuracy::mandelbulbIterations, kDefaultMandelbulbIterations, 1, 64));
        k.push_back(countKnob({"julia-iterations", "iterations of the Julia distance estimator (HLSL: 200)", "count", true},
                              &Accuracy::juliaIterations, kDefaultJuliaIterations, 1, 10000));
        k.push_back(factorKnob({"normal-epsilon", "multiplies every normal-estimation offset", "factor", false},
                               &Accuracy::normalEpsilonFactor));
        k.push_back(countKnob({"metaball-steps", "samples of the metaballs' fixed-step march (HLSL: 128)", "count", true},
                              &Accuracy::metaballSteps, kDefaultMetaballSteps, 1, 65536));
        k.push_back(countKnob({"recursion-depth", "MAX_RAY_RECURSION_DEPTH: reflection bounces (HLSL: 3)", "count", true},
                              &Accuracy::maxRecursionDepth, kDefaultRecursionDepth, 1, 31, /*keepExplicit*/ true));
        k.push_back({{"spp", "samples per pixel, a square number (k x k pixel centres)", "count", true},
                     [](RenderSettings& s, std::string_view v) {
                         const uint32_t n = parseCount("spp", v, 1, 4096);
                         const auto root = uint32_t(std::lround(std::sqrt(double(n))));
                         REFRAY_CHECK(root * root == n, knobError("spp", v, "a square number (1, 4, 9, 16, ...)"));
                         s.spp = n;
                     },
                     [](const RenderSettings& s) { return std::to_string(s.spp); },
                     [](const RenderSettings& s) { return s.spp == 1; }});
        k.push_back({{"precision", "scalar type of the shader math: float (the GPU's) or double", "", true},
                     [](RenderSettings& s, std::string_view v) {
                         const std::optional<procedural::Precision> p = procedural::parsePrecision(v);
                         REFRAY_CHECK(p, knobError("precision", v, "float or double"));
                         s.precision = *p;
                     },
                     [](const RenderSettings& s) { return std::string(procedural::toString(s.precision)); },
                     [](const RenderSettings& s) { return s.precision == procedural::Precision::Float; }});
        return k;
    }();
    return all;
}

const KnobAccess& findKnob(std::string_view name) {
    std::vector<std::string> names;
    for (const KnobAccess& k : knobAccess()) {
        if (k.info.name == name) return k;
        names.push_back(k.info.name);
    }
    std::string text = "unknown knob " + inQuotes(name) + didYouMean(name, names);
    text += "; knobs: ";
    text += joined(names);
    throw Error(text);
}

}  // namespace

const std::vector<KnobInfo>& knobs() {
    static const std::vector<KnobInfo> infos = [] {
        std::vector<KnobInfo> v;
        for (const KnobAccess& k : knobAccess()) v.push_back(k.info);
        return v;
    }();
    return infos;
}

void applyKnob(RenderSettings& settings, std::string_view name, std::string_view value) { findKnob(name).set(settings, value); }

void applyKnobAssignment(RenderSettings& settings, std::string_view assignment) {
    const size_t eq = assignment.find('=');
    REFRAY_CHECK(eq != std::string_view::npos && eq > 0,
                 "a knob setting is name=value (e.g. steps=2), got " << inQuotes(assignment));
    applyKnob(settings, assignment.substr(0, eq), assignment.substr(eq + 1));
}

void applyKnobList(RenderSettings& settings, std::string_view list) {
    while (!list.empty()) {
        const size_t comma = list.find(',');
        applyKnobAssignment(settings, list.substr(0, comma));
        if (comma == std::string_view::npos) break;
        list.remove_prefix(comma + 1);
    }
}

std::string knobValue(const RenderSettings& settings, std::string_view name) { return findKnob(name).get(settings); }

std::string describeKnobs(const RenderSettings& settings) {
    std::string text;
    for (const KnobAccess& k : knobAccess()) {
        if (k.isDefault(settings)) continue;
        if (!text.empty()) text += ',';
        text += k.info.name;
        text += '=';
        text += k.get(settings);
    }
    return text.empty() ? "defaults" : text;
}

}  // namespace refray::scenes
