// Conformance tests for emulator/intersection.*: the fixed-function triangle test
// (dxr-semantics.md section 14, TRI), the triangle ray interval (TRV-2) and the AABB slab
// test (BLAS-7), on the pure functions and through DispatchRays.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "core/random.h"
#include "emulator/intersection.h"
#include "harness.h"

namespace refray::test {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A triangle soup: 3 vertices per triangle, in app order.
struct Mesh {
    std::vector<vec3> v;
    size_t count() const { return v.size() / 3; }
    void add(vec3 a, vec3 b, vec3 c) { v.insert(v.end(), {a, b, c}); }
};

// The triangles a ray hits with TMin < t < TMax (TRV-2), by index.
std::vector<size_t> hitsOf(const Mesh& m, vec3 o, vec3 d, bool alternate = false, float tMin = 0.0f, float tMax = kInf) {
    std::vector<size_t> out;
    for (size_t i = 0; i < m.count(); ++i) {
        const auto hit = intersectTriangle(o, d, m.v[3 * i], m.v[3 * i + 1], m.v[3 * i + 2], alternate);
        if (hit && hit->t > tMin && hit->t < tMax) out.push_back(i);
    }
    return out;
}

// An n x n grid over [-1,1]^2 (vertices at multiples of 2/n, exact for n a power of two),
// cells split along alternating diagonals, consistently wound. `height` gives z per vertex;
// `jitter` moves interior vertices in xy. `flipEvery` > 0 reverses the winding of every
// flipEvery-th triangle (still a manifold).
Mesh gridMesh(int n, float heightAmplitude, float jitter, uint32_t seed, int flipEvery = 0) {
    Random rng(seed, 0, 0);
    std::vector<vec3> p((n + 1) * (n + 1));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            vec3 q(-1.0f + 2.0f * float(i) / float(n), -1.0f + 2.0f * float(j) / float(n), 0.0f);
            if (heightAmplitude != 0.0f) q.z = heightAmplitude * (2.0f * rng.nextFloat() - 1.0f);
            if (jitter != 0.0f && i > 0 && j > 0 && i < n && j < n) {
                q.x += jitter * (2.0f * rng.nextFloat() - 1.0f);
                q.y += jitter * (2.0f * rng.nextFloat() - 1.0f);
            }
            p[j * (n + 1) + i] = q;
        }
    Mesh m;
    int t = 0;
    auto add = [&](vec3 a, vec3 b, vec3 c) {
        if (flipEvery > 0 && ++t % flipEvery == 0) m.add(a, c, b);
        else m.add(a, b, c);
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const vec3 a = p[j * (n + 1) + i], b = p[j * (n + 1) + i + 1], c = p[(j + 1) * (n + 1) + i + 1],
                       d = p[(j + 1) * (n + 1) + i];
            if ((i + j) % 2) {
                add(a, b, c);
                add(a, c, d);
            } else {
                add(a, b, d);
                add(b, c, d);
            }
        }
    return m;
}

// 10 000 axis-aligned rays on a 1/64 lattice: many pass exactly through grid edges,
// diagonals and vertices of an 8 x 8 grid (spacing 1/4).
std::vector<RayDesc> latticeRays(float dz) {
    std::vector<RayDesc> rays;
    for (int j = 0; j < 100; ++j)
        for (int i = 0; i < 100; ++i)
            rays.push_back(RayDesc{vec3(float(i - 50) / 64.0f, float(j - 50) / 64.0f, -5.0f * dz), 0.0f, vec3(0, 0, dz), 100.0f});
    return rays;
}

// Seeded oblique rays through points of [-0.9,0.9]^2 on the plane z = 0.
std::vector<RayDesc> obliqueRays(uint32_t seed, size_t count) {
    Random rng(seed, 1, 2);
    std::vector<RayDesc> rays;
    for (size_t k = 0; k < count; ++k) {
        const vec3 target(1.8f * rng.nextFloat() - 0.9f, 1.8f * rng.nextFloat() - 0.9f, 0.0f);
        vec3 d(2.0f * rng.nextFloat() - 1.0f, 2.0f * rng.nextFloat() - 1.0f, rng.nextFloat() < 0.5f ? 1.0f : -1.0f);
        d.z *= 0.3f + rng.nextFloat();  // sometimes x or y dominates
        rays.push_back(RayDesc{target - 3.0f * d, 0.0f, d, 100.0f});
    }
    return rays;
}

// Rays with dyadic directions through every interior vertex and edge midpoint of an
// unjittered planar n x n grid: origin = point - 4 * d is exact, so each ray passes exactly
// through the vertex or edge.
std::vector<RayDesc> exactFeatureRays(int n) {
    const std::vector<vec3> dirs = {{0, 0, 1},         {0, 0, -1},          {0.25f, -0.125f, 1}, {-0.5f, 0.375f, -1},
                                    {1, 0.5f, 0.25f},  {-0.75f, -1, 0.5f},  {0.5f, 0.5f, 1},     {-1, 1, -0.5f}};
    std::vector<RayDesc> rays;
    const float h = 2.0f / float(n);
    for (int j = 0; j <= 2 * n; ++j)
        for (int i = 0; i <= 2 * n; ++i) {
            if (i == 0 || j == 0 || i == 2 * n || j == 2 * n) continue;  // boundary
            const vec3 p(-1.0f + 0.5f * h * float(i), -1.0f + 0.5f * h * float(j), 0.0f);
            for (vec3 d : dirs) rays.push_back(RayDesc{p - 4.0f * d, 0.0f, d, 100.0f});
        }
    return rays;
}

void expectExactlyOnce(const Mesh& m, const std::vector<RayDesc>& rays, bool alternate) {
    size_t bad = 0;
    for (size_t k = 0; k < rays.size(); ++k) {
        const auto hits = hitsOf(m, rays[k].Origin, rays[k].Direction, alternate);
        if (hits.size() != 1 && ++bad <= 5)
            ADD_FAILURE() << "ray " << k << " origin (" << rays[k].Origin.x << "," << rays[k].Origin.y << ","
                          << rays[k].Origin.z << ") dir (" << rays[k].Direction.x << "," << rays[k].Direction.y << ","
                          << rays[k].Direction.z << ") hits " << hits.size() << " triangles";
    }
    EXPECT_EQ(bad, 0u) << "of " << rays.size() << " rays";
}

// A harness with a 1D ray generation shader tracing rays[i]; "AH_Ignore" counts any-hit calls.
class Rig {
public:
    Harness h;
    std::vector<RayDesc> rays;
    std::vector<Probe> results;
    uint32_t flags = RAY_FLAG_NONE;
    StateObjectPtr so;

    Rig() {
        h.addProbeShaders();
        h.library->addRayGeneration("RG", [this](ShaderContext& ctx) {
            const uint32_t i = ctx.DispatchRaysIndex().x;
            Probe p;
            ctx.TraceRay(h.scene, flags, 0xFF, 0, 0, 0, rays[i], p);
            results[i] = p;
        });
        h.library->addAnyHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "AH_Ignore", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
                p.anyHits++;
                p.primitiveIndex = ctx.PrimitiveIndex();
                ctx.IgnoreHit();
            });
        h.stateObject.hitGroups.push_back({"HG_TriIgnore", HitGroupType::Triangles, "AH_Ignore", "CH_Probe", ""});
    }
    Rig(const Rig&) = delete;

    const std::vector<Probe>& trace(const std::vector<RayDesc>& r, const std::string& hitGroup = "HG_Tri",
                                    DispatchOptions options = {}) {
        if (!so) so = h.pipeline();
        rays = r;
        results.assign(r.size(), Probe{});
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {hitGroup}), uvec3(uint32_t(r.size()), 1, 1), options);
        return results;
    }
    void scene(const Mesh& m, uint32_t geometryFlags) { h.tlas({Harness::instance(h.blas({h.triangles(m.v, geometryFlags)}))}); }
};

// Every ray's any-hit count through a dispatch (non-opaque geometry, AHS ignores every hit).
void expectDispatchExactlyOnce(const Mesh& m, const std::vector<RayDesc>& rays, DispatchOptions options) {
    Rig r;
    r.scene(m, GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION);
    const auto& p = r.trace(rays, "HG_TriIgnore", options);
    size_t bad = 0;
    for (size_t k = 0; k < p.size(); ++k)
        if ((p[k].anyHits != 1 || p[k].misses != 1) && ++bad <= 5)
            ADD_FAILURE() << "ray " << k << " origin (" << rays[k].Origin.x << "," << rays[k].Origin.y << ","
                          << rays[k].Origin.z << "): " << p[k].anyHits << " any-hit calls";
    EXPECT_EQ(bad, 0u) << "of " << rays.size() << " rays";
}

// Every ray of `rays` against every triangle of `m`, 16 rays at a time through intersectTriangleLanes (with some lanes
// left out of each call): each tested lane must be the one-ray test's result bit for bit, a lane in `exact` one the
// one-ray test must decide (its float edge functions have an exact zero), and an untested lane in neither mask.
// Returns how many lanes were left to the one-ray test.
size_t expectLanesMatchOneRay(const Mesh& m, const std::vector<RayDesc>& rays) {
    size_t bad = 0, exact = 0;
    for (size_t first = 0; first < rays.size(); first += dxr::RayLanes::kCount) {
        dxr::RayLanes lanes;
        uint32_t tested = 0;
        for (int i = 0; i < dxr::RayLanes::kCount; ++i) {
            const RayDesc& r = rays[std::min(first + size_t(i), rays.size() - 1)];
            lanes.ox[i] = r.Origin.x, lanes.oy[i] = r.Origin.y, lanes.oz[i] = r.Origin.z;
            lanes.dx[i] = r.Direction.x, lanes.dy[i] = r.Direction.y, lanes.dz[i] = r.Direction.z;
            if (first + size_t(i) < rays.size() && (first / 16 + size_t(i)) % 7 != 3) tested |= 1u << i;
        }
        for (size_t t = 0; t < m.count(); ++t) {
            const vec3 v0 = m.v[3 * t], v1 = m.v[3 * t + 1], v2 = m.v[3 * t + 2];
            dxr::intersectTriangleLanes(v0, v1, v2, tested, lanes);
            EXPECT_EQ(lanes.hit & lanes.exact, 0u);
            EXPECT_EQ((lanes.hit | lanes.exact) & ~tested, 0u);
            for (int i = 0; i < dxr::RayLanes::kCount; ++i) {
                if (!(tested >> i & 1u)) continue;
                const vec3 o(lanes.ox[i], lanes.oy[i], lanes.oz[i]), d(lanes.dx[i], lanes.dy[i], lanes.dz[i]);
                if (lanes.exact >> i & 1u) {
                    ++exact;
                    continue;
                }
                const auto one = intersectTriangle(o, d, v0, v1, v2);
                const bool hit = lanes.hit >> i & 1u;
                const bool same = hit == one.has_value() &&
                                  (!hit || (std::bit_cast<uint32_t>(lanes.t[i]) == std::bit_cast<uint32_t>(one->t) &&
                                            std::bit_cast<uint32_t>(lanes.b1[i]) == std::bit_cast<uint32_t>(one->barycentrics.x) &&
                                            std::bit_cast<uint32_t>(lanes.b2[i]) == std::bit_cast<uint32_t>(one->barycentrics.y)));
                if (!same && ++bad <= 5)
                    ADD_FAILURE() << "ray " << first + size_t(i) << " triangle " << t << ": lanes " << (hit ? "hit" : "miss")
                                  << (hit ? " t " + std::to_string(lanes.t[i]) : "") << ", one ray "
                                  << (one ? "hit t " + std::to_string(one->t) : "miss");
            }
        }
    }
    EXPECT_EQ(bad, 0u) << "of " << rays.size() << " rays";
    return exact;
}

// ---------------------------------------------------------------------------------------
// The broad phase's packet test (intersectTriangleLanes): each lane the one-ray test's result, bit for bit

TEST(Intersection, TRI_1_LanesMatchOneRayOnObliqueRaysThroughJitteredMesh) {
    expectLanesMatchOneRay(gridMesh(8, 0.3f, 0.08f, 11), obliqueRays(5, 4000));
}

TEST(Intersection, TRI_2_LanesLeaveRaysThroughEdgesAndVerticesToTheOneRayTest) {
    // Rays exactly through the grid's vertices and edges: their edge functions have exact zeros.
    EXPECT_GT(expectLanesMatchOneRay(gridMesh(8, 0.0f, 0.0f, 1), exactFeatureRays(8)), 0u);
}

TEST(Intersection, TRI_5_LanesMatchOneRayOnParallelZeroNaNAndDegenerateCases) {
    Mesh m = gridMesh(2, 0.0f, 0.0f, 3);
    m.add(vec3(0, 0, 0), vec3(1, 1, 0), vec3(2, 2, 0));        // collinear: inactive (DEGEN-7)
    m.add(vec3(0.5f, 0.5f, 0), vec3(0.5f, 0.5f, 0), vec3(0, 1, 0));  // two equal vertices
    m.add(vec3(-1, -1, 1), vec3(1, -1, 1), vec3(-1, 1, 1e-30f));     // nearly on edge
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<RayDesc> rays = {
        {vec3(0.1f, 0.2f, -1), 0, vec3(1, 0, 0), 100},        // parallel to the plane
        {vec3(0.1f, 0.2f, 0), 0, vec3(1, 0.5f, 0), 100},       // in the plane
        {vec3(0.1f, 0.2f, -1), 0, vec3(0, 0, 0), 100},         // zero direction
        {vec3(0.1f, 0.2f, -1), 0, vec3(0, 0, nan), 100},       // NaN direction
        {vec3(nan, 0.2f, -1), 0, vec3(0, 0, 1), 100},          // NaN origin
        {vec3(0.1f, 0.2f, -1), 0, vec3(0, 0, kInf), 100},      // infinite direction
        {vec3(0.3f, -0.7f, 1), 0, vec3(0, 0, -1), 100},        // from above
        {vec3(0.3f, -0.7f, 1), 0, vec3(-0.0f, 0.0f, -1), 100}, // signed zeros
        {vec3(1e30f, 0, -1), 0, vec3(-1e30f, 0, 1), 100},      // huge values
        {vec3(0.25f, 0.25f, -1), 0, vec3(1e-30f, 1e-30f, 1), 100},
    };
    const std::vector<RayDesc> oblique = obliqueRays(17, 200);
    rays.insert(rays.end(), oblique.begin(), oblique.end());
    expectLanesMatchOneRay(m, rays);
}

// ---------------------------------------------------------------------------------------
// TRI-1: watertightness

TEST(Intersection, TRI_1_LatticeRaysThroughHeightfieldHitExactlyOnce) {
    const Mesh m = gridMesh(8, 0.25f, 0.0f, 11);
    expectExactlyOnce(m, latticeRays(1.0f), false);
    expectExactlyOnce(m, latticeRays(-1.0f), false);
}

TEST(Intersection, TRI_1_SeededObliqueRaysThroughJitteredMeshHitExactlyOnce) {
    const Mesh m = gridMesh(8, 0.0f, 0.1f, 12);
    expectExactlyOnce(m, obliqueRays(13, 10000), false);
}

TEST(Intersection, TRI_1_LargeCoordinatesStayWatertight) {
    // The same lattice scaled by 2^20 and moved far from the origin: still exactly once.
    Mesh m = gridMesh(8, 0.25f, 0.0f, 14);
    const float s = 1048576.0f;
    const vec3 offset(3.0e7f, -2.0e7f, 0.0f);
    for (vec3& v : m.v) v = v * s + offset;
    std::vector<RayDesc> rays = latticeRays(1.0f);
    for (RayDesc& r : rays) {
        r.Origin = vec3(r.Origin.x * s, r.Origin.y * s, -5.0f * s) + offset;
        r.TMax = kInf;
    }
    expectExactlyOnce(m, rays, false);
}

TEST(Intersection, TRI_1_DispatchLatticeRaysHitExactlyOnce) {
    expectDispatchExactlyOnce(gridMesh(8, 0.25f, 0.0f, 11), latticeRays(1.0f), {});
}

TEST(Intersection, TRI_1_DispatchSeededObliqueRaysHitExactlyOnce) {
    expectDispatchExactlyOnce(gridMesh(8, 0.0f, 0.1f, 12), obliqueRays(13, 10000), {});
}

// ---------------------------------------------------------------------------------------
// TRI-2: shared edges and vertices of a manifold

TEST(Intersection, TRI_2_RaysExactlyThroughSharedEdgesAndVerticesHitOnce) {
    const Mesh m = gridMesh(8, 0.0f, 0.0f, 0);
    expectExactlyOnce(m, exactFeatureRays(8), false);
}

TEST(Intersection, TRI_2_InconsistentWindingStillHitsOnce) {
    const Mesh m = gridMesh(8, 0.0f, 0.0f, 0, 3);
    expectExactlyOnce(m, exactFeatureRays(8), false);
    expectExactlyOnce(m, exactFeatureRays(8), true);
}

TEST(Intersection, TRI_2_QuadDiagonalAndFanCentre) {
    Mesh quad;
    const vec3 a(-1, -1, 0), b(1, -1, 0), c(1, 1, 0), d(-1, 1, 0);
    quad.add(a, b, c);
    quad.add(a, c, d);
    Mesh fan;
    const std::vector<vec3> ring = {{1, 0, 0}, {0.5f, 1, 0}, {-0.5f, 1, 0}, {-1, 0, 0}, {-0.5f, -1, 0}, {0.5f, -1, 0}};
    for (size_t i = 0; i < ring.size(); ++i) fan.add(vec3(0), ring[i], ring[(i + 1) % ring.size()]);
    const std::vector<vec3> dirs = {{0, 0, 1}, {0, 0, -1}, {0.25f, -0.125f, 1}, {1, 0.5f, 0.25f}, {-0.5f, -1, -0.25f}, {0, 1, 1}};
    for (bool alternate : {false, true})
        for (vec3 dir : dirs) {
            for (vec3 p : {vec3(0, 0, 0), vec3(0.5f, 0.5f, 0), vec3(-0.25f, -0.25f, 0)})
                EXPECT_EQ(hitsOf(quad, p - 4.0f * dir, dir, alternate).size(), 1u)
                    << "diagonal point (" << p.x << "," << p.y << ") alternate " << alternate;
            EXPECT_EQ(hitsOf(fan, -4.0f * dir, dir, alternate).size(), 1u) << "fan centre, alternate " << alternate;
            // The spokes of the fan are shared edges too.
            for (const vec3& q : ring)
                EXPECT_EQ(hitsOf(fan, 0.5f * q - 4.0f * dir, dir, alternate).size(), 1u) << "spoke, alternate " << alternate;
        }
}

// ---------------------------------------------------------------------------------------
// TRI-3: non-manifold geometry

TEST(Intersection, TRI_3_FinEdgeHitsEveryTriangleOnOneSide) {
    Mesh m;
    const vec3 e0(0, -1, 0), e1(0, 1, 0);
    m.add(e0, e1, vec3(-1, 0, 0));  // 0: left
    m.add(e0, e1, vec3(1, 0, 0));   // 1: right
    m.add(e0, e1, vec3(1, 0, 1));   // 2: right, tilted up
    for (bool alternate : {false, true})
        for (vec3 dir : {vec3(0, 0, 1), vec3(0, 0, -1), vec3(0, 0.25f, 1)}) {
            const vec3 p(0, 0.25f, 0);
            auto hits = hitsOf(m, p - 4.0f * dir, dir, alternate);
            const bool left = hits == std::vector<size_t>{0};
            const bool right = hits == std::vector<size_t>{1, 2};
            EXPECT_TRUE(left || right) << "alternate " << alternate << ": " << hits.size() << " hits";
        }
}

TEST(Intersection, TRI_3_VertexSharedBySeparateSurfacesHitOncePerSurface) {
    // Two cones touching at their apex (an hourglass): a ray through the apex hits each once.
    Mesh m;
    const std::vector<vec3> ring = {{1, 0, 0}, {0.5f, 1, 0}, {-0.5f, 1, 0}, {-1, 0, 0}, {-0.5f, -1, 0}, {0.5f, -1, 0}};
    for (float z : {1.0f, -1.0f})
        for (size_t i = 0; i < ring.size(); ++i)
            m.add(vec3(0), ring[i] + vec3(0, 0, z), ring[(i + 1) % ring.size()] + vec3(0, 0, z));
    for (bool alternate : {false, true})
        for (vec3 dir : {vec3(0, 0, 1), vec3(0, 0, -1), vec3(0.25f, 0.125f, 1)}) {
            const auto hits = hitsOf(m, -4.0f * dir, dir, alternate);
            ASSERT_EQ(hits.size(), 2u) << "alternate " << alternate;
            EXPECT_LT(hits[0], ring.size());   // upper cone
            EXPECT_GE(hits[1], ring.size());   // lower cone
        }
}

// ---------------------------------------------------------------------------------------
// TRI-4: a deterministic edge rule that depends only on the ray; the alternate rule
// (adversarial mode, GEN-3) is watertight too.

TEST(Intersection, TRI_4_AlternateEdgeRuleIsAlsoExactlyOnce) {
    expectExactlyOnce(gridMesh(8, 0.25f, 0.0f, 11), latticeRays(1.0f), true);
    expectExactlyOnce(gridMesh(8, 0.0f, 0.0f, 0), exactFeatureRays(8), true);
    expectExactlyOnce(gridMesh(8, 0.0f, 0.1f, 12), obliqueRays(13, 10000), true);
}

TEST(Intersection, TRI_4_DispatchAdversarialSeedsStayExactlyOnce) {
    const Mesh m = gridMesh(8, 0.25f, 0.0f, 11);
    for (uint64_t seed : {1u, 2u, 7u}) {  // odd seeds use the alternate edge rule
        SCOPED_TRACE("seed " + std::to_string(seed));
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        expectDispatchExactlyOnce(m, latticeRays(1.0f), o);
    }
}

TEST(Intersection, TRI_4_OwnerDoesNotDependOnPrimitiveOrderOrVertexRotation) {
    const vec3 a(-1, -1, 0), b(1, -1, 0), c(1, 1, 0), d(-1, 1, 0);
    // Triangle "lower" = (a,b,c), "upper" = (a,c,d); the ray runs exactly through the diagonal.
    const vec3 o(0, 0, -4), dir(0, 0, 1);
    for (bool alternate : {false, true}) {
        const bool lowerOwns = intersectTriangle(o, dir, a, b, c, alternate).has_value();
        EXPECT_NE(lowerOwns, intersectTriangle(o, dir, a, c, d, alternate).has_value());
        // Rotating the vertex order of either triangle keeps the owner.
        EXPECT_EQ(lowerOwns, intersectTriangle(o, dir, b, c, a, alternate).has_value());
        EXPECT_EQ(lowerOwns, intersectTriangle(o, dir, c, a, b, alternate).has_value());
        EXPECT_EQ(!lowerOwns, intersectTriangle(o, dir, c, d, a, alternate).has_value());
        // The same ray, asked again, gets the same answer.
        for (int k = 0; k < 3; ++k) EXPECT_EQ(lowerOwns, intersectTriangle(o, dir, a, b, c, alternate).has_value());
    }
    // Through a dispatch, the BLAS order of the two triangles does not change the owner.
    Rig r1, r2;
    Mesh m1, m2;
    m1.add(a, b, c);
    m1.add(a, c, d);
    m2.add(a, c, d);
    m2.add(a, b, c);
    r1.scene(m1, GEOMETRY_FLAG_OPAQUE);
    r2.scene(m2, GEOMETRY_FLAG_OPAQUE);
    const RayDesc ray{o, 0.0f, dir, 100.0f};
    const uint32_t p1 = r1.trace({ray})[0].primitiveIndex, p2 = r2.trace({ray})[0].primitiveIndex;
    ASSERT_LT(p1, 2u);
    ASSERT_LT(p2, 2u);
    EXPECT_EQ(p1, 1u - p2) << "the same geometric triangle owns the diagonal";
}

// ---------------------------------------------------------------------------------------
// TRI-5: parallel rays

TEST(Intersection, TRI_5_RayParallelToTrianglePlaneDoesNotHit) {
    const vec3 v0(-1, -1, 0), v1(0, 1, 0), v2(1, -1, 0);
    for (float z : {0.0f, 0.5f, -0.0f})
        for (vec3 d : {vec3(1, 0, 0), vec3(-1, 0.5f, 0), vec3(0, -1, 0), vec3(0.25f, 1, -0.0f)}) {
            const vec3 o = vec3(0, 0, z) - 3.0f * d;
            EXPECT_FALSE(intersectTriangle(o, d, v0, v1, v2, false).has_value()) << "z " << z;
            EXPECT_FALSE(intersectTriangle(o, d, v0, v1, v2, true).has_value()) << "z " << z;
        }
    Rig r;
    Mesh m;
    m.add(v0, v1, v2);
    r.scene(m, GEOMETRY_FLAG_OPAQUE);
    const auto& p = r.trace({RayDesc{vec3(-3, 0, 0), 0, vec3(1, 0, 0), 100}, RayDesc{vec3(0, -3, 0), 0, vec3(0, 1, 0), 100}});
    EXPECT_EQ(p[0].misses, 1u);
    EXPECT_EQ(p[1].misses, 1u);
}

// ---------------------------------------------------------------------------------------
// TRI-6: barycentrics and t in the app's vertex order

TEST(Intersection, TRI_6_BarycentricsFollowAppVertexOrder) {
    const vec3 v0(0, 0, 0), v1(4, 0, 0), v2(0, 4, 0);
    const vec3 p(1, 2, 0);  // weights: v0 0.25, v1 0.25, v2 0.5
    for (vec3 d : {vec3(0, 0, 1), vec3(0, 0, -1), vec3(0.5f, 0.25f, 1), vec3(1, 0.25f, 0.5f), vec3(-0.25f, -1, -0.5f)}) {
        const vec3 o = p - 2.0f * d;
        const auto h = intersectTriangle(o, d, v0, v1, v2);
        ASSERT_TRUE(h.has_value());
        EXPECT_NEAR(h->t, 2.0f, 1e-6);
        EXPECT_NEAR(h->barycentrics.x, 0.25f, 1e-6);  // weight of v1
        EXPECT_NEAR(h->barycentrics.y, 0.5f, 1e-6);   // weight of v2
        const auto r = intersectTriangle(o, d, v1, v2, v0);  // rotated: weights of v2, v0
        ASSERT_TRUE(r.has_value());
        EXPECT_NEAR(r->t, 2.0f, 1e-6);
        EXPECT_NEAR(r->barycentrics.x, 0.5f, 1e-6);
        EXPECT_NEAR(r->barycentrics.y, 0.25f, 1e-6);
        const auto s = intersectTriangle(o, d, v0, v2, v1);  // swapped: weights of v2, v1
        ASSERT_TRUE(s.has_value());
        EXPECT_NEAR(s->barycentrics.x, 0.5f, 1e-6);
        EXPECT_NEAR(s->barycentrics.y, 0.25f, 1e-6);
    }
}

TEST(Intersection, TRI_6_DispatchBarycentricsFollowAppVertexOrder) {
    Rig r;
    Mesh m;
    m.add(vec3(0, 0, 0), vec3(4, 0, 0), vec3(0, 4, 0));
    m.add(vec3(10, 4, 0), vec3(10, 0, 0), vec3(14, 0, 0));  // the same shape, rotated order
    r.scene(m, GEOMETRY_FLAG_OPAQUE);
    const auto& p = r.trace({RayDesc{vec3(1, 2, -3), 0, vec3(0, 0, 1), 100}, RayDesc{vec3(11, 2, 3), 0, vec3(0, 0, -1), 100}});
    EXPECT_FLOAT_EQ(p[0].t, 3.0f);
    EXPECT_NEAR(p[0].barycentrics.x, 0.25f, 1e-6);
    EXPECT_NEAR(p[0].barycentrics.y, 0.5f, 1e-6);
    EXPECT_EQ(p[1].primitiveIndex, 1u);
    EXPECT_FLOAT_EQ(p[1].t, 3.0f);
    EXPECT_NEAR(p[1].barycentrics.x, 0.25f, 1e-6);  // weight of (10,0,0)
    EXPECT_NEAR(p[1].barycentrics.y, 0.25f, 1e-6);  // weight of (14,0,0)
}

// ---------------------------------------------------------------------------------------
// TRV-2 for triangles: TMin < t < TCurrent, both ends open.

TEST(Intersection, TRV_2_TriangleAtExactlyTMinOrTMaxIsNotAHit) {
    const vec3 v0(-1, -1, 0), v1(0, 1, 0), v2(1, -1, 0);
    const auto h = intersectTriangle(vec3(0, 0, -5), vec3(0, 0, 1), v0, v1, v2);
    ASSERT_TRUE(h.has_value());
    ASSERT_EQ(h->t, 5.0f);  // exact, so the interval ends below are exact too
    Rig r;
    Mesh m;
    m.add(v0, v1, v2);
    r.scene(m, GEOMETRY_FLAG_OPAQUE);
    const float below = std::nextafter(5.0f, 0.0f), above = std::nextafter(5.0f, 10.0f);
    const auto& p = r.trace({
        RayDesc{vec3(0, 0, -5), 5.0f, vec3(0, 0, 1), 100.0f},  // t == TMin
        RayDesc{vec3(0, 0, -5), 0.0f, vec3(0, 0, 1), 5.0f},    // t == TMax
        RayDesc{vec3(0, 0, -5), 5.0f, vec3(0, 0, 1), 5.0f},    // TMin == TMax == t
        RayDesc{vec3(0, 0, -5), below, vec3(0, 0, 1), above},  // just inside
    });
    EXPECT_EQ(p[0].misses, 1u);
    EXPECT_EQ(p[1].misses, 1u);
    EXPECT_EQ(p[2].misses, 1u);
    EXPECT_EQ(p[3].closestHits, 1u);
    EXPECT_EQ(p[3].t, 5.0f);
}

TEST(Intersection, TRV_2_SecondTriangleAtCommittedTIsRejected) {
    // Two coincident opaque triangles: the first committed keeps the tie (TRV-3), and only one
    // commit happens; the AHS of a non-opaque copy never runs at t == TCurrent.
    Rig r;
    Mesh m;
    m.add(vec3(-1, -1, 0), vec3(0, 1, 0), vec3(1, -1, 0));
    m.add(vec3(-1, -1, 0), vec3(0, 1, 0), vec3(1, -1, 0));
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(m.v, GEOMETRY_FLAG_NONE)}))});
    const Probe p = r.trace({RayDesc{vec3(0, 0, -5), 0, vec3(0, 0, 1), 100}}, "HG_TriAH")[0];
    EXPECT_EQ(p.anyHits, 1u);
    EXPECT_EQ(p.closestHits, 1u);
}

// ---------------------------------------------------------------------------------------
// BLAS-7: the slab test is inclusive and NaN-free.

void expectSlab(const std::optional<SlabInterval>& s, float enter, float exit, const char* what) {
    ASSERT_TRUE(s.has_value()) << what;
    EXPECT_FALSE(std::isnan(s->tEnter) || std::isnan(s->tExit)) << what;
    EXPECT_EQ(s->tEnter, enter) << what;
    EXPECT_EQ(s->tExit, exit) << what;
}

TEST(Intersection, BLAS_7_SlabWithPlusAndMinusZeroDirectionComponents) {
    const RaytracingAABB box = unitBox();
    expectSlab(intersectAABB({0, 0, -5}, {0.0f, 0.0f, 1}, box, 0, 100), 4, 6, "+0 components");
    expectSlab(intersectAABB({0, 0, -5}, {-0.0f, -0.0f, 1}, box, 0, 100), 4, 6, "-0 components");
    expectSlab(intersectAABB({0, 0, 5}, {-0.0f, 0.0f, -1}, box, 0, kInf), 4, 6, "mixed zeros, infinite TMax");
    // Origin outside a slab with a zero component: no hit, whichever sign the zero has.
    EXPECT_FALSE(intersectAABB({1.5f, 0, -5}, {0.0f, 0, 1}, box, 0, 100).has_value());
    EXPECT_FALSE(intersectAABB({1.5f, 0, -5}, {-0.0f, 0, 1}, box, 0, 100).has_value());
    EXPECT_FALSE(intersectAABB({std::nextafter(1.0f, 2.0f), 0, -5}, {-0.0f, 0, 1}, box, 0, 100).has_value());
}

TEST(Intersection, BLAS_7_SlabOriginExactlyOnFaceIsInclusive) {
    const RaytracingAABB box = unitBox();
    // On the face, parallel to it (zero component): inside.
    expectSlab(intersectAABB({1, 0, -5}, {0.0f, 0, 1}, box, 0, 100), 4, 6, "on +x face, +0");
    expectSlab(intersectAABB({-1, 0, -5}, {-0.0f, 0, 1}, box, 0, 100), 4, 6, "on -x face, -0");
    expectSlab(intersectAABB({-5, 1, 1}, {1, 0, -0.0f}, box, 0, 100), 4, 6, "along an edge");
    // On the face, moving in: enters at t = 0.
    expectSlab(intersectAABB({-1, 0, 0}, {1, 0, 0}, box, 0, 100), 0, 2, "on -x face, moving in");
    // On the face, moving out: touches at t = 0 only.
    expectSlab(intersectAABB({1, 0, 0}, {1, 0, 0}, box, 0, 100), 0, 0, "on +x face, moving out");
    EXPECT_FALSE(intersectAABB({1, 0, 0}, {1, 0, 0}, box, 0.5f, 100).has_value());
    // Touching the box exactly at TMax, and exactly at TMin.
    expectSlab(intersectAABB({-3, 0, 0}, {1, 0, 0}, box, 0, 2), 2, 2, "entry at TMax");
    expectSlab(intersectAABB({-3, 0, 0}, {1, 0, 0}, box, 4, 10), 4, 4, "exit at TMin");
    EXPECT_FALSE(intersectAABB({-3, 0, 0}, {1, 0, 0}, box, 0, std::nextafter(2.0f, 0.0f)).has_value());
    // A point-sized box hit exactly.
    expectSlab(intersectAABB({0.5f, 0.5f, -1}, {0, 0, 1}, {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}, 0, 100), 1.5f, 1.5f, "point box");
}

TEST(Intersection, BLAS_7_SlabNeverProducesNaNForAxisRays) {
    // Every combination of signed-zero components with a unit axis, origins on the faces.
    const RaytracingAABB box = unitBox();
    const float zeros[2] = {0.0f, -0.0f};
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {1.0f, -1.0f})
            for (float za : zeros)
                for (float zb : zeros)
                    for (float face : {-1.0f, 0.0f, 1.0f}) {
                        vec3 d(0.0f);
                        d[axis] = sign;
                        d[(axis + 1) % 3] = za;
                        d[(axis + 2) % 3] = zb;
                        vec3 o(face, face, face);
                        o[axis] = -4.0f * sign;
                        const auto s = intersectAABB(o, d, box, 0, kInf);
                        ASSERT_TRUE(s.has_value());
                        EXPECT_EQ(s->tEnter, 3.0f);
                        EXPECT_EQ(s->tExit, 5.0f);
                    }
}

}  // namespace
}  // namespace refray::test
