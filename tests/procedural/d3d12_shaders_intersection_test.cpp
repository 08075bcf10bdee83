// Tests procedural/d3d12/d3d12_shaders.cpp end to end, its intersection shaders through the probe hit groups of
// tiny Device scenes built from the fact sheet (§1.2-1.4): the red box, the analytic spheres, animated metaballs,
// two SDF primitives, and the first hits of §6 in the whole scene. The rig is d3d12_shaders_rig.h.
#include "procedural/d3d12/d3d12_shaders.h"

#include <cmath>
#include <numbers>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "tests/procedural/d3d12_shaders_rig.h"

namespace refray::procedural::d3d12 {
namespace {

using namespace shaders_rig;

// ---- Intersection shaders through the probe hit groups ---------------------------------------------------

// FACE-1: a ray going down meets the plane's front face; one coming from below is back-facing and culled.
TEST(D3D12Shaders, FACE_1_GroundPlaneIsHitFromAboveOnly) {
    D3D12Rig down(true, {});
    down.probeRay = {vec3(0.3f, 5.0f, 0.7f), 0.0f, vec3(0, -1, 0), 10000.0f};
    down.dispatch("RG_Probe", true);
    ASSERT_EQ(down.probe.closestHits, 1);
    EXPECT_NEAR(down.probe.t, 5.0f, 1e-5f);
    EXPECT_EQ(down.probe.hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);

    D3D12Rig up(true, {});
    up.probeRay = {vec3(0.3f, -5.0f, 0.7f), 0.0f, vec3(0, 1, 0), 10000.0f};
    up.dispatch("RG_Probe", true);
    EXPECT_EQ(up.probe.closestHits, 0);
    EXPECT_EQ(up.probe.misses, 1);
}

// The red box (i = 0): world box x ∈ [5, 7], y ∈ [0, 3], z ∈ [-7, -5]; scale (1, 1.5, 1).
TEST(D3D12Shaders, AnalyticBoxReportsItsEntryFaceAndIsHollow) {
    D3D12Rig rig(false, {0});
    rig.probeRay = {vec3(0.0f, 1.5f, -6.0f), 0.0f, vec3(1, 0, 0), 10000.0f};
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 5.0f, 1e-5f);
    EXPECT_EQ(rig.probe.hitKind, 0u);
    expectNear(rig.probe.normal, vec3(-1, 0, 0), 1e-6f, "normal");

    // From above, onto the top face (local +y, world y = 3).
    D3D12Rig top(false, {0});
    top.probeRay = {vec3(6.5f, 10.0f, -5.5f), 0.0f, vec3(0, -1, 0), 10000.0f};
    top.dispatch("RG_Probe", true);
    ASSERT_EQ(top.probe.closestHits, 1);
    EXPECT_NEAR(top.probe.t, 7.0f, 1e-5f);
    expectNear(top.probe.normal, vec3(0, 1, 0), 1e-6f, "normal");

    // §2.3 step 5: a ray starting inside the box never hits it.
    D3D12Rig inside(false, {0});
    inside.probeRay = {vec3(6.0f, 1.5f, -6.0f), 0.0f, vec3(1, 0, 0), 10000.0f};
    inside.dispatch("RG_Probe", true);
    EXPECT_EQ(inside.probe.closestHits, 0);
    EXPECT_EQ(inside.probe.misses, 1);
}

// Sphere A of the Spheres primitive (i = 1): local centre (-0.3)³, r 0.6, scale 1.5 -> world r 0.9. A ray 0.45 off
// its centre meets it at dz = sqrt(0.81 - 0.2025) before the centre, with the normal (0, 0.5, -sqrt(3)/2).
TEST(D3D12Shaders, AnalyticSpheresAtT0AndRotatedByTheAnimation) {
    const float dz = std::sqrt(0.81f - 0.2025f);
    {
        D3D12Rig rig(false, {1}, 0.0f);
        // At T = 0 sphere A is centred at (3.05, 1.05, -2.95) (§2.4).
        rig.probeRay = {vec3(3.05f, 1.5f, -10.0f), 0.0f, vec3(0, 0, 1), 10000.0f};
        rig.dispatch("RG_Probe", true);
        ASSERT_EQ(rig.probe.closestHits, 1);
        EXPECT_NEAR(rig.probe.t, 10.0f - 2.95f - dz, 1e-4f);
        expectNear(rig.probe.normal, vec3(0.0f, 0.5f, -dz / 0.9f), 1e-4f, "normal");
    }
    {
        // At T = π/4 the rotation is -π/2: x' = -z, z' = x, so sphere A's offset (-0.45, -0.45, -0.45) from the box
        // centre (3.5, 1.5, -2.5) becomes (0.45, -0.45, -0.45).
        D3D12Rig rig(false, {1}, float(std::numbers::pi / 4));
        rig.probeRay = {vec3(3.95f, 1.5f, -10.0f), 0.0f, vec3(0, 0, 1), 10000.0f};
        rig.dispatch("RG_Probe", true);
        ASSERT_EQ(rig.probe.closestHits, 1);
        EXPECT_NEAR(rig.probe.t, 10.0f - 2.95f - dz, 1e-4f);
        expectNear(rig.probe.normal, vec3(0.0f, 0.5f, -dz / 0.9f), 1e-4f, "normal");
    }
}

// An independent double-precision metaball field (§2.5) for the keyframe interpolant s.
struct Metaballs {
    dvec3 centre[3];
    double radius[3] = {0.45, 0.55, 0.45};
    explicit Metaballs(double s) {
        const dvec3 k0[3] = {{-0.3, -0.3, -0.4}, {0.0, -0.2, 0.5}, {0.4, 0.4, 0.4}};
        const dvec3 k1[3] = {{0.3, -0.3, 0.0}, {0.0, 0.4, 0.5}, {-0.4, 0.2, -0.4}};
        for (int j = 0; j < 3; ++j) centre[j] = k0[j] + s * (k1[j] - k0[j]);
    }
    double field(dvec3 p) const {
        double sum = 0.0;
        for (int j = 0; j < 3; ++j) {
            const double rho = glm::length(p - centre[j]);
            if (rho > radius[j]) continue;
            const double x = (radius[j] - rho) / radius[j];
            sum += x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
        }
        return sum;
    }
};

// The local ray (0, 0.4, -19/3) + t·(0, 0, 2/3): at T = 0 it passes outside balls 0 and 1 and grazes ball 2 (field
// < 0.25); at T = 6 (s = 1) ball 1 sits on it. The reported t is the first of 128 samples with field >= 0.25 (§2.5),
// so it lies within one step after the true surface, which is found here by bisection. The world ray is made from
// the local one with the primitive's transform at T (θ = -12 rad at T = 6), so t is the same in both.
TEST(D3D12Shaders, MetaballsAnimateWithElapsedTime) {
    const dvec3 o(0.0, 0.4, (-15.0 + 5.5) / 1.5), d(0.0, 0.0, 1.0 / 1.5);
    const auto worldRay = [&](double T) {
        const DMat4 M = localSpaceToBottomLevelAS(2, T);
        return RayDesc{vec3(transform(M, o, 1.0) + dvec3(0, 1, 0)), 0.0f, vec3(transform(M, d, 0.0)), 10000.0f};
    };
    {
        D3D12Rig rig(false, {2}, 0.0f);
        rig.probeRay = worldRay(0.0);
        rig.dispatch("RG_Probe", true);
        EXPECT_EQ(rig.probe.closestHits, 0);
        EXPECT_EQ(rig.probe.misses, 1);
    }
    D3D12Rig rig(false, {2}, 6.0f);
    rig.probeRay = worldRay(6.0);
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);

    const Metaballs balls(1.0);
    // The bounding-sphere span and the step.
    double tmin = std::numeric_limits<double>::infinity(), tmax = -tmin;
    for (int j = 0; j < 3; ++j) {
        const dvec3 L = o - balls.centre[j];
        const double a = glm::dot(d, d), b = 2.0 * glm::dot(d, L), c = glm::dot(L, L) - balls.radius[j] * balls.radius[j];
        const double disc = b * b - 4.0 * a * c;
        if (disc < 0.0) continue;
        tmin = std::min(tmin, std::max((-b - std::sqrt(disc)) / (2.0 * a), 0.0));
        tmax = std::max(tmax, (-b + std::sqrt(disc)) / (2.0 * a));
    }
    const double step = (tmax - tmin) / 128.0;
    double lo = tmin, hi = tmax;  // the first crossing of 0.25 from the entry
    for (double t = tmin; t < tmax; t += step / 16)
        if (balls.field(o + t * d) >= 0.25) {
            hi = t;
            break;
        }
    lo = hi - step / 16;
    for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (balls.field(o + mid * d) >= 0.25 ? hi : lo) = mid;
    }
    EXPECT_GE(rig.probe.t, hi - 1e-4);
    EXPECT_LE(rig.probe.t, hi + step + 1e-4);

    // The normal: minus the field gradient at the reported point, through the forward matrix.
    const dvec3 p = o + double(rig.probe.t) * d;
    const double e = 1e-6;
    const dvec3 g(balls.field(p - dvec3(e, 0, 0)) - balls.field(p + dvec3(e, 0, 0)),
                  balls.field(p - dvec3(0, e, 0)) - balls.field(p + dvec3(0, e, 0)),
                  balls.field(p - dvec3(0, 0, e)) - balls.field(p + dvec3(0, 0, e)));
    expectNear(rig.probe.normal, vec3(glm::normalize(transform(localSpaceToBottomLevelAS(2, 6.0), g, 0.0))), 2e-2f,
               "normal");
}

// MiniSpheres (i = 3, unscaled, box centre (2, 1, -6)): the sphere at local (-0.75, 0.25, 0.25), radius 0.1625, is
// met at local x = -0.9125 by a ray along +x.
TEST(D3D12Shaders, SignedDistanceMiniSpheres) {
    D3D12Rig rig(false, {3});
    rig.probeRay = {vec3(-5.0f, 1.25f, -5.75f), 0.0f, vec3(1, 0, 0), 10000.0f};
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 7.0f - 0.9125f, 1e-3f);
    expectNear(rig.probe.normal, vec3(-1, 0, 0), 1e-3f, "normal");
}

// FractalPyramid (i = 9, scale 3, box centre (4, 3, 4) in the world): in the pyramid's frame q = local + (0, 1, 0)
// the point (0.975, 0.05, 0.9375) lies on the +x face 2x + y = 2 and inside the corner sub-pyramid of every
// iteration, so a ray along -x meets the outer face there (world (6.925, 0.15, 6.8125)), normal (2, 1, 0)/√5.
TEST(D3D12Shaders, SignedDistanceFractalPyramid) {
    D3D12Rig rig(false, {9});
    rig.probeRay = {vec3(10.0f, 0.15f, 6.8125f), 0.0f, vec3(-1, 0, 0), 10000.0f};
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 10.0f - 6.925f, 2e-3f);
    expectNear(rig.probe.normal, vec3(2.0f, 1.0f, 0.0f) / std::sqrt(5.0f), 1e-2f, "normal");
}

// §6: first hits of the whole scene at T = 0, 1280×720.
TEST(D3D12Shaders, WholeSceneFirstHitsMatchTheCheckValues) {
    const Camera camera = sampleCamera(1280, 720);
    struct Check {
        uvec2 pixel;
        uint32_t instance, geometry;
        float t, tolerance;
    };
    const Check checks[] = {
        {{640, 360}, 1, 2, 10.146f, 0.03f},  // metaballs (sampled: one step ≈ 0.02)
        {{1000, 300}, 1, 0, 18.787f, 2e-3f},  // the red box's -x face
        {{640, 100}, 1, 9, 21.98f, 0.01f},   // fractal pyramid
        {{200, 500}, 0, 0, 13.277f, 2e-3f},  // ground
        {{640, 700}, 0, 0, 8.475f, 2e-3f},   // ground
    };
    for (const Check& check : checks) {
        D3D12Rig rig(true, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
        vec3 origin, direction;
        GenerateCameraRay(check.pixel, uvec2(1280, 720), vec3(camera.position), camera.projectionToWorld, origin,
                          direction);
        rig.probeRay = {origin, 0.0f, direction, 10000.0f};
        rig.dispatch("RG_Probe", true);
        ASSERT_EQ(rig.probe.closestHits, 1) << check.pixel.x << "," << check.pixel.y;
        EXPECT_EQ(rig.probe.instanceIndex, check.instance) << check.pixel.x << "," << check.pixel.y;
        EXPECT_EQ(rig.probe.geometryIndex, check.geometry) << check.pixel.x << "," << check.pixel.y;
        EXPECT_NEAR(rig.probe.t, check.t, check.tolerance) << check.pixel.x << "," << check.pixel.y;
        if (check.pixel == uvec2(1000, 300)) {
            expectNear(rig.probe.position, vec3(5.000f, 1.277f, -5.160f), 2e-3f, "position");
            expectNear(rig.probe.normal, vec3(-1, 0, 0), 1e-6f, "normal");
        }
    }
}

}  // namespace
}  // namespace refray::procedural::d3d12
