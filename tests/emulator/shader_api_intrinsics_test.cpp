// Conformance tests for the system-value intrinsics of ShaderContext (emulator/shader_api.cpp, dxr-semantics.md
// section 11). Each test name carries the rule id it checks. The rig is dispatch_rig.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "dispatch_rig.h"
#include "emulator/limits.h"

namespace refray::test {
namespace {

using namespace dispatch_rig;

bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(vec3 a, vec3 b) { return std::memcmp(&a, &b, sizeof a) == 0; }

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

}  // namespace
}  // namespace refray::test
