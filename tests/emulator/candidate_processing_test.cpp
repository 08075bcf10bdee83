// Conformance tests for the processing of one candidate (emulator/candidate_processing.cpp): opacity, the TRV-2
// interval and the TRV-4 rules of a candidate, and the any-hit shader (dxr-semantics.md sections 6, 7 and 8). The
// intersection shader and ReportHit are in intersection_shader_test.cpp. Each test name carries the rule id it
// checks. The rig is dispatch_rig.h.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "dispatch_rig.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

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

}  // namespace
}  // namespace refray::test
