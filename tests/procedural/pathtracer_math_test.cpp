// The path tracer's pure math (procedural/pathtracer/pt_math.h): densities integrate to one, samplers agree with
// their densities, the RNG is deterministic and in [0, 1), NEE, BSDF sampling and their MIS combination estimate
// the same direct light, and Russian roulette keeps the expectation. Monte Carlo checks use fixed seeds and bounds
// of several standard errors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <vector>

#include "procedural/pathtracer/pt_math.h"

namespace refray::procedural::pathtracer {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// Mean and standard error of a running sum.
struct Accumulator {
    double sum = 0.0, sumSquares = 0.0;
    uint64_t n = 0;
    void add(double x) {
        sum += x;
        sumSquares += x * x;
        ++n;
    }
    double mean() const { return sum / double(n); }
    double standardError() const {
        const double m = mean();
        return std::sqrt(std::max(0.0, sumSquares / double(n) - m * m) / double(n));
    }
};

// A uniform direction on the unit sphere (density 1 / 4pi).
template <typename T>
tvec3<T> uniformSphere(PathRng& rng) {
    const T z = T(1) - T(2) * nextUniform<T>(rng);
    const T r = std::sqrt(std::max(T(0), T(1) - z * z));
    const T phi = T(2) * kPi<T> * nextUniform<T>(rng);
    return tvec3<T>(r * std::cos(phi), r * std::sin(phi), z);
}

// ---- Random numbers -------------------------------------------------------------------------------------------

TEST(PathTracerMath, RngIsDeterministicAndKeyedByEveryInput) {
    PathRng a = makePathRng(3, 5, 7, 11), b = makePathRng(3, 5, 7, 11);
    for (int i = 0; i < 100; ++i) ASSERT_EQ(nextUint(a), nextUint(b));
    PathRng fresh = makePathRng(3, 5, 7, 11);
    const uint32_t reference = nextUint(fresh);
    std::set<uint32_t> firsts = {reference};
    for (const PathRng& other : {makePathRng(4, 5, 7, 11), makePathRng(3, 6, 7, 11), makePathRng(3, 5, 8, 11),
                                 makePathRng(3, 5, 7, 12), makePathRng(5, 3, 7, 11)}) {
        PathRng copy = other;
        firsts.insert(nextUint(copy));
    }
    EXPECT_EQ(firsts.size(), 6u) << "each key component must change the stream";
}

TEST(PathTracerMath, RngIsUniformInHalfOpenUnitInterval) {
    constexpr int kBins = 16, kSamples = 160000;
    std::array<int, kBins> bins{};
    Accumulator mean;
    for (uint32_t pixel = 0; pixel < 400; ++pixel) {
        PathRng rng = makePathRng(pixel % 20, pixel / 20, 0, 1);
        for (int i = 0; i < kSamples / 400; ++i) {
            const float u = nextUniform(rng);
            ASSERT_GE(u, 0.0f);
            ASSERT_LT(u, 1.0f);
            ++bins[std::min(kBins - 1, int(u * kBins))];
            mean.add(u);
        }
    }
    EXPECT_NEAR(mean.mean(), 0.5, 4.0 * mean.standardError());
    // Chi-square with 15 degrees of freedom: the 0.999 quantile is 37.7.
    double chi2 = 0.0;
    const double expected = double(kSamples) / kBins;
    for (int b : bins) chi2 += (b - expected) * (b - expected) / expected;
    EXPECT_LT(chi2, 37.7);
    // The largest value nextUniform can return, (2^24 - 1) / 2^24, is below 1 in float.
    EXPECT_LT(float(0xFFFFFFFFu >> 8) * float(1.0 / 16777216.0), 1.0f);
}

// ---- Frames ---------------------------------------------------------------------------------------------------

TEST(PathTracerMath, OrthonormalBasisIsRightHandedAndOrthonormal) {
    PathRng rng = makePathRng(0, 0, 0, 2);
    std::vector<vec3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}};
    for (int i = 0; i < 1000; ++i) normals.push_back(uniformSphere<float>(rng));
    for (const vec3& n : normals) {
        vec3 t, b;
        orthonormalBasis(n, t, b);
        EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::length(b), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(t, n), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(b, n), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(t, b), 0.0f, 1e-5f);
        EXPECT_GT(glm::dot(glm::cross(t, b), n), 0.999f);
    }
}

// ---- Densities integrate to one (uniform sphere directions, fixed seed) ------------------------------------------

TEST(PathTracerMath, CosineHemispherePdfIntegratesToOne) {
    PathRng rng = makePathRng(1, 2, 3, 4);
    Accumulator integral;
    for (int i = 0; i < 200000; ++i) integral.add(4.0 * kPiD * cosineHemispherePdf(uniformSphere<double>(rng).z));
    EXPECT_NEAR(integral.mean(), 1.0, 4.0 * integral.standardError());
    EXPECT_LT(integral.standardError(), 0.005);
}

TEST(PathTracerMath, PhongLobePdfIntegratesToOne) {
    for (double exponent : {0.0, 1.0, 10.0, 50.0}) {
        PathRng rng = makePathRng(1, 2, 3, uint32_t(exponent));
        Accumulator integral;
        for (int i = 0; i < 400000; ++i)
            integral.add(4.0 * kPiD * phongLobePdf(uniformSphere<double>(rng).z, exponent));
        EXPECT_NEAR(integral.mean(), 1.0, 4.0 * integral.standardError()) << "exponent " << exponent;
        EXPECT_LT(integral.standardError(), 0.02) << "exponent " << exponent;
    }
}

TEST(PathTracerMath, MaterialPdfIntegratesToOne) {
    const SurfaceBsdf<double> bsdf = makeSurfaceBsdf(dvec3(0.5, 0.4, 0.3), dvec3(0.3, 0.3, 0.3), 20.0);
    const dvec3 n(0, 0, 1), wo = glm::normalize(dvec3(0.5, 0.2, 0.8));
    PathRng rng = makePathRng(9, 9, 9, 9);
    Accumulator integral;
    for (int i = 0; i < 400000; ++i) integral.add(4.0 * kPiD * bsdfPdf(bsdf, n, wo, uniformSphere<double>(rng)));
    EXPECT_NEAR(integral.mean(), 1.0, 4.0 * integral.standardError());
}

TEST(PathTracerMath, TriangleAreaPdfIntegratesToOneOverTheTriangle) {
    // Uniform points of the parallelogram v0 + s e1 + t e2; the triangle is s + t <= 1.
    const dvec3 v0(1, 2, 3), v1(4, 2.5, 3), v2(1.5, 5, 4);
    const double area = triangleArea(v0, v1, v2);
    EXPECT_NEAR(area, 0.5 * glm::length(glm::cross(v1 - v0, v2 - v0)), 1e-12);
    const double parallelogram = 2.0 * area;
    PathRng rng = makePathRng(0, 1, 0, 1);
    Accumulator integral;
    for (int i = 0; i < 200000; ++i) {
        const double s = nextUniform<double>(rng), t = nextUniform<double>(rng);
        integral.add(s + t <= 1.0 ? triangleAreaPdf(area) * parallelogram : 0.0);
    }
    EXPECT_NEAR(integral.mean(), 1.0, 4.0 * integral.standardError());
}

// ---- Samplers agree with their densities -------------------------------------------------------------------------

// Sample counts in bins of cos(theta) against the integral of the density over each bin.
template <class Sample, class BinProbability>
void expectHistogramMatches(Sample sample, BinProbability probability, const char* what) {
    constexpr int kBins = 10, kSamples = 100000;
    std::array<int, kBins> bins{};
    PathRng rng = makePathRng(7, 7, 7, 7);
    for (int i = 0; i < kSamples; ++i) {
        const double c = sample(rng);
        ASSERT_GT(c, 0.0) << what;
        ASSERT_LE(c, 1.0 + 1e-6) << what;
        ++bins[std::min(kBins - 1, int(c * kBins))];
    }
    for (int b = 0; b < kBins; ++b) {
        const double p = probability(double(b) / kBins, double(b + 1) / kBins);
        const double expected = p * kSamples, sigma = std::sqrt(kSamples * p * (1.0 - p));
        EXPECT_NEAR(bins[b], expected, 5.0 * sigma + 1.0) << what << " bin " << b;
    }
}

TEST(PathTracerMath, CosineHemisphereSamplesFollowTheirPdf) {
    // P(cos theta in [a, b]) = b^2 - a^2 for density cos/pi; every sample is unit and above the surface.
    expectHistogramMatches(
        [](PathRng& rng) {
            const dvec3 d = sampleCosineHemisphere(nextUniform<double>(rng), nextUniform<double>(rng));
            EXPECT_NEAR(glm::length(d), 1.0, 1e-9);
            return d.z;
        },
        [](double a, double b) { return b * b - a * a; }, "cosine");
}

TEST(PathTracerMath, PhongLobeSamplesFollowTheirPdf) {
    for (double n : {1.0, 20.0, 300.0}) {
        // P(cos alpha in [a, b]) = b^(n+1) - a^(n+1).
        expectHistogramMatches(
            [n](PathRng& rng) {
                const dvec3 d = samplePhongLobe(nextUniform<double>(rng), nextUniform<double>(rng), n);
                EXPECT_NEAR(glm::length(d), 1.0, 1e-9);
                return d.z;
            },
            [n](double a, double b) { return std::pow(b, n + 1.0) - std::pow(a, n + 1.0); }, "phong");
    }
}

TEST(PathTracerMath, BsdfSamplingEstimatesTheReflectedFraction) {
    // E[weight] = integral of f cos over the hemisphere, computed independently with uniform hemisphere directions.
    const SurfaceBsdf<double> bsdf = makeSurfaceBsdf(dvec3(0.5, 0.3, 0.2), dvec3(0.2, 0.3, 0.4), 30.0);
    const dvec3 n = glm::normalize(dvec3(0.1, -0.2, 1.0));
    const dvec3 wo = glm::normalize(dvec3(0.6, 0.1, 0.5));
    PathRng rng = makePathRng(1, 1, 1, 1);
    Accumulator sampled, uniform;
    for (int i = 0; i < 400000; ++i) {
        const BsdfSample<double> s =
            sampleBsdf(bsdf, n, wo, nextUniform<double>(rng), nextUniform<double>(rng), nextUniform<double>(rng));
        if (s.pdf > 0.0) {
            EXPECT_NEAR(s.pdf, bsdfPdf(bsdf, n, wo, s.wi), 1e-9 * s.pdf);
        }
        sampled.add(s.weight.y);
        dvec3 d = uniformSphere<double>(rng);
        if (glm::dot(d, n) < 0.0) d = -d;
        uniform.add(evalBsdf(bsdf, n, wo, d).y * glm::dot(d, n) * 2.0 * kPiD);
    }
    const double bound = 4.0 * std::hypot(sampled.standardError(), uniform.standardError());
    EXPECT_NEAR(sampled.mean(), uniform.mean(), bound);
}

TEST(PathTracerMath, MaterialNeverReflectsMoreThanItReceives) {
    // Kd + Ks > 1 is scaled down; the Phong lobe reflects at most 1 (exactly 1 at normal incidence).
    const SurfaceBsdf<double> bsdf = makeSurfaceBsdf(dvec3(0.72, 0.45, 0.2), dvec3(0.6, 0.5, 0.4), 120.0);
    EXPECT_NEAR(bsdf.diffuse.x + bsdf.specular.x, 1.0, 1e-12);
    const dvec3 n(0, 0, 1);
    for (double angle : {0.0, 0.5, 1.0, 1.4}) {
        const dvec3 wo(std::sin(angle), 0.0, std::cos(angle));
        PathRng rng = makePathRng(uint32_t(angle * 10), 0, 0, 5);
        Accumulator albedo, lobe;
        for (int i = 0; i < 100000; ++i) {
            const BsdfSample<double> s =
                sampleBsdf(bsdf, n, wo, nextUniform<double>(rng), nextUniform<double>(rng), nextUniform<double>(rng));
            albedo.add(s.weight.x);
            const dvec3 d = fromLocal(samplePhongLobe(nextUniform<double>(rng), nextUniform<double>(rng), 120.0),
                                      mirror(wo, n));
            const double cosAlpha = glm::dot(d, mirror(wo, n));
            lobe.add(d.z > 0.0 ? phongLobeBrdf(cosAlpha, 120.0) * d.z / phongLobePdf(cosAlpha, 120.0) : 0.0);
        }
        EXPECT_LE(albedo.mean(), 1.0 + 4.0 * albedo.standardError()) << "angle " << angle;
        EXPECT_LE(lobe.mean(), 1.0 + 4.0 * lobe.standardError()) << "angle " << angle;
        if (angle == 0.0) {
            EXPECT_NEAR(lobe.mean(), 1.0, 0.01);
        }
    }
}

// ---- Triangles --------------------------------------------------------------------------------------------------

TEST(PathTracerMath, TriangleSamplesLieInsideAndAreUniform) {
    const vec3 v0(-1, 0, 2), v1(3, 1, 2), v2(0, 4, 5);
    const vec3 normal = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    const double area = triangleArea(v0, v1, v2);
    // The medial subdivision: four triangles of a quarter of the area each.
    const vec3 m01 = 0.5f * (v0 + v1), m12 = 0.5f * (v1 + v2), m20 = 0.5f * (v2 + v0);
    const std::array<std::array<vec3, 3>, 4> quarters = {
        {{v0, m01, m20}, {m01, v1, m12}, {m20, m12, v2}, {m01, m12, m20}}};
    const auto barycentrics = [](vec3 p, vec3 a, vec3 b, vec3 c) {
        const vec3 n = glm::cross(b - a, c - a);
        const float inv = 1.0f / glm::dot(n, n);
        const float wa = glm::dot(glm::cross(c - b, p - b), n) * inv, wb = glm::dot(glm::cross(a - c, p - c), n) * inv;
        return vec3(wa, wb, 1.0f - wa - wb);
    };
    std::array<int, 4> counts{};
    constexpr int kSamples = 40000;
    PathRng rng = makePathRng(2, 3, 4, 5);
    for (int i = 0; i < kSamples; ++i) {
        const vec3 p = sampleTriangleUniform(v0, v1, v2, nextUniform(rng), nextUniform(rng));
        EXPECT_NEAR(glm::dot(p - v0, normal), 0.0f, 1e-5f);
        const vec3 b = barycentrics(p, v0, v1, v2);
        ASSERT_GE(b.x, -1e-5f);
        ASSERT_GE(b.y, -1e-5f);
        ASSERT_GE(b.z, -1e-5f);
        for (int q = 0; q < 4; ++q) {
            const vec3 bq = barycentrics(p, quarters[q][0], quarters[q][1], quarters[q][2]);
            if (bq.x >= 0 && bq.y >= 0 && bq.z >= 0) {
                ++counts[q];
                break;
            }
        }
    }
    const double sigma = std::sqrt(kSamples * 0.25 * 0.75);
    for (int c : counts) EXPECT_NEAR(c, 0.25 * kSamples, 5.0 * sigma);
    EXPECT_NEAR(triangleAreaPdf(area) * area, 1.0, 1e-12);
}

// ---- Next-event estimation and MIS ---------------------------------------------------------------------------------

// The solid angle of a triangle seen from the origin (Van Oosterom and Strackee 1983).
double solidAngle(dvec3 a, dvec3 b, dvec3 c) {
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double numerator = std::abs(glm::dot(a, glm::cross(b, c)));
    const double denominator = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
    return 2.0 * std::atan2(numerator, denominator);
}

TEST(PathTracerMath, SolidAnglePdfOfAreaSamplesIntegratesToOne) {
    // Sampling by area and converting with distance^2 / cos: E[1 / pdf_omega] is the solid angle of the triangle.
    const dvec3 v0(-0.5, 2.0, 0.3), v1(1.0, 2.5, -0.2), v2(0.2, 1.8, 1.4);
    const dvec3 lightNormal = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    const double area = triangleArea(v0, v1, v2);
    PathRng rng = makePathRng(5, 5, 5, 5);
    Accumulator estimate;
    for (int i = 0; i < 200000; ++i) {
        const dvec3 y = sampleTriangleUniform(v0, v1, v2, nextUniform<double>(rng), nextUniform<double>(rng));
        const double distance = glm::length(y);
        const double pdf = areaToSolidAnglePdf(triangleAreaPdf(area), distance, glm::dot(lightNormal, -y / distance));
        estimate.add(1.0 / pdf);
    }
    EXPECT_NEAR(estimate.mean(), solidAngle(v0, v1, v2), 4.0 * estimate.standardError());
}

TEST(PathTracerMath, PowerHeuristicWeightsSumToOne) {
    for (double a : {0.0, 1e-3, 0.5, 2.0, 100.0})
        for (double b : {1e-3, 0.5, 2.0, 100.0}) EXPECT_NEAR(powerHeuristic(a, b) + powerHeuristic(b, a), 1.0, 1e-12);
    EXPECT_EQ(powerHeuristic(0.0, 0.0), 0.0);
    EXPECT_EQ(powerHeuristic(1.0, 0.0), 1.0);
}

// Direct light at the origin (normal +z, a Lambert + Phong material) from one emitting triangle, estimated by
// NEE alone, BSDF sampling alone and their power-heuristic combination: all three must agree with the irradiance
// from Lambert's polygon formula for the diffuse part of the material.
std::optional<dvec3> hitTriangle(dvec3 d, dvec3 v0, dvec3 v1, dvec3 v2) {
    // Moller-Trumbore from the origin.
    const dvec3 e1 = v1 - v0, e2 = v2 - v0, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12) return std::nullopt;
    const dvec3 s = -v0;
    const double u = glm::dot(s, p) / det;
    const dvec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) / det, t = glm::dot(e2, q) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 0.0) return std::nullopt;
    return t * d;
}

TEST(PathTracerMath, NextEventEstimationBsdfSamplingAndMisAgree) {
    // The light faces down towards the origin: cross(v1 - v0, v2 - v0) points to -z.
    const dvec3 v0(-0.4, -0.3, 1.0), v1(0.2, 0.9, 1.2), v2(0.9, -0.2, 0.8);
    const dvec3 lightNormal = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    ASSERT_LT(lightNormal.z, 0.0);
    const double area = triangleArea(v0, v1, v2), emission = 3.0;
    const dvec3 n(0, 0, 1), wo = glm::normalize(dvec3(-0.3, 0.2, 1.0));
    const SurfaceBsdf<double> diffuse = makeSurfaceBsdf(dvec3(0.6), dvec3(0.0), 0.0);
    const SurfaceBsdf<double> glossy = makeSurfaceBsdf(dvec3(0.3), dvec3(0.4), 15.0);

    // Lambert: E = Le * sum over edges of theta_i * (n . unit(cross(p_i, p_i+1))) / 2.
    const std::array<dvec3, 3> corners = {v0, v1, v2};
    double formFactorSum = 0.0;
    for (int i = 0; i < 3; ++i) {
        const dvec3 a = glm::normalize(corners[i]), b = glm::normalize(corners[(i + 1) % 3]);
        formFactorSum += std::acos(glm::dot(a, b)) * glm::dot(n, glm::normalize(glm::cross(a, b)));
    }
    const double irradiance = emission * 0.5 * std::abs(formFactorSum);
    const double diffuseExpected = 0.6 / kPiD * irradiance;

    for (const SurfaceBsdf<double>* bsdf : {&diffuse, &glossy}) {
        PathRng rng = makePathRng(3, 1, 4, 1);
        Accumulator nee, bsdfOnly, mis;
        for (int i = 0; i < 200000; ++i) {
            // NEE (one light, so the selection probability is 1).
            const dvec3 y = sampleTriangleUniform(v0, v1, v2, nextUniform<double>(rng), nextUniform<double>(rng));
            const double distance = glm::length(y);
            const dvec3 wi = y / distance;
            const double cosLight = -glm::dot(lightNormal, wi);
            const double lightPdf = areaToSolidAnglePdf(triangleAreaPdf(area), distance, cosLight);
            double neeValue = 0.0, neeWeighted = 0.0;
            if (cosLight > 0.0 && wi.z > 0.0) {
                neeValue = evalBsdf(*bsdf, n, wo, wi).x * wi.z * emission / lightPdf;
                neeWeighted = neeValue * powerHeuristic(lightPdf, bsdfPdf(*bsdf, n, wo, wi));
            }
            // BSDF sampling.
            const BsdfSample<double> s = sampleBsdf(*bsdf, n, wo, nextUniform<double>(rng), nextUniform<double>(rng),
                                                    nextUniform<double>(rng));
            double bsdfValue = 0.0, bsdfWeighted = 0.0;
            if (s.weight.x > 0.0) {
                if (const auto hit = hitTriangle(s.wi, v0, v1, v2)) {
                    const double cosAtLight = -glm::dot(lightNormal, s.wi);
                    if (cosAtLight > 0.0) {
                        bsdfValue = s.weight.x * emission;
                        const double pdfLight =
                            areaToSolidAnglePdf(triangleAreaPdf(area), glm::length(*hit), cosAtLight);
                        bsdfWeighted = bsdfValue * powerHeuristic(s.pdf, pdfLight);
                    }
                }
            }
            nee.add(neeValue);
            bsdfOnly.add(bsdfValue);
            mis.add(neeWeighted + bsdfWeighted);
        }
        const double reference = nee.mean();
        EXPECT_NEAR(bsdfOnly.mean(), reference, 4.0 * std::hypot(bsdfOnly.standardError(), nee.standardError()));
        EXPECT_NEAR(mis.mean(), reference, 4.0 * std::hypot(mis.standardError(), nee.standardError()));
        if (bsdf == &diffuse) {
            EXPECT_NEAR(nee.mean(), diffuseExpected, 4.0 * nee.standardError());
            EXPECT_NEAR(mis.mean(), diffuseExpected, 4.0 * mis.standardError());
        }
    }
}

// ---- Russian roulette -------------------------------------------------------------------------------------------

TEST(PathTracerMath, RussianRouletteSurvivalFollowsTheRule) {
    EXPECT_FLOAT_EQ(russianRouletteSurvival(vec3(0.2f, 0.5f, 0.1f)), 0.5f);
    EXPECT_FLOAT_EQ(russianRouletteSurvival(vec3(3.0f, 0.5f, 0.1f)), 0.95f);
    vec3 dead(0.0f);
    EXPECT_FALSE(russianRoulette(dead, 0.0f));
    vec3 t(0.5f, 0.25f, 0.1f);
    EXPECT_TRUE(russianRoulette(t, 0.49f));
    EXPECT_FLOAT_EQ(t.x, 1.0f);
    vec3 u(0.5f, 0.25f, 0.1f);
    EXPECT_FALSE(russianRoulette(u, 0.5f));
}

TEST(PathTracerMath, RussianRouletteKeepsTheExpectation) {
    // One step: E[survivor throughput] = throughput.
    PathRng rng = makePathRng(8, 8, 8, 8);
    for (const dvec3& start : {dvec3(0.3, 0.1, 0.05), dvec3(0.9, 0.6, 0.2), dvec3(2.0, 1.0, 0.5)}) {
        Accumulator red, blue;
        for (int i = 0; i < 200000; ++i) {
            dvec3 t = start;
            if (!russianRoulette(t, nextUniform<double>(rng))) t = dvec3(0.0);
            red.add(t.x);
            blue.add(t.z);
        }
        EXPECT_NEAR(red.mean(), start.x, 4.0 * red.standardError() + 1e-12);
        EXPECT_NEAR(blue.mean(), start.z, 4.0 * blue.standardError() + 1e-12);
    }
    // A whole path: emission 1 at every vertex, albedo a, roulette from bounce 3 on, no bounce limit; the
    // expectation is 1 / (1 - a) as without roulette.
    const double a = 0.6;
    Accumulator path;
    for (int i = 0; i < 200000; ++i) {
        double radiance = 0.0;
        dvec3 throughput(1.0);
        for (uint32_t bounce = 0;; ++bounce) {
            radiance += throughput.x;
            throughput *= a;
            if (bounce >= kRussianRouletteStartBounce && !russianRoulette(throughput, nextUniform<double>(rng))) break;
            if (bounce > 10000) break;
        }
        path.add(radiance);
    }
    EXPECT_NEAR(path.mean(), 1.0 / (1.0 - a), 4.0 * path.standardError());
}

}  // namespace
}  // namespace refray::procedural::pathtracer
