// Stability: an object's image under translation of the whole scene (issue 6).
//
// The scene is tests/inspect/table_view_test.cpp's kExplicit (the D3D12 sample's shader library, its ground plane
// and one AABB of analytic spheres) with every world position moved by an offset: both instance translations, the
// camera's eye and target, and the light. The spheres' `primitiveTransforms` centre is object space (the AABB's
// centre in the BLAS) and the ground's vertices are object space, so neither moves. The offset is
// (D, D/2, -D) with D an even integer, so the inputs are exact floats and the ground's checkers (period 2 in world
// x and z) land on the same squares; any difference in the image is rounding inside the pipeline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.h"
#include "scenes/render_settings.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {
namespace {

using procedural::Precision;

// "%.17g" of a double: the exact value of every number the scenes below use.
std::string num(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    return buffer;
}

std::string vec3Text(double x, double y, double z) {
    std::string text = "[";
    text += num(x);
    text += ", ";
    text += num(y);
    text += ", ";
    text += num(z);
    text += "]";
    return text;  // appended piece by piece: GCC 12's -Wrestrict misfires on chains of operator+
}

// What varies between the scenes of this file: where the world origin is, the spheres' instance scale, the camera
// and light (given for offset 0), and whether the ground plane is there. A scaled instance is tested apart: at the
// Julia's scale 100 x 30 x 100 the spheres are hit but the sample's distance fog turns every pixel to background
// (HazardScale.D3D12SpheresUnderTheJuliaScaleAreHitButFogged in hazards_emulator_test.cpp).
struct Layout {
    double offset[3] = {0, 0, 0};
    double scale[3] = {1, 1, 1};
    double eye[3] = {0, 4, -9};
    double target[3] = {0, 1.5, 0};
    double light[3] = {0, 18, -20};
    double nearPlane = 0.01;
    double farPlane = 125;
    bool ground = true;
};

// `text` with `from` replaced by `to`; `from` must occur exactly once.
std::string replacedOnce(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    if (at == std::string::npos || text.find(from, at + 1) != std::string::npos) {
        std::string message = "the scene text does not hold exactly one '";
        message += from;
        message += "'";
        throw std::runtime_error(message);
    }
    return text.replace(at, from.size(), to);
}

// The scene-format example in explicit layout (tests/scenes/data/ground-and-spheres-explicit.json) with every
// world position moved by the layout's offset, the spheres' instance scaled, and the camera and light of `l`.
std::string sceneText(const Layout& l) {
    static const std::string base = [] {
        std::ifstream in(std::string(REFRAY_SOURCE_DIR) + "/tests/scenes/data/ground-and-spheres-explicit.json");
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }();
    const double* o = l.offset;
    std::string text = replacedOnce(base, "\"ground-and-spheres\"", "\"translated-ground-and-spheres\"");
    std::string ground;
    if (l.ground) {
        ground = "    {\"name\": \"ground\", \"blas\": \"Plane\", \"mask\": 1,\n     \"transform\": {\"scale\": [40, 1, 40], "
                 "\"translate\": ";
        ground += vec3Text(-20 + o[0], o[1], -20 + o[2]);
        ground += "}, \"contribution\": 0},\n";
    }
    text = replacedOnce(text,
                        "    {\"name\": \"ground\", \"blas\": \"Plane\", \"mask\": 1,\n     \"transform\": {\"scale\": [40, 1, "
                        "40], \"translate\": [-20, 0, -20]}, \"contribution\": 0},\n",
                        ground);
    std::string spheres = "\"contribution\": 2, \"transform\": {\"scale\": ";
    spheres += vec3Text(l.scale[0], l.scale[1], l.scale[2]);
    spheres += ", \"translate\": ";
    spheres += vec3Text(o[0], o[1], o[2]);
    spheres += "}}";
    text = replacedOnce(text, "\"contribution\": 2}", spheres);
    std::string camera = "\"eye\": ";
    camera += vec3Text(l.eye[0] + o[0], l.eye[1] + o[1], l.eye[2] + o[2]);
    camera += ", \"target\": ";
    camera += vec3Text(l.target[0] + o[0], l.target[1] + o[1], l.target[2] + o[2]);
    text = replacedOnce(text, "\"eye\": [0, 4, -9], \"target\": [0, 1.5, 0]", camera);
    std::string planes = "\"near\": ";
    planes += num(l.nearPlane);
    planes += ", \"far\": ";
    planes += num(l.farPlane);
    text = replacedOnce(text, "\"near\": 0.01, \"far\": 125", planes);
    std::string light = "\"position\": ";
    light += vec3Text(l.light[0] + o[0], l.light[1] + o[1], l.light[2] + o[2]);
    light.back() = ',';
    light += " 0]";
    return replacedOnce(text, "\"position\": [0, 18, -20, 0]", light);
}

constexpr uint32_t kWidth = 96;
constexpr uint32_t kHeight = 54;

Image render(const Layout& layout, Precision precision) {
    Scene scene(parseScene(sceneText(layout), "translated.json"));
    RenderSettings s;
    s.width = kWidth;
    s.height = kHeight;
    s.threads = 4;
    s.precision = precision;
    return scene.render(s).image;
}

// How far one render is from another, channel by channel (RGB, each clamped to [0, 1] as the UNORM target does).
struct Difference {
    double maxAbs = 0;
    double shareOver1of255 = 0;  // of the pixels, those with a channel more than 1/255 off
    double shareOver0p1 = 0;     // ... more than 0.1 off
    size_t nonFinite = 0;        // channels of `actual` that are NaN or Inf
    size_t objectPixels = 0;     // pixels not of the background colour in either image
    size_t objectOver1of255 = 0;  // of those, how many are more than 1/255 off
};

// The miss shader's colour is a constant: the top-left pixel, which none of the scenes below cover.
bool isBackground(const Image& image, uint32_t x, uint32_t y) {
    const vec4 a = image.at(x, y), b = image.at(0, 0);
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

Difference compare(const Image& expected, const Image& actual) {
    Difference d;
    size_t over1of255 = 0, over0p1 = 0;
    for (uint32_t y = 0; y < expected.height(); ++y)
        for (uint32_t x = 0; x < expected.width(); ++x) {
            double worst = 0;
            for (int c = 0; c < 3; ++c) {
                const float a = actual.at(x, y)[c];
                if (!std::isfinite(a)) {
                    ++d.nonFinite;
                    worst = 1;
                    continue;
                }
                const double e = std::clamp(double(expected.at(x, y)[c]), 0.0, 1.0);
                worst = std::max(worst, std::abs(std::clamp(double(a), 0.0, 1.0) - e));
            }
            d.maxAbs = std::max(d.maxAbs, worst);
            if (!isBackground(expected, x, y) || !isBackground(actual, x, y)) {
                ++d.objectPixels;
                d.objectOver1of255 += worst > 1.0 / 255.0;
            }
            over1of255 += worst > 1.0 / 255.0;
            over0p1 += worst > 0.1;
        }
    const double pixels = double(expected.width()) * expected.height();
    d.shareOver1of255 = double(over1of255) / pixels;
    d.shareOver0p1 = double(over0p1) / pixels;
    return d;
}

const char* name(Precision precision) { return precision == Precision::Float ? "float" : "double"; }

// The picture of one render's difference from the reference: white where equal, darker by 4 x the largest channel
// difference (black from 0.25 on), magenta where `actual` is not finite. docs/images/stability/translation-fringe.png
// is made of these.
Image differenceImage(const Image& expected, const Image& actual) {
    Image out(expected.width(), expected.height(), vec4(0, 0, 0, 1));
    for (uint32_t y = 0; y < expected.height(); ++y)
        for (uint32_t x = 0; x < expected.width(); ++x) {
            const vec4 a = actual.at(x, y), e = expected.at(x, y);
            if (!(std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]))) {
                out.at(x, y) = vec4(1, 0, 1, 1);
                continue;
            }
            float worst = 0;
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::abs(std::clamp(a[c], 0.0f, 1.0f) - std::clamp(e[c], 0.0f, 1.0f)));
            const float g = 1 - std::min(1.0f, 4 * worst);
            out.at(x, y) = vec4(g, g, g, 1);
        }
    return out;
}

// "1e3" for 1000, "0" for 0.
std::string offsetName(double D) {
    if (D == 0) return "0";
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "1e%d", int(std::lround(std::log10(D))));
    return buffer;
}

// Renders `base` at offset 0 and at each D of `offsets` (offset (D, D/2, -D)), prints one line per offset and
// returns the differences, in the order of `offsets`. With a `picture` prefix, writes the reference render and each
// difference image to REFRAY_TEST_OUTPUT_DIR as PREFIX-PRECISION-0.png and PREFIX-PRECISION-diff-1eN.png.
std::vector<Difference> sweep(const char* label, Layout base, Precision precision, const std::vector<double>& offsets,
                              const char* picture = nullptr) {
    const Image reference = render(base, precision);
    const std::string prefix =
        picture ? std::string(REFRAY_TEST_OUTPUT_DIR) + "/" + picture + "-" + name(precision) + "-" : std::string();
    if (picture) {
        std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
        writeImage(prefix + "0.png", reference);
    }
    std::vector<Difference> out;
    for (const double D : offsets) {
        base.offset[0] = D;
        base.offset[1] = D / 2;
        base.offset[2] = -D;
        const Image image = render(base, precision);
        const Difference d = compare(reference, image);
        if (picture) writeImage(prefix + "diff-" + offsetName(D) + ".png", differenceImage(reference, image));
        std::printf("[translation] %s %s D=%.0e: max |diff| %.4f, pixels > 1/255 %.1f%%, > 0.1 %.1f%%, non-finite %zu; "
                    "object pixels %zu, of them > 1/255 %zu\n",
                    label, name(precision), D, d.maxAbs, 100 * d.shareOver1of255, 100 * d.shareOver0p1, d.nonFinite,
                    d.objectPixels, d.objectOver1of255);
        out.push_back(d);
    }
    return out;
}

const std::vector<double> kOffsets = {1e3, 1e4, 1e5};

// Why the image is not invariant. The ray generation shader unprojects each pixel at the near plane (z = 0) through
// projectionToWorld, which the scene constants hold in float: the homogeneous point is about eye / near, so after
// the divide by w the near-plane point carries an error of about ulp(|eye|) and the direction
// normalize(point - eye), a vector of length ~near, turns by about ulp(|eye|) / near radians. With near = 0.01, a
// 45 degree field of view and 54 rows (0.0145 rad a pixel) that is 6.1e-5 / 0.01 = 0.006 rad = 0.4 pixel at
// D = 1e3, 4 pixels at 1e4 and 40 pixels at 1e5; the rounding of the matrix is in the constants, so double
// shaders do not remove it. Silhouettes and the chrome's reflections move by that much, so even D = 1e3 is not
// identical: only there do the differences stay a one-pixel fringe, which is the stated bound.
constexpr double kBoundMaxAbsAt1e3 = 0.35;   // measured 0.26 to 0.33: a pixel of sphere against background or ground
constexpr double kBoundShareOver0p1At1e3 = 0.02;  // measured 0.2% (spheres) and 0.5% to 1.3% (with the ground)

void expectWithinTheBoundAt1e3(const Difference& d) {
    EXPECT_LE(d.maxAbs, kBoundMaxAbsAt1e3);
    EXPECT_LE(d.shareOver0p1, kBoundShareOver0p1At1e3);
}

TEST(Translation, GroundAndSpheresStayWithinAPixelFringeAt1e3AndFiniteInDoubleTo1e5) {
    for (const Precision precision : {Precision::Float, Precision::Double}) {
        // Also the pictures of docs/numerical-stability.md (translation-fringe.png).
        const std::vector<Difference> d = sweep("ground+spheres", Layout{}, precision, kOffsets, "translation");
        expectWithinTheBoundAt1e3(d[0]);
        EXPECT_EQ(d[0].nonFinite, 0u);
        // With float shaders the ground renders NaN from D = 1e4 on (7668 channels at 1e4, 12579 at 1e5, measured):
        // the neighbouring pixels' rays round to the same direction, so CheckersTextureBoxFilter's filter width w is
        // 0 and its integral divides 0 by 0, as the HLSL does on a GPU. Not a port error; the render reports it
        // (GEN_4_NaNPixelsOfTheFloatGroundAreReported below).
        if (precision == Precision::Double) {
            for (const Difference& x : d) EXPECT_EQ(x.nonFinite, 0u);
        }
    }
}

TEST(Translation, SpheresAloneStayWithinAPixelFringeAt1e3AndFiniteTo1e5) {
    Layout l;
    l.ground = false;
    for (const Precision precision : {Precision::Float, Precision::Double}) {
        const std::vector<Difference> d = sweep("spheres", l, precision, kOffsets);
        expectWithinTheBoundAt1e3(d[0]);
        for (const Difference& x : d) EXPECT_EQ(x.nonFinite, 0u);
    }
}

TEST(Translation, GEN_4_NaNPixelsOfTheFloatGroundAreReported) {
    Layout l;
    l.offset[0] = 1e4, l.offset[1] = 0.5e4, l.offset[2] = -1e4;
    Scene scene(parseScene(sceneText(l), "translated.json"));
    RenderSettings s;
    s.width = kWidth;
    s.height = kHeight;
    s.threads = 2;
    const RenderResult r = scene.render(s);
    size_t nonFinite = 0;
    for (const vec4& p : r.image.pixels()) nonFinite += !(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b));
    ASSERT_GT(nonFinite, 0u) << "the float ground no longer goes NaN at 1e4: update docs/numerical-stability.md";
    const std::optional<dxr::Diagnostic> w = r.dispatch.diagnostics.find("GEN-4");
    ASSERT_TRUE(w.has_value()) << "a NaN pixel must not be silent";
    EXPECT_EQ(w->severity, dxr::Severity::Warning);
    std::string count = "pixels = ";
    count += std::to_string(nonFinite);
    EXPECT_NE(w->format().find(count), std::string::npos) << w->format();
}

}  // namespace
}  // namespace refray::scenes
