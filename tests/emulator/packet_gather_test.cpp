// The packet gather (detail::gatherCandidatesPacket, emulator/embree_bridge.h): the rays of a wave traverse as one
// Embree packet, and each must get exactly the candidates it gets alone (gatherCandidates), whatever rays share its
// packet, in mode All and in mode Closest (whose interval shrinks to the nearest sure commit as Embree meets
// triangles, in an order that differs between one ray and a packet). Seeded random rays, with instance masks,
// skipped geometry kinds, a nonzero TMin and finite and infinite TMax, against a TLAS of transformed instances of
// triangles and boxes; packets of every size 1..16.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <exception>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "emulator/embree_bridge.h"
#include "harness.h"

namespace refray::test {
namespace {

namespace detail = dxr::detail;
using detail::Candidate;
using detail::GatherMode;
using detail::GatherRequest;

float uniform(std::mt19937& rng, float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); }

// Random triangles and random boxes, each BLAS under three instances: rotated, scaled, translated, with masks
// 0x01, 0x02 and 0xFF.
struct Scene {
    Harness h;
    const dxr::TopLevelAS* tlas = nullptr;

    Scene() {
        std::mt19937 rng(2026);
        std::vector<vec3> triangles;
        for (int i = 0; i < 60; ++i) {
            const vec3 c(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -3, 3));
            for (int k = 0; k < 3; ++k)
                triangles.push_back(c + vec3(uniform(rng, -0.8f, 0.8f), uniform(rng, -0.8f, 0.8f), uniform(rng, -0.8f, 0.8f)));
        }
        std::vector<RaytracingAABB> boxes;
        for (int i = 0; i < 30; ++i) {
            const float x = uniform(rng, -3, 3), y = uniform(rng, -3, 3), z = uniform(rng, -3, 3);
            const float s = uniform(rng, 0.1f, 0.7f);
            boxes.push_back({x - s, y - s, z - s, x + s, y + s, z + s});
        }
        // A BLAS holds one kind of geometry (BLAS-1): triangles in two geometries, and boxes.
        const GpuVirtualAddress tris = h.blas({h.triangles({triangles.begin(), triangles.begin() + 90}),
                                              h.triangles({triangles.begin() + 90, triangles.end()})});
        const GpuVirtualAddress procedural = h.blas({h.aabbs(boxes)});
        const GpuVirtualAddress address = h.tlas({
            Harness::instance(tris),
            Harness::instance(procedural),
            Harness::instance(tris, 0, Matrix3x4::translation(vec3(7, 0, 0)), 0x01),
            Harness::instance(procedural, 0, Matrix3x4::rotation(glm::normalize(vec3(1, 2, 3)), 0.7f), 0x02),
            Harness::instance(tris, 0, Matrix3x4::scale(vec3(2, 0.5f, 1.5f))),
            Harness::instance(procedural, 0, Matrix3x4::translation(vec3(0, 0, 9))),
        });
        tlas = h.device.findTopLevelAS(address);
    }
};

// What a request's traversal-shortcut callback sees: whether a triangle is sure to commit (here: even primitive
// indices, so that Closest shrinks the interval for some triangles and not others), and a ray whose callback throws.
struct Shortcut {
    bool throws = false;
};
bool evenPrimitivesCommit(const void* user, const Candidate& c) {
    if (static_cast<const Shortcut*>(user)->throws) throw std::runtime_error("the shortcut failed");
    return c.primitiveIndex % 2 == 0;
}

struct Ray {
    GatherRequest request;
    Shortcut shortcut;
};

std::vector<Ray> randomRays(const dxr::TopLevelAS* tlas, GatherMode mode, uint32_t seed, int count) {
    std::mt19937 rng(seed);
    std::vector<Ray> rays(static_cast<size_t>(count));
    for (Ray& r : rays) {
        GatherRequest& q = r.request;
        q.tlas = tlas;
        q.origin = vec3(uniform(rng, -6, 12), uniform(rng, -6, 6), uniform(rng, -6, 14));
        const vec3 towards(uniform(rng, -3, 10), uniform(rng, -3, 3), uniform(rng, -3, 11));
        q.direction = glm::normalize(towards - q.origin) * uniform(rng, 0.5f, 2.0f);  // not unit: t is scaled
        q.tMin = rng() % 3 == 0 ? uniform(rng, 0, 2) : 0.0f;
        q.tMax = rng() % 4 == 0 ? INFINITY : uniform(rng, 4, 30);
        const uint32_t masks[] = {0xFF, 0x01, 0x02, 0xFE};
        q.instanceInclusionMask = masks[rng() % 4];
        q.skipTriangles = rng() % 8 == 0;
        q.skipProcedural = !q.skipTriangles && rng() % 8 == 0;
        q.mode = mode;
        q.commitsSurely = evenPrimitivesCommit;
    }
    return rays;
}

// A ray's candidates as bits, in one order, without Embree's duplicate reports (the dispatcher drops those, AHS-6).
using Key = std::tuple<uint32_t, uint32_t, uint32_t, bool, uint32_t, uint32_t, uint32_t, uint32_t, uint32_t, uint32_t,
                       uint32_t, uint32_t, uint32_t, uint32_t>;
std::vector<Key> keys(const std::vector<Candidate>& cs) {
    std::vector<Key> out;
    for (const Candidate& c : cs)
        out.emplace_back(c.instanceIndex, c.geometryIndex, c.primitiveIndex, c.procedural, std::bit_cast<uint32_t>(c.key),
                         std::bit_cast<uint32_t>(c.t), std::bit_cast<uint32_t>(c.barycentrics.x),
                         std::bit_cast<uint32_t>(c.barycentrics.y), std::bit_cast<uint32_t>(c.objectRayOrigin.x),
                         std::bit_cast<uint32_t>(c.objectRayOrigin.y), std::bit_cast<uint32_t>(c.objectRayOrigin.z),
                         std::bit_cast<uint32_t>(c.objectRayDirection.x), std::bit_cast<uint32_t>(c.objectRayDirection.y),
                         std::bit_cast<uint32_t>(c.objectRayDirection.z));
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

// Each ray alone, then the same rays in packets of 1, 2, .., 16, 1, ..: per ray, the candidates of the two.
// Returns the candidates the rays got alone, in all.
size_t expectPacketsGiveEachRayItsOwn(std::vector<Ray>& rays) {
    std::vector<std::vector<Candidate>> alone(rays.size()), packed(rays.size());
    size_t total = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        rays[i].request.user = &rays[i].shortcut;
        rays[i].request.out = &alone[i];
        detail::gatherCandidates(rays[i].request);
        total += keys(alone[i]).size();
    }
    size_t first = 0;
    for (size_t size = 1; first < rays.size(); size = size % size_t(detail::kMaxGatherPacket) + 1) {
        const size_t n = std::min(size, rays.size() - first);
        std::array<const GatherRequest*, detail::kMaxGatherPacket> requests{};
        std::array<std::exception_ptr, detail::kMaxGatherPacket> errors{};
        for (size_t k = 0; k < n; ++k) {
            rays[first + k].request.out = &packed[first + k];
            requests[k] = &rays[first + k].request;
        }
        detail::gatherCandidatesPacket(std::span(requests.data(), n), std::span(errors.data(), n));
        for (size_t k = 0; k < n; ++k) {
            EXPECT_FALSE(errors[k]) << "ray " << first + k;
            EXPECT_EQ(keys(packed[first + k]), keys(alone[first + k]))
                << "ray " << first + k << " in a packet of " << n << " (mode " << int(rays[first].request.mode) << ")";
        }
        first += n;
    }
    return total;
}

TEST(PacketGather, EveryRayGetsTheCandidatesItGetsAloneInModeAll) {
    Scene scene;
    std::vector<Ray> rays = randomRays(scene.tlas, GatherMode::All, 7, 400);
    EXPECT_GT(expectPacketsGiveEachRayItsOwn(rays), 250u);
}

TEST(PacketGather, EveryRayGetsTheCandidatesItGetsAloneInModeClosest) {
    Scene scene;
    std::vector<Ray> all = randomRays(scene.tlas, GatherMode::All, 8, 400);
    std::vector<Ray> closest = randomRays(scene.tlas, GatherMode::Closest, 8, 400);
    const size_t everyCandidate = expectPacketsGiveEachRayItsOwn(all);
    const size_t bounded = expectPacketsGiveEachRayItsOwn(closest);
    // The shortcut took effect: the sure commits cut candidates off behind them.
    EXPECT_LT(bounded, everyCandidate);
    EXPECT_GT(bounded, everyCandidate / 4);
}

TEST(PacketGather, AFailingRayStopsAloneAndTheOthersGoOn) {
    Scene scene;
    std::vector<Ray> rays = randomRays(scene.tlas, GatherMode::Closest, 9, 16);
    std::vector<std::vector<Candidate>> alone(rays.size()), packed(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
        rays[i].request.user = &rays[i].shortcut;
        rays[i].request.out = &alone[i];
        detail::gatherCandidates(rays[i].request);
    }
    // Make the first ray that meets a triangle (its shortcut callback runs) throw.
    size_t failing = rays.size();
    for (size_t i = 0; i < rays.size() && failing == rays.size(); ++i)
        for (const Candidate& c : alone[i])
            if (!c.procedural) failing = i;
    ASSERT_LT(failing, rays.size()) << "no ray of the seed meets a triangle";
    rays[failing].shortcut.throws = true;
    std::array<const GatherRequest*, detail::kMaxGatherPacket> requests{};
    std::array<std::exception_ptr, detail::kMaxGatherPacket> errors{};
    for (size_t k = 0; k < rays.size(); ++k) {
        rays[k].request.out = &packed[k];
        requests[k] = &rays[k].request;
    }
    detail::gatherCandidatesPacket(std::span(requests.data(), rays.size()), std::span(errors.data(), rays.size()));
    for (size_t k = 0; k < rays.size(); ++k) {
        if (k == failing) {
            ASSERT_TRUE(errors[k]);
            EXPECT_THROW(std::rethrow_exception(errors[k]), std::runtime_error);
            continue;
        }
        EXPECT_FALSE(errors[k]) << "ray " << k;
        EXPECT_EQ(keys(packed[k]), keys(alone[k])) << "ray " << k;
    }
    // Alone, the failing ray's gather throws what its callback threw.
    rays[failing].request.out = &alone[failing];
    EXPECT_THROW(detail::gatherCandidates(rays[failing].request), std::runtime_error);
}

}  // namespace
}  // namespace refray::test
