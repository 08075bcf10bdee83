// LDR-FLIP: known values, properties, and agreement with a direct (non-separable,
// double-precision) evaluation of the paper's formulas.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/flip.h"
#include "core/random.h"

using namespace refray;

namespace {

constexpr double kPi = 3.14159265358979323846;

Image noiseImage(uint32_t width, uint32_t height, uint32_t seed) {
    Image image(width, height);
    Random random(0, 0, 0, seed);
    for (vec4& p : image.pixels()) p = vec4(random.nextFloat(), random.nextFloat(), random.nextFloat(), 1.0f);
    return image;
}

// Smooth content with a few sharp edges, as a render has.
Image sceneImage(uint32_t width, uint32_t height) {
    Image image(width, height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            const float u = float(x) / float(width), v = float(y) / float(height);
            const bool disc = (u - 0.5f) * (u - 0.5f) + (v - 0.5f) * (v - 0.5f) < 0.08f;
            image.at(x, y) = disc ? vec4(0.9f, 0.3f * v, 0.2f, 1.0f) : vec4(0.2f + 0.5f * u, 0.4f, 0.6f * v, 1.0f);
        }
    return image;
}

double mean(const FlipMap& map) { return flipStatistics(map).mean; }

// --- A direct evaluation of the paper's formulas, for comparison -----------------

// Published CIELAB (D65) of the sRGB primaries green and blue.
constexpr dvec3 kLabGreen{87.737, -86.185, 83.181};
constexpr dvec3 kLabBlue{32.303, 79.197, -107.864};

dvec3 hunt(dvec3 lab) { return {lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z}; }
double hyab(dvec3 a, dvec3 b) { return std::abs(a.x - b.x) + std::hypot(a.y - b.y, a.z - b.z); }
double cmax() { return std::pow(hyab(hunt(kLabGreen), hunt(kLabBlue)), 0.7); }

double redistribute(double e) {
    const double c = cmax();
    return e < 0.4 * c ? 0.95 / (0.4 * c) * e : 0.95 + (e - 0.4 * c) / (c - 0.4 * c) * 0.05;
}

// L* of a grey with display value v (a* = b* = 0).
double greyLightness(double v) {
    const double linear = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
    const double d = 6.0 / 29.0;
    const double f = linear > d * d * d ? std::cbrt(linear) : linear / (3 * d * d) + 4.0 / 29.0;
    return 116.0 * f - 16.0;
}

// sRGB primaries, D65.
const glm::dmat3 kToXYZ = glm::transpose(glm::dmat3(0.4124564, 0.3575761, 0.1804375, 0.2126729, 0.7151522, 0.0721750,
                                                    0.0193339, 0.1191920, 0.9503041));

std::vector<double> directFlip(const Image& reference, const Image& test, double ppd) {
    const int w = int(reference.width()), h = int(reference.height());
    const dvec3 white = kToXYZ * dvec3(1.0);
    const auto clampX = [&](int x) { return std::clamp(x, 0, w - 1); };
    const auto clampY = [&](int y) { return std::clamp(y, 0, h - 1); };

    // 2D CSF kernels, normalised to sum 1.
    const int r = int(std::ceil(3.0 * std::sqrt(0.04 / (2 * kPi * kPi)) * ppd));
    const auto csf = [&](double a1, double b1, double a2, double b2) {
        std::vector<double> k;
        double sum = 0;
        for (int j = -r; j <= r; ++j)
            for (int i = -r; i <= r; ++i) {
                const double z = (i * i + j * j) / (ppd * ppd);
                const double v = a1 * std::sqrt(kPi / b1) * std::exp(-kPi * kPi * z / b1) +
                                 a2 * std::sqrt(kPi / b2) * std::exp(-kPi * kPi * z / b2);
                k.push_back(v);
                sum += v;
            }
        for (double& v : k) v /= sum;
        return k;
    };
    const std::vector<double> kernels[3] = {csf(1, 0.0047, 0, 1e-5), csf(1, 0.0053, 0, 1e-5), csf(34.1, 0.04, 13.5, 0.025)};

    // Feature kernels: x-derivatives, positive part normalised to 1, negative to -1.
    const double sd = 0.5 * 0.082 * ppd;
    const int fr = int(std::ceil(3 * sd));
    const auto feature = [&](bool point) {
        std::vector<double> k;
        double positive = 0, negative = 0;
        for (int j = -fr; j <= fr; ++j)
            for (int i = -fr; i <= fr; ++i) {
                const double g = std::exp(-(i * i + j * j) / (2 * sd * sd));
                const double v = point ? (i * i / (sd * sd) - 1) * g : -i * g;
                k.push_back(v);
                (v > 0 ? positive : negative) += v;
            }
        for (double& v : k) v = v > 0 ? v / positive : -v / negative;
        return k;
    };
    const std::vector<double> edgeKernel = feature(false), pointKernel = feature(true);

    struct Prepared {
        std::vector<dvec3> lab;
        std::vector<double> edges, points;
    };
    const auto prepare = [&](const Image& image) {
        std::vector<dvec3> ycc(size_t(w * h));
        std::vector<double> lum(size_t(w * h));
        for (size_t i = 0; i < ycc.size(); ++i) {
            dvec3 rgb = glm::clamp(dvec3(image.pixels()[i]), 0.0, 1.0);
            for (int c = 0; c < 3; ++c)
                rgb[c] = rgb[c] <= 0.04045 ? rgb[c] / 12.92 : std::pow((rgb[c] + 0.055) / 1.055, 2.4);
            const dvec3 n = kToXYZ * rgb / white;
            ycc[i] = {116 * n.y - 16, 500 * (n.x - n.y), 200 * (n.y - n.z)};
            lum[i] = n.y;
        }
        Prepared p;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                dvec3 f(0.0);
                size_t k = 0;
                for (int j = -r; j <= r; ++j)
                    for (int i = -r; i <= r; ++i, ++k) {
                        const dvec3 v = ycc[size_t(clampY(y + j) * w + clampX(x + i))];
                        for (int c = 0; c < 3; ++c) f[c] += kernels[c][k] * v[c];
                    }
                const double ny = (f.x + 16) / 116;
                const dvec3 n(f.y / 500 + ny, ny, ny - f.z / 200);
                const dvec3 rgb = glm::clamp(glm::inverse(kToXYZ) * (n * white), 0.0, 1.0);
                const dvec3 t = kToXYZ * rgb / white;
                const auto lab = [](double v) {
                    const double d = 6.0 / 29.0;
                    return v > d * d * d ? std::cbrt(v) : v / (3 * d * d) + 4.0 / 29.0;
                };
                p.lab.push_back(hunt({116 * lab(t.y) - 16, 500 * (lab(t.x) - lab(t.y)), 200 * (lab(t.y) - lab(t.z))}));

                double ex = 0, ey = 0, px = 0, py = 0;
                k = 0;
                for (int j = -fr; j <= fr; ++j)
                    for (int i = -fr; i <= fr; ++i, ++k) {
                        ex += edgeKernel[k] * lum[size_t(clampY(y + j) * w + clampX(x + i))];
                        px += pointKernel[k] * lum[size_t(clampY(y + j) * w + clampX(x + i))];
                        ey += edgeKernel[k] * lum[size_t(clampY(y + i) * w + clampX(x + j))];  // transposed kernel
                        py += pointKernel[k] * lum[size_t(clampY(y + i) * w + clampX(x + j))];
                    }
                p.edges.push_back(std::hypot(ex, ey));
                p.points.push_back(std::hypot(px, py));
            }
        return p;
    };
    const Prepared a = prepare(reference), b = prepare(test);
    std::vector<double> out;
    for (size_t i = 0; i < a.lab.size(); ++i) {
        const double colour = redistribute(std::pow(hyab(a.lab[i], b.lab[i]), 0.7));
        const double f = std::max(std::abs(a.edges[i] - b.edges[i]), std::abs(a.points[i] - b.points[i]));
        out.push_back(std::pow(colour, 1 - std::pow(f / std::sqrt(2.0), 0.5)));
    }
    return out;
}

}  // namespace

TEST(Flip, IdenticalImagesGiveZero) {
    const Image image = noiseImage(40, 30, 7);
    const FlipMap map = computeFlip(image, image);
    ASSERT_EQ(map.error.size(), 40u * 30u);
    for (float e : map.error) EXPECT_EQ(e, 0.0f);
}

TEST(Flip, BlackAgainstWhiteIsTheAnalyticValueNearOne) {
    // Uniform images: no features, filters keep constants, so every pixel is the
    // redistributed HyAB of L* 0 against L* 100.
    const FlipMap map = computeFlip(Image(24, 16, vec4(0, 0, 0, 1)), Image(24, 16, vec4(1, 1, 1, 1)));
    const double expected = redistribute(std::pow(100.0, 0.7));
    EXPECT_GT(expected, 0.95);
    for (float e : map.error) EXPECT_NEAR(e, expected, 1e-4);
}

TEST(Flip, UniformGreysFollowTheLowerBranchOfTheRedistribution) {
    const FlipMap map = computeFlip(Image(20, 20, vec4(vec3(0.5f), 1)), Image(20, 20, vec4(vec3(0.52f), 1)));
    const double expected = redistribute(std::pow(greyLightness(0.52) - greyLightness(0.5), 0.7));
    EXPECT_LT(expected, 0.95 * 0.9);
    for (float e : map.error) EXPECT_NEAR(e, expected, 2e-4);
}

TEST(Flip, AgreesWithADirectEvaluationOfThePaperFormulas) {
    const Image reference = sceneImage(28, 22);
    Image test = noiseImage(28, 22, 3);
    for (size_t i = 0; i < test.pixels().size(); ++i)
        test.pixels()[i] = glm::mix(reference.pixels()[i], test.pixels()[i], (i % 7 == 0) ? 0.6f : 0.05f);
    for (const double ppd : {67.0, 30.0}) {
        const FlipMap fast = computeFlip(reference, test, ppd);
        const std::vector<double> slow = directFlip(reference, test, ppd);
        double worst = 0;
        for (size_t i = 0; i < slow.size(); ++i) worst = std::max(worst, std::abs(fast.error[i] - slow[i]));
        EXPECT_LT(worst, 2e-4) << "at " << ppd << " ppd";
    }
}

TEST(Flip, TinyDifferenceGivesASmallMean) {
    const Image reference = sceneImage(64, 48);
    Image test = reference;
    for (vec4& p : test.pixels()) p.g = std::min(1.0f, p.g + 1.0f / 255.0f);
    const double m = mean(computeFlip(reference, test));
    EXPECT_GT(m, 0.0);
    EXPECT_LT(m, 0.05);
}

TEST(Flip, GrowsMonotonicallyWithTheDifference) {
    const Image reference = sceneImage(48, 36);
    double previous = 0.0;
    for (int step = 1; step <= 6; ++step) {
        Image test = reference;
        for (vec4& p : test.pixels()) p = glm::clamp(p + vec4(0.04f * step, -0.02f * step, 0.0f, 0.0f), 0.0f, 1.0f);
        const double m = mean(computeFlip(reference, test));
        EXPECT_GT(m, previous) << "step " << step;
        previous = m;
    }
}

TEST(Flip, IsSymmetric) {
    const Image a = sceneImage(30, 20), b = noiseImage(30, 20, 11);
    const FlipMap ab = computeFlip(a, b), ba = computeFlip(b, a);
    for (size_t i = 0; i < ab.error.size(); ++i) EXPECT_FLOAT_EQ(ab.error[i], ba.error[i]);
}

TEST(Flip, AChangedPixelOnlyAffectsItsNeighbourhood) {
    const Image reference(41, 41, vec4(0.5f, 0.5f, 0.5f, 1.0f));
    Image test = reference;
    test.at(20, 20) = vec4(0.0f, 0.0f, 0.0f, 1.0f);
    const FlipMap map = computeFlip(reference, test);
    // Colour filter radius 10 and feature radius 9 at 67 ppd: nothing beyond 10 pixels.
    for (uint32_t y = 0; y < 41; ++y)
        for (uint32_t x = 0; x < 41; ++x) {
            const int d = std::max(std::abs(int(x) - 20), std::abs(int(y) - 20));
            if (d > 10) {
                EXPECT_EQ(map.at(x, y), 0.0f) << x << "," << y;
            }
            if (d > 0) {
                EXPECT_LT(map.at(x, y), map.at(20, 20)) << x << "," << y;
            }
        }
    EXPECT_GT(map.at(20, 20), 0.1f);
    EXPECT_FLOAT_EQ(map.at(15, 20), map.at(25, 20));
}

TEST(Flip, NaNReadsAsZeroAndValuesAreClamped) {
    Image a(8, 8, vec4(0.0f, 1.0f, 0.25f, 1.0f)), b = a;
    b.at(3, 3) = vec4(std::nanf(""), 7.0f, 0.25f, 1.0f);
    for (float e : computeFlip(a, b).error) EXPECT_EQ(e, 0.0f);
}

TEST(Flip, MisuseIsAnError) {
    EXPECT_THROW(computeFlip(Image(4, 4), Image(4, 5)), Error);
    EXPECT_THROW(computeFlip(Image(), Image()), Error);
    EXPECT_THROW(computeFlip(Image(4, 4), Image(4, 4), 0.0), Error);
}

TEST(Flip, StatisticsUseLinearlyInterpolatedQuartiles) {
    FlipMap map;
    map.width = 5;
    map.height = 1;
    map.error = {0.4f, 0.0f, 0.3f, 0.1f, 0.2f};
    const FlipStats all = flipStatistics(map);
    EXPECT_NEAR(all.mean, 0.2, 1e-7);
    EXPECT_NEAR(all.median, 0.2, 1e-7);
    EXPECT_NEAR(all.firstQuartile, 0.1, 1e-7);
    EXPECT_NEAR(all.thirdQuartile, 0.3, 1e-7);
    EXPECT_NEAR(all.max, 0.4, 1e-7);
    EXPECT_EQ(all.pixels, 5u);

    const FlipStats some = flipStatistics(map, {0, 1, 1, 1, 1});  // without 0.4
    EXPECT_NEAR(some.max, 0.3, 1e-7);
    EXPECT_NEAR(some.median, 0.15, 1e-7);
    EXPECT_EQ(some.pixels, 4u);
    EXPECT_EQ(flipStatistics(map, {0, 0, 0, 0, 0}).pixels, 0u);
    EXPECT_THROW(flipStatistics(map, {1, 1}), Error);
}

TEST(Flip, MagmaRunsFromBlackToPaleYellowWithRisingLightness) {
    EXPECT_LT(glm::length(magma(0.0f)), 0.02f);
    EXPECT_NEAR(magma(1.0f).r, 252.0f / 255.0f, 1e-6);
    EXPECT_NEAR(magma(1.0f).b, 191.0f / 255.0f, 1e-6);
    float previous = -1.0f;
    for (int i = 0; i <= 64; ++i) {
        const vec3 c = magma(float(i) / 64.0f);
        const float luma = 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
        EXPECT_GT(luma, previous) << i;
        previous = luma;
    }
    EXPECT_EQ(magma(-1.0f), magma(0.0f));
    EXPECT_EQ(magma(2.0f), magma(1.0f));
}
