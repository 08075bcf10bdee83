// The traversal shortcuts (DispatchOptions::specialise, detail::GatherMode): which rays take which, and that
// they change no result, no invocation count and no diagnostic compared with gathering every candidate.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "emulator/trace.h"
#include "harness.h"

namespace refray::test {
namespace {

constexpr size_t kAll = 0, kClosest = 1, kFirstHit = 2;

// Ten parallel walls z = 1..10 (opaque unless `nonOpaqueFront`: then the nearest is non-opaque), a unit box at
// z = 0 in front of them for half the rays (x < 0) and one at z = 20 behind them; rays along +z from z = -5
// over x in [-2, 2).
class Stack {
public:
    Stack(bool anyHitInPipeline, bool nonOpaqueFront, Harness::TraceArgs args) {
        h.addProbeShaders();
        if (!anyHitInPipeline)
            std::erase_if(h.stateObject.hitGroups, [](const HitGroupDesc& g) { return !g.AnyHitShaderImport.empty(); });
        h.addTracingRayGen(
            [](uvec3 i) {
                return RayDesc{vec3(-2.0f + 0.25f * float(i.x) + 0.125f, 0.1f * float(i.y) - 0.3f, -5.0f), 0.0f,
                               vec3(0.0f, 0.0f, 1.0f), 100.0f};
            },
            args, results);
        std::vector<vec3> walls;
        for (int z = 1; z <= 10; ++z) {
            const float fz = float(z);
            walls.insert(walls.end(), {{-9, -9, fz}, {9, -9, fz}, {-9, 9, fz}, {9, -9, fz}, {9, 9, fz}, {-9, 9, fz}});
        }
        std::vector<GeometryDesc> geometries;
        if (nonOpaqueFront) {
            geometries.push_back(h.triangles(std::vector<vec3>(walls.begin(), walls.begin() + 6), GEOMETRY_FLAG_NONE));
            geometries.push_back(h.triangles(std::vector<vec3>(walls.begin() + 6, walls.end())));
        } else {
            geometries.push_back(h.triangles(walls));
        }
        const GpuVirtualAddress wallBLAS = h.blas(geometries);
        const GpuVirtualAddress boxBLAS = h.blas({h.aabbs({unitBox()})});
        const bool twoGeometries = geometries.size() == 2;
        h.tlas({Harness::instance(wallBLAS, 0),
                Harness::instance(boxBLAS, twoGeometries ? 2 : 1, Matrix3x4::translation(vec3(-1.5f, 0, 0))),
                Harness::instance(boxBLAS, twoGeometries ? 2 : 1, Matrix3x4::translation(vec3(1.5f, 0, 20)))});
        so = h.pipeline();
        miss = h.table(so, {"Miss_Probe"});
        const std::string frontGroup = anyHitInPipeline && nonOpaqueFront ? "HG_TriAH" : "HG_Tri";
        hitGroups = twoGeometries ? h.table(so, {frontGroup, "HG_Tri", "HG_Box"}) : h.table(so, {"HG_Tri", "HG_Box"});
    }

    DispatchResult run(DispatchOptions options) {
        results.assign(16 * 7, Probe{});
        return h.dispatch(so, miss, hitGroups, uvec3(16, 7, 1), options);
    }

    Harness h;
    std::vector<Probe> results;
    StateObjectPtr so;
    GpuVirtualAddressRangeAndStride miss, hitGroups;
};

// Runs with and without the shortcuts; every probe value and invocation count must agree. An occlusion query
// meets candidates in Embree's order and stops at the first hit, so it may run fewer intersection shaders:
// `sameIntersections` false compares the other stages only.
struct Both {
    DispatchStats with, without;
};
Both runBoth(Stack& s, DispatchOptions options = {}, bool sameIntersections = true) {
    options.specialise = false;
    Both b;
    b.without = s.run(options).stats;
    const std::vector<Probe> reference = s.results;
    options.specialise = true;
    b.with = s.run(options).stats;
    for (size_t i = 0; i < reference.size(); ++i) {
        SCOPED_TRACE("launch " + std::to_string(i));
        EXPECT_EQ(s.results[i].t, reference[i].t);
        EXPECT_EQ(s.results[i].instanceIndex, reference[i].instanceIndex);
        EXPECT_EQ(s.results[i].geometryIndex, reference[i].geometryIndex);
        EXPECT_EQ(s.results[i].primitiveIndex, reference[i].primitiveIndex);
        EXPECT_EQ(s.results[i].closestHits, reference[i].closestHits);
        EXPECT_EQ(s.results[i].misses, reference[i].misses);
        EXPECT_EQ(s.results[i].anyHits, reference[i].anyHits);
    }
    for (size_t stage = 0; stage < b.with.invocations.size(); ++stage) {
        if (sameIntersections || ShaderStage(stage) != ShaderStage::Intersection) {
            EXPECT_EQ(b.with.invocations[stage], b.without.invocations[stage]) << toString(ShaderStage(stage));
        }
    }
    EXPECT_EQ(b.with.raysTraced, b.without.raysTraced);
    EXPECT_EQ(b.without.raysPerGatherMode[kAll], b.without.raysTraced);
    return b;
}

}  // namespace

// Closest: the nearest opaque wall bounds the gather, so the nine walls behind it and the far box are never
// candidates; the near box's intersection shader still runs first.
TEST(TraversalShortcuts, NearestOpaqueTriangleBoundsTheGather) {
    Stack s(/*anyHitInPipeline*/ true, /*nonOpaqueFront*/ false, {});
    const Both b = runBoth(s);
    EXPECT_EQ(b.with.raysPerGatherMode[kClosest], b.with.raysTraced);
    EXPECT_EQ(b.with.raysPerGatherMode[kFirstHit], 0u);
    EXPECT_GT(b.with.invocationsOf(ShaderStage::Intersection), 0u);
    // Without shortcuts: 20 wall triangles in reach per ray (two per wall; rays meet one of each pair, plus
    // edge sharers), with them only the first wall's.
    EXPECT_LT(b.with.candidates * 4, b.without.candidates);
}

// With an any-hit shader on the non-opaque front wall, only opaque walls may bound the gather: the front
// wall's AHS still runs for every ray that reaches it (the 10 columns of rays that miss the near box),
// exactly as often as without shortcuts.
TEST(TraversalShortcuts, NonOpaqueTrianglesWithAnyHitDoNotBoundTheGather) {
    Stack s(/*anyHitInPipeline*/ true, /*nonOpaqueFront*/ true, {});
    const Both b = runBoth(s);
    EXPECT_EQ(b.with.invocationsOf(ShaderStage::AnyHit), b.without.invocationsOf(ShaderStage::AnyHit));
    EXPECT_EQ(b.with.invocationsOf(ShaderStage::AnyHit), 10u * 7u);
    EXPECT_LT(b.with.candidates, b.without.candidates);
}

// Without any-hit shaders in the pipeline, a non-opaque triangle commits whenever reached: it bounds the gather.
TEST(TraversalShortcuts, WithoutAnyHitEveryTriangleBoundsTheGather) {
    Stack withAHS(/*anyHitInPipeline*/ true, /*nonOpaqueFront*/ true, {});
    Stack withoutAHS(/*anyHitInPipeline*/ false, /*nonOpaqueFront*/ true, {});
    const Both a = runBoth(withAHS), b = runBoth(withoutAHS);
    EXPECT_LT(b.with.candidates, a.with.candidates);
}

// Shadow-ray flags in a pipeline without any-hit shaders: an occlusion query (rtcOccluded1) that stops at the
// first hit. Every ray is occluded either way; the query may skip intersection shaders the ordered loop runs
// (here the near box's: Embree meets the wall first), and its counts do not depend on the thread count. With an
// any-hit shader anywhere in the pipeline, never.
TEST(TraversalShortcuts, OcclusionQueryOnlyWithoutAnyHitShaders) {
    const Harness::TraceArgs shadow{RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER};
    Stack noAHS(/*anyHitInPipeline*/ false, /*nonOpaqueFront*/ false, shadow);
    const Both b = runBoth(noAHS, {}, /*sameIntersections*/ false);
    EXPECT_EQ(b.with.raysPerGatherMode[kFirstHit], b.with.raysTraced);
    EXPECT_EQ(b.with.invocationsOf(ShaderStage::Miss), 0u);  // every ray hits a wall
    EXPECT_LE(b.with.invocationsOf(ShaderStage::Intersection), b.without.invocationsOf(ShaderStage::Intersection));
    EXPECT_LE(b.with.candidates, b.with.raysTraced * 2);  // one wall triangle, maybe the near box first
    for (uint32_t threads : {1u, 2u, 5u}) {
        DispatchOptions options;
        options.threads = threads;
        options.tileSize = 3;
        const DispatchStats st = noAHS.run(options).stats;
        EXPECT_EQ(st.invocations, b.with.invocations) << threads << " threads";
        EXPECT_EQ(st.candidates, b.with.candidates) << threads << " threads";
    }

    Stack withAHS(/*anyHitInPipeline*/ true, /*nonOpaqueFront*/ false, shadow);
    const Both c = runBoth(withAHS);
    EXPECT_EQ(c.with.raysPerGatherMode[kFirstHit], 0u);
    EXPECT_EQ(c.with.raysPerGatherMode[kClosest], c.with.raysTraced);
}

// Accept-first rays that still run their closest hit keep the ordered loop: the nearest candidate commits.
TEST(TraversalShortcuts, AcceptFirstWithClosestHitKeepsTheOrder) {
    Stack s(/*anyHitInPipeline*/ false, /*nonOpaqueFront*/ false, {RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH});
    const Both b = runBoth(s);
    EXPECT_EQ(b.with.raysPerGatherMode[kFirstHit], 0u);
    EXPECT_EQ(b.with.raysPerGatherMode[kClosest], b.with.raysTraced);
}

// Observed rays and adversarial order gather everything: explain and the order check see every candidate.
TEST(TraversalShortcuts, ObserverAndAdversarialOrderGatherEverything) {
    struct Count : TraceObserver {
        void onEvent(const TraceEvent& e) override {
            if (e.kind == TraceEvent::Kind::Candidate) ++candidates;
        }
        std::atomic<uint64_t> candidates{0};
    } observer;
    Stack s(/*anyHitInPipeline*/ false, /*nonOpaqueFront*/ false, {});
    DispatchOptions observed;
    observed.observer = &observer;
    const DispatchStats st = s.run(observed).stats;
    EXPECT_EQ(st.raysPerGatherMode[kAll], st.raysTraced);
    EXPECT_EQ(observer.candidates.load(), st.candidates);

    DispatchOptions adversarial;
    adversarial.order = TraversalOrder::Adversarial;
    adversarial.adversarialSeed = 3;
    const DispatchStats sa = s.run(adversarial).stats;
    EXPECT_EQ(sa.raysPerGatherMode[kAll], sa.raysTraced);
}

}  // namespace refray::test
