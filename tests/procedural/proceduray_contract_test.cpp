// Tests the intersection-shader contract of procedural/proceduray/proceduray_shaders.cpp (issue 3) in both
// precisions: Intersection_Pacman, Intersection_Mandelbulb and Intersection_Julia respect RayTMin, RayTCurrent
// (TMax, and a nearer hit committed before they run) and the culling flags the way the HLSL applies them (H13),
// and report unit world-space normals; float and double agree within measured bounds.
//
// Each scene is one procedural instance (plus, where asked, an opaque occluder triangle). The hit group's
// intersection shader is a probe that wraps the library's export: it records RayTCurrent() when it starts, can
// first commit a nearer hit of its own (IS-9: several ReportHit calls interact only through TCurrent), then runs
// the library's IS and records RayTCurrent() again.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "emulator/device.h"
#include "emulator/shader_api.h"
#include "procedural/math/fractals.h"
#include "procedural/precision.h"
#include "procedural/proceduray/proceduray_shaders.h"
#include "tests/procedural/contract_support.h"

namespace refray::procedural::proceduray {
namespace {

using namespace refray::dxr;
using procedural::fixtures::angleBetween;
using procedural::fixtures::occluderAcross;

// ---- The rig --------------------------------------------------------------------------------------

// The instance buffer's matrices in row-vector form (§1.7): local = world · inverse(M).
using procedural::rowVectorForm;

// One procedural instance of the reference scene (§1.2, §1.8).
struct ProceduralCase {
    const char* name;
    const char* intersection;  // the library export under test
    RaytracingAABB box;
    Matrix3x4 transform;
    uint32_t ordinal;  // l_aabbCB.instanceIndex
    SignedDistancePrimitive type;
    PrimitiveConstantBuffer material;
};

constexpr PrimitiveConstantBuffer kPacmanMaterial{{1, 1, 0, 1}, 0.3f, 0.3f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
constexpr PrimitiveConstantBuffer kMandelbulbMaterial{{1, 1, 0, 1}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
constexpr PrimitiveConstantBuffer kJuliaMaterial{{1.0f, 0.5f, 0.5f, 1.0f}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};

// Pac-man A: S(50)·T(35,-35,0), AABB [-0.5,0.5]^3, ordinal 1.
ProceduralCase pacmanA() {
    return {"Pacman", "Intersection_Pacman", {-0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f},
            Matrix3x4::translation(vec3(35, -35, 0)) * Matrix3x4::scale(vec3(50)), 1,
            SignedDistancePrimitive::IntersectedRoundCube, kPacmanMaterial};
}

// The Mandelbulb: S(40)·T(0,-50,115), AABB [-1.5,1.5]^3, ordinal 3.
ProceduralCase mandelbulb() {
    return {"Mandelbulb", "Intersection_Mandelbulb", {-1.5f, -1.5f, -1.5f, 1.5f, 1.5f, 1.5f},
            Matrix3x4::translation(vec3(0, -50, 115)) * Matrix3x4::scale(vec3(40)), 3,
            SignedDistancePrimitive::Mandelbulb, kMandelbulbMaterial};
}

// The Julia with its exact float32 matrix S(100,30,100)·RotX(3.1421)·T(0,130,75), AABB [-3.5,3.5]^3, ordinal 0.
ProceduralCase julia() {
    Matrix3x4 m;
    m.m[0] = {100.0f, 0.0f, 0.0f, 0.0f};
    m.m[1] = {0.0f, -29.9999962f, 0.0507354662f, 130.0f};
    m.m[2] = {0.0f, -0.0152206402f, -99.9999847f, 75.0f};
    return {"Julia", "Intersection_Julia", {-3.5f, -3.5f, -3.5f, 3.5f, 3.5f, 3.5f}, m, 0,
            SignedDistancePrimitive::JuliaSets, kJuliaMaterial};
}

// What one wrapped intersection-shader call saw.
struct ISCall {
    float tCurrentAtEntry = 0.0f;
    float tCurrentAfter = 0.0f;
};

// What one trace ended in.
struct Outcome {
    int closestHits = 0;
    int misses = 0;
    bool triangle = false;  // the committed hit is the occluder
    float t = -1.0f;
    uint32_t hitKind = ~0u;
    ProceduralPrimitiveAttributes attr{};
    std::vector<ISCall> isCalls;
    bool hit() const { return closestHits == 1 && misses == 0; }
};

constexpr uint32_t kPreCommitHitKind = 7;

class ContractRig {
public:
    ContractRig(Precision precision, const ProceduralCase& c, std::optional<std::array<vec3, 3>> occluder = {})
        : case_(c), library_(makeProcedurayShaderLibrary(precision)) {
        GpuMemory& memory = device_.memory();
        GeometryDesc g;
        g.Type = GeometryType::ProceduralPrimitiveAABBs;
        g.Flags = GEOMETRY_FLAG_OPAQUE;
        g.AABBs.AABBCount = 1;
        g.AABBs.AABBs = {memory.upload(&c.box, sizeof c.box, "AABB"), sizeof c.box};
        std::vector<InstanceDesc> instances = {
            makeInstanceDesc(c.transform, 0, 1, 0, INSTANCE_FLAG_NONE, device_.buildBottomLevelAS({BUILD_FLAG_NONE, {g}}))};
        if (occluder) {
            GeometryDesc t;
            t.Type = GeometryType::Triangles;
            t.Flags = GEOMETRY_FLAG_OPAQUE;
            t.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
            t.Triangles.VertexCount = 3;
            t.Triangles.VertexBuffer = {memory.upload(occluder->data(), sizeof(*occluder), "occluder"), sizeof(vec3)};
            // Hit-group records 2 (radiance) and 3 (shadow).
            instances.push_back(makeInstanceDesc(Matrix3x4::identity(), 0, 1, 2, INSTANCE_FLAG_NONE,
                                                 device_.buildBottomLevelAS({BUILD_FLAG_NONE, {t}})));
        }
        tlas_ = device_.buildTopLevelAS(
            {BUILD_FLAG_NONE, uint32_t(instances.size()), ElementsLayout::Array, memory.upload(instances, "instances")});

        std::vector<InstanceBuffer> instanceBuffer(4);
        instanceBuffer.at(c.ordinal) = {rowVectorForm(*affineInverse(c.transform)), rowVectorForm(c.transform)};
        instanceBuffer_ = memory.upload(instanceBuffer, "g_instanceBuffer");
        heap_ = &device_.createDescriptorHeap(1, "contract heap");
        heap_->setTexture2D(0, DescriptorRangeType::UAV, &output_);

        scene.cameraPosition = vec4(0, 0, 50, 1);
        scene.lightPosition = vec4(0, 18, -20, 0);
        scene.lightAmbientColor = vec4(0.25f, 0.25f, 0.25f, 1.0f);
        scene.lightDiffuseColor = vec4(0.6f, 0.6f, 0.6f, 1.0f);
        scene.elapsedTime = 0.0f;  // T0
        for (int i = 0; i < 4; ++i) scene.projectionToWorld.m[i][i] = 1.0f;
        addProbes();
    }

    RayDesc ray;
    uint32_t rayFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;  // what TraceRadianceRay passes
    std::optional<float> preCommitT;  // the probe IS commits this t (kind 7) before the library IS runs
    SceneConstantBuffer scene{};
    TraversalOrder order = TraversalOrder::Ordered;
    uint64_t adversarialSeed = 0;

    Outcome trace() {
        outcome_ = {};
        StateObjectDesc desc;
        desc.name = "proceduray contract";
        desc.libraries = {{probes_, {}}};
        desc.hitGroups = {{"Probe_Procedural", HitGroupType::ProceduralPrimitive, "", "CH_Probe", "IS_Probe"},
                          {"Probe_Triangle", HitGroupType::Triangles, "", "CH_ProbeTriangle", ""}};
        const RootSignaturePtr proceduralSignature = RootSignature::create(proceduralLocalRootSignatureDesc());
        const RootSignaturePtr globalSignature = RootSignature::create(globalRootSignatureDesc());
        desc.localRootSignatures = {{proceduralSignature, {"Probe_Procedural"}}};
        desc.globalRootSignatures = {{globalSignature, {}}};
        desc.shaderConfigs = {{sizeof(RayPayload), sizeof(ProceduralPrimitiveAttributes)}};
        desc.pipelineConfigs = {{MAX_RAY_RECURSION_DEPTH, PIPELINE_FLAG_NONE}};
        const StateObjectPtr so = StateObject::create(desc);

        GpuMemory& memory = device_.memory();
        LocalRootArguments arguments(proceduralSignature);
        arguments.setConstants(kMaterialConstantBuffer, case_.material);
        arguments.setConstants(kAABBConstantBuffer, PrimitiveInstanceConstantBuffer{case_.ordinal, uint32_t(case_.type)});
        const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier("RG_Probe")).upload(memory);
        DispatchRaysDesc rays;
        rays.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
        rays.MissShaderTable = ShaderTableBuilder("miss").addRecord(so->shaderIdentifier("Miss_Probe")).upload(memory);
        rays.HitGroupTable = ShaderTableBuilder("hit groups")
                                 .addRecord(so->shaderIdentifier("Probe_Procedural"), arguments)
                                 .addRecord(so->shaderIdentifier("Probe_Procedural"), arguments)
                                 .addRecord(so->shaderIdentifier("Probe_Triangle"))
                                 .addRecord(so->shaderIdentifier("Probe_Triangle"))
                                 .upload(memory);
        rays.Width = rays.Height = rays.Depth = 1;

        GlobalRootArguments globals(globalSignature);
        globals.setDescriptor(kOutputView, heap_->gpuHandle(0));
        globals.setDescriptor(kAccelerationStructure, tlas_);
        globals.setDescriptor(kSceneConstantBuffer, memory.upload(&scene, sizeof scene, "g_sceneCB"));
        globals.setDescriptor(kInstanceBuffer, instanceBuffer_);
        globals.setDescriptor(kVertexBuffers, heap_->gpuHandle(0));
        DispatchOptions options;
        options.threads = 1;
        options.order = order;
        options.adversarialSeed = adversarialSeed;
        device_.dispatchRays(rays, so, &globals, options);
        return outcome_;
    }

private:
    void addProbes() {
        probes_->addRayGeneration("RG_Probe", [this](ShaderContext& ctx) {
            RayPayload payload{vec4(0.0f), 1, 0.0f, 0, 0};
            ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure), rayFlags, kInstanceMask, Radiance,
                         RayTypeCount, Radiance, ray, payload);
        });
        const ShaderExport* target = library_->find(case_.intersection);
        probes_->addIntersection<ProceduralPrimitiveAttributes>("IS_Probe", [this, target](ShaderContext& ctx) {
            ISCall call;
            call.tCurrentAtEntry = ctx.RayTCurrent();
            if (preCommitT) {
                const ProceduralPrimitiveAttributes marker{vec3(0.0f), vec4(7.0f)};
                ctx.ReportHit(*preCommitT, kPreCommitHitKind, marker);
            }
            target->function(ctx, nullptr, nullptr);
            call.tCurrentAfter = ctx.RayTCurrent();
            outcome_.isCalls.push_back(call);
        });
        probes_->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
            "CH_Probe", [this](ShaderContext& ctx, RayPayload&, const ProceduralPrimitiveAttributes& attr) {
                outcome_.closestHits++;
                outcome_.t = ctx.RayTCurrent();
                outcome_.hitKind = ctx.HitKind();
                outcome_.attr = attr;
            });
        probes_->addClosestHit<RayPayload, BuiltInTriangleIntersectionAttributes>(
            "CH_ProbeTriangle", [this](ShaderContext& ctx, RayPayload&, const BuiltInTriangleIntersectionAttributes&) {
                outcome_.closestHits++;
                outcome_.triangle = true;
                outcome_.t = ctx.RayTCurrent();
                outcome_.hitKind = ctx.HitKind();
            });
        probes_->addMiss<RayPayload>("Miss_Probe", [this](ShaderContext&, RayPayload&) { outcome_.misses++; });
    }

    ProceduralCase case_;
    std::shared_ptr<ShaderLibrary> library_;
    std::shared_ptr<ShaderLibrary> probes_ = std::make_shared<ShaderLibrary>();
    Device device_;
    Image output_{1, 1};
    GpuVirtualAddress tlas_ = 0;
    GpuVirtualAddress instanceBuffer_ = 0;
    DescriptorHeap* heap_ = nullptr;
    Outcome outcome_;
};

// ---- The contract, per intersection shader and precision ------------------------------------------

// A ray that starts inside the instance's AABB (so the box is enumerated from t = TMin, whatever TMax or a
// nearer hit is) and hits the primitive at `expectedT` (in the shader's own t units, H1) at T0.
struct InsideRay {
    RayDesc ray;
    float expectedT;
    float tolerance;
};

InsideRay insideRay(const std::string& name) {
    // Pac-man: local o = (0,-0.2,0.48), d = -z, so the head is at 0.48 - sqrt(0.21) = 0.021742.
    if (name == "Pacman") return {{vec3(35, -45, 24), 0.0f, vec3(0, 0, -1), 10000.0f}, 0.021742f, 1e-5f};
    // Mandelbulb: H14's ray from inside the bounding sphere, t = 0.02999 at T0.
    if (name == "Mandelbulb") return {{vec3(35, -45, 100), 0.0f, vec3(0, 0, -1), 10000.0f}, 0.02999f, 1e-4f};
    // Julia: H9's ray up into the cut face from local y = 3.33 (q-space y = 0.333) instead of 3.67:
    // the march starts at the cut plane either way, so t_rep = 0.6667 - 0.1333 (measured: 0.53338).
    return {{vec3(0, 30, 74.96f), 0.0f, vec3(0, 1, 0), 10000.0f}, 0.5334f, 1e-3f};
}

struct ContractParam {
    Precision precision;
    ProceduralCase (*make)();
};

std::string paramName(const testing::TestParamInfo<ContractParam>& info) {
    return std::string(info.param.make().name) + "_" + std::string(toString(info.param.precision));
}

class ProcedurayContract : public testing::TestWithParam<ContractParam> {
protected:
    ProceduralCase c = GetParam().make();
    Precision precision = GetParam().precision;
    InsideRay inside = insideRay(c.name);
};

TEST_P(ProcedurayContract, InsideRayHitsAtTheExpectedT) {
    ContractRig rig(precision, c);
    rig.ray = inside.ray;
    const Outcome o = rig.trace();
    ASSERT_TRUE(o.hit());
    EXPECT_NEAR(o.t, inside.expectedT, inside.tolerance);
    EXPECT_EQ(o.hitKind, 0u);
    ASSERT_EQ(o.isCalls.size(), 1u);
    EXPECT_EQ(o.isCalls[0].tCurrentAtEntry, 10000.0f);
}

// RayTCurrent = TMax: a hit beyond it is not reported, although the IS runs (the box starts at TMin).
TEST_P(ProcedurayContract, HitBeyondTMaxIsAMiss) {
    ContractRig rig(precision, c);
    rig.ray = inside.ray;
    rig.ray.TMax = 0.9f * inside.expectedT;
    const Outcome o = rig.trace();
    EXPECT_EQ(o.closestHits, 0);
    EXPECT_EQ(o.misses, 1);
    ASSERT_EQ(o.isCalls.size(), 1u);
    EXPECT_EQ(o.isCalls[0].tCurrentAtEntry, rig.ray.TMax);
    EXPECT_EQ(o.isCalls[0].tCurrentAfter, rig.ray.TMax);
}

// RayTMin past the hit: nothing is reported below TMin. The Pac-man march starts at TMin, which now lies inside
// the solid, so it reports exactly TMin (as the HLSL does); the Mandelbulb and Julia marches ignore TMin (as
// the HLSL does) and their t below TMin is rejected by ReportHit (IS-3): a miss.
TEST_P(ProcedurayContract, TMinPastTheHitReportsNothingBelowTMin) {
    ContractRig rig(precision, c);
    rig.ray = inside.ray;
    rig.ray.TMin = 1.1f * inside.expectedT;
    const Outcome o = rig.trace();
    ASSERT_EQ(o.isCalls.size(), 1u);
    if (std::string(c.name) == "Pacman") {
        ASSERT_TRUE(o.hit());
        EXPECT_EQ(o.t, rig.ray.TMin);
    } else {
        EXPECT_EQ(o.closestHits, 0);
        EXPECT_EQ(o.misses, 1);
    }
}

// A nearer hit committed before the library IS runs (RayTCurrent < its hit): it reports nothing past
// RayTCurrent, so TCurrent is unchanged and the nearer hit stays the closest.
TEST_P(ProcedurayContract, NearerCommittedHitIsKept) {
    ContractRig rig(precision, c);
    rig.ray = inside.ray;
    rig.preCommitT = 0.5f * inside.expectedT;
    const Outcome o = rig.trace();
    ASSERT_TRUE(o.hit());
    EXPECT_EQ(o.hitKind, kPreCommitHitKind);
    EXPECT_EQ(o.t, *rig.preCommitT);
    ASSERT_EQ(o.isCalls.size(), 1u);
    EXPECT_EQ(o.isCalls[0].tCurrentAfter, *rig.preCommitT);
}

// The same with an opaque triangle in front: under adversarial traversal some seeds run the IS after the
// triangle was committed (RayTCurrent = t_triangle < the IS's t); every seed, and the ordered traversal,
// end on the triangle. (t_triangle is exact only to the float ulp of the world coordinates, ~8e-6 at 100.)
TEST_P(ProcedurayContract, OpaqueTriangleInFrontIsKept) {
    const float tTriangle = 0.5f * inside.expectedT;
    ContractRig rig(precision, c, occluderAcross(inside.ray, tTriangle));
    rig.ray = inside.ray;
    {
        const Outcome o = rig.trace();
        ASSERT_TRUE(o.hit());
        EXPECT_TRUE(o.triangle);
        EXPECT_NEAR(o.t, tTriangle, 1e-5f);
    }
    rig.order = TraversalOrder::Adversarial;
    int isAfterTriangle = 0;
    for (uint64_t seed = 1; seed <= 16; ++seed) {
        rig.adversarialSeed = seed;
        const Outcome o = rig.trace();
        ASSERT_TRUE(o.hit()) << "seed " << seed;
        EXPECT_TRUE(o.triangle) << "seed " << seed;
        EXPECT_NEAR(o.t, tTriangle, 1e-5f) << "seed " << seed;
        for (const ISCall& call : o.isCalls) {
            if (call.tCurrentAtEntry < 1.0f) {
                ++isAfterTriangle;
                EXPECT_EQ(call.tCurrentAfter, call.tCurrentAtEntry) << "seed " << seed;
            }
        }
    }
    EXPECT_GT(isAfterTriangle, 0);
}

// Culling (H13): the HLSL applies RAY_FLAG_CULL_*_FACING_TRIANGLES to procedural hits only in the Pac-man's
// sphere tracer (IsAValidHit: back-facing = dot(d, n) > 0). The Mandelbulb and Julia ignore the flags.
TEST_P(ProcedurayContract, CullingFlagsAsTheHlslAppliesThem) {
    if (std::string(c.name) == "Pacman") {
        // Camera inside Pac-man A (H13): local o = (0, 0, 0.2); at t = 0 the distance is <= 0 (the mouth term)
        // and the normal is ~(0, 0, 1). -z (dot(d, n) ~ -1) and +x (dot = n.x = 0 exactly, not > 0) are hits.
        ContractRig rig(precision, c);
        const vec3 origin(35, -35, 10);
        for (const vec3 d : {vec3(0, 0, -1), vec3(1, 0, 0)}) {
            rig.ray = {origin, 0.0f, d, 10000.0f};
            rig.rayFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
            const Outcome o = rig.trace();
            ASSERT_TRUE(o.hit()) << d.x << "," << d.y << "," << d.z;
            EXPECT_EQ(o.t, 0.0f);
            EXPECT_NEAR(o.attr.normal.z, 1.0f, 1e-3f);
        }
        // -y is a knife edge: dot(d, n) = -n.y, and n.y comes from the |p.y| kink of the mouth prism. In float
        // the local origin rounds to y = 0 exactly and n.y = +6.8e-5: a hit at t = 0, as H13 measured. In double
        // the origin is y = 3.7e-9 (0.02f and 0.7f do not cancel) and n.y = -1.1e-4: back-facing, culled.
        rig.ray = {origin, 0.0f, vec3(0, -1, 0), 10000.0f};
        const Outcome down = rig.trace();
        if (precision == Precision::Float) {
            ASSERT_TRUE(down.hit());
            EXPECT_EQ(down.t, 0.0f);
            EXPECT_GT(down.attr.normal.y, 0.0f);
        } else {
            EXPECT_FALSE(down.hit());
            rig.rayFlags = RAY_FLAG_NONE;
            const Outcome unculled = rig.trace();
            ASSERT_TRUE(unculled.hit());
            EXPECT_LT(unculled.attr.normal.y, 0.0f);
        }
        // +z: back-facing at t = 0. Culled, t steps negative and never becomes a valid hit.
        rig.ray = {origin, 0.0f, vec3(0, 0, 1), 10000.0f};
        rig.rayFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
        EXPECT_FALSE(rig.trace().hit());
        rig.rayFlags = RAY_FLAG_NONE;
        Outcome o = rig.trace();
        ASSERT_TRUE(o.hit());
        EXPECT_EQ(o.t, 0.0f);
        rig.rayFlags = RAY_FLAG_CULL_FRONT_FACING_TRIANGLES;
        o = rig.trace();
        ASSERT_TRUE(o.hit());
        EXPECT_EQ(o.t, 0.0f);
        // -z: front-facing at t = 0, so front-face culling rejects it.
        rig.ray = {origin, 0.0f, vec3(0, 0, -1), 10000.0f};
        EXPECT_FALSE(rig.trace().hit());
        return;
    }
    ContractRig rig(precision, c);
    rig.ray = inside.ray;
    rig.rayFlags = RAY_FLAG_NONE;
    const Outcome none = rig.trace();
    ASSERT_TRUE(none.hit());
    for (const uint32_t flags :
         {uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES), uint32_t(RAY_FLAG_CULL_FRONT_FACING_TRIANGLES)}) {
        rig.rayFlags = flags;
        const Outcome o = rig.trace();
        ASSERT_TRUE(o.hit()) << flags;
        EXPECT_EQ(o.t, none.t) << flags;
        EXPECT_EQ(o.attr.normal, none.attr.normal) << flags;
    }
}

// The reported normal is unit length and in world space: normalize(n_local · WorldToObject3x3), the inverse
// transpose of ObjectToWorld. n_local is recomputed here from the same local ray with the same math, in T.
template <typename T>
glm::vec<3, T> localNormal(const ProceduralCase& c, const RayDesc& ray, float elapsedTime) {
    using V3 = glm::vec<3, T>;
    using V4 = glm::vec<4, T>;
    const Float4x4 w2o = rowVectorForm(*affineInverse(c.transform));
    const V3 o = V3(mul(V4(V3(ray.Origin), T(1)), w2o));
    const V3 d = hlsl::normalize(V3(mul(V4(V3(ray.Direction), T(0)), w2o)));
    if (c.type == SignedDistancePrimitive::Mandelbulb) {
        const int iMax = math::mandelbulb::MandelbulbIterationCount(T(elapsedTime), int(c.ordinal));
        return math::mandelbulb::MandelbulbDistance(o, d, iMax).normal;
    }
    if (c.type == SignedDistancePrimitive::JuliaSets) return math::julia::JuliaDistance(o, d).normal;
    const T mouth = math::pacman::PacmanMouthInterpolant(T(elapsedTime));
    math::SphereTraceParams<T> params;
    params.stepScale = T(c.material.stepScale);
    const math::RayExtent<T> extent{T(ray.TMin), T(ray.TMax), true, false};
    return math::RaySignedDistancePrimitiveTest(math::Ray<T>{o, d}, extent,
                                                [mouth](const V3& p) { return math::pacman::pacMan(p, mouth); }, params)
        .normal;
}

// Rays from outside towards each instance, through a rotated and non-uniformly scaled copy of it.
TEST_P(ProcedurayContract, NormalIsUnitAndWorldSpace) {
    ProceduralCase rotated = c;
    const vec3 centre(c.transform.m[0][3], c.transform.m[1][3], c.transform.m[2][3]);
    if (c.type != SignedDistancePrimitive::JuliaSets) {  // the Julia's own matrix already rotates and stretches
        const float s = c.type == SignedDistancePrimitive::Mandelbulb ? 40.0f : 50.0f;
        rotated.transform = Matrix3x4::translation(centre) * Matrix3x4::rotation(glm::normalize(vec3(1, 2, 3)), 0.7f) *
                            Matrix3x4::scale(vec3(s, 0.6f * s, 0.8f * s));
    }
    // Julia: towards local (0, 1.25, 0), q-space (0, -0.5, 0), between the cut planes; tilted so rd.y != 0 (H10).
    const vec3 target = c.type == SignedDistancePrimitive::JuliaSets ? vec3(0.0f, 92.5f, 74.98f) : centre;
    const vec3 direction = glm::normalize(vec3(-1.0f, 0.05f, 0.03f));
    ContractRig rig(precision, rotated);
    rig.ray = {target - 300.0f * direction, 0.0f, direction, 10000.0f};
    const Outcome o = rig.trace();
    ASSERT_TRUE(o.hit());
    const vec3 n = o.attr.normal;
    EXPECT_NEAR(glm::length(dvec3(n)), 1.0, 1e-5);

    const dvec3 nLocal = precision == Precision::Double ? localNormal<double>(rotated, rig.ray, 0.0f)
                                                        : dvec3(localNormal<float>(rotated, rig.ray, 0.0f));
    const Matrix3x4 w2o = *affineInverse(rotated.transform);
    dvec3 expected;
    for (int j = 0; j < 3; ++j)
        expected[j] = nLocal.x * w2o.m[0][j] + nLocal.y * w2o.m[1][j] + nLocal.z * w2o.m[2][j];
    expected = glm::normalize(expected);
    EXPECT_LT(glm::length(dvec3(n) - expected), 1e-5) << "world normal";
    // Neither the local normal nor M·n_local: the transform matters for this instance.
    EXPECT_GT(glm::length(dvec3(n) - nLocal), 0.05);
    dvec3 wrong;
    for (int i = 0; i < 3; ++i)
        wrong[i] = rotated.transform.m[i][0] * nLocal.x + rotated.transform.m[i][1] * nLocal.y +
                   rotated.transform.m[i][2] * nLocal.z;
    EXPECT_GT(glm::length(dvec3(n) - glm::normalize(wrong)), 0.01);
}

INSTANTIATE_TEST_SUITE_P(Proceduray, ProcedurayContract,
                         testing::Values(ContractParam{Precision::Float, pacmanA}, ContractParam{Precision::Double, pacmanA},
                                         ContractParam{Precision::Float, mandelbulb},
                                         ContractParam{Precision::Double, mandelbulb},
                                         ContractParam{Precision::Float, julia}, ContractParam{Precision::Double, julia}),
                         paramName);

// ---- Float vs double --------------------------------------------------------------------------------

Outcome traceWith(Precision precision, const ProceduralCase& c, const RayDesc& ray, float elapsedTime) {
    ContractRig rig(precision, c);
    rig.ray = ray;
    rig.scene.elapsedTime = elapsedTime;
    return rig.trace();
}

void report(const char* what, const Outcome& f, const Outcome& d) {
    std::printf("[precision] %s: t float %.9g double %.9g |dt| %.3g normal angle %.3g rad\n", what, double(f.t),
                double(d.t), std::fabs(double(f.t) - double(d.t)), angleBetween(f.attr.normal, d.attr.normal));
}

// PORT (precision option): the H1 Pac-man ray. The sphere trace takes the same steps in both; the difference is
// float rounding of t ~ 0.54 (ulp 6e-8) over a few steps. Measured: t equal to the bit (0.541730225), normal
// angle 7.4e-5 rad.
TEST(ProcedurayPrecision, PacmanH1RayAgreesWithinOneE5) {
    const RayDesc ray{vec3(35, -45, 50), 0.0f, vec3(0, 0, -1), 10000.0f};
    const Outcome f = traceWith(Precision::Float, pacmanA(), ray, 0.0f);
    const Outcome d = traceWith(Precision::Double, pacmanA(), ray, 0.0f);
    ASSERT_TRUE(f.hit());
    ASSERT_TRUE(d.hit());
    report("Pacman H1", f, d);
    EXPECT_NEAR(f.t, 0.54173f, 1e-4f);
    EXPECT_NEAR(f.t, d.t, 1e-5f);
    EXPECT_LT(angleBetween(f.attr.normal, d.attr.normal), 1e-3);
    EXPECT_EQ(f.attr.color, d.attr.color);
}

// T1 = 15.8429795 (iMax 129: the fully detailed Mandelbulb). A ray from outside towards the centre.
constexpr float kT1 = 15.8429795f;

// Bounds for the fractal marches, measured (printed as "[precision] ..."):
//   Mandelbulb T1: |dt| = 6.0e-8 (1 ulp of t = 0.884), normal angle 6.3e-4 rad;
//   Julia side-wall ray: |dt| = 3.0e-8 (1 ulp of t = 0.385), normal angle 3.0e-4 rad.
// t: 1e-5. Both marches converged with the same step count; a step more or less would move t by up to the stop
// threshold (1e-4·t = 8.8e-5 for the Mandelbulb, kPrecis = 2.5e-4 for the Julia), which the bound rejects, while
// float rounding of the distance estimate moves it by ~1e-7.
// Normal: 1e-2 rad. The tetrahedral normal divides DE differences over offsets of 5.8e-5 (Mandelbulb) and
// 1.4e-4 (Julia); float DE rounding of ~1e-7 there gives angles up to ~2e-3, and the bound is 5x that.
// (Rays onto the Julia's cut face are excluded: there a sub-ulp change moves the hit by a whole 0.2 step, H9.)

// PORT (precision option).
TEST(ProcedurayPrecision, MandelbulbT1RayAgreesWithinTheMeasuredBound) {
    const RayDesc ray{vec3(35, -45, 50), 0.0f, glm::normalize(vec3(0, -50, 115) - vec3(35, -45, 50)), 10000.0f};
    const Outcome f = traceWith(Precision::Float, mandelbulb(), ray, kT1);
    const Outcome d = traceWith(Precision::Double, mandelbulb(), ray, kT1);
    ASSERT_TRUE(f.hit());
    ASSERT_TRUE(d.hit());
    report("Mandelbulb T1", f, d);
    EXPECT_NEAR(f.t, d.t, 1e-5f);
    EXPECT_LT(angleBetween(f.attr.normal, d.attr.normal), 1e-2);
}

// PORT (precision option): the side-wall ray of NormalIsUnitAndWorldSpace, towards q-space (0, -0.5, 0).
TEST(ProcedurayPrecision, JuliaRayAgreesWithinTheMeasuredBound) {
    const vec3 direction = glm::normalize(vec3(-1.0f, 0.05f, 0.03f));
    const RayDesc ray{vec3(0.0f, 92.5f, 74.98f) - 300.0f * direction, 0.0f, direction, 10000.0f};
    const Outcome f = traceWith(Precision::Float, julia(), ray, 0.0f);
    const Outcome d = traceWith(Precision::Double, julia(), ray, 0.0f);
    ASSERT_TRUE(f.hit());
    ASSERT_TRUE(d.hit());
    report("Julia side", f, d);
    EXPECT_NEAR(f.t, d.t, 1e-5f);
    EXPECT_LT(angleBetween(f.attr.normal, d.attr.normal), 1e-2);
}

TEST(ProcedurayPrecision, NamesRoundTrip) {
    EXPECT_EQ(toString(Precision::Float), "float");
    EXPECT_EQ(toString(Precision::Double), "double");
    EXPECT_EQ(parsePrecision("float"), Precision::Float);
    EXPECT_EQ(parsePrecision("double"), Precision::Double);
    EXPECT_EQ(parsePrecision("Double"), std::nullopt);
    EXPECT_EQ(parsePrecision(""), std::nullopt);
}

}  // namespace
}  // namespace refray::procedural::proceduray
