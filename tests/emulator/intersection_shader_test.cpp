// Conformance tests for intersection shaders and ReportHit (emulator/candidate_processing.cpp, dxr-semantics.md
// section 7). Each test name carries the rule id it checks. The rig is dispatch_rig.h.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "dispatch_rig.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

struct OtherAttributes {
    int a = 0;
    int b = 0;
};

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

}  // namespace
}  // namespace refray::test
