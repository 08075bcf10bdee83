// Conformance tests for CallShader and callable shaders (emulator/shader_invocation.cpp, dxr-semantics.md section
// 10). Each test name carries the rule id it checks. The rig is dispatch_rig.h.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dispatch_rig.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

struct OtherParams {
    double value = 0.0;
};

// ---------------------------------------------------------------------------------------
// CALL.

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

}  // namespace
}  // namespace refray::test
