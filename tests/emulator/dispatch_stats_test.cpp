// Statistics of a dispatch (emulator/dispatch_stats.h): counts per ray type x depth and per export, checked
// against hand counts on tiny scenes; their independence of threads, tiles and finishing order; and the
// exclusive stage times of DispatchOptions::profileStages.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "harness.h"

namespace refray::test {
namespace {

using std::chrono::microseconds;

struct Payload {
    uint32_t hits = 0;
};

void spin(microseconds duration) {
    const auto end = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < end) {
    }
}

// Rays along +z from (x*step, y*step, -10) + offset. A non-opaque triangle around the origin (with an any-hit
// shader), and a unit box moved to x = 8; optionally a large non-opaque wall behind both at z = 2.
// Records [primary, secondary] per geometry (M = 2): the triangles use C = 0, the box C = 2; the secondary
// records are NULL. Every closest-hit shader traces one secondary ray (R = 1, miss 1) back the way the
// primary came, which misses everything.
class StatsScene {
public:
    struct Setup {
        float step = 4.0f;
        vec2 offset{0.0f};
        bool wall = false;
        microseconds closestHitSpin{0};
        microseconds secondaryMissSpin{0};
    };

    explicit StatsScene(Setup setup) {
        auto& lib = *h.library;
        lib.addRayGeneration("RG_Stats", [this, setup](ShaderContext& ctx) {
            const uvec3 i = ctx.DispatchRaysIndex();
            const RayDesc ray{vec3(float(i.x) * setup.step + setup.offset.x, float(i.y) * setup.step + setup.offset.y, -10.0f),
                              0.0f, vec3(0.0f, 0.0f, 1.0f), 100.0f};
            Payload p;
            ctx.TraceRay(h.scene, RAY_FLAG_NONE, 0xFF, 0, 2, 0, ray, p);
        });
        auto secondary = [this, setup](ShaderContext& ctx, Payload& p) {
            spin(setup.closestHitSpin);
            const RayDesc back{ctx.WorldRayOrigin(), 0.0f, -ctx.WorldRayDirection(), 100.0f};
            Payload s;
            ctx.TraceRay(h.scene, RAY_FLAG_NONE, 0xFF, 1, 2, 1, back, s);
            p.hits++;
        };
        lib.addClosestHit<Payload, BuiltInTriangleIntersectionAttributes>(
            "CH_Triangle", [secondary](ShaderContext& ctx, Payload& p, const BuiltInTriangleIntersectionAttributes&) {
                secondary(ctx, p);
            });
        lib.addClosestHit<Payload, ProbeAttributes>(
            "CH_Box", [secondary](ShaderContext& ctx, Payload& p, const ProbeAttributes&) { secondary(ctx, p); });
        lib.addAnyHit<Payload, BuiltInTriangleIntersectionAttributes>(
            "AH_Triangle", [](ShaderContext&, Payload&, const BuiltInTriangleIntersectionAttributes&) {});
        lib.addMiss<Payload>("Miss_Primary", [](ShaderContext&, Payload&) {});
        lib.addMiss<Payload>("Miss_Secondary", [setup](ShaderContext&, Payload&) { spin(setup.secondaryMissSpin); });
        h.addProbeShaders();  // IS_Box: reports the unit box's entry t
        h.stateObject.hitGroups.push_back({"HG_Triangle", HitGroupType::Triangles, "AH_Triangle", "CH_Triangle", ""});
        h.stateObject.hitGroups.push_back({"HG_StatsBox", HitGroupType::ProceduralPrimitive, "", "CH_Box", "IS_Box"});

        std::vector<vec3> triangles{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
        if (setup.wall) triangles.insert(triangles.end(), {{-20, -20, 2}, {60, -20, 2}, {-20, 60, 2}});
        const GpuVirtualAddress triangleBLAS = h.blas({h.triangles(triangles, GEOMETRY_FLAG_NONE)});
        const GpuVirtualAddress boxBLAS = h.blas({h.aabbs({unitBox()})});
        h.tlas({Harness::instance(triangleBLAS, 0), Harness::instance(boxBLAS, 2, Matrix3x4::translation(vec3(8, 0, 0)))});
        so = h.pipeline();
        miss = h.table(so, {"Miss_Primary", "Miss_Secondary"});
        hitGroups = h.table(so, {"HG_Triangle", "", "HG_StatsBox", ""});
    }

    DispatchResult run(uvec3 dims, DispatchOptions options = {}) {
        return h.dispatch(so, miss, hitGroups, dims, options, nullptr, {}, "RG_Stats");
    }

    Harness h;
    StateObjectPtr so;
    GpuVirtualAddressRangeAndStride miss, hitGroups;
};

constexpr RayTypeKey kPrimary{0, 0};
constexpr RayTypeKey kSecondary{1, 1};

void expectSameCounts(const DispatchStats& a, const DispatchStats& b, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_EQ(a.raysTraced, b.raysTraced);
    EXPECT_EQ(a.raysPerDepth, b.raysPerDepth);
    EXPECT_EQ(a.invocations, b.invocations);
    EXPECT_EQ(a.candidates, b.candidates);
    ASSERT_EQ(a.raysPerType.size(), b.raysPerType.size());
    for (size_t i = 0; i < a.raysPerType.size(); ++i) {
        EXPECT_EQ(a.raysPerType[i].key, b.raysPerType[i].key) << i;
        EXPECT_EQ(a.raysPerType[i].raysPerDepth, b.raysPerType[i].raysPerDepth) << i;
    }
    ASSERT_EQ(a.invocationsPerExport.size(), b.invocationsPerExport.size());
    for (size_t i = 0; i < a.invocationsPerExport.size(); ++i) {
        EXPECT_EQ(a.invocationsPerExport[i].exportName, b.invocationsPerExport[i].exportName) << i;
        EXPECT_EQ(a.invocationsPerExport[i].stage, b.invocationsPerExport[i].stage) << i;
        EXPECT_EQ(a.invocationsPerExport[i].count, b.invocationsPerExport[i].count) << i;
    }
}

}  // namespace

// 4x2 rays 4 apart: launch (0,0) hits the triangle (its AHS runs: the triangle is non-opaque), launch (2,0)
// hits the box; the other six miss. Each hit traces one secondary ray at depth 2, which misses.
TEST(DispatchStats, CountsPerExportAndRayTypeMatchAHandCount) {
    StatsScene scene({});
    const DispatchStats st = scene.run(uvec3(4, 2, 1)).stats;

    EXPECT_EQ(st.invocationsOf("RG_Stats", ShaderStage::RayGeneration), 8u);
    EXPECT_EQ(st.invocationsOf("IS_Box", ShaderStage::Intersection), 1u);
    EXPECT_EQ(st.invocationsOf("AH_Triangle", ShaderStage::AnyHit), 1u);
    EXPECT_EQ(st.invocationsOf("CH_Triangle", ShaderStage::ClosestHit), 1u);
    EXPECT_EQ(st.invocationsOf("CH_Box", ShaderStage::ClosestHit), 1u);
    EXPECT_EQ(st.invocationsOf("Miss_Primary", ShaderStage::Miss), 6u);
    EXPECT_EQ(st.invocationsOf("Miss_Secondary", ShaderStage::Miss), 2u);
    EXPECT_EQ(st.invocationsOf("CH_Probe", ShaderStage::ClosestHit), 0u);  // exported, never run
    EXPECT_EQ(st.invocationsOf("Miss_Primary", ShaderStage::ClosestHit), 0u);
    ASSERT_EQ(st.invocationsPerExport.size(), 7u);  // only what ran, sorted by stage, then name
    EXPECT_EQ(st.invocationsPerExport[0].exportName, "RG_Stats");
    EXPECT_EQ(st.invocationsPerExport[3].exportName, "CH_Box");
    EXPECT_EQ(st.invocationsPerExport[4].exportName, "CH_Triangle");
    EXPECT_EQ(st.invocationsPerExport[6].exportName, "Miss_Secondary");

    // The per-stage totals agree with the per-export counts.
    EXPECT_EQ(st.invocationsOf(ShaderStage::RayGeneration), 8u);
    EXPECT_EQ(st.invocationsOf(ShaderStage::Intersection), 1u);
    EXPECT_EQ(st.invocationsOf(ShaderStage::AnyHit), 1u);
    EXPECT_EQ(st.invocationsOf(ShaderStage::ClosestHit), 2u);
    EXPECT_EQ(st.invocationsOf(ShaderStage::Miss), 8u);

    // Rays per (R, miss) x depth.
    ASSERT_EQ(st.raysPerType.size(), 2u);
    EXPECT_EQ(st.raysPerType[0].key, kPrimary);
    EXPECT_EQ(st.raysPerType[0].raysPerDepth, (std::vector<uint64_t>{0, 8}));
    EXPECT_EQ(st.raysPerType[1].key, kSecondary);
    EXPECT_EQ(st.raysPerType[1].raysPerDepth, (std::vector<uint64_t>{0, 0, 2}));
    EXPECT_EQ(st.raysOfType(kPrimary, 1), 8u);
    EXPECT_EQ(st.raysOfType(kSecondary, 2), 2u);
    EXPECT_EQ(st.raysOfType(kSecondary, 1), 0u);
    EXPECT_EQ(st.raysOfType(RayTypeKey{0, 1}), nullptr);
    EXPECT_EQ(st.raysOfType(kSecondary)->total(), 2u);
    EXPECT_EQ(st.raysTraced, 10u);
    EXPECT_EQ(st.raysPerDepth, (std::vector<uint64_t>{0, 8, 2}));
    EXPECT_EQ(st.candidates, 2u);  // the triangle for (0,0), the box for (2,0)
}

// IDX-2, IDX-7: a ray type is keyed by the bits the indexing rule uses.
TEST(DispatchStats, RayTypeKeyKeepsOnlyTheBitsTheRuleUses) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen([](uvec3) { return RayDesc{vec3(0, 0, -5), 0.0f, vec3(0, 0, 1), 100.0f}; },
                       {RAY_FLAG_NONE, 0xFF, 0x31, 1, 0x20001}, results);
    h.tlas({Harness::instance(h.blas({h.triangles({{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}})}))});
    const StateObjectPtr so = h.pipeline();
    const DispatchResult r = h.dispatch(so, h.table(so, {"Miss_Probe", "Miss_Probe"}), h.table(so, {"HG_Tri", "HG_Tri"}));
    ASSERT_EQ(r.stats.raysPerType.size(), 1u);
    EXPECT_EQ(r.stats.raysPerType[0].key, (RayTypeKey{1, 1}));
    EXPECT_EQ(toString(r.stats.raysPerType[0].key), "R=1 miss=1");
    EXPECT_EQ(results[0].closestHits, 1u);
}

// DET-1: counts depend on the scene, settings and order, never on threads, tiles or which tile ends first.
TEST(DispatchStats, CountsDoNotDependOnThreadsTilesOrOrder) {
    StatsScene scene({.step = 0.5f, .offset = vec2(-2.0f), .wall = true});
    const uvec3 dims(32, 16, 1);
    for (const TraversalOrder order : {TraversalOrder::Ordered, TraversalOrder::Adversarial}) {
        DispatchOptions one;
        one.threads = 1;
        one.order = order;
        one.adversarialSeed = 7;
        DispatchOptions four = one;
        four.threads = 4;
        four.tileSize = 1;
        DispatchOptions profiled = four;
        profiled.tileSize = 3;
        profiled.profileStages = true;
        const DispatchStats reference = scene.run(dims, one).stats;
        const std::string name = order == TraversalOrder::Ordered ? "ordered" : "adversarial";
        expectSameCounts(reference, scene.run(dims, four).stats, name + ", 4 threads, tile 1");
        expectSameCounts(reference, scene.run(dims, profiled).stats, name + ", 4 threads, tile 3, profiled");
        EXPECT_EQ(reference.raysOfType(kPrimary, 1), 32u * 16u);
        EXPECT_EQ(reference.invocationsOf("RG_Stats", ShaderStage::RayGeneration), 32u * 16u);
        EXPECT_GT(reference.invocationsOf("IS_Box", ShaderStage::Intersection), 0u);
        EXPECT_EQ(reference.raysOfType(kSecondary, 2),
                  reference.invocationsOf("CH_Triangle", ShaderStage::ClosestHit) +
                      reference.invocationsOf("CH_Box", ShaderStage::ClosestHit));
    }
    // The adversarial order presents the wall before the triangle and box in front of it: more any-hit calls.
    DispatchOptions adversarial;
    adversarial.order = TraversalOrder::Adversarial;
    adversarial.adversarialSeed = 7;
    EXPECT_GT(scene.run(dims, adversarial).stats.invocationsOf(ShaderStage::AnyHit),
              scene.run(dims).stats.invocationsOf(ShaderStage::AnyHit));
}

TEST(DispatchStats, StageTimesAreZeroWithoutProfiling) {
    StatsScene scene({.step = 0.5f, .offset = vec2(-2.0f), .wall = true});
    const DispatchStats st = scene.run(uvec3(32, 16, 1)).stats;
    EXPECT_FALSE(st.stagesProfiled);
    for (size_t i = 0; i < kProfileStageCount; ++i) EXPECT_EQ(st.stageSeconds[i], 0.0) << toString(ProfileStage(i));
    EXPECT_EQ(st.profiledSeconds(), 0.0);
}

TEST(DispatchStats, StageTimesArePositiveAndWithinThreadsTimesWallTime) {
    StatsScene scene({.step = 0.5f, .offset = vec2(-2.0f), .wall = true});
    DispatchOptions options;
    options.threads = 4;
    options.tileSize = 4;
    options.profileStages = true;
    const DispatchResult r = scene.run(uvec3(32, 16, 1), options);
    const DispatchStats& st = r.stats;
    EXPECT_TRUE(st.stagesProfiled);
    for (const ProfileStage s : {ProfileStage::RayGeneration, ProfileStage::Intersection, ProfileStage::AnyHit,
                                 ProfileStage::ClosestHit, ProfileStage::Miss, ProfileStage::Traversal})
        EXPECT_GT(st.secondsIn(s), 0.0) << toString(s);
    EXPECT_EQ(st.secondsIn(ProfileStage::Callable), 0.0);  // no callable shader ran
    EXPECT_GT(st.profiledSeconds(), 0.0);
    EXPECT_LE(st.profiledSeconds(), 4.0 * r.seconds * 1.1);
}

// A closest-hit shader's time excludes the ray it traces: that ray's miss shader (and traversal) keep theirs.
TEST(DispatchStats, NestedTraceRayTimeIsNotTheCallersTime) {
    // Spins far longer than a time slice, so that a loaded machine's preemption (a few ms) cannot move a
    // stage's time across the bounds: only the nested miss (200 ms) counted as closest-hit time can.
    const microseconds closestHitSpin(20000), missSpin(200000);
    StatsScene scene({.closestHitSpin = closestHitSpin, .secondaryMissSpin = missSpin});
    DispatchOptions options;
    options.threads = 1;
    options.profileStages = true;
    const DispatchResult r = scene.run(uvec3(1, 1, 1), options);  // hits the triangle: CHS, then a missing ray
    ASSERT_EQ(r.stats.invocationsOf("Miss_Secondary", ShaderStage::Miss), 1u);
    const double chs = r.stats.secondsIn(ProfileStage::ClosestHit), miss = r.stats.secondsIn(ProfileStage::Miss);
    EXPECT_GE(chs, 0.02);
    EXPECT_GE(miss, 0.2);
    EXPECT_LT(chs, 0.1) << "the nested ray's miss time was counted as closest-hit time";
    EXPECT_LT(r.stats.secondsIn(ProfileStage::RayGeneration), 0.1);
    EXPECT_LT(r.stats.secondsIn(ProfileStage::Traversal), 0.1);
    EXPECT_LE(r.stats.profiledSeconds(), r.seconds * 1.1);
}

TEST(DispatchStats, MergeAddsAndSortsTypesAndExports) {
    DispatchStats a, b;
    a.raysPerType = {{{3, 0}, {0, 5}}, {{0, 0}, {0, 1, 2}}};
    a.invocationsPerExport = {{"Miss", ShaderStage::Miss, 4}, {"RG", ShaderStage::RayGeneration, 1}};
    b.raysPerType = {{{0, 0}, {0, 10}}, {{1, 1}, {0, 0, 0, 7}}};
    b.invocationsPerExport = {{"RG", ShaderStage::RayGeneration, 2}, {"CH", ShaderStage::ClosestHit, 3}};
    b.stagesProfiled = true;
    b.stageSeconds[size_t(ProfileStage::Traversal)] = 0.5;
    DispatchStats merged;
    merged.merge(a);
    merged.merge(b);
    ASSERT_EQ(merged.raysPerType.size(), 3u);
    EXPECT_EQ(merged.raysPerType[0].key, (RayTypeKey{0, 0}));
    EXPECT_EQ(merged.raysPerType[0].raysPerDepth, (std::vector<uint64_t>{0, 11, 2}));
    EXPECT_EQ(merged.raysPerType[1].key, (RayTypeKey{1, 1}));
    EXPECT_EQ(merged.raysPerType[2].key, (RayTypeKey{3, 0}));
    ASSERT_EQ(merged.invocationsPerExport.size(), 3u);
    EXPECT_EQ(merged.invocationsPerExport[0].exportName, "RG");
    EXPECT_EQ(merged.invocationsPerExport[0].count, 3u);
    EXPECT_EQ(merged.invocationsPerExport[1].exportName, "CH");
    EXPECT_EQ(merged.invocationsPerExport[2].exportName, "Miss");
    EXPECT_TRUE(merged.stagesProfiled);
    EXPECT_EQ(merged.secondsIn(ProfileStage::Traversal), 0.5);
    EXPECT_EQ(toString(ProfileStage::Traversal), "traversal");
    EXPECT_EQ(toString(ProfileStage::ClosestHit), "closesthit");
}

}  // namespace refray::test
