// Shaders written for waves (emulator/tracing_wave.h, docs/emulator.md "Waves"): a wave's ray generation shader
// (emulator/ray_generation_wave.h) runs one call for its launches, a closest-hit shader (emulator/closest_hit_wave.h)
// one call for the lanes whose rays selected it, and each issues its lanes' TraceRays together. Every lane's TraceRay
// must be the one it makes alone: the same results, diagnostics and statistics at every wave width, closest-hit
// shaders that trace rays of their own (on fibers, or as waves in turn), miss shaders that do (run on the wave's
// stack), lanes whose ray is refused or whose launch stops, and the floating-point modes.
#include <gtest/gtest.h>
#include <xmmintrin.h>

#include <algorithm>
#include <string>
#include <vector>

#include "dispatch_rig.h"
#include "emulator/closest_hit_wave.h"
#include "emulator/ray_generation_wave.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

// A rig whose wave ray generation shader "RGW" traces one ray per launch (rayFor), records each lane's Probe at its
// launch number (y * width + x) and what it saw after the TraceRay.
struct WaveRig {
    Rig r;
    uvec2 grid;
    std::function<RayDesc(uint32_t launch)> rayFor;
    std::function<bool(uint32_t launch)> traces = [](uint32_t) { return true; };
    std::vector<Probe> results;
    std::vector<int> after;  // 1 once the lane's code after its TraceRay ran

    explicit WaveRig(uvec2 size) : grid(size) {
        r.h.library->addWaveRayGeneration("RGW", [this](RayGenerationWave& wave) {
            std::array<Probe, kMaxWaveWidth> payloads{};
            std::array<TraceRayCall, kMaxWaveWidth> calls{};
            LaneMask tracing;
            wave.forEachLane([&](int i, ShaderContext& ctx) {
                const uint32_t launch = number(ctx);
                if (!traces(launch)) return;
                payloads[size_t(i)].tag = launch;
                calls[size_t(i)] = traceRayCall(r.h.scene, r.args.flags, r.args.mask, r.args.rayContribution,
                                                r.args.multiplier, r.args.missIndex, rayFor(launch), payloads[size_t(i)]);
                tracing.set(i);
            });
            wave.TraceRay(tracing, calls);
            wave.forEachLane([&](int i, ShaderContext& ctx) {
                const uint32_t launch = number(ctx);
                results[launch] = payloads[size_t(i)];
                after[launch] = 1;
            });
        });
    }
    uint32_t number(ShaderContext& ctx) const { return ctx.DispatchRaysIndex().y * grid.x + ctx.DispatchRaysIndex().x; }

    DispatchResult run(const std::vector<std::string>& hitGroups, uint32_t width, DispatchOptions options,
                       const std::vector<std::string>& missTable = {"Miss_S"}) {
        if (!r.so) r.build();
        results.assign(size_t(grid.x) * grid.y, Probe{});
        after.assign(results.size(), 0);
        options.waveWidth = width;
        options.tileSize = 64;  // one tile: its waves hold `width` lanes
        return r.h.dispatch(r.so, r.h.table(r.so, missTable), r.h.table(r.so, hitGroups), uvec3(grid, 1u), options,
                            nullptr, r.h.table(r.so, {"CL_S"}), "RGW");
    }
};

bool sameProbe(const Probe& a, const Probe& b) {
    return a.t == b.t && a.hitKind == b.hitKind && a.instanceIndex == b.instanceIndex &&
           a.geometryIndex == b.geometryIndex && a.primitiveIndex == b.primitiveIndex &&
           a.barycentrics == b.barycentrics && a.closestHits == b.closestHits && a.misses == b.misses &&
           a.anyHits == b.anyHits && a.tag == b.tag;
}

std::vector<std::string> formatted(const DispatchResult& result) {
    std::vector<std::string> out;
    for (const Diagnostic& d : result.diagnostics.diagnostics()) out.push_back(d.format());
    std::sort(out.begin(), out.end());
    return out;
}

// A dispatch at wave width `width` against the same dispatch one lane at a time: the same diagnostics and
// statistics.
void expectSameDispatch(const DispatchResult& waved, const DispatchResult& alone, uint32_t width) {
    EXPECT_EQ(formatted(waved), formatted(alone)) << "width " << width;
    EXPECT_EQ(waved.stats.raysTraced, alone.stats.raysTraced) << "width " << width;
    EXPECT_EQ(waved.stats.raysPerDepth, alone.stats.raysPerDepth) << "width " << width;
    EXPECT_EQ(waved.stats.invocations, alone.stats.invocations) << "width " << width;
    EXPECT_EQ(waved.stats.candidates, alone.stats.candidates) << "width " << width;
}

// Rays across a triangle at z = 0 (x < 0.3 hits it) and a box at z = 10: hits, misses, and three refused or
// untraceable rays (RAY-5: NaN direction, TMin > TMax; RAY-7: an infinite origin component).
RayDesc mixedRay(uint32_t launch) {
    RayDesc ray{vec3(-1.0f + 0.06f * float(launch % 37), 0.2f * float(launch % 3) - 0.2f, -5.0f), 0.0f,
                vec3(0.0f, 0.0f, 1.0f), 100.0f};
    if (launch == 3) ray.Direction.y = kNaN;
    if (launch == 8) ray.TMin = 200.0f;
    if (launch == 21) ray.Origin.x = kInf;
    return ray;
}

// The scene of mixedRay: a triangle at z = 0 (instance 0) and an opaque unit box at z = 10 (instance 1).
void triangleAndBox(Harness& h) {
    const auto tri = h.blas({h.triangles(triAt(0))});
    const auto box = h.blas({h.aabbs({unitBox()}, GEOMETRY_FLAG_OPAQUE)});
    Matrix3x4 boxAt = Matrix3x4::identity();
    boxAt.m[2][3] = 10.0f;
    h.tlas({Harness::instance(tri, 0), Harness::instance(box, 1, boxAt)});
}

TEST(RayGenerationWave, EveryLaneTracesAsItWouldAlone) {
    WaveRig w(uvec2(7, 5));  // 35 launches: waves that do not divide them
    triangleAndBox(w.r.h);
    w.r.recursion(3);
    w.rayFor = mixedRay;
    w.traces = [](uint32_t launch) { return launch != 30; };  // a lane that traces nothing
    // Closest-hit shaders trace rays of their own (on their lanes' fibers); so does the miss shader of primary rays
    // (on the wave's stack: its ray traverses at once).
    const auto nested = [&w](ShaderContext& ctx, Probe& p) {
        if (ctx.RayFlags() & RAY_FLAG_FORCE_OPAQUE) return;  // the nested rays themselves
        Probe q;
        ctx.TraceRay(ctx.DispatchRaysIndex().x == 0 ? 0 : w.r.h.scene, RAY_FLAG_FORCE_OPAQUE,
                     0xFF, 0, 1, 0, RayDesc{vec3(0.1f, 0.0f, -3.0f), 0.0f, vec3(0, 0, 1), 100.0f}, q);
        p.anyHits += q.closestHits * 10 + q.misses;
    };
    w.r.chTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) { nested(ctx, p); };
    w.r.chBox = [&](ShaderContext& ctx, Probe& p, const ProbeAttributes&) { nested(ctx, p); };
    w.r.miss = [&](ShaderContext& ctx, Probe& p) { nested(ctx, p); };

    const DispatchResult alone = w.run({"HG_TriS_noAH", "HG_BoxS_noAH"}, 1, continueMode());
    const std::vector<Probe> expected = w.results;
    EXPECT_EQ(std::count(w.after.begin(), w.after.end(), 1), 35);
    EXPECT_EQ(expected[3].closestHits + expected[3].misses, 0u) << "RAY-5: no shader runs";
    EXPECT_EQ(expected[21].misses, 1u) << "RAY-7: a miss";
    EXPECT_GT(std::count_if(expected.begin(), expected.end(), [](const Probe& p) { return p.closestHits > 0; }), 5);
    EXPECT_GT(std::count_if(expected.begin(), expected.end(), [](const Probe& p) { return p.anyHits >= 10; }), 5)
        << "nested rays that hit";
    const std::vector<std::string> expectedDiagnostics = formatted(alone);
    ASSERT_GE(expectedDiagnostics.size(), 3u);

    for (const uint32_t width : {3u, 16u}) {
        const DispatchResult waved = w.run({"HG_TriS_noAH", "HG_BoxS_noAH"}, width, continueMode());
        for (size_t i = 0; i < expected.size(); ++i)
            EXPECT_TRUE(sameProbe(w.results[i], expected[i])) << "width " << width << ", launch " << i;
        expectSameDispatch(waved, alone, width);
    }
}

TEST(RayGenerationWave, ALaneWhoseLaunchStopsLeavesTheOthersTracing) {
    WaveRig w(uvec2(4, 4));  // one wave of 16 lanes
    w.r.h.tlas({Harness::instance(w.r.h.blas({w.r.h.triangles(triAt(0))}), 0)});
    w.rayFor = [](uint32_t launch) {
        RayDesc ray = zRay();
        if (launch == 5 || launch == 11) ray.Direction.x = kNaN;
        return ray;
    };
    // OnError::Stop: the dispatch stops with the first failed launch's error, at its launch index.
    const Diagnostic d = expectDxrError("RAY-5", [&] { w.run({"HG_TriS_noAH"}, 16, {}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(1, 1, 0));
    EXPECT_EQ(w.after[5], 0) << "no code of a stopped launch runs after its TraceRay";
    EXPECT_EQ(w.after[4], 1);
    EXPECT_EQ(w.results[4].closestHits, 1u);
    EXPECT_FLOAT_EQ(w.results[4].t, 5.0f);
    // OnError::Continue: the refused rays trace nothing and their lanes go on.
    w.run({"HG_TriS_noAH"}, 16, continueMode());
    for (uint32_t i = 0; i < 16; ++i) {
        EXPECT_EQ(w.after[i], 1) << "launch " << i;
        EXPECT_EQ(w.results[i].closestHits, (i == 5 || i == 11) ? 0u : 1u) << "launch " << i;
    }
}

// The traversal runs in the floating-point mode of the dispatch, not the one a ray generation shader set for its own
// math: a shader that flushes denormals (as refray's float ports do, H18) must not make refray's triangle test treat
// a triangle of denormal size as degenerate (DEGEN-7) when its wave traces the rays.
TEST(RayGenerationWave, RaysTraverseInTheDispatchsFloatingPointMode) {
    WaveRig w(uvec2(4, 2));
    const float tiny = 1e-39f;  // a denormal float
    w.r.h.tlas({Harness::instance(
        w.r.h.blas({w.r.h.triangles({{-tiny, -tiny, 1.0f}, {0.0f, tiny, 1.0f}, {tiny, -tiny, 1.0f}})}), 0)});
    // Even launches' rays hit the triangle; odd launches' rays miss, and their miss shader traces one that hits it
    // (on the wave's stack, where the shader's mode is in force).
    const RayDesc towards{vec3(0.0f), 0.0f, vec3(0.0f, 0.0f, 1.0f), 100.0f};
    w.rayFor = [towards](uint32_t launch) {
        RayDesc ray = towards;
        if (launch % 2) ray.Direction.z = -1.0f;
        return ray;
    };
    w.r.miss = [&w, towards](ShaderContext& ctx, Probe& p) {
        if (ctx.RayFlags() & RAY_FLAG_FORCE_OPAQUE) return;
        Probe q;
        ctx.TraceRay(w.r.h.scene, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, towards, q);
        p.anyHits = q.closestHits;
        p.t = q.t;
    };
    w.r.recursion(2);
    w.r.h.library->addWaveRayGeneration("RGW_FTZ", [&w](RayGenerationWave& wave) {
        const uint32_t saved = _mm_getcsr();
        _mm_setcsr(saved | 0x8040u);  // FTZ and DAZ
        std::array<Probe, kMaxWaveWidth> payloads{};
        std::array<TraceRayCall, kMaxWaveWidth> calls{};
        wave.forEachLane([&](int i, ShaderContext& ctx) {
            calls[size_t(i)] =
                traceRayCall(w.r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, w.rayFor(w.number(ctx)), payloads[size_t(i)]);
        });
        wave.TraceRay(wave.active(), calls);
        _mm_setcsr(saved);
        wave.forEachLane([&](int i, ShaderContext& ctx) { w.results[w.number(ctx)] = payloads[size_t(i)]; });
    });
    w.r.build();
    for (const uint32_t width : {1u, 8u}) {
        w.results.assign(8, Probe{});
        DispatchOptions options;
        options.waveWidth = width;
        w.r.h.dispatch(w.r.so, w.r.h.table(w.r.so, {"Miss_S"}), w.r.h.table(w.r.so, {"HG_TriS_noAH"}), uvec3(4, 2, 1),
                       options, nullptr, {}, "RGW_FTZ");
        for (uint32_t i = 0; i < 8; ++i) {
            EXPECT_EQ(w.results[i].closestHits, i % 2 ? 0u : 1u) << "width " << width << ", launch " << i;
            EXPECT_EQ(w.results[i].anyHits, i % 2 ? 1u : 0u) << "width " << width << ", launch " << i << " (nested)";
            EXPECT_FLOAT_EQ(w.results[i].t, 1.0f) << "width " << width << ", launch " << i;
        }
    }
}

// A wave closest-hit shader "CHW_Tri" (hit group HG_TriW) on the triangle: it records each lane's hit, and the lanes
// of primary rays (not FORCE_OPAQUE) trace a nested ray together, which hits the triangle again (the shader runs as
// a wave at depth 2) or, for some lanes, is refused (RAY-5) or names no acceleration structure. The box's closest
// hit is an ordinary one (CH_BoxS, on its lanes' fibers) that traces the same nested ray alone.
struct ClosestHitWaveRig : WaveRig {
    int widestCall = 0;           // the most lanes one CHW_Tri call ran for
    int depthTwoWaveCalls = 0;    // CHW_Tri calls for nested rays with more than one lane
    std::vector<int> afterNested;  // 1 once the lane's CHW_Tri code after its nested TraceRay ran

    static RayDesc nestedRay(uint32_t launch) {
        RayDesc ray{vec3(0.1f, 0.0f, -3.0f), 0.0f, vec3(0.0f, 0.0f, 1.0f), 100.0f};
        if (launch == 7) ray.Direction.x = kNaN;  // RAY-5, from a closest-hit shader
        return ray;
    }
    GpuVirtualAddress nestedScene(uint32_t launch) const { return launch % 4 == 0 ? 0 : r.h.scene; }

    explicit ClosestHitWaveRig(uvec2 size) : WaveRig(size) {
        afterNested.assign(size_t(size.x) * size.y, 0);
        r.h.library->addWaveClosestHit<Probe, BuiltInTriangleIntersectionAttributes>("CHW_Tri", [this](ClosestHitWave& wave) {
            widestCall = std::max(widestCall, wave.active().count());
            std::array<Probe, kMaxWaveWidth> nested{};
            std::array<TraceRayCall, kMaxWaveWidth> calls{};
            LaneMask tracing;
            wave.forEachLane([&](int i, ShaderContext& ctx) {
                Probe& p = wave.payload<Probe>(i);
                recordHitValues(ctx, p);
                p.barycentrics = wave.attributes<BuiltInTriangleIntersectionAttributes>(i).barycentrics;
                if (ctx.RayFlags() & RAY_FLAG_FORCE_OPAQUE) return;  // the nested rays themselves
                const uint32_t launch = number(ctx);
                if (launch % 3 == 2) return;  // a lane that traces nothing
                calls[size_t(i)] = traceRayCall(nestedScene(launch), RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0,
                                                nestedRay(launch), nested[size_t(i)]);
                tracing.set(i);
            });
            if (wave.active().count() > 1 && wave.lane(wave.active().lowest()).RayFlags() & RAY_FLAG_FORCE_OPAQUE)
                depthTwoWaveCalls++;
            wave.TraceRay(tracing, calls);
            wave.forEachLane([&](int i, ShaderContext& ctx) {
                if (!tracing.test(i)) return;
                wave.payload<Probe>(i).anyHits += nested[size_t(i)].closestHits * 10 + nested[size_t(i)].misses;
                afterNested[number(ctx)] = 1;
            });
        });
        r.h.stateObject.hitGroups.push_back({"HG_TriW", HitGroupType::Triangles, "", "CHW_Tri", ""});
        r.chBox = [this](ShaderContext& ctx, Probe& p, const ProbeAttributes&) {
            Probe q;
            const uint32_t launch = number(ctx);
            ctx.TraceRay(nestedScene(launch), RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, nestedRay(launch), q);
            p.anyHits += q.closestHits * 10 + q.misses;
        };
        r.recursion(3);
        rayFor = mixedRay;
    }
};

TEST(ClosestHitWave, EveryLaneRunsAsItWouldAlone) {
    ClosestHitWaveRig w(uvec2(7, 5));  // 35 launches: waves that do not divide them
    triangleAndBox(w.r.h);

    const DispatchResult alone = w.run({"HG_TriW", "HG_BoxS_noAH"}, 1, continueMode());
    const std::vector<Probe> expected = w.results;
    EXPECT_EQ(w.widestCall, 1) << "width 1: the shader runs a lane at a time";
    EXPECT_GT(std::count_if(expected.begin(), expected.end(), [](const Probe& p) { return p.anyHits >= 10; }), 5)
        << "nested rays that hit";
    EXPECT_GT(std::count_if(expected.begin(), expected.end(), [](const Probe& p) { return p.anyHits == 1; }), 2)
        << "nested rays that miss (no acceleration structure)";
    const std::vector<std::string> expectedDiagnostics = formatted(alone);
    EXPECT_TRUE(std::any_of(expectedDiagnostics.begin(), expectedDiagnostics.end(),
                            [](const std::string& d) { return d.find("RAY-5") != std::string::npos; }));
    const std::vector<int> expectedAfter = w.afterNested;

    for (const uint32_t width : {3u, 16u}) {
        w.widestCall = 0;
        w.depthTwoWaveCalls = 0;
        w.afterNested.assign(expectedAfter.size(), 0);
        const DispatchResult waved = w.run({"HG_TriW", "HG_BoxS_noAH"}, width, continueMode());
        EXPECT_GT(w.widestCall, 1) << "width " << width << ": lanes run the shader together";
        EXPECT_GT(w.depthTwoWaveCalls, 0) << "width " << width << ": nested closest hits run as waves";
        for (size_t i = 0; i < expected.size(); ++i)
            EXPECT_TRUE(sameProbe(w.results[i], expected[i])) << "width " << width << ", launch " << i;
        EXPECT_EQ(w.afterNested, expectedAfter) << "width " << width;
        expectSameDispatch(waved, alone, width);
    }
}

TEST(ClosestHitWave, ALaneWhoseLaunchStopsLeavesTheOthersShading) {
    ClosestHitWaveRig w(uvec2(4, 4));  // one wave of 16 lanes
    w.r.h.tlas({Harness::instance(w.r.h.blas({w.r.h.triangles(triAt(0))}), 0)});
    w.rayFor = [](uint32_t) { return zRay(); };  // every primary ray hits the triangle
    // OnError::Stop: launch 7's nested ray is RAY-5; the dispatch stops with its error at its launch index.
    const Diagnostic d = expectDxrError("RAY-5", [&] { w.run({"HG_TriW"}, 16, {}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(3, 1, 0));
    EXPECT_EQ(d.site->stage, ShaderStage::ClosestHit);
    EXPECT_EQ(w.afterNested[7], 0) << "no code of a stopped launch runs after its TraceRay";
    EXPECT_EQ(w.after[7], 0) << "nor does its ray generation shader";
    EXPECT_EQ(w.afterNested[6], 1);
    EXPECT_EQ(w.after[6], 1);
    EXPECT_EQ(w.results[6].closestHits, 1u);
    EXPECT_EQ(w.results[6].anyHits, 10u) << "launch 6's nested ray hit";
    EXPECT_EQ(w.results[4].anyHits, 1u) << "launch 4's nested ray names no acceleration structure: a miss";
}

// A closest-hit shader's floating-point mode is its own: one that sets FTZ/DAZ and leaves it set must not change the
// mode of the ray generation shader that traced the ray, as on its own fiber it would not.
TEST(ClosestHitWave, AShadersFloatingPointModeEndsWithIt) {
    WaveRig w(uvec2(4, 2));
    w.r.h.tlas({Harness::instance(w.r.h.blas({w.r.h.triangles(triAt(0))}), 0)});
    w.rayFor = [](uint32_t) { return zRay(); };
    w.r.h.library->addWaveClosestHit<Probe, BuiltInTriangleIntersectionAttributes>("CHW_FTZ", [](ClosestHitWave& wave) {
        _mm_setcsr(_mm_getcsr() | 0x8040u);  // FTZ and DAZ, never restored
        wave.forEachLane([&](int i, ShaderContext&) { wave.payload<Probe>(i).closestHits++; });
    });
    w.r.h.stateObject.hitGroups.push_back({"HG_TriFTZ", HitGroupType::Triangles, "", "CHW_FTZ", ""});
    std::vector<uint32_t> modes;
    w.r.h.library->addWaveRayGeneration("RGW_Mode", [&w, &modes](RayGenerationWave& wave) {
        std::array<Probe, kMaxWaveWidth> payloads{};
        std::array<TraceRayCall, kMaxWaveWidth> calls{};
        wave.forEachLane([&](int i, ShaderContext& ctx) {
            calls[size_t(i)] = traceRayCall(w.r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), payloads[size_t(i)]);
            (void)ctx;
        });
        const uint32_t before = _mm_getcsr();
        wave.TraceRay(wave.active(), calls);
        modes.push_back(_mm_getcsr() ^ before);
        wave.forEachLane([&](int i, ShaderContext& ctx) { w.results[w.number(ctx)] = payloads[size_t(i)]; });
    });
    w.r.build();
    w.results.assign(8, Probe{});
    DispatchOptions options;
    options.waveWidth = 8;
    options.threads = 1;
    w.r.h.dispatch(w.r.so, w.r.h.table(w.r.so, {"Miss_S"}), w.r.h.table(w.r.so, {"HG_TriFTZ"}), uvec3(4, 2, 1),
                   options, nullptr, {}, "RGW_Mode");
    ASSERT_EQ(modes.size(), 1u);
    EXPECT_EQ(modes[0], 0u) << "the MXCSR bits the closest-hit shader changed leaked into its caller";
    for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(w.results[i].closestHits, 1u) << "launch " << i;
}

}  // namespace
}  // namespace refray::test
