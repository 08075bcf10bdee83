// The SDF, metaballs and analytic intersection tests over lanes (T = Lanes<float, W>, W = 16 and 8, one ray per lane) against the
// scalar float code, ray by ray: lane i of every result (hit flag, t, normal, position, step count, out-parameters)
// must be bit for bit what T = float gives for ray i, whatever the other lanes hold (procedural/math/lanes.h).
#ifndef REFRAY_LANES_TEST_WIDTH
#define REFRAY_LANES_TEST_WIDTH 16
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "procedural/accuracy.h"
#include "procedural/math/analytic.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/ray.h"
#include "procedural/math/sdf.h"

namespace refray::procedural::math {
namespace {

constexpr int W = REFRAY_LANES_TEST_WIDTH;  // tests/procedural/CMakeLists.txt: 16 (kMaxLanes) and 8 (the ports')
using L = Lanes<float, W>;
using LMask = LaneMask<L>;

// ---- Seeded inputs ------------------------------------------------------------------------------------------------
struct Rng {
    uint64_t s;
    uint64_t next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float uni(float a, float b) { return a + (b - a) * float(next() >> 40) / float(1 << 24); }
    glm::vec3 vec(float a, float b) { return glm::vec3(uni(a, b), uni(a, b), uni(a, b)); }
};

// One ray of a test: origin, direction, extent, cull flags, and a per-ray parameter (time or step scale).
struct RayIn {
    glm::vec3 o{0.0f}, d{1.0f, 0.0f, 0.0f};
    float tMin = 0.0f, tCurrent = 0.0f;
    bool cullBack = false, cullFront = false;
    float param = 0.0f;
};

// Rays aimed into [-targetSize, targetSize]^3 from outside, from inside, in random directions (mostly missing), with an
// axis-parallel component, unnormalised, and grazing the unit sphere and cube; random [tMin, tCurrent] and flags.
RayIn makeRay(Rng& rng, int i, float paramLo, float paramHi, float targetSize = 1.2f) {
    RayIn r;
    r.o = rng.vec(-3.0f, 3.0f);
    const glm::vec3 target = rng.vec(-targetSize, targetSize);
    switch (i % 7) {
        case 0: r.d = target - r.o; break;                                  // aimed
        case 1: r.o = rng.vec(-0.8f, 0.8f); r.d = target - r.o; break;      // from inside
        case 2: r.d = rng.vec(-1.0f, 1.0f); break;                          // random: mostly missing
        case 3: r.d = target - r.o; r.d[int(rng.next() % 3)] = 0.0f; break;  // axis-parallel component
        case 4: r.d = (target - r.o) * rng.uni(0.3f, 3.0f); break;           // unnormalised
        case 5: {                                                           // grazing the unit cube/sphere
            const float side = (rng.next() % 2) ? 1.0f : -1.0f;
            r.o = glm::vec3(-3.0f, rng.uni(-1.01f, 1.01f), side * rng.uni(0.98f, 1.02f));
            r.d = glm::vec3(1.0f, rng.uni(-1e-3f, 1e-3f), 0.0f);
            break;
        }
        default: r.d = target - r.o + rng.vec(-0.5f, 0.5f); break;
    }
    if (i % 7 != 4 && glm::dot(r.d, r.d) > 0.0f) r.d = glm::normalize(r.d);
    switch (rng.next() % 4) {
        case 0: r.tMin = 0.0f; r.tCurrent = 10000.0f; break;
        case 1: r.tMin = rng.uni(0.0f, 2.0f); r.tCurrent = rng.uni(2.0f, 8.0f); break;
        case 2: r.tMin = rng.uni(0.0f, 1.0f); r.tCurrent = rng.uni(0.0f, 3.0f); break;
        default: r.tMin = 0.0f; r.tCurrent = rng.uni(1.0f, 6.0f); break;
    }
    r.cullBack = rng.next() % 3 == 0;
    r.cullFront = rng.next() % 4 == 0;
    r.param = rng.uni(paramLo, paramHi);
    return r;
}

std::vector<RayIn> makeRays(uint64_t seed, int n, float paramLo, float paramHi, float targetSize = 1.2f) {
    Rng rng{seed};
    std::vector<RayIn> rays;
    for (int i = 0; i < n; ++i) rays.push_back(makeRay(rng, i, paramLo, paramHi, targetSize));
    // Shuffle so that every group of W mixes the kinds (and so hits and misses).
    for (int i = n - 1; i > 0; --i) std::swap(rays[i], rays[rng.next() % uint64_t(i + 1)]);
    return rays;
}

// A ray in lanes that holds no real ray: NaN, infinite or huge values, random flags.
RayIn garbageRay(Rng& rng, int i) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    RayIn r;
    switch (i % 4) {
        case 0: r.o = glm::vec3(nan); r.d = glm::vec3(nan); r.tMin = nan; r.tCurrent = nan; break;
        case 1: r.o = glm::vec3(1e30f, -1e30f, 3e38f); r.d = glm::vec3(0.0f); r.tMin = -inf; r.tCurrent = inf; break;
        case 2: r.o = glm::vec3(0.0f); r.d = glm::vec3(nan, 1.0f, inf); r.tMin = 0.0f; r.tCurrent = inf; break;
        default:  // never hits, runs every step
            r.o = glm::vec3(50.0f, 50.0f, 50.0f); r.d = glm::vec3(1e-30f, 0.0f, 0.0f); r.tMin = 0.0f;
            r.tCurrent = 1e30f; break;
    }
    r.cullBack = rng.next() % 2;
    r.cullFront = rng.next() % 2;
    r.param = (i % 2) ? nan : 1e30f;
    return r;
}

// ---- Lanes <-> rays -----------------------------------------------------------------------------------------------
Ray<float> scalarRay(const RayIn& in) { return {in.o, in.d}; }
RayExtent<float> scalarExtent(const RayIn& in) { return {in.tMin, in.tCurrent, in.cullBack, in.cullFront}; }

Ray<L> laneRay(const RayIn* in) {
    Ray<L> r;
    for (int i = 0; i < W; ++i) {
        setLane(r.origin, i, in[i].o);
        setLane(r.direction, i, in[i].d);
    }
    return r;
}
RayExtent<L> laneExtent(const RayIn* in) {
    RayExtent<L> e;
    for (int i = 0; i < W; ++i) {
        setLane(e.tMin, i, in[i].tMin);
        setLane(e.tCurrent, i, in[i].tCurrent);
        setLane(e.cullBackFacing, i, in[i].cullBack);
        setLane(e.cullFrontFacing, i, in[i].cullFront);
    }
    return e;
}
L laneParam(const RayIn* in) { return L::generate([&](int i) { return in[i].param; }); }

uint32_t bits(float x) { return std::bit_cast<uint32_t>(x); }

// Bitwise comparison of lane i with the scalar result; `what` names the field.
void expectSame(float scalar, const L& lanes, int i, const std::string& what) {
    EXPECT_EQ(bits(scalar), bits(lane(lanes, i))) << what << " lane " << i << ": " << scalar << " vs " << lane(lanes, i);
}
void expectSame(const glm::vec3& scalar, const vec3<L>& lanes, int i, const std::string& what) {
    for (int k = 0; k < 3; ++k) expectSame(scalar[k], lanes[k], i, what + "[" + std::to_string(k) + "]");
}
void expectSame(const glm::vec2& scalar, const vec2<L>& lanes, int i, const std::string& what) {
    for (int k = 0; k < 2; ++k) expectSame(scalar[k], lanes[k], i, what + "[" + std::to_string(k) + "]");
}
void expectSame(bool scalar, const LMask& lanes, int i, const std::string& what) {
    EXPECT_EQ(scalar, lane(lanes, i)) << what << " lane " << i;
}
void expectSame(uint32_t scalar, const LaneUint<L>& lanes, int i, const std::string& what) {
    EXPECT_EQ(scalar, lane(lanes, i)) << what << " lane " << i;
}

// Counts hits and misses, and the groups that hold both.
struct HitStats {
    int hits = 0, misses = 0, mixedGroups = 0, groups = 0;
    void group(const LMask& hit, const std::vector<int>& real) {
        int h = 0;
        for (int i : real) h += lane(hit, i);
        hits += h;
        misses += int(real.size()) - h;
        mixedGroups += (h > 0 && h < int(real.size()));
        ++groups;
    }
    void expectMixed(const char* name) const {
        EXPECT_GT(hits, 0) << name;
        EXPECT_GT(misses, 0) << name;
        // A third: groups of 8 mix less often than groups of 16 (TwistedTorus: 11 of 29 groups of 8).
        EXPECT_GE(mixedGroups * 3, groups) << name << ": too few groups mix hits and misses";
    }
};

// Runs `check(group, realLanes)` over the rays in groups of W, then over groups where only a few lanes hold real
// rays and the others garbage.
template <class Check>
void forGroups(const std::vector<RayIn>& rays, uint64_t seed, Check check) {
    std::vector<int> all;
    for (int i = 0; i < W; ++i) all.push_back(i);
    for (size_t g = 0; g + W <= rays.size(); g += W) check(&rays[g], all);

    Rng rng{seed ^ 0xABCDEFull};
    const std::vector<std::vector<int>> sparse = {{0}, {3, 9 % W}, {0, 5, 11 % W}, {W - 1}, {1, 2, 14 % W}};
    for (size_t s = 0; s < sparse.size(); ++s) {
        RayIn group[W];
        for (int i = 0; i < W; ++i) group[i] = garbageRay(rng, i);
        for (size_t k = 0; k < sparse[s].size(); ++k) group[sparse[s][k]] = rays[(s * 7 + k * 3) % rays.size()];
        check(group, sparse[s]);
    }
}

// ---- The tests ----------------------------------------------------------------------------------------------------
// The six D3D12 SDFs (the switch cases of GetDistanceFromSignedDistancePrimitive) as sphere-tracing callbacks.
using L8 = Lanes<float, 8>;
struct NamedSdf {
    const char* name;
    float (*scalar)(const vec3<float>&);
    L (*lanes)(const vec3<L>&);
    L8 (*lanes8)(const vec3<L8>&);  // a queue wider than 8 lanes finishes its last rays over 8
    // Over L, or over 8 lanes: what a march queue calls.
    auto queued() const {
        return [this](const auto& p) {
            if constexpr (std::is_same_v<std::decay_t<decltype(p)>, vec3<L>>) return lanes(p);
            else return lanes8(p);
        };
    }
};
// Each SDF over float, over the test's lanes and over 8.
#define REFRAY_SDF(name, fn) {name, fn<float>, fn<L>, fn<L8>}
const NamedSdf kSdfs[] = {
    REFRAY_SDF("MiniSpheres", d3d12::sdMiniSpheres),
    REFRAY_SDF("IntersectedRoundCube", d3d12::sdIntersectedRoundCube),
    REFRAY_SDF("SquareTorus", d3d12::sdSquareTorus),
    REFRAY_SDF("TwistedTorus", d3d12::sdTwistedTorus),
    REFRAY_SDF("Cog", d3d12::sdCog),
    REFRAY_SDF("CylinderColumns", d3d12::sdCylinderColumns),
};
#undef REFRAY_SDF

TEST(LanesSdf, SphereTracingMatchesScalarPerLane) {
    const std::vector<RayIn> rays = makeRays(0x5DF, 16 * 12, 0.5f, 1.0f);  // param: the material's stepScale
    Accuracy coarse;
    coarse.stepsFactor = 0.05;  // 26 steps: some rays run out of steps
    coarse.thresholdFactor = 4.0;
    coarse.normalEpsilonFactor = 3.0;
    for (const NamedSdf& sdf : kSdfs) {
        for (const Accuracy& accuracy : {Accuracy{}, coarse}) {
            HitStats stats;
            forGroups(rays, 1, [&](const RayIn* group, const std::vector<int>& real) {
                const SphereTraceResult<L> lanes =
                    RaySignedDistancePrimitiveTest(laneRay(group), laneExtent(group), sdf.lanes,
                                                   sphereTraceParams(accuracy, laneParam(group)));
                for (int i : real) {
                    const SphereTraceResult<float> s =
                        RaySignedDistancePrimitiveTest(scalarRay(group[i]), scalarExtent(group[i]), sdf.scalar,
                                                       sphereTraceParams(accuracy, group[i].param));
                    const std::string what = std::string(sdf.name) + (accuracy.isDefault() ? "" : " coarse");
                    expectSame(s.hit, lanes.hit, i, what + " hit");
                    expectSame(s.thit, lanes.thit, i, what + " thit");
                    expectSame(s.normal, lanes.normal, i, what + " normal");
                    expectSame(s.position, lanes.position, i, what + " position");
                    expectSame(s.steps, lanes.steps, i, what + " steps");
                }
                stats.group(lanes.hit, real);
            });
            stats.expectMixed(sdf.name);
        }
    }
}

TEST(LanesSdf, SphereTracingQueuesGiveEachRayItsScalarResult) {
    // RaySignedDistancePrimitiveTestQueue refills its W lanes from a queue of up to 32 rays (over 16 lanes, a queue of
    // more than 16 marches two sets of 16, and its last 8 or fewer rays go on over 8, from where they stopped): every
    // ray's result (hit, t, normal, position, step count)
    // is bit for bit its one-ray RaySignedDistancePrimitiveTest, for every queue length 1..32, with each ray's own stepScale, rays that hit, miss, start beyond RayTCurrent, run out of steps
    // (the coarse and one-step accuracies), and rays of NaN and infinite values.
    std::vector<RayIn> rays = makeRays(0x9E5, 16 * 10, 0.5f, 1.0f);
    Rng rng{0x77};
    for (int i = 0; i < 24; ++i) rays.insert(rays.begin() + 7 * i, garbageRay(rng, i));
    for (RayIn& r : rays)
        if (std::isnan(r.param) || r.param > 2.0f) r.param = 0.75f;  // the stepScale: a material's
    Accuracy coarse;
    coarse.stepsFactor = 0.05;  // 26 steps: some rays run out of steps
    coarse.thresholdFactor = 4.0;
    coarse.normalEpsilonFactor = 3.0;
    Accuracy oneStep;
    oneStep.stepsFactor = 1e-9;  // scaledSteps gives 1
    int hits = 0, misses = 0, queues = 0;
    for (const NamedSdf& sdf : kSdfs) {
        for (const Accuracy& accuracy : {Accuracy{}, coarse, oneStep}) {
            const SphereTraceParams<float> params = sphereTraceParams(accuracy, 1.0f);
            size_t first = 0;
            for (int count = 1; first < rays.size(); count = count % kMaxMarchQueue + 1) {
                const int n = int(std::min<size_t>(size_t(count), rays.size() - first));
                std::vector<SphereTraceRay<float>> queue;
                for (int k = 0; k < n; ++k) {
                    const RayIn& r = rays[first + size_t(k)];
                    queue.push_back({scalarRay(r), scalarExtent(r), r.param});
                }
                std::vector<SphereTraceResult<float>> got(static_cast<size_t>(n));
                RaySignedDistancePrimitiveTestQueue<L>(queue.data(), n, sdf.queued(), params, got.data());
                ++queues;
                for (int k = 0; k < n; ++k) {
                    const RayIn& r = rays[first + size_t(k)];
                    const SphereTraceResult<float> want = RaySignedDistancePrimitiveTest(
                        scalarRay(r), scalarExtent(r), sdf.scalar, sphereTraceParams(accuracy, r.param));
                    const SphereTraceResult<float>& g = got[size_t(k)];
                    const std::string what = std::string(sdf.name) + " ray " + std::to_string(first + size_t(k)) +
                                             " of a queue of " + std::to_string(n) + ", " +
                                             std::to_string(params.maxSteps) + " steps";
                    EXPECT_EQ(want.hit, g.hit) << what;
                    EXPECT_EQ(bits(want.thit), bits(g.thit)) << what;
                    for (int c = 0; c < 3; ++c) {
                        EXPECT_EQ(bits(want.normal[c]), bits(g.normal[c])) << what << " normal";
                        EXPECT_EQ(bits(want.position[c]), bits(g.position[c])) << what << " position";
                    }
                    EXPECT_EQ(want.steps, g.steps) << what;
                    (want.hit ? hits : misses)++;
                }
                first += size_t(n);
            }
        }
    }
    EXPECT_GT(hits, 100);
    EXPECT_GT(misses, 100);
    EXPECT_GT(queues, 100);
}

TEST(LanesSdf, MetaballsMatchScalarPerLane) {
    const std::vector<RayIn> rays = makeRays(0x3E7A, 16 * 24, 0.0f, 30.0f, 0.5f);  // param: elapsed time; aimed at the balls
    MetaballsParams<float> fewSteps;
    fewSteps.maxSteps = 20;
    fewSteps.normalOffset = 1e-3f;
    for (const MetaballsParams<float>& params : {MetaballsParams<float>{}, fewSteps}) {
        const MetaballsParams<L> laneParams{params.maxSteps, L(params.normalOffset)};
        HitStats stats;
        forGroups(rays, 2, [&](const RayIn* group, const std::vector<int>& real) {
            const Ray<L> ray = laneRay(group);
            const RayExtent<L> extent = laneExtent(group);
            const MetaballsHit<L> lanes = RayMetaballsIntersectionTest(ray, extent, laneParam(group), L(12), laneParams);
            // The span of the balls, with its out-parameters.
            L tmin = L::generate([](int i) { return 70.0f + float(i); });
            L tmax = tmin;
            FindIntersectingMetaballs(ray, extent, tmin, tmax, InitializeAnimatedMetaballs(laneParam(group), L(12)));
            for (int i : real) {
                const Ray<float> sray = scalarRay(group[i]);
                const RayExtent<float> sext = scalarExtent(group[i]);
                const MetaballsHit<float> s =
                    RayMetaballsIntersectionTest(sray, sext, group[i].param, 12.0f, params);
                expectSame(s.hit, lanes.hit, i, "metaballs hit");
                expectSame(s.thit, lanes.thit, i, "metaballs thit");
                expectSame(s.normal, lanes.normal, i, "metaballs normal");
                expectSame(s.step, lanes.step, i, "metaballs step");
                float stmin = 70.0f + float(i), stmax = stmin;
                FindIntersectingMetaballs(sray, sext, stmin, stmax, InitializeAnimatedMetaballs(group[i].param, 12.0f));
                expectSame(stmin, tmin, i, "FindIntersectingMetaballs tmin");
                expectSame(stmax, tmax, i, "FindIntersectingMetaballs tmax");
            }
            stats.group(lanes.hit, real);
        });
        stats.expectMixed("metaballs");
    }
}

TEST(LanesSdf, AnalyticMatchScalarPerLane) {
    const std::vector<RayIn> rays = makeRays(0xA11, 16 * 40, 0.1f, 1.2f);  // param: a sphere radius
    HitStats spheres, cube, sphere;
    forGroups(rays, 3, [&](const RayIn* group, const std::vector<int>& real) {
        const Ray<L> ray = laneRay(group);
        const RayExtent<L> extent = laneExtent(group);
        const AnalyticHit<L> lSpheres = RaySpheresIntersectionTest(ray, extent);
        const AnalyticHit<L> lCube = RayUnitCubeIntersectionTest(ray, extent);
        // The hollow sphere with a per-lane radius and its tmax out-parameter (untouched without roots).
        L lTmax = L::generate([](int i) { return -5.0f - float(i); });
        const AnalyticHit<L> lSphere =
            RaySphereIntersectionTest(ray, extent, lTmax, vec3<L>(L(0.05f), L(-0.1f), L(0.1f)), laneParam(group));
        L lThit = L::generate([](int i) { return 30.0f + float(i); });
        L lTmax2 = L::generate([](int i) { return 40.0f + float(i); });
        const LMask lSolid = RaySolidSphereIntersectionTest(ray, extent, lThit, lTmax2, vec3<L>(L(0)), laneParam(group));
        // The slab test with a per-lane box and its out-parameters.
        const vec3<L> box[2] = {vec3<L>(L(-0.7f), L(-1.0f), L(-0.2f)) * laneParam(group),
                                vec3<L>(L(0.9f), L(0.5f), L(1.1f)) * laneParam(group)};
        L lSlabMin = L(-9.0f), lSlabMax = L(9.0f);
        const LMask lSlab = RayAABBIntersectionTest(ray, box, extent, lSlabMin, lSlabMax);
        const AnalyticHit<L> lBox = RayAABBIntersectionTest(ray, box, extent);
        const vec2<L> lIsphere = isphere(vec4<L>(L(0), L(0), L(0), L(1.25f)), ray.origin, ray.direction);
        for (int i : real) {
            const Ray<float> s = scalarRay(group[i]);
            const RayExtent<float> e = scalarExtent(group[i]);
            const AnalyticHit<float> sSpheres = RaySpheresIntersectionTest(s, e);
            expectSame(sSpheres.hit, lSpheres.hit, i, "spheres hit");
            expectSame(sSpheres.thit, lSpheres.thit, i, "spheres thit");
            expectSame(sSpheres.normal, lSpheres.normal, i, "spheres normal");
            const AnalyticHit<float> sCube = RayUnitCubeIntersectionTest(s, e);
            expectSame(sCube.hit, lCube.hit, i, "cube hit");
            expectSame(sCube.thit, lCube.thit, i, "cube thit");
            expectSame(sCube.normal, lCube.normal, i, "cube normal");
            float sTmax = -5.0f - float(i);
            const AnalyticHit<float> sSphere =
                RaySphereIntersectionTest(s, e, sTmax, glm::vec3(0.05f, -0.1f, 0.1f), group[i].param);
            expectSame(sSphere.hit, lSphere.hit, i, "sphere hit");
            expectSame(sSphere.thit, lSphere.thit, i, "sphere thit");
            expectSame(sSphere.normal, lSphere.normal, i, "sphere normal");
            expectSame(sTmax, lTmax, i, "sphere tmax");
            float sThit = 30.0f + float(i), sTmax2 = 40.0f + float(i);
            expectSame(RaySolidSphereIntersectionTest(s, e, sThit, sTmax2, glm::vec3(0.0f), group[i].param), lSolid, i,
                       "solid sphere");
            expectSame(sThit, lThit, i, "solid sphere thit");
            expectSame(sTmax2, lTmax2, i, "solid sphere tmax");
            const glm::vec3 sBox[2] = {glm::vec3(-0.7f, -1.0f, -0.2f) * group[i].param,
                                       glm::vec3(0.9f, 0.5f, 1.1f) * group[i].param};
            float sSlabMin = -9.0f, sSlabMax = 9.0f;
            expectSame(RayAABBIntersectionTest(s, sBox, e, sSlabMin, sSlabMax), lSlab, i, "slabs");
            expectSame(sSlabMin, lSlabMin, i, "slabs tmin");
            expectSame(sSlabMax, lSlabMax, i, "slabs tmax");
            const AnalyticHit<float> sBoxHit = RayAABBIntersectionTest(s, sBox, e);
            expectSame(sBoxHit.hit, lBox.hit, i, "box hit");
            expectSame(sBoxHit.thit, lBox.thit, i, "box thit");
            expectSame(sBoxHit.normal, lBox.normal, i, "box normal");
            expectSame(isphere(glm::vec4(0.0f, 0.0f, 0.0f, 1.25f), s.origin, s.direction), lIsphere, i, "isphere");
        }
        spheres.group(lSpheres.hit, real);
        cube.group(lCube.hit, real);
        sphere.group(lSphere.hit, real);
    });
    spheres.expectMixed("spheres");
    cube.expectMixed("unit cube");
    sphere.expectMixed("sphere");
}

// The quadratic solver's out-parameters stay untouched per lane without roots; the double root and the swap.
TEST(LanesSdf, SolveQuadraticEqnMatchesScalarPerLane) {
    Rng rng{0x9AD};
    for (int g = 0; g < 64; ++g) {
        float a[W], b[W], c[W];
        for (int i = 0; i < W; ++i) {
            a[i] = rng.uni(-2.0f, 2.0f);
            b[i] = rng.uni(-2.0f, 2.0f);
            c[i] = rng.uni(-2.0f, 2.0f);
            if ((i + g) % 5 == 0) { a[i] = 1.0f; b[i] = 2.0f; c[i] = 1.0f; }  // discriminant 0
            if ((i + g) % 7 == 3) a[i] = std::numeric_limits<float>::quiet_NaN();
        }
        L x0 = L::generate([](int i) { return 100.0f + float(i); });
        L x1 = L::generate([](int i) { return 200.0f + float(i); });
        const LMask roots = SolveQuadraticEqn(L::generate([&](int i) { return a[i]; }),
                                              L::generate([&](int i) { return b[i]; }),
                                              L::generate([&](int i) { return c[i]; }), x0, x1);
        for (int i = 0; i < W; ++i) {
            float s0 = 100.0f + float(i), s1 = 200.0f + float(i);
            expectSame(SolveQuadraticEqn(a[i], b[i], c[i], s0, s1), roots, i, "roots");
            expectSame(s0, x0, i, "x0");
            expectSame(s1, x1, i, "x1");
        }
    }
}

// Every SDF primitive and operator, the normal, the helpers of ray.h, at random points.
TEST(LanesSdf, PrimitivesMatchScalarPerLane) {
    Rng rng{0x9219};
    for (int g = 0; g < 32; ++g) {
        glm::vec3 p[W], q[W];
        RayIn in[W];
        for (int i = 0; i < W; ++i) {
            p[i] = rng.vec(-1.5f, 1.5f);
            q[i] = rng.vec(0.1f, 1.5f);
            in[i] = makeRay(rng, i, 0.0f, 30.0f);
        }
        vec3<L> lp, lq;
        for (int i = 0; i < W; ++i) {
            setLane(lp, i, p[i]);
            setLane(lq, i, q[i]);
        }
        const vec2<L> lq2(lq);
        const L la = lp.x, lb = lp.y, lc = lq.z;
        const Ray<L> lray = laneRay(in);
        const RayExtent<L> lext = laneExtent(in);
        // Each entry: the lane result and a function giving the scalar result for lane i.
        const auto same = [&](const auto& lanes, auto scalarOf, const char* what) {
            for (int i = 0; i < W; ++i) expectSame(scalarOf(i), lanes, i, what);
        };
#define REFRAY_SAME(expr, what)                                                                   \
    same(                                                                                         \
        [&] {                                                                                     \
            using T = L;                                                                          \
            [[maybe_unused]] const vec3<T>& P = lp;                                               \
            [[maybe_unused]] const vec3<T>& Q = lq;                                               \
            [[maybe_unused]] const vec2<T>& Q2 = lq2;                                             \
            [[maybe_unused]] const T A = la, B = lb, C = lc;                                      \
            [[maybe_unused]] const Ray<T>& R = lray;                                              \
            [[maybe_unused]] const RayExtent<T>& E = lext;                                        \
            return expr;                                                                          \
        }(),                                                                                      \
        [&](int i) {                                                                              \
            using T = float;                                                                      \
            [[maybe_unused]] const vec3<T> P = p[i];                                              \
            [[maybe_unused]] const vec3<T> Q = q[i];                                              \
            [[maybe_unused]] const vec2<T> Q2 = vec2<T>(q[i]);                                    \
            [[maybe_unused]] const T A = p[i].x, B = p[i].y, C = q[i].z;                          \
            [[maybe_unused]] const Ray<T> R = scalarRay(in[i]);                                   \
            [[maybe_unused]] const RayExtent<T> E = scalarExtent(in[i]);                          \
            return expr;                                                                          \
        },                                                                                        \
        what)
        REFRAY_SAME(opS(A, B), "opS");
        REFRAY_SAME(opU(A, B), "opU");
        REFRAY_SAME(opI(A, B), "opI");
        REFRAY_SAME(opRep(P, Q), "opRep");
        REFRAY_SAME(smin(A, B, T(0.3f)), "smin");
        REFRAY_SAME(smax(A, B, T(0.3f)), "smax");
        REFRAY_SAME(opBlendU(A, B), "opBlendU");
        REFRAY_SAME(opBlendI(A, B), "opBlendI");
        REFRAY_SAME(opTwist(P), "opTwist");
        REFRAY_SAME(sdPlane(P), "sdPlane");
        REFRAY_SAME(sdSphere(P, C), "sdSphere");
        REFRAY_SAME(sdBox(P, Q), "sdBox");
        REFRAY_SAME(sdEllipsoid(P, Q), "sdEllipsoid");
        REFRAY_SAME(udRoundBox(P, Q, T(0.1f)), "udRoundBox");
        REFRAY_SAME(sdTorus(P, Q2), "sdTorus");
        REFRAY_SAME(sdHexPrism(P, Q2), "sdHexPrism");
        REFRAY_SAME(sdCapsule(P, Q, -Q, T(0.2f)), "sdCapsule");
        REFRAY_SAME(sdTriPrism(P, Q2), "sdTriPrism");
        REFRAY_SAME(sdCylinder(P, Q2), "sdCylinder");
        REFRAY_SAME(sdOctahedron(P, Q), "sdOctahedron");
        REFRAY_SAME(sdPyramid(P, Q), "sdPyramid");
        REFRAY_SAME(length_toPowNegative6(vec2<T>(P)), "length_toPowNegative6");
        REFRAY_SAME(length_toPowNegative8(vec2<T>(P)), "length_toPowNegative8");
        REFRAY_SAME(sdTorus82(P, Q2), "sdTorus82");
        REFRAY_SAME(sdTorus88(P, Q2), "sdTorus88");
        REFRAY_SAME(sdCylinder6(P, Q2), "sdCylinder6");
        REFRAY_SAME(d3d12::sdMiniSpheres(P), "sdMiniSpheres");
        REFRAY_SAME(d3d12::sdIntersectedRoundCube(P), "sdIntersectedRoundCube");
        REFRAY_SAME(d3d12::sdSquareTorus(P), "sdSquareTorus");
        REFRAY_SAME(d3d12::sdTwistedTorus(P), "sdTwistedTorus");
        REFRAY_SAME(d3d12::sdCog(P), "sdCog");
        REFRAY_SAME(d3d12::sdCylinderColumns(P), "sdCylinderColumns");
        REFRAY_SAME(sdCalculateNormal(P, [](const vec3<T>& x) { return d3d12::sdCog(x); }), "sdCalculateNormal");
        REFRAY_SAME(IsInRange(A, B, C), "IsInRange");
        REFRAY_SAME(IsCulled(R, P, E), "IsCulled");
        REFRAY_SAME(IsAValidHit(R, A, P, E), "IsAValidHit");
        REFRAY_SAME(CalculateAnimationInterpolant(C * T(20.0f), T(12.0f)), "CalculateAnimationInterpolant");
        REFRAY_SAME(CalculateMetaballsPotential(P * T(0.4f), InitializeAnimatedMetaballs(C, T(12.0f))),
                    "CalculateMetaballsPotential");
        REFRAY_SAME(CalculateMetaballsNormal(P * T(0.4f), InitializeAnimatedMetaballs(C, T(12.0f))),
                    "CalculateMetaballsNormal");
#undef REFRAY_SAME
    }
}

}  // namespace
}  // namespace refray::procedural::math
