// Tests procedural/math/metaballs.h: the quintic potential, the keyframe animation and the
// 128-sample march against a lone ball whose iso-surface radius is solved here independently.
#include "procedural/math/metaballs.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace refray::procedural::math {
namespace {

using glm::dvec3;
using glm::vec3;

// Radius fraction x = rho/R where 6u^5 - 15u^4 + 10u^3 = 0.25 with u = 1 - x (bisection).
double loneBallIsoRadiusFraction() {
    double lo = 0.0;
    double hi = 1.0;  // potential(u) is increasing in u
    for (int i = 0; i < 200; ++i) {
        const double u = 0.5 * (lo + hi);
        const double f = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
        (f < 0.25 ? lo : hi) = u;
    }
    return 1.0 - 0.5 * (lo + hi);
}

TEST(MetaballPotential, OneAtCentreZeroAtRadiusAndOutside) {
    const Metaball<float> ball{vec3(0.3f, -0.2f, 0.1f), 0.45f};
    float distance = -1;
    EXPECT_NEAR(CalculateMetaballPotential(ball.center, ball, distance), 1.0f, 1e-6f);
    EXPECT_EQ(distance, 0.0f);
    EXPECT_NEAR(CalculateMetaballPotential(ball.center + vec3(0.45f, 0, 0), ball, distance), 0.0f, 1e-6f);
    EXPECT_EQ(CalculateMetaballPotential(ball.center + vec3(0, 0.5f, 0), ball, distance), 0.0f);
    EXPECT_NEAR(distance, 0.5f, 1e-6f);
}

TEST(MetaballPotential, LoneBallIsoSurfaceAtPoint6406R) {
    const double x = loneBallIsoRadiusFraction();
    EXPECT_NEAR(x, 0.6406, 1e-4);  // D3D12 fact sheet §2.5
    const Metaball<double> ball{dvec3(0), 0.55};
    double distance = 0;
    EXPECT_NEAR(CalculateMetaballPotential(dvec3(0, 0, x * 0.55), ball, distance), 0.25, 1e-12);
}

TEST(MetaballAnimation, KeyframesAtT0AndT6AndMidpointAtT3) {
    const auto k0 = InitializeAnimatedMetaballs(0.0f, 12.0f);
    EXPECT_EQ(k0[0].center, vec3(-0.3f, -0.3f, -0.4f));
    EXPECT_EQ(k0[1].center, vec3(0.0f, -0.2f, 0.5f));
    EXPECT_EQ(k0[2].center, vec3(0.4f, 0.4f, 0.4f));
    EXPECT_EQ(k0[0].radius, 0.45f);
    EXPECT_EQ(k0[1].radius, 0.55f);
    EXPECT_EQ(k0[2].radius, 0.45f);
    // s = 1 at T = 6; lerp is a + s(b - a), so keyframe 1 is reached to rounding only.
    const auto k1 = InitializeAnimatedMetaballs(6.0f, 12.0f);
    const vec3 expected1[3] = {vec3(0.3f, -0.3f, 0.0f), vec3(0.0f, 0.4f, 0.5f), vec3(-0.4f, 0.2f, -0.4f)};
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(k1[j].center[i], expected1[j][i], 1e-7f) << j << "," << i;
    const auto mid = InitializeAnimatedMetaballs(3.0, 12.0);
    EXPECT_NEAR(mid[1].center.y, 0.1, 1e-12);
    EXPECT_NEAR(mid[2].center.x, 0.0, 1e-12);
}

TEST(MetaballMarch, LoneBallHitWithinOneStepOfTheIsoSurface) {
    // At T = 0 the line y = -0.3, z = -0.4 passes through ball 0's centre only (ball 1 is 0.906
    // away, ball 2 1.063 away). Bounding span t in [1.25, 2.15]: step 0.9/128.
    const Ray<double> ray{dvec3(-2, -0.3, -0.4), dvec3(1, 0, 0)};
    const auto hit = RayMetaballsIntersectionTest(ray, RayExtent<double>{0, 100, true, false}, 0.0);
    ASSERT_TRUE(hit.hit);
    const double tSurface = 1.7 - loneBallIsoRadiusFraction() * 0.45;
    const double step = 0.9 / 128;
    EXPECT_GE(hit.thit, tSurface);
    EXPECT_LT(hit.thit, tSurface + step);
    EXPECT_NEAR(hit.normal.x, -1.0, 1e-6);
    // The same ray in float.
    const auto hf = RayMetaballsIntersectionTest(Ray<float>{vec3(-2, -0.3f, -0.4f), vec3(1, 0, 0)},
                                                 RayExtent<float>{0, 100, true, false}, 0.0f);
    ASSERT_TRUE(hf.hit);
    EXPECT_NEAR(hf.thit, hit.thit, 1e-5);
}

TEST(MetaballMarch, H8RayMissingEveryBallReportsNothing) {
    const Ray<float> ray{vec3(-2, 0.9f, -0.9f), vec3(1, 0, 0)};
    float tmin = 0, tmax = 0;
    FindIntersectingMetaballs(ray, RayExtent<float>{0, 100, true, false}, tmin, tmax, InitializeAnimatedMetaballs(0.0f, 12.0f));
    EXPECT_TRUE(std::isinf(tmin) && tmin > 0);
    EXPECT_TRUE(std::isinf(tmax) && tmax < 0);
    EXPECT_FALSE(RayMetaballsIntersectionTest(ray, RayExtent<float>{0, 100, true, false}, 0.0f).hit);
}

// RayMetaballsIntersectionTest lets a ray with tmin = +inf leave its loop at once. That is sound only if none of the
// 128 samples the HLSL takes for it can be a candidate: replay them here, for rays that miss every ball in every
// direction class (axis-parallel and zero components make NaN positions), with TMin = +inf too, and for animated
// balls; every sample's potential must stay below the 0.25 threshold (it is 0).
TEST(MetaballMarch, ARayWithAnInfiniteSpanStartSamplesNoPotential) {
    const float inf = std::numeric_limits<float>::infinity();
    int replayed = 0;
    for (int i = 0; i < 400; ++i) {
        const float a = float(i) * 0.7853f, b = float(i % 13) * 0.31f;
        vec3 d(std::cos(a) * std::cos(b), std::sin(b), std::sin(a) * std::cos(b));
        if (i % 5 == 0) d[i % 3] = 0.0f;        // a zero component: 0 * inf is NaN
        if (i % 7 == 0) d = vec3(0, 0, 1) * float(1 - 2 * (i % 2));
        const vec3 o = vec3(std::sin(float(i)), std::cos(float(i) * 1.3f), std::sin(float(i) * 0.7f)) * 3.0f;
        const RayExtent<float> extent{i % 11 == 0 ? inf : 0.0f, i % 11 == 0 ? inf : 100.0f, false, false};
        const Ray<float> ray{o, d};
        const Metaballs<float> blobs = InitializeAnimatedMetaballs(float(i % 12), 12.0f);
        float tmin = 0, tmax = 0;
        FindIntersectingMetaballs(ray, extent, tmin, tmax, blobs);
        if (tmin != inf) continue;
        ++replayed;
        // The HLSL's loop, sample by sample.
        float t = tmin;
        const float minTStep = (tmax - tmin) / 128.0f;
        for (int step = 0; step < 128; ++step) {
            const vec3 position = ray.origin + t * ray.direction;
            EXPECT_FALSE(CalculateMetaballsPotential(position, blobs) >= 0.25f) << "ray " << i << " sample " << step;
            t = t + minTStep;
        }
        EXPECT_FALSE(RayMetaballsIntersectionTest(ray, extent, float(i % 12)).hit) << "ray " << i;
    }
    EXPECT_GT(replayed, 100);
}

TEST(MetaballMarch, SpanIsClippedToTCurrent) {
    const Ray<double> ray{dvec3(-2, -0.3, -0.4), dvec3(1, 0, 0)};
    double tmin = 0, tmax = 0;
    FindIntersectingMetaballs(ray, RayExtent<double>{0, 1.5, true, false}, tmin, tmax, InitializeAnimatedMetaballs(0.0, 12.0));
    EXPECT_NEAR(tmin, 1.25, 1e-12);
    EXPECT_EQ(tmax, 1.5);
    // With TCurrent before the iso-surface the march samples only [1.25, 1.3]: no hit (H10).
    EXPECT_FALSE(RayMetaballsIntersectionTest(ray, RayExtent<double>{0, 1.3, true, false}, 0.0).hit);
}

TEST(MetaballNormal, PointsOutwardFromALoneBall) {
    const Metaballs<double> blobs = {Metaball<double>{dvec3(0), 0.5}, Metaball<double>{dvec3(5, 0, 0), 0.1},
                                     Metaball<double>{dvec3(-5, 0, 0), 0.1}};
    const dvec3 n = CalculateMetaballsNormal(glm::normalize(dvec3(1, 2, -2)) * 0.3, blobs);
    const dvec3 e = glm::normalize(dvec3(1, 2, -2));
    EXPECT_NEAR(glm::dot(n, e), 1.0, 1e-6);
}

}  // namespace
}  // namespace refray::procedural::math
