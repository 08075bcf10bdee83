// Conformance tests for the dispatcher (emulator/dispatcher.cpp, trace_ray.cpp, candidate_*.cpp, record_lookup.cpp): TraceRay, the TRV-4 hit-processing loop,
// intersection/any-hit/closest-hit/miss/callable control flow and the system-value
// intrinsics (dxr-semantics.md sections 0, 4-11 and LIM-2). Each test name carries the
// rule id it checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "emulator/intersection.h"
#include "emulator/limits.h"
#include "harness.h"

namespace refray::test {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A triangle in the plane z = `z`, front-facing for rays along +z (FACE-1: dot(n, d) < 0).
std::vector<vec3> triAt(float z) { return {{-1, -1, z}, {0, 1, z}, {1, -1, z}}; }
// The standard probe ray: from (0, 0.2, -5) along +z, so a triangle at z hits at t = z + 5
// with barycentrics (0.6, 0.2).
RayDesc zRay(float tMax = 100.0f) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), tMax}; }

struct CallParams {
    int value = 0;
    int nesting = 0;
};
struct OtherParams {
    double value = 0.0;
};
struct OtherAttributes {
    int a = 0;
    int b = 0;
};

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(vec3 a, vec3 b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }


// A harness with scriptable shaders. Every script is optional; the defaults record like
// the harness probes. Hit groups:
//   HG_Tri {CH_Probe}, HG_TriAH {AH_Probe, CH_Probe}, HG_Box {IS_Box, CH_ProbeAABB} (harness)
//   HG_TriS {AH_TriS, CH_TriS}, HG_TriS_noAH {CH_TriS}, HG_TriS_noCH {AH_TriS}
//   HG_BoxS {IS_S, AH_BoxS, CH_BoxS}, HG_BoxS_noAH {IS_S, CH_BoxS}
//   HG_BoxR {IS_R, AH_BoxS, CH_BoxS}, HG_BoxR_noAH {IS_R, CH_BoxS}: IS_R runs the IS_S script but is registered
//   with ReportHitEnd::Return
// Miss shaders: Miss_Probe (harness), Miss_S. Callable: CL_S (CallParams).
struct Rig {
    Harness h;
    RayDesc ray = zRay();
    Harness::TraceArgs args;
    bool useTlasOverride = false;
    GpuVirtualAddress tlasOverride = 0;
    Probe initial;
    Probe result;
    bool traced = false;
    bool log = false;  // single-pixel tests only
    std::vector<std::string> events;

    std::function<void(ShaderContext&)> rg;  // replaces the default trace
    std::function<void(ShaderContext&)> is;  // default: report the unit-box entry t, kind `isKind`
    uint32_t isKind = 0;
    std::function<void(ShaderContext&, Probe&, const BuiltInTriangleIntersectionAttributes&)> ahTri;
    std::function<void(ShaderContext&, Probe&, const ProbeAttributes&)> ahBox;
    std::function<void(ShaderContext&, Probe&, const BuiltInTriangleIntersectionAttributes&)> chTri;
    std::function<void(ShaderContext&, Probe&, const ProbeAttributes&)> chBox;
    std::function<void(ShaderContext&, Probe&)> miss;
    std::function<void(ShaderContext&, CallParams&)> callable;
    std::atomic<int> isCalls{0};

    StateObjectPtr so;

    Rig() {
        h.addProbeShaders();
        auto& lib = *h.library;
        lib.addRayGeneration("RG", [this](ShaderContext& ctx) {
            if (log) events.push_back("RG");
            if (rg) return rg(ctx);
            Probe p = initial;
            ctx.TraceRay(useTlasOverride ? tlasOverride : h.scene, args.flags, args.mask, args.rayContribution,
                         args.multiplier, args.missIndex, ray, p);
            result = p;
            traced = true;
        });
        const auto intersection = [this](ShaderContext& ctx) {
            isCalls++;
            if (log) events.push_back("IS");
            if (is) return is(ctx);
            auto slab = intersectAABB(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(), unitBox(), ctx.RayTMin(),
                                      ctx.RayTCurrent());
            if (slab) ctx.ReportHit(slab->tEnter, isKind, ProbeAttributes{slab->tEnter});
        };
        lib.addIntersection<ProbeAttributes>("IS_S", intersection);
        lib.addIntersection<ProbeAttributes>("IS_R", intersection, ReportHitEnd::Return);
        lib.addAnyHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "AH_TriS", [this](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
                p.anyHits++;
                if (log) events.push_back("AH");
                if (ahTri) ahTri(ctx, p, a);
            });
        lib.addAnyHit<Probe, ProbeAttributes>("AH_BoxS", [this](ShaderContext& ctx, Probe& p, const ProbeAttributes& a) {
            p.anyHits++;
            if (log) events.push_back("AH");
            if (ahBox) ahBox(ctx, p, a);
        });
        lib.addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "CH_TriS", [this](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
                if (log) events.push_back("CH");
                recordHitValues(ctx, p);
                p.barycentrics = a.barycentrics;
                if (chTri) chTri(ctx, p, a);
            });
        lib.addClosestHit<Probe, ProbeAttributes>("CH_BoxS", [this](ShaderContext& ctx, Probe& p, const ProbeAttributes& a) {
            if (log) events.push_back("CH");
            recordHitValues(ctx, p);
            if (chBox) chBox(ctx, p, a);
        });
        lib.addMiss<Probe>("Miss_S", [this](ShaderContext& ctx, Probe& p) {
            if (log) events.push_back("MS");
            p.misses++;
            p.t = ctx.RayTCurrent();
            if (miss) miss(ctx, p);
        });
        lib.addCallable<CallParams>("CL_S", [this](ShaderContext& ctx, CallParams& c) {
            if (log) events.push_back("CL");
            if (callable) callable(ctx, c);
        });
        auto& hg = h.stateObject.hitGroups;
        hg.push_back({"HG_TriS", HitGroupType::Triangles, "AH_TriS", "CH_TriS", ""});
        hg.push_back({"HG_TriS_noAH", HitGroupType::Triangles, "", "CH_TriS", ""});
        hg.push_back({"HG_TriS_noCH", HitGroupType::Triangles, "AH_TriS", "", ""});
        hg.push_back({"HG_BoxS", HitGroupType::ProceduralPrimitive, "AH_BoxS", "CH_BoxS", "IS_S"});
        hg.push_back({"HG_BoxS_noAH", HitGroupType::ProceduralPrimitive, "", "CH_BoxS", "IS_S"});
        hg.push_back({"HG_BoxR", HitGroupType::ProceduralPrimitive, "AH_BoxS", "CH_BoxS", "IS_R"});
        hg.push_back({"HG_BoxR_noAH", HitGroupType::ProceduralPrimitive, "", "CH_BoxS", "IS_R"});
    }
    Rig(const Rig&) = delete;
    Rig& operator=(const Rig&) = delete;

    void recursion(uint32_t depth, uint32_t pipelineFlags = PIPELINE_FLAG_NONE) {
        h.stateObject.pipelineConfigs = {{depth, pipelineFlags}};
    }
    void build() { so = h.pipeline(); }
    // One dispatch; `hitGroups` is the hit-group table, `missTable` the miss table.
    DispatchResult run(const std::vector<std::string>& hitGroups, uvec3 dims = uvec3(1u), DispatchOptions options = {},
                       const std::vector<std::string>& missTable = {"Miss_S"},
                       const std::vector<std::string>& callables = {"CL_S"}) {
        if (!so) build();
        traced = false;
        result = Probe{};
        events.clear();
        isCalls = 0;
        return h.dispatch(so, missTable.empty() ? GpuVirtualAddressRangeAndStride{} : h.table(so, missTable),
                          hitGroups.empty() ? GpuVirtualAddressRangeAndStride{} : h.table(so, hitGroups), dims, options,
                          nullptr, callables.empty() ? GpuVirtualAddressRangeAndStride{} : h.table(so, callables));
    }
};

DispatchOptions continueMode() {
    DispatchOptions o;
    o.onError = OnError::Continue;
    return o;
}

// ---------------------------------------------------------------------------------------
// RAY: TraceRay and RayDesc.

TEST(Dispatcher, RAY_1_ArgumentsUseOnlyTheirLowBits) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0x01)});
    r.h.library->addMiss<Probe>("Miss_Tag", [](ShaderContext&, Probe& p) { p.tag = 77; });
    // InstanceInclusionMask: only the low 8 bits count, so 0x100 masks everything out.
    r.args.mask = 0x100;
    r.run({"HG_Tri"}, uvec3(1u), {}, {"Miss_S", "Miss_Tag"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);
    // MissShaderIndex: only the low 16 bits count, so 0x10001 selects miss record 1.
    r.args.missIndex = 0x10001;
    r.run({"HG_Tri"}, uvec3(1u), {}, {"Miss_S", "Miss_Tag"});
    EXPECT_EQ(r.result.tag, 77u);
    EXPECT_EQ(r.result.misses, 0u);
    // RayContributionToHitGroupIndex: low 4 bits, so 0x11 selects record 1.
    r.args = {};
    r.args.mask = 0x101;
    r.args.rayContribution = 0x11;
    r.chTri = [](ShaderContext&, Probe& p, const BuiltInTriangleIntersectionAttributes&) { p.tag = 11; };
    r.run({"HG_Tri", "HG_TriS_noAH"}, uvec3(1u), {}, {"Miss_S", "Miss_Tag"});
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.tag, 11u);
    EXPECT_FLOAT_EQ(r.result.t, 5.0f);
}

TEST(Dispatcher, RAY_2_TraceRayFromIntersectionAnyHitOrCallableIsRefused) {
    Rig r;
    const auto box = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(box)});
    auto nested = [](ShaderContext& ctx) {
        Probe q;
        ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);
    };
    r.is = nested;
    auto d = expectDxrError("RAY-2", [&] { r.run({"HG_BoxS"}); });
    EXPECT_TRUE(contains(d.message, "TraceRay")) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::Intersection);

    r.is = nullptr;
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { nested(ctx); };
    d = expectDxrError("RAY-2", [&] { r.run({"HG_BoxS"}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::AnyHit);

    r.ahBox = nullptr;
    r.rg = [](ShaderContext& ctx) {
        CallParams c;
        ctx.CallShader(0, c);
    };
    r.callable = [&](ShaderContext& ctx, CallParams&) { nested(ctx); };
    d = expectDxrError("RAY-2", [&] { r.run({"HG_BoxS"}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::Callable);
    EXPECT_EQ(d.site->exportName, "CL_S");
}

TEST(Dispatcher, RAY_3_NullAccelerationStructureForcesMissWithTMax) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.useTlasOverride = true;
    r.tlasOverride = 0;
    r.ray = zRay(42.5f);
    r.run({"HG_Tri"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);
    EXPECT_EQ(r.result.t, 42.5f);
}

TEST(Dispatcher, RAY_4_DirectionIsNotNormalizedTIsInItsUnits) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.ray = RayDesc{vec3(0.0f, 0.2f, -4.0f), 0.0f, vec3(0, 0, 2), 100.0f};
    r.run({"HG_TriS_noAH"});
    ASSERT_EQ(r.result.closestHits, 1u);
    EXPECT_FLOAT_EQ(r.result.t, 2.0f);
    // TMax is in the same units: 1.9 direction lengths fall short of the triangle.
    r.ray.TMax = 1.9f;
    r.run({"HG_TriS_noAH"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);
}

TEST(Dispatcher, RAY_5_NaNInEachRayDescFieldIsAnErrorNamingTheField) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    struct Case {
        const char* field;
        std::function<void(RayDesc&)> poison;
    };
    const std::vector<Case> cases = {
        {"Origin.x", [](RayDesc& d) { d.Origin.x = kNaN; }},       {"Origin.y", [](RayDesc& d) { d.Origin.y = kNaN; }},
        {"Origin.z", [](RayDesc& d) { d.Origin.z = kNaN; }},       {"Direction.x", [](RayDesc& d) { d.Direction.x = kNaN; }},
        {"Direction.y", [](RayDesc& d) { d.Direction.y = kNaN; }}, {"Direction.z", [](RayDesc& d) { d.Direction.z = kNaN; }},
        {"TMin", [](RayDesc& d) { d.TMin = kNaN; }},               {"TMax", [](RayDesc& d) { d.TMax = kNaN; }},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.field);
        r.ray = zRay();
        c.poison(r.ray);
        const auto d = expectDxrError("RAY-5", [&] { r.run({"HG_Tri"}); });
        EXPECT_TRUE(contains(d.message, c.field)) << d.format();
        EXPECT_TRUE(contains(valueOf(d, c.field), "nan")) << d.format();
    }
}

TEST(Dispatcher, RAY_5_NegativeTMinIsAnError) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.ray.TMin = -0.5f;
    const auto d = expectDxrError("RAY-5", [&] { r.run({"HG_Tri"}); });
    EXPECT_EQ(valueOf(d, "TMin"), "-0.5");
    EXPECT_EQ(limitOf(d, "TMin"), ">= 0");
}

TEST(Dispatcher, RAY_5_TMinGreaterThanTMaxIsAnError) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.ray.TMin = 7.0f;
    r.ray.TMax = 6.0f;
    const auto d = expectDxrError("RAY-5", [&] { r.run({"HG_Tri"}); });
    EXPECT_EQ(valueOf(d, "TMin"), "7");
    EXPECT_EQ(valueOf(d, "TMax"), "6");
}

TEST(Dispatcher, RAY_5_NegativeZeroTMinIsAValidZero) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.ray.TMin = -0.0f;
    const auto result = r.run({"HG_Tri"});
    EXPECT_TRUE(result.diagnostics.empty());
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_FLOAT_EQ(r.result.t, 5.0f);
}

TEST(Dispatcher, RAY_6_TMinEqualsTMaxNoTriangleButProceduralHitAtThatT) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.ray = zRay();
    r.run({"HG_Tri"});
    ASSERT_EQ(r.result.t, 5.0f);  // the triangle's t is exactly 5
    r.ray.TMin = r.ray.TMax = 5.0f;
    r.run({"HG_Tri"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);

    Rig p;
    const auto box = p.h.blas({p.h.aabbs({unitBox()})});
    p.h.tlas({Harness::instance(box)});  // the point at t = 5 is the box centre
    p.ray = zRay();
    p.ray.TMin = p.ray.TMax = 5.0f;
    bool accepted = false;
    p.is = [&](ShaderContext& ctx) { accepted = ctx.ReportHit(5.0f, 3, ProbeAttributes{}); };
    p.run({"HG_BoxS_noAH"});
    EXPECT_TRUE(accepted);
    EXPECT_EQ(p.result.closestHits, 1u);
    EXPECT_EQ(p.result.t, 5.0f);
    EXPECT_EQ(p.result.hitKind, 3u);
}

TEST(Dispatcher, RAY_7_ZeroDirectionWarnsAndDoesNotHit) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.ray.Direction = vec3(0.0f);
    const auto result = r.run({"HG_Tri"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);
    const auto w = result.diagnostics.find("RAY-7");
    ASSERT_TRUE(w);
    EXPECT_EQ(w->severity, Severity::Warning);
    EXPECT_TRUE(result.diagnostics.errors().empty());
}

TEST(Dispatcher, RAY_7_InfiniteOriginOrDirectionComponentWarnsAndMisses) {
    // Runs in a child process: a crash inside the traversal must fail this test only.
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    for (int which = 0; which < 2; ++which) {
        SCOPED_TRACE(which == 0 ? "Origin.x = +inf" : "Direction.x = +inf");
        EXPECT_EXIT(
            {
                Rig r;
                r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
                if (which == 0) r.ray.Origin.x = kInf;
                else r.ray.Direction.x = kInf;
                DispatchOptions o;
                o.threads = 1;
                const auto result = r.run({"HG_Tri"}, uvec3(1u), o);
                const auto w = result.diagnostics.find("RAY-7");
                const bool ok = w && w->severity == Severity::Warning && result.diagnostics.errors().empty() &&
                                r.result.closestHits == 0 && r.result.misses == 1;
                std::fflush(nullptr);
                std::_Exit(ok ? 0 : 1);
            },
            ::testing::ExitedWithCode(0), "");
    }
}

TEST(Dispatcher, RAY_8_TMinNeverChangesAndTCurrentOnlyDecreasesOnCommit) {
    Rig r;
    const auto box = r.h.blas({r.h.aabbs({unitBox()})});
    r.h.tlas({Harness::instance(box)});
    r.ray.TMin = 1.5f;
    std::vector<float> tMin, tCurrent;
    r.is = [&](ShaderContext& ctx) {
        for (float t : {9.0f, 12.0f, 7.0f, 1.0f, 8.0f, 6.5f}) {
            ctx.ReportHit(t, 0, ProbeAttributes{t});
            tMin.push_back(ctx.RayTMin());
            tCurrent.push_back(ctx.RayTCurrent());
        }
    };
    r.run({"HG_BoxS_noAH"});
    for (float v : tMin) EXPECT_EQ(v, 1.5f);
    EXPECT_EQ(tCurrent, (std::vector<float>{9.0f, 9.0f, 7.0f, 7.0f, 7.0f, 6.5f}));
    EXPECT_EQ(r.result.t, 6.5f);
}

TEST(Dispatcher, RAY_9_PayloadIsPassedByValue) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    Probe* callerPayload = nullptr;
    uint32_t seenDuringCHS = 0;
    bool aliased = true;
    r.rg = [&](ShaderContext& ctx) {
        Probe p;
        p.tag = 1;
        callerPayload = &p;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);
        r.result = p;
    };
    r.chTri = [&](ShaderContext&, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        EXPECT_EQ(p.tag, 1u);  // copied in
        p.tag = 2;
        aliased = &p == callerPayload;
        seenDuringCHS = callerPayload->tag;
    };
    r.run({"HG_TriS_noAH"});
    EXPECT_FALSE(aliased);
    EXPECT_EQ(seenDuringCHS, 1u);  // the caller's copy is untouched until TraceRay returns
    EXPECT_EQ(r.result.tag, 2u);   // copied out
}

TEST(Dispatcher, RAY_10_UndefinedFlagBitsAreAnErrorNamingTheBits) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    for (uint32_t bit : {0x400u, 0x800u, 0x10000u, 0x80000000u}) {
        SCOPED_TRACE(bit);
        r.args.flags = RAY_FLAG_FORCE_OPAQUE | bit;
        const auto d = expectDxrError("RAY-10", [&] { r.run({"HG_Tri"}); });
        char hex[24];
        std::snprintf(hex, sizeof hex, "0x%X", bit);
        EXPECT_EQ(valueOf(d, "undefined bits"), hex);
    }
}

// ---------------------------------------------------------------------------------------
// FLAG: ray flags.

TEST(Dispatcher, FLAG_1_ValuesEqualD3D12) {
    EXPECT_EQ(RAY_FLAG_NONE, 0x00u);
    EXPECT_EQ(RAY_FLAG_FORCE_OPAQUE, 0x01u);
    EXPECT_EQ(RAY_FLAG_FORCE_NON_OPAQUE, 0x02u);
    EXPECT_EQ(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0x04u);
    EXPECT_EQ(RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, 0x08u);
    EXPECT_EQ(RAY_FLAG_CULL_BACK_FACING_TRIANGLES, 0x10u);
    EXPECT_EQ(RAY_FLAG_CULL_FRONT_FACING_TRIANGLES, 0x20u);
    EXPECT_EQ(RAY_FLAG_CULL_OPAQUE, 0x40u);
    EXPECT_EQ(RAY_FLAG_CULL_NON_OPAQUE, 0x80u);
    EXPECT_EQ(RAY_FLAG_SKIP_TRIANGLES, 0x100u);
    EXPECT_EQ(RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES, 0x200u);
    EXPECT_EQ(kDefinedRayFlags, 0x3FFu);
}

TEST(Dispatcher, FLAG_2_OpacityFlagsArePairwiseExclusive) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    const uint32_t group[] = {RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_FORCE_NON_OPAQUE, RAY_FLAG_CULL_OPAQUE, RAY_FLAG_CULL_NON_OPAQUE};
    for (int a = 0; a < 4; ++a) {
        for (int b = a + 1; b < 4; ++b) {
            r.args.flags = group[a] | group[b];
            SCOPED_TRACE(rayFlagsToString(r.args.flags));
            const auto d = expectDxrError("FLAG-2", [&] { r.run({"HG_Tri"}); });
            EXPECT_EQ(valueOf(d, "TraceRay flags"), rayFlagsToString(group[a] | group[b]));
        }
    }
    // One of them alone is fine.
    for (uint32_t f : group) {
        r.args.flags = f;
        EXPECT_NO_THROW(r.run({"HG_Tri"}));
    }
}

TEST(Dispatcher, FLAG_3_CullBackAndCullFrontAreExclusive) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.args.flags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_CULL_FRONT_FACING_TRIANGLES;
    const auto d = expectDxrError("FLAG-3", [&] { r.run({"HG_Tri"}); });
    EXPECT_EQ(valueOf(d, "TraceRay flags"), "CULL_BACK_FACING_TRIANGLES|CULL_FRONT_FACING_TRIANGLES");
}

TEST(Dispatcher, FLAG_4_SkipTrianglesExcludesFaceCullingAndSkipProcedural) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    for (uint32_t other : {uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES), uint32_t(RAY_FLAG_CULL_FRONT_FACING_TRIANGLES),
                           uint32_t(RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES)}) {
        r.args.flags = RAY_FLAG_SKIP_TRIANGLES | other;
        SCOPED_TRACE(rayFlagsToString(r.args.flags));
        expectDxrError("FLAG-4", [&] { r.run({"HG_Tri"}); });
    }
    // SKIP_PROCEDURAL_PRIMITIVES with face culling is legal.
    r.args.flags = RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES | RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
    EXPECT_NO_THROW(r.run({"HG_Tri"}));
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, FLAG_5_PipelineSkipTrianglesPlusRayCullBackIsRefusedNamingBothSources) {
    Rig r;
    r.recursion(1, PIPELINE_FLAG_SKIP_TRIANGLES);
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    r.h.tlas({Harness::instance(tri)});
    r.args.flags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
    const auto d = expectDxrError("FLAG-5", [&] { r.run({"HG_Tri"}); });
    EXPECT_EQ(valueOf(d, "TraceRay flags"), "CULL_BACK_FACING_TRIANGLES");
    EXPECT_EQ(valueOf(d, "pipeline flags"), "SKIP_TRIANGLES");
    // Pipeline SKIP_PROCEDURAL_PRIMITIVES plus ray SKIP_TRIANGLES.
    Rig q;
    q.recursion(1, PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES);
    q.h.tlas({Harness::instance(q.h.blas({q.h.triangles(triAt(0))}))});
    q.args.flags = RAY_FLAG_SKIP_TRIANGLES;
    const auto e = expectDxrError("FLAG-5", [&] { q.run({"HG_Tri"}); });
    EXPECT_EQ(valueOf(e, "TraceRay flags"), "SKIP_TRIANGLES");
    EXPECT_EQ(valueOf(e, "pipeline flags"), "SKIP_PROCEDURAL_PRIMITIVES");
}

TEST(Dispatcher, FLAG_6_ForceOpaqueRunsNoAnyHit) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    const auto box = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_FORCE_NON_OPAQUE),
              Harness::instance(box, 1, Matrix3x4::translation({0, 0, 3}))});
    r.args.flags = RAY_FLAG_FORCE_OPAQUE;
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_FLOAT_EQ(r.result.t, 5.0f);
    r.ray.Origin.x = 10.0f;  // misses the triangle, IS-only path: still no AHS
    r.h.tlas({Harness::instance(box, 1, Matrix3x4::translation({10, 0, 3}))});
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, FLAG_7_ForceNonOpaqueRunsAnyHitOnOpaqueGeometry) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_OPAQUE)});
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_FORCE_OPAQUE)});
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 0u);
    r.args.flags = RAY_FLAG_FORCE_NON_OPAQUE;
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, FLAG_8_AcceptFirstHitRunsClosestHitOnFirstCommitted) {
    // Two triangles: in the documented (Ordered) order the nearer is first; it wins.
    Rig r;
    const auto tri = r.h.blas({r.h.triangles({triAt(0)[0], triAt(0)[1], triAt(0)[2], triAt(-2)[0], triAt(-2)[1], triAt(-2)[2]},
                                             GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri)});
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(r.result.primitiveIndex, 1u);
    EXPECT_FLOAT_EQ(r.result.t, 3.0f);
    // IgnoreHit on the first candidate cancels the end: the search goes on to the second.
    r.ahTri = [](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        if (ctx.PrimitiveIndex() == 1) ctx.IgnoreHit();
    };
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.anyHits, 2u);
    EXPECT_EQ(r.result.primitiveIndex, 0u);
    EXPECT_FLOAT_EQ(r.result.t, 5.0f);
}

TEST(Dispatcher, FLAG_8_FirstCommittedWinsEvenIfNearerGeometryIsNotVisited) {
    // Box A is entered first (t = 4) but its IS reports a far hit (t = 20); box B is
    // entered later (t = 6) and reports t = 6. Without the flag B wins; with it, A does.
    Rig r;
    const auto box = r.h.blas({r.h.aabbs({unitBox()})});
    r.h.tlas({Harness::instance(box, 0, Matrix3x4::translation({0, 0, 0})),
              Harness::instance(box, 0, Matrix3x4::translation({0, 0, 2}))});
    r.is = [](ShaderContext& ctx) {
        const float t = ctx.InstanceIndex() == 0 ? 20.0f : 6.0f;
        ctx.ReportHit(t, ctx.InstanceIndex(), ProbeAttributes{t});
    };
    r.run({"HG_BoxS_noAH"});
    EXPECT_EQ(r.result.instanceIndex, 1u);
    EXPECT_FLOAT_EQ(r.result.t, 6.0f);
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    r.run({"HG_BoxS_noAH"});
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.instanceIndex, 0u);
    EXPECT_FLOAT_EQ(r.result.t, 20.0f);
    EXPECT_EQ(r.isCalls.load(), 1);
}

TEST(Dispatcher, FLAG_8_IgnoreHitInsideReportHitCancelsTheEndForThatCandidate) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    std::vector<bool> results;
    int after = 0;
    r.is = [&](ShaderContext& ctx) {
        results.push_back(ctx.ReportHit(8.0f, 1, ProbeAttributes{}));  // ignored by the AHS: the search goes on
        results.push_back(ctx.ReportHit(9.0f, 2, ProbeAttributes{}));  // accepted: ends inside ReportHit
        ++after;
    };
    r.ahBox = [](ShaderContext& ctx, Probe&, const ProbeAttributes&) {
        if (ctx.HitKind() == 1) ctx.IgnoreHit();
    };
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    r.run({"HG_BoxS"});
    EXPECT_EQ(results, (std::vector<bool>{false}));
    EXPECT_EQ(after, 0);
    EXPECT_EQ(r.result.anyHits, 2u);
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.hitKind, 2u);
    EXPECT_EQ(r.result.t, 9.0f);
}

TEST(Dispatcher, FLAG_9_SkipClosestHitRunsNoClosestHitButMissAndAnyHitStillRun) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri)});
    r.args.flags = RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 0u);
    EXPECT_EQ(r.result.anyHits, 1u);
    r.ray.Origin.x = 10.0f;
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.misses, 1u);
    EXPECT_EQ(r.result.closestHits, 0u);
}

TEST(Dispatcher, FLAG_10_FaceCullingAndTriangleCullDisable) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    const auto box = r.h.blas({r.h.aabbs({unitBox()})});
    struct Case {
        float dirZ;
        uint32_t flags;
        uint32_t instanceFlags;
        bool hit;
        uint32_t kind;
    };
    const Case cases[] = {
        {+1, RAY_FLAG_NONE, 0, true, HIT_KIND_TRIANGLE_FRONT_FACE},
        {-1, RAY_FLAG_NONE, 0, true, HIT_KIND_TRIANGLE_BACK_FACE},
        {+1, RAY_FLAG_CULL_FRONT_FACING_TRIANGLES, 0, false, 0},
        {+1, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, 0, true, HIT_KIND_TRIANGLE_FRONT_FACE},
        {-1, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, 0, false, 0},
        {-1, RAY_FLAG_CULL_FRONT_FACING_TRIANGLES, 0, true, HIT_KIND_TRIANGLE_BACK_FACE},
        {+1, RAY_FLAG_CULL_FRONT_FACING_TRIANGLES, INSTANCE_FLAG_TRIANGLE_CULL_DISABLE, true, HIT_KIND_TRIANGLE_FRONT_FACE},
        {-1, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, INSTANCE_FLAG_TRIANGLE_CULL_DISABLE, true, HIT_KIND_TRIANGLE_BACK_FACE},
        {+1, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE, false, 0},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(rayFlagsToString(c.flags) + " dirZ " + std::to_string(c.dirZ) + " inst " + std::to_string(c.instanceFlags));
        r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0xFF, c.instanceFlags)});
        r.ray = RayDesc{vec3(0.0f, 0.2f, -5.0f * c.dirZ), 0.0f, vec3(0, 0, c.dirZ), 100.0f};
        r.args.flags = c.flags;
        r.run({"HG_TriS_noAH"});
        EXPECT_EQ(r.result.closestHits, c.hit ? 1u : 0u);
        if (c.hit) {
            EXPECT_EQ(r.result.hitKind, c.kind);
        }
    }
    // No effect on procedural primitives.
    r.h.tlas({Harness::instance(box)});
    for (uint32_t f : {uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES), uint32_t(RAY_FLAG_CULL_FRONT_FACING_TRIANGLES)}) {
        r.args.flags = f;
        r.ray = zRay();
        r.run({"HG_BoxS_noAH"});
        EXPECT_EQ(r.result.closestHits, 1u);
    }
}

TEST(Dispatcher, FLAG_11_CullOpaqueAndNonOpaqueOnTrianglesAndAABBs) {
    Rig r;
    const auto triOpaque = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_OPAQUE)});
    const auto triNon = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    const auto boxOpaque = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_OPAQUE)});
    const auto boxNon = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    struct Case {
        GpuVirtualAddress blas;
        bool opaque;
        bool procedural;
    };
    for (const Case& c : {Case{triOpaque, true, false}, Case{triNon, false, false}, Case{boxOpaque, true, true},
                          Case{boxNon, false, true}}) {
        r.h.tlas({Harness::instance(c.blas)});
        for (uint32_t f : {uint32_t(RAY_FLAG_CULL_OPAQUE), uint32_t(RAY_FLAG_CULL_NON_OPAQUE)}) {
            SCOPED_TRACE(std::string(c.procedural ? "box" : "triangle") + (c.opaque ? " opaque " : " non-opaque ") +
                         rayFlagsToString(f));
            r.args.flags = f;
            r.run({c.procedural ? "HG_BoxS" : "HG_TriS"});
            const bool culled = (f == RAY_FLAG_CULL_OPAQUE) == c.opaque;
            EXPECT_EQ(r.result.closestHits, culled ? 0u : 1u);
            EXPECT_EQ(r.result.misses, culled ? 1u : 0u);
            EXPECT_EQ(r.result.anyHits, culled || c.opaque ? 0u : 1u);
            if (c.procedural) {
                EXPECT_EQ(r.isCalls.load(), culled ? 0 : 1);  // a culled AABB's IS never runs
            }
        }
    }
}

TEST(Dispatcher, FLAG_12_SkipTrianglesAndSkipProcedural) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0))});
    const auto box = r.h.blas({r.h.aabbs({unitBox()})});
    // Triangle at t = 5 (cull-disabled instance), box entered at t = 7.
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_TRIANGLE_CULL_DISABLE),
              Harness::instance(box, 1, Matrix3x4::translation({0, 0, 3}))});
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.instanceIndex, 0u);
    r.args.flags = RAY_FLAG_SKIP_TRIANGLES;
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.instanceIndex, 1u);
    EXPECT_FLOAT_EQ(r.result.t, 7.0f);
    r.args.flags = RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES;
    r.ray.Origin.x = 0.0f;
    r.h.tlas({Harness::instance(box, 1, Matrix3x4::translation({0, 0, 3}))});
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.isCalls.load(), 0);
    EXPECT_EQ(r.result.misses, 1u);
}

TEST(Dispatcher, FLAG_13_RayFlagsReturnsTheArgumentOnly) {
    Rig r;
    r.recursion(1, PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES);
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri)});
    std::vector<uint32_t> seen;
    r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { seen.push_back(ctx.RayFlags()); };
    r.chTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { seen.push_back(ctx.RayFlags()); };
    r.miss = [&](ShaderContext& ctx, Probe&) { seen.push_back(ctx.RayFlags()); };
    r.args.flags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_NON_OPAQUE;
    r.run({"HG_TriS"});
    r.ray.Origin.x = 10.0f;
    r.run({"HG_TriS"});
    EXPECT_EQ(seen, (std::vector<uint32_t>(3, 0x12u)));
    // Undefined bits (Continue mode) never show either.
    seen.clear();
    r.args.flags = RAY_FLAG_FORCE_OPAQUE | 0x1000;
    r.run({"HG_TriS"}, uvec3(1u), continueMode());
    EXPECT_EQ(seen, (std::vector<uint32_t>{0x1u}));
}

// ---------------------------------------------------------------------------------------
// OPQ: opacity.

TEST(Dispatcher, OPQ_1_PrecedenceRayOverInstanceOverGeometryExhaustive) {
    Rig r;
    const auto triOpaque = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_OPAQUE)});
    const auto triNon = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    const auto boxOpaque = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_OPAQUE)});
    const auto boxNon = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    const uint32_t instanceFlags[] = {INSTANCE_FLAG_NONE, INSTANCE_FLAG_FORCE_OPAQUE, INSTANCE_FLAG_FORCE_NON_OPAQUE};
    const uint32_t rayFlags[] = {RAY_FLAG_NONE, RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_FORCE_NON_OPAQUE};
    for (bool procedural : {false, true}) {
        for (bool geometryOpaque : {false, true}) {
            for (uint32_t inst : instanceFlags) {
                for (uint32_t ray : rayFlags) {
                    bool opaque = geometryOpaque;
                    if (inst == INSTANCE_FLAG_FORCE_OPAQUE) opaque = true;
                    if (inst == INSTANCE_FLAG_FORCE_NON_OPAQUE) opaque = false;
                    if (ray == RAY_FLAG_FORCE_OPAQUE) opaque = true;
                    if (ray == RAY_FLAG_FORCE_NON_OPAQUE) opaque = false;
                    SCOPED_TRACE(std::string(procedural ? "box" : "tri") + " geometry " + (geometryOpaque ? "opaque" : "non") +
                                 " instance " + instanceFlagsToString(inst) + " ray " + rayFlagsToString(ray));
                    const auto blas = procedural ? (geometryOpaque ? boxOpaque : boxNon) : (geometryOpaque ? triOpaque : triNon);
                    r.h.tlas({Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF, inst)});
                    r.args.flags = ray;
                    r.run({procedural ? "HG_BoxS" : "HG_TriS"});
                    EXPECT_EQ(r.result.anyHits, opaque ? 0u : 1u);
                    EXPECT_EQ(r.result.closestHits, 1u);
                    // OPQ-2: culling follows the same result (ray FORCE_* excluded by FLAG-2).
                    if (ray == RAY_FLAG_NONE) {
                        r.args.flags = RAY_FLAG_CULL_OPAQUE;
                        r.run({procedural ? "HG_BoxS" : "HG_TriS"});
                        EXPECT_EQ(r.result.closestHits, opaque ? 0u : 1u);
                        r.args.flags = RAY_FLAG_CULL_NON_OPAQUE;
                        r.run({procedural ? "HG_BoxS" : "HG_TriS"});
                        EXPECT_EQ(r.result.closestHits, opaque ? 1u : 0u);
                    }
                }
            }
        }
    }
}

TEST(Dispatcher, OPQ_2_CullingIgnoresWhetherTheHitGroupHasAnAnyHit) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri)});
    r.args.flags = RAY_FLAG_CULL_NON_OPAQUE;
    r.run({"HG_TriS_noAH"});  // no AHS, but the geometry is still non-opaque
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);
    r.args.flags = RAY_FLAG_CULL_OPAQUE;
    r.run({"HG_TriS_noAH"});
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, OPQ_3_AnyHitRunsIffNonOpaqueAndPresent) {
    Rig r;
    const auto triNon = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    const auto triOpaque = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_OPAQUE)});
    r.h.tlas({Harness::instance(triNon)});
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 1u);
    r.run({"HG_TriS_noAH"});  // non-opaque, no AHS: accepted directly
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.closestHits, 1u);
    r.h.tlas({Harness::instance(triOpaque)});
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, OPQ_4_NullHitGroupCommitsWithoutAnyHitOrClosestHit) {
    Rig r;
    // Geometry 0 (NULL record) at t = 3 in front of geometry 1 (HG_TriS) at t = 5.
    const auto tri = r.h.blas({r.h.triangles(triAt(-2), GEOMETRY_FLAG_NONE), r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri)});
    r.initial.tag = 99;
    r.run({"", "HG_TriS"});
    // The NULL group's candidate was committed (so geometry 1 lost), and nothing ran.
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 0u);
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.tag, 99u);
    // A procedural geometry with a NULL hit group never produces a hit.
    Rig p;
    p.h.tlas({Harness::instance(p.h.blas({p.h.aabbs({unitBox()})}))});
    p.run({""});
    EXPECT_EQ(p.result.misses, 1u);
    EXPECT_EQ(p.isCalls.load(), 0);
}

TEST(Dispatcher, OPQ_5_SilentFiltersRunNoShaderAndEmitNoDiagnostic) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    const auto box = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0x02),
              Harness::instance(box, 1, Matrix3x4::translation({0, 0, 3}), 0x02)});
    struct Case {
        uint32_t flags, mask;
        float tMax;
    };
    for (const Case& c : {Case{RAY_FLAG_NONE, 0x01, 100}, Case{RAY_FLAG_CULL_NON_OPAQUE, 0xFF, 100},
                          Case{RAY_FLAG_CULL_FRONT_FACING_TRIANGLES | RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES, 0xFF, 100},
                          Case{RAY_FLAG_NONE, 0xFF, 4.0f}}) {
        SCOPED_TRACE(rayFlagsToString(c.flags));
        r.args.flags = c.flags;
        r.args.mask = c.mask;
        r.ray.TMax = c.tMax;
        const auto result = r.run({"HG_TriS", "HG_BoxS"});
        EXPECT_TRUE(result.diagnostics.empty());
        EXPECT_EQ(r.result.anyHits, 0u);
        EXPECT_EQ(r.result.misses, 1u);
        EXPECT_EQ(r.isCalls.load(), 0);
    }
}

// ---------------------------------------------------------------------------------------
// TRV: traversal and hit processing.

TEST(Dispatcher, TRV_1_BoxTouchedOnlyAtItsFaceIsEnumerated) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    r.ray = RayDesc{vec3(1.0f, 0.0f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f};  // runs along the face x = 1
    r.run({"HG_BoxS_noAH"});
    EXPECT_EQ(r.isCalls.load(), 1);
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, TRV_2_TriangleIntervalIsOpenProceduralIsClosed) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.run({"HG_Tri"});
    ASSERT_EQ(r.result.t, 5.0f);
    r.ray.TMin = 5.0f;
    r.run({"HG_Tri"});
    EXPECT_EQ(r.result.closestHits, 0u) << "t == TMin must not hit a triangle";
    r.ray = zRay(5.0f);
    r.run({"HG_Tri"});
    EXPECT_EQ(r.result.closestHits, 0u) << "t == TMax must not hit a triangle";
    r.ray.TMin = 4.5f;
    r.ray.TMax = 5.5f;
    r.run({"HG_Tri"});
    EXPECT_EQ(r.result.closestHits, 1u);

    Rig p;
    p.h.tlas({Harness::instance(p.h.blas({p.h.aabbs({unitBox()})}))});
    p.ray.TMin = 4.5f;
    p.ray.TMax = 5.5f;
    std::vector<bool> accepted;
    p.is = [&](ShaderContext& ctx) {
        accepted.push_back(ctx.ReportHit(5.5f, 0, ProbeAttributes{}));  // == TMax
        accepted.push_back(ctx.ReportHit(4.5f, 0, ProbeAttributes{}));  // == TMin
    };
    p.run({"HG_BoxS_noAH"});
    EXPECT_EQ(accepted, (std::vector<bool>{true, true}));
    EXPECT_EQ(p.result.t, 4.5f);
}

TEST(Dispatcher, TRV_3_TriangleAtCommittedTIsRejected) {
    Rig r;
    // Two coincident non-opaque triangles in geometries 0 and 1.
    r.h.tlas({Harness::instance(
        r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE), r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)}))});
    r.run({"HG_TriS", "HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(r.result.geometryIndex, 0u);
}

TEST(Dispatcher, TRV_3_ReportHitAtExactlyTCurrentIsAcceptedAndReplaces) {
    Rig r;
    // Triangle (instance 0) at t = 5; box (instance 1) entered at exactly t = 5.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))})),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}), 1, Matrix3x4::translation({0, 0, 1}))});
    float seen = -1.0f;
    bool accepted = false;
    r.is = [&](ShaderContext& ctx) {
        seen = ctx.RayTCurrent();
        accepted = ctx.ReportHit(ctx.RayTCurrent(), 9, ProbeAttributes{});
    };
    r.run({"HG_TriS_noAH", "HG_BoxS_noAH"});
    EXPECT_EQ(seen, 5.0f);
    EXPECT_TRUE(accepted);
    EXPECT_EQ(r.result.instanceIndex, 1u);
    EXPECT_EQ(r.result.hitKind, 9u);
    EXPECT_EQ(r.result.t, 5.0f);
}

TEST(Dispatcher, TRV_4_CandidateBeyondCurrentTCurrentIsDroppedWithoutAnyHit) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    std::vector<float> ahsT;
    std::vector<bool> accepted;
    r.is = [&](ShaderContext& ctx) {
        for (float t : {6.0f, 7.0f, 5.5f}) accepted.push_back(ctx.ReportHit(t, 0, ProbeAttributes{t}));
    };
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes& a) {
        ahsT.push_back(ctx.RayTCurrent());
        EXPECT_EQ(a.value, ctx.RayTCurrent());
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(ahsT, (std::vector<float>{6.0f, 5.5f}));
    EXPECT_EQ(accepted, (std::vector<bool>{true, false, true}));
    EXPECT_EQ(r.result.t, 5.5f);
}

TEST(Dispatcher, TRV_5_ClosestHitComesFromTheHitsRecordWithRAndM) {
    Rig r;
    r.h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Tag", [](ShaderContext&, Probe& p, const BuiltInTriangleIntersectionAttributes&) { p.tag = 6; });
    r.h.stateObject.hitGroups.push_back({"HG_Tag", HitGroupType::Triangles, "", "CH_Tag", ""});
    // Geometry 1 hit; I = R + M*G + C = 1 + 2*1 + 3 = 6.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(5)), r.h.triangles(triAt(0))}), 3)});
    r.args.rayContribution = 1;
    r.args.multiplier = 2;
    r.run({"HG_Tri", "HG_Tri", "HG_Tri", "HG_Tri", "HG_Tri", "HG_Tri", "HG_Tag", "HG_Tri"});
    EXPECT_EQ(r.result.tag, 6u);
}

TEST(Dispatcher, TRV_6_ExactlyOneClosestHitOrMissPerTraceRay) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)})),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}), 1, Matrix3x4::translation({0.5f, 0, 2}))});
    std::vector<Probe> out(16 * 16);
    r.rg = [&](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        Probe p;
        const RayDesc ray{vec3(-2.0f + i.x * 0.25f, -2.0f + i.y * 0.25f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f};
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
        out[i.y * 16 + i.x] = p;
    };
    r.run({"HG_TriS", "HG_BoxS"}, uvec3(16, 16, 1));
    int hits = 0, misses = 0;
    for (const Probe& p : out) {
        EXPECT_EQ(p.closestHits + p.misses, 1u);
        hits += p.closestHits;
        misses += p.misses;
    }
    EXPECT_GT(hits, 0);
    EXPECT_GT(misses, 0);
}

TEST(Dispatcher, TRV_7_AllAnyHitsFinishBeforeClosestHit) {
    Rig r;
    r.log = true;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    r.is = [](ShaderContext& ctx) {
        for (float t : {9.0f, 8.0f, 7.0f}) ctx.ReportHit(t, 0, ProbeAttributes{t});
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(r.events, (std::vector<std::string>{"RG", "IS", "AH", "AH", "AH", "CH"}));
}

TEST(Dispatcher, TRV_8_ObjectRayUnderRotatedScaledTranslatedInstance) {
    Rig r;
    const Matrix3x4 m =
        Matrix3x4::translation({3.0f, -2.0f, 7.5f}) * Matrix3x4::rotation(glm::normalize(vec3(1, 2, 3)), 0.7f) *
        Matrix3x4::scale({2.0f, 0.5f, 3.0f});
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles({{-10, -10, 0}, {0, 10, 0}, {10, -10, 0}})}), 0, m)});
    const vec3 objectHit(0.5f, 0.25f, 0.0f);
    const vec3 worldHit = m.transformPoint(objectHit);
    const vec3 worldDir = m.transformVector(vec3(0.1f, -0.2f, 1.0f));
    r.ray = RayDesc{worldHit - 3.0f * worldDir, 0.0f, worldDir, 100.0f};
    vec3 objOrigin{0.0f}, objDir{0.0f};
    r.chTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        objOrigin = ctx.ObjectRayOrigin();
        objDir = ctx.ObjectRayDirection();
    };
    r.run({"HG_TriS_noAH"});
    ASSERT_EQ(r.result.closestHits, 1u);
    EXPECT_NEAR(r.result.t, 3.0f, 3e-5f);  // world t
    const vec3 p = objOrigin + r.result.t * objDir;
    EXPECT_NEAR(p.x, objectHit.x, 1e-4f);
    EXPECT_NEAR(p.y, objectHit.y, 1e-4f);
    EXPECT_NEAR(p.z, objectHit.z, 1e-4f);
    // The object direction is the mapped world direction, not renormalized.
    EXPECT_NEAR(objDir.x, 0.1f, 1e-5f);
    EXPECT_NEAR(objDir.y, -0.2f, 1e-5f);
    EXPECT_NEAR(objDir.z, 1.0f, 1e-5f);
}

TEST(Dispatcher, TRV_9_NestedTraceRayFromClosestHitIsIndependent) {
    Rig r;
    // Instance 0: triangle at t = 5; instance 1 (mask 0x02): triangle far away along +x.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}), 0, Matrix3x4::identity(), 0x01),
              Harness::instance(r.h.blas({r.h.triangles(triAt(0))}), 0, Matrix3x4::translation({0, 0, 20}), 0x02)});
    r.args.mask = 0x01;
    Probe inner;
    float tBefore = -1, tAfter = -1;
    uint32_t instAfter = ~0u;
    r.chTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        if (ctx.InstanceIndex() != 0) return;  // the inner ray's CHS
        tBefore = ctx.RayTCurrent();
        p.tag = 5;
        Probe q;
        q.tag = 100;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0x02, 0, 1, 0, zRay(), q);
        inner = q;
        tAfter = ctx.RayTCurrent();
        instAfter = ctx.InstanceIndex();
        EXPECT_EQ(p.tag, 5u);
    };
    r.run({"HG_TriS_noAH"});
    EXPECT_EQ(inner.closestHits, 1u);
    EXPECT_FLOAT_EQ(inner.t, 25.0f);
    EXPECT_EQ(inner.instanceIndex, 1u);
    EXPECT_EQ(inner.tag, 100u);
    EXPECT_EQ(tBefore, 5.0f);
    EXPECT_EQ(tAfter, 5.0f);
    EXPECT_EQ(instAfter, 0u);
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.tag, 5u);
    EXPECT_EQ(r.result.instanceIndex, 0u);
}

// ---------------------------------------------------------------------------------------
// IS: intersection shaders and ReportHit.

TEST(Dispatcher, IS_1_OneIntersectionCallPerEnumeratedBoxByDefault) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox(), {-1, -1, 3, 1, 1, 5}, {-1, -1, 7, 1, 1, 9}})}))});
    std::vector<uint32_t> prims;
    r.is = [&](ShaderContext& ctx) { prims.push_back(ctx.PrimitiveIndex()); };  // reports nothing
    r.run({"HG_BoxS"});
    EXPECT_EQ(prims, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(r.result.misses, 1u);
}

TEST(Dispatcher, IS_2_IntersectionMayNotUseHitKindIgnoreHitAcceptOrCallShader) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    struct Case {
        const char* rule;
        const char* intrinsic;
        std::function<void(ShaderContext&)> fn;
    };
    const std::vector<Case> cases = {
        {"SV-1", "HitKind", [](ShaderContext& ctx) { (void)ctx.HitKind(); }},
        {"SV-1", "IgnoreHit", [](ShaderContext& ctx) { ctx.IgnoreHit(); }},
        {"SV-1", "AcceptHitAndEndSearch", [](ShaderContext& ctx) { ctx.AcceptHitAndEndSearch(); }},
        {"CALL-2", "CallShader", [](ShaderContext& ctx) {
             CallParams c;
             ctx.CallShader(0, c);
         }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.intrinsic);
        r.is = c.fn;
        const auto d = expectDxrError(c.rule, [&] { r.run({"HG_BoxS"}); });
        EXPECT_TRUE(contains(d.message, c.intrinsic)) << d.format();
    }
}

TEST(Dispatcher, IS_3_ReportHitOutsideTheClosedIntervalReturnsFalse) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    r.ray.TMin = 2.0f;
    r.ray.TMax = 10.0f;
    std::vector<bool> results;
    r.is = [&](ShaderContext& ctx) {
        results.push_back(ctx.ReportHit(1.999f, 0, ProbeAttributes{}));
        results.push_back(ctx.ReportHit(10.001f, 0, ProbeAttributes{}));
        results.push_back(ctx.ReportHit(-1.0f, 0, ProbeAttributes{}));
        results.push_back(ctx.ReportHit(kInf, 0, ProbeAttributes{}));
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(results, (std::vector<bool>(4, false)));
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.misses, 1u);
}

TEST(Dispatcher, IS_3_NaNTHitIsAnErrorAndRejected) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    bool accepted = true;
    r.is = [&](ShaderContext& ctx) { accepted = ctx.ReportHit(kNaN, 0, ProbeAttributes{}); };
    const auto d = expectDxrError("IS-3", [&] { r.run({"HG_BoxS"}); });
    EXPECT_TRUE(contains(valueOf(d, "THit"), "nan")) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::Intersection);
    EXPECT_EQ(d.site->exportName, "IS_S");
    // Continue: the fallback rejects the hit.
    const auto result = r.run({"HG_BoxS"}, uvec3(1u), continueMode());
    EXPECT_FALSE(accepted);
    EXPECT_EQ(r.result.misses, 1u);
    ASSERT_TRUE(result.diagnostics.find("IS-3"));
}

TEST(Dispatcher, IS_4_HitKindAbove127IsAnError) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    r.isKind = 200;
    const auto d = expectDxrError("IS-4", [&] { r.run({"HG_BoxS"}); });
    EXPECT_EQ(valueOf(d, "HitKind"), "200");
    EXPECT_EQ(limitOf(d, "HitKind"), "0..127");
    // Continue: the value passes through unchanged.
    r.run({"HG_BoxS"}, uvec3(1u), continueMode());
    EXPECT_EQ(r.result.hitKind, 200u);
    r.isKind = 127;
    const auto ok = r.run({"HG_BoxS"});
    EXPECT_TRUE(ok.diagnostics.empty());
    EXPECT_EQ(r.result.hitKind, 127u);
}

TEST(Dispatcher, IS_5_AttributeTypeMismatchIsAnError) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    r.is = [](ShaderContext& ctx) { ctx.ReportHit(5.0f, 0, OtherAttributes{1, 2}); };
    const auto d = expectDxrError("IS-5", [&] { r.run({"HG_BoxS"}); });
    EXPECT_TRUE(contains(valueOf(d, "reported"), "OtherAttributes")) << d.format();
    EXPECT_TRUE(contains(valueOf(d, "expected"), "ProbeAttributes")) << d.format();
}

TEST(Dispatcher, IS_5_AttributeTypeIsCheckedOnEveryReportHitEvenARejectedOne) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    r.is = [](ShaderContext& ctx) { ctx.ReportHit(1000.0f, 0, OtherAttributes{1, 2}); };  // beyond TMax
    expectDxrError("IS-5", [&] { r.run({"HG_BoxS"}); });
}

TEST(Dispatcher, IS_6_OpaqueInRangeCommitsAtOnceWithoutAnyHit) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_OPAQUE)}))});
    bool accepted = false;
    r.is = [&](ShaderContext& ctx) { accepted = ctx.ReportHit(6.0f, 1, ProbeAttributes{6.0f}); };
    r.run({"HG_BoxS"});
    EXPECT_TRUE(accepted);
    EXPECT_EQ(r.result.anyHits, 0u);
    EXPECT_EQ(r.result.t, 6.0f);
}

TEST(Dispatcher, IS_7_AnyHitRunsInsideReportHitAndDecidesItsResult) {
    Rig r;
    r.log = true;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    std::vector<bool> results;
    int after = 0;
    float ahT = -1, ahAttr = -1;
    uint32_t ahKind = 0;
    r.is = [&](ShaderContext& ctx) {
        results.push_back(ctx.ReportHit(8.0f, 4, ProbeAttributes{8.5f}));
        r.events.push_back("IS-after-1");
        results.push_back(ctx.ReportHit(7.0f, 5, ProbeAttributes{7.5f}));
        r.events.push_back("IS-after-2");
        results.push_back(ctx.ReportHit(6.0f, 6, ProbeAttributes{6.5f}));
        ++after;
    };
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes& a) {
        ahT = ctx.RayTCurrent();
        ahKind = ctx.HitKind();
        ahAttr = a.value;
        if (ctx.HitKind() == 5) ctx.IgnoreHit();
        if (ctx.HitKind() == 6) ctx.AcceptHitAndEndSearch();
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(results, (std::vector<bool>{true, false}));
    EXPECT_EQ(after, 0);  // AcceptHitAndEndSearch terminated the IS
    EXPECT_EQ(ahT, 6.0f);
    EXPECT_EQ(ahKind, 6u);
    EXPECT_EQ(ahAttr, 6.5f);
    EXPECT_EQ(r.events, (std::vector<std::string>{"RG", "IS", "AH", "IS-after-1", "AH", "IS-after-2", "AH", "CH"}));
    EXPECT_EQ(r.result.t, 6.0f);
    EXPECT_EQ(r.result.hitKind, 6u);
}

TEST(Dispatcher, IS_8_RayTCurrentUpdatesAfterAcceptedReportHitOnly) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    std::vector<float> seen;
    r.is = [&](ShaderContext& ctx) {
        seen.push_back(ctx.RayTCurrent());
        ctx.ReportHit(8.0f, 0, ProbeAttributes{});
        seen.push_back(ctx.RayTCurrent());
        ctx.ReportHit(9.0f, 0, ProbeAttributes{});  // rejected
        seen.push_back(ctx.RayTCurrent());
    };
    r.ray.TMax = 50.0f;
    r.run({"HG_BoxS_noAH"});
    EXPECT_EQ(seen, (std::vector<float>{50.0f, 8.0f, 8.0f}));
}

TEST(Dispatcher, IS_9_MultipleReportHitCallsAreSeparateCandidates) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    std::vector<bool> results;
    r.is = [&](ShaderContext& ctx) {
        results.push_back(ctx.ReportHit(8.0f, 1, ProbeAttributes{}));
        results.push_back(ctx.ReportHit(6.0f, 2, ProbeAttributes{}));
        results.push_back(ctx.ReportHit(7.0f, 3, ProbeAttributes{}));
        results.push_back(ctx.ReportHit(6.0f, 4, ProbeAttributes{}));
    };
    r.run({"HG_BoxS_noAH"});
    EXPECT_EQ(results, (std::vector<bool>{true, true, false, true}));
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.t, 6.0f);
    EXPECT_EQ(r.result.hitKind, 4u);
}

TEST(Dispatcher, IS_10_CodeAfterTerminatingReportHitNeverRuns) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    int after = 0;
    r.is = [&](ShaderContext& ctx) {
        ctx.ReportHit(8.0f, 1, ProbeAttributes{});
        ++after;
        ctx.ReportHit(6.0f, 2, ProbeAttributes{});
        ++after;
    };
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    r.run({"HG_BoxS_noAH"});
    EXPECT_EQ(after, 0);
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.t, 8.0f);
    EXPECT_EQ(r.result.hitKind, 1u);
}

// ReportHitEnd::Return: the shader promises its ReportHit is its last action, so an ending ReportHit returns true
// instead of unwinding. Everything DXR defines comes out as with the unwind; a broken promise is an IS-10 error.
TEST(Dispatcher, IS_10_ReturnDeclaredShaderEndsTheSearchWithoutUnwinding) {
    Rig r;
    const auto box = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});  // non-opaque: the AHS runs
    // Two boxes on the ray: entries at t = 4 and t = 7.
    r.h.tlas({Harness::instance(box), Harness::instance(box, 0, Matrix3x4::translation({0, 0, 3}))});
    std::vector<bool> results;
    r.is = [&](ShaderContext& ctx) {
        auto slab = intersectAABB(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(), unitBox(), ctx.RayTMin(),
                                  ctx.RayTCurrent());
        if (slab) results.push_back(ctx.ReportHit(slab->tEnter, 3, ProbeAttributes{slab->tEnter}));
    };
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;  // FLAG-8
    for (const char* group : {"HG_BoxS_noAH", "HG_BoxR_noAH"}) {
        SCOPED_TRACE(group);
        results.clear();
        r.run({group});
        EXPECT_EQ(r.isCalls, 1);  // the search ended at the first box
        EXPECT_EQ(r.result.closestHits, 1u);
        EXPECT_EQ(r.result.t, 4.0f);
        EXPECT_EQ(r.result.hitKind, 3u);
        // Unwound, the call never returns; declared, it returns true.
        EXPECT_EQ(results, std::string(group) == "HG_BoxR_noAH" ? std::vector<bool>{true} : std::vector<bool>{});
    }
    // An any-hit shader's AcceptHitAndEndSearch inside ReportHit ends the IS the same way.
    r.args.flags = RAY_FLAG_NONE;
    r.ahBox = [](ShaderContext& ctx, Probe&, const ProbeAttributes&) { ctx.AcceptHitAndEndSearch(); };
    results.clear();
    r.run({"HG_BoxR"});
    EXPECT_EQ(results, std::vector<bool>{true});
    EXPECT_EQ(r.isCalls, 1);
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(r.result.t, 4.0f);
    // With the shortcuts off the declaration is ignored: the call unwinds.
    DispatchOptions plain;
    plain.specialise = false;
    results.clear();
    r.run({"HG_BoxR"}, uvec3(1u), plain);
    EXPECT_TRUE(results.empty());
    EXPECT_EQ(r.isCalls, 1);
    EXPECT_EQ(r.result.t, 4.0f);
}

TEST(Dispatcher, IS_10_ReturnDeclaredShaderUsingAnIntrinsicAfterTheEndIsAnError) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    struct Case {
        const char* what;
        std::function<void(ShaderContext&)> after;
    };
    const std::vector<Case> cases = {
        {"RayTCurrent()", [](ShaderContext& ctx) { (void)ctx.RayTCurrent(); }},
        {"ReportHit()", [](ShaderContext& ctx) { ctx.ReportHit(6.0f, 0, ProbeAttributes{}); }},
        {"DispatchRaysIndex()", [](ShaderContext& ctx) { (void)ctx.DispatchRaysIndex(); }},
        {"a global root argument read", [](ShaderContext& ctx) { (void)ctx.globalRootDescriptor(0); }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        r.is = [&](ShaderContext& ctx) {
            ctx.ReportHit(8.0f, 1, ProbeAttributes{});
            c.after(ctx);
        };
        const auto d = expectDxrError("IS-10", [&] { r.run({"HG_BoxR_noAH"}); });
        EXPECT_TRUE(contains(d.message, "'IS_R'")) << d.format();
        EXPECT_TRUE(contains(d.message, std::string("used ") + c.what + " after a ReportHit that ended the search"))
            << d.format();
        // Without the declaration the same script is fine: the unwind never lets it get there.
        r.run({"HG_BoxS_noAH"});
        EXPECT_EQ(r.result.t, 8.0f);
    }
}

// ---------------------------------------------------------------------------------------
// AHS: any-hit shaders.

TEST(Dispatcher, AHS_1_NeverRunsForTAtOrBeyondTCurrent) {
    Rig r;
    // prim 0 at t = 5, prim 1 at t = 7, prim 2 coincident with prim 0.
    std::vector<vec3> v;
    for (float z : {0.0f, 2.0f, 0.0f})
        for (const vec3& p : triAt(z)) v.push_back(p);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NONE)}))});
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(r.result.primitiveIndex, 0u);
    // Under every adversarial order: each AHS candidate lies strictly below the committed t.
    for (uint64_t seed = 0; seed < 16; ++seed) {
        float committed = kInf;
        bool ok = true;
        r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
            ok = ok && ctx.RayTCurrent() < committed;
            committed = ctx.RayTCurrent();  // returning accepts
        };
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        r.run({"HG_TriS"}, uvec3(1u), o);
        EXPECT_TRUE(ok) << "seed " << seed;
        EXPECT_FLOAT_EQ(r.result.t, 5.0f);
    }
}

TEST(Dispatcher, AHS_2_AnyHitSeesCandidateTKindAndBarycentrics) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)}))});
    float t = -1;
    uint32_t kind = 0;
    vec2 bary{-1.0f};
    r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes& a) {
        t = ctx.RayTCurrent();
        kind = ctx.HitKind();
        bary = a.barycentrics;
    };
    r.run({"HG_TriS"});
    EXPECT_EQ(t, 5.0f);
    EXPECT_EQ(kind, HIT_KIND_TRIANGLE_FRONT_FACE);
    EXPECT_NEAR(bary.x, 0.6f, 1e-6f);
    EXPECT_NEAR(bary.y, 0.2f, 1e-6f);
}

TEST(Dispatcher, AHS_3_OutcomesAcceptIgnoreAndAcceptAndEnd) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    r.is = [](ShaderContext& ctx) {
        ctx.ReportHit(9.0f, 1, ProbeAttributes{});
        ctx.ReportHit(8.0f, 2, ProbeAttributes{});
        ctx.ReportHit(7.0f, 3, ProbeAttributes{});
    };
    // Accept everything: the nearest wins, the search continues after each accept.
    r.run({"HG_BoxS"});
    EXPECT_EQ(r.result.anyHits, 3u);
    EXPECT_EQ(r.result.hitKind, 3u);
    // Ignore kind 3: the committed hit stays kind 2.
    r.ahBox = [](ShaderContext& ctx, Probe&, const ProbeAttributes&) {
        if (ctx.HitKind() == 3) ctx.IgnoreHit();
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(r.result.anyHits, 3u);
    EXPECT_EQ(r.result.hitKind, 2u);
    EXPECT_EQ(r.result.t, 8.0f);
    // AcceptHitAndEndSearch on kind 1: the CHS runs on it, nothing else is visited.
    r.ahBox = [](ShaderContext& ctx, Probe&, const ProbeAttributes&) {
        if (ctx.HitKind() == 1) ctx.AcceptHitAndEndSearch();
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.hitKind, 1u);
    EXPECT_EQ(r.result.t, 9.0f);
}

TEST(Dispatcher, AHS_4_IgnoreAndAcceptEndTheShaderAndKeepPayloadChanges) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)}))});
    int after = 0;
    r.ahTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        p.tag = 42;
        ctx.IgnoreHit();
        ++after;
        p.tag = 43;
    };
    r.run({"HG_TriS"});
    EXPECT_EQ(after, 0);
    EXPECT_EQ(r.result.tag, 42u);
    EXPECT_EQ(r.result.misses, 1u);
    r.ahTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        p.tag = 52;
        ctx.AcceptHitAndEndSearch();
        ++after;
        p.tag = 53;
    };
    r.run({"HG_TriS"});
    EXPECT_EQ(after, 0);
    EXPECT_EQ(r.result.tag, 52u);
    EXPECT_EQ(r.result.closestHits, 1u);
}

TEST(Dispatcher, AHS_5_OrderAndCountMayVaryButResultDoesNot) {
    Rig r;
    std::vector<vec3> v;
    for (float z : {3.0f, 0.0f, 1.0f, 2.0f})
        for (const vec3& p : triAt(z)) v.push_back(p);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION)}))});
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.anyHits, 1u);  // Ordered: nearest first, the rest fall outside
    std::set<uint32_t> counts;
    for (uint64_t seed = 0; seed < 16; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        r.run({"HG_TriS"}, uvec3(1u), o);
        EXPECT_EQ(r.result.primitiveIndex, 1u);
        EXPECT_FLOAT_EQ(r.result.t, 5.0f);
        counts.insert(r.result.anyHits);
    }
    EXPECT_GT(counts.size(), 1u);
}

TEST(Dispatcher, AHS_6_DuplicatesOnlyWithoutNoDuplicateFlag) {
    for (bool noDuplicate : {false, true}) {
        SCOPED_TRACE(noDuplicate ? "NO_DUPLICATE_ANYHIT_INVOCATION" : "no flag");
        Rig r;
        const uint32_t gflags = noDuplicate ? GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION : GEOMETRY_FLAG_NONE;
        r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), gflags)})),
                  Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, gflags)}), 1, Matrix3x4::translation({4, 0, 0}))});
        r.ahTri = [](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { ctx.IgnoreHit(); };
        std::vector<uint32_t> triAH(64), boxAH(64);
        r.rg = [&](ShaderContext& ctx) {
            const uvec3 i = ctx.DispatchRaysIndex();
            Probe p;
            ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);
            triAH[i.x] = p.anyHits;
            Probe q;
            RayDesc ray = zRay();
            ray.Origin.x = 4.0f;
            ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, q);
            boxAH[i.x] = q.anyHits;
        };
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = 7;
        r.run({"HG_TriS", "HG_BoxS"}, uvec3(64, 1, 1), o);
        uint32_t triTotal = 0, boxTotal = 0;
        for (int i = 0; i < 64; ++i) {
            EXPECT_GE(triAH[i], 1u);
            EXPECT_GE(boxAH[i], 1u);
            if (noDuplicate) {
                EXPECT_EQ(triAH[i], 1u);
                EXPECT_EQ(boxAH[i], 1u);
            }
            triTotal += triAH[i];
            boxTotal += boxAH[i];
        }
        if (!noDuplicate) {
            EXPECT_GT(triTotal, 64u);  // triangle duplicates follow an IgnoreHit
            EXPECT_GT(boxTotal, 64u);  // procedural duplicates follow an accept (t == TCurrent)
        }
    }
}

TEST(Dispatcher, AHS_7_AnyHitMayNotReportHitTraceRayOrCallShader) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    struct Case {
        const char* rule;
        const char* intrinsic;
        std::function<void(ShaderContext&)> fn;
    };
    const std::vector<Case> cases = {
        {"SV-1", "ReportHit", [](ShaderContext& ctx) { ctx.ReportHit(1.0f, 0, ProbeAttributes{}); }},
        {"RAY-2", "TraceRay",
         [](ShaderContext& ctx) {
             Probe q;
             ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);
         }},
        {"CALL-2", "CallShader",
         [](ShaderContext& ctx) {
             CallParams c;
             ctx.CallShader(0, c);
         }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.intrinsic);
        r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { c.fn(ctx); };
        const auto d = expectDxrError(c.rule, [&] { r.run({"HG_BoxS"}); });
        EXPECT_TRUE(contains(d.message, c.intrinsic)) << d.format();
        ASSERT_TRUE(d.site);
        EXPECT_EQ(d.site->stage, ShaderStage::AnyHit);
        EXPECT_EQ(d.site->exportName, "AH_BoxS");
    }
}

// ---------------------------------------------------------------------------------------
// CHS, MISS, RGS, CALL.

TEST(Dispatcher, CHS_1_AtMostOnceOnFinalCommittedHitAndSkippedWhenAbsent) {
    Rig r;
    std::vector<vec3> v;
    for (float z : {2.0f, 0.0f, 1.0f})
        for (const vec3& p : triAt(z)) v.push_back(p);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NONE)}))});
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.primitiveIndex, 1u);
    r.run({"HG_TriS_noCH"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 0u);
    EXPECT_EQ(r.result.anyHits, 1u);
    r.run({""});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 0u);
    r.args.flags = RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.closestHits, 0u);
    EXPECT_EQ(r.result.misses, 0u);
}

TEST(Dispatcher, CHS_2_ClosestHitSeesFirstAcceptedUnderAcceptFirstEvenIfNotNearest) {
    Rig r;
    std::vector<vec3> v;
    for (float z : {2.0f, 0.0f, 1.0f})
        for (const vec3& p : triAt(z)) v.push_back(p);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NONE)}), 0, Matrix3x4::identity(), 0xFF,
                                INSTANCE_FLAG_NONE, 0x123)});
    float ahsT = -1;
    uint32_t ahsPrim = ~0u;
    r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        ahsT = ctx.RayTCurrent();
        ahsPrim = ctx.PrimitiveIndex();
    };
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    bool sawFarther = false;
    for (uint64_t seed = 0; seed < 16; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        r.run({"HG_TriS"}, uvec3(1u), o);
        ASSERT_EQ(r.result.closestHits, 1u);
        EXPECT_EQ(r.result.anyHits, 1u);
        EXPECT_EQ(r.result.t, ahsT);
        EXPECT_EQ(r.result.primitiveIndex, ahsPrim);
        EXPECT_EQ(r.result.instanceID, 0x123u);
        EXPECT_EQ(r.result.hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
        EXPECT_FLOAT_EQ(r.result.t, 5.0f + 2.0f * (ahsPrim == 0) + 1.0f * (ahsPrim == 2));
        sawFarther = sawFarther || ahsPrim != 1;
    }
    EXPECT_TRUE(sawFarther);
}

TEST(Dispatcher, CHS_3_ClosestHitMayTraceRayAndCallShader) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.callable = [](ShaderContext&, CallParams& c) { c.value += 10; };
    r.chTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        Probe q;
        ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(33.0f), q);
        CallParams c{1, 0};
        ctx.CallShader(0, c);
        p.tag = uint32_t(q.t) * 100 + uint32_t(c.value);
    };
    r.run({"HG_TriS_noAH"});
    EXPECT_EQ(r.result.tag, 3311u);
}

TEST(Dispatcher, MISS_1_MissWhenNothingIsCommitted) {
    Rig r;
    const auto tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::identity(), 0x0F)});
    r.args.mask = 0xF0;  // masked out
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.misses, 1u);
    r.args.mask = 0xFF;
    r.args.flags = RAY_FLAG_CULL_FRONT_FACING_TRIANGLES;  // culled
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.misses, 1u);
    r.args.flags = RAY_FLAG_NONE;
    r.ahTri = [](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { ctx.IgnoreHit(); };
    r.run({"HG_TriS"});  // ignored
    EXPECT_EQ(r.result.misses, 1u);
    EXPECT_EQ(r.result.anyHits, 1u);
    r.ahTri = nullptr;
    r.ray.TMax = 4.0f;  // out of range
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.misses, 1u);
    r.h.tlas({Harness::instance(0)});  // only an inactive instance
    r.ray = zRay();
    r.run({"HG_TriS"});
    EXPECT_EQ(r.result.misses, 1u);
}

TEST(Dispatcher, MISS_2_MissSeesTMaxAndNoHitValues) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.ray.Origin.x = 10.0f;
    r.ray.TMax = 77.25f;
    r.run({"HG_Tri"});
    EXPECT_EQ(r.result.t, 77.25f);
    for (const char* intrinsic : {"InstanceIndex", "PrimitiveIndex", "HitKind", "ObjectRayOrigin"}) {
        SCOPED_TRACE(intrinsic);
        const std::string name = intrinsic;
        r.miss = [name](ShaderContext& ctx, Probe&) {
            if (name == "InstanceIndex") (void)ctx.InstanceIndex();
            if (name == "PrimitiveIndex") (void)ctx.PrimitiveIndex();
            if (name == "HitKind") (void)ctx.HitKind();
            if (name == "ObjectRayOrigin") (void)ctx.ObjectRayOrigin();
        };
        const auto d = expectDxrError("SV-1", [&] { r.run({"HG_Tri"}); });
        EXPECT_TRUE(contains(d.message, name)) << d.format();
    }
}

TEST(Dispatcher, MISS_3_MissRunsDespiteSkipClosestHitAndMayTraceAndCall) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.args.flags = RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    r.ray.Origin.x = 10.0f;
    r.callable = [](ShaderContext&, CallParams& c) { c.value = 7; };
    r.miss = [&](ShaderContext& ctx, Probe& p) {
        if (ctx.RayFlags() != RAY_FLAG_SKIP_CLOSEST_HIT_SHADER) return;  // only the outer ray
        Probe q;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);
        CallParams c;
        ctx.CallShader(0, c);
        p.tag = q.closestHits * 10 + uint32_t(c.value);
    };
    r.run({"HG_TriS_noAH"});
    EXPECT_EQ(r.result.misses, 1u);
    EXPECT_EQ(r.result.tag, 17u);
}

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

TEST(Dispatcher, CALL_1_CallShaderRunsOneCallableSynchronously) {
    Rig r;
    r.h.library->addCallable<CallParams>("CL_Add100", [](ShaderContext&, CallParams& c) { c.value += 100; });
    r.log = true;
    r.callable = [](ShaderContext&, CallParams& c) { c.value += 1; };
    std::vector<int> values;
    r.rg = [&](ShaderContext& ctx) {
        CallParams c{1, 0};
        ctx.CallShader(0, c);
        values.push_back(c.value);
        ctx.CallShader(1, c);
        values.push_back(c.value);
    };
    r.run({}, uvec3(1u), {}, {}, {"CL_S", "CL_Add100"});
    EXPECT_EQ(values, (std::vector<int>{2, 102}));
    EXPECT_EQ(r.events, (std::vector<std::string>{"RG", "CL"}));
}

TEST(Dispatcher, CALL_1_ParameterTypeMismatchIsAnError) {
    Rig r;
    r.rg = [](ShaderContext& ctx) {
        OtherParams o;
        ctx.CallShader(0, o);
    };
    const auto d = expectDxrError("CALL-1", [&] { r.run({}); });
    EXPECT_TRUE(contains(valueOf(d, "passed"), "OtherParams")) << d.format();
    EXPECT_TRUE(contains(valueOf(d, "declared"), "CallParams")) << d.format();
}

TEST(Dispatcher, CALL_1_NullCallableLeavesParametersUnchanged) {
    Rig r;
    CallParams seen{};
    r.rg = [&](ShaderContext& ctx) {
        CallParams c{41, 3};
        ctx.CallShader(0, c);
        seen = c;
    };
    r.run({}, uvec3(1u), {}, {}, {""});
    EXPECT_EQ(seen.value, 41);
    EXPECT_EQ(seen.nesting, 3);
}

TEST(Dispatcher, CALL_2_CallShaderFromIntersectionOrAnyHitIsRefused) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    auto call = [](ShaderContext& ctx) {
        CallParams c;
        ctx.CallShader(0, c);
    };
    r.is = call;
    auto d = expectDxrError("CALL-2", [&] { r.run({"HG_BoxS"}); });
    EXPECT_EQ(d.site->stage, ShaderStage::Intersection);
    r.is = nullptr;
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { call(ctx); };
    d = expectDxrError("CALL-2", [&] { r.run({"HG_BoxS"}); });
    EXPECT_EQ(d.site->stage, ShaderStage::AnyHit);
    // Callables may call callables.
    r.ahBox = nullptr;
    r.callable = [](ShaderContext& ctx, CallParams& c) {
        if (c.nesting++ < 3) ctx.CallShader(0, c);
    };
    int nesting = 0;
    r.rg = [&](ShaderContext& ctx) {
        CallParams c;
        ctx.CallShader(0, c);
        nesting = c.nesting;
    };
    r.run({"HG_BoxS"});
    EXPECT_EQ(nesting, 4);
}

TEST(Dispatcher, CALL_3_CallableNestingDoesNotCountTowardRecursion) {
    Rig r;
    r.recursion(1);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.callable = [](ShaderContext& ctx, CallParams& c) {
        if (++c.nesting < 40) ctx.CallShader(0, c);
    };
    uint32_t hits = 0;
    int nesting = 0;
    r.rg = [&](ShaderContext& ctx) {
        CallParams c;
        ctx.CallShader(0, c);  // 40 deep, past the 31 limit of TraceRay recursion
        nesting = c.nesting;
        Probe p;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);  // still depth 0
        hits = p.closestHits;
    };
    r.run({"HG_TriS_noAH"});
    EXPECT_EQ(nesting, 40);
    EXPECT_EQ(hits, 1u);
    // A diagnostic deep inside callables still reports depth 0.
    r.callable = [](ShaderContext& ctx, CallParams& c) {
        if (++c.nesting < 5) ctx.CallShader(0, c);
        else (void)ctx.RayTCurrent();
    };
    const auto d = expectDxrError("SV-1", [&] { r.run({"HG_TriS_noAH"}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->depth, 0u);
    EXPECT_EQ(d.site->stage, ShaderStage::Callable);
}

TEST(Dispatcher, CALL_4_CallableSeesOnlyDispatchValues) {
    Rig r;
    uvec3 index{99u}, dims{99u};
    r.callable = [&](ShaderContext& ctx, CallParams&) {
        index = ctx.DispatchRaysIndex();
        dims = ctx.DispatchRaysDimensions();
    };
    r.rg = [&](ShaderContext& ctx) {
        if (ctx.DispatchRaysIndex() != uvec3(1, 2, 0)) return;
        CallParams c;
        ctx.CallShader(0, c);
    };
    r.run({}, uvec3(2, 3, 1));
    EXPECT_EQ(index, uvec3(1, 2, 0));
    EXPECT_EQ(dims, uvec3(2, 3, 1));
    r.callable = [](ShaderContext& ctx, CallParams&) { (void)ctx.WorldRayDirection(); };
    expectDxrError("SV-1", [&] { r.run({}, uvec3(2, 3, 1)); });
    r.callable = [](ShaderContext& ctx, CallParams&) { (void)ctx.PrimitiveIndex(); };
    expectDxrError("SV-1", [&] { r.run({}, uvec3(2, 3, 1)); });
}

// ---------------------------------------------------------------------------------------
// SV: system-value intrinsics.

enum class Intrinsic {
    DispatchRaysIndex, DispatchRaysDimensions, WorldRayOrigin, WorldRayDirection, RayTMin, RayTCurrent, RayFlags,
    InstanceIndex, InstanceID, GeometryIndex, PrimitiveIndex, ObjectRayOrigin, ObjectRayDirection, ObjectToWorld3x4,
    ObjectToWorld4x3, WorldToObject3x4, WorldToObject4x3, HitKind, ReportHit, IgnoreHit, AcceptHitAndEndSearch,
    TraceRay, CallShader, Count
};
const char* kIntrinsicNames[] = {
    "DispatchRaysIndex", "DispatchRaysDimensions", "WorldRayOrigin", "WorldRayDirection", "RayTMin", "RayTCurrent",
    "RayFlags", "InstanceIndex", "InstanceID", "GeometryIndex", "PrimitiveIndex", "ObjectRayOrigin",
    "ObjectRayDirection", "ObjectToWorld3x4", "ObjectToWorld4x3", "WorldToObject3x4", "WorldToObject4x3", "HitKind",
    "ReportHit", "IgnoreHit", "AcceptHitAndEndSearch", "TraceRay", "CallShader"};

// The SV-1 table: which stages may call each intrinsic (RG, IS, AH, CH, MS, CL).
uint8_t allowedStages(Intrinsic i) {
    auto s = [](std::initializer_list<ShaderStage> list) {
        uint8_t m = 0;
        for (ShaderStage st : list) m |= uint8_t(1u << uint8_t(st));
        return m;
    };
    using S = ShaderStage;
    switch (i) {
        case Intrinsic::DispatchRaysIndex:
        case Intrinsic::DispatchRaysDimensions:
            return s({S::RayGeneration, S::Intersection, S::AnyHit, S::ClosestHit, S::Miss, S::Callable});
        case Intrinsic::WorldRayOrigin:
        case Intrinsic::WorldRayDirection:
        case Intrinsic::RayTMin:
        case Intrinsic::RayTCurrent:
        case Intrinsic::RayFlags: return s({S::Intersection, S::AnyHit, S::ClosestHit, S::Miss});
        case Intrinsic::HitKind: return s({S::AnyHit, S::ClosestHit});
        case Intrinsic::ReportHit: return s({S::Intersection});
        case Intrinsic::IgnoreHit:
        case Intrinsic::AcceptHitAndEndSearch: return s({S::AnyHit});
        case Intrinsic::TraceRay: return s({S::RayGeneration, S::ClosestHit, S::Miss});
        case Intrinsic::CallShader: return s({S::RayGeneration, S::ClosestHit, S::Miss, S::Callable});
        default: return s({S::Intersection, S::AnyHit, S::ClosestHit});  // hit and object values
    }
}

void callIntrinsic(ShaderContext& ctx, Intrinsic i) {
    switch (i) {
        case Intrinsic::DispatchRaysIndex: (void)ctx.DispatchRaysIndex(); break;
        case Intrinsic::DispatchRaysDimensions: (void)ctx.DispatchRaysDimensions(); break;
        case Intrinsic::WorldRayOrigin: (void)ctx.WorldRayOrigin(); break;
        case Intrinsic::WorldRayDirection: (void)ctx.WorldRayDirection(); break;
        case Intrinsic::RayTMin: (void)ctx.RayTMin(); break;
        case Intrinsic::RayTCurrent: (void)ctx.RayTCurrent(); break;
        case Intrinsic::RayFlags: (void)ctx.RayFlags(); break;
        case Intrinsic::InstanceIndex: (void)ctx.InstanceIndex(); break;
        case Intrinsic::InstanceID: (void)ctx.InstanceID(); break;
        case Intrinsic::GeometryIndex: (void)ctx.GeometryIndex(); break;
        case Intrinsic::PrimitiveIndex: (void)ctx.PrimitiveIndex(); break;
        case Intrinsic::ObjectRayOrigin: (void)ctx.ObjectRayOrigin(); break;
        case Intrinsic::ObjectRayDirection: (void)ctx.ObjectRayDirection(); break;
        case Intrinsic::ObjectToWorld3x4: (void)ctx.ObjectToWorld3x4(); break;
        case Intrinsic::ObjectToWorld4x3: (void)ctx.ObjectToWorld4x3(); break;
        case Intrinsic::WorldToObject3x4: (void)ctx.WorldToObject3x4(); break;
        case Intrinsic::WorldToObject4x3: (void)ctx.WorldToObject4x3(); break;
        case Intrinsic::HitKind: (void)ctx.HitKind(); break;
        case Intrinsic::ReportHit: ctx.ReportHit(1.0f, 0, ProbeAttributes{}); break;
        case Intrinsic::IgnoreHit: ctx.IgnoreHit(); break;
        case Intrinsic::AcceptHitAndEndSearch: ctx.AcceptHitAndEndSearch(); break;
        case Intrinsic::TraceRay: {
            Probe q;
            ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);
            break;
        }
        case Intrinsic::CallShader: {
            CallParams c;
            ctx.CallShader(0, c);
            break;
        }
        case Intrinsic::Count: break;
    }
}

TEST(Dispatcher, SV_1_EveryIntrinsicOutsideItsStagesIsRefused) {
    Rig r;
    r.recursion(3);
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    Intrinsic target = Intrinsic::Count;
    ShaderStage targetStage = ShaderStage::RayGeneration;
    bool poked = false;
    auto poke = [&](ShaderContext& ctx) {
        if (poked || ctx.stage() != targetStage) return;
        poked = true;
        callIntrinsic(ctx, target);
    };
    r.rg = [&](ShaderContext& ctx) {
        poke(ctx);
        Probe p;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);  // IS, AHS, CHS
        Probe q;
        RayDesc away = zRay();
        away.Origin.x = 10.0f;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, away, q);  // miss
        CallParams c;
        ctx.CallShader(0, c);  // callable
    };
    r.is = [&](ShaderContext& ctx) {
        poke(ctx);
        ctx.ReportHit(5.0f, 0, ProbeAttributes{});
    };
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { poke(ctx); };
    r.chBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { poke(ctx); };
    r.miss = [&](ShaderContext& ctx, Probe&) { poke(ctx); };
    r.callable = [&](ShaderContext& ctx, CallParams&) { poke(ctx); };
    r.build();
    const ShaderStage stages[] = {ShaderStage::RayGeneration, ShaderStage::Intersection, ShaderStage::AnyHit,
                                  ShaderStage::ClosestHit,    ShaderStage::Miss,         ShaderStage::Callable};
    int refused = 0;
    for (int i = 0; i < int(Intrinsic::Count); ++i) {
        for (ShaderStage stage : stages) {
            target = Intrinsic(i);
            targetStage = stage;
            poked = false;
            const bool allowed = allowedStages(target) & (1u << uint8_t(stage));
            SCOPED_TRACE(std::string(kIntrinsicNames[i]) + " in " + std::string(toString(stage)));
            if (allowed) {
                EXPECT_NO_THROW(r.run({"HG_BoxS"}));
            } else {
                const char* rule = target == Intrinsic::TraceRay ? "RAY-2" : target == Intrinsic::CallShader ? "CALL-2" : "SV-1";
                const auto d = expectDxrError(rule, [&] { r.run({"HG_BoxS"}); });
                EXPECT_TRUE(contains(d.message, kIntrinsicNames[i])) << d.format();
                EXPECT_TRUE(contains(d.message, std::string(toString(stage)))) << d.format();
                ASSERT_TRUE(d.site);
                EXPECT_EQ(d.site->stage, stage);
                ++refused;
            }
            EXPECT_TRUE(poked);
        }
    }
    EXPECT_EQ(refused, 64);
}

TEST(Dispatcher, SV_2_IndexAndDimensionsWithDepthAboveOne) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    const uvec3 dims(3, 2, 4);
    std::vector<uvec3> seen(24, uvec3(~0u));
    std::vector<int> okCHS(24, 0), okDims(24, 0);
    r.chTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        const uvec3 i = ctx.DispatchRaysIndex();
        p.tag = (i.z * dims.y + i.y) * dims.x + i.x;
        p.misses = ctx.DispatchRaysDimensions() == dims ? 1000 : 0;
    };
    r.rg = [&](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        const uint32_t linear = (i.z * dims.y + i.y) * dims.x + i.x;
        seen[linear] = i;
        okDims[linear] = ctx.DispatchRaysDimensions() == dims;
        Probe p;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);
        okCHS[linear] = p.tag == linear && p.misses == 1000;
    };
    r.run({"HG_TriS_noAH"}, dims);
    for (uint32_t z = 0; z < 4; ++z)
        for (uint32_t y = 0; y < 2; ++y)
            for (uint32_t x = 0; x < 3; ++x) {
                const uint32_t linear = (z * 2 + y) * 3 + x;
                EXPECT_EQ(seen[linear], uvec3(x, y, z));
                EXPECT_TRUE(okDims[linear]);
                EXPECT_TRUE(okCHS[linear]) << linear;
            }
}

TEST(Dispatcher, SV_3_WorldRayValuesAreBitExactAndNotNormalized) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({{-5, -5, -5, 5, 5, 5}}, GEOMETRY_FLAG_NONE)}))});
    r.ray = RayDesc{vec3(0.1f, -0.3f, -9.7f), 0.0125f, vec3(0.013f, 0.027f, 3.7f), 1e6f};
    int checked = 0;
    auto check = [&](ShaderContext& ctx) {
        EXPECT_TRUE(sameBits(ctx.WorldRayOrigin(), r.ray.Origin)) << toString(ctx.stage());
        EXPECT_TRUE(sameBits(ctx.WorldRayDirection(), r.ray.Direction)) << toString(ctx.stage());
        EXPECT_TRUE(sameBits(ctx.RayTMin(), r.ray.TMin)) << toString(ctx.stage());  // SV-4
        ++checked;
    };
    r.is = [&](ShaderContext& ctx) {
        check(ctx);
        ctx.ReportHit(1.0f, 0, ProbeAttributes{});
    };
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { check(ctx); };
    r.chBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { check(ctx); };
    r.miss = [&](ShaderContext& ctx, Probe&) { check(ctx); };
    r.run({"HG_BoxS"});
    r.ray.Origin.x += 100.0f;
    r.run({"HG_BoxS"});
    EXPECT_EQ(checked, 4);
}

TEST(Dispatcher, SV_5_RayTCurrentByStage) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}))});
    r.ray.TMax = 60.0f;
    std::vector<std::pair<std::string, float>> seen;
    r.is = [&](ShaderContext& ctx) {
        seen.push_back({"IS", ctx.RayTCurrent()});
        ctx.ReportHit(9.0f, 0, ProbeAttributes{});
        seen.push_back({"IS", ctx.RayTCurrent()});
        ctx.ReportHit(7.0f, 0, ProbeAttributes{});
        seen.push_back({"IS", ctx.RayTCurrent()});
    };
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) {
        seen.push_back({"AH", ctx.RayTCurrent()});
        if (ctx.RayTCurrent() == 7.0f) ctx.IgnoreHit();
    };
    r.chBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { seen.push_back({"CH", ctx.RayTCurrent()}); };
    r.miss = [&](ShaderContext& ctx, Probe&) { seen.push_back({"MS", ctx.RayTCurrent()}); };
    r.run({"HG_BoxS"});
    r.ray.Origin.x = 10.0f;
    r.run({"HG_BoxS"});
    const std::vector<std::pair<std::string, float>> expected = {
        {"IS", 60.0f}, {"AH", 9.0f}, {"IS", 9.0f}, {"AH", 7.0f}, {"IS", 9.0f}, {"CH", 9.0f}, {"MS", 60.0f}};
    EXPECT_EQ(seen, expected);
}

TEST(Dispatcher, SV_7_IndexValuesCountInactiveElements) {
    Rig r;
    // Geometry 1's primitive 0 is inactive (NaN x); the hit is its primitive 2.
    std::vector<vec3> g1;
    for (float z : {50.0f, 40.0f, 0.0f})
        for (const vec3& p : triAt(z)) g1.push_back(p);
    g1[0].x = kNaN;
    const auto blas = r.h.blas({r.h.triangles(triAt(60)), r.h.triangles(g1)});
    r.h.tlas({Harness::instance(0), Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_NONE, 0xABCDEF)});
    r.run({"HG_TriS_noAH", "HG_TriS_noAH"});
    ASSERT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.instanceIndex, 1u);
    EXPECT_EQ(r.result.instanceID, 0xABCDEFu);
    EXPECT_EQ(r.result.geometryIndex, 1u);
    EXPECT_EQ(r.result.primitiveIndex, 2u);
    EXPECT_FLOAT_EQ(r.result.t, 5.0f);
}

TEST(Dispatcher, SV_9_TransformIntrinsicsUnderRotatedScaledTranslatedInstance) {
    Rig r;
    const Matrix3x4 m = Matrix3x4::translation({-1.25f, 4.0f, 2.5f}) *
                        Matrix3x4::rotation(glm::normalize(vec3(-2, 1, 0.5f)), 1.1f) * Matrix3x4::scale({0.5f, 3.0f, 1.5f});
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles({{-10, -10, 0}, {0, 10, 0}, {10, -10, 0}})}), 0, m)});
    const vec3 worldHit = m.transformPoint(vec3(0.3f, -0.4f, 0.0f));
    const vec3 worldDir = m.transformVector(vec3(0, 0, 1));
    r.ray = RayDesc{worldHit - 2.0f * worldDir, 0.0f, worldDir, 100.0f};
    Matrix3x4 o2w, w2o;
    std::array<std::array<float, 3>, 4> o2w43{}, w2o43{};
    vec3 objOrigin{0.0f}, objDir{0.0f};
    r.chTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        o2w = ctx.ObjectToWorld3x4();
        o2w43 = ctx.ObjectToWorld4x3();
        w2o = ctx.WorldToObject3x4();
        w2o43 = ctx.WorldToObject4x3();
        objOrigin = ctx.ObjectRayOrigin();
        objDir = ctx.ObjectRayDirection();
    };
    r.run({"HG_TriS_noAH"});
    ASSERT_EQ(r.result.closestHits, 1u);
    // ObjectToWorld3x4 is the instance transform bit for bit; 4x3 is its transpose.
    EXPECT_EQ(std::memcmp(&o2w, &m, sizeof m), 0);
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 4; ++col) {
            EXPECT_TRUE(sameBits(o2w43[col][row], m.m[row][col]));
            EXPECT_TRUE(sameBits(w2o43[col][row], w2o.m[row][col]));
        }
    // WorldToObject3x4 is the affine inverse computed in double and rounded once.
    long double a[3][3], inv[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a[i][j] = m.m[i][j];
    const long double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                            a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                            a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            inv[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / det;
        }
    for (int i = 0; i < 3; ++i) {
        long double t = 0;
        for (int k = 0; k < 3; ++k) {
            const float expected = float(inv[i][k]);
            EXPECT_NEAR(w2o.m[i][k], expected, std::fabs(expected) * 2e-7f + 1e-12f) << i << "," << k;
            t -= inv[i][k] * m.m[k][3];
        }
        EXPECT_NEAR(w2o.m[i][3], float(t), std::fabs(float(t)) * 2e-7f + 1e-6f) << i;
    }
    const auto reference = affineInverse(m);
    ASSERT_TRUE(reference);
    EXPECT_EQ(std::memcmp(&w2o, &*reference, sizeof w2o), 0);
    // SV-8: the object ray is the world ray under WorldToObject, not normalized.
    const vec3 mappedOrigin = w2o.transformPoint(r.ray.Origin), mappedDir = w2o.transformVector(r.ray.Direction);
    EXPECT_TRUE(sameBits(objOrigin, mappedOrigin));
    EXPECT_TRUE(sameBits(objDir, mappedDir));
    EXPECT_NEAR(objDir.z, 1.0f, 1e-5f);
}

TEST(Dispatcher, SV_10_HitKindForTrianglesAndProcedurals) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)})),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}), 1, Matrix3x4::translation({5, 0, 0}))});
    std::vector<uint32_t> ahKinds;
    r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { ahKinds.push_back(ctx.HitKind()); };
    r.ahBox = [&](ShaderContext& ctx, Probe&, const ProbeAttributes&) { ahKinds.push_back(ctx.HitKind()); };
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
    r.ray = RayDesc{vec3(0.0f, 0.2f, 5.0f), 0.0f, vec3(0, 0, -1), 100.0f};
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
    r.ray = zRay();
    r.ray.Origin.x = 5.0f;
    r.isKind = 77;
    r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_EQ(r.result.hitKind, 77u);
    EXPECT_EQ(ahKinds, (std::vector<uint32_t>{0xFE, 0xFF, 77}));
}

TEST(Dispatcher, SV_11_HitValuesDescribeTheCandidateNotTheLastEnumerated) {
    Rig r;
    // prim 0 at t = 7 (x offset 0), prim 1 at t = 5, prim 2 at t = 6; AHS accepts all.
    std::vector<vec3> v;
    for (float z : {2.0f, 0.0f, 1.0f})
        for (const vec3& p : triAt(z)) v.push_back(p);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NONE)}))});
    bool consistent = true;
    r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes& a) {
        const float expectedT = ctx.PrimitiveIndex() == 0 ? 7.0f : ctx.PrimitiveIndex() == 1 ? 5.0f : 6.0f;
        consistent = consistent && ctx.RayTCurrent() == expectedT && std::fabs(a.barycentrics.x - 0.6f) < 1e-6f;
    };
    for (uint64_t seed = 0; seed < 12; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        r.run({"HG_TriS"}, uvec3(1u), o);
        EXPECT_EQ(r.result.primitiveIndex, 1u);
        EXPECT_EQ(r.result.t, 5.0f);
    }
    EXPECT_TRUE(consistent);
    // IS: the AABB being intersected.
    Rig p;
    p.h.tlas({Harness::instance(p.h.blas({p.h.aabbs({unitBox(), {-1, -1, 3, 1, 1, 5}, {-1, -1, 7, 1, 1, 9}})}))});
    bool isConsistent = true;
    p.is = [&](ShaderContext& ctx) {
        const float centre = float(ctx.PrimitiveIndex()) * 4.0f;
        auto slab = intersectAABB(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(),
                                  {-1, -1, centre - 1, 1, 1, centre + 1}, ctx.RayTMin(), kInf);
        isConsistent = isConsistent && slab && slab->tEnter == centre + 4.0f;
    };
    for (uint64_t seed = 0; seed < 4; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        p.run({"HG_BoxS"}, uvec3(1u), o);
    }
    EXPECT_TRUE(isConsistent);
}

TEST(Dispatcher, SV_12_BarycentricsWeightV1AndV2InAppOrder) {
    Rig r;
    const vec3 v0(-2, -1, 0), v1(3, -1, 0), v2(0, 4, 0);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles({v0, v1, v2})}))});
    const vec3 p = v0 + 0.25f * (v1 - v0) + 0.125f * (v2 - v0);
    r.ray = RayDesc{vec3(p.x, p.y, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f};
    r.run({"HG_TriS_noAH"});
    ASSERT_EQ(r.result.closestHits, 1u);
    EXPECT_NEAR(r.result.barycentrics.x, 0.25f, 2e-6f);
    EXPECT_NEAR(r.result.barycentrics.y, 0.125f, 2e-6f);
    // Rotating the vertex order rotates the weights.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles({v1, v2, v0})}))});
    r.run({"HG_TriS_noAH"});
    EXPECT_NEAR(r.result.barycentrics.x, 0.125f, 2e-6f);  // weight of v2 (now v1)
    EXPECT_NEAR(r.result.barycentrics.y, 1.0f - 0.25f - 0.125f, 2e-6f);  // weight of v0 (now v2)
}

// ---------------------------------------------------------------------------------------
// LIM-2: recursion limit.

TEST(Dispatcher, LIM_2_TraceRayAtTheLimitIsAnErrorNamingDepthAndLimit) {
    Rig r;
    r.recursion(1);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.run({"HG_TriS_noAH"});  // limit 1: ray generation may trace
    EXPECT_EQ(r.result.closestHits, 1u);
    r.chTri = [](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        Probe q;
        ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);
    };
    const auto d = expectDxrError("LIM-2", [&] { r.run({"HG_TriS_noAH"}); });
    EXPECT_EQ(valueOf(d, "depth"), "1");
    EXPECT_TRUE(contains(limitOf(d, "depth"), "1")) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::ClosestHit);
    EXPECT_EQ(d.site->exportName, "CH_TriS");
    EXPECT_TRUE(contains(valueOf(d, "call chain"), "CH_TriS")) << d.format();
}

TEST(Dispatcher, LIM_2_DiagnosticNamesTheWholeCallChain) {
    Rig r;
    r.recursion(2);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.chTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        Probe q;
        q.tag = p.tag + 1;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);  // the CHS at depth 2 breaks the limit
    };
    const auto d = expectDxrError("LIM-2", [&] { r.run({"HG_TriS_noAH"}); });
    EXPECT_EQ(valueOf(d, "depth"), "2");
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->depth, 2u);
    const std::string chain = valueOf(d, "call chain");
    EXPECT_TRUE(contains(chain, "RG")) << "the call chain should start at the ray generation shader: " << d.format();
    EXPECT_TRUE(contains(chain, "CH_TriS")) << d.format();
}

TEST(Dispatcher, LIM_2_LimitZeroForbidsTraceRayFromRayGeneration) {
    Rig r;
    r.recursion(0);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    const auto d = expectDxrError("LIM-2", [&] { r.run({"HG_TriS_noAH"}); });
    EXPECT_EQ(valueOf(d, "depth"), "0");
    EXPECT_TRUE(contains(limitOf(d, "depth"), "0")) << d.format();
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
}

TEST(Dispatcher, LIM_2_DeepestLegalRecursionSucceeds) {
    Rig r;
    r.recursion(3);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    r.chTri = [&](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
        Probe q;
        q.tag = p.tag + 1;
        if (q.tag < 3) ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), q);  // CHS at depth 1, 2
        p.tag = q.tag;
    };
    const auto result = r.run({"HG_TriS_noAH"});
    EXPECT_EQ(r.result.tag, 3u);
    ASSERT_GE(result.stats.raysPerDepth.size(), 4u);
    EXPECT_EQ(result.stats.raysPerDepth[3], 1u);
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
