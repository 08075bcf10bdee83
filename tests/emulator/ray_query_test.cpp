// Conformance tests for RayQuery, DXR 1.1 inline ray tracing (emulator/ray_query.h; dxr-semantics.md section 18,
// RQ-1..RQ-33), and for the compute dispatch that runs queries outside the ray-tracing pipeline (Device::dispatch).
// Each test name carries the rule id it checks. The rig is dispatch_rig.h: the queries run in its shaders, mostly the
// ray generation shader, over small scenes built on the device; no hit-group table is bound unless a test says so.
//
// Scenes: triAt(z) is hit by zRay() (from (0, 0.2, -5) along +z) at t = z + 5 with barycentrics (0.6, 0.2); the unit
// box [-1,1]^3 is entered at t = 4 and left at t = 6.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "dispatch_rig.h"
#include "emulator/compute_wave.h"
#include "emulator/ray_query.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

// Triangles triAt(z) for each z, in one vertex list: primitive i is hit by zRay() at t = zs[i] + 5.
std::vector<vec3> trisAt(const std::vector<float>& zs) {
    std::vector<vec3> v;
    for (float z : zs)
        for (const vec3& p : triAt(z)) v.push_back(p);
    return v;
}

// triAt(z) wound the other way: back-facing for rays along +z.
std::vector<vec3> backTriAt(float z) {
    auto v = triAt(z);
    std::swap(v[1], v[2]);
    return v;
}

// One instance of one geometry; the rig's scene.
GpuVirtualAddress oneInstance(Rig& r, const GeometryDesc& g, uint32_t instanceFlags = INSTANCE_FLAG_NONE,
                              uint32_t instanceID = 0) {
    return r.h.tlas({Harness::instance(r.h.blas({g}), 0, Matrix3x4::identity(), 0xFF, instanceFlags, instanceID)});
}

// The template ray flags of the RayQuery objects `shader` makes (RQ-2: an undeclared one stops the shader).
void declare(Rig& r, const std::string& shader, std::vector<uint32_t> templateFlags) {
    r.h.library->declareRayQueries(shader, std::move(templateFlags));
}

// One DispatchRays of the rig's ray generation shader with no miss, hit-group or callable table: a query needs none.
DispatchResult runQuery(Rig& r, DispatchOptions options = {}, uvec3 dims = uvec3(1u)) {
    return r.run({}, dims, options, {}, {});
}

bool hasRule(const std::vector<Diagnostic>& ds, const std::string& rule) {
    return std::any_of(ds.begin(), ds.end(), [&](const Diagnostic& d) { return d.ruleId == rule; });
}

uint64_t countOf(const std::vector<Diagnostic>& ds, const std::string& rule) {
    uint64_t n = 0;
    for (const Diagnostic& d : ds)
        if (d.ruleId == rule) n += d.count;
    return n;
}

bool startsWith(const char* s, const char* prefix) { return s && std::string(s).rfind(prefix, 0) == 0; }

// The events a dispatch reports, copied (what `refray explain` records).
struct EventLog : TraceObserver {
    struct Entry {
        TraceEvent::Kind kind = TraceEvent::Kind::ShaderCall;
        uint32_t queryId = 0;
        uvec3 launch{0u};
        ShaderStage stage = ShaderStage::RayGeneration;
        std::string exportName, note, table;
        uint32_t instanceIndex = 0, instanceID = 0, geometryIndex = 0, primitiveIndex = 0;
        bool procedural = false, accepted = false, committed = false;
        float t = 0.0f;
        uint32_t rayFlags = 0, effectiveFlags = 0, mask = 0;
    };
    std::mutex lock;
    std::vector<Entry> entries;

    void onEvent(const TraceEvent& e) override {
        Entry x;
        x.kind = e.kind;
        x.queryId = e.queryId;
        x.launch = e.launchIndex;
        x.stage = e.stage;
        x.exportName = std::string(e.exportName);
        x.note = std::string(e.note);
        x.table = std::string(e.table);
        x.instanceIndex = e.instanceIndex;
        x.instanceID = e.instanceID;
        x.geometryIndex = e.geometryIndex;
        x.primitiveIndex = e.primitiveIndex;
        x.procedural = e.procedural;
        x.accepted = e.accepted;
        x.committed = e.committed;
        x.t = e.t;
        x.rayFlags = e.rayFlags;
        x.effectiveFlags = e.effectiveFlags;
        x.mask = e.instanceInclusionMask;
        std::lock_guard<std::mutex> guard(lock);
        entries.push_back(std::move(x));
    }
    std::vector<Entry> of(TraceEvent::Kind kind) {
        std::vector<Entry> out;
        for (const Entry& e : entries)
            if (e.kind == kind) out.push_back(e);
        return out;
    }
};

DispatchOptions observed(EventLog& log, DispatchOptions o = {}) {
    o.observer = &log;
    return o;
}

// ---------------------------------------------------------------------------------------
// 18a. Object, availability, flags.

TEST(RayQuery, RQ_1_AQueryRunsFromEveryRayTracingStageAndFromCompute) {
    Rig r;
    // What the queries trace: one opaque triangle at z = 20 (t = 25) with InstanceID 42.
    const GpuVirtualAddress target = r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(20))}), 0,
                                                                 Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_NONE, 42)});
    // What TraceRay traces: a non-opaque triangle at t = 5 (HG_TriS: any hit, closest hit) and a box entered at t = 2
    // (HG_BoxS: the intersection shader runs and reports nothing).
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)}), 0),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}), 1, Matrix3x4::translation({0, 0, -2}))});
    struct Seen {
        uint32_t status = 99;
        float t = -1.0f;
        uint32_t instanceID = 0;
    };
    std::map<ShaderStage, Seen> seen;
    auto query = [&seen, target](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(target, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
        }
        seen[ctx.stage()] = {q.CommittedStatus(), q.CommittedRayT(), q.CommittedInstanceID()};
    };
    r.rg = [&](ShaderContext& ctx) {
        query(ctx);
        Probe p;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);  // IS, AHS, CHS
        r.result = p;
        Probe m;
        ctx.TraceRay(r.h.scene, RAY_FLAG_NONE, 0x00, 0, 1, 0, zRay(), m);  // miss
        CallParams c;
        ctx.CallShader(0, c);
    };
    r.is = query;
    r.ahTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { query(ctx); };
    r.chTri = [&](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) { query(ctx); };
    r.miss = [&](ShaderContext& ctx, Probe&) { query(ctx); };
    r.callable = [&](ShaderContext& ctx, CallParams&) { query(ctx); };
    r.h.library->addCompute("CS", uvec3(1u), query);
    for (const char* shader : {"RG", "IS_S", "AH_TriS", "CH_TriS", "Miss_S", "CL_S", "CS"}) declare(r, shader, {RAY_FLAG_NONE});

    const DispatchResult rays = r.run({"HG_TriS", "HG_BoxS"});
    EXPECT_TRUE(rays.diagnostics.errors().empty());
    EXPECT_EQ(r.result.closestHits, 1u);
    r.h.device.dispatch(DispatchDesc{"CS", 1, 1, 1}, r.so, nullptr);

    const std::vector<ShaderStage> stages = {ShaderStage::RayGeneration, ShaderStage::Intersection, ShaderStage::AnyHit,
                                             ShaderStage::ClosestHit,    ShaderStage::Miss,         ShaderStage::Callable,
                                             ShaderStage::Compute};
    EXPECT_EQ(seen.size(), stages.size());
    for (ShaderStage s : stages) {
        ASSERT_TRUE(seen.count(s)) << "no query ran in a " << toString(s) << " shader";
        EXPECT_EQ(seen[s].status, COMMITTED_TRIANGLE_HIT) << toString(s);
        EXPECT_EQ(seen[s].t, 25.0f) << toString(s);
        EXPECT_EQ(seen[s].instanceID, 42u) << toString(s);
    }
}

// A ray that accepts the first hit and skips the closest hit, in a pipeline without any-hit shaders, has its
// candidates processed while Embree traverses (GatherMode::FirstHit): the intersection shader runs inside Embree's
// callback, and its query traverses again from there.
TEST(RayQuery, RQ_1_AQueryInAnIntersectionShaderRunsDuringAFirstHitTraversal) {
    Rig r;
    r.h.stateObject.hitGroups.erase(std::remove_if(r.h.stateObject.hitGroups.begin(), r.h.stateObject.hitGroups.end(),
                                                   [](const HitGroupDesc& g) { return !g.AnyHitShaderImport.empty(); }),
                                    r.h.stateObject.hitGroups.end());
    const GpuVirtualAddress target =
        r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(trisAt({20, 10}), GEOMETRY_FLAG_NONE)}), 0,
                                    Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_NONE, 42)});
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});  // entered at t = 4
    declare(r, "IS_S", {RAY_FLAG_NONE});
    std::vector<float> seen;
    r.is = [&, target](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(target, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
            seen.push_back(q.CandidateTriangleRayT());
            if (q.CandidatePrimitiveIndex() == 0) q.CommitNonOpaqueTriangleHit();
        }
        if (q.CommittedStatus() == COMMITTED_TRIANGLE_HIT) ctx.ReportHit(q.CommittedRayT() - 20.0f, 3, ProbeAttributes{});
    };
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    r.build();
    const DispatchResult res = r.run({"HG_BoxS_noAH"});
    EXPECT_TRUE(res.diagnostics.errors().empty());
    EXPECT_EQ(res.stats.raysPerGatherMode[2], 1u) << "the outer ray took the FirstHit path (GatherMode 2)";
    EXPECT_EQ(seen, (std::vector<float>{15.0f, 25.0f}));
    EXPECT_EQ(r.isCalls.load(), 1);
    EXPECT_EQ(r.result.misses, 0u) << "the hit the intersection shader reported ended the search";
}

TEST(RayQuery, RQ_2_TheSecondTemplateArgumentIsOptionalAndBothAreConstants) {
    static_assert(std::is_same_v<RayQuery<RAY_FLAG_FORCE_OPAQUE>, RayQuery<RAY_FLAG_FORCE_OPAQUE, RAYQUERY_FLAG_NONE>>);
    static_assert(std::is_base_of_v<RayQueryObject, RayQuery<RAY_FLAG_NONE, RAYQUERY_FLAG_ALLOW_CLUSTERED_GEOMETRY>>);
    static_assert(rayQueryTemplateError(RAY_FLAG_FORCE_OPAQUE, RAYQUERY_FLAG_NONE) == nullptr);
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_NONE});
    uint32_t status[2] = {9, 9};
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_FORCE_OPAQUE> opaque(ctx);
        opaque.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        EXPECT_FALSE(opaque.Proceed());  // the template flag makes the triangle opaque
        status[0] = opaque.CommittedStatus();
        RayQuery<RAY_FLAG_NONE, RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS | RAYQUERY_FLAG_ALLOW_CLUSTERED_GEOMETRY> plain(ctx);
        plain.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        EXPECT_TRUE(plain.Proceed());
        EXPECT_EQ(plain.CandidateType(), CANDIDATE_NON_OPAQUE_TRIANGLE);
        status[1] = plain.CommittedStatus();
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    EXPECT_EQ(status[0], COMMITTED_TRIANGLE_HIT);
    EXPECT_EQ(status[1], COMMITTED_NOTHING);
}

TEST(RayQuery, RQ_2_ARayQueryItsShaderDoesNotDeclareStopsTheShader) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0)));
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [](ShaderContext& ctx) { RayQuery<RAY_FLAG_CULL_OPAQUE> q(ctx); };
    Diagnostic d = expectDxrError("RQ-2", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "declareRayQueries")) << d.format();
    EXPECT_TRUE(contains(d.message, "CULL_OPAQUE")) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
    EXPECT_EQ(d.site->exportName, "RG");
    // A misdeclared shader is a compile error in HLSL: OnError::Continue stops it too.
    d = expectDxrError("RQ-2", [&] { runQuery(r, continueMode()); });
    // A shader that declares nothing makes no RayQuery.
    r.h.library->addCompute("CS", uvec3(1u), [](ShaderContext& ctx) { RayQuery<RAY_FLAG_NONE> q(ctx); });
    r.so = nullptr;
    d = expectDxrError("RQ-2", [&] { r.h.device.dispatch(DispatchDesc{"CS"}, r.h.pipeline(), nullptr); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::Compute);
}

TEST(RayQuery, RQ_3_TemplateAndDynamicFlagsAreORed) {
    Rig r;
    // Primitive 0: front-facing, non-opaque, t = 5. Primitive 1: back-facing, non-opaque, t = 3.
    std::vector<vec3> v = triAt(0);
    for (const vec3& p : backTriAt(-2)) v.push_back(p);
    oneInstance(r, r.h.triangles(v, GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_CULL_BACK_FACING_TRIANGLES});
    uint32_t dynamicFlags = RAY_FLAG_NONE;
    bool firstProceed = false;
    uint32_t primitive = 9, flags = 0, status = 9;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_CULL_BACK_FACING_TRIANGLES> q(ctx);
        q.TraceRayInline(scene, dynamicFlags, 0xFF, zRay());
        firstProceed = q.Proceed();
        primitive = firstProceed ? q.CandidatePrimitiveIndex() : q.CommittedPrimitiveIndex();
        while (q.Proceed()) {
        }
        flags = q.RayFlags();
        status = q.CommittedStatus();
    };
    // The template flag culls the back face: the first candidate is primitive 0.
    runQuery(r);
    EXPECT_TRUE(firstProceed);
    EXPECT_EQ(primitive, 0u);
    EXPECT_EQ(status, COMMITTED_NOTHING);
    EXPECT_EQ(flags, uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES));
    // The dynamic FORCE_OPAQUE joins it: primitive 0 is committed inside the first Proceed, primitive 1 still culled.
    dynamicFlags = RAY_FLAG_FORCE_OPAQUE;
    runQuery(r);
    EXPECT_FALSE(firstProceed);
    EXPECT_EQ(primitive, 0u);
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
    EXPECT_EQ(flags, uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE));

    // An undefined dynamic bit is undefined behaviour: diagnosed, and dropped under OnError::Continue.
    dynamicFlags = RAY_FLAG_FORCE_OPAQUE | 0x8000u;
    const Diagnostic d = expectDxrError("RQ-3", [&] { runQuery(r); });
    EXPECT_TRUE(contains(valueOf(d, "undefined bits"), "8000")) << d.format();
    const DispatchResult cont = runQuery(r, continueMode());
    EXPECT_TRUE(hasRule(cont.diagnostics.errors(), "RQ-3"));
    EXPECT_EQ(flags, uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE));
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
    // Undefined template bits do not compile.
    EXPECT_TRUE(startsWith(rayQueryTemplateError(0x8000u, RAYQUERY_FLAG_NONE), "RQ-3"));
}

TEST(RayQuery, RQ_4_SkipClosestHitShaderIsRefusedAsTemplateOrDynamicFlag) {
    EXPECT_TRUE(startsWith(rayQueryTemplateError(RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, RAYQUERY_FLAG_NONE), "RQ-4"));
    EXPECT_TRUE(startsWith(
        rayQueryTemplateError(RAY_FLAG_SKIP_CLOSEST_HIT_SHADER | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, RAYQUERY_FLAG_NONE),
        "RQ-4"));
    EXPECT_EQ(rayQueryTemplateError(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, RAYQUERY_FLAG_NONE), nullptr);

    Rig r;
    oneInstance(r, r.h.triangles(triAt(0)));
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t flags = 99, status = 99;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_SKIP_CLOSEST_HIT_SHADER | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0xFF, zRay());
        q.Proceed();
        flags = q.RayFlags();
        status = q.CommittedStatus();
    };
    const Diagnostic d = expectDxrError("RQ-4", [&] { runQuery(r); });
    EXPECT_TRUE(contains(valueOf(d, "RayFlags"), "SKIP_CLOSEST_HIT_SHADER")) << d.format();
    EXPECT_TRUE(contains(valueOf(d, "state"), "initialised")) << d.format();
    const DispatchResult cont = runQuery(r, continueMode());
    EXPECT_TRUE(hasRule(cont.diagnostics.errors(), "RQ-4"));
    EXPECT_EQ(flags, uint32_t(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH)) << "the flag is dropped, the rest kept";
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
}

TEST(RayQuery, RQ_5_ExclusionsHoldOnTheORedFlags) {
    struct Case {
        uint32_t templ, dynamic;
    };
    const std::vector<Case> invalid = {
        {RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_FORCE_NON_OPAQUE},
        {RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_CULL_OPAQUE},
        {RAY_FLAG_CULL_OPAQUE, RAY_FLAG_CULL_NON_OPAQUE},
        {RAY_FLAG_FORCE_NON_OPAQUE, RAY_FLAG_CULL_NON_OPAQUE},
        {RAY_FLAG_CULL_BACK_FACING_TRIANGLES, RAY_FLAG_CULL_FRONT_FACING_TRIANGLES},
        {RAY_FLAG_SKIP_TRIANGLES, RAY_FLAG_CULL_BACK_FACING_TRIANGLES},
        {RAY_FLAG_SKIP_TRIANGLES, RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES},
        {RAY_FLAG_NONE, RAY_FLAG_SKIP_TRIANGLES | RAY_FLAG_CULL_FRONT_FACING_TRIANGLES},
    };
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0)));
    std::vector<uint32_t> declared;
    for (const Case& c : invalid) declared.push_back(c.templ);
    declared.push_back(RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES);
    declare(r, "RG", declared);
    Case current{};
    bool proceeded = true;
    uint32_t status = 99;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQueryObject q(ctx, current.templ, RAYQUERY_FLAG_NONE);
        q.TraceRayInline(scene, current.dynamic, 0xFF, zRay());
        proceeded = q.Proceed();
        status = q.CommittedStatus();
    };
    for (const Case& c : invalid) {
        current = c;
        const Diagnostic d = expectDxrError("RQ-5", [&] { runQuery(r); });
        EXPECT_EQ(valueOf(d, "template flags"), rayFlagsToString(c.templ)) << d.format();
        EXPECT_EQ(valueOf(d, "TraceRayInline flags"), rayFlagsToString(c.dynamic)) << d.format();
        // OnError::Continue: the query finds nothing, though an opaque triangle lies on the ray.
        const DispatchResult cont = runQuery(r, continueMode());
        EXPECT_TRUE(hasRule(cont.diagnostics.errors(), "RQ-5")) << rayFlagsToString(c.templ | c.dynamic);
        EXPECT_FALSE(proceeded);
        EXPECT_EQ(status, COMMITTED_NOTHING) << rayFlagsToString(c.templ | c.dynamic);
    }
    // A valid combination: no diagnostic, and the triangle is found.
    current = {RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES, RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE};
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
}

TEST(RayQuery, RQ_6_RayQueryFlagValues) {
    static_assert(RAYQUERY_FLAG_NONE == 0x0 && RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS == 0x1 &&
                  RAYQUERY_FLAG_ALLOW_CLUSTERED_GEOMETRY == 0x2);
    EXPECT_EQ(rayQueryTemplateError(RAY_FLAG_NONE, 0x3), nullptr);
    EXPECT_TRUE(startsWith(rayQueryTemplateError(RAY_FLAG_NONE, 0x4), "RQ-6"));
    EXPECT_TRUE(startsWith(rayQueryTemplateError(RAY_FLAG_NONE, 0x80000001u), "RQ-6"));
}

TEST(RayQuery, RQ_7_CopiesShareOneStateMachine) {
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({-2, 0, 2}), GEOMETRY_FLAG_NONE));  // t = 3, 5, 7
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> a(ctx);
        a.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        RayQueryObject b = a;  // HLSL assignment: a reference to the same query
        EXPECT_TRUE(b.sameQueryAs(a));
        ASSERT_TRUE(b.Proceed());
        EXPECT_EQ(a.CandidateTriangleRayT(), 3.0f) << "Proceed through the copy advanced the original";
        auto commit = [](RayQueryObject byReference) { byReference.CommitNonOpaqueTriangleHit(); };
        commit(a);  // a parameter is passed by reference
        EXPECT_EQ(b.CommittedStatus(), COMMITTED_TRIANGLE_HIT);
        EXPECT_EQ(a.CommittedRayT(), 3.0f);

        // Any number of queries may be live at once, each with its own state.
        RayQuery<RAY_FLAG_NONE> c(ctx);
        EXPECT_FALSE(c.sameQueryAs(a));
        c.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(c.Proceed());
        ASSERT_TRUE(c.Proceed());
        EXPECT_EQ(c.CandidateTriangleRayT(), 5.0f);
        EXPECT_EQ(c.CommittedStatus(), COMMITTED_NOTHING);
        EXPECT_EQ(a.CommittedRayT(), 3.0f);
        b = c;
        EXPECT_TRUE(b.sameQueryAs(c));
        EXPECT_FALSE(b.sameQueryAs(a));
        b.CommitNonOpaqueTriangleHit();
        EXPECT_EQ(c.CommittedRayT(), 5.0f);
        EXPECT_EQ(a.CommittedRayT(), 3.0f);
        EXPECT_FALSE(a.Proceed()) << "7 lies beyond a's CommittedRayT 3";
        EXPECT_FALSE(c.Proceed()) << "7 lies beyond c's CommittedRayT 5";
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
}

TEST(RayQuery, RQ_7_AQueryMadeAfterAnotherIsGoneStartsFresh) {
    // Once no handle refers to a query's state, it is kept for the next query its worker thread makes: that query
    // starts with nothing of the old one (no candidates, commit or Proceed; RayQueryObject, "Counted by the handles").
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({-2, 0, 2}), GEOMETRY_FLAG_NONE));  // t = 3, 5, 7
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayDesc away = zRay();
        away.Direction = -away.Direction;  // meets nothing
        for (int round = 0; round < 3; ++round) {
            {
                RayQuery<RAY_FLAG_NONE> a(ctx);
                a.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
                ASSERT_TRUE(a.Proceed());
                ASSERT_TRUE(a.Proceed());  // the triangle at t = 5 waits for the shader
                a.CommitNonOpaqueTriangleHit();
                const RayQueryObject copy = a;
                EXPECT_TRUE(copy.sameQueryAs(a));
            }
            RayQuery<RAY_FLAG_NONE> b(ctx);
            b.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, away);
            EXPECT_FALSE(b.Proceed()) << "round " << round << ": the new query met the old one's candidates";
            EXPECT_EQ(b.CommittedStatus(), COMMITTED_NOTHING) << "round " << round;
        }
        RayQuery<RAY_FLAG_NONE> fresh(ctx);
        fresh.Proceed();  // before its TraceRayInline, whatever the state it may reuse went through: RQ-19
    };
    const Diagnostic d = expectDxrError("RQ-19", [&] { runQuery(r); });
    EXPECT_TRUE(contains(valueOf(d, "state"), "no TraceRayInline")) << d.format();
}

TEST(RayQuery, RQ_7_AQueryKeepsItsStateAcrossATraceRayWhoseShadersRunQueriesOfTheirOwn) {
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({-2, 0, 2}), GEOMETRY_FLAG_NONE));  // t = 3, 5, 7
    declare(r, "RG", {RAY_FLAG_NONE});
    declare(r, "CH_TriS", {RAY_FLAG_FORCE_OPAQUE});
    float inner = -1.0f;
    r.chTri = [&, scene = r.h.scene](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        RayQuery<RAY_FLAG_FORCE_OPAQUE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, RayDesc{vec3(0.0f, 0.2f, -5.0f), 4.0f, vec3(0, 0, 1), 100.0f});
        EXPECT_FALSE(q.Proceed());
        inner = q.CommittedRayT();
    };
    std::vector<float> outer;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(q.Proceed());
        outer.push_back(q.CandidateTriangleRayT());
        Probe p;
        ctx.TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);  // AHS and CHS run; the CHS makes query 2
        r.result = p;
        EXPECT_EQ(q.CandidateTriangleRayT(), 3.0f);
        q.CommitNonOpaqueTriangleHit();
        while (q.Proceed()) outer.push_back(q.CandidateTriangleRayT());
        outer.push_back(q.CommittedRayT());
    };
    EventLog log;
    const DispatchResult res = r.run({"HG_TriS"}, uvec3(1u), observed(log));
    EXPECT_TRUE(res.diagnostics.errors().empty());
    EXPECT_EQ(r.result.closestHits, 1u);
    EXPECT_EQ(r.result.anyHits, 1u);
    EXPECT_EQ(inner, 5.0f);
    EXPECT_EQ(outer, (std::vector<float>{3.0f, 3.0f}));
    std::vector<std::pair<uint32_t, ShaderStage>> inits;
    for (const auto& e : log.of(TraceEvent::Kind::QueryInit)) inits.push_back({e.queryId, e.stage});
    EXPECT_EQ(inits, (std::vector<std::pair<uint32_t, ShaderStage>>{{1, ShaderStage::RayGeneration}, {2, ShaderStage::ClosestHit}}));
}

// RQ-8 says a RayQuery is no wave-repacking point. What refray can observe of that is that a query runs inside the
// shader that owns it, to the end: it invokes no other shader and reads no shader record, whatever the scene holds.
TEST(RayQuery, RQ_8_AQueryInvokesNoOtherShaderAndReadsNoRecord) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(trisAt({-2, 2}), GEOMETRY_FLAG_NONE)}), 0),
              Harness::instance(r.h.blas({r.h.triangles(triAt(0))}), 0),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)}), 1,
                                Matrix3x4::translation({0, 0, -3}))});
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t candidates = 0;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
            ++candidates;
            if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE) q.CommitProceduralPrimitiveHit(6.0f);
            else q.CommitNonOpaqueTriangleHit();
        }
    };
    EventLog log;
    // Full tables are bound, so any shader the query wrongly invoked could run.
    const DispatchResult res = r.run({"HG_TriS", "HG_BoxS"}, uvec3(1u), observed(log));
    EXPECT_EQ(candidates, 2u);  // the box (entered at t = 1, committed at 6), then the triangle at t = 3
    std::vector<std::string> calls, records;
    for (const auto& e : log.of(TraceEvent::Kind::ShaderCall)) calls.push_back(e.exportName);
    for (const auto& e : log.of(TraceEvent::Kind::RecordLookup)) records.push_back(e.table);
    EXPECT_EQ(calls, std::vector<std::string>{"RG"});
    ASSERT_EQ(records.size(), 1u);
    EXPECT_TRUE(contains(records[0], "ray generation")) << records[0];
    ASSERT_EQ(res.stats.invocationsPerExport.size(), 1u);
    EXPECT_EQ(res.stats.invocationsPerExport[0].exportName, "RG");
    EXPECT_EQ(res.stats.invocationsPerExport[0].count, 1u);
    EXPECT_EQ(r.isCalls.load(), 0);
}

// ---------------------------------------------------------------------------------------
// 18b. State machine.

TEST(RayQuery, RQ_9_TraceRayInlineOnlyInitialisesAndDiscardsTheCurrentQuery) {
    Rig r;
    // Primitive 0: opaque at t = 5; primitive 1: non-opaque at t = 3.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0)), r.h.triangles(triAt(-2), GEOMETRY_FLAG_NONE)}))});
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING) << "traversal has not started: nothing committed yet";
        ASSERT_TRUE(q.Proceed());
        EXPECT_EQ(q.CandidateTriangleRayT(), 3.0f);
        q.CommitNonOpaqueTriangleHit();
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_TRIANGLE_HIT);

        // From the candidate state: the commit is discarded and the new ray starts afresh.
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay(4.0f));
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);
        ASSERT_TRUE(q.Proceed());
        EXPECT_EQ(q.CandidateTriangleRayT(), 3.0f) << "the same primitive is enumerated again";
        EXPECT_EQ(q.CommittedRayT(), 4.0f);
        EXPECT_FALSE(q.Proceed());  // the opaque triangle lies beyond TMax 4
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);

        // From the finished state: Proceed works again.
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(q.Proceed());
        EXPECT_FALSE(q.Proceed());  // the opaque triangle is committed by the system
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_TRIANGLE_HIT);
        EXPECT_EQ(q.CommittedPrimitiveIndex(), 0u);
        EXPECT_EQ(q.CommittedGeometryIndex(), 0u);

        // Twice in a row, before any Proceed: the last one counts.
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        q.TraceRayInline(scene, RAY_FLAG_FORCE_OPAQUE, 0xFF, zRay());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);
        EXPECT_FALSE(q.Proceed());
        EXPECT_EQ(q.CommittedRayT(), 3.0f);
        EXPECT_EQ(q.CommittedGeometryIndex(), 1u);
    };
    EventLog log;
    const DispatchResult res = runQuery(r, observed(log));
    EXPECT_TRUE(res.diagnostics.errors().empty());
    std::vector<uint32_t> ids;
    for (const auto& e : log.of(TraceEvent::Kind::QueryInit)) ids.push_back(e.queryId);
    EXPECT_EQ(ids, (std::vector<uint32_t>{1, 2, 3, 4, 5}));
}

TEST(RayQuery, RQ_10_NullAccelerationStructureMissesAndOnlyTheLow8MaskBitsCount) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0))}), 0, Matrix3x4::identity(), 0x01)});
    declare(r, "RG", {RAY_FLAG_NONE});
    GpuVirtualAddress as = 0;
    uint32_t mask = 0xFF, status = 99;
    float t = -1.0f;
    r.rg = [&](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(as, RAY_FLAG_NONE, mask, zRay(42.5f));
        EXPECT_FALSE(q.Proceed());
        status = q.CommittedStatus();
        t = q.CommittedRayT();
    };
    const DispatchResult nullAs = runQuery(r);
    EXPECT_TRUE(nullAs.diagnostics.errors().empty());
    EXPECT_EQ(status, COMMITTED_NOTHING);
    EXPECT_EQ(t, 42.5f);
    as = r.h.scene;
    runQuery(r);
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
    mask = 0x100;  // (0x100 & 0x01) & 0xff == 0
    runQuery(r);
    EXPECT_EQ(status, COMMITTED_NOTHING);
    mask = 0x101;
    runQuery(r);
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
    mask = 0xFE;
    runQuery(r);
    EXPECT_EQ(status, COMMITTED_NOTHING);
}

TEST(RayQuery, RQ_11_InvalidRaysAreDiagnosedAndFindNothing) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0)));
    declare(r, "RG", {RAY_FLAG_NONE});
    RayDesc ray = zRay();
    bool proceeded = true;
    uint32_t status = 99;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
        proceeded = q.Proceed();
        status = q.CommittedStatus();
    };
    struct Case {
        const char* field;
        std::function<void(RayDesc&)> poison;
    };
    const std::vector<Case> nans = {
        {"Origin.x", [](RayDesc& d) { d.Origin.x = kNaN; }},       {"Origin.y", [](RayDesc& d) { d.Origin.y = kNaN; }},
        {"Origin.z", [](RayDesc& d) { d.Origin.z = kNaN; }},       {"Direction.x", [](RayDesc& d) { d.Direction.x = kNaN; }},
        {"Direction.y", [](RayDesc& d) { d.Direction.y = kNaN; }}, {"Direction.z", [](RayDesc& d) { d.Direction.z = kNaN; }},
        {"TMin", [](RayDesc& d) { d.TMin = kNaN; }},               {"TMax", [](RayDesc& d) { d.TMax = kNaN; }},
    };
    for (const Case& c : nans) {
        ray = zRay();
        c.poison(ray);
        const Diagnostic d = expectDxrError("RQ-11", [&] { runQuery(r); });
        EXPECT_TRUE(contains(d.message, c.field)) << d.format();
    }
    ray = zRay();
    ray.TMin = -0.5f;
    Diagnostic d = expectDxrError("RQ-11", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "negative")) << d.format();
    ray = zRay(2.0f);
    ray.TMin = 3.0f;
    d = expectDxrError("RQ-11", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "greater than TMax")) << d.format();
    const DispatchResult cont = runQuery(r, continueMode());
    EXPECT_TRUE(hasRule(cont.diagnostics.errors(), "RQ-11"));
    EXPECT_FALSE(proceeded);
    EXPECT_EQ(status, COMMITTED_NOTHING);

    // +INF is valid for either end.
    ray = zRay(kInf);
    EXPECT_TRUE(runQuery(r).diagnostics.errors().empty());
    EXPECT_EQ(status, COMMITTED_TRIANGLE_HIT);
    ray.TMin = kInf;
    EXPECT_TRUE(runQuery(r).diagnostics.errors().empty());
    EXPECT_EQ(status, COMMITTED_NOTHING);
}

TEST(RayQuery, RQ_11_TriangleIntervalIsOpenProceduralIsClosed) {
    Rig r;
    const GpuVirtualAddress triangles = oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    const GpuVirtualAddress box = oneInstance(r, r.h.aabbs({unitBox()}));
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<bool> enumerated;
    std::vector<float> committed;
    const float below = std::nextafter(5.0f, 0.0f), above = std::nextafter(5.0f, 10.0f);
    r.rg = [&](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        auto triangleSeen = [&](float tMin, float tMax) {
            q.TraceRayInline(triangles, RAY_FLAG_NONE, 0xFF, RayDesc{vec3(0, 0, -5), tMin, vec3(0, 0, 1), tMax});
            const bool seen = q.Proceed();
            if (seen) {
                EXPECT_EQ(q.CandidateTriangleRayT(), 5.0f);
            }
            return seen;
        };
        enumerated = {triangleSeen(5.0f, 100.0f), triangleSeen(0.0f, 5.0f), triangleSeen(5.0f, 5.0f),
                      triangleSeen(below, above)};
        // A procedural hit may lie at either end: [4.5, 5.5] inside the box.
        q.TraceRayInline(box, RAY_FLAG_NONE, 0xFF, RayDesc{vec3(0, 0, -5), 4.5f, vec3(0, 0, 1), 5.5f});
        ASSERT_TRUE(q.Proceed());
        q.CommitProceduralPrimitiveHit(5.5f);  // == TMax == CommittedRayT
        committed.push_back(q.CommittedRayT());
        q.CommitProceduralPrimitiveHit(4.5f);  // == RayTMin
        committed.push_back(q.CommittedRayT());
        EXPECT_FALSE(q.Proceed());
    };
    const DispatchResult res = runQuery(r);
    EXPECT_TRUE(res.diagnostics.errors().empty());
    EXPECT_EQ(enumerated, (std::vector<bool>{false, false, false, true}));
    EXPECT_EQ(committed, (std::vector<float>{5.5f, 4.5f}));
}

TEST(RayQuery, RQ_12_ProceedAfterFalseStaysFalseAndDoesNothingWithANote) {
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({-2, 0}), GEOMETRY_FLAG_NONE));  // t = 3, 5
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<bool> results;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        results.push_back(q.Proceed());
        results.push_back(q.Proceed());
        q.CommitNonOpaqueTriangleHit();  // t = 5
        results.push_back(q.Proceed());
        results.push_back(q.Proceed());
        results.push_back(q.Proceed());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_TRIANGLE_HIT);
        EXPECT_EQ(q.CommittedRayT(), 5.0f);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());  // until the next TraceRayInline
        results.push_back(q.Proceed());
    };
    EventLog log;
    const DispatchResult res = runQuery(r, observed(log));
    EXPECT_EQ(results, (std::vector<bool>{true, true, false, false, false, true}));
    EXPECT_EQ(log.of(TraceEvent::Kind::Candidate).size(), 3u) << "no candidate is met after FALSE";
    EXPECT_EQ(log.of(TraceEvent::Kind::QueryCommit).size(), 1u);
    const auto notes = res.diagnostics.notes();
    ASSERT_TRUE(hasRule(notes, "RQ-12"));
    for (const Diagnostic& n : notes)
        if (n.ruleId == "RQ-12") {
            EXPECT_EQ(n.severity, Severity::Note);
            EXPECT_TRUE(contains(n.message, "SPIR-V")) << n.format();
        }
    EXPECT_TRUE(res.diagnostics.warnings().empty());
    EXPECT_TRUE(res.diagnostics.errors().empty());
}

TEST(RayQuery, RQ_12_NotesAreCountedOverTheDispatchAndLocatedAtTheFirstLaunch) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        if (i.x == 0 && i.y == 0) return;  // the first launch makes no note
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
        }
        for (uint32_t k = 0; k < i.x; ++k) q.Proceed();  // after FALSE: i.x notes
    };
    std::vector<Diagnostic> seen;
    for (uint32_t threads : {1u, 2u, 0u}) {
        DispatchOptions o;
        o.threads = threads;
        o.tileSize = 3;
        const auto notes = runQuery(r, o, uvec3(7, 5, 1)).diagnostics.notes();
        ASSERT_EQ(notes.size(), 1u) << threads << " threads";
        const Diagnostic& n = notes[0];
        EXPECT_EQ(n.ruleId, "RQ-12");
        EXPECT_EQ(n.count, (1u + 2 + 3 + 4 + 5 + 6) * 5) << threads << " threads";
        ASSERT_TRUE(n.site);
        EXPECT_EQ(n.site->launchIndex, uvec3(1, 0, 0)) << threads << " threads";
        seen.push_back(n);
    }
    for (const Diagnostic& n : seen) EXPECT_EQ(n.format(), seen[0].format());
}

TEST(RayQuery, RQ_13_EveryPrimitiveReallyHitIsEnumeratedInAnyOrder) {
    Rig r;
    // Primitives 0..4 on the ray inside [1, 20]: t = 7, 3, 5, 9, 6. Primitive 5 is off the ray, 6 beyond TMax
    // (t = 55), 7 before TMin (t = 0.5).
    std::vector<vec3> v = trisAt({2, -2, 0, 4, 1});
    for (const vec3& p : triAt(3)) v.push_back(p + vec3(10, 0, 0));
    for (const vec3& p : trisAt({50, -4.5f})) v.push_back(p);
    oneInstance(r, r.h.triangles(v, GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_NONE});
    const RayDesc ray{vec3(0.0f, 0.2f, -5.0f), 1.0f, vec3(0, 0, 1), 20.0f};
    bool commitAll = false;
    std::set<uint32_t> seen;
    float committedT = -1.0f;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
        while (q.Proceed()) {
            seen.insert(q.CandidatePrimitiveIndex());
            if (commitAll) q.CommitNonOpaqueTriangleHit();
        }
        committedT = q.CommittedRayT();
    };
    const std::set<uint32_t> reallyHit = {0, 1, 2, 3, 4};
    runQuery(r);
    EXPECT_EQ(seen, reallyHit);
    EXPECT_EQ(committedT, 20.0f);
    // The seeded adversarial orders shuffle the candidates (and present some twice): each is still enumerated, and a
    // shader that commits every candidate it is shown ends with the nearest.
    for (uint64_t seed = 1; seed <= 6; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        seen.clear();
        commitAll = false;
        runQuery(r, o);
        EXPECT_EQ(seen, reallyHit) << "seed " << seed;
        seen.clear();
        commitAll = true;
        runQuery(r, o);
        EXPECT_TRUE(seen.count(1)) << "seed " << seed;
        EXPECT_EQ(committedT, 3.0f) << "seed " << seed;
    }
}

TEST(RayQuery, RQ_13_CommittingLowersCommittedRayTSoFartherTrianglesAreSkipped) {
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({2, -2, 0, 4}), GEOMETRY_FLAG_NONE));  // t = 7, 3, 5, 9
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t proceeds = 0;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
            ++proceeds;
            EXPECT_EQ(q.CandidateTriangleRayT(), 3.0f);
            q.CommitNonOpaqueTriangleHit();
            EXPECT_EQ(q.CommittedRayT(), 3.0f);
        }
    };
    EventLog log;
    runQuery(r, observed(log));
    EXPECT_EQ(proceeds, 1u);
    const auto skipped = log.of(TraceEvent::Kind::Skipped);
    std::set<uint32_t> skippedPrimitives;
    for (const auto& e : skipped) {
        skippedPrimitives.insert(e.primitiveIndex);
        EXPECT_EQ(e.queryId, 1u);
        EXPECT_TRUE(contains(e.note, "CommittedRayT")) << e.note;
    }
    EXPECT_EQ(skippedPrimitives, (std::set<uint32_t>{0, 2, 3}));
}

TEST(RayQuery, RQ_14_OpaqueTrianglesAreCommittedInsideProceedAndNeverReachTheShader) {
    Rig r;
    // Instance 0: non-opaque at t = 3, 5, 7; instance 1: opaque at t = 5.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(trisAt({-2, 0, 2}), GEOMETRY_FLAG_NONE)})),
              Harness::instance(r.h.blas({r.h.triangles(triAt(0))}))});
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<float> shown;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) shown.push_back(q.CandidateTriangleRayT());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_TRIANGLE_HIT);
        EXPECT_EQ(q.CommittedInstanceIndex(), 1u);
        EXPECT_EQ(q.CommittedRayT(), 5.0f);
    };
    EventLog log;
    runQuery(r, observed(log));
    // t = 5 of instance 0 ties with the opaque one and is met first; nothing at or beyond 5 follows the commit.
    EXPECT_EQ(shown, (std::vector<float>{3.0f, 5.0f}));
    const auto commits = log.of(TraceEvent::Kind::QueryCommit);
    ASSERT_EQ(commits.size(), 1u);
    EXPECT_TRUE(contains(commits[0].note, "RQ-14")) << commits[0].note;
    EXPECT_EQ(commits[0].instanceIndex, 1u);
}

TEST(RayQuery, RQ_14_OpacityComesFromGeometryThenInstanceThenRayFlags) {
    // OPQ-1 for queries: ray flags (template or dynamic) over instance flags over the geometry flag.
    Rig r;
    const std::vector<uint32_t> geometryFlags = {GEOMETRY_FLAG_OPAQUE, GEOMETRY_FLAG_NONE};
    const std::vector<uint32_t> instanceFlags = {INSTANCE_FLAG_NONE, INSTANCE_FLAG_FORCE_OPAQUE, INSTANCE_FLAG_FORCE_NON_OPAQUE};
    const std::vector<uint32_t> rayFlags = {RAY_FLAG_NONE, RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_FORCE_NON_OPAQUE};
    struct Scene {
        GpuVirtualAddress tlas;
        bool opaque;  // from geometry and instance
        uint32_t instanceFlags;
    };
    std::vector<Scene> scenes;
    for (uint32_t g : geometryFlags) {
        const GpuVirtualAddress blas = r.h.blas({r.h.triangles(triAt(0), g)});
        for (uint32_t i : instanceFlags) {
            const bool opaque = i == INSTANCE_FLAG_FORCE_OPAQUE ? true
                                : i == INSTANCE_FLAG_FORCE_NON_OPAQUE ? false
                                                                      : g == GEOMETRY_FLAG_OPAQUE;
            scenes.push_back({r.h.tlas({Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF, i)}), opaque, i});
        }
    }
    declare(r, "RG", rayFlags);
    uint32_t cases = 0;
    r.rg = [&](ShaderContext& ctx) {
        for (const Scene& s : scenes)
            for (uint32_t f : rayFlags)
                for (bool asTemplate : {false, true}) {
                    const bool opaque = f == RAY_FLAG_FORCE_OPAQUE ? true : f == RAY_FLAG_FORCE_NON_OPAQUE ? false : s.opaque;
                    RayQueryObject q(ctx, asTemplate ? f : RAY_FLAG_NONE, RAYQUERY_FLAG_NONE);
                    q.TraceRayInline(s.tlas, asTemplate ? RAY_FLAG_NONE : f, 0xFF, zRay());
                    const bool shown = q.Proceed();
                    EXPECT_EQ(shown, !opaque) << "instance flags " << s.instanceFlags << ", ray flags "
                                              << rayFlagsToString(f) << (asTemplate ? " (template)" : " (dynamic)");
                    if (shown) {
                        EXPECT_EQ(q.CandidateType(), CANDIDATE_NON_OPAQUE_TRIANGLE);
                        EXPECT_FALSE(q.Proceed());
                    }
                    EXPECT_EQ(q.CommittedStatus(), opaque ? COMMITTED_TRIANGLE_HIT : COMMITTED_NOTHING);
                    ++cases;
                }
    };
    EXPECT_TRUE(runQuery(r).diagnostics.errors().empty());
    EXPECT_EQ(cases, 36u);
}

TEST(RayQuery, RQ_14_CulledOpaqueTrianglesAreNotCommitted) {
    Rig r;
    // Opaque, back-facing at t = 3; opaque, front-facing at t = 5.
    std::vector<vec3> v = backTriAt(-2);
    for (const vec3& p : triAt(0)) v.push_back(p);
    oneInstance(r, r.h.triangles(v));
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t flags = RAY_FLAG_NONE, status = 99, primitive = 99;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, flags, 0xFF, zRay());
        EXPECT_FALSE(q.Proceed());
        status = q.CommittedStatus();
        primitive = status ? q.CommittedPrimitiveIndex() : 99;
    };
    runQuery(r);
    EXPECT_EQ(primitive, 0u);
    flags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
    runQuery(r);
    EXPECT_EQ(primitive, 1u);
    flags = RAY_FLAG_CULL_OPAQUE;
    runQuery(r);
    EXPECT_EQ(status, COMMITTED_NOTHING);
}

TEST(RayQuery, RQ_15_AbortFinishesTheQueryAndKeepsTheCommittedHitReadable) {
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({-2, 0}), GEOMETRY_FLAG_NONE), INSTANCE_FLAG_NONE, 31);  // t = 3, 5
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(q.Proceed());
        q.CommitNonOpaqueTriangleHit();
        q.Abort();
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_TRIANGLE_HIT);
        EXPECT_EQ(q.CommittedRayT(), 3.0f);
        EXPECT_EQ(q.CommittedPrimitiveIndex(), 0u);
        EXPECT_EQ(q.CommittedInstanceID(), 31u);
        EXPECT_NEAR(q.CommittedTriangleBarycentrics().x, 0.6f, 1e-6f);
        EXPECT_NEAR(q.CommittedTriangleBarycentrics().y, 0.2f, 1e-6f);
        EXPECT_TRUE(q.CommittedTriangleFrontFace());
        EXPECT_FALSE(q.Proceed());

        // Abort ends the search although a candidate (t = 5) remains.
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(q.Proceed());
        q.Abort();
        EXPECT_FALSE(q.Proceed());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);
    };
    const DispatchResult afterTrue = runQuery(r);
    EXPECT_TRUE(afterTrue.diagnostics.errors().empty());
    EXPECT_FALSE(hasRule(afterTrue.diagnostics.notes(), "RQ-15")) << "each Abort followed a TRUE Proceed";
    // Abort right after TraceRayInline, or after Proceed returned FALSE: legal in DXR, undefined in SPIR-V.
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay(7.0f));
        q.Abort();
        EXPECT_FALSE(q.Proceed());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);
        EXPECT_EQ(q.CommittedRayT(), 7.0f);
    };
    const DispatchResult early = runQuery(r);
    EXPECT_TRUE(early.diagnostics.errors().empty());
    EXPECT_TRUE(early.diagnostics.warnings().empty());
    const auto note = early.diagnostics.find("RQ-15");
    ASSERT_TRUE(note);
    EXPECT_EQ(note->severity, Severity::Note);
    // Before TraceRayInline there is nothing to abort.
    r.rg = [](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.Abort();
    };
    expectDxrError("RQ-19", [&] { runQuery(r); });
}

TEST(RayQuery, RQ_16_AcceptFirstHitEndsTheSearchAfterASystemOrAShaderCommit) {
    Rig r;
    // A triangle at t = 5 (instance 0) and a box entered at exactly t = 5 (instance 1): the box comes next.
    const GpuVirtualAddress boxBlas = r.h.blas({r.h.aabbs({unitBox()})});
    const Matrix3x4 boxAt5 = Matrix3x4::translation({0, 0, 1});
    const GpuVirtualAddress opaque = r.h.tlas(
        {Harness::instance(r.h.blas({r.h.triangles(triAt(0))})), Harness::instance(boxBlas, 0, boxAt5)});
    const GpuVirtualAddress nonOpaque = r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)})),
                                                  Harness::instance(boxBlas, 0, boxAt5)});
    // The unit box (entered at 4) and a non-opaque triangle at t = 5.5.
    const GpuVirtualAddress boxFirst = r.h.tlas({Harness::instance(boxBlas),
                                                 Harness::instance(r.h.blas({r.h.triangles(triAt(0.5f), GEOMETRY_FLAG_NONE)}))});
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t flags = RAY_FLAG_NONE;
    std::vector<std::string> steps;
    r.rg = [&](ShaderContext& ctx) {
        for (GpuVirtualAddress scene : {opaque, nonOpaque, boxFirst}) {
            RayQuery<RAY_FLAG_NONE> q(ctx);
            q.TraceRayInline(scene, flags, 0xFF, zRay());
            std::string s;
            while (q.Proceed()) {
                if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE) {
                    s += "box ";
                    if (q.CommittedStatus() == COMMITTED_NOTHING) q.CommitProceduralPrimitiveHit(6.0f);
                } else {
                    s += "triangle ";
                    if (q.CommittedStatus() == COMMITTED_NOTHING) q.CommitNonOpaqueTriangleHit();
                }
            }
            s += std::to_string(q.CommittedStatus()) + "@" + std::to_string(int(q.CommittedRayT() * 10));
            steps.push_back(s);
        }
    };
    runQuery(r);
    EXPECT_EQ(steps, (std::vector<std::string>{"box 1@50", "triangle box 1@50", "box triangle 2@60"}));
    steps.clear();
    flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    EventLog log;
    runQuery(r, observed(log));
    EXPECT_EQ(steps, (std::vector<std::string>{"1@50", "triangle 1@50", "box 2@60"}));
    const auto proceeds = log.of(TraceEvent::Kind::QueryProceed);
    ASSERT_FALSE(proceeds.empty());
    EXPECT_TRUE(contains(proceeds.back().note, "ACCEPT_FIRST_HIT_AND_END_SEARCH")) << proceeds.back().note;
}

TEST(RayQuery, RQ_17_CandidateTypeIsValidOnlyAfterATrueProceed) {
    static_assert(CANDIDATE_NON_OPAQUE_TRIANGLE == 0 && CANDIDATE_PROCEDURAL_PRIMITIVE == 1);
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(-2), GEOMETRY_FLAG_NONE)})),  // t = 3
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});                      // entered at 4
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<uint32_t> types;
    bool afterFalse = false;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) types.push_back(q.CandidateType());
        if (afterFalse) q.CandidateType();
    };
    runQuery(r);
    EXPECT_EQ(types, (std::vector<uint32_t>{CANDIDATE_NON_OPAQUE_TRIANGLE, CANDIDATE_PROCEDURAL_PRIMITIVE}));
    afterFalse = true;
    const Diagnostic d = expectDxrError("RQ-28", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "CandidateType")) << d.format();
    EXPECT_TRUE(contains(valueOf(d, "state"), "FALSE")) << d.format();
}

TEST(RayQuery, RQ_18_CommittedStatusThroughTheQuerysLife) {
    static_assert(COMMITTED_NOTHING == 0 && COMMITTED_TRIANGLE_HIT == 1 && COMMITTED_PROCEDURAL_PRIMITIVE_HIT == 2);
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})})),  // entered at 4
              Harness::instance(r.h.blas({r.h.triangles(triAt(-0.5f), GEOMETRY_FLAG_NONE)}))});  // t = 4.5
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<uint32_t> statuses;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        statuses.push_back(q.CommittedStatus());
        ASSERT_TRUE(q.Proceed());
        statuses.push_back(q.CommittedStatus());
        q.CommitProceduralPrimitiveHit(5.0f);
        statuses.push_back(q.CommittedStatus());
        ASSERT_TRUE(q.Proceed());
        q.CommitNonOpaqueTriangleHit();
        statuses.push_back(q.CommittedStatus());
        EXPECT_FALSE(q.Proceed());
        statuses.push_back(q.CommittedStatus());  // after traversal finished
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    EXPECT_EQ(statuses, (std::vector<uint32_t>{COMMITTED_NOTHING, COMMITTED_NOTHING, COMMITTED_PROCEDURAL_PRIMITIVE_HIT,
                                               COMMITTED_TRIANGLE_HIT, COMMITTED_TRIANGLE_HIT}));
    r.rg = [](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.CommittedStatus();
    };
    const Diagnostic d = expectDxrError("RQ-19", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "before TraceRayInline")) << d.format();
}

TEST(RayQuery, RQ_19_ACallInAnUnlistedStateStopsWithRuleLaunchStageAndState) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        if (ctx.DispatchRaysIndex() == uvec3(2, 1, 0)) q.Proceed();  // before TraceRayInline
    };
    Diagnostic d = expectDxrError("RQ-19", [&] { runQuery(r, {}, uvec3(3, 2, 1)); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(2, 1, 0));
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
    EXPECT_EQ(d.site->exportName, "RG");
    EXPECT_TRUE(contains(d.message, "Proceed")) << d.format();
    EXPECT_TRUE(contains(valueOf(d, "state"), "no TraceRayInline")) << d.format();

    // From a closest-hit shader, a candidate getter after Proceed returned FALSE.
    const GpuVirtualAddress target = r.h.scene;
    r.rg = nullptr;
    r.chTri = [target](ShaderContext& ctx, Probe&, const BuiltInTriangleIntersectionAttributes&) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(target, RAY_FLAG_FORCE_OPAQUE, 0xFF, zRay());
        EXPECT_FALSE(q.Proceed());
        q.CandidateInstanceIndex();
    };
    declare(r, "CH_TriS", {RAY_FLAG_NONE});
    r.so = nullptr;
    d = expectDxrError("RQ-28", [&] { r.run({"HG_TriS_noAH"}, uvec3(2, 2, 1)); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(0u));
    EXPECT_EQ(d.site->stage, ShaderStage::ClosestHit);
    EXPECT_EQ(d.site->exportName, "CH_TriS");
    EXPECT_EQ(d.site->depth, 1u);
    EXPECT_TRUE(contains(valueOf(d, "state"), "FALSE")) << d.format();
    EXPECT_EQ(valueOf(d, "CommittedStatus"), "COMMITTED_TRIANGLE_HIT") << d.format();
}

TEST(RayQuery, RQ_19_UnderContinueEveryCallIsRecordedAndReturnsZeros) {
    Rig r;
    // Instance 1 (InstanceID 9, translated) holds the triangle, so zeros are told apart from real values.
    const GpuVirtualAddress tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(tri, 0, Matrix3x4::translation({50, 0, 0})),
              Harness::instance(tri, 0, Matrix3x4::translation({0, 0, 1}), 0xFF, INSTANCE_FLAG_NONE, 9)});
    declare(r, "RG", {RAY_FLAG_NONE});
    struct Out {
        bool proceedBeforeTrace = true;
        uint32_t candidateIndex = 99, committedID = 99, committedIndex = 99;
        float candidateT = -1.0f;
        vec2 barycentrics{-1.0f};
        Matrix3x4 objectToWorld = Matrix3x4::identity();
        vec3 objectOrigin{-1.0f};
    };
    std::vector<Out> out(4);
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        Out& o = out[ctx.DispatchRaysIndex().x];
        RayQuery<RAY_FLAG_NONE> q(ctx);
        o.proceedBeforeTrace = q.Proceed();
        q.Abort();
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
        }
        o.candidateIndex = q.CandidateInstanceIndex();
        o.candidateT = q.CandidateTriangleRayT();
        o.barycentrics = q.CandidateTriangleBarycentrics();
        o.committedID = q.CommittedInstanceID();
        o.committedIndex = q.CommittedInstanceIndex();
        o.objectToWorld = q.CommittedObjectToWorld3x4();
        o.objectOrigin = q.CommittedObjectRayOrigin();
    };
    const DispatchResult res = runQuery(r, continueMode(), uvec3(4, 1, 1));
    for (const Out& o : out) {
        EXPECT_FALSE(o.proceedBeforeTrace);
        EXPECT_EQ(o.candidateIndex, 0u);
        EXPECT_EQ(o.candidateT, 0.0f);
        EXPECT_EQ(o.barycentrics, vec2(0.0f));
        EXPECT_EQ(o.committedID, 0u);
        EXPECT_EQ(o.committedIndex, 0u);
        EXPECT_EQ(o.objectToWorld, Matrix3x4{});
        EXPECT_EQ(o.objectOrigin, vec3(0.0f));
    }
    const auto errors = res.diagnostics.errors();
    EXPECT_EQ(countOf(errors, "RQ-19"), 8u);  // Proceed and Abort before TraceRayInline, on 4 launches
    EXPECT_EQ(countOf(errors, "RQ-28"), 12u);
    EXPECT_EQ(countOf(errors, "RQ-29"), 16u);
    for (const Diagnostic& d : errors) {
        ASSERT_TRUE(d.site);
        EXPECT_EQ(d.site->launchIndex, uvec3(0u)) << "the first occurrence is kept: " << d.format();
        EXPECT_NE(findValue(d, "state"), nullptr) << d.format();
    }
}

// ---------------------------------------------------------------------------------------
// 18c. Commits.

TEST(RayQuery, RQ_20_ATriangleCandidateLiesStrictlyBetweenRayTMinAndCommittedRayT) {
    Rig r;
    // t = 2, 3 (== TMin), 4, 5, 6, 7, 8, 9, 10 (== TMax), 11.
    oneInstance(r, r.h.triangles(trisAt({-3, -2, -1, 0, 1, 2, 3, 4, 5, 6}), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_NONE});
    const RayDesc ray{vec3(0.0f, 0.2f, -5.0f), 3.0f, vec3(0, 0, 1), 10.0f};
    std::set<float> shown;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
        uint32_t n = 0;
        while (q.Proceed()) {
            const float t = q.CandidateTriangleRayT();
            shown.insert(t);
            EXPECT_LT(q.RayTMin(), t);
            EXPECT_LT(t, q.CommittedRayT());
            if (n++ % 2) q.CommitNonOpaqueTriangleHit();
        }
    };
    for (uint64_t seed = 0; seed <= 8; ++seed) {
        DispatchOptions o;
        o.order = seed ? TraversalOrder::Adversarial : TraversalOrder::Ordered;
        o.adversarialSeed = seed;
        runQuery(r, o);
    }
    ASSERT_FALSE(shown.empty());
    EXPECT_GT(*shown.begin(), 3.0f);
    EXPECT_LT(*shown.rbegin(), 10.0f);
    EXPECT_GE(shown.size(), 4u) << "adversarial orders show farther triangles before nearer ones are committed";
}

TEST(RayQuery, RQ_21_CommitKeepsTheCandidatesValuesAndASecondCommitDoesNothing) {
    Rig r;
    // Geometry 1 of instance 1 (translated, InstanceID 5): two coincident back-facing triangles at t = 4.
    const std::vector<vec3> back = backTriAt(0);
    const GpuVirtualAddress backBlas = r.h.blas({r.h.triangles(triAt(30), GEOMETRY_FLAG_NONE),
                                                 r.h.triangles({back[0], back[1], back[2], back[0], back[1], back[2]},
                                                               GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(backBlas, 0, Matrix3x4::translation({60, 0, 0})),
              Harness::instance(backBlas, 2, Matrix3x4::translation({0, 0, -1}), 0xFF, INSTANCE_FLAG_NONE, 5)});
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(q.Proceed());
        const uint32_t index = q.CandidateInstanceIndex(), id = q.CandidateInstanceID(),
                       contribution = q.CandidateInstanceContributionToHitGroupIndex(), geometry = q.CandidateGeometryIndex(),
                       primitive = q.CandidatePrimitiveIndex();
        const float t = q.CandidateTriangleRayT();
        const vec2 bary = q.CandidateTriangleBarycentrics();
        const bool front = q.CandidateTriangleFrontFace();
        const vec3 origin = q.CandidateObjectRayOrigin(), direction = q.CandidateObjectRayDirection();
        const Matrix3x4 o2w = q.CandidateObjectToWorld3x4(), w2o = q.CandidateWorldToObject3x4();
        EXPECT_EQ(index, 1u);
        EXPECT_EQ(id, 5u);
        EXPECT_EQ(contribution, 2u);
        EXPECT_EQ(geometry, 1u);
        EXPECT_EQ(primitive, 0u);
        EXPECT_EQ(t, 4.0f);
        EXPECT_FALSE(front);
        q.CommitNonOpaqueTriangleHit();
        q.CommitNonOpaqueTriangleHit();
        // The coincident primitive (1) is not shown: t == CommittedRayT.
        EXPECT_FALSE(q.Proceed());
        EXPECT_EQ(q.CommittedInstanceIndex(), index);
        EXPECT_EQ(q.CommittedInstanceID(), id);
        EXPECT_EQ(q.CommittedInstanceContributionToHitGroupIndex(), contribution);
        EXPECT_EQ(q.CommittedGeometryIndex(), geometry);
        EXPECT_EQ(q.CommittedPrimitiveIndex(), primitive);
        EXPECT_EQ(q.CommittedRayT(), t);
        EXPECT_EQ(q.CommittedTriangleBarycentrics(), bary);
        EXPECT_EQ(q.CommittedTriangleFrontFace(), front);
        EXPECT_EQ(q.CommittedObjectRayOrigin(), origin);
        EXPECT_EQ(q.CommittedObjectRayDirection(), direction);
        EXPECT_EQ(q.CommittedObjectToWorld3x4(), o2w);
        EXPECT_EQ(q.CommittedWorldToObject3x4(), w2o);
    };
    EventLog log;
    EXPECT_TRUE(runQuery(r, observed(log)).diagnostics.empty());
    EXPECT_EQ(log.of(TraceEvent::Kind::QueryCommit).size(), 1u) << "the second commit has no effect";
}

TEST(RayQuery, RQ_22_ProceduralCommitsZeroOrMoreTimesInsideTMinAndCommittedRayT) {
    Rig r;
    oneInstance(r, r.h.aabbs({unitBox()}));  // entered at 4, left at 6
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<float> commits;
    uint32_t status = 99;
    float t = -1.0f;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, RayDesc{vec3(0, 0, -5), 1.0f, vec3(0, 0, 1), 100.0f});
        while (q.Proceed())
            for (float c : commits) q.CommitProceduralPrimitiveHit(c);
        status = q.CommittedStatus();
        t = q.CommittedRayT();
    };
    runQuery(r);  // no commit
    EXPECT_EQ(status, COMMITTED_NOTHING);
    commits = {5.5f, 4.5f, 5.0f};  // the third is past the new CommittedRayT
    Diagnostic d = expectDxrError("RQ-22", [&] { runQuery(r); });
    EXPECT_EQ(valueOf(d, "tHit"), "5") << d.format();
    EXPECT_EQ(valueOf(d, "CommittedRayT"), "4.5") << d.format();
    DispatchResult cont = runQuery(r, continueMode());
    EXPECT_EQ(countOf(cont.diagnostics.errors(), "RQ-22"), 1u);
    EXPECT_EQ(status, COMMITTED_PROCEDURAL_PRIMITIVE_HIT);
    EXPECT_EQ(t, 4.5f) << "the out-of-range commit is dropped";
    commits = {0.5f};  // below RayTMin
    d = expectDxrError("RQ-22", [&] { runQuery(r); });
    EXPECT_EQ(valueOf(d, "RayTMin"), "1") << d.format();
    cont = runQuery(r, continueMode());
    EXPECT_EQ(status, COMMITTED_NOTHING);
    commits = {kNaN};
    expectDxrError("RQ-22", [&] { runQuery(r); });
    commits = {5.5f, 4.5f};
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    EXPECT_EQ(t, 4.5f);

    // CommitProceduralPrimitiveHit is for procedural candidates only.
    Rig tri;
    oneInstance(tri, tri.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(tri, "RG", {RAY_FLAG_NONE});
    tri.rg = [scene = tri.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        if (q.Proceed()) q.CommitProceduralPrimitiveHit(5.0f);
    };
    d = expectDxrError("RQ-22", [&] { runQuery(tri); });
    EXPECT_TRUE(contains(d.message, "CANDIDATE_PROCEDURAL_PRIMITIVE")) << d.format();
}

TEST(RayQuery, RQ_23_AProceduralCommitKeepsTheGivenTAndTheNodeOnly) {
    Rig r;
    // Instance 1 (InstanceID 77, contribution 4, translated by (3, 0, 0)); geometry 1, primitive 2 on the ray.
    const GpuVirtualAddress boxes =
        r.h.blas({r.h.aabbs({{40, 40, 40, 41, 41, 41}}),
                  r.h.aabbs({{30, 30, 30, 31, 31, 31}, {20, 20, 20, 21, 21, 21}, unitBox()}, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(boxes, 0, Matrix3x4::translation({-50, 0, 0})),
              Harness::instance(boxes, 4, Matrix3x4::translation({3, 0, 0}), 0xFF, INSTANCE_FLAG_NONE, 77)});
    declare(r, "RG", {RAY_FLAG_NONE});
    const RayDesc ray{vec3(3.0f, 0.5f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f};
    r.rg = [scene = r.h.scene, ray](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
        ASSERT_TRUE(q.Proceed());
        ASSERT_EQ(q.CandidateType(), CANDIDATE_PROCEDURAL_PRIMITIVE);
        const uint32_t index = q.CandidateInstanceIndex(), id = q.CandidateInstanceID(),
                       contribution = q.CandidateInstanceContributionToHitGroupIndex(), geometry = q.CandidateGeometryIndex(),
                       primitive = q.CandidatePrimitiveIndex();
        const vec3 origin = q.CandidateObjectRayOrigin(), direction = q.CandidateObjectRayDirection();
        const Matrix3x4 o2w = q.CandidateObjectToWorld3x4(), w2o = q.CandidateWorldToObject3x4();
        EXPECT_EQ(index, 1u);
        EXPECT_EQ(id, 77u);
        EXPECT_EQ(contribution, 4u);
        EXPECT_EQ(geometry, 1u);
        EXPECT_EQ(primitive, 2u);
        EXPECT_EQ(origin, vec3(0.0f, 0.5f, -5.0f));
        q.CommitProceduralPrimitiveHit(5.25f);  // not the box entry (4)
        EXPECT_FALSE(q.Proceed());
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_PROCEDURAL_PRIMITIVE_HIT);
        EXPECT_EQ(q.CommittedRayT(), 5.25f);
        EXPECT_EQ(q.CommittedInstanceIndex(), index);
        EXPECT_EQ(q.CommittedInstanceID(), id);
        EXPECT_EQ(q.CommittedInstanceContributionToHitGroupIndex(), contribution);
        EXPECT_EQ(q.CommittedGeometryIndex(), geometry);
        EXPECT_EQ(q.CommittedPrimitiveIndex(), primitive);
        EXPECT_EQ(q.CommittedObjectRayOrigin(), origin);
        EXPECT_EQ(q.CommittedObjectRayDirection(), direction);
        EXPECT_EQ(q.CommittedObjectToWorld3x4(), o2w);
        EXPECT_EQ(q.CommittedWorldToObject3x4(), w2o);
        EXPECT_EQ(o2w, Matrix3x4::translation({3, 0, 0}));
        // No triangle values and no attributes: those a shader keeps itself.
        EXPECT_EQ(q.CommittedTriangleBarycentrics(), vec2(0.0f));
        EXPECT_FALSE(q.CommittedTriangleFrontFace());
    };
    const DispatchResult res = runQuery(r, continueMode());
    const auto errors = res.diagnostics.errors();
    ASSERT_EQ(errors.size(), 2u);
    EXPECT_EQ(countOf(errors, "RQ-29"), 2u);
    // Under OnError::Stop the triangle getters stop the dispatch.
    expectDxrError("RQ-29", [&] { runQuery(r); });
}

TEST(RayQuery, RQ_24_ProceduralOpacityIsReportedAndOnlyUsedForCulling) {
    Rig r;
    const std::vector<uint32_t> geometryFlags = {GEOMETRY_FLAG_OPAQUE, GEOMETRY_FLAG_NONE};
    const std::vector<uint32_t> instanceFlags = {INSTANCE_FLAG_NONE, INSTANCE_FLAG_FORCE_OPAQUE, INSTANCE_FLAG_FORCE_NON_OPAQUE};
    struct Scene {
        GpuVirtualAddress tlas;
        bool opaque;
    };
    std::vector<Scene> scenes;
    for (uint32_t g : geometryFlags) {
        const GpuVirtualAddress blas = r.h.blas({r.h.aabbs({unitBox()}, g)});
        for (uint32_t i : instanceFlags) {
            const bool opaque = i == INSTANCE_FLAG_FORCE_OPAQUE ? true
                                : i == INSTANCE_FLAG_FORCE_NON_OPAQUE ? false
                                                                      : g == GEOMETRY_FLAG_OPAQUE;
            scenes.push_back({r.h.tlas({Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF, i)}), opaque});
        }
    }
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t cases = 0;
    r.rg = [&](ShaderContext& ctx) {
        for (const Scene& s : scenes)
            for (uint32_t f : {RAY_FLAG_NONE, RAY_FLAG_FORCE_OPAQUE, RAY_FLAG_FORCE_NON_OPAQUE, RAY_FLAG_CULL_OPAQUE,
                               RAY_FLAG_CULL_NON_OPAQUE}) {
                const bool opaque = f == RAY_FLAG_FORCE_OPAQUE ? true : f == RAY_FLAG_FORCE_NON_OPAQUE ? false : s.opaque;
                const bool culled = (f == RAY_FLAG_CULL_OPAQUE && opaque) || (f == RAY_FLAG_CULL_NON_OPAQUE && !opaque);
                RayQuery<RAY_FLAG_NONE> q(ctx);
                q.TraceRayInline(s.tlas, f, 0xFF, zRay());
                const bool shown = q.Proceed();
                EXPECT_EQ(shown, !culled) << rayFlagsToString(f) << ", opaque " << opaque;
                if (shown) {
                    // Opaque or not, the box reaches the shader: the system commits nothing for it.
                    EXPECT_EQ(q.CandidateType(), CANDIDATE_PROCEDURAL_PRIMITIVE);
                    EXPECT_EQ(q.CandidateProceduralPrimitiveNonOpaque(), !opaque) << rayFlagsToString(f);
                    EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);
                    q.CommitProceduralPrimitiveHit(5.0f);  // the shader is free to ignore the opacity
                    EXPECT_FALSE(q.Proceed());
                    EXPECT_EQ(q.CommittedStatus(), COMMITTED_PROCEDURAL_PRIMITIVE_HIT);
                }
                ++cases;
            }
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    EXPECT_EQ(cases, 30u);

    // It is a procedural candidate's getter.
    Rig tri;
    oneInstance(tri, tri.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(tri, "RG", {RAY_FLAG_NONE});
    tri.rg = [scene = tri.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        if (q.Proceed()) q.CandidateProceduralPrimitiveNonOpaque();
    };
    expectDxrError("RQ-28", [&] { runQuery(tri); });
}

// ---------------------------------------------------------------------------------------
// 18d. Getters.

TEST(RayQuery, RQ_25_GettersBeforeTheFirstProceedWarnNotInTheTable) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_CULL_OPAQUE});
    const RayDesc ray{vec3(0.0f, 0.2f, -5.0f), 0.25f, vec3(0, 0, 2), 30.0f};
    bool proceedFirst = false;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_CULL_OPAQUE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0xFF, ray);
        if (proceedFirst) {
            EXPECT_TRUE(q.Proceed());
        }
        EXPECT_EQ(q.RayFlags(), uint32_t(RAY_FLAG_CULL_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH));
        EXPECT_EQ(q.WorldRayOrigin(), ray.Origin);
        EXPECT_EQ(q.WorldRayDirection(), ray.Direction);
        EXPECT_EQ(q.RayTMin(), 0.25f);
        EXPECT_EQ(q.CommittedRayT(), 30.0f);
        EXPECT_EQ(q.CommittedStatus(), COMMITTED_NOTHING);
        if (proceedFirst) {
            EXPECT_FALSE(q.Proceed());
            EXPECT_EQ(q.RayTMin(), 0.25f);
        }
    };
    const DispatchResult before = runQuery(r);
    EXPECT_TRUE(before.diagnostics.errors().empty());
    std::set<std::string> warned;
    for (const Diagnostic& w : before.diagnostics.warnings()) {
        EXPECT_EQ(w.ruleId, "RQ-25") << w.format();
        EXPECT_TRUE(contains(w.message, "not in the specification's table")) << w.format();
        warned.insert(w.message.substr(0, w.message.find('(')));
    }
    EXPECT_EQ(warned, (std::set<std::string>{"RayFlags", "WorldRayOrigin", "WorldRayDirection", "RayTMin", "CommittedRayT"}));
    proceedFirst = true;
    const DispatchResult after = runQuery(r);
    EXPECT_TRUE(after.diagnostics.warnings().empty());
    EXPECT_TRUE(after.diagnostics.errors().empty());
    // Before TraceRayInline they are errors.
    r.rg = [](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_CULL_OPAQUE> q(ctx);
        q.RayTMin();
    };
    expectDxrError("RQ-19", [&] { runQuery(r); });
}

TEST(RayQuery, RQ_26_RayFlagsAreTheTemplateFlagsOrTheDynamicFlags) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_CULL_NON_OPAQUE, RAY_FLAG_NONE});
    std::vector<uint32_t> flags;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_CULL_NON_OPAQUE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES, 0xFF, zRay());
        EXPECT_FALSE(q.Proceed());  // the only triangle is non-opaque: culled
        flags.push_back(q.RayFlags());
        RayQuery<RAY_FLAG_NONE> p(ctx);
        p.TraceRayInline(scene, RAY_FLAG_CULL_FRONT_FACING_TRIANGLES, 0xFF, zRay());
        EXPECT_FALSE(p.Proceed());
        flags.push_back(p.RayFlags());
    };
    EventLog log;
    EXPECT_TRUE(runQuery(r, observed(log)).diagnostics.empty());
    EXPECT_EQ(flags, (std::vector<uint32_t>{RAY_FLAG_CULL_NON_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH |
                                                RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES,
                                            RAY_FLAG_CULL_FRONT_FACING_TRIANGLES}));
    const auto inits = log.of(TraceEvent::Kind::QueryInit);
    ASSERT_EQ(inits.size(), 2u);
    EXPECT_EQ(inits[0].rayFlags, uint32_t(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES));
    EXPECT_EQ(inits[0].effectiveFlags, flags[0]);
}

TEST(RayQuery, RQ_27_CommittedRayTIsTMaxWhileNothingIsCommittedWithANote) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_NONE});
    bool commit = false;
    std::vector<float> ts;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        for (float tMax : {42.5f, kInf}) {
            q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay(tMax));
            while (q.Proceed())
                if (commit) q.CommitNonOpaqueTriangleHit();
            ts.push_back(q.CommittedRayT());
        }
    };
    const DispatchResult nothing = runQuery(r);
    EXPECT_EQ(ts, (std::vector<float>{42.5f, kInf}));
    EXPECT_TRUE(nothing.diagnostics.warnings().empty());
    const auto note = nothing.diagnostics.find("RQ-27");
    ASSERT_TRUE(note);
    EXPECT_EQ(note->severity, Severity::Note);
    EXPECT_TRUE(contains(note->message, "SPIR-V")) << note->format();
    ts.clear();
    commit = true;
    const DispatchResult committed = runQuery(r);
    EXPECT_EQ(ts, (std::vector<float>{5.0f, 5.0f}));
    EXPECT_TRUE(committed.diagnostics.empty()) << "with a committed hit CommittedRayT is defined everywhere";
}

TEST(RayQuery, RQ_28_CandidateGettersFollowTheCandidateType) {
    Rig r;
    // Instance 0 (InstanceID 3, contribution 2): a non-opaque triangle at t = 3 (geometry 0) and the unit box entered
    // at 4 (instance 1, rotated, InstanceID 8, contribution 6).
    const Matrix3x4 rotation = Matrix3x4::rotation(vec3(0, 0, 1), 0.5f);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(-2), GEOMETRY_FLAG_NONE)}), 2, Matrix3x4::identity(), 0xFF,
                                INSTANCE_FLAG_NONE, 3),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}), 6, rotation, 0xFF, INSTANCE_FLAG_NONE, 8)});
    declare(r, "RG", {RAY_FLAG_NONE});
    int triangleGetter = -1;  // which triangle-only getter to call on the procedural candidate
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        uint32_t n = 0;
        while (q.Proceed()) {
            const bool procedural = q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE;
            EXPECT_EQ(procedural, n++ == 1);
            // Valid for both types.
            EXPECT_EQ(q.CandidateInstanceIndex(), procedural ? 1u : 0u);
            EXPECT_EQ(q.CandidateInstanceID(), procedural ? 8u : 3u);
            EXPECT_EQ(q.CandidateInstanceContributionToHitGroupIndex(), procedural ? 6u : 2u);
            EXPECT_EQ(q.CandidateGeometryIndex(), 0u);
            EXPECT_EQ(q.CandidatePrimitiveIndex(), 0u);
            const Matrix3x4 o2w = q.CandidateObjectToWorld3x4(), w2o = q.CandidateWorldToObject3x4();
            EXPECT_EQ(o2w, procedural ? rotation : Matrix3x4::identity());
            const auto o2w43 = q.CandidateObjectToWorld4x3(), w2o43 = q.CandidateWorldToObject4x3();
            for (int row = 0; row < 3; ++row)
                for (int col = 0; col < 4; ++col) {
                    EXPECT_EQ(o2w43[col][row], o2w.m[row][col]);
                    EXPECT_EQ(w2o43[col][row], w2o.m[row][col]);
                }
            const vec3 origin = q.CandidateObjectRayOrigin(), direction = q.CandidateObjectRayDirection();
            const vec3 back = o2w.transformPoint(origin), backDirection = o2w.transformVector(direction);
            EXPECT_NEAR(back.x, 0.0f, 1e-5f);
            EXPECT_NEAR(back.y, 0.2f, 1e-5f);
            EXPECT_NEAR(back.z, -5.0f, 1e-5f);
            EXPECT_NEAR(backDirection.z, 1.0f, 1e-5f);
            const vec3 there = w2o.transformPoint(vec3(0.0f, 0.2f, -5.0f));
            EXPECT_NEAR(there.x, origin.x, 1e-5f);
            EXPECT_NEAR(there.y, origin.y, 1e-5f);
            if (!procedural) {
                EXPECT_EQ(q.CandidateTriangleRayT(), 3.0f);
                EXPECT_TRUE(q.CandidateTriangleFrontFace());
                EXPECT_NEAR(q.CandidateTriangleBarycentrics().x, 0.6f, 1e-6f);
            } else if (triangleGetter == 0) {
                EXPECT_EQ(q.CandidateTriangleRayT(), 0.0f);
            } else if (triangleGetter == 1) {
                EXPECT_EQ(q.CandidateTriangleBarycentrics(), vec2(0.0f));
            } else if (triangleGetter == 2) {
                EXPECT_FALSE(q.CandidateTriangleFrontFace());
            }
        }
        EXPECT_EQ(n, 2u);
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    for (int getter = 0; getter < 3; ++getter) {
        triangleGetter = getter;
        const Diagnostic d = expectDxrError("RQ-28", [&] { runQuery(r); });
        EXPECT_TRUE(contains(d.message, "CANDIDATE_PROCEDURAL_PRIMITIVE")) << d.format();
        const DispatchResult cont = runQuery(r, continueMode());
        EXPECT_EQ(countOf(cont.diagnostics.errors(), "RQ-28"), 1u);
    }
}

TEST(RayQuery, RQ_29_CommittedGettersFollowTheCommittedStatus) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}), 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_NONE, 4),
              Harness::instance(r.h.blas({r.h.triangles(triAt(1), GEOMETRY_FLAG_NONE)}), 0, Matrix3x4::identity(), 0xFF,
                                INSTANCE_FLAG_NONE, 6)});  // t = 6
    declare(r, "RG", {RAY_FLAG_NONE});
    uint32_t wanted = COMMITTED_NOTHING;
    bool beforeProceed = false;
    struct Read {
        uint32_t index = 99, id = 99, geometry = 99, primitive = 99, contribution = 99;
        vec2 bary{-1.0f};
        bool front = true;
        Matrix3x4 o2w = Matrix3x4::identity();
    } read;
    auto readAll = [&](RayQueryObject& q) {
        read.index = q.CommittedInstanceIndex();
        read.id = q.CommittedInstanceID();
        read.geometry = q.CommittedGeometryIndex();
        read.primitive = q.CommittedPrimitiveIndex();
        read.contribution = q.CommittedInstanceContributionToHitGroupIndex();
        read.o2w = q.CommittedObjectToWorld3x4();
        q.CommittedObjectToWorld4x3();
        q.CommittedWorldToObject3x4();
        q.CommittedWorldToObject4x3();
        q.CommittedObjectRayOrigin();
        q.CommittedObjectRayDirection();
        read.bary = q.CommittedTriangleBarycentrics();
        read.front = q.CommittedTriangleFrontFace();
    };
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        if (beforeProceed) readAll(q);
        while (q.Proceed()) {
            if (wanted == COMMITTED_PROCEDURAL_PRIMITIVE_HIT && q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE)
                q.CommitProceduralPrimitiveHit(4.0f);
            if (wanted == COMMITTED_TRIANGLE_HIT && q.CandidateType() == CANDIDATE_NON_OPAQUE_TRIANGLE)
                q.CommitNonOpaqueTriangleHit();
        }
        EXPECT_EQ(q.CommittedStatus(), wanted);
        readAll(q);
    };
    // COMMITTED_NOTHING: no node getter, no triangle getter (13 calls), all zeros.
    DispatchResult res = runQuery(r, continueMode());
    EXPECT_EQ(countOf(res.diagnostics.errors(), "RQ-29"), 13u);
    EXPECT_EQ(read.id, 0u);
    EXPECT_EQ(read.o2w, Matrix3x4{});
    EXPECT_FALSE(read.front);
    expectDxrError("RQ-29", [&] { runQuery(r); });
    // COMMITTED_PROCEDURAL_PRIMITIVE_HIT: the node getters, not the triangle ones.
    wanted = COMMITTED_PROCEDURAL_PRIMITIVE_HIT;
    res = runQuery(r, continueMode());
    EXPECT_EQ(countOf(res.diagnostics.errors(), "RQ-29"), 2u);
    EXPECT_EQ(read.index, 0u);
    EXPECT_EQ(read.id, 4u);
    EXPECT_EQ(read.o2w, Matrix3x4::identity());
    // COMMITTED_TRIANGLE_HIT: every committed getter.
    wanted = COMMITTED_TRIANGLE_HIT;
    res = runQuery(r);
    EXPECT_TRUE(res.diagnostics.empty());
    EXPECT_EQ(read.index, 1u);
    EXPECT_EQ(read.id, 6u);
    EXPECT_TRUE(read.front);
    EXPECT_NEAR(read.bary.y, 0.2f, 1e-6f);
    // Before the first Proceed the third table does not apply yet.
    beforeProceed = true;
    const Diagnostic d = expectDxrError("RQ-29", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "after Proceed")) << d.format();
}

TEST(RayQuery, RQ_30_BarycentricsWeightVertex1AndVertex2) {
    // A tilted triangle; the ray from (0, 1, -5) along +z meets it at P = (0, 1, 2), t = 7, where
    // P = v0 + 0.25 (v1 - v0) + 0.5 (v2 - v0).
    const vec3 v0(-2, -1, 1), v1(2, -1, 3), v2(0, 3, 2);
    const float a0 = 10.0f, a1 = 30.0f, a2 = 70.0f;  // a per-vertex attribute: 10 + 0.25*20 + 0.5*60 = 45
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles({v0, v1, v2}, GEOMETRY_FLAG_NONE)})),
              Harness::instance(r.h.blas({r.h.triangles({v0, v1, v2})}), 0, Matrix3x4::translation({10, 0, 0}))});
    declare(r, "RG", {RAY_FLAG_NONE});
    std::vector<vec2> bary;
    std::vector<float> ts;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, RayDesc{vec3(0, 1, -5), 0.0f, vec3(0, 0, 1), 100.0f});
        ASSERT_TRUE(q.Proceed());
        bary.push_back(q.CandidateTriangleBarycentrics());
        ts.push_back(q.CandidateTriangleRayT());
        q.CommitNonOpaqueTriangleHit();
        EXPECT_FALSE(q.Proceed());
        bary.push_back(q.CommittedTriangleBarycentrics());
        // The opaque copy (instance 1, translated by x + 10): committed by the system inside Proceed.
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, RayDesc{vec3(10, 1, -5), 0.0f, vec3(0, 0, 1), 100.0f});
        EXPECT_FALSE(q.Proceed());
        bary.push_back(q.CommittedTriangleBarycentrics());
        ts.push_back(q.CommittedRayT());
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    ASSERT_EQ(bary.size(), 3u);
    for (const vec2& b : bary) {
        EXPECT_NEAR(b.x, 0.25f, 1e-6f);
        EXPECT_NEAR(b.y, 0.5f, 1e-6f);
        EXPECT_NEAR(a0 + b.x * (a1 - a0) + b.y * (a2 - a0), 45.0f, 1e-4f);
        const vec3 p = v0 + b.x * (v1 - v0) + b.y * (v2 - v0);
        EXPECT_NEAR(p.x, 0.0f, 1e-5f);
        EXPECT_NEAR(p.y, 1.0f, 1e-5f);
        EXPECT_NEAR(p.z, 2.0f, 1e-5f);
    }
    for (float t : ts) EXPECT_NEAR(t, 7.0f, 1e-5f);
}

TEST(RayQuery, RQ_31_InstanceIndexInstanceIDAndAContributionWithoutEffect) {
    const std::vector<uint32_t> ids = {0xABCDEF, 7, 0};
    struct Hit {
        uint32_t candidateIndex = 99, candidateID = 99, candidateContribution = 99;
        uint32_t committedIndex = 99, committedID = 99, committedContribution = 99;
        float t = -1.0f;
    };
    auto run = [&](const std::vector<uint32_t>& contributions) {
        Rig r;
        const GpuVirtualAddress tri = r.h.blas({r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE)});
        std::vector<InstanceDesc> instances;
        for (uint32_t i = 0; i < 3; ++i)
            instances.push_back(Harness::instance(tri, contributions[i], Matrix3x4::translation({10.0f * i, 0, 0}), 0xFF,
                                                  INSTANCE_FLAG_NONE, ids[i]));
        r.h.tlas(instances);
        declare(r, "RG", {RAY_FLAG_NONE});
        std::vector<Hit> hits(3);
        r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
            for (uint32_t i = 0; i < 3; ++i) {
                RayQuery<RAY_FLAG_NONE> q(ctx);
                RayDesc ray = zRay();
                ray.Origin.x = 10.0f * i;
                q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
                Hit& h = hits[i];
                while (q.Proceed()) {
                    h.candidateIndex = q.CandidateInstanceIndex();
                    h.candidateID = q.CandidateInstanceID();
                    h.candidateContribution = q.CandidateInstanceContributionToHitGroupIndex();
                    q.CommitNonOpaqueTriangleHit();
                }
                h.committedIndex = q.CommittedInstanceIndex();
                h.committedID = q.CommittedInstanceID();
                h.committedContribution = q.CommittedInstanceContributionToHitGroupIndex();
                h.t = q.CommittedRayT();
            }
        };
        EXPECT_TRUE(runQuery(r).diagnostics.empty()) << "no hit-group table is bound, whatever the contributions";
        return hits;
    };
    const std::vector<uint32_t> contributions = {3, 0xFFFFFF, 15};
    const auto hits = run(contributions);
    for (uint32_t i = 0; i < 3; ++i) {
        EXPECT_EQ(hits[i].candidateIndex, i);
        EXPECT_EQ(hits[i].committedIndex, i);
        EXPECT_EQ(hits[i].candidateID, ids[i]);
        EXPECT_EQ(hits[i].committedID, ids[i]);
        EXPECT_EQ(hits[i].candidateContribution, contributions[i]);
        EXPECT_EQ(hits[i].committedContribution, contributions[i]);
        EXPECT_EQ(hits[i].t, 5.0f);
    }
    // Other contributions change nothing but the contribution getters.
    const auto other = run({0, 0, 0});
    for (uint32_t i = 0; i < 3; ++i) {
        EXPECT_EQ(other[i].committedIndex, hits[i].committedIndex);
        EXPECT_EQ(other[i].committedID, hits[i].committedID);
        EXPECT_EQ(other[i].t, hits[i].t);
        EXPECT_EQ(other[i].committedContribution, 0u);
    }
}

TEST(RayQuery, RQ_32_TriangleObjectPositionsAreOutOfScopeAndStop) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    declare(r, "RG", {RAY_FLAG_NONE});
    bool committed = false;
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        ASSERT_TRUE(q.Proceed());
        if (!committed) {
            q.CandidateTriangleObjectPositions();
        } else {
            q.CommitNonOpaqueTriangleHit();
            q.CommittedTriangleObjectPositions();
        }
    };
    Diagnostic d = expectDxrError("RQ-32", [&] { runQuery(r); });
    EXPECT_TRUE(contains(d.message, "CandidateTriangleObjectPositions")) << d.format();
    committed = true;
    d = expectDxrError("RQ-32", [&] { runQuery(r, continueMode()); });
    EXPECT_TRUE(contains(d.message, "CommittedTriangleObjectPositions")) << d.format();
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
}

// refray's acceleration structures hold no opacity micromaps, so of RQ-33 only the template rule and the flag's
// harmlessness are observable: an OMM-free acceleration structure behaves the same with or without it.
TEST(RayQuery, RQ_33_ForceOmm2StateNeedsAllowOpacityMicromapsAndChangesNothingWithoutOmms) {
    EXPECT_TRUE(startsWith(rayQueryTemplateError(RAY_FLAG_FORCE_OMM_2_STATE, RAYQUERY_FLAG_NONE), "RQ-33"));
    EXPECT_TRUE(startsWith(rayQueryTemplateError(RAY_FLAG_FORCE_OMM_2_STATE, RAYQUERY_FLAG_ALLOW_CLUSTERED_GEOMETRY), "RQ-33"));
    EXPECT_EQ(rayQueryTemplateError(RAY_FLAG_FORCE_OMM_2_STATE, RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS), nullptr);
    Rig r;
    // Non-opaque at t = 3, opaque at t = 5.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(-2), GEOMETRY_FLAG_NONE), r.h.triangles(triAt(0))}))});
    declare(r, "RG", {RAY_FLAG_FORCE_OMM_2_STATE, RAY_FLAG_NONE});
    std::vector<std::string> steps;
    uint32_t flags = 0;
    auto walk = [&](RayQueryObject& q, GpuVirtualAddress scene) {
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        std::string s;
        while (q.Proceed()) s += std::to_string(int(q.CandidateTriangleRayT())) + " ";
        s += std::to_string(q.CommittedStatus()) + "@" + std::to_string(int(q.CommittedRayT()));
        steps.push_back(s);
    };
    r.rg = [&, scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_FORCE_OMM_2_STATE, RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS> omm(ctx);
        walk(omm, scene);
        flags = omm.RayFlags();
        RayQuery<RAY_FLAG_NONE> plain(ctx);
        walk(plain, scene);
    };
    EXPECT_TRUE(runQuery(r).diagnostics.empty());
    EXPECT_EQ(steps, (std::vector<std::string>{"3 1@5", "3 1@5"}));
    EXPECT_EQ(flags, uint32_t(RAY_FLAG_FORCE_OMM_2_STATE)) << "RayFlags() includes the template flags (RQ-26)";
}

// ---------------------------------------------------------------------------------------
// What `refray explain` sees of a query: its events.

TEST(RayQuery, RQ_14_TheEventsOfAQueryTellItsLife) {
    Rig r;
    // Instance 0: non-opaque at t = 3 (primitive 0) and t = 7 (primitive 1); instance 1: opaque at t = 5.
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(trisAt({-2, 2}), GEOMETRY_FLAG_NONE)})),
              Harness::instance(r.h.blas({r.h.triangles(triAt(0))}), 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_NONE, 12)});
    declare(r, "RG", {RAY_FLAG_NONE});
    r.rg = [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0x0F, zRay());
        while (q.Proceed()) {  // t = 3: not committed
        }
        RayQuery<RAY_FLAG_NONE> second(ctx);
        second.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        if (second.Proceed()) second.CommitNonOpaqueTriangleHit();
        second.Abort();
    };
    EventLog log;
    runQuery(r, observed(log));
    std::vector<std::string> lines;
    for (const auto& e : log.entries) {
        if (e.kind == TraceEvent::Kind::ShaderCall || e.kind == TraceEvent::Kind::RecordLookup) continue;
        std::string s = "q";
        s += std::to_string(e.queryId) + " ";
        switch (e.kind) {
            case TraceEvent::Kind::QueryInit: s += "init mask " + std::to_string(e.mask); break;
            case TraceEvent::Kind::Candidate: s += "candidate i" + std::to_string(e.instanceIndex) + " p" + std::to_string(e.primitiveIndex); break;
            case TraceEvent::Kind::Skipped: s += "skipped p" + std::to_string(e.primitiveIndex); break;
            case TraceEvent::Kind::QueryProceed: s += std::string("proceed ") + (e.accepted ? "TRUE" : "FALSE"); break;
            case TraceEvent::Kind::QueryCommit: s += "commit i" + std::to_string(e.instanceIndex) + " id" + std::to_string(e.instanceID); break;
            case TraceEvent::Kind::QueryAbort: s += "abort"; break;
            default: s += "other"; break;
        }
        s += " t" + std::to_string(int(e.t));
        lines.push_back(s);
        EXPECT_EQ(e.stage, ShaderStage::RayGeneration);
        EXPECT_EQ(e.exportName, "RG");
    }
    const std::vector<std::string> expected = {
        "q1 init mask 15 t0",
        "q1 candidate i0 p0 t3",
        "q1 proceed TRUE t3",
        "q1 candidate i1 p0 t5",
        "q1 commit i1 id12 t5",  // RQ-14: by the system, inside Proceed
        "q1 candidate i0 p1 t7",
        "q1 skipped p1 t7",
        "q1 proceed FALSE t5",
        "q2 init mask 255 t0",
        "q2 candidate i0 p0 t3",
        "q2 proceed TRUE t3",
        "q2 commit i0 id0 t3",  // by the shader
        "q2 abort t3",
    };
    EXPECT_EQ(lines, expected);
    const auto commits = log.of(TraceEvent::Kind::QueryCommit);
    ASSERT_EQ(commits.size(), 2u);
    EXPECT_TRUE(contains(commits[0].note, "inside Proceed")) << commits[0].note;
    EXPECT_TRUE(contains(commits[1].note, "CommitNonOpaqueTriangleHit")) << commits[1].note;
}

// ---------------------------------------------------------------------------------------
// The compute dispatch (Device::dispatch): where most engines trace inline.

TEST(ComputeDispatch, RQ_1_ThreadIdsFollowNumThreadsAndTheGroupGrid) {
    Rig r;
    const uvec3 numThreads(4, 2, 3), groups(3, 2, 2);
    const uvec3 grid = numThreads * groups;
    struct Ids {
        uvec3 dispatchThread{~0u}, group{~0u}, groupThread{~0u};
        uint32_t groupIndex = ~0u;
        uint32_t runs = 0;
    };
    std::vector<Ids> ids(size_t(grid.x) * grid.y * grid.z);
    r.h.library->addCompute("CS", numThreads, [&](ShaderContext& ctx) {
        const uvec3 t = ctx.DispatchThreadID();
        Ids& i = ids[(size_t(t.z) * grid.y + t.y) * grid.x + t.x];
        i.dispatchThread = t;
        i.group = ctx.GroupID();
        i.groupThread = ctx.GroupThreadID();
        i.groupIndex = ctx.GroupIndex();
        i.runs++;
    });
    r.build();
    DispatchOptions o;
    o.tileSize = 5;  // tiles that cut across thread groups
    const DispatchResult res = r.h.device.dispatch(DispatchDesc{"CS", groups.x, groups.y, groups.z}, r.so, nullptr, o);
    EXPECT_TRUE(res.diagnostics.empty());
    for (uint32_t z = 0; z < grid.z; ++z)
        for (uint32_t y = 0; y < grid.y; ++y)
            for (uint32_t x = 0; x < grid.x; ++x) {
                const Ids& i = ids[(size_t(z) * grid.y + y) * grid.x + x];
                const uvec3 t(x, y, z);
                ASSERT_EQ(i.runs, 1u);
                EXPECT_EQ(i.dispatchThread, t);
                EXPECT_EQ(i.group, t / numThreads);
                EXPECT_EQ(i.groupThread, t % numThreads);
                EXPECT_EQ(i.group * numThreads + i.groupThread, t);
                const uvec3 g = i.groupThread;
                EXPECT_EQ(i.groupIndex, g.z * numThreads.x * numThreads.y + g.y * numThreads.x + g.x);
            }
    ASSERT_EQ(res.stats.invocationsPerExport.size(), 1u);
    EXPECT_EQ(res.stats.invocationsPerExport[0].stage, ShaderStage::Compute);
    EXPECT_EQ(res.stats.invocationsPerExport[0].count, ids.size());
    // No thread group runs nothing.
    std::fill(ids.begin(), ids.end(), Ids{});
    r.h.device.dispatch(DispatchDesc{"CS", 0, 1, 1}, r.so, nullptr);
    EXPECT_TRUE(std::all_of(ids.begin(), ids.end(), [](const Ids& i) { return i.runs == 0; }));
}

TEST(ComputeDispatch, SV_1_RayTracingSystemValuesAreRefusedInCompute) {
    Rig r;
    int which = 0;
    r.h.library->addCompute("CS", uvec3(2, 1, 1), [&](ShaderContext& ctx) {
        if (ctx.DispatchThreadID() != uvec3(1, 0, 0)) return;
        if (which == 0) ctx.DispatchRaysIndex();
        if (which == 1) ctx.DispatchRaysDimensions();
        if (which == 2) ctx.WorldRayOrigin();
    });
    r.build();
    for (which = 0; which < 3; ++which) {
        const Diagnostic d = expectDxrError("SV-1", [&] { r.h.device.dispatch(DispatchDesc{"CS"}, r.so, nullptr); });
        EXPECT_TRUE(contains(d.message, "compute")) << d.format();
        ASSERT_TRUE(d.site);
        EXPECT_EQ(d.site->stage, ShaderStage::Compute);
        EXPECT_EQ(d.site->launchIndex, uvec3(1, 0, 0));
    }
    // And the compute ids outside compute.
    r.rg = [](ShaderContext& ctx) { ctx.DispatchThreadID(); };
    const Diagnostic d = expectDxrError("SV-1", [&] { r.run({}); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
}

// A compute shader written for waves whose lanes make their TraceRayInline as wave calls (traceRayInlineCall, through
// ShaderWave::CallsInLoop): the rays of a wave's queries gather their candidates in Embree packets, and each lane must
// find what it finds alone, at every width: the same candidates in the same order, the same committed hit, the same
// statistics and diagnostics. Thread 5's ray has a NaN direction (RQ-11) and thread 11's a TMin above its TMax: their
// queries find nothing; under OnError::Stop the dispatch stops with thread 5's error, and the other lanes of its wave
// still finish.
TEST(ComputeWave, RQ_13_QueriesTracedTogetherFindWhatEachFindsAlone) {
    Rig r;
    oneInstance(r, r.h.triangles(trisAt({0.0f, 2.0f, 4.0f, 7.0f}), GEOMETRY_FLAG_NONE));  // non-opaque: candidates
    const uvec2 grid(7, 5);
    struct Result {
        std::vector<float> candidates;  // their t, in the order Proceed hands them out
        uint32_t status = 0;
        float t = 0.0f;
        bool done = false;
    };
    std::vector<Result> results;
    r.h.library->addWaveCompute("CSW", uvec3(1u), [&, scene = r.h.scene](ComputeWave& wave) {
        std::array<std::optional<RayQueryObject>, kMaxWaveWidth> queries;
        std::array<RayQueryTraceCall, kMaxWaveWidth> traces;
        std::array<bool, kMaxWaveWidth> traced{};
        const auto number = [&grid](ShaderContext& ctx) {
            return ctx.DispatchThreadID().y * grid.x + ctx.DispatchThreadID().x;
        };
        wave.forEachLane([&](int i, ShaderContext& ctx) {
            const uint32_t n = number(ctx);
            RayDesc ray = zRay();
            ray.Origin.x = -0.6f + 0.08f * float(n % 13);  // some rays pass beside the triangles
            ray.TMax = 6.0f + float(n % 4) * 2.0f;         // and some end before the far ones
            if (n == 5) ray.Direction.y = kNaN;
            if (n == 11) ray.TMin = 100.0f;
            queries[size_t(i)].emplace(ctx, RAY_FLAG_NONE, RAYQUERY_FLAG_NONE);
            traces[size_t(i)] = RayQueryTraceCall{&*queries[size_t(i)], scene, RAY_FLAG_NONE, 0xFF, ray, nullptr};
        });
        wave.CallsInLoop(wave.active(), [&](int i, ShaderContext& ctx, WaveCall& call) {
            if (!traced[size_t(i)]) {
                traced[size_t(i)] = true;
                call = traceRayInlineCall(traces[size_t(i)]);
                return true;
            }
            if (traces[size_t(i)].failure) std::rethrow_exception(traces[size_t(i)].failure);
            RayQueryObject& q = *queries[size_t(i)];
            Result& res = results[number(ctx)];
            while (q.Proceed()) {
                res.candidates.push_back(q.CandidateTriangleRayT());
                if (q.CandidateTriangleRayT() > 6.5f) q.CommitNonOpaqueTriangleHit();  // a chosen hit, not the nearest
            }
            res.status = q.CommittedStatus();
            res.t = q.CommittedRayT();
            res.done = true;
            return false;
        });
    });
    declare(r, "CSW", {RAY_FLAG_NONE});
    r.build();
    const auto run = [&](uint32_t width, OnError onError) {
        results.assign(size_t(grid.x) * grid.y, Result{});
        DispatchOptions o;
        o.waveWidth = width;
        o.tileSize = 64;  // one tile: its waves hold `width` lanes
        o.onError = onError;
        return r.h.device.dispatch(DispatchDesc{"CSW", grid.x, grid.y, 1}, r.so, nullptr, o);
    };
    const DispatchResult alone = run(1, OnError::Continue);
    const std::vector<Result> aloneResults = results;
    EXPECT_TRUE(hasRule(alone.diagnostics.diagnostics(), "RQ-11")) << "the refused rays are reported";
    size_t hits = 0, found = 0;
    for (const Result& res : aloneResults) {
        hits += res.status == COMMITTED_TRIANGLE_HIT;
        found += res.candidates.size();
    }
    EXPECT_GT(hits, 0u);
    EXPECT_GT(found, hits);  // rays with several candidates
    for (const uint32_t width : {3u, 16u, 32u}) {
        const DispatchResult waved = run(width, OnError::Continue);
        for (size_t n = 0; n < results.size(); ++n) {
            EXPECT_TRUE(results[n].done) << "width " << width << ", thread " << n;
            EXPECT_EQ(results[n].candidates, aloneResults[n].candidates) << "width " << width << ", thread " << n;
            EXPECT_EQ(results[n].status, aloneResults[n].status) << "width " << width << ", thread " << n;
            EXPECT_EQ(results[n].t, aloneResults[n].t) << "width " << width << ", thread " << n;
        }
        std::vector<std::string> a, b;
        for (const Diagnostic& d : alone.diagnostics.diagnostics()) a.push_back(d.format());
        for (const Diagnostic& d : waved.diagnostics.diagnostics()) b.push_back(d.format());
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
        EXPECT_EQ(b, a) << "width " << width;
        EXPECT_EQ(waved.stats.rayQueries, alone.stats.rayQueries) << "width " << width;
        EXPECT_EQ(waved.stats.candidates, alone.stats.candidates) << "width " << width;
        EXPECT_EQ(waved.stats.queryCandidates, alone.stats.queryCandidates) << "width " << width;
    }
    // OnError::Stop: thread 5's RQ-11 stops the dispatch; the lanes of its wave that trace well still finish.
    const Diagnostic d = expectDxrError("RQ-11", [&] { run(16, OnError::Stop); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(5, 0, 0));
    EXPECT_EQ(d.site->stage, ShaderStage::Compute);
    EXPECT_FALSE(results[5].done);
    EXPECT_TRUE(results[4].done);
    EXPECT_EQ(results[4].candidates, aloneResults[4].candidates);
}

TEST(ComputeDispatch, RAY_2_TraceRayAndCallShaderAreRefusedInCompute) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0)));
    bool call = false;
    r.h.library->addCompute("CS", uvec3(1u), [&, scene = r.h.scene](ShaderContext& ctx) {
        if (call) {
            CallParams c;
            ctx.CallShader(0, c);
        } else {
            Probe p;
            ctx.TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, zRay(), p);
        }
    });
    r.build();
    Diagnostic d = expectDxrError("RAY-2", [&] { r.h.device.dispatch(DispatchDesc{"CS"}, r.so, nullptr); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->stage, ShaderStage::Compute);
    call = true;
    d = expectDxrError("CALL-2", [&] { r.h.device.dispatch(DispatchDesc{"CS"}, r.so, nullptr); });
}

TEST(ComputeDispatch, RQ_1_UnknownExportsAndTooManyGroupsAreRefused) {
    Rig r;
    uint32_t runs = 0;
    r.h.library->addCompute("CS", uvec3(1u), [&](ShaderContext&) { ++runs; });
    r.build();
    Diagnostic d = expectDxrError("RQ-1", [&] { r.h.device.dispatch(DispatchDesc{"CS_missing"}, r.so, nullptr); });
    EXPECT_EQ(valueOf(d, "ComputeShader"), "CS_missing") << d.format();
    EXPECT_EQ(valueOf(d, "compute exports"), "CS") << d.format();
    d = expectDxrError("RQ-1", [&] { r.h.device.dispatch(DispatchDesc{"RG"}, r.so, nullptr); });  // not a compute shader
    for (int axis = 0; axis < 3; ++axis) {
        DispatchDesc desc{"CS"};
        (axis == 0 ? desc.ThreadGroupCountX : axis == 1 ? desc.ThreadGroupCountY : desc.ThreadGroupCountZ) = 65536;
        d = expectDxrError("RQ-1", [&] { r.h.device.dispatch(desc, r.so, nullptr); });
        EXPECT_TRUE(contains(d.message, "65535")) << d.format();
    }
    EXPECT_EQ(runs, 0u);
    DispatchOptions one;
    one.threads = 1;
    r.h.device.dispatch(DispatchDesc{"CS", 65535, 1, 1}, r.so, nullptr, one);
    EXPECT_EQ(runs, 65535u);
    expectDxrError("RGS-3", [&] { r.h.device.dispatch(DispatchDesc{"CS"}, nullptr, nullptr); });
}

TEST(ComputeDispatch, RQ_1_AComputeShaderTracesTheAccelerationStructureOfItsGlobalRootArguments) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0)), INSTANCE_FLAG_NONE, 23);
    // RaytracingAccelerationStructure Scene : register(t0); cbuffer Params : register(b0) { float tMax; }
    const RootSignaturePtr signature = RootSignature::create(
        {"ComputeGlobal", {RootParameter::srv(0), RootParameter::constants(1, 0)}, ROOT_SIGNATURE_FLAG_NONE});
    GlobalRootArguments global(signature);
    global.setDescriptor(0, r.h.scene);
    global.setConstants(1, 4.0f);
    std::vector<uint32_t> ids(4, 99);
    r.h.library->addCompute("CS", uvec3(2, 1, 1), [&](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        const float tMax = ctx.globalRootConstants<float>(1);
        q.TraceRayInline(ctx.globalRootDescriptor(0), RAY_FLAG_NONE, 0xFF, zRay(tMax + float(ctx.DispatchThreadID().x)));
        while (q.Proceed()) {
        }
        ids[ctx.DispatchThreadID().x] = q.CommittedStatus() ? q.CommittedInstanceID() : 0;
    });
    declare(r, "CS", {RAY_FLAG_NONE});
    r.build();
    EXPECT_TRUE(r.h.device.dispatch(DispatchDesc{"CS", 2, 1, 1}, r.so, &global).diagnostics.errors().empty());
    EXPECT_EQ(ids, (std::vector<uint32_t>{0, 0, 23, 23}));  // tMax 4, 5 (open: no hit), 6, 7
    // Without the arguments the read stops with PIPE-6.
    expectDxrError("PIPE-6", [&] { r.h.device.dispatch(DispatchDesc{"CS", 2, 1, 1}, r.so, nullptr); });
}

TEST(ComputeDispatch, RQ_19_DiagnosticsNameTheThreadByItsDispatchThreadID) {
    Rig r;
    oneInstance(r, r.h.triangles(triAt(0), GEOMETRY_FLAG_NONE));
    r.h.library->addCompute("CS", uvec3(4, 4, 1), [scene = r.h.scene](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, zRay());
        if (ctx.DispatchThreadID().x >= 5 && ctx.DispatchThreadID().y >= 6) q.CommittedInstanceID();  // nothing committed
    });
    declare(r, "CS", {RAY_FLAG_NONE});
    r.build();
    const Diagnostic d = expectDxrError("RQ-29", [&] { r.h.device.dispatch(DispatchDesc{"CS", 2, 2, 1}, r.so, nullptr); });
    ASSERT_TRUE(d.site);
    EXPECT_EQ(d.site->launchIndex, uvec3(5, 6, 0)) << "the lowest thread in launch order";
    EXPECT_EQ(d.site->stage, ShaderStage::Compute);
    EXPECT_EQ(d.site->exportName, "CS");
}

TEST(ComputeDispatch, RQ_13_QueriesGiveTheSameResultsOnAnyNumberOfThreads) {
    Rig r;
    // Rows of non-opaque triangles and boxes over a 24 x 16 grid of rays.
    std::vector<vec3> v;
    for (int i = 0; i < 12; ++i)
        for (const vec3& p : triAt(float(i % 5) - 2.0f)) v.push_back(p * vec3(3.0f, 3.0f, 1.0f) + vec3(float(i % 4) - 1.5f, float(i / 4) - 1.0f, 0.0f));
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NONE)}), 0, Matrix3x4::identity(), 0xFF,
                                INSTANCE_FLAG_NONE, 1),
              Harness::instance(r.h.blas({r.h.aabbs({unitBox(), {-2, 0, 1, -1, 1, 2}})}, GEOMETRY_FLAG_NONE), 0,
                                Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_NONE, 2)});
    const uvec3 grid(24, 16, 1);
    struct Out {
        uint32_t status = 0, id = 0, primitive = 0, proceeds = 0;
        float t = 0.0f;
        bool operator==(const Out&) const = default;
    };
    std::vector<Out> out(size_t(grid.x) * grid.y);
    r.h.library->addCompute("CS", uvec3(8, 8, 1), [&, scene = r.h.scene](ShaderContext& ctx) {
        const uvec3 id = ctx.DispatchThreadID();
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF,
                         RayDesc{vec3(float(id.x) / 3.0f - 4.0f, float(id.y) / 2.0f - 4.0f, -5.0f), 0.0f, vec3(0.05f, 0, 1), 50.0f});
        Out& o = out[size_t(id.y) * grid.x + id.x];
        o = Out{};
        while (q.Proceed()) {
            ++o.proceeds;
            if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE) {
                if (q.CandidatePrimitiveIndex() == 0) q.CommitProceduralPrimitiveHit(std::max(q.RayTMin(), std::min(q.CommittedRayT(), 4.5f)));
            } else if ((q.CandidatePrimitiveIndex() + id.x) % 3) {
                q.CommitNonOpaqueTriangleHit();
            }
        }
        o.status = q.CommittedStatus();
        o.t = q.CommittedRayT();
        o.id = o.status ? q.CommittedInstanceID() : 0;
        o.primitive = o.status ? q.CommittedPrimitiveIndex() : 0;
    });
    declare(r, "CS", {RAY_FLAG_NONE});
    r.build();
    for (TraversalOrder order : {TraversalOrder::Ordered, TraversalOrder::Adversarial}) {
        std::vector<Out> reference;
        for (uint32_t threads : {1u, 2u, 0u}) {
            DispatchOptions o;
            o.threads = threads;
            o.order = order;
            o.adversarialSeed = 5;
            o.tileSize = 3;
            const DispatchResult res = r.h.device.dispatch(DispatchDesc{"CS", 3, 2, 1}, r.so, nullptr, o);
            EXPECT_TRUE(res.diagnostics.errors().empty());
            if (reference.empty()) reference = out;
            else EXPECT_TRUE(out == reference) << threads << " threads";
        }
        const size_t hits = size_t(std::count_if(reference.begin(), reference.end(), [](const Out& o) { return o.status != 0; }));
        EXPECT_GT(hits, 10u);
        EXPECT_LT(hits, reference.size());
    }
}

}  // namespace
}  // namespace refray::test

namespace refray::test {
namespace {

using namespace dispatch_rig;

// IS-10 with queries: an intersection shader registered with ReportHitEnd::Return promises its ReportHit is its last
// action; a RayQuery it made before that ReportHit may not be used after a ReportHit that ended the search.
TEST(RayQuery, IS_10_AQueryUsedAfterAnEndingReportHitBreaksTheReturnPromise) {
    Rig r;
    const GpuVirtualAddress target = r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(triAt(10))}))});
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});  // entered at t = 4
    r.h.library->declareRayQueries("IS_R", {RAY_FLAG_NONE});
    bool usedAfter = false;
    r.is = [&, target](ShaderContext& ctx) {
        RayQuery<RAY_FLAG_NONE> q(ctx);
        q.TraceRayInline(target, RAY_FLAG_NONE, 0xFF, zRay());
        while (q.Proceed()) {
        }
        const bool keepsGoing = ctx.ReportHit(4.0f, 3, ProbeAttributes{});  // ends the search: ACCEPT_FIRST_HIT
        if (keepsGoing) {
            usedAfter = true;
            (void)q.CommittedStatus();  // the broken promise
        }
    };
    r.args.flags = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH;
    r.build();
    try {
        r.run({"HG_BoxR_noAH"});
        FAIL() << "the query call after the ending ReportHit must stop the dispatch";
    } catch (const DxrError& e) {
        EXPECT_EQ(e.diagnostic().ruleId, "IS-10");
        EXPECT_NE(std::string(e.what()).find("RayQuery::CommittedStatus()"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(usedAfter);
}

}  // namespace
}  // namespace refray::test
