// Tests procedural/math/analytic.h: ray-sphere and ray-box t and normals in closed form.
#include "procedural/math/analytic.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace refray::procedural::math {
namespace {

using glm::dvec3;
using glm::vec3;

RayExtent<float> cullBack(float tMin = 0.0f, float tCurrent = 10000.0f) { return {tMin, tCurrent, true, false}; }

// ---- quadratic ----------------------------------------------------------------------------------
TEST(AnalyticQuadratic, OrderedRootsTangentAndNoRoots) {
    float x0 = 0, x1 = 0;
    ASSERT_TRUE(SolveQuadraticEqn(1.0f, -3.0f, 2.0f, x0, x1));  // (x-1)(x-2)
    EXPECT_FLOAT_EQ(x0, 1.0f);
    EXPECT_FLOAT_EQ(x1, 2.0f);
    ASSERT_TRUE(SolveQuadraticEqn(2.0f, 2.0f, -4.0f, x0, x1));  // 2(x+2)(x-1)
    EXPECT_FLOAT_EQ(x0, -2.0f);
    EXPECT_FLOAT_EQ(x1, 1.0f);
    ASSERT_TRUE(SolveQuadraticEqn(1.0f, -4.0f, 4.0f, x0, x1));  // double root
    EXPECT_EQ(x0, 2.0f);
    EXPECT_EQ(x1, 2.0f);
    EXPECT_FALSE(SolveQuadraticEqn(1.0f, 0.0f, 1.0f, x0, x1));
}

// ---- one hollow sphere -----------------------------------------------------------------------------
TEST(AnalyticSphere, HeadOnHitGivesDistanceMinusRadiusAndOutwardNormal) {
    float tmax = 0;
    const auto h = RaySphereIntersectionTest(Ray<float>{vec3(0, 0, -5), vec3(0, 0, 1)}, cullBack(), tmax);
    ASSERT_TRUE(h.hit);
    EXPECT_FLOAT_EQ(h.thit, 4.0f);
    EXPECT_FLOAT_EQ(tmax, 6.0f);
    EXPECT_EQ(h.normal, vec3(0, 0, -1));
}

TEST(AnalyticSphere, OffCentreHitMatchesClosedForm) {
    // o = (0.3, 0.4, -5), d = +z, centre (0,0,1), r = 2: t = 6 - sqrt(4 - 0.25).
    double tmax = 0;
    const dvec3 c(0, 0, 1);
    const auto h = RaySphereIntersectionTest(Ray<double>{dvec3(0.3, 0.4, -5), dvec3(0, 0, 1)},
                                             RayExtent<double>{0, 100, true, false}, tmax, c, 2.0);
    ASSERT_TRUE(h.hit);
    const double z = std::sqrt(3.75);
    EXPECT_NEAR(h.thit, 6.0 - z, 1e-12);
    EXPECT_NEAR(tmax, 6.0 + z, 1e-12);
    EXPECT_NEAR(h.normal.x, 0.15, 1e-12);
    EXPECT_NEAR(h.normal.y, 0.2, 1e-12);
    EXPECT_NEAR(h.normal.z, -z / 2, 1e-12);
}

TEST(AnalyticSphere, UnnormalisedDirectionScalesT) {
    float tmax = 0;
    const auto h = RaySphereIntersectionTest(Ray<float>{vec3(0, 0, -5), vec3(0, 0, 2)}, cullBack(), tmax);
    ASSERT_TRUE(h.hit);
    EXPECT_FLOAT_EQ(h.thit, 2.0f);
}

TEST(AnalyticSphere, TangentRayHitsOnce) {
    float tmax = 0;
    const auto h = RaySphereIntersectionTest(Ray<float>{vec3(1, 0, -5), vec3(0, 0, 1)}, cullBack(), tmax);
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.thit, 5.0f);
    EXPECT_EQ(tmax, 5.0f);
    EXPECT_EQ(h.normal, vec3(1, 0, 0));
}

TEST(AnalyticSphere, FromInsideExitIsBackFacingAndCulled) {
    float tmax = 0;
    const Ray<float> ray{vec3(0), vec3(0, 0, 1)};
    EXPECT_FALSE(RaySphereIntersectionTest(ray, cullBack(), tmax).hit);
    const auto h = RaySphereIntersectionTest(ray, RayExtent<float>{0, 100, false, false}, tmax);
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.thit, 1.0f);
    EXPECT_EQ(h.normal, vec3(0, 0, 1));
}

TEST(AnalyticSphere, BehindTheRayOrBeyondTCurrentMisses) {
    float tmax = 0;
    EXPECT_FALSE(RaySphereIntersectionTest(Ray<float>{vec3(0, 0, 5), vec3(0, 0, 1)}, cullBack(), tmax).hit);
    EXPECT_FALSE(RaySphereIntersectionTest(Ray<float>{vec3(0, 0, -5), vec3(0, 0, 1)}, cullBack(0, 3.5f), tmax).hit);
    // TCurrent exactly at the entry: IsAValidHit is inclusive.
    EXPECT_TRUE(RaySphereIntersectionTest(Ray<float>{vec3(0, 0, -5), vec3(0, 0, 1)}, cullBack(0, 4.0f), tmax).hit);
    EXPECT_FALSE(RaySphereIntersectionTest(Ray<float>{vec3(0, 2, -5), vec3(0, 0, 1)}, cullBack(), tmax).hit);
}

TEST(AnalyticSphere, SolidSphereClipsToExtent) {
    float thit = 0, tmax = 0;
    ASSERT_TRUE(RaySolidSphereIntersectionTest(Ray<float>{vec3(0), vec3(0, 0, 1)}, cullBack(0, 0.5f), thit, tmax));
    EXPECT_EQ(thit, 0.0f);   // max(-1, TMin)
    EXPECT_EQ(tmax, 0.5f);   // min(1, TCurrent)
    EXPECT_FALSE(RaySolidSphereIntersectionTest(Ray<float>{vec3(0, 3, 0), vec3(0, 0, 1)}, cullBack(), thit, tmax));
}

// ---- three spheres ------------------------------------------------------------------------------------
TEST(AnalyticSpheres, RayThroughLargestSphereCentre) {
    // Through (-0.3,-0.3,-0.3), r 0.6; the other spheres are > r away from this line.
    const auto h = RaySpheresIntersectionTest(Ray<double>{dvec3(-0.3, -0.3, -5), dvec3(0, 0, 1)},
                                              RayExtent<double>{0, 100, true, false});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.thit, 5.0 - 0.3 - 0.6, 1e-12);
    EXPECT_NEAR(h.normal.z, -1.0, 1e-12);
}

TEST(AnalyticSpheres, ClosestOfOverlappingSpheresWins) {
    // Along x at y = 0.35, z = 0: through sphere 2 (0.35,0.35,0) r 0.15, entry x = 0.2.
    // Sphere 0 (-0.3,-0.3,-0.3) r 0.6: line distance sqrt(0.65^2 + 0.3^2) = 0.716: missed.
    // Sphere 1 (0.1,0.1,0.4) r 0.3: distance sqrt(0.25^2 + 0.4^2) = 0.47 > 0.3: missed.
    const auto h = RaySpheresIntersectionTest(Ray<double>{dvec3(-5, 0.35, 0.0), dvec3(1, 0, 0)},
                                              RayExtent<double>{0, 100, true, false});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.thit, 5.0 + 0.35 - 0.15, 1e-12);
    // Down the z axis at x = y = 0.1: sphere 1's top (z = 0.7) comes before sphere 0.
    const auto g = RaySpheresIntersectionTest(Ray<double>{dvec3(0.1, 0.1, 5), dvec3(0, 0, -1)},
                                              RayExtent<double>{0, 100, true, false});
    ASSERT_TRUE(g.hit);
    EXPECT_NEAR(g.thit, 5.0 - 0.7, 1e-12);
    EXPECT_NEAR(g.normal.z, 1.0, 1e-12);
}

TEST(AnalyticSpheres, HitExactlyAtTCurrentIsRejected) {
    const Ray<float> ray{vec3(-0.3f, -0.3f, -5.0f), vec3(0, 0, 1)};
    const auto first = RaySpheresIntersectionTest(ray, cullBack());
    ASSERT_TRUE(first.hit);
    EXPECT_FALSE(RaySpheresIntersectionTest(ray, cullBack(0, first.thit)).hit);  // strict <, D3D12 I4
}

// ---- box ------------------------------------------------------------------------------------------------
TEST(AnalyticBox, AxisAlignedHitsOnEachFace) {
    struct Case {
        vec3 o, d, n;
    };
    const Case cases[6] = {
        {vec3(-5, 0.3f, 0.2f), vec3(1, 0, 0), vec3(-1, 0, 0)}, {vec3(5, 0.3f, 0.2f), vec3(-1, 0, 0), vec3(1, 0, 0)},
        {vec3(0.1f, -5, 0.2f), vec3(0, 1, 0), vec3(0, -1, 0)}, {vec3(0.1f, 5, 0.2f), vec3(0, -1, 0), vec3(0, 1, 0)},
        {vec3(0.1f, 0.3f, -5), vec3(0, 0, 1), vec3(0, 0, -1)}, {vec3(0.1f, 0.3f, 5), vec3(0, 0, -1), vec3(0, 0, 1)},
    };
    for (const Case& c : cases) {
        const auto h = RayUnitCubeIntersectionTest(Ray<float>{c.o, c.d}, cullBack());
        ASSERT_TRUE(h.hit);
        EXPECT_EQ(h.thit, 4.0f);
        EXPECT_EQ(h.normal, c.n);
    }
}

TEST(AnalyticBox, ObliqueRayEntersThroughTheLaterSlab) {
    // x-slab [2,4], y-slab [1,3]: entry t = 2 at (-1, 0, 0.5) on the -x face.
    const auto h = RayUnitCubeIntersectionTest(Ray<float>{vec3(-3, -2, 0.5f), vec3(1, 1, 0)}, cullBack());
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.thit, 2.0f);
    EXPECT_EQ(h.normal, vec3(-1, 0, 0));
    // A non-unit box.
    const vec3 aabb[2] = {vec3(5, -1, -7), vec3(7, 2, -5)};
    const auto g = RayAABBIntersectionTest(Ray<float>{vec3(0, 1.5f, -6), vec3(2, 0, 0)}, aabb, cullBack());
    ASSERT_TRUE(g.hit);
    EXPECT_EQ(g.thit, 2.5f);
    EXPECT_EQ(g.normal, vec3(-1, 0, 0));
}

TEST(AnalyticBox, ZeroDirectionWithOriginOnSlabPlaneIsInsideWithoutNaN) {
    // d.x = +0 or -0 and o.x exactly on x = +1 or x = -1: HLSL would form 0 * inf there.
    const vec3 box[2] = {vec3(-1), vec3(1)};
    for (float dx : {0.0f, -0.0f}) {
        for (float ox : {1.0f, -1.0f}) {
            float tmin = 0, tmax = 0;
            const Ray<float> ray{vec3(ox, 0.5f, -5), vec3(dx, 0, 1)};
            ASSERT_TRUE(RayAABBIntersectionTest(ray, box, cullBack(), tmin, tmax));
            EXPECT_EQ(tmin, 4.0f);
            EXPECT_EQ(tmax, 6.0f);
            const auto h = RayUnitCubeIntersectionTest(ray, cullBack());
            ASSERT_TRUE(h.hit);
            EXPECT_EQ(h.thit, 4.0f);
            EXPECT_FALSE(std::isnan(h.normal.x) || std::isnan(h.normal.y) || std::isnan(h.normal.z));
            // The hit point (ox, 0.5, -1) touches the -x face when ox = -1 (tested first), else -z.
            EXPECT_EQ(h.normal, ox < 0 ? vec3(-1, 0, 0) : vec3(0, 0, -1));
        }
    }
}

TEST(AnalyticBox, ZeroDirectionOutsideTheSlabMisses) {
    float tmin = 0, tmax = 0;
    const vec3 box[2] = {vec3(-1), vec3(1)};
    EXPECT_FALSE(RayAABBIntersectionTest(Ray<float>{vec3(1.5f, 0, -5), vec3(0, 0, 1)}, box, cullBack(), tmin, tmax));
    EXPECT_FALSE(RayAABBIntersectionTest(Ray<float>{vec3(-1.5f, 0, -5), vec3(-0.0f, 0, 1)}, box, cullBack(), tmin, tmax));
    EXPECT_FALSE(std::isnan(tmin) || std::isnan(tmax));
}

TEST(AnalyticBox, GrazingAlongAFaceHits) {
    const auto h = RayUnitCubeIntersectionTest(Ray<float>{vec3(-5, 1, 0), vec3(1, 0, 0)}, cullBack());
    ASSERT_TRUE(h.hit);
    EXPECT_EQ(h.thit, 4.0f);
    EXPECT_EQ(h.normal, vec3(-1, 0, 0));
}

TEST(AnalyticBox, RayStartingInsideNeverHits) {
    EXPECT_FALSE(RayUnitCubeIntersectionTest(Ray<float>{vec3(0), vec3(0, 0, 1)}, cullBack()).hit);
    EXPECT_FALSE(RayUnitCubeIntersectionTest(Ray<float>{vec3(0), vec3(0, 0, 1)}, RayExtent<float>{0, 100, false, false}).hit);
}

TEST(AnalyticBox, BoxBehindOrBeyondTCurrentMisses) {
    EXPECT_FALSE(RayUnitCubeIntersectionTest(Ray<float>{vec3(0, 0, 5), vec3(0, 0, 1)}, cullBack()).hit);
    EXPECT_FALSE(RayUnitCubeIntersectionTest(Ray<float>{vec3(0, 0, -5), vec3(0, 0, 1)}, cullBack(0, 3.0f)).hit);
}

// ---- isphere ---------------------------------------------------------------------------------------------
TEST(AnalyticIsphere, EntryAndExitOrMinusOne) {
    const glm::vec2 t = isphere(glm::vec4(0, 0, 0, 1.25f), vec3(0, 0, -5), vec3(0, 0, 1));
    EXPECT_EQ(t.x, 3.75f);
    EXPECT_EQ(t.y, 6.25f);
    const glm::vec2 m = isphere(glm::vec4(0, 0, 0, 1.25f), vec3(0, 2, -5), vec3(0, 0, 1));
    EXPECT_EQ(m, glm::vec2(-1, -1));
    const glm::vec2 s = isphere(glm::vec4(1, 0, 0, 1.0f), vec3(1, 0, 0), vec3(0, 1, 0));
    EXPECT_EQ(s, glm::vec2(-1, 1));
}

// ---- float vs double --------------------------------------------------------------------------------------
TEST(AnalyticPrecision, FloatAndDoubleSphereHitsAgreeWithinOneE5) {
    for (int i = 0; i < 20; ++i) {
        const dvec3 o(0.05 * i - 0.5, 0.3 - 0.02 * i, -4.0);
        const dvec3 d = glm::normalize(dvec3(0.01 * i, -0.005 * i, 1.0));
        double tmaxd = 0;
        float tmaxf = 0;
        const auto hd = RaySphereIntersectionTest(Ray<double>{o, d}, RayExtent<double>{0, 100, true, false}, tmaxd);
        const auto hf = RaySphereIntersectionTest(Ray<float>{vec3(o), vec3(d)}, cullBack(0, 100), tmaxf);
        ASSERT_EQ(hd.hit, hf.hit) << i;
        if (hd.hit) {
            EXPECT_NEAR(hf.thit, hd.thit, 1e-5 * hd.thit) << i;
        }
    }
}

}  // namespace
}  // namespace refray::procedural::math
