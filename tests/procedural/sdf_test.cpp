// Tests procedural/math/sdf.h: distances at points where geometry gives the answer, the HLSL
// fmod repetition, the tetrahedral normal and the sphere-tracing loop.
#include "procedural/math/sdf.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace refray::procedural::math {
namespace {

using glm::dvec2;
using glm::dvec3;
using glm::vec2;
using glm::vec3;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// ---- primitives ---------------------------------------------------------------------------------
TEST(SdfSphere, DistanceToCentreMinusRadius) {
    EXPECT_FLOAT_EQ(sdSphere(vec3(2, 0, 0), 1.0f), 1.0f);
    EXPECT_FLOAT_EQ(sdSphere(vec3(0, 0, 0), 0.5f), -0.5f);
    EXPECT_FLOAT_EQ(sdSphere(vec3(3, 4, 0), 1.0f), 4.0f);
}

TEST(SdfBox, FaceEdgeCornerAndInside) {
    const vec3 b(1, 1, 1);
    EXPECT_FLOAT_EQ(sdBox(vec3(3, 0, 0), b), 2.0f);             // face
    EXPECT_FLOAT_EQ(sdBox(vec3(2, 2, 0), b), std::sqrt(2.0f));  // edge
    EXPECT_FLOAT_EQ(sdBox(vec3(2, 2, 2), b), std::sqrt(3.0f));  // corner
    EXPECT_FLOAT_EQ(sdBox(vec3(0, 0, 0), b), -1.0f);
    EXPECT_FLOAT_EQ(sdBox(vec3(0.5f, 0, 0), vec3(1, 2, 3)), -0.5f);
}

TEST(SdfRoundBox, OutsideAlongAxisAndDiagonal) {
    EXPECT_FLOAT_EQ(udRoundBox(vec3(2, 0, 0), vec3(0.75f), 0.2f), 1.05f);
    // Beyond a corner: distance to the corner of the inner box minus r.
    EXPECT_NEAR(udRoundBox(dvec3(1.75, 1.75, 1.75), dvec3(0.75), 0.2), std::sqrt(3.0) - 0.2, 1e-12);
}

TEST(SdfTorus, RingCentreTubeAndAxis) {
    const vec2 t(0.6f, 0.2f);
    EXPECT_FLOAT_EQ(sdTorus(vec3(0.6f, 0, 0), t), -0.2f);    // on the ring: -tube radius
    EXPECT_FLOAT_EQ(sdTorus(vec3(0, 0, 0), t), 0.4f);        // centre: R - r
    EXPECT_FLOAT_EQ(sdTorus(vec3(0, 0, -0.6f), t), -0.2f);   // the ring lies in the xz plane
    EXPECT_FLOAT_EQ(sdTorus(vec3(0.6f, 0.5f, 0), t), 0.3f);  // above the ring
}

TEST(SdfTorus82, SquareCrossSectionIsAnL8Norm) {
    const dvec2 t(0.75, 0.15);
    EXPECT_NEAR(sdTorus82(dvec3(0.75, 0, 0), t), -0.15, 1e-12);
    EXPECT_NEAR(sdTorus82(dvec3(1.25, 0, 0), t), 0.5 - 0.15, 1e-12);
    // Diagonal of the cross-section: L8(a, a) = a * 2^(1/8).
    EXPECT_NEAR(sdTorus82(dvec3(0.75 + 0.4, 0.4, 0), t), 0.4 * std::pow(2.0, 0.125) - 0.15, 1e-12);
    EXPECT_NEAR(sdTorus82(vec3(0, 0, 1.25f), vec2(0.75f, 0.15f)), 0.35f, 1e-6f);
}

TEST(SdfTorus88, SquareRingAndSquareTube) {
    // On the x axis the L8 ring radius equals |x|.
    EXPECT_NEAR(sdTorus88(dvec3(1.0, 0, 0), dvec2(0.75, 0.15)), 0.25 - 0.15, 1e-12);
}

TEST(SdfCylinder, SideCapRimAndInside) {
    const vec2 h(1.0f, 1.0f);
    EXPECT_FLOAT_EQ(sdCylinder(vec3(2, 0, 0), h), 1.0f);
    EXPECT_FLOAT_EQ(sdCylinder(vec3(0, 3, 0), h), 2.0f);
    EXPECT_FLOAT_EQ(sdCylinder(vec3(0, 0, 2), h), 1.0f);
    EXPECT_FLOAT_EQ(sdCylinder(vec3(2, 2, 0), h), std::sqrt(2.0f));
    EXPECT_FLOAT_EQ(sdCylinder(vec3(0, 0, 0), vec2(0.3f, 2.0f)), -0.3f);
}

TEST(SdfCylinder6, L6RadiusAndCaps) {
    EXPECT_NEAR(sdCylinder6(dvec3(2, 0, 0), dvec2(1, 1)), 1.0, 1e-12);
    EXPECT_NEAR(sdCylinder6(dvec3(0, 3, 0), dvec2(1, 1)), 2.0, 1e-12);
}

TEST(SdfCapsule, DistanceToSegmentMinusRadius) {
    const vec3 a(0, 0, 0);
    const vec3 b(0, 2, 0);
    EXPECT_FLOAT_EQ(sdCapsule(vec3(1, 1, 0), a, b, 0.5f), 0.5f);
    EXPECT_FLOAT_EQ(sdCapsule(vec3(0, 3, 0), a, b, 0.5f), 0.5f);
    EXPECT_FLOAT_EQ(sdCapsule(vec3(0, -2, 0), a, b, 0.5f), 1.5f);
    EXPECT_FLOAT_EQ(sdCapsule(vec3(0, 1, 0), a, b, 0.5f), -0.5f);
}

TEST(SdfTriPrism, FacePlaneDistances) {
    const dvec2 h(1.0, 1.0);  // triangle: base y = -0.5, apex y = 1; length |z| <= 1
    EXPECT_NEAR(sdTriPrism(dvec3(0, -1, 0), h), 0.5, 1e-12);   // below the base
    EXPECT_NEAR(sdTriPrism(dvec3(0, 0, 3), h), 2.0, 1e-12);    // beyond the end cap
    EXPECT_NEAR(sdTriPrism(dvec3(0, 0, 0), h), -0.5, 1e-12);   // centroid: nearest face is the base
    // Outside a sloped face, along its normal (0.866025, 0.5) from the face midpoint
    // (0.4330127, 0.25): the bound equals the true plane distance.
    const double s = 0.3;
    EXPECT_NEAR(sdTriPrism(dvec3(0.4330127 + s * 0.866025, 0.25 + s * 0.5, 0), h), s, 1e-6);
}

TEST(SdfPyramid, BaseSidesAndOctahedron) {
    const dvec3 h(0.894, 0.447, 2.0);  // apex (0,2,0), base |x|,|z| <= 1 at y = 0
    EXPECT_NEAR(sdPyramid(dvec3(0, -1, 0), h), 1.0, 1e-12);   // below the base centre
    EXPECT_NEAR(sdPyramid(dvec3(0, 0.5, 0), h), -0.5, 1e-12); // inside: the base is nearest
    EXPECT_NEAR(sdPyramid(dvec3(0, 2, 0), h), 0.0, 1e-12);    // apex
    EXPECT_NEAR(sdPyramid(dvec3(1, 0, 1), h), 0.0, 1e-12);    // base corner
    EXPECT_NEAR(sdOctahedron(dvec3(0, -2, 0), h), 0.0, 1e-12);  // the lower octahedron tip
}

TEST(SdfOperators, UnionSubtractionIntersection) {
    EXPECT_EQ(opU(1.0f, -2.0f), -2.0f);
    EXPECT_EQ(opI(1.0f, -2.0f), 1.0f);
    EXPECT_EQ(opS(1.0f, -2.0f), 2.0f);
    EXPECT_EQ(opS(-1.0f, 0.5f), -0.5f);
    EXPECT_EQ(opU(kNaN, 0.3f), 0.3f);  // GPU min ignores NaN
    EXPECT_EQ(opI(0.3f, kNaN), 0.3f);
}

TEST(SdfOperators, SmoothBlendsEqualMinMaxFarApartAndDipInBetween) {
    EXPECT_EQ(smin(0.0f, 1.0f, 0.1f), 0.0f);
    EXPECT_EQ(smax(0.0f, 1.0f, 0.1f), 1.0f);
    EXPECT_FLOAT_EQ(opBlendU(0.0f, 0.0f), -0.025f);  // h = 0.5: -k/4
    EXPECT_FLOAT_EQ(opBlendI(0.0f, 0.0f), 0.025f);
}

TEST(SdfOperators, TwistKeepsHlslComponentOrder) {
    // y = 0: no rotation; the result is (x, z, y).
    EXPECT_EQ(opTwist(vec3(1, 0, 2)), vec3(1, 2, 0));
    // 3y = pi/2: (x, z) -> (-z, x).
    const dvec3 q = opTwist(dvec3(1, std::acos(-1.0) / 6, 2));
    EXPECT_NEAR(q.x, -2.0, 1e-12);
    EXPECT_NEAR(q.y, 1.0, 1e-12);
    EXPECT_NEAR(q.z, std::acos(-1.0) / 6, 1e-15);
}

TEST(SdfOperators, RepetitionUsesHlslFmodWithoutNegativeCells) {
    const vec3 c(1.0f);
    const vec3 r = opRep(vec3(2.3f, 0.5f, 7.75f), c);
    EXPECT_NEAR(r.x, -0.2f, 1e-5f);
    EXPECT_NEAR(r.y, 0.0f, 1e-6f);
    EXPECT_NEAR(r.z, 0.25f, 1e-5f);
    // Negative coordinates do not repeat (fmod keeps the dividend's sign, D3D12 H14).
    EXPECT_NEAR(opRep(vec3(-0.3f, -2.3f, 0), c).x, -0.8f, 1e-6f);
    EXPECT_NEAR(opRep(vec3(-0.3f, -2.3f, 0), c).y, -0.8f, 1e-5f);
}

// ---- D3D12 composite primitives ------------------------------------------------------------------
TEST(SdfD3D12, MiniSpheresAtEverySphereCentre) {
    const float cs[4] = {-0.75f, -0.25f, 0.25f, 0.75f};
    for (float x : cs)
        for (float y : cs)
            for (float z : cs) EXPECT_NEAR(d3d12::sdMiniSpheres(vec3(x, y, z)), -0.1625f, 1e-6f);
    // Between spheres along an axis: 0.25 from both centres.
    EXPECT_NEAR(d3d12::sdMiniSpheres(vec3(0.0f, 0.25f, 0.25f)), 0.25f - 0.1625f, 1e-6f);
    // Outside the clipping box.
    EXPECT_NEAR(d3d12::sdMiniSpheres(vec3(0.25f, 0.25f, 1.5f)), 0.5f, 1e-6f);
}

TEST(SdfD3D12, IntersectedRoundCubeShellMidpointOnDiagonal) {
    // On the diagonal at |p| = 1.26 the round box contains the point, and the shell
    // 1.2 <= |p| <= 1.32 is 0.06 away on both sides.
    const double k = 1.26 / std::sqrt(3.0);
    EXPECT_NEAR(d3d12::sdIntersectedRoundCube(dvec3(k, k, k)), -0.06, 1e-12);
    // Inside the inner ball: 1.2 - |p|.
    EXPECT_NEAR(d3d12::sdIntersectedRoundCube(dvec3(0.5, 0, 0)), 0.7, 1e-12);
}

TEST(SdfD3D12, SquareTorusAndTwistedTorusOnTheirRings) {
    EXPECT_NEAR(d3d12::sdSquareTorus(vec3(0.75f, 0, 0)), -0.15f, 1e-6f);
    EXPECT_NEAR(d3d12::sdSquareTorus(vec3(0, 0, -0.75f)), -0.15f, 1e-6f);
    // At y = 0 the twisted torus is a vertical ring in the xy plane: (0.6,0,0) is on its core,
    // (0,0,0.6) is sqrt(0.72) from the core.
    EXPECT_NEAR(d3d12::sdTwistedTorus(dvec3(0.6, 0, 0)), -0.2, 1e-12);
    EXPECT_NEAR(d3d12::sdTwistedTorus(dvec3(0, 0, 0.6)), std::sqrt(0.72) - 0.2, 1e-12);
}

TEST(SdfD3D12, CogEqualsSquareTorusAwayFromSlotsAndIsFiniteOnAxis) {
    EXPECT_NEAR(d3d12::sdCog(vec3(2, 0, 0)), 2.0f - 0.6f - 0.3f, 1e-6f);
    // On the y axis atan2(0,0) = pi/2 (DXC): finite, and the torus term dominates (H15).
    const float onAxis = d3d12::sdCog(vec3(0, 0.5f, 0));
    EXPECT_TRUE(std::isfinite(onAxis));
    EXPECT_NEAR(onAxis, sdTorus82(vec3(0, 0.5f, 0), vec2(0.6f, 0.3f)), 1e-6f);
}

TEST(SdfD3D12, CylinderColumnsExistOnlyForNonNegativeCells) {
    // Column centre (x, z) = (-0.5, -0.5): inside by the column radius.
    EXPECT_NEAR(d3d12::sdCylinderColumns(vec3(-0.5f, 0, -0.5f)), -0.3f, 1e-6f);
    EXPECT_NEAR(d3d12::sdCylinderColumns(vec3(0.5f, 0.5f, 0.5f)), -0.3f, 1e-6f);
    // x + 1 < 0: fmod does not wrap, so no column at x = -1.5; the nearest column is 1 away.
    EXPECT_NEAR(d3d12::sdCylinderColumns(vec3(-1.5f, 0, -0.5f)), 0.7f, 1e-6f);
}

// ---- normal ---------------------------------------------------------------------------------------
TEST(SdfNormal, TetrahedralNormalOfSphereIsRadial) {
    // The tetrahedral estimate carries an O(e) curvature bias on a unit sphere (third moments of
    // the tetrahedron), so the bound is 2e = 1.2e-4.
    const auto sphere = [](const dvec3& p) { return sdSphere(p, 1.0); };
    const dvec3 dirs[3] = {dvec3(1, 0, 0), glm::normalize(dvec3(1, -2, 3)), dvec3(0, 0, -1)};
    for (const dvec3& d : dirs) {
        const dvec3 n = sdCalculateNormal(d, sphere);
        EXPECT_NEAR(n.x, d.x, 1.2e-4);
        EXPECT_NEAR(n.y, d.y, 1.2e-4);
        EXPECT_NEAR(n.z, d.z, 1.2e-4);
        EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
    }
}

TEST(SdfNormal, ConstantOrNaNFieldGivesNaNNormal) {
    const vec3 n = sdCalculateNormal(vec3(0.3f, 0.1f, 0), [](const vec3&) { return 0.25f; });
    EXPECT_TRUE(std::isnan(n.x) && std::isnan(n.y) && std::isnan(n.z));
    const vec3 m = sdCalculateNormal(vec3(0), [](const vec3&) { return kNaN; });
    EXPECT_TRUE(std::isnan(m.x));
}

TEST(SdfNormal, OffsetIsPointFiveSevenSevenThreeTimesOneEMinus4) {
    EXPECT_EQ(tetrahedralOffset<float>(), 0.5773f * 0.0001f);
    EXPECT_NEAR(tetrahedralOffset<double>(), 5.773e-5, 1e-18);
}

// ---- sphere tracing --------------------------------------------------------------------------------
// Closed form: first root of |o + t d - c| = r for unit d.
double sphereEntry(const dvec3& o, const dvec3& d, const dvec3& c, double r) {
    const dvec3 L = o - c;
    const double b = glm::dot(L, d);
    return -b - std::sqrt(b * b - (glm::dot(L, L) - r * r));
}

TEST(SdfSphereTrace, ReachesClosedFormSphereHitWithinThreshold) {
    // Sphere tracing an exact convex SDF never overshoots, and it stops once D <= 1e-4 t; a
    // distance D to the sphere is at most D / cos(theta) along the ray near the hit, theta being
    // the angle between the ray and the true normal. So 0 <= t* - t <= 1e-4 t / cos(theta).
    const dvec3 c(0.2, -0.1, 5.0);
    const double r = 1.0;
    const auto sdf = [&](const auto& p) {
        using T = typename std::decay_t<decltype(p)>::value_type;
        return sdSphere(p - glm::vec<3, T>(c), T(r));
    };
    const dvec3 dirs[3] = {dvec3(0, 0, 1), glm::normalize(dvec3(0.1, 0.05, 1)), glm::normalize(dvec3(-0.12, 0.1, 1))};
    for (const dvec3& d : dirs) {
        const double expected = sphereEntry(dvec3(0), d, c, r);
        const dvec3 n = glm::normalize(d * expected - c);  // outward normal at the true hit
        const double cosTheta = std::abs(glm::dot(d, n));
        {
            const Ray<double> ray{dvec3(0), d};
            const RayExtent<double> extent{0.0, 100.0, true, false};
            const auto res = RaySignedDistancePrimitiveTest(ray, extent, sdf);
            ASSERT_TRUE(res.hit);
            EXPECT_LE(res.thit, expected + 1e-12);
            EXPECT_LE(expected - res.thit, 1e-4 * res.thit / cosTheta);
            EXPECT_NEAR(glm::dot(res.normal, n), 1.0, 1e-3);
        }
        {
            const Ray<float> ray{vec3(0), vec3(d)};
            const RayExtent<float> extent{0.0f, 100.0f, true, false};
            const auto res = RaySignedDistancePrimitiveTest(ray, extent, sdf);
            ASSERT_TRUE(res.hit);
            EXPECT_LE(std::abs(expected - res.thit), 1e-4 * res.thit / cosTheta + 1e-5);
        }
    }
}

TEST(SdfSphereTrace, StepScaleAndThresholdParametersApply) {
    const auto sdf = [](const dvec3& p) { return sdSphere(p - dvec3(0, 0, 5), 1.0); };
    const Ray<double> ray{dvec3(0), dvec3(0, 0, 1)};
    const RayExtent<double> extent{0.0, 100.0, true, false};
    SphereTraceParams<double> half;
    // After k steps t = 4(1 - 0.5^k) and D = 4*0.5^k; the first step i with
    // 0.5^(i-1) <= 1e-4 (1 - 0.5^(i-1)) is i = 15 (0.5^14 = 6.1e-5, 0.5^13 = 1.2e-4).
    half.stepScale = 0.5;
    const auto res = RaySignedDistancePrimitiveTest(ray, extent, sdf, half);
    ASSERT_TRUE(res.hit);
    EXPECT_NEAR(res.thit, 4.0, 4e-4);
    EXPECT_EQ(res.steps, 15u);
}

TEST(SdfSphereTrace, MissStopsAtTCurrentAndRespectsMaxSteps) {
    const auto sdf = [](const dvec3& p) { return sdSphere(p - dvec3(0, 0, 5), 1.0); };
    const Ray<double> ray{dvec3(0), dvec3(0, 1, 0)};
    const RayExtent<double> extent{0.0, 50.0, true, false};
    const auto res = RaySignedDistancePrimitiveTest(ray, extent, sdf);
    EXPECT_FALSE(res.hit);
    SphereTraceParams<double> few;  // half steps need 15 iterations (previous test); allow 3
    few.stepScale = 0.5;
    few.maxSteps = 3;
    const auto res3 = RaySignedDistancePrimitiveTest(Ray<double>{dvec3(0), dvec3(0, 0, 1)}, extent, sdf, few);
    EXPECT_FALSE(res3.hit);
    EXPECT_EQ(res3.steps, 3u);
}

TEST(SdfSphereTrace, HitBeyondTCurrentIsNotReported) {
    const auto sdf = [](const dvec3& p) { return sdSphere(p - dvec3(0, 0, 5), 1.0); };
    const auto res = RaySignedDistancePrimitiveTest(Ray<double>{dvec3(0), dvec3(0, 0, 1)},
                                                    RayExtent<double>{0.0, 3.9, true, false}, sdf);
    EXPECT_FALSE(res.hit);
}

TEST(SdfSphereTrace, RayStartingInsideIsCulledAndStepsBackwards) {
    // From inside, t = 0 is a candidate (D <= 0) but its normal faces along the ray: culled.
    // The march then steps backwards (t < TMin) and never reports (D3D12 H12, Proceduray H13).
    const auto sdf = [](const dvec3& p) { return sdSphere(p - dvec3(0, 0, 5), 1.0); };
    const auto culled = RaySignedDistancePrimitiveTest(Ray<double>{dvec3(0, 0, 5.5), dvec3(0, 0, 1)},
                                                       RayExtent<double>{0.0, 100.0, true, false}, sdf);
    EXPECT_FALSE(culled.hit);
    // Without culling the t = 0 candidate is accepted.
    const auto accepted = RaySignedDistancePrimitiveTest(Ray<double>{dvec3(0, 0, 5.5), dvec3(0, 0, 1)},
                                                         RayExtent<double>{0.0, 100.0, false, false}, sdf);
    ASSERT_TRUE(accepted.hit);
    EXPECT_EQ(accepted.thit, 0.0);
    EXPECT_EQ(accepted.steps, 1u);
}

}  // namespace
}  // namespace refray::procedural::math
