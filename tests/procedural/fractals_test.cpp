// Tests procedural/math/fractals.h: the Proceduray fact-sheet values (H1, H4, H5, H8, H14, T0/T1),
// Mandelbulb and Julia symmetries, the Pac-man SDF geometry and the D3D12 fractal pyramid.
#include "procedural/math/fractals.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>

#include <gtest/gtest.h>

namespace refray::procedural::math {
namespace {

using glm::dvec3;
using glm::vec3;
using glm::vec4;

// T1 of the Proceduray fact sheet §1.9: float bits 0x417D7CD8.
float canonicalT1() {
    const std::uint32_t bits = 0x417D7CD8u;
    float t = 0;
    std::memcpy(&t, &bits, sizeof t);
    return t;
}

dvec3 rotateY(const dvec3& p, double phi) {
    return dvec3(p.x * std::cos(phi) + p.z * std::sin(phi), p.y, -p.x * std::sin(phi) + p.z * std::cos(phi));
}

// ---- time constants ---------------------------------------------------------------------------------
TEST(ProcedurayTime, CanonicalT1IsFifteenPointEightFourAndSquaresTo251) {
    const float T1 = canonicalT1();
    EXPECT_FLOAT_EQ(T1, 15.8429795f);
    EXPECT_EQ(T1 * T1, 251.0f);
}

TEST(MandelbulbIterationCount, FactSheetValuesAtT0AndT1) {
    EXPECT_EQ(mandelbulb::MandelbulbIterationCount(0.0f, 3), 4);
    EXPECT_EQ(mandelbulb::MandelbulbIterationCount(canonicalT1(), 3), 129);
}

TEST(MandelbulbIterationCount, TriangleWaveOverTime) {
    // 0.5*20^2 + 3 = 203 -> 256 - 203 = 53 -> 54.   0.5*24^2 + 3 = 291 % 256 = 35 -> 36.
    EXPECT_EQ(mandelbulb::MandelbulbIterationCount(20.0f, 3), 54);
    EXPECT_EQ(mandelbulb::MandelbulbIterationCount(24.0f, 3), 36);
    EXPECT_EQ(mandelbulb::MandelbulbIterationCount(0.0f, 0), 1);
    EXPECT_EQ(mandelbulb::MandelbulbIterationCount(2.0f, 1), 4);  // 0.5*4 + 1 = 3
}

TEST(PacmanMouth, TauAtT0IsZeroAndAtT1Is176Over300) {
    EXPECT_EQ(pacman::PacmanMouthInterpolant(0.0f), 0.0f);
    EXPECT_EQ(pacman::PacmanMouthInterpolant(canonicalT1()), 176.0f / 300.0f);
    // 200.5*2 = 401 > 300 -> 600 - 401 = 199.
    EXPECT_EQ(pacman::PacmanMouthInterpolant(2.0f), 199.0f / 300.0f);
}

// ---- Mandelbulb DE ---------------------------------------------------------------------------------
TEST(MandelbulbDistanceEstimator, H5OnTheYAxisMatchesFactSheet) {
    vec4 resColor;
    const float de = mandelbulb::mdist(vec3(0.0f, 0.7f, 0.0f), resColor);
    EXPECT_NEAR(de, 0.00162148f, 1e-8f);
    EXPECT_NEAR(resColor.x, 1.14192f, 1e-5f);
    EXPECT_NEAR(resColor.y, 0.7f, 1e-7f);
    EXPECT_EQ(resColor.z, 0.0f);
    EXPECT_NEAR(resColor.w, 0.49f, 1e-7f);
}

TEST(MandelbulbDistanceEstimator, H4AtTheOriginIsNaN) {
    vec4 resColor;
    EXPECT_TRUE(std::isnan(mandelbulb::mdist(vec3(0.0f), resColor)));
    EXPECT_TRUE(std::isnan(mandelbulb::mdist(dvec3(0.0))));
}

TEST(MandelbulbDistanceEstimator, PositiveWellOutside) {
    const dvec3 pts[5] = {dvec3(2, 0.1, 0.2), dvec3(0, 2, 0), dvec3(-1.5, -1.5, 1.5), dvec3(0, 0, 3), dvec3(1.3, 0, 0)};
    for (const dvec3& p : pts) {
        const double de = mandelbulb::mdist(p);
        EXPECT_GT(de, 0.0) << p.x << "," << p.y << "," << p.z;
        // A distance estimate never exceeds the distance to the origin, which is in the set.
        EXPECT_LT(de, glm::length(p));
    }
}

TEST(MandelbulbDistanceEstimator, SevenFoldSymmetryAboutYAxis) {
    // Power 8: rotating w by phi rotates w^8 by 8*phi, so the map commutes with rotations where
    // 8*phi = phi (mod 2 pi): phi = 2 pi k / 7. (The 8-fold rotation is NOT a symmetry.)
    const dvec3 pts[3] = {dvec3(0.7, 0.3, 0.5), dvec3(-0.4, -0.6, 0.9), dvec3(1.1, 0.05, -0.2)};
    for (const dvec3& p : pts) {
        glm::dvec4 c0;
        const double d0 = mandelbulb::mdist(p, c0);
        for (int k = 1; k < 7; ++k) {
            glm::dvec4 ck;
            const double dk = mandelbulb::mdist(rotateY(p, 2 * std::numbers::pi * k / 7), ck);
            EXPECT_NEAR(dk, d0, 1e-9 * (1 + std::abs(d0))) << "k=" << k;
            EXPECT_NEAR(ck.x, c0.x, 1e-9 * c0.x);
            EXPECT_NEAR(ck.y, c0.y, 1e-9);  // trap.y and trap.w are rotation invariant
            EXPECT_NEAR(ck.w, c0.w, 1e-9);
        }
    }
    // The eighth-turn gives a different value at the first point.
    EXPECT_GT(std::abs(mandelbulb::mdist(rotateY(pts[0], std::numbers::pi / 4)) - mandelbulb::mdist(pts[0])), 1e-4);
}

TEST(MandelbulbDistanceEstimator, MirrorSymmetricInX) {
    const dvec3 pts[3] = {dvec3(0.7, 0.3, 0.5), dvec3(-0.4, -0.6, 0.9), dvec3(1.1, 0.05, -0.2)};
    for (const dvec3& p : pts)
        EXPECT_NEAR(mandelbulb::mdist(dvec3(-p.x, p.y, p.z)), mandelbulb::mdist(p), 1e-12 * (1 + std::abs(mandelbulb::mdist(p))));
}

TEST(MandelbulbDistanceEstimator, FloatAgreesWithDoubleAwayFromHazards) {
    // Bound: 1e-4 relative + 1e-6 absolute (float rounding through 4 iterations of r^8).
    const dvec3 pts[4] = {dvec3(0.7, 0.3, 0.5), dvec3(2, 0.1, 0.2), dvec3(-1.0, 0.4, 0.3), dvec3(0.2, -1.1, 0.1)};
    for (const dvec3& p : pts) {
        const double d = mandelbulb::mdist(p);
        const float f = mandelbulb::mdist(vec3(p));
        EXPECT_NEAR(f, d, 1e-4 * std::abs(d) + 1e-6);
    }
}

// ---- Mandelbulb march ---------------------------------------------------------------------------------
TEST(MandelbulbMarch, H14UnconvergedMarchFromInsideTheBoundIsAHit) {
    // World o = (35,-45,100), d = (0,0,-1) at T0 -> local o = (0.875, 0.125, -0.375), 4 steps.
    const auto hit = mandelbulb::MandelbulbDistance(vec3(0.875f, 0.125f, -0.375f), vec3(0, 0, -1),
                                                    mandelbulb::MandelbulbIterationCount(0.0f, 3));
    ASSERT_TRUE(hit.hit);
    EXPECT_NEAR(hit.thit, 0.02999f, 1e-5f);
}

TEST(MandelbulbMarch, MissesWhenTheBoundingSphereIsMissed) {
    EXPECT_FALSE(mandelbulb::MandelbulbDistance(vec3(0, 2, -3), vec3(0, 0, 1), 129).hit);
    EXPECT_FALSE(mandelbulb::MandelbulbDistance(vec3(0, 0, 3), vec3(0, 0, 1), 129).hit);  // sphere behind
}

TEST(MandelbulbMarch, H4RayThroughTheCentreFromTheCentreMisses) {
    const auto hit = mandelbulb::MandelbulbDistance(vec3(0), vec3(0, 0, 1), 129);
    EXPECT_FALSE(hit.hit);  // NaN distance -> NaN t -> "t < dis.y" is false
}

TEST(MandelbulbMarch, ConvergedHitIsOnTheEstimatorZeroSetInsideTheBound) {
    const auto hit = mandelbulb::MandelbulbDistance(dvec3(0.05, 0.1, -1.4), dvec3(0, 0, 1), 129);
    ASSERT_TRUE(hit.hit);
    EXPECT_GT(hit.thit, 1.4 - 1.25);
    EXPECT_LT(mandelbulb::mdist(hit.pos), 1e-4 * hit.thit);
    EXPECT_NEAR(glm::length(hit.normal), 1.0, 1e-9);
    EXPECT_LT(hit.normal.z, 0.0);  // faces the incoming ray
}

// ---- Quaternion Julia -------------------------------------------------------------------------------
TEST(JuliaConstants, KcAndKPrecis) {
    const vec4 c = julia::kc<float>();
    EXPECT_FLOAT_EQ(c.x, -0.0909091f);
    EXPECT_FLOAT_EQ(c.y, 0.2727273f);
    EXPECT_FLOAT_EQ(c.z, 0.6818182f);
    EXPECT_FLOAT_EQ(c.w, -0.2727273f);
    EXPECT_EQ(julia::kPrecis<float>, 0.00025f);
}

glm::dvec4 hamilton(const glm::dvec4& a, const glm::dvec4& b) {
    return glm::dvec4(a.x * b.x - a.y * b.y - a.z * b.z - a.w * b.w, a.x * b.y + a.y * b.x + a.z * b.w - a.w * b.z,
                      a.x * b.z - a.y * b.w + a.z * b.x + a.w * b.y, a.x * b.w + a.y * b.z - a.z * b.y + a.w * b.x);
}

TEST(JuliaQuaternion, SquareAndCubeEqualHamiltonProducts) {
    const glm::dvec4 q(0.3, -0.7, 1.1, 0.4);
    const glm::dvec4 q2 = hamilton(q, q);
    const glm::dvec4 q3 = hamilton(q2, q);
    const glm::dvec4 s = julia::qSquare_float4(q);
    const glm::dvec4 c = julia::qCube_float4(q);
    for (int i = 0; i < 4; ++i) {
        EXPECT_NEAR(s[i], q2[i], 1e-14);
        EXPECT_NEAR(c[i], q3[i], 1e-14);
    }
    EXPECT_NEAR(julia::qLength2_float4(q), 0.09 + 0.49 + 1.21 + 0.16, 1e-15);
}

TEST(JuliaDistanceEstimator, H8AtTheOriginIsInfinityAfter22Iterations) {
    const glm::vec2 r = julia::jdist(vec3(0.0f), julia::kc<float>(), 200);
    EXPECT_TRUE(std::isinf(r.x) && r.x > 0);
    EXPECT_EQ(r.y, 22.0f);
}

TEST(JuliaDistanceEstimator, MirrorSymmetryAcrossThePlaneOfCsImaginaryPart) {
    // z -> z^3 + c commutes with orthogonal maps of the imaginary part that fix Im(c). The
    // reflection of (y, z) across the line through (6, 15) keeps the w = 0 slice and fixes Im(c).
    const glm::dvec2 u = glm::normalize(glm::dvec2(6, 15));
    const dvec3 pts[3] = {dvec3(0.3, 0.5, -0.2), dvec3(0.1, -0.4, 0.6), dvec3(-0.5, 0.2, 0.3)};
    for (const dvec3& p : pts) {
        const glm::dvec2 v(p.y, p.z);
        const glm::dvec2 w = 2.0 * glm::dot(u, v) * u - v;
        const glm::dvec2 a = julia::jdist(p, julia::kc<double>(), 200);
        const glm::dvec2 b = julia::jdist(dvec3(p.x, w.x, w.y), julia::kc<double>(), 200);
        EXPECT_EQ(a.y, b.y);
        EXPECT_NEAR(a.x, b.x, 1e-9 * a.x);
    }
}

TEST(JuliaRaycast, PlanesRejectRaysLeavingTheSlab) {
    // Above the upper plane y = 0 going up, below y = -1.1 going down: (-2, 0).
    EXPECT_EQ(julia::raycast(vec3(0, 0.5f, 0), vec3(0, 1, 0)), glm::vec2(-2, 0));
    EXPECT_EQ(julia::raycast(vec3(0, -1.5f, 0), vec3(0, -1, 0)), glm::vec2(-2, 0));
    // Inside the slab but leaving the radius-1.2 sphere.
    EXPECT_EQ(julia::raycast(vec3(0, -0.5f, 2), vec3(0, 0, 1)), glm::vec2(-2, 0));
}

TEST(JuliaRaycast, H10HorizontalRayFollowsIeeeComparisons) {
    // rd.y = 0: tpS = +-inf (and NaN when ro.y = 0); nothing traps and the planes do not reject.
    const glm::vec2 a = julia::raycast(vec3(0, -0.5f, 2), vec3(0, 0, -1));
    EXPECT_NE(a.x, -2.0f);
    const glm::vec2 b = julia::raycast(vec3(-2, 0.0f, 0.3f), vec3(1, 0, 0));
    EXPECT_NE(b.x, -2.0f);
    EXPECT_FALSE(std::isnan(b.x));
}

TEST(JuliaRaycast, HitLiesWithinKPrecisOfTheSetAndAfterOutsideSamples) {
    const dvec3 ro(0, -0.5, -1.15);
    const dvec3 rd(0, 0, 1);
    const glm::dvec2 r = julia::raycast(ro, rd);
    ASSERT_GE(r.x, 0.0);
    EXPECT_LT(julia::jdist(ro + r.x * rd, julia::kc<double>(), 200).x, 0.00025);
    EXPECT_GT(julia::jdist(ro + (r.x - 0.05) * rd, julia::kc<double>(), 200).x, 0.0);
    // The float march lands on the same surface within one 0.2 step.
    const glm::vec2 rf = julia::raycast(vec3(ro), vec3(rd));
    EXPECT_NEAR(rf.x, r.x, 1e-3);
}

TEST(JuliaDistance, SpaceChangeScalesByPointFourAndShiftsY) {
    // Local ro = (0, 1.25, -2.875) -> q-space (0, -0.5, -1.15): the ray of the previous test.
    const auto hit = julia::JuliaDistance(dvec3(0, 1.25, -2.875), dvec3(0, 0, 1));
    ASSERT_TRUE(hit.hit);
    const glm::dvec2 direct = julia::raycast(dvec3(0, -0.5, -1.15), dvec3(0, 0, 1));
    EXPECT_NEAR(hit.resT.x, direct.x, 1e-12);
    EXPECT_EQ(hit.resT.y, direct.y);
    EXPECT_NEAR(glm::length(hit.normal), 1.0, 1e-9);
    EXPECT_LT(hit.normal.z, 0.0);
    EXPECT_FALSE(julia::JuliaDistance(dvec3(0, 1.25, 5.0), dvec3(0, 0, 1)).hit);
}

// ---- Pac-man ------------------------------------------------------------------------------------------
TEST(PacmanSdf, BackOfTheHeadIsTheHeadSphere) {
    for (float tau : {0.0f, 0.5f, 1.0f}) EXPECT_NEAR(pacman::pacMan(vec3(0, 0, -0.8f), tau), 0.3f, 1e-6f);
    EXPECT_NEAR(pacman::pacMan(vec3(-0.7f, 0, 0), 0.5f), 0.2f, 1e-6f);
}

TEST(PacmanSdf, MouthApexOnTheAxisAtHalfMinusK) {
    // k = 0.05 + 0.4 tau; the wedge apex is at (0, 0, 0.5 - k).
    for (float tau : {0.0f, 0.5f, 1.0f}) {
        const float k = 0.05f + 0.4f * tau;
        EXPECT_NEAR(pacman::pacMan(vec3(0, 0, 0.5f - k), tau), 0.0f, 1e-6f) << tau;
        EXPECT_LT(pacman::pacMan(vec3(0, 0, 0.5f - k - 0.05f), tau), 0.0f) << tau;  // solid behind it
        EXPECT_GT(pacman::pacMan(vec3(0, 0, 0.5f - k + 0.02f), tau), 0.0f) << tau;  // open in front
    }
}

TEST(PacmanSdf, EyeCentresAreOneDentRadiusOutside) {
    EXPECT_NEAR(pacman::pacMan(vec3(0.25f, -0.365f, 0.225f), 0.0f), 0.075f, 1e-6f);
    EXPECT_NEAR(pacman::pacMan(vec3(-0.25f, -0.365f, 0.225f), 0.0f), 0.075f, 1e-6f);
}

TEST(PacmanTrace, H1RayHitsTheHeadAtTheClosedFormT) {
    // World o = (35,-45,50), d = (0,0,-1) at T0 -> local o = (0,-0.2,1): t = 1 - sqrt(0.25 - 0.04).
    auto sdf = [](const vec3& p) { return pacman::pacMan(p, pacman::PacmanMouthInterpolant(0.0f)); };
    const auto r = RaySignedDistancePrimitiveTest(Ray<float>{vec3(0, -0.2f, 1), vec3(0, 0, -1)},
                                                  RayExtent<float>{0, 10000, true, false}, sdf);
    ASSERT_TRUE(r.hit);
    EXPECT_NEAR(r.thit, 1.0f - std::sqrt(0.21f), 1e-4f * r.thit);
    EXPECT_NEAR(r.thit, 0.54173f, 1e-5f);  // fact sheet H1
    EXPECT_NEAR(r.normal.x, 0.0f, 1e-3f);
    EXPECT_NEAR(r.normal.y, -0.4f, 1e-3f);
    EXPECT_NEAR(r.normal.z, 0.9165f, 1e-3f);
    EXPECT_EQ(pacman::PacmanHitColor(r.normal, r.position), vec4(1, 1, 1, 1));  // head: white
}

TEST(PacmanTrace, HitColourIsBlackWhereTheNormalIsNotRadial) {
    EXPECT_EQ(pacman::PacmanHitColor(vec3(0, 0, 1), vec3(0.3f, 0, 0.4f)), vec4(0, 0, 0, 1));
    EXPECT_EQ(pacman::PacmanHitColor(vec3(0.6f, 0, 0.8f), vec3(0.3f, 0, 0.4f)), vec4(1, 1, 1, 1));
    EXPECT_EQ(pacman::PacmanHitColor(vec3(-0.6f, 0, -0.8f), vec3(0.3f, 0, 0.4f)), vec4(1, 1, 1, 1));
}

// ---- D3D12 fractal pyramid ----------------------------------------------------------------------------
TEST(FractalPyramid, ApexAndBaseCornersAreFixedPointsOnTheSurface) {
    const vec3 h(0.894f, 0.447f, 2.0f);
    EXPECT_EQ(d3d12::sdFractalPyramid(vec3(0, 2, 0), h), 0.0f);
    EXPECT_EQ(d3d12::sdFractalPyramid(vec3(1, 0, 1), h), 0.0f);
    EXPECT_EQ(d3d12::sdFractalPyramid(vec3(-1, 0, -1), h), 0.0f);
}

TEST(FractalPyramid, BelowTheBaseCentreIsTheDistanceToTheBase) {
    const vec3 h(0.894f, 0.447f, 2.0f);
    EXPECT_NEAR(d3d12::sdFractalPyramid(vec3(0, -1, 0), h), 1.0f, 1e-6f);
    EXPECT_NEAR(d3d12::sdFractalPyramid(dvec3(0, -0.5, 0), dvec3(0.894, 0.447, 2.0)), 0.5, 1e-12);
}

TEST(FractalPyramid, DispatcherShiftsBaseToLocalMinusOne) {
    using d3d12::SignedDistancePrimitive;
    EXPECT_EQ(d3d12::GetDistanceFromSignedDistancePrimitive(vec3(0, 1, 0), SignedDistancePrimitive::FractalPyramid), 0.0f);
    EXPECT_NEAR(d3d12::GetDistanceFromSignedDistancePrimitive(vec3(0, -2, 0), SignedDistancePrimitive::FractalPyramid), 1.0f, 1e-6f);
    EXPECT_NEAR(d3d12::GetDistanceFromSignedDistancePrimitive(vec3(0.75f, 0, 0), SignedDistancePrimitive::SquareTorus), -0.15f, 1e-6f);
    EXPECT_EQ(d3d12::GetDistanceFromSignedDistancePrimitive(vec3(0.5f), static_cast<SignedDistancePrimitive>(9)), 0.0f);
}

}  // namespace
}  // namespace refray::procedural::math
