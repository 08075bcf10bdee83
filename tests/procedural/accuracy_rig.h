// The accuracy-knob tests' rig (accuracy_test.cpp, accuracy_march_test.cpp, accuracy_shading_test.cpp): their
// shorthands, the bit comparison, and both shader libraries through their factories in a small scene with the
// fact sheet's instances and rays.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "core/image.h"
#include "emulator/device.h"
#include "emulator/shader_api.h"
#include "procedural/accuracy.h"
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/math/fractals.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/sdf.h"
#include "procedural/proceduray/proceduray_shaders.h"
#include "tests/procedural/contract_support.h"
#include "tests/procedural/sweep_support.h"

// Its own namespace: other test files of this binary have a Probe, a kJuliaRay and an addJulia of their own.
namespace refray::procedural::accuracy_rig {

using namespace refray::dxr;
using glm::dvec3;
using math::Ray;
using math::RayExtent;
using procedural::fixtures::angleBetween;

template <typename T>
using tvec3 = glm::vec<3, T>;
template <typename T>
using tvec4 = glm::vec<4, T>;

// ---- Bit-exact comparison ---------------------------------------------------------------------------

template <typename T>
auto bitsOf(T x) {
    return std::bit_cast<std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>(x);
}

// =======================================================================================================
// The emulator rig: both libraries through their factories
// =======================================================================================================

// What differs between the two samples for the rig.
struct ProcedurayTraits {
    using SceneConstantBuffer = proceduray::SceneConstantBuffer;
    using RayPayload = proceduray::RayPayload;
    using Attributes = proceduray::ProceduralPrimitiveAttributes;
    static constexpr uint32_t kMaxRecursionDepth = proceduray::MAX_RAY_RECURSION_DEPTH;
    static std::shared_ptr<ShaderLibrary> library(Precision p, const Accuracy& a) {
        return proceduray::makeProcedurayShaderLibrary(p, proceduray::defaultTraceRayArguments(), a);
    }
    static std::vector<HitGroupDesc> hitGroups() { return proceduray::procedurayHitGroups(); }
    static std::vector<std::string> triangleGroups() { return {"HitGroup_Triangle", "HitGroup_Triangle_Shadow"}; }
    static std::vector<std::string> intersections() {
        return {"Intersection_Julia", "Intersection_Pacman", "Intersection_Mandelbulb"};
    }
    static RootSignatureDesc global() { return proceduray::globalRootSignatureDesc(); }
    static RootSignatureDesc triangleLocal() { return proceduray::triangleLocalRootSignatureDesc(); }
    static RootSignatureDesc aabbLocal() { return proceduray::proceduralLocalRootSignatureDesc(); }
    static constexpr const char* kRaygen = "Raygen";
    static constexpr const char* kMiss = "Miss";
    static constexpr const char* kShadowMiss = "Miss_Shadow";
    static constexpr const char* kShadowGroupSuffix = "_Shadow";
    static std::span<const uint16_t> indices() { return proceduray::kSlabIndices; }
    static std::span<const Vertex> vertices() { return proceduray::kSlabVertices; }
};

struct D3D12Traits {
    using SceneConstantBuffer = d3d12::SceneConstantBuffer;
    using RayPayload = d3d12::RayPayload;
    using Attributes = d3d12::ProceduralPrimitiveAttributes;
    static constexpr uint32_t kMaxRecursionDepth = d3d12::MAX_RAY_RECURSION_DEPTH;
    static std::shared_ptr<ShaderLibrary> library(Precision p, const Accuracy& a) {
        return d3d12::makeD3D12ShaderLibrary(p, d3d12::defaultTraceRayArguments(), a);
    }
    static std::vector<HitGroupDesc> hitGroups() { return d3d12::d3d12HitGroups(); }
    static std::vector<std::string> triangleGroups() { return d3d12::triangleHitGroupNames(); }
    static std::vector<std::string> intersections() {
        return {"MyIntersectionShader_AnalyticPrimitive", "MyIntersectionShader_VolumetricPrimitive",
                "MyIntersectionShader_SignedDistancePrimitive"};
    }
    static RootSignatureDesc global() { return d3d12::globalRootSignatureDesc(); }
    static RootSignatureDesc triangleLocal() { return d3d12::triangleLocalRootSignatureDesc(); }
    static RootSignatureDesc aabbLocal() { return d3d12::aabbLocalRootSignatureDesc(); }
    static constexpr const char* kRaygen = "MyRaygenShader";
    static constexpr const char* kMiss = "MyMissShader";
    static constexpr const char* kShadowMiss = "MyMissShader_ShadowRay";
    static constexpr const char* kShadowGroupSuffix = "_ShadowRay";
    static std::span<const uint16_t> indices() { return d3d12::kPlaneIndices; }
    static std::span<const Vertex> vertices() { return d3d12::kPlaneVertices; }
};

// The root parameters both samples share (procedural/sample_layout.h).
enum GlobalSlot : uint32_t { kOutput = 0, kScene = 1, kSceneCB = 2, kInstanceData = 3, kBuffers = 4 };
enum LocalSlot : uint32_t { kMaterial = 0, kAABBCB = 1 };

// What the probe closest hit saw.
template <class Sample>
struct Probe {
    int closestHits = 0;
    float t = -1.0f;
    typename Sample::Attributes attr{};
};

// One library (one precision and Accuracy) and a scene of instances, each with its own pair of hit-group records
// (radiance, shadow). `render` runs the library's ray generation for one pixel; `probe` traces one radiance ray
// whose closest hit, for the records added with `probe`, is a probe recording the intersection shader's report.
template <class Sample>
class KnobRig {
public:
    explicit KnobRig(const Accuracy& accuracy = {}, Precision precision = Precision::Float)
        : accuracy_(accuracy), library_(Sample::library(precision, accuracy)) {
        GpuMemory& memory = device_.memory();
        const auto indices = Sample::indices();
        const auto vertices = Sample::vertices();
        heap_ = &device_.createDescriptorHeap(3, "accuracy knobs heap");
        heap_->setTexture2D(0, DescriptorRangeType::UAV, &output_);
        heap_->setBuffer(1, DescriptorRangeType::SRV,
                         {memory.upload(indices.data(), indices.size_bytes(), "g_indices"), indices.size_bytes(), 0});
        heap_->setBuffer(2, DescriptorRangeType::SRV,
                         {memory.upload(vertices.data(), vertices.size_bytes(), "g_vertices"), vertices.size_bytes(),
                          sizeof(Vertex)});
        scene.lightPosition = vec4(0, 18, -20, 0);
        scene.lightAmbientColor = vec4(0.25f, 0.25f, 0.25f, 1.0f);
        scene.lightDiffuseColor = vec4(0.6f, 0.6f, 0.6f, 1.0f);
        for (int i = 0; i < 4; ++i) scene.projectionToWorld.m[i][i] = 1.0f;

        probes_->addRayGeneration("RG_Probe", [this](ShaderContext& ctx) {
            typename Sample::RayPayload payload{};
            payload.recursionDepth = 1;
            // The radiance ray's arguments in both samples: R = 0, M = 2 (ray types), miss 0.
            ctx.TraceRay(ctx.globalRootDescriptor(kScene), RAY_FLAG_CULL_BACK_FACING_TRIANGLES, 0xFF, 0, 2, 0,
                         probeRay_, payload);
        });
        probes_->addClosestHit<typename Sample::RayPayload, typename Sample::Attributes>(
            "CH_Probe",
            [this](ShaderContext& ctx, typename Sample::RayPayload&, const typename Sample::Attributes& attr) {
                probe_.closestHits++;
                probe_.t = ctx.RayTCurrent();
                probe_.attr = attr;
            });
    }

    typename Sample::SceneConstantBuffer scene{};

    // An AABB instance: its box and transform, g_instanceBuffer / g_AABBPrimitiveAttributes[element] = matrices,
    // l_aabbCB and the material. Its records are the library's groups, except that with `probe` the radiance one
    // pairs the library's intersection shader `intersection` with the probe closest hit.
    void addAABB(const RaytracingAABB& box, const Matrix3x4& transform, uint32_t element,
                 const std::array<Float4x4, 2>& matrices, PrimitiveInstanceConstantBuffer aabbCB,
                 const PrimitiveConstantBuffer& material, const std::string& radianceGroup,
                 const std::string& intersection, bool probe) {
        GeometryDesc g;
        g.Type = GeometryType::ProceduralPrimitiveAABBs;
        g.Flags = GEOMETRY_FLAG_OPAQUE;
        g.AABBs.AABBCount = 1;
        g.AABBs.AABBs = {device_.memory().upload(&box, sizeof box, "AABB"), sizeof box};
        instanceData_.at(element) = matrices;
        instances_.push_back({g, transform, material, aabbCB, probe ? "Probe_" + intersection : radianceGroup,
                              radianceGroup + Sample::kShadowGroupSuffix, false});
    }

    // An instance of the sample's triangles (the slab or the ground plane) with the library's triangle hit groups.
    void addTriangles(const Matrix3x4& transform, const PrimitiveConstantBuffer& material) {
        GpuMemory& memory = device_.memory();
        const auto indices = Sample::indices();
        const auto vertices = Sample::vertices();
        GeometryDesc g;
        g.Type = GeometryType::Triangles;
        g.Flags = GEOMETRY_FLAG_OPAQUE;
        g.Triangles.IndexFormat = Format::R16_UINT;
        g.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
        g.Triangles.IndexCount = uint32_t(indices.size());
        g.Triangles.VertexCount = uint32_t(vertices.size());
        g.Triangles.IndexBuffer = memory.upload(indices.data(), indices.size_bytes(), "indices");
        g.Triangles.VertexBuffer = {memory.upload(vertices.data(), vertices.size_bytes(), "vertices"), sizeof(Vertex)};
        const auto groups = Sample::triangleGroups();
        instances_.push_back({g, transform, material, {}, groups.at(0), groups.at(1), true});
    }

    struct Result {
        DispatchStats stats;
        vec4 pixel{0.0f};
        Probe<Sample> probe;
        // The recursion levels that traced rays (raysPerDepth[1] is the primary ray).
        size_t levels() const {
            size_t n = 0;
            for (size_t d = 1; d < stats.raysPerDepth.size(); ++d) n += stats.raysPerDepth[d] > 0;
            return n;
        }
    };

    // The library's ray generation for a 1x1 dispatch: the camera at `eye` looking at `target`.
    Result render(vec3 eye, vec3 target) {
        scene.cameraPosition = vec4(eye, 1.0f);
        scene.projectionToWorld.m[3] = {target.x, target.y, target.z, 1.0f};
        return dispatch(Sample::kRaygen);
    }

    // One radiance ray traced by a probe ray generation.
    Result probe(const RayDesc& ray) {
        probeRay_ = ray;
        return dispatch("RG_Probe");
    }

private:
    struct Instance {
        GeometryDesc geometry;
        Matrix3x4 transform;
        PrimitiveConstantBuffer material;
        PrimitiveInstanceConstantBuffer aabbCB;
        std::string radianceGroup, shadowGroup;
        bool triangles;
    };

    Result dispatch(const std::string& rayGen) {
        GpuMemory& memory = device_.memory();
        std::vector<InstanceDesc> descs;
        for (size_t i = 0; i < instances_.size(); ++i)
            descs.push_back(makeInstanceDesc(instances_[i].transform, 0, 0xFF, uint32_t(2 * i), INSTANCE_FLAG_NONE,
                                             device_.buildBottomLevelAS({BUILD_FLAG_NONE, {instances_[i].geometry}})));
        const GpuVirtualAddress tlas =
            device_.buildTopLevelAS({BUILD_FLAG_NONE, uint32_t(descs.size()), ElementsLayout::Array,
                                     memory.upload(descs, "instances")});

        StateObjectDesc desc;
        desc.name = "accuracy knobs";
        desc.libraries = {{library_, {}}, {probes_, {}}};
        desc.hitGroups = Sample::hitGroups();
        std::vector<std::string> aabbGroups;
        for (const HitGroupDesc& g : desc.hitGroups)
            if (g.Type == HitGroupType::ProceduralPrimitive) aabbGroups.push_back(g.HitGroupExport);
        for (const std::string& is : Sample::intersections()) {
            desc.hitGroups.push_back({"Probe_" + is, HitGroupType::ProceduralPrimitive, "", "CH_Probe", is});
            aabbGroups.push_back("Probe_" + is);
        }
        const RootSignaturePtr triangleSignature = RootSignature::create(Sample::triangleLocal());
        const RootSignaturePtr aabbSignature = RootSignature::create(Sample::aabbLocal());
        const RootSignaturePtr globalSignature = RootSignature::create(Sample::global());
        desc.localRootSignatures = {{triangleSignature, Sample::triangleGroups()}, {aabbSignature, aabbGroups}};
        desc.globalRootSignatures = {{globalSignature, {}}};
        desc.shaderConfigs = {{sizeof(typename Sample::RayPayload), sizeof(typename Sample::Attributes)}};
        // As the scenes do: the pipeline's limit follows the library's MAX_RAY_RECURSION_DEPTH.
        desc.pipelineConfigs = {
            {std::max(Sample::kMaxRecursionDepth, accuracy_.maxRecursionDepth.value_or(0)), PIPELINE_FLAG_NONE}};
        const StateObjectPtr so = StateObject::create(desc);

        ShaderTableBuilder hitGroups("hit groups");
        for (const Instance& instance : instances_) {
            LocalRootArguments arguments(instance.triangles ? triangleSignature : aabbSignature);
            arguments.setConstants(kMaterial, instance.material);
            if (!instance.triangles) arguments.setConstants(kAABBCB, instance.aabbCB);
            hitGroups.addRecord(so->shaderIdentifier(instance.radianceGroup), arguments)
                .addRecord(so->shaderIdentifier(instance.shadowGroup), arguments);
        }
        const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier(rayGen)).upload(memory);
        DispatchRaysDesc rays;
        rays.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
        rays.MissShaderTable = ShaderTableBuilder("miss")
                                   .addRecord(so->shaderIdentifier(Sample::kMiss))
                                   .addRecord(so->shaderIdentifier(Sample::kShadowMiss))
                                   .upload(memory);
        rays.HitGroupTable = hitGroups.upload(memory);
        rays.Width = rays.Height = rays.Depth = 1;

        GlobalRootArguments globals(globalSignature);
        globals.setDescriptor(kOutput, heap_->gpuHandle(0));
        globals.setDescriptor(kScene, tlas);
        globals.setDescriptor(kSceneCB, memory.upload(&scene, sizeof scene, "g_sceneCB"));
        globals.setDescriptor(kInstanceData, memory.upload(instanceData_, "instance data"));
        globals.setDescriptor(kBuffers, heap_->gpuHandle(1));
        DispatchOptions options;
        options.threads = 1;
        probe_ = {};
        output_.at(0, 0) = vec4(-1.0f);
        Result result;
        result.stats = device_.dispatchRays(rays, so, &globals, options).stats;
        result.pixel = output_.at(0, 0);
        result.probe = probe_;
        return result;
    }

    Accuracy accuracy_;
    Device device_;
    std::shared_ptr<ShaderLibrary> library_;
    std::shared_ptr<ShaderLibrary> probes_ = std::make_shared<ShaderLibrary>();
    DescriptorHeap* heap_ = nullptr;
    Image output_{1, 1};
    std::vector<Instance> instances_;
    std::vector<std::array<Float4x4, 2>> instanceData_ = std::vector<std::array<Float4x4, 2>>(10);
    RayDesc probeRay_;
    Probe<Sample> probe_;
};

using ProcedurayRig = KnobRig<ProcedurayTraits>;
using D3D12Rig = KnobRig<D3D12Traits>;

// ---- The Proceduray instances of the fact sheet (§1.2, §1.8) -------------------------------------------

inline constexpr PrimitiveConstantBuffer kPacmanMaterial{{1, 1, 0, 1}, 0.3f, 0.3f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
inline constexpr PrimitiveConstantBuffer kMandelbulbMaterial{{1, 1, 0, 1}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
inline constexpr PrimitiveConstantBuffer kJuliaMaterial{{1.0f, 0.5f, 0.5f, 1.0f}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
inline constexpr PrimitiveConstantBuffer kSlabMaterial{{1.0f, 0.9f, 0.7f, 1.0f}, 0.25f, 1.0f, 0.4f, 50.0f, 1.0f, vec3(0.0f)};

// g_instanceBuffer[ordinal] = {inverse(M), M} in row-vector form (§1.7).
inline void addProceduray(ProcedurayRig& rig, const RaytracingAABB& box, const Matrix3x4& m, uint32_t ordinal,
                   proceduray::SignedDistancePrimitive type, const PrimitiveConstantBuffer& material,
                   const std::string& name, bool probe) {
    rig.addAABB(box, m, ordinal, {rowVectorForm(*affineInverse(m)), rowVectorForm(m)}, {ordinal, uint32_t(type)},
                material, "HitGroup_" + name, "Intersection_" + name, probe);
}

// Pac-man A: S(50)·T(35,-35,0), AABB [-0.5,0.5]^3, ordinal 1.
inline void addPacmanA(ProcedurayRig& rig, bool probe = true) {
    addProceduray(rig, {-0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f},
                  Matrix3x4::translation(vec3(35, -35, 0)) * Matrix3x4::scale(vec3(50)), 1,
                  proceduray::SignedDistancePrimitive::IntersectedRoundCube, kPacmanMaterial, "Pacman", probe);
}

// The Mandelbulb: S(40)·T(0,-50,115), AABB [-1.5,1.5]^3, ordinal 3.
inline void addMandelbulb(ProcedurayRig& rig, bool probe = true) {
    addProceduray(rig, {-1.5f, -1.5f, -1.5f, 1.5f, 1.5f, 1.5f},
                  Matrix3x4::translation(vec3(0, -50, 115)) * Matrix3x4::scale(vec3(40)), 3,
                  proceduray::SignedDistancePrimitive::Mandelbulb, kMandelbulbMaterial, "Mandelbulb", probe);
}

// The Julia with its exact float32 matrix S(100,30,100)·RotX(3.1421)·T(0,130,75), AABB [-3.5,3.5]^3, ordinal 0.
inline void addJulia(ProcedurayRig& rig, bool probe = true) {
    Matrix3x4 m;
    m.m[0] = {100.0f, 0.0f, 0.0f, 0.0f};
    m.m[1] = {0.0f, -29.9999962f, 0.0507354662f, 130.0f};
    m.m[2] = {0.0f, -0.0152206402f, -99.9999847f, 75.0f};
    addProceduray(rig, {-3.5f, -3.5f, -3.5f, 3.5f, 3.5f, 3.5f}, m, 0, proceduray::SignedDistancePrimitive::JuliaSets,
                  kJuliaMaterial, "Julia", probe);
}

// The rays of proceduray_shaders_test.cpp: H1 on Pac-man A's head, H14 into the Mandelbulb at T0, H9 up into
// the Julia's cut face.
inline const RayDesc kPacmanRay{vec3(35, -45, 50), 0.0f, vec3(0, 0, -1), 10000.0f};
inline const RayDesc kMandelbulbRay{vec3(35, -45, 100), 0.0f, vec3(0, 0, -1), 10000.0f};
inline const RayDesc kJuliaRay{vec3(0, 20, 74.96f), 0.0f, vec3(0, 1, 0), 10000.0f};

// ---- The D3D12 primitives of the fact sheet (§1.3, §1.4) ------------------------------------------------

// Primitive i in the AABB instance T(0,1,0): box (-7,-1,-7) + 4·offset, size `size`, grown by 0.5 (as the
// contract rig does); g_AABBPrimitiveAttributes[i] = {S·Tr, its inverse} at T = 0.
inline void addD3D12(D3D12Rig& rig, uint32_t i, vec3 offset, vec3 size, vec3 scale, uint32_t primitiveType,
              float stepScale, const std::string& group, const std::string& intersection, bool probe) {
    const vec3 lo = vec3(-7.0f, -1.0f, -7.0f) + offset * 4.0f;
    const vec3 centre = lo + 0.5f * size;
    std::array<Float4x4, 2> matrices{};
    for (int k = 0; k < 3; ++k) {
        matrices[0].m[k][k] = scale[k];
        matrices[0].m[3][k] = centre[k];
        matrices[1].m[k][k] = 1.0f / scale[k];
        matrices[1].m[3][k] = -centre[k] / scale[k];
    }
    matrices[0].m[3][3] = matrices[1].m[3][3] = 1.0f;
    const PrimitiveConstantBuffer material{vec4(1.0f), 0.0f, 0.9f, 0.7f, 50.0f, stepScale, vec3(0.0f)};
    rig.addAABB({lo.x - 0.5f, lo.y - 0.5f, lo.z - 0.5f, lo.x + size.x + 0.5f, lo.y + size.y + 0.5f,
                 lo.z + size.z + 0.5f},
                Matrix3x4::translation(vec3(0, 1, 0)), i, matrices, {i, primitiveType}, material, group,
                intersection, probe);
}

inline void addMetaballs(D3D12Rig& rig) {
    addD3D12(rig, 2, vec3(0), vec3(3), vec3(1.5f), d3d12::VolumetricPrimitive::Metaballs, 1.0f,
             "MyHitGroup_AABB_VolumetricPrimitive", "MyIntersectionShader_VolumetricPrimitive", true);
}

inline void addRoundCube(D3D12Rig& rig) {
    addD3D12(rig, 4, vec3(0, 0, 2), vec3(2), vec3(1), uint32_t(d3d12::SignedDistancePrimitive::IntersectedRoundCube),
             1.0f, "MyHitGroup_AABB_SignedDistancePrimitive", "MyIntersectionShader_SignedDistancePrimitive", true);
}

// Past metaball 2's centre (a ray through it gets an exactly axial normal whatever the offset) and onto the round
// cube's frame.
inline const RayDesc kMetaballsRay{vec3(-5.5f, 1.35f, -15), 0.0f, vec3(0, 0, 1), 10000.0f};
inline const RayDesc kRoundCubeRay{vec3(-10, 1.85f, 2), 0.0f, vec3(1, 0, 0), 10000.0f};

}  // namespace refray::procedural::accuracy_rig
