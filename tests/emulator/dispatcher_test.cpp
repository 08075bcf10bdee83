// Conformance tests for DispatchRays (emulator/dispatcher.cpp): the launch (RGS), diagnostics and determinism (GEN),
// trace events and launch regions (dxr-semantics.md sections 0 and 10). TraceRay, the ray flags, candidate
// processing, intersection shaders, CallShader and the intrinsics are tested in trace_ray_test.cpp,
// ray_flags_test.cpp, candidate_processing_test.cpp, intersection_shader_test.cpp, shader_invocation_test.cpp and
// shader_api_intrinsics_test.cpp, with the rig of dispatch_rig.h. Each test name carries the rule id it checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "dispatch_rig.h"
#include "emulator/limits.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

// ---------------------------------------------------------------------------------------
// RGS: ray generation and the launch.

TEST(Dispatcher, RGS_1_ZeroDimensionStartsNothing) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    std::atomic<int> started{0};
    r.rg = [&](ShaderContext&) { started++; };
    for (uvec3 dims : {uvec3(0, 4, 1), uvec3(4, 0, 1), uvec3(4, 4, 0)}) {
        const auto result = r.run({"HG_Tri"}, dims);
        EXPECT_EQ(result.stats.invocationsOf(ShaderStage::RayGeneration), 0u);
    }
    EXPECT_EQ(started.load(), 0);
    const auto result = r.run({"HG_Tri"}, uvec3(3, 2, 4));
    EXPECT_EQ(started.load(), 24);
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::RayGeneration), 24u);
}

TEST(Dispatcher, RGS_1_MoreThan2To30ThreadsIsRefused) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    std::atomic<int> started{0};
    r.rg = [&](ShaderContext&) { started++; };
    const auto d = expectDxrError("RGS-1", [&] { r.run({"HG_Tri"}, uvec3(65536, 16384, 2)); });
    EXPECT_EQ(valueOf(d, "Width*Height*Depth"), std::to_string(1ull << 31));
    EXPECT_EQ(limitOf(d, "Width*Height*Depth"), std::to_string(kMaxRayGenerationShaderThreads));
    // The product is computed in 64 bits: 2^32 must not wrap to 0.
    expectDxrError("RGS-1", [&] { r.run({"HG_Tri"}, uvec3(65536, 65536, 1)); });
    expectDxrError("RGS-1", [&] { r.run({"HG_Tri"}, uvec3((1u << 30) + 1, 1, 1)); });
    EXPECT_EQ(started.load(), 0);
}

TEST(Dispatcher, RGS_2_RayGenerationRunsAtDepthZeroAndMayTraceAndCall) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.callable = [](ShaderContext&, CallParams& c) { c.value = 5; };
    int value = 0;
    r.rg = [&](ShaderContext& ctx) {
        Probe p;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);
        CallParams c;
        ctx.CallShader(0, c);
        value = int(p.closestHits) * 10 + c.value;
        (void)ctx.RayTMin();  // SV-1: no ray values at depth 0
    };
    const auto d = expectDxrError("SV-1", [&] { r.run({"HG_Tri"}); });
    EXPECT_EQ(value, 15);
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->depth, 0u);
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
}

TEST(Dispatcher, RGS_3_NullPipelineIsRefused) {
    Harness h;
    DispatchRaysDesc desc;
    desc.Width = desc.Height = desc.Depth = 1;
    try {
        h.device.dispatchRays(desc, nullptr, nullptr);
        ADD_FAILURE() << "expected RGS-3";
    } catch (const DxrError& e) {
        EXPECT_EQ(e.diagnostic().ruleId, "RGS-3");
    }
}

// ---------------------------------------------------------------------------------------
// GEN: diagnostics and determinism.

TEST(Dispatcher, GEN_1_DiagnosticCarriesRuleSiteAndValues) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.rg = [](ShaderContext& ctx) {
        if (ctx.DispatchRaysIndex() != uvec3(2, 1, 0)) return;
        Probe p;
        RayDesc ray = zRay();
        ray.TMin = -3.0f;
        ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    };
    auto d = expectDxrError("RAY-5", [&] { r.run({"HG_Tri"}, uvec3(4, 4, 1)); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(2, 1, 0));
    EXPECT_EQ(d.site->depth, 0u);
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
    EXPECT_EQ(d.site->exportName, "RG");
    EXPECT_EQ(valueOf(d, "TMin"), "-3");
    EXPECT_EQ(limitOf(d, "TMin"), ">= 0");
    EXPECT_EQ(d.severity, Severity::Error);
    EXPECT_TRUE(contains(d.format(), "launch (2,1,0)")) << d.format();
    // From a closest-hit shader: depth 1, its export name.
    r.rg = nullptr;
    r.chTri = [](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        ctx.ReportHit(1.0f, 0, ProbeAttributes{});
    };
    d = expectDxrError("SV-1", [&] { r.run({"HG_TriS_noAH"}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->depth, 1u);
    EXPECT_EQ(d.site->stage, ShaderStage::ClosestHit);
    EXPECT_EQ(d.site->exportName, "CH_TriS");
}

TEST(Dispatcher, GEN_1_StopModeReportsLowestLaunchIndexRegardlessOfThreads) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.rg = [&](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        Probe p;
        RayDesc ray = zRay();
        if (i == uvec3(10, 40, 0) || i == uvec3(50, 5, 0)) ray.TMin = kNaN;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    };
    for (uint32_t threads : {0u, 1u, 2u, 4u}) {
        for (uint32_t tile : {8u, 3u, 64u}) {
            SCOPED_TRACE("threads " + std::to_string(threads) + " tile " + std::to_string(tile));
            DispatchOptions o;
            o.threads = threads;
            o.tileSize = tile;
            const auto d = expectDxrError("RAY-5", [&] { r.run({"HG_Tri"}, uvec3(64, 64, 1), o); });
            ASSERT_TRUE(d.site);
            EXPECT_EQ(d.site->launchIndex, uvec3(50, 5, 0));  // linear 370 < 2570
        }
    }
}

TEST(Dispatcher, GEN_2_ContinueModeDeduplicatesWithCountAndFirstOccurrence) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    std::vector<uint32_t> hits(120);
    r.rg = [&](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        Probe p;
        const uint32_t flags = i.x >= 2 ? RAY_FLAG_FORCE_OPAQUE | 0x4000u : RAY_FLAG_FORCE_OPAQUE;
        ctx.TraceRay(r.h.scene, flags, 0xFF, 0, 1, 0, zRay(), p);
        hits[i.y * 12 + i.x] = p.closestHits;
    };
    for (uint32_t threads : {1u, 4u}) {
        DispatchOptions o = continueMode();
        o.threads = threads;
        o.tileSize = 3;
        const auto result = r.run({"HG_TriS_noAH"}, uvec3(12, 10, 1), o);
        const auto errors = result.diagnostics.errors();
        ASSERT_EQ(errors.size(), 1u);
        EXPECT_EQ(errors[0].ruleId, "RAY-10");
        EXPECT_EQ(errors[0].count, 100u);
        ASSERT_TRUE(errors[0].site);
        EXPECT_EQ(errors[0].site->launchIndex, uvec3(2, 0, 0));
        for (uint32_t h : hits) EXPECT_EQ(h, 1u);  // fallback: the undefined bits are dropped
    }
}

TEST(Dispatcher, GEN_3_DefaultOrderIsIncreasingEntryT) {
    Rig r;
    const auto box = r.h.blas({r.h.aabbs({unitBox()})});
    r.h.tlas({Harness::instance(box, 0, Matrix3x4::translation({0, 0, 10})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 4})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 7})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 13}))});
    std::vector<uint32_t> order;
    std::vector<float> tCur;
    r.is = [&](ShaderContext& ctx) {
        order.push_back(ctx.InstanceIndex());
        tCur.push_back(ctx.RayTCurrent());
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(order, (std::vector<uint32_t>{1, 2, 0, 3}));
}

TEST(Dispatcher, GEN_3_AdversarialSeedsChangeOrderNotOrderIndependentResults) {
    Rig r;
    const auto box = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(box, 0, Matrix3x4::translation({0, 0, 10})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 4})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 7})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 13}))});
    std::vector<uint32_t> order;
    bool report = false;
    r.is = [&](ShaderContext& ctx) {
        order.push_back(ctx.InstanceIndex());
        if (!report) return;
        auto slab = intersectAABB(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(), unitBox(), ctx.RayTMin(), ctx.RayTCurrent());
        if (slab) ctx.ReportHit(slab->tEnter, 0, ProbeAttributes{slab->tEnter});
    };
    std::set<std::vector<uint32_t>> orders;
    std::vector<std::vector<uint32_t>> firstPass;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        report = false;
        order.clear();
        r.run({"HG_BoxS"}, uvec3(1u), o);
        std::vector<uint32_t> unique = order;
        std::sort(unique.begin(), unique.end());
        unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
        EXPECT_EQ(unique, (std::vector<uint32_t>{0, 1, 2, 3})) << "every box is still enumerated";
        orders.insert(order);
        firstPass.push_back(order);
        report = true;
        r.run({"HG_BoxS"}, uvec3(1u), o);
        EXPECT_EQ(r.result.instanceIndex, 1u);
        EXPECT_FLOAT_EQ(r.result.t, 8.0f);
    }
    EXPECT_GT(orders.size(), 1u);
    // The same seed gives the same order.
    DispatchOptions o;
    o.order = TraversalOrder::Adversarial;
    o.adversarialSeed = 1;
    report = false;
    order.clear();
    r.run({"HG_BoxS"}, uvec3(1u), o);
    EXPECT_EQ(order, firstPass[0]);
}

TEST(Dispatcher, GEN_4_WarningsDoNotChangeResults) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))})),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}), 1, Matrix3x4::translation({0.5f, 0.5f, 3}))});
    uint32_t rContribution = 0, multiplier = 1;
    std::vector<Probe> out(64);
    r.rg = [&](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        Probe p;
        const RayDesc ray{vec3(-1.0f + i.x * 0.3f, -1.0f + i.y * 0.3f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f};
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, rContribution, multiplier, 0, ray, p);
        out[i.y * 8 + i.x] = p;
    };
    const auto clean = r.run({"HG_TriS", "HG_BoxS"}, uvec3(8, 8, 1));
    EXPECT_TRUE(clean.diagnostics.empty());
    const auto reference = out;
    rContribution = 0x10;  // the low 4 bits are 0: IDX-2 warning, same records
    multiplier = 0x11;
    const auto warned = r.run({"HG_TriS", "HG_BoxS"}, uvec3(8, 8, 1));
    ASSERT_FALSE(warned.diagnostics.warnings().empty());
    EXPECT_TRUE(warned.diagnostics.errors().empty());
    EXPECT_EQ(std::memcmp(out.data(), reference.data(), out.size() * sizeof(Probe)), 0);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Trace events (emulator/trace.h) and launch regions: what refray explain records.

namespace {

struct EventLog : TraceObserver {
    std::mutex lock;
    std::vector<std::string> lines;
    void onEvent(const TraceEvent& e) override {
        std::string s;
        switch (e.kind) {
            case TraceEvent::Kind::TraceRay: s = "TraceRay R" + std::to_string(e.rayContribution) + " M" + std::to_string(e.multiplier); break;
            case TraceEvent::Kind::Candidate: s = "Candidate p" + std::to_string(e.primitiveIndex); break;
            case TraceEvent::Kind::Skipped: s = "Skipped " + std::string(e.note); break;
            case TraceEvent::Kind::RecordLookup:
                s = "Record " + std::string(e.table) + " " + std::to_string(e.recordIndex) + " " + std::string(e.exportName);
                if (e.hasTerms) s += " I=" + std::to_string(e.terms.index) + " G=" + std::to_string(e.terms.geometryIndex);
                break;
            case TraceEvent::Kind::ShaderCall: s = "Call " + std::string(e.exportName); break;
            case TraceEvent::Kind::ReportHit: s = "ReportHit " + std::string(e.note); break;
            case TraceEvent::Kind::AnyHit: s = "AnyHit p" + std::to_string(e.primitiveIndex) + " " + std::string(e.note); break;
            case TraceEvent::Kind::Commit: s = "Commit p" + std::to_string(e.primitiveIndex); break;
            case TraceEvent::Kind::TraceRayEnd: s = e.committed ? "End hit p" + std::to_string(e.primitiveIndex) : "End miss"; break;
            case TraceEvent::Kind::QueryInit: s = "QueryInit"; break;
            case TraceEvent::Kind::QueryProceed: s = std::string("Proceed ") + (e.accepted ? "TRUE" : "FALSE"); break;
            case TraceEvent::Kind::QueryCommit: s = "QueryCommit p" + std::to_string(e.primitiveIndex); break;
            case TraceEvent::Kind::QueryAbort: s = "Abort"; break;
        }
        std::lock_guard<std::mutex> guard(lock);
        lines.push_back(s);
    }
};

}  // namespace

TEST(Dispatcher, TraceEventsFollowTheAnyHitDecisionsAndTheRecords) {
    // Two non-opaque triangles on the ray: primitive 1 at t = 3, primitive 0 at t = 5. The any-hit shader
    // ignores primitive 1, so primitive 0 is committed and its closest-hit shader runs.
    Rig r;
    const auto tri = r.h.blas({r.h.triangles({triAt(0)[0], triAt(0)[1], triAt(0)[2], triAt(-2)[0], triAt(-2)[1], triAt(-2)[2]},
                                             GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri)});
    r.ahTri = [](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        if (ctx.PrimitiveIndex() == 1) ctx.IgnoreHit();
    };
    EventLog log;
    DispatchOptions options;
    options.observer = &log;
    r.run({"HG_TriS"}, uvec3(1u), options);
    const std::vector<std::string> expected = {
        "Record ray generation record 0 RG",
        "Call RG",
        "TraceRay R0 M1",
        "Candidate p1",
        "Record hit-group table 0 HG_TriS I=0 G=0",
        "Call AH_TriS",
        "AnyHit p1 IgnoreHit: the candidate is dropped",
        "Candidate p0",
        "Record hit-group table 0 HG_TriS I=0 G=0",
        "Call AH_TriS",
        "AnyHit p0 accept (returned normally)",
        "Commit p0",
        "Record hit-group table 0 HG_TriS I=0 G=0",
        "Call CH_TriS",
        "End hit p0",
    };
    EXPECT_EQ(log.lines, expected);
    EXPECT_EQ(r.result.primitiveIndex, 0u);
}

TEST(Dispatcher, TraceEventsOfACulledTriangleAndTheMissThatFollows) {
    // The ray meets one face of the triangle: exactly one of the two cull flags drops it (FLAG-10), and the
    // log of that run says so, then reads miss record 0.
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    int culledRuns = 0;
    for (const uint32_t cull : {RAY_FLAG_CULL_BACK_FACING_TRIANGLES, RAY_FLAG_CULL_FRONT_FACING_TRIANGLES}) {
        EventLog log;
        DispatchOptions options;
        options.observer = &log;
        r.args.flags = cull | RAY_FLAG_FORCE_OPAQUE;
        r.run({"HG_TriS"}, uvec3(1u), options);
        const std::string skip = cull == RAY_FLAG_CULL_BACK_FACING_TRIANGLES
                                     ? "Skipped back face culled: CULL_BACK_FACING_TRIANGLES (FLAG-10)"
                                     : "Skipped front face culled: CULL_FRONT_FACING_TRIANGLES (FLAG-10)";
        if (std::find(log.lines.begin(), log.lines.end(), skip) == log.lines.end()) {
            EXPECT_EQ(log.lines.back(), "End hit p0");
            continue;
        }
        ++culledRuns;
        EXPECT_EQ(log.lines.back(), "End miss");
        EXPECT_NE(std::find(log.lines.begin(), log.lines.end(), "Record miss shader table 0 Miss_S"), log.lines.end());
        EXPECT_EQ(r.result.misses, 1u);
    }
    EXPECT_EQ(culledRuns, 1);
}

TEST(Dispatcher, ALaunchRegionRunsOnlyItsLaunchIndices) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    std::mutex lock;
    std::vector<uvec3> ran;
    r.rg = [&](ShaderContext& ctx) {
        std::lock_guard<std::mutex> guard(lock);
        ran.push_back(ctx.DispatchRaysIndex());
        EXPECT_EQ(ctx.DispatchRaysDimensions(), uvec3(8, 6, 1));  // the full dispatch's
    };
    DispatchOptions options;
    options.region = LaunchRegion{5, 2, 2, 3};
    r.run({"HG_TriS"}, uvec3(8, 6, 1), options);
    std::sort(ran.begin(), ran.end(), [](uvec3 a, uvec3 b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
    EXPECT_EQ(ran, (std::vector<uvec3>{{5, 2, 0}, {6, 2, 0}, {5, 3, 0}, {6, 3, 0}, {5, 4, 0}, {6, 4, 0}}));

    options.region = LaunchRegion{7, 0, 2, 1};
    try {
        r.run({"HG_TriS"}, uvec3(8, 6, 1), options);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "the launch region 2x1 at (7, 0) is not inside the 8x6 dispatch");
    }
}

}  // namespace refray::test
