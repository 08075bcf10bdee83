// Conformance tests for TraceRay (emulator/trace_ray.cpp): RayDesc and its arguments, the TRV-4 loop around the
// candidates, the closest-hit or miss shader and the recursion limit (dxr-semantics.md sections 4, 6, 9 and LIM-2).
// Each test name carries the rule id it checks. The rig is dispatch_rig.h.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "dispatch_rig.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

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
// TRV: the TraceRay side of traversal (records, one closest hit or miss, object rays, nesting).

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
// CHS, MISS.

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

}  // namespace
}  // namespace refray::test
