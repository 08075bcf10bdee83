// Tests procedural/proceduray/proceduray_shaders.cpp: the export table, the HLSL struct layouts, the root
// signatures, and end-to-end dispatches through a tiny Device scene that reproduce fact-sheet hazards
// (H1 on a Pac-man, H14 on the Mandelbulb) and the Pac-man's shaded colour.
#include "procedural/proceduray/proceduray_shaders.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "emulator/device.h"
#include "emulator/shader_api.h"
#include "emulator/trace.h"
#include "procedural/math/fractals.h"
#include "procedural/math/sdf.h"

namespace refray::procedural::proceduray {
namespace {

using namespace refray::dxr;

// ---- Exports --------------------------------------------------------------------------------------

TEST(ProcedurayShaders, EveryHlslExportExistsWithItsStage) {
    const auto lib = makeProcedurayShaderLibrary();
    const std::map<std::string, ShaderStage> expected = {
        {"Raygen", ShaderStage::RayGeneration},
        {"Miss", ShaderStage::Miss},
        {"Miss_Shadow", ShaderStage::Miss},
        {"ClosestHit_Triangle", ShaderStage::ClosestHit},
        {"Intersection_Julia", ShaderStage::Intersection},
        {"ClosestHit_Julia", ShaderStage::ClosestHit},
        {"Intersection_Pacman", ShaderStage::Intersection},
        {"ClosestHit_Pacman", ShaderStage::ClosestHit},
        {"Intersection_Mandelbulb", ShaderStage::Intersection},
        {"ClosestHit_Mandelbulb", ShaderStage::ClosestHit},
    };
    EXPECT_EQ(lib->exports().size(), expected.size());
    for (const auto& [name, stage] : expected) {
        const ShaderExport* e = lib->find(name);
        ASSERT_NE(e, nullptr) << name;
        EXPECT_EQ(e->stage, stage) << name;
    }
}

// PORT (makeProcedurayShaderLibrary's precision): the double library has the same exports and interface types;
// proceduray_contract_test.cpp runs every intersection shader in both and bounds the differences.
TEST(ProcedurayShaders, PORT_DoublePrecisionLibraryHasTheSameInterface) {
    const auto f = makeProcedurayShaderLibrary(Precision::Float);
    const auto d = makeProcedurayShaderLibrary(Precision::Double);
    ASSERT_EQ(f->exports().size(), d->exports().size());
    for (const auto& [name, e] : f->exports()) {
        const ShaderExport* other = d->find(name);
        ASSERT_NE(other, nullptr) << name;
        EXPECT_EQ(other->stage, e.stage) << name;
        EXPECT_EQ(other->payload, e.payload) << name;
        EXPECT_EQ(other->attributes, e.attributes) << name;
    }
}

TEST(ProcedurayShaders, ExportsDeclareTheHlslPayloadAndAttributeTypes) {
    const auto lib = makeProcedurayShaderLibrary();
    EXPECT_EQ(lib->find("Miss")->payload, typeTag<RayPayload>());
    EXPECT_EQ(lib->find("Miss_Shadow")->payload, typeTag<ShadowRayPayload>());
    EXPECT_EQ(lib->find("ClosestHit_Triangle")->attributes, typeTag<BuiltInTriangleIntersectionAttributes>());
    for (const char* name : {"Julia", "Pacman", "Mandelbulb"}) {
        EXPECT_EQ(lib->find(std::string("Intersection_") + name)->attributes, typeTag<ProceduralPrimitiveAttributes>());
        EXPECT_EQ(lib->find(std::string("ClosestHit_") + name)->attributes, typeTag<ProceduralPrimitiveAttributes>());
        EXPECT_EQ(lib->find(std::string("ClosestHit_") + name)->payload, typeTag<RayPayload>());
    }
}

TEST(ProcedurayShaders, HitGroupsImportTheLibraryExports) {
    const auto lib = makeProcedurayShaderLibrary();
    const auto groups = procedurayHitGroups();
    EXPECT_EQ(groups.size(), 8u);
    for (const HitGroupDesc& g : groups) {
        for (const std::string& import : {g.ClosestHitShaderImport, g.IntersectionShaderImport}) {
            if (!import.empty()) {
                EXPECT_NE(lib->find(import), nullptr) << g.HitGroupExport << " imports " << import;
            }
        }
        EXPECT_TRUE(g.AnyHitShaderImport.empty());
    }
}

// ---- Layouts --------------------------------------------------------------------------------------

TEST(ProcedurayShaders, StructLayoutsMatchTheHlsl) {
    EXPECT_EQ(sizeof(RayPayload), 32u);
    EXPECT_EQ(offsetof(RayPayload, recursionDepth), 16u);
    EXPECT_EQ(offsetof(RayPayload, hit), 28u);
    EXPECT_EQ(sizeof(ShadowRayPayload), 8u);
    EXPECT_EQ(sizeof(ProceduralPrimitiveAttributes), 28u);
    EXPECT_EQ(offsetof(ProceduralPrimitiveAttributes, color), 12u);
    EXPECT_EQ(sizeof(PrimitiveConstantBuffer), 48u);
    EXPECT_EQ(offsetof(PrimitiveConstantBuffer, stepScale), 32u);
    EXPECT_EQ(sizeof(PrimitiveInstanceConstantBuffer), 8u);
    EXPECT_EQ(sizeof(ProceduralRootArguments), 56u);
    EXPECT_EQ(offsetof(ProceduralRootArguments, aabbCB), 48u);
    EXPECT_EQ(sizeof(SceneConstantBuffer), 144u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, cameraPosition), 64u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, lightDiffuseColor), 112u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, elapsedTime), 132u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, debugFlag), 136u);
    EXPECT_EQ(sizeof(InstanceBuffer), 128u);
    EXPECT_EQ(sizeof(Vertex), 24u);
}

TEST(ProcedurayShaders, RootSignaturesFollowTheBuilder) {
    const auto global = RootSignature::create(globalRootSignatureDesc());
    ASSERT_EQ(global->parameterCount(), 5u);
    EXPECT_EQ(global->parameter(kOutputView).parameterType, RootParameterType::DescriptorTable);
    EXPECT_EQ(global->parameter(kAccelerationStructure).parameterType, RootParameterType::SRV);
    EXPECT_EQ(global->parameter(kSceneConstantBuffer).parameterType, RootParameterType::CBV);
    EXPECT_EQ(global->parameter(kInstanceBuffer).parameterType, RootParameterType::SRV);
    EXPECT_EQ(global->parameter(kInstanceBuffer).shaderRegister, 3u);
    EXPECT_EQ(global->parameter(kVertexBuffers).ranges.at(0).numDescriptors, 2u);
    EXPECT_EQ(global->parameter(kVertexBuffers).ranges.at(0).baseShaderRegister, 1u);

    const auto triangle = RootSignature::create(triangleLocalRootSignatureDesc());
    EXPECT_EQ(triangle->name(), "Triangle");
    EXPECT_EQ(triangle->recordSize(), 32u + 48u);
    const auto procedural = RootSignature::create(proceduralLocalRootSignatureDesc());
    EXPECT_EQ(procedural->name(), "Procedural");
    EXPECT_EQ(procedural->argumentOffset(kAABBConstantBuffer), 32u + 48u);
    EXPECT_EQ(procedural->recordSize(), 32u + 56u);  // the 88 B that round up to the 96 B stride of §1.5
}

// ---- Pure helpers ---------------------------------------------------------------------------------

TEST(ProcedurayShaders, SlabTrianglesUseTheOutwardNegatedFirstNormal) {
    const auto* bytes = reinterpret_cast<const uint8_t*>(kSlabIndices.data());
    const vec3 outward[6] = {{0, 0, 1}, {0, -1, 0}, {0, 0, -1}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
    for (uint32_t primitive = 0; primitive < 12; ++primitive) {
        const uvec3 i = Load3x16BitIndices(primitive * 6, bytes, sizeof(kSlabIndices));
        EXPECT_EQ(i, uvec3(kSlabIndices[primitive * 3], kSlabIndices[primitive * 3 + 1], kSlabIndices[primitive * 3 + 2]));
        EXPECT_EQ(-kSlabVertices[i.x].normal, outward[primitive / 2]) << "triangle " << primitive;
    }
    // Past the end of the buffer the loads read 0.
    EXPECT_EQ(Load3x16BitIndices(72, bytes, sizeof(kSlabIndices)), uvec3(0));
}

TEST(ProcedurayShaders, FresnelAndCameraRay) {
    const vec3 f = FresnelReflectanceSchlick(vec3(0, 0, -1), vec3(0, 0, 1), vec3(1.0f, 0.9f, 0.7f));
    EXPECT_NEAR(f.y, 0.9f, 1e-6f);  // head-on: f0
    const vec3 grazing = FresnelReflectanceSchlick(vec3(1, 0, 0), vec3(0, 0, 1), vec3(0.0f));
    EXPECT_NEAR(grazing.x, 1.0f, 1e-6f);

    Float4x4 p2w;  // row 3 alone decides the pixel-centre ray of a 1x1 dispatch
    p2w.m[3] = {35.0f, -45.0f, 40.0f, 1.0f};
    vec3 origin, direction;
    GenerateCameraRay(uvec2(0), uvec2(1), vec3(35, -45, 50), p2w, origin, direction);
    EXPECT_EQ(origin, vec3(35, -45, 50));
    EXPECT_EQ(direction, vec3(0, 0, -1));
}

// ---- A tiny scene ---------------------------------------------------------------------------------

// The instance buffer's matrices in row-vector form (§1.7): local = world · inverse(M).
using procedural::rowVectorForm;

// The material table of §1.8.
constexpr PrimitiveConstantBuffer kPacmanMaterial{{1, 1, 0, 1}, 0.3f, 0.3f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
constexpr PrimitiveConstantBuffer kMandelbulbMaterial{{1, 1, 0, 1}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};

// What the probe closest hit saw.
struct Probe {
    int closestHits = 0;
    int misses = 0;
    float t = -1.0f;
    uint32_t hitKind = ~0u;
    vec3 hitWorldPosition{0.0f};
    ProceduralPrimitiveAttributes attr{};
};

// One instance (an AABB or the slab), the library's shaders, probe shaders and every global argument.
class ProcedurayRig {
public:
    // `instanceIndex` is the procedural ordinal (l_aabbCB.instanceIndex): the instance buffer gets 4
    // elements, with inverse(M) in that one (§1.7).
    ProcedurayRig(RaytracingAABB box, const Matrix3x4& transform, uint32_t instanceIndex, SignedDistancePrimitive type,
                  const PrimitiveConstantBuffer& material)
        : aabbCB_{instanceIndex, uint32_t(type)}, material_(material) {
        GeometryDesc g;
        g.Type = GeometryType::ProceduralPrimitiveAABBs;
        g.Flags = GEOMETRY_FLAG_OPAQUE;
        g.AABBs.AABBCount = 1;
        g.AABBs.AABBs = {device.memory().upload(&box, sizeof box, "AABB"), sizeof box};
        build(g, transform, instanceIndex);
    }

    // The slab (G0) with the plane material: an indexed triangle instance.
    ProcedurayRig(const Matrix3x4& transform, const PrimitiveConstantBuffer& material)
        : material_(material), triangles_(true) {
        GpuMemory& memory = device.memory();
        GeometryDesc g;
        g.Type = GeometryType::Triangles;
        g.Flags = GEOMETRY_FLAG_OPAQUE;
        g.Triangles.IndexFormat = Format::R16_UINT;
        g.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
        g.Triangles.IndexCount = uint32_t(kSlabIndices.size());
        g.Triangles.VertexCount = uint32_t(kSlabVertices.size());
        g.Triangles.IndexBuffer = memory.upload(kSlabIndices.data(), sizeof(kSlabIndices), "slab indices");
        g.Triangles.VertexBuffer = {memory.upload(kSlabVertices.data(), sizeof(kSlabVertices), "slab vertices"),
                                    sizeof(Vertex)};
        build(g, transform, 0);
    }

    // Binds `vertices` as g_vertices (descriptor 2 of the heap, 1 of the table at global parameter 4); the view
    // covers the first `viewVertices` of them.
    void bindVertices(const std::array<Vertex, 8>& vertices, uint32_t viewVertices = 8) {
        heap_->setBuffer(2, DescriptorRangeType::SRV,
                         {device.memory().upload(vertices.data(), sizeof(vertices), "g_vertices"),
                          viewVertices * sizeof(Vertex), sizeof(Vertex)});
    }

    // The ray the probe ray generation traces with the radiance arguments of §1.4.
    RayDesc probeRay;
    SceneConstantBuffer scene{};
    Image output{1, 1};
    Probe probe;
    Device device;
    TraceRayArgumentSet traceRay = defaultTraceRayArguments();  // of the library under test
    TraceObserver* observer = nullptr;                           // of the dispatch

    // Dispatches 1x1 with ray generation `rayGen` and the hit-group records [radiance, shadow] of
    // `hitGroup`; the radiance miss is `radianceMiss`.
    DispatchResult dispatch(const std::string& rayGen, const std::string& hitGroup, const std::string& radianceMiss) {
        StateObjectDesc desc;
        desc.name = "proceduray test";
        desc.libraries = {{makeProcedurayShaderLibrary(Precision::Float, traceRay), {}}, {probes_, {}}};
        desc.hitGroups = procedurayHitGroups();
        std::vector<std::string> procedural = {"HitGroup_Pacman",     "HitGroup_Pacman_Shadow", "HitGroup_Mandelbulb",
                                               "HitGroup_Mandelbulb_Shadow", "HitGroup_Julia", "HitGroup_Julia_Shadow"};
        for (const char* is : {"Intersection_Pacman", "Intersection_Mandelbulb", "Intersection_Julia"}) {
            desc.hitGroups.push_back({std::string("Probe_") + is, HitGroupType::ProceduralPrimitive, "", "CH_Probe", is});
            procedural.push_back(std::string("Probe_") + is);
        }
        const RootSignaturePtr triangleSignature = RootSignature::create(triangleLocalRootSignatureDesc());
        const RootSignaturePtr proceduralSignature = RootSignature::create(proceduralLocalRootSignatureDesc());
        const RootSignaturePtr globalSignature = RootSignature::create(globalRootSignatureDesc());
        desc.localRootSignatures = {{triangleSignature, {"HitGroup_Triangle", "HitGroup_Triangle_Shadow"}},
                                    {proceduralSignature, procedural}};
        desc.globalRootSignatures = {{globalSignature, {}}};
        desc.shaderConfigs = {{sizeof(RayPayload), sizeof(ProceduralPrimitiveAttributes)}};
        desc.pipelineConfigs = {{MAX_RAY_RECURSION_DEPTH, PIPELINE_FLAG_NONE}};
        const StateObjectPtr so = StateObject::create(desc);

        GpuMemory& memory = device.memory();
        LocalRootArguments arguments(triangles_ ? triangleSignature : proceduralSignature);
        arguments.setConstants(kMaterialConstantBuffer, material_);
        if (!triangles_) arguments.setConstants(kAABBConstantBuffer, aabbCB_);
        const std::string shadowGroup = hitGroup.starts_with("Probe_Intersection_")
                                            ? "HitGroup_" + hitGroup.substr(19) + "_Shadow"
                                            : hitGroup + "_Shadow";
        const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier(rayGen)).upload(memory);
        DispatchRaysDesc rays;
        rays.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
        rays.MissShaderTable = ShaderTableBuilder("miss")
                                   .addRecord(so->shaderIdentifier(radianceMiss))
                                   .addRecord(so->shaderIdentifier("Miss_Shadow"))
                                   .upload(memory);
        rays.HitGroupTable = ShaderTableBuilder("hit groups")
                                 .addRecord(so->shaderIdentifier(hitGroup), arguments)
                                 .addRecord(so->shaderIdentifier(shadowGroup), arguments)
                                 .upload(memory);
        rays.Width = rays.Height = rays.Depth = 1;

        GlobalRootArguments globals(globalSignature);
        globals.setDescriptor(kOutputView, heap_->gpuHandle(0));
        globals.setDescriptor(kAccelerationStructure, tlas_);
        globals.setDescriptor(kSceneConstantBuffer, memory.upload(&scene, sizeof scene, "g_sceneCB"));
        globals.setDescriptor(kInstanceBuffer, instanceBuffer_);
        globals.setDescriptor(kVertexBuffers, heap_->gpuHandle(1));
        DispatchOptions options;
        options.threads = 1;
        options.observer = observer;
        return device.dispatchRays(rays, so, &globals, options);
    }

private:
    void build(const GeometryDesc& g, const Matrix3x4& transform, uint32_t instanceIndex) {
        GpuMemory& memory = device.memory();
        const GpuVirtualAddress blas = device.buildBottomLevelAS({BUILD_FLAG_NONE, {g}});
        const std::vector<InstanceDesc> instances = {makeInstanceDesc(transform, 0, 1, 0, INSTANCE_FLAG_NONE, blas)};
        tlas_ = device.buildTopLevelAS({BUILD_FLAG_NONE, 1, ElementsLayout::Array, memory.upload(instances, "instances")});

        std::vector<InstanceBuffer> instanceBuffer(4);
        instanceBuffer.at(instanceIndex) = {rowVectorForm(*affineInverse(transform)), rowVectorForm(transform)};
        instanceBuffer_ = memory.upload(instanceBuffer, "g_instanceBuffer");

        heap_ = &device.createDescriptorHeap(3, "proceduray test heap");
        heap_->setTexture2D(0, DescriptorRangeType::UAV, &output);
        heap_->setBuffer(1, DescriptorRangeType::SRV,
                         {memory.upload(kSlabIndices.data(), sizeof(kSlabIndices), "g_indices"), sizeof(kSlabIndices), 0});
        heap_->setBuffer(2, DescriptorRangeType::SRV,
                         {memory.upload(kSlabVertices.data(), sizeof(kSlabVertices), "g_vertices"),
                          sizeof(kSlabVertices), sizeof(Vertex)});

        scene.cameraPosition = vec4(0, 0, 50, 1);
        scene.lightPosition = vec4(0, 18, -20, 0);
        scene.lightAmbientColor = vec4(0.25f, 0.25f, 0.25f, 1.0f);
        scene.lightDiffuseColor = vec4(0.6f, 0.6f, 0.6f, 1.0f);
        scene.reflectance = 0.0f;
        scene.elapsedTime = 0.0f;  // T0
        scene.debugFlag = 0;
        scene.padding = 0;
        for (int i = 0; i < 4; ++i) scene.projectionToWorld.m[i][i] = 1.0f;

        addProbeShaders();
    }

    void addProbeShaders() {
        probes_->addRayGeneration("RG_Probe", [this](ShaderContext& ctx) {
            RayPayload payload{vec4(0.0f), 1, 0.0f, 0, 0};
            ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure), RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
                         kInstanceMask, Radiance, RayTypeCount, Radiance, probeRay, payload);
        });
        probes_->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
            "CH_Probe", [this](ShaderContext& ctx, RayPayload&, const ProceduralPrimitiveAttributes& attr) {
                probe.closestHits++;
                probe.t = ctx.RayTCurrent();
                probe.hitKind = ctx.HitKind();
                probe.hitWorldPosition = ctx.WorldRayOrigin() + ctx.RayTCurrent() * ctx.WorldRayDirection();
                probe.attr = attr;
            });
        probes_->addMiss<RayPayload>("Miss_Probe", [this](ShaderContext&, RayPayload&) { probe.misses++; });
    }

    PrimitiveInstanceConstantBuffer aabbCB_{};
    PrimitiveConstantBuffer material_;
    bool triangles_ = false;
    std::shared_ptr<ShaderLibrary> probes_ = std::make_shared<ShaderLibrary>();
    GpuVirtualAddress tlas_ = 0;
    GpuVirtualAddress instanceBuffer_ = 0;
    DescriptorHeap* heap_ = nullptr;
};

// Pac-man A of §1.2: S(50)·T(35,-35,0), AABB [-0.5,0.5]^3, procedural ordinal 1.
ProcedurayRig pacmanA() {
    return ProcedurayRig({-0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f},
                         Matrix3x4::translation(vec3(35, -35, 0)) * Matrix3x4::scale(vec3(50)), 1,
                         SignedDistancePrimitive::IntersectedRoundCube, kPacmanMaterial);
}

// H1: the Pac-man reports t in normalised local units. The true surface is at world z = 22.913 (t = 27.09),
// but t_rep = 1 - sqrt(0.25 - 0.04) = 0.54173 is committed, so HitWorldPosition lands at z = 49.458.
TEST(ProcedurayShaders, H1_PacmanReportsTInLocalUnits) {
    ProcedurayRig rig = pacmanA();
    rig.probeRay = {vec3(35, -45, 50), 0.0f, vec3(0, 0, -1), 10000.0f};
    rig.dispatch("RG_Probe", "Probe_Intersection_Pacman", "Miss_Probe");

    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_EQ(rig.probe.misses, 0);
    EXPECT_NEAR(rig.probe.t, 0.54173f, 1e-4f);
    EXPECT_EQ(rig.probe.hitKind, 0u);
    EXPECT_NEAR(rig.probe.hitWorldPosition.x, 35.0f, 1e-4f);
    EXPECT_NEAR(rig.probe.hitWorldPosition.y, -45.0f, 1e-4f);
    EXPECT_NEAR(rig.probe.hitWorldPosition.z, 49.458f, 1e-3f);
    EXPECT_NEAR(rig.probe.attr.normal.x, 0.0f, 1e-3f);
    EXPECT_NEAR(rig.probe.attr.normal.y, -0.4f, 1e-3f);
    EXPECT_NEAR(rig.probe.attr.normal.z, 0.9165f, 1e-3f);
    EXPECT_EQ(rig.probe.attr.color, vec4(1.0f));  // the head is white
}

// H14: at T0 the Mandelbulb marches 4 steps and reports the unconverged shell as a hit.
TEST(ProcedurayShaders, H14_MandelbulbReportsAnUnconvergedHitAtT0) {
    ProcedurayRig rig({-1.5f, -1.5f, -1.5f, 1.5f, 1.5f, 1.5f},
                      Matrix3x4::translation(vec3(0, -50, 115)) * Matrix3x4::scale(vec3(40)), 3,
                      SignedDistancePrimitive::Mandelbulb, kMandelbulbMaterial);
    rig.probeRay = {vec3(35, -45, 100), 0.0f, vec3(0, 0, -1), 10000.0f};
    rig.dispatch("RG_Probe", "Probe_Intersection_Mandelbulb", "Miss_Probe");

    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 0.02999f, 1e-4f);
    EXPECT_GT(rig.probe.attr.color.x, 0.0f);  // the orbit trap's final |w|^2
}

// H9: a ray up into the Julia's cut face (the Julia instance of §1.2 with its exact float32 matrix) reports
// t in q-space units; measured t_rep = 0.6667 at x = 0.
TEST(ProcedurayShaders, H9_JuliaReportsTInQSpaceUnits) {
    Matrix3x4 m;
    m.m[0] = {100.0f, 0.0f, 0.0f, 0.0f};
    m.m[1] = {0.0f, -29.9999962f, 0.0507354662f, 130.0f};
    m.m[2] = {0.0f, -0.0152206402f, -99.9999847f, 75.0f};
    constexpr PrimitiveConstantBuffer kJuliaMaterial{{1.0f, 0.5f, 0.5f, 1.0f}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
    ProcedurayRig rig({-3.5f, -3.5f, -3.5f, 3.5f, 3.5f, 3.5f}, m, 0, SignedDistancePrimitive::JuliaSets, kJuliaMaterial);
    rig.probeRay = {vec3(0, 20, 74.96f), 0.0f, vec3(0, 1, 0), 10000.0f};
    rig.dispatch("RG_Probe", "Probe_Intersection_Julia", "Miss_Probe");

    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 0.6667f, 1e-3f);
    EXPECT_EQ(rig.probe.attr.color.x, rig.probe.t);  // attr.color = (t, n, 0, 0)
    EXPECT_GT(rig.probe.attr.color.y, 0.0f);
}

TEST(ProcedurayShaders, DebugFlagMakesIntersectionShadersReportKindOneAtZero) {
    ProcedurayRig rig = pacmanA();
    rig.scene.debugFlag = 1;
    rig.probeRay = {vec3(35, -45, 50), 0.0f, vec3(0, 0, -1), 10000.0f};
    rig.dispatch("RG_Probe", "Probe_Intersection_Pacman", "Miss_Probe");
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_EQ(rig.probe.t, 0.0f);
    EXPECT_EQ(rig.probe.hitKind, 1u);
}

// The whole pipeline on one pixel: Raygen -> Intersection_Pacman -> ClosestHit_Pacman, which traces a
// shadow ray (it misses: the light is off the sphere) and a reflection ray (it misses: background).
// The expected colour is the Phong + Fresnel of §3.1/§3.3 evaluated here in double.
TEST(ProcedurayShaders, RaygenShadesThePacmanHeadWithPhongAndReflection) {
    ProcedurayRig rig = pacmanA();
    rig.scene.cameraPosition = vec4(35, -45, 50, 1);
    rig.scene.projectionToWorld.m[3] = {35.0f, -45.0f, 40.0f, 1.0f};  // pixel (0,0) of 1x1 looks along -z
    const DispatchResult result = rig.dispatch("Raygen", "HitGroup_Pacman", "Miss");
    EXPECT_EQ(result.stats.raysTraced, 3u);  // primary, shadow, reflection
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 2u);
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::ClosestHit), 1u);

    const dvec3 D(0, 0, -1);
    const double t = 1.0 - std::sqrt(0.21);
    const dvec3 P = dvec3(35, -45, 50) + t * D;
    const dvec3 N = glm::normalize(dvec3(0, -0.2, std::sqrt(0.21)));
    const dvec3 L = glm::normalize(P - dvec3(0, 18, -20));
    const double Kd = std::clamp(glm::dot(-L, N), 0.0, 1.0);
    const dvec3 R = glm::normalize(L - 2.0 * glm::dot(N, L) * N);
    const double Ks = std::pow(std::clamp(glm::dot(R, -D), 0.0, 1.0), 50.0);
    const double a = 1.0 - std::clamp(-N.y, 0.0, 1.0);
    const glm::dvec4 albedo(1, 1, 0, 1), A(0.25, 0.25, 0.25, 1);
    const glm::dvec4 ambient = albedo * ((A - 0.1) + a * 0.1);
    const glm::dvec4 diffuse = 0.3 * Kd * glm::dvec4(0.6, 0.6, 0.6, 1) * albedo;
    const glm::dvec4 specular(0.7 * Ks);
    const double cosi = glm::dot(-D, N);
    const dvec3 f0(1, 1, 0);
    const dvec3 F = f0 + (1.0 - f0) * std::pow(1.0 - cosi, 5.0);
    const glm::dvec4 reflected = 0.3 * glm::dvec4(F, 1) * glm::dvec4(0.6, 0.7, 0.9, 1.0);
    const glm::dvec4 expected = ambient + diffuse + specular + reflected;  // head colour is white

    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-3) << "component " << c;
}

// The colour of ClosestHit_Triangle on the slab's top face P = (0, 3, 0), seen straight down (D = -y), lit, with the
// background as the reflection, for the normal N it read from g_vertices (§3.1/§3.3, in double).
glm::dvec4 expectedSlabTopColor(const dvec3& N) {
    const dvec3 D(0, -1, 0), P(0, 3, 0);
    const dvec3 L = glm::normalize(P - dvec3(0, 18, -20));
    const double Kd = std::clamp(glm::dot(-L, N), 0.0, 1.0);
    const dvec3 R = glm::normalize(L - 2.0 * glm::dot(N, L) * N);
    const double Ks = std::pow(std::clamp(glm::dot(R, -D), 0.0, 1.0), 50.0);
    const glm::dvec4 albedo(1.0, 0.9, 0.7, 1.0), A(0.25, 0.25, 0.25, 1), background(0.6, 0.7, 0.9, 1.0);
    const double a = 1.0 - std::clamp(-N.y, 0.0, 1.0);
    const dvec3 f0(albedo);
    const dvec3 F = f0 + (1.0 - f0) * std::pow(1.0 - std::clamp(glm::dot(-D, N), 0.0, 1.0), 5.0);
    return albedo * ((A - 0.1) + a * 0.1) + Kd * glm::dvec4(0.6, 0.6, 0.6, 1) * albedo + glm::dvec4(0.4 * Ks) +
           0.25 * glm::dvec4(F, 1.0) * background;
}

constexpr PrimitiveConstantBuffer kSlabMaterial{{1.0f, 0.9f, 0.7f, 1.0f}, 0.25f, 1.0f, 0.4f, 50.0f, 1.0f, vec3(0.0f)};

// Renders the slab's top face from above through Raygen -> ClosestHit_Triangle; `bind` may rebind g_vertices.
// With a normal that points along the face (`lit` false) the rays are not checked: a zero normal sends the
// reflection ray down into the slab.
template <class Bind>
vec4 renderSlabTop(Bind&& bind, bool lit = true) {
    ProcedurayRig rig(Matrix3x4::scale(vec3(120, 15, 120)), kSlabMaterial);
    bind(rig);
    rig.scene.cameraPosition = vec4(0, 10, 0, 1);
    rig.scene.projectionToWorld.m[3] = {0.0f, 9.0f, 0.0f, 1.0f};  // looks along -y
    const DispatchResult result = rig.dispatch("Raygen", "HitGroup_Triangle", "Miss");
    if (lit) {
        EXPECT_EQ(result.stats.raysTraced, 3u);  // primary, shadow, reflection
        EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 2u);
    }
    return rig.output.at(0, 0);
}

// ClosestHit_Triangle on the slab's top face (triangles 6-7, N = -stored normal = +y) seen from above:
// lit (the shadow ray leaves the face, which is back-facing to it), reflection = background.
TEST(ProcedurayShaders, RaygenShadesTheSlabTopWithPhongAndReflection) {
    const vec4 got = renderSlabTop([](ProcedurayRig&) {});
    const glm::dvec4 expected = expectedSlabTopColor(dvec3(0, 1, 0));
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
}

// ClosestHit_Triangle reads g_indices / g_vertices through the descriptor table of global parameter 4 (the rig
// binds both views, as the scene does): the top face's first index is 3, and giving g_vertices[3] the stored
// normal +y (so N = -y) shades the same hit as a face turned down: 0.15 ambient, no diffuse, Fresnel factor 1.
TEST(ProcedurayShaders, ClosestHitTriangleReadsTheBoundVertexBuffer) {
    const vec4 got = renderSlabTop([](ProcedurayRig& rig) {
        std::array<Vertex, 8> vertices = kSlabVertices;
        vertices[3].normal = vec3(0, 1, 0);
        rig.bindVertices(vertices);
    });
    const glm::dvec4 expected = expectedSlabTopColor(dvec3(0, -1, 0));
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
    EXPECT_GT(std::fabs(double(got.x) - expectedSlabTopColor(dvec3(0, 1, 0)).x), 0.1);
}

// A g_vertices view that ends before vertex 3 reads zeros there (D3D out-of-range loads): the same colour as a
// bound vertex 3 whose normal is zero.
TEST(ProcedurayShaders, ClosestHitTriangleReadsZerosPastTheEndOfTheView) {
    const vec4 truncated = renderSlabTop([](ProcedurayRig& rig) { rig.bindVertices(kSlabVertices, 3); }, false);
    const vec4 zeroNormal = renderSlabTop(
        [](ProcedurayRig& rig) {
            std::array<Vertex, 8> vertices = kSlabVertices;
            vertices[3].normal = vec3(0.0f);
            rig.bindVertices(vertices);
        },
        false);
    EXPECT_EQ(truncated, zeroNormal);
    EXPECT_NE(truncated, renderSlabTop([](ProcedurayRig&) {}));
}

// PORT (Raygen): the render target keeps the float colour; quantisation to R8G8B8A8_UNORM happens only when
// the image is written out. The Pac-man head's red and green channels are not multiples of 1/255.
TEST(ProcedurayShaders, PORT_RaygenStoresUnquantisedFloats) {
    ProcedurayRig rig = pacmanA();
    rig.scene.cameraPosition = vec4(35, -45, 50, 1);
    rig.scene.projectionToWorld.m[3] = {35.0f, -45.0f, 40.0f, 1.0f};
    rig.dispatch("Raygen", "HitGroup_Pacman", "Miss");
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 2; ++c) {
        const float quantised = std::round(std::clamp(got[c], 0.0f, 1.0f) * 255.0f) / 255.0f;
        EXPECT_GT(std::fabs(got[c] - quantised), 1e-5f) << "component " << c;
    }
}

// What the TraceRay calls of a dispatch passed, and the hit-group records they read (in program order: the rig
// dispatches on one thread).
class TraceRayRecorder final : public TraceObserver {
public:
    struct Call {
        uint32_t payloadSize = 0;
        TraceRayArguments arguments;
    };
    void onEvent(const TraceEvent& e) override {
        if (e.kind == TraceEvent::Kind::TraceRay)
            calls.push_back({e.payloadSize, {e.rayContribution, e.multiplier, e.missShaderIndex, e.instanceInclusionMask}});
        else if (e.kind == TraceEvent::Kind::RecordLookup && e.hasTerms)
            lookups.push_back(e.terms);
    }
    std::vector<Call> calls;
    std::vector<HitGroupIndexTerms> lookups;
};

// Pac-man A's head seen through Raygen, as in RaygenShadesThePacmanHeadWithPhongAndReflection.
vec4 renderPacmanHead(const TraceRayArgumentSet& traceRay, TraceRayRecorder* recorder = nullptr,
                      DispatchResult* result = nullptr) {
    ProcedurayRig rig = pacmanA();
    rig.traceRay = traceRay;
    rig.observer = recorder;
    rig.scene.cameraPosition = vec4(35, -45, 50, 1);
    rig.scene.projectionToWorld.m[3] = {35.0f, -45.0f, 40.0f, 1.0f};
    const DispatchResult r = rig.dispatch("Raygen", "HitGroup_Pacman", "Miss");
    if (result) *result = r;
    return rig.output.at(0, 0);
}

// PORT (makeProcedurayShaderLibrary's traceRay): the shaders pass the library's TraceRay arguments, not the HLSL's
// constants. R = 16 and M = 18 keep only their low 4 bits (0 and 2, IDX-2 warns), and the miss indices' and masks'
// high bits do not count (IDX-7, INST-4), so the primary, shadow and reflection rays run the HLSL's records and
// the pixel is unchanged, while the trace shows the arguments as passed. A radiance mask whose low 8 bits exclude
// the instance (mask 1) makes the primary ray miss.
TEST(ProcedurayShaders, PORT_TraceRayArgumentsComeFromTheLibrary) {
    const vec4 reference = renderPacmanHead(defaultTraceRayArguments());

    TraceRayArgumentSet traceRay;
    traceRay[Radiance] = {16, 18, 0x10000, 0xFFFFFF01};
    traceRay[Shadow] = {1, 3, 0x20001, 0x301};
    TraceRayRecorder recorder;
    DispatchResult result;
    EXPECT_EQ(renderPacmanHead(traceRay, &recorder, &result), reference);
    ASSERT_EQ(recorder.calls.size(), 3u);  // primary, shadow, reflection
    EXPECT_EQ(recorder.calls[0].payloadSize, sizeof(RayPayload));
    EXPECT_EQ(recorder.calls[0].arguments, traceRay[Radiance]);
    EXPECT_EQ(recorder.calls[1].payloadSize, sizeof(ShadowRayPayload));
    EXPECT_EQ(recorder.calls[1].arguments, traceRay[Shadow]);
    EXPECT_EQ(recorder.calls[2].payloadSize, sizeof(RayPayload));
    EXPECT_EQ(recorder.calls[2].arguments, traceRay[Radiance]);
    ASSERT_FALSE(recorder.lookups.empty());
    const HitGroupIndexTerms& primary = recorder.lookups[0];
    EXPECT_EQ(primary.rawRayContribution, 16u);
    EXPECT_EQ(primary.rawMultiplier, 18u);
    EXPECT_EQ(primary.rayContribution, 0u);
    EXPECT_EQ(primary.multiplier, 2u);
    EXPECT_EQ(primary.index, 0u);
    EXPECT_TRUE(result.diagnostics.find("IDX-2").has_value());

    TraceRayArgumentSet masked = defaultTraceRayArguments();
    masked[Radiance].instanceInclusionMask = 0xFFFFFF02;
    EXPECT_EQ(renderPacmanHead(masked), kBackgroundColor);
}

// Pac-man A's mouth axis: o = (35,-35,50), d = -z, i.e. local o = (0,0,1), d = (0,0,-1).
constexpr float kT1 = 15.8429795f;  // tau = 176/300: the mouth wide open

// PORT (GetDistanceFromSignedDistancePrimitive): the mouth interpolant is computed once per IS instead of in
// every distance evaluation. It depends on time only, so the IS's t equals, bit for bit, a march that
// recomputes PacmanMouthInterpolant(time) inside every evaluation, as the HLSL does.
TEST(ProcedurayShaders, PORT_PacmanMouthComputedOncePerIntersectionMatchesPerEvaluation) {
    ProcedurayRig rig = pacmanA();
    rig.scene.elapsedTime = kT1;
    rig.probeRay = {vec3(35, -35, 50), 0.0f, vec3(0, 0, -1), 10000.0f};
    rig.dispatch("RG_Probe", "Probe_Intersection_Pacman", "Miss_Probe");
    ASSERT_EQ(rig.probe.closestHits, 1);

    const float time = kT1;
    const auto perEvaluation = [time](const vec3& p) {
        return math::pacman::pacMan(p, math::pacman::PacmanMouthInterpolant(time));
    };
    const Float4x4 w2o = rowVectorForm(*affineInverse(Matrix3x4::translation(vec3(35, -35, 0)) * Matrix3x4::scale(vec3(50))));
    math::Ray<float> local;
    local.origin = vec3(mul(vec4(35, -35, 50, 1), w2o));
    local.direction = hlsl::normalize(vec3(mul(vec4(0, 0, -1, 0), w2o)));
    hlsl::ScopedFlushDenormals ftz;
    const math::SphereTraceResult<float> hlslForm =
        math::RaySignedDistancePrimitiveTest(local, math::RayExtent<float>{0.0f, 10000.0f, true, false}, perEvaluation);
    ASSERT_TRUE(hlslForm.hit);
    EXPECT_EQ(rig.probe.t, hlslForm.thit);
    // The open mouth moves the hit from the head (0.5 at T0's nearly shut mouth: apex z = 0.45) to the apex
    // at z = 0.5 - (0.05 + 0.4 * 176/300) = 0.2153.
    EXPECT_NEAR(rig.probe.t, 1.0f - 0.2153f, 1e-3f);
}

// PORT (Intersection_Julia): the HLSL's cut animation (iMax from 10.5·time, deltaT) is computed and ignored,
// and the port does not compute it: the Julia's hit does not depend on the time.
TEST(ProcedurayShaders, PORT_JuliaIgnoresTheTime) {
    Matrix3x4 m;
    m.m[0] = {100.0f, 0.0f, 0.0f, 0.0f};
    m.m[1] = {0.0f, -29.9999962f, 0.0507354662f, 130.0f};
    m.m[2] = {0.0f, -0.0152206402f, -99.9999847f, 75.0f};
    constexpr PrimitiveConstantBuffer kJuliaMaterial{{1.0f, 0.5f, 0.5f, 1.0f}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
    Probe first;
    for (const float time : {0.0f, kT1, 7.3f, 100.0f}) {
        ProcedurayRig rig({-3.5f, -3.5f, -3.5f, 3.5f, 3.5f, 3.5f}, m, 0, SignedDistancePrimitive::JuliaSets, kJuliaMaterial);
        rig.scene.elapsedTime = time;
        rig.probeRay = {vec3(0, 20, 74.96f), 0.0f, vec3(0, 1, 0), 10000.0f};
        rig.dispatch("RG_Probe", "Probe_Intersection_Julia", "Miss_Probe");
        ASSERT_EQ(rig.probe.closestHits, 1) << time;
        if (time == 0.0f) {
            first = rig.probe;
            continue;
        }
        EXPECT_EQ(rig.probe.t, first.t) << time;
        EXPECT_EQ(rig.probe.attr.normal, first.attr.normal) << time;
        EXPECT_EQ(rig.probe.attr.color, first.attr.color) << time;
    }
}

}  // namespace
}  // namespace refray::procedural::proceduray
