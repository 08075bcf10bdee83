// Conformance tests for the ray flags (dxr-semantics.md section 5): their validation in emulator/trace_ray.cpp and
// their effect on candidates in candidate_gathering.cpp and candidate_processing.cpp. Each test name carries the
// rule id it checks. The rig is dispatch_rig.h.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dispatch_rig.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

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

}  // namespace
}  // namespace refray::test
