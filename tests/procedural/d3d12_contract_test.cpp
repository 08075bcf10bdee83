// Tests the intersection-shader contract of procedural/d3d12/d3d12_shaders.cpp (issue 3) in both precisions:
// MyIntersectionShader_AnalyticPrimitive (box, spheres), _VolumetricPrimitive (metaballs) and
// _SignedDistancePrimitive (all seven SDFs) respect RayTMin, RayTCurrent (TMax, and a nearer hit committed before
// they run) and the culling flags the way the HLSL applies them (I3: IsCulled on the local d·n), and report unit
// normals transformed the way the HLSL does (I1: the forward matrices, not the inverse transpose); float and double
// agree within stated bounds.
//
// Each scene is one AABB instance holding one primitive of the fact sheet (§1.3) at T = 0, plus, where asked, an
// opaque occluder triangle. The BLAS AABB is the fact-sheet box grown by 0.5 on every side (DXR boxes may be
// conservative), so every intersection shader runs from before its primitive, even for the analytic box whose local
// cube is the fact-sheet box itself. The hit group's intersection shader is a probe that wraps the library's export:
// it records RayTCurrent() when it starts, can first commit a nearer hit of its own (IS-9), then runs the library's
// IS and records RayTCurrent() again.
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
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/math/analytic.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/sdf.h"
#include "procedural/precision.h"
#include "tests/procedural/contract_support.h"

namespace refray::procedural::d3d12 {
namespace {

using namespace refray::dxr;
using procedural::fixtures::angleBetween;
using procedural::fixtures::occluderAcross;

// ---- The primitives (§1.3, §1.4) and their rays ----------------------------------------------------

enum class IS { Analytic, Volumetric, SignedDistance };

struct Primitive {
    const char* name;
    int index;  // i of §1.3: l_aabbCB.instanceIndex
    vec3 offset, size, scale;
    IS is;
    uint32_t primitiveType;
    float stepScale;
    RayDesc ray;  // from outside, in the world of the (0, 1, 0) AABB instance; hits the primitive front-facing
};

const char* exportOf(IS is) {
    switch (is) {
        case IS::Analytic: return "MyIntersectionShader_AnalyticPrimitive";
        case IS::Volumetric: return "MyIntersectionShader_VolumetricPrimitive";
        default: return "MyIntersectionShader_SignedDistancePrimitive";
    }
}

RayDesc rayFrom(vec3 origin, vec3 direction) { return {origin, 0.0f, direction, 10000.0f}; }

// At T = 0 no primitive is rotated. The rays: the box's -x face; sphere A from -z (§2.4); through metaball 1's
// centre; a mini sphere from -x; the round cube's frame; the square torus's top; the twisted torus's vertical ring
// (local x = 0.6); the cog's rim from above; a cylinder column from -x; the pyramid's +x face.
const Primitive kPrimitives[] = {
    {"Box", 0, {3, 0, 0}, {2, 3, 2}, {1, 1.5f, 1}, IS::Analytic, 0, 1.0f, rayFrom({0, 1.5f, -6}, {1, 0, 0})},
    {"Spheres", 1, {2.25f, 0, 0.75f}, {3, 3, 3}, vec3(1.5f), IS::Analytic, 1, 1.0f,
     rayFrom({3.05f, 1.5f, -10}, {0, 0, 1})},
    {"Metaballs", 2, {0, 0, 0}, {3, 3, 3}, vec3(1.5f), IS::Volumetric, 0, 1.0f, rayFrom({-5.5f, 1.2f, -15}, {0, 0, 1})},
    {"MiniSpheres", 3, {2, 0, 0}, {2, 2, 2}, vec3(1), IS::SignedDistance, 0, 1.0f, rayFrom({-5, 1.25f, -5.75f}, {1, 0, 0})},
    {"IntersectedRoundCube", 4, {0, 0, 2}, {2, 2, 2}, vec3(1), IS::SignedDistance, 1, 1.0f,
     rayFrom({-10, 1.85f, 2}, {1, 0, 0})},
    {"SquareTorus", 5, {0.75f, -0.1f, 2.25f}, {3, 3, 3}, vec3(1.5f), IS::SignedDistance, 2, 1.0f,
     rayFrom({-1.375f, 10, 3.5f}, {0, -1, 0})},
    {"TwistedTorus", 6, {0, 0, 1}, {2, 2, 2}, vec3(1), IS::SignedDistance, 3, 0.5f, rayFrom({-5.4f, 1, -10}, {0, 0, 1})},
    {"Cog", 7, {1, 0, 0}, {2, 2, 2}, vec3(1), IS::SignedDistance, 4, 1.0f, rayFrom({-1.4f, 10, -5.95f}, {0, -1, 0})},
    {"Cylinder", 8, {0, 0, 3}, {2, 3, 2}, {1, 1.5f, 1}, IS::SignedDistance, 5, 1.0f, rayFrom({-10, 1.5f, 6.5f}, {1, 0, 0})},
    {"FractalPyramid", 9, {2, 0, 2}, {6, 6, 6}, vec3(3), IS::SignedDistance, 6, 0.8f,
     rayFrom({10, 0.15f, 6.8125f}, {-1, 0, 0})},
};

RaytracingAABB factSheetBox(const Primitive& p, float pad = 0.0f) {
    const vec3 lo = vec3(-7.0f, -1.0f, -7.0f) + p.offset * 4.0f;
    const vec3 hi = lo + p.size;
    return {lo.x - pad, lo.y - pad, lo.z - pad, hi.x + pad, hi.y + pad, hi.z + pad};
}

// localSpaceToBottomLevelAS = S·Tr at T = 0 (row-vector form) and its inverse, both exact in float here.
PrimitiveInstancePerFrameBuffer transforms(const Primitive& p) {
    const RaytracingAABB b = factSheetBox(p);
    const vec3 centre(0.5f * (b.MinX + b.MaxX), 0.5f * (b.MinY + b.MaxY), 0.5f * (b.MinZ + b.MaxZ));
    PrimitiveInstancePerFrameBuffer out{};
    for (int k = 0; k < 3; ++k) {
        out.localSpaceToBottomLevelAS.m[k][k] = p.scale[k];
        out.localSpaceToBottomLevelAS.m[3][k] = centre[k];
        out.bottomLevelASToLocalSpace.m[k][k] = 1.0f / p.scale[k];
        out.bottomLevelASToLocalSpace.m[3][k] = -centre[k] / p.scale[k];
    }
    out.localSpaceToBottomLevelAS.m[3][3] = out.bottomLevelASToLocalSpace.m[3][3] = 1.0f;
    return out;
}

// ---- The rig --------------------------------------------------------------------------------------

struct ISCall {
    float tCurrentAtEntry = 0.0f;
    float tCurrentAfter = 0.0f;
};

struct Outcome {
    int closestHits = 0;
    int misses = 0;
    bool triangle = false;
    float t = -1.0f;
    uint32_t hitKind = ~0u;
    vec3 normal{0.0f};
    std::vector<ISCall> isCalls;
    bool hit() const { return closestHits == 1 && misses == 0; }
};

constexpr uint32_t kPreCommitHitKind = 7;
const Matrix3x4 kAABBInstance = Matrix3x4::translation(vec3(0, 1, 0));  // §1.2

class ContractRig {
public:
    ContractRig(Precision precision, const Primitive& p, const Matrix3x4& instance = kAABBInstance,
                std::optional<std::array<vec3, 3>> occluder = {})
        : primitive_(p), library_(makeD3D12ShaderLibrary(precision)) {
        GpuMemory& memory = device_.memory();
        const RaytracingAABB box = factSheetBox(p, 0.5f);
        GeometryDesc g;
        g.Type = GeometryType::ProceduralPrimitiveAABBs;
        g.Flags = GEOMETRY_FLAG_OPAQUE;
        g.AABBs.AABBCount = 1;
        g.AABBs.AABBs = {memory.upload(&box, sizeof box, "AABB"), sizeof box};
        std::vector<InstanceDesc> instances = {
            makeInstanceDesc(instance, 0, 1, 0, INSTANCE_FLAG_NONE, device_.buildBottomLevelAS({BUILD_FLAG_NONE, {g}}))};
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

        std::vector<PrimitiveInstancePerFrameBuffer> attributes(10);
        attributes.at(size_t(p.index)) = transforms(p);
        attributeBuffer_ = memory.upload(attributes, "g_AABBPrimitiveAttributes");
        heap_ = &device_.createDescriptorHeap(1, "contract heap");
        heap_->setTexture2D(0, DescriptorRangeType::UAV, &output_);

        scene.lightPosition = vec4(0, 18, -20, 0);
        scene.lightAmbientColor = vec4(0.25f, 0.25f, 0.25f, 1.0f);
        scene.lightDiffuseColor = vec4(0.6f, 0.6f, 0.6f, 1.0f);
        scene.elapsedTime = 0.0f;
        addProbes();
    }

    RayDesc ray;
    uint32_t rayFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;  // what TraceRadianceRay passes
    std::optional<float> preCommitT;
    SceneConstantBuffer scene{};
    TraversalOrder order = TraversalOrder::Ordered;
    uint64_t adversarialSeed = 0;

    Outcome trace() {
        outcome_ = {};
        StateObjectDesc desc;
        desc.name = "d3d12 contract";
        desc.libraries = {{probes_, {}}};
        desc.hitGroups = {{"Probe_AABB", HitGroupType::ProceduralPrimitive, "", "CH_Probe", "IS_Probe"},
                          {"Probe_Triangle", HitGroupType::Triangles, "", "CH_ProbeTriangle", ""}};
        const RootSignaturePtr aabbSignature = RootSignature::create(aabbLocalRootSignatureDesc());
        const RootSignaturePtr globalSignature = RootSignature::create(globalRootSignatureDesc());
        desc.localRootSignatures = {{aabbSignature, {"Probe_AABB"}}};
        desc.globalRootSignatures = {{globalSignature, {}}};
        desc.shaderConfigs = {{kMaxPayloadSizeInBytes, kMaxAttributeSizeInBytes}};
        desc.pipelineConfigs = {{MAX_RAY_RECURSION_DEPTH, PIPELINE_FLAG_NONE}};
        const StateObjectPtr so = StateObject::create(desc);

        GpuMemory& memory = device_.memory();
        LocalRootArguments arguments(aabbSignature);
        arguments.setConstants(kMaterialConstant, PrimitiveConstantBuffer{vec4(1.0f), 0.0f, 0.9f, 0.7f, 50.0f,
                                                                          primitive_.stepScale, vec3(0.0f)});
        arguments.setConstants(kGeometryIndex,
                               PrimitiveInstanceConstantBuffer{uint32_t(primitive_.index), primitive_.primitiveType});
        const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier("RG_Probe")).upload(memory);
        DispatchRaysDesc rays;
        rays.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
        rays.MissShaderTable = ShaderTableBuilder("miss").addRecord(so->shaderIdentifier("Miss_Probe")).upload(memory);
        rays.HitGroupTable = ShaderTableBuilder("hit groups")
                                 .addRecord(so->shaderIdentifier("Probe_AABB"), arguments)
                                 .addRecord(so->shaderIdentifier("Probe_AABB"), arguments)
                                 .addRecord(so->shaderIdentifier("Probe_Triangle"))
                                 .addRecord(so->shaderIdentifier("Probe_Triangle"))
                                 .upload(memory);
        rays.Width = rays.Height = rays.Depth = 1;

        GlobalRootArguments globals(globalSignature);
        globals.setDescriptor(kOutputView, heap_->gpuHandle(0));
        globals.setDescriptor(kAccelerationStructure, tlas_);
        globals.setDescriptor(kSceneConstant, memory.upload(&scene, sizeof scene, "g_sceneCB"));
        globals.setDescriptor(kAABBattributeBuffer, attributeBuffer_);
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
            RayPayload payload{vec4(0.0f), 1};
            ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure), rayFlags, TraceRayParameters::InstanceMask,
                         RayType::Radiance, TraceRayParameters::GeometryStride, RayType::Radiance, ray, payload);
        });
        const ShaderExport* target = library_->find(exportOf(primitive_.is));
        probes_->addIntersection<ProceduralPrimitiveAttributes>("IS_Probe", [this, target](ShaderContext& ctx) {
            ISCall call;
            call.tCurrentAtEntry = ctx.RayTCurrent();
            if (preCommitT) ctx.ReportHit(*preCommitT, kPreCommitHitKind, ProceduralPrimitiveAttributes{vec3(7.0f)});
            target->function(ctx, nullptr, nullptr);
            call.tCurrentAfter = ctx.RayTCurrent();
            outcome_.isCalls.push_back(call);
        });
        probes_->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
            "CH_Probe", [this](ShaderContext& ctx, RayPayload&, const ProceduralPrimitiveAttributes& attr) {
                outcome_.closestHits++;
                outcome_.t = ctx.RayTCurrent();
                outcome_.hitKind = ctx.HitKind();
                outcome_.normal = attr.normal;
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

    Primitive primitive_;
    std::shared_ptr<ShaderLibrary> library_;
    std::shared_ptr<ShaderLibrary> probes_ = std::make_shared<ShaderLibrary>();
    Device device_;
    Image output_{1, 1};
    GpuVirtualAddress tlas_ = 0;
    GpuVirtualAddress attributeBuffer_ = 0;
    DescriptorHeap* heap_ = nullptr;
    Outcome outcome_;
};

// The sign the HLSL's IsCulled tests: dot(d_L, n_L) for the reported world normal n of a hit of `ray` under the
// translation-only instance. n = normalize(n_L·l2b) there (I1), so n_L ∝ n·b2l and d_L = d·b2l (3x3 parts).
double localFacing(const Primitive& p, const RayDesc& ray, vec3 n) {
    const PrimitiveInstancePerFrameBuffer m = transforms(p);
    double s = 0.0;
    for (int j = 0; j < 3; ++j) {
        double nL = 0.0, dL = 0.0;
        for (int i = 0; i < 3; ++i) {
            nL += double(n[i]) * m.bottomLevelASToLocalSpace.m[i][j];
            dL += double(ray.Direction[i]) * m.bottomLevelASToLocalSpace.m[i][j];
        }
        s += nL * dL;
    }
    return s;
}

// ---- The contract, per primitive and precision ---------------------------------------------------------

struct ContractParam {
    Precision precision;
    int primitive;  // index into kPrimitives
};

std::string paramName(const testing::TestParamInfo<ContractParam>& info) {
    return std::string(kPrimitives[info.param.primitive].name) + "_" + std::string(toString(info.param.precision));
}

class D3D12Contract : public testing::TestWithParam<ContractParam> {
protected:
    void SetUp() override {
        ContractRig rig(precision, p);
        rig.ray = p.ray;
        first = rig.trace();
        ASSERT_TRUE(first.hit()) << p.name;
        ASSERT_EQ(first.hitKind, 0u);
        ASSERT_EQ(first.isCalls.size(), 1u);
        ASSERT_EQ(first.isCalls[0].tCurrentAtEntry, 10000.0f);
        // Front-facing, and the box is entered at least 0.5 before the hit (the 0.5 padding).
        ASSERT_LT(localFacing(p, p.ray, first.normal), 0.0) << p.name;
        ASSERT_GT(first.t, 0.5f);
    }
    Precision precision = GetParam().precision;
    Primitive p = kPrimitives[GetParam().primitive];
    Outcome first;  // the hit of p.ray with the radiance flags and TMax 10000
};

TEST_P(D3D12Contract, HitIsUnitNormalAndNotKindedOrMoved) {
    EXPECT_NEAR(glm::length(dvec3(first.normal)), 1.0, 1e-5);
    EXPECT_EQ(first.isCalls[0].tCurrentAfter, first.t);
}

// RayTCurrent = TMax just below the hit (0.2 before it, inside the padded box): the IS runs and reports nothing.
TEST_P(D3D12Contract, HitBeyondTMaxIsAMiss) {
    ContractRig rig(precision, p);
    rig.ray = p.ray;
    rig.ray.TMax = first.t - 0.2f;
    const Outcome o = rig.trace();
    EXPECT_EQ(o.closestHits, 0);
    EXPECT_EQ(o.misses, 1);
    ASSERT_EQ(o.isCalls.size(), 1u);
    EXPECT_EQ(o.isCalls[0].tCurrentAtEntry, rig.ray.TMax);
    EXPECT_EQ(o.isCalls[0].tCurrentAfter, rig.ray.TMax);
}

// RayTMin past the hit: nothing is reported below TMin. The hollow box never reports its exit (§2.3 step 5); the
// other tests start at or clamp to TMin and report, if anything, a t >= TMin.
TEST_P(D3D12Contract, TMinPastTheHitReportsNothingBelowTMin) {
    ContractRig rig(precision, p);
    rig.ray = p.ray;
    rig.ray.TMin = first.t + 0.05f;
    const Outcome o = rig.trace();
    ASSERT_EQ(o.isCalls.size(), 1u);
    if (o.closestHits > 0) {
        EXPECT_GE(o.t, rig.ray.TMin);
    }
    if (p.primitiveType == AnalyticPrimitive::AABB && p.is == IS::Analytic) {
        EXPECT_EQ(o.closestHits, 0);
        EXPECT_EQ(o.misses, 1);
    }
}

// A nearer hit committed before the library IS runs: it reports nothing past RayTCurrent, so TCurrent is unchanged
// and the nearer hit stays the closest.
TEST_P(D3D12Contract, NearerCommittedHitIsKept) {
    ContractRig rig(precision, p);
    rig.ray = p.ray;
    rig.preCommitT = first.t - 0.1f;
    const Outcome o = rig.trace();
    ASSERT_TRUE(o.hit());
    EXPECT_EQ(o.hitKind, kPreCommitHitKind);
    EXPECT_EQ(o.t, *rig.preCommitT);
    ASSERT_EQ(o.isCalls.size(), 1u);
    EXPECT_EQ(o.isCalls[0].tCurrentAfter, *rig.preCommitT);
}

// An opaque triangle 0.1 before the hit, inside the padded box: under the ordered traversal and 16 adversarial seeds
// the triangle wins; every IS call made after the triangle was committed leaves RayTCurrent as it found it.
TEST_P(D3D12Contract, OpaqueTriangleInFrontIsKept) {
    const float tTriangle = first.t - 0.1f;
    ContractRig rig(precision, p, kAABBInstance, occluderAcross(p.ray, tTriangle));
    rig.ray = p.ray;
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
            if (call.tCurrentAtEntry < first.t) {
                ++isAfterTriangle;
                EXPECT_EQ(call.tCurrentAfter, call.tCurrentAtEntry) << "seed " << seed;
            }
        }
    }
    EXPECT_GT(isAfterTriangle, 0);
}

// I3: the sample applies RAY_FLAG_CULL_{BACK,FRONT}_FACING_TRIANGLES to procedural hits itself, through IsCulled on
// the local dot(d, n) (> 0 back-facing, < 0 front-facing). The front-facing hit of p.ray survives back-face culling
// and no culling alike; front-face culling removes it (any hit left is further and back-facing: the far side).
// (The two flags together are invalid in DXR, FLAG-3.)
TEST_P(D3D12Contract, CullingFlagsAsTheHlslAppliesThem) {
    ContractRig rig(precision, p);
    rig.ray = p.ray;
    rig.rayFlags = RAY_FLAG_NONE;
    const Outcome none = rig.trace();
    ASSERT_TRUE(none.hit());
    EXPECT_EQ(none.t, first.t);
    EXPECT_EQ(none.normal, first.normal);

    rig.rayFlags = RAY_FLAG_CULL_FRONT_FACING_TRIANGLES;
    const Outcome front = rig.trace();
    if (front.closestHits > 0) {
        EXPECT_GT(front.t, first.t);
        // Back-facing, or (metaballs, H11) a NaN normal from the flat field near a ball's centre, which p.ray
        // crosses: IsCulled's comparisons are false for NaN, so no flag ever culls it.
        const double facing = localFacing(p, p.ray, front.normal);
        if (p.is == IS::Volumetric && std::isnan(facing)) {
            EXPECT_TRUE(std::isnan(front.normal.x));
        } else {
            EXPECT_GT(facing, 0.0);
        }
    }
    if (p.is == IS::Analytic) {
        if (p.primitiveType == AnalyticPrimitive::AABB) {
            EXPECT_EQ(front.misses, 1);  // the hollow box has only its entry face
        } else {
            EXPECT_TRUE(front.hit());  // sphere A's far side
        }
    }
}

// The back-facing side, for the spheres and the metaballs (the hollow box has no far side, see
// TMinPastTheHitReportsNothingBelowTMin; a sphere trace started inside the solid reports TMin itself): with TMin just
// past the front hit the spheres report the far side (back-facing, local dot(d, n) > 0), which back-face culling
// removes.
class D3D12FarSide : public D3D12Contract {};

TEST_P(D3D12FarSide, BackFacingFarSideIsCulledOnlyWithCullBack) {
    ContractRig rig(precision, p);
    rig.ray = p.ray;
    rig.ray.TMin = first.t + 0.05f;
    rig.rayFlags = RAY_FLAG_NONE;
    const Outcome none = rig.trace();
    if (p.is == IS::Analytic) {
        ASSERT_TRUE(none.hit());
        EXPECT_GT(localFacing(p, rig.ray, none.normal), 0.0);
        rig.rayFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
        EXPECT_FALSE(rig.trace().hit());
        return;
    }
    // Metaballs: the march restarts at TMin inside the field, where the first sample is the hit; whatever it
    // reports under back-face culling is not back-facing.
    rig.rayFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
    const Outcome back = rig.trace();
    if (back.closestHits > 0) {
        EXPECT_LE(localFacing(p, rig.ray, back.normal), 0.0);
    }
}

// ---- Normals under a rotated, non-uniformly scaled instance -----------------------------------------------

// Object -> world: T(0,1,0)·S(1.3, 0.7, 1.1)·R(axis, 0.7), i.e. rotated then stretched: a shear, under which the
// forward matrix and the inverse transpose send even an axis normal to different directions.
Matrix3x4 shearedInstance() {
    return Matrix3x4::translation(vec3(0, 1, 0)) * Matrix3x4::scale(vec3(1.3f, 0.7f, 1.1f)) *
           Matrix3x4::rotation(glm::normalize(vec3(1, 2, 3)), 0.7f);
}

// The local normal the IS computes for an object-space ray, with the library's math in T.
template <typename T>
glm::vec<3, T> localNormal(const Primitive& p, vec3 objectOrigin, vec3 objectDirection) {
    using V3 = glm::vec<3, T>;
    using V4 = glm::vec<4, T>;
    const PrimitiveInstancePerFrameBuffer m = transforms(p);
    math::Ray<T> ray;
    ray.origin = V3(mul(V4(V3(objectOrigin), T(1)), m.bottomLevelASToLocalSpace));
    ray.direction = V3(mul(V4(V3(objectDirection), T(0)), m.bottomLevelASToLocalSpace));
    const math::RayExtent<T> extent{T(0), T(10000), true, false};
    if (p.is == IS::Analytic)
        return p.primitiveType == AnalyticPrimitive::AABB ? math::RayUnitCubeIntersectionTest(ray, extent).normal
                                                          : math::RaySpheresIntersectionTest(ray, extent).normal;
    if (p.is == IS::Volumetric) return math::RayMetaballsIntersectionTest(ray, extent, T(0), T(12)).normal;
    math::SphereTraceParams<T> params;
    params.stepScale = T(p.stepScale);
    const auto type = SignedDistancePrimitive(p.primitiveType);
    return math::RaySignedDistancePrimitiveTest(
               ray, extent, [type](const V3& x) { return math::d3d12::GetDistanceFromSignedDistancePrimitive(x, type); },
               params)
        .normal;
}

// 3x3 helpers in double, column-vector form (A[i][j]: row i, column j).
using D3 = std::array<std::array<double, 3>, 3>;
D3 product(const D3& a, const D3& b) {
    D3 r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) r[i][j] += a[i][k] * b[k][j];
    return r;
}
dvec3 times(const D3& a, dvec3 v) {
    return {a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z, a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z,
            a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z};
}
D3 inverseTranspose(const D3& a) {
    D3 c{};  // cofactor matrix = det · inverse^T
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            c[i][j] = a[(i + 1) % 3][(j + 1) % 3] * a[(i + 2) % 3][(j + 2) % 3] -
                      a[(i + 1) % 3][(j + 2) % 3] * a[(i + 2) % 3][(j + 1) % 3];
    return c;  // the scale does not matter for a normal
}

// The reported normal is unit length and equals the HLSL's normalize(ObjectToWorld3x3 · (n_L · l2b3x3)) (I1), which
// here is measurably not the inverse-transpose normal, nor the local one.
TEST_P(D3D12Contract, NormalIsUnitAndTransformedAsTheHlslDoes) {
    const Matrix3x4 M = shearedInstance();
    // The same object-space ray as p.ray under the (0, 1, 0) instance: t keeps its meaning (the direction is not
    // renormalised).
    const vec3 objectOrigin = p.ray.Origin - vec3(0, 1, 0);
    ContractRig rig(precision, p, M);
    rig.ray = {M.transformPoint(objectOrigin), 0.0f, M.transformVector(p.ray.Direction), 10000.0f};
    const Outcome o = rig.trace();
    ASSERT_TRUE(o.hit());
    EXPECT_NEAR(o.t, first.t, 1e-3f * first.t);
    const dvec3 n(o.normal);
    EXPECT_NEAR(glm::length(n), 1.0, 1e-5);

    // The object ray exactly as the emulator forms it (WorldToObject3x4 = affineInverse(ObjectToWorld)).
    const Matrix3x4 w2o = *affineInverse(M);
    const vec3 oObj = w2o.transformPoint(rig.ray.Origin);
    const vec3 dObj = w2o.transformVector(rig.ray.Direction);
    const dvec3 nL = precision == Precision::Double ? localNormal<double>(p, oObj, dObj)
                                                    : dvec3(localNormal<float>(p, oObj, dObj));
    const PrimitiveInstancePerFrameBuffer m = transforms(p);
    D3 objectToWorld{}, localToObject{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            objectToWorld[i][j] = M.m[i][j];
            localToObject[i][j] = m.localSpaceToBottomLevelAS.m[j][i];  // row-vector form, transposed
        }
    const D3 A = product(objectToWorld, localToObject);
    const dvec3 forward = glm::normalize(times(A, nL));
    EXPECT_LT(glm::length(n - forward), 1e-5) << "world normal";
    const dvec3 inverseTransposed = glm::normalize(times(inverseTranspose(A), nL));
    EXPECT_GT(glm::length(n - inverseTransposed), 0.02) << "I1: the forward matrix, not the inverse transpose";
    EXPECT_GT(glm::length(n - glm::normalize(nL)), 0.05) << "the normal is in world space";
}

std::vector<ContractParam> allParams() {
    std::vector<ContractParam> params;
    for (int i = 0; i < int(std::size(kPrimitives)); ++i)
        for (const Precision precision : {Precision::Float, Precision::Double}) params.push_back({precision, i});
    return params;
}

INSTANTIATE_TEST_SUITE_P(D3D12, D3D12Contract, testing::ValuesIn(allParams()), paramName);
INSTANTIATE_TEST_SUITE_P(D3D12, D3D12FarSide,
                         testing::Values(ContractParam{Precision::Float, 1}, ContractParam{Precision::Double, 1},
                                         ContractParam{Precision::Float, 2}, ContractParam{Precision::Double, 2}),
                         paramName);

// ---- Float vs double ----------------------------------------------------------------------------------------

// PORT (makeD3D12ShaderLibrary's precision): each primitive's ray traced with the float and the double library.
// Bounds, per intersection test (u = 2^-24 ~ 6e-8; t is 3-10 here, so one ulp of t is up to 1e-6):
//   analytic box: the slab t = (B - o)·(1/d) is a handful of float operations: |dt| <= 1e-5 (~10 ulps); the face
//     normal is an exact axis in both, so the world normals are equal to ~1e-7 (bound 1e-6 rad);
//   spheres: the stable quadratic root loses no digits (disc >> 0 away from the silhouette): |dt| <= 1e-5; the
//     normal normalize(o + t·d - c) moves by |dt|/r: bound 1e-4 rad;
//   metaballs: the hit is a sample of the 128-step march; both precisions take the same sample unless the field
//     crosses 0.25 within float noise of one, so |dt| is the rounding of tmin + k·step: bound 1e-4 (the step is
//     ~0.02, so a different sample would fail it). The central difference divides field differences of ~1e-5 by
//     e = 5.8e-6 (H11): float rounding of the ~0.25 field (1.5e-8) is ~1e-3 of that, so the normal angle bound is
//     2e-2 rad (H11 quotes 0.1-0.3% of normal error);
//   SDFs: sphere tracing stops once dist <= 1e-4·t, so a step more or less moves t by up to ~1e-4·t; the bound
//     is 2e-4·t. The tetrahedral normal divides distance differences over e = 5.8e-5 by e; float rounding of the
//     distance (~1e-7) gives ~2e-3, bound 2e-2 rad. (The math headers' SDF literals such as 0.65 or 0.894 are
//     written T(0.65), so double mode also uses their double values; that moves the surface by < 1e-7.)
TEST(D3D12Precision, FloatAndDoubleAgreeWithinTheStatedBounds) {
    for (const Primitive& p : kPrimitives) {
        Outcome o[2];
        for (int k = 0; k < 2; ++k) {
            ContractRig rig(k == 0 ? Precision::Float : Precision::Double, p);
            rig.ray = p.ray;
            o[k] = rig.trace();
            ASSERT_TRUE(o[k].hit()) << p.name;
        }
        const double dt = std::fabs(double(o[0].t) - double(o[1].t));
        const double angle = angleBetween(o[0].normal, o[1].normal);
        std::printf("[precision] %s: t float %.9g double %.9g |dt| %.3g normal angle %.3g rad\n", p.name,
                    double(o[0].t), double(o[1].t), dt, angle);
        double tBound = 1e-5, angleBound = 1e-4;
        if (p.is == IS::Analytic && p.primitiveType == AnalyticPrimitive::AABB) angleBound = 1e-6;
        if (p.is == IS::Volumetric) tBound = 1e-4, angleBound = 2e-2;
        if (p.is == IS::SignedDistance) tBound = 2e-4 * double(o[1].t), angleBound = 2e-2;
        EXPECT_LE(dt, tBound) << p.name;
        EXPECT_LE(angle, angleBound) << p.name;
    }
}

}  // namespace
}  // namespace refray::procedural::d3d12
