// Tests procedural/accuracy.h as the two shader libraries apply it (issue 7): with Accuracy{} every march is the
// HLSL's bit for bit (the math with the knobs' default parameters equals the calls without them, in float and
// double), and each knob does what accuracy.h says: stepsFactor scales the SDF, Julia and Mandelbulb step limits,
// thresholdFactor the hit thresholds (not Julia's tmin), the iteration counts change the distance estimators,
// normalEpsilonFactor moves normals slightly, metaballSteps changes the metaballs' samples, and maxRecursionDepth
// the number of TraceRay levels.
//
// The math is checked through the libraries' own conversions (sphereTraceParams, mandelbulbParams, ...), the
// entry points through both factories in a small scene: the library's Raygen and hit groups, or a probe closest
// hit that records what the library's intersection shader reported.
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

namespace refray::procedural {
namespace {

using namespace refray::dxr;
using glm::dvec3;
using math::Ray;
using math::RayExtent;
using procedural::fixtures::angleBetween;

template <typename T>
using tvec3 = glm::vec<3, T>;
template <typename T>
using tvec4 = glm::vec<4, T>;

using Scalars = ::testing::Types<float, double>;

// ---- Bit-exact comparison ---------------------------------------------------------------------------

template <typename T>
auto bitsOf(T x) {
    return std::bit_cast<std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>(x);
}

template <typename T, glm::length_t N>
void expectSameBits(const glm::vec<N, T>& a, const glm::vec<N, T>& b, const std::string& what) {
    for (glm::length_t i = 0; i < N; ++i) EXPECT_EQ(bitsOf(a[i]), bitsOf(b[i])) << what << " component " << i;
}

// ---- Seeded rays (sweep_support.h) ---------------------------------------------------------------------

template <typename T>
const Ray<T>& rayOf(const math::fixtures::RayPair& r) {
    if constexpr (std::is_same_v<T, float>) return r.f;
    else return r.d;
}

// `count` rays from the sphere of radius `from` about `centre`, each aimed at a point within `within` of it.
std::vector<math::fixtures::RayPair> raysAt(uint32_t seed, int count, const glm::dvec3& centre, double from,
                                            double within) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> radius(0.0, within);
    std::vector<math::fixtures::RayPair> rays;
    for (int i = 0; i < count; ++i) {
        const glm::dvec3 origin = centre + from * math::fixtures::randomUnit(rng);
        const glm::dvec3 aim = centre + radius(rng) * math::fixtures::randomUnit(rng);
        rays.push_back(math::fixtures::rayPair(origin, aim));
    }
    return rays;
}

// The Accuracy that spells out every HLSL value instead of leaving it unset.
Accuracy spelledOutHlslAccuracy() {
    Accuracy a;
    a.stepsFactor = 1.0;
    a.thresholdFactor = 1.0;
    a.mandelbulbIterations = 4;
    a.juliaIterations = 200;
    a.normalEpsilonFactor = 1.0;
    a.metaballSteps = 128;
    a.maxRecursionDepth = 3;
    return a;
}

// =======================================================================================================
// Helpers of accuracy.h
// =======================================================================================================

TEST(AccuracyKnobsHelpers, ScaledConstantKeepsTheConstantAtFactorOneAndMultipliesInT) {
    EXPECT_EQ(bitsOf(scaledConstant(0.0001f, 1.0)), bitsOf(0.0001f));
    EXPECT_EQ(bitsOf(scaledConstant(double(0.00025f), 1.0)), bitsOf(double(0.00025f)));
    EXPECT_EQ(bitsOf(scaledConstant(0.0001f, 0.1)), bitsOf(0.0001f * 0.1f));  // the factor rounded to float first
    EXPECT_EQ(bitsOf(scaledConstant(0.0001, 0.1)), bitsOf(0.0001 * 0.1));
}

TEST(AccuracyKnobsHelpers, LoopCountsStayInTheHlslIntRange) {
    EXPECT_EQ(hlslLoopCount(0), 0);
    EXPECT_EQ(hlslLoopCount(200), 200);
    EXPECT_EQ(hlslLoopCount(2147483647u), 2147483647);
    EXPECT_EQ(hlslLoopCount(4000000000u), 2147483647);
}

// =======================================================================================================
// Defaults: the HLSL's constants, bit for bit
// =======================================================================================================

template <typename T>
class AccuracyKnobsDefaults : public ::testing::Test {};
TYPED_TEST_SUITE(AccuracyKnobsDefaults, Scalars);

// Every parameter the libraries derive from Accuracy{} (or from the HLSL values spelled out) is the HLSL literal
// computed the way the HLSL computes it.
TYPED_TEST(AccuracyKnobsDefaults, LibraryParametersAreTheHlslConstants) {
    using T = TypeParam;
    for (const Accuracy& a : {Accuracy{}, spelledOutHlslAccuracy()}) {
        for (const math::SphereTraceParams<T>& sdf :
             {proceduray::sphereTraceParams<T>(a, T(0.8f)), d3d12::sphereTraceParams<T>(a, T(0.8f))}) {
            EXPECT_EQ(bitsOf(sdf.threshold), bitsOf(T(0.0001)));
            EXPECT_EQ(sdf.maxSteps, 512u);
            EXPECT_EQ(bitsOf(sdf.stepScale), bitsOf(T(0.8f)));
            EXPECT_EQ(bitsOf(sdf.normalOffset), bitsOf(T(T(0.5773) * T(0.0001))));
        }

        const auto mandelbulb = proceduray::mandelbulbParams<T>(a);
        EXPECT_EQ(bitsOf(mandelbulb.threshold), bitsOf(T(0.0001)));
        EXPECT_EQ(mandelbulb.iterations, 4);
        EXPECT_EQ(bitsOf(mandelbulb.normalOffset), bitsOf(T(T(0.5773) * T(0.0001))));
        for (int iMax = -300; iMax <= 300; ++iMax) ASSERT_EQ(proceduray::mandelbulbStepCount(iMax, a), iMax);

        const auto julia = proceduray::juliaParams<T>(a);
        EXPECT_EQ(julia.iterations, 200);
        EXPECT_EQ(julia.marchSteps, 1024);
        EXPECT_EQ(bitsOf(julia.precis), bitsOf(T(0.00025f)));
        EXPECT_EQ(bitsOf(julia.normalOffset), bitsOf(T(T(0.5773f) * T(0.00025f))));

        const auto metaballs = d3d12::metaballsParams<T>(a);
        EXPECT_EQ(metaballs.maxSteps, 128u);
        EXPECT_EQ(bitsOf(metaballs.normalOffset), bitsOf(static_cast<T>(0.5773 * 0.00001)));

        EXPECT_EQ(proceduray::maxRayRecursionDepth(a), 3u);
        EXPECT_EQ(d3d12::maxRayRecursionDepth(a), 3u);
    }
    // The public constants stay the HLSL's.
    EXPECT_EQ(proceduray::MAX_RAY_RECURSION_DEPTH, 3u);
    EXPECT_EQ(d3d12::MAX_RAY_RECURSION_DEPTH, 3u);
}

// The Mandelbulb: mdist, calcNormal and the march with the parameters of Accuracy{} against the old call forms.
TYPED_TEST(AccuracyKnobsDefaults, MandelbulbWithDefaultParametersIsBitIdentical) {
    using T = TypeParam;
    namespace mb = math::mandelbulb;
    const auto params = proceduray::mandelbulbParams<T>(Accuracy{});
    for (const auto& pair : raysAt(11, 8, glm::dvec3(0.0), 1.6, 0.8)) {
        const Ray<T>& r = rayOf<T>(pair);
        for (const int iMax : {4, 129}) {
            const mb::MandelbulbHit<T> old = mb::MandelbulbDistance(r.origin, r.direction, iMax);
            const int steps = proceduray::mandelbulbStepCount(iMax, Accuracy{});
            const mb::MandelbulbHit<T> knobs = mb::MandelbulbDistance(r.origin, r.direction, steps, params);
            ASSERT_EQ(old.hit, knobs.hit);
            EXPECT_EQ(bitsOf(old.thit), bitsOf(knobs.thit));
            expectSameBits(old.normal, knobs.normal, "normal");
            expectSameBits(old.color, knobs.color, "trap");
            expectSameBits(old.pos, knobs.pos, "pos");
        }
        const tvec3<T> p = r.origin * T(0.5);
        tvec4<T> oldTrap, knobsTrap;
        EXPECT_EQ(bitsOf(mb::mdist(p, oldTrap)), bitsOf(mb::mdist(p, knobsTrap, params.iterations)));
        expectSameBits(oldTrap, knobsTrap, "mdist trap");
        EXPECT_EQ(bitsOf(mb::mdist(p)), bitsOf(mb::mdist(p, params.iterations)));
        expectSameBits(mb::calcNormal(p), mb::calcNormal(p, params.normalOffset, params.iterations), "calcNormal");
    }
}

// The Julia set: raycast, calcNormal and JuliaDistance with the parameters of Accuracy{} against the old call forms.
TYPED_TEST(AccuracyKnobsDefaults, JuliaWithDefaultParametersIsBitIdentical) {
    using T = TypeParam;
    namespace jl = math::julia;
    const auto params = proceduray::juliaParams<T>(Accuracy{});
    for (const auto& pair : raysAt(12, 4, glm::dvec3(0, -0.5, 0), 1.5, 0.8)) {
        const Ray<T>& q = rayOf<T>(pair);  // in q-space
        const glm::vec<2, T> old = jl::raycast(q.origin, q.direction);
        const glm::vec<2, T> knobs = jl::raycast(q.origin, q.direction, jl::kc<T>(), T(0), params.iterations,
                                                 params.marchSteps, params.precis);
        expectSameBits(old, knobs, "raycast");
        const tvec3<T> p = q.origin * T(0.6);
        expectSameBits(jl::calcNormal(p), jl::calcNormal(p, jl::kc<T>(), params.iterations, params.normalOffset),
                       "calcNormal");

        // The same ray in local space: q = 0.4 * local + (0, -1, 0).
        const tvec3<T> local = (q.origin - tvec3<T>(T(0), T(-1), T(0))) / T(0.4);
        const jl::JuliaHit<T> oldHit = jl::JuliaDistance(local, q.direction);
        const jl::JuliaHit<T> knobsHit = jl::JuliaDistance(local, q.direction, params);
        ASSERT_EQ(oldHit.hit, knobsHit.hit);
        expectSameBits(oldHit.resT, knobsHit.resT, "resT");
        expectSameBits(oldHit.normal, knobsHit.normal, "normal");
    }
}

template <typename T, class Sdf>
void expectSameSphereTrace(const Ray<T>& r, Sdf&& sdf, T stepScale, const math::SphereTraceParams<T>& params) {
    math::SphereTraceParams<T> old;  // what the entry points passed before the knobs
    old.stepScale = stepScale;
    const auto a = math::RaySignedDistancePrimitiveTest(r, math::fixtures::radianceExtent<T>(), sdf, old);
    const auto b = math::RaySignedDistancePrimitiveTest(r, math::fixtures::radianceExtent<T>(), sdf, params);
    ASSERT_EQ(a.hit, b.hit);
    EXPECT_EQ(bitsOf(a.thit), bitsOf(b.thit));
    expectSameBits(a.normal, b.normal, "normal");
    expectSameBits(a.position, b.position, "position");
    EXPECT_EQ(a.steps, b.steps);
}

// The sphere tracing of both libraries: the Pac-man (at T0 and T1) and the seven D3D12 SDFs.
TYPED_TEST(AccuracyKnobsDefaults, SphereTracingWithDefaultParametersIsBitIdentical) {
    using T = TypeParam;
    for (const T time : {T(0), T(math::fixtures::canonicalT1())}) {
        const T mouth = math::pacman::PacmanMouthInterpolant(time);
        const auto pacman = [mouth](const tvec3<T>& p) { return math::pacman::pacMan(p, mouth); };
        for (const auto& pair : raysAt(13, 6, glm::dvec3(0.0), 1.2, 0.4))
            expectSameSphereTrace(rayOf<T>(pair), pacman, T(1), proceduray::sphereTraceParams<T>(Accuracy{}, T(1)));
    }
    for (uint32_t type = 0; type <= 6; ++type) {
        const auto sdf = [type](const tvec3<T>& p) {
            return math::d3d12::GetDistanceFromSignedDistancePrimitive(p, math::d3d12::SignedDistancePrimitive(type));
        };
        for (const auto& pair : raysAt(14 + type, 3, glm::dvec3(0.0), 2.5, 0.8))
            expectSameSphereTrace(rayOf<T>(pair), sdf, T(0.8f), d3d12::sphereTraceParams<T>(Accuracy{}, T(0.8f)));
    }
}

// The metaballs: the march and the normal with the parameters of Accuracy{} against the old call forms.
TYPED_TEST(AccuracyKnobsDefaults, MetaballsWithDefaultParametersAreBitIdentical) {
    using T = TypeParam;
    const auto params = d3d12::metaballsParams<T>(Accuracy{});
    for (const T time : {T(0), T(3)}) {
        const math::Metaballs<T> blobs = math::InitializeAnimatedMetaballs(time, T(12));
        for (const auto& pair : raysAt(21, 8, glm::dvec3(0.0), 2.0, 0.6)) {
            const Ray<T>& r = rayOf<T>(pair);
            const auto old = math::RayMetaballsIntersectionTest(r, math::fixtures::radianceExtent<T>(), time);
            const auto knobs =
                math::RayMetaballsIntersectionTest(r, math::fixtures::radianceExtent<T>(), time, T(12), params);
            ASSERT_EQ(old.hit, knobs.hit);
            EXPECT_EQ(bitsOf(old.thit), bitsOf(knobs.thit));
            expectSameBits(old.normal, knobs.normal, "normal");
            EXPECT_EQ(old.step, knobs.step);
            const tvec3<T> p = r.origin * T(0.2);
            expectSameBits(math::CalculateMetaballsNormal(p, blobs),
                           math::CalculateMetaballsNormal(p, blobs, params.normalOffset), "CalculateMetaballsNormal");
        }
    }
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

constexpr PrimitiveConstantBuffer kPacmanMaterial{{1, 1, 0, 1}, 0.3f, 0.3f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
constexpr PrimitiveConstantBuffer kMandelbulbMaterial{{1, 1, 0, 1}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
constexpr PrimitiveConstantBuffer kJuliaMaterial{{1.0f, 0.5f, 0.5f, 1.0f}, 0.2f, 0.6f, 0.7f, 50.0f, 1.0f, vec3(0.0f)};
constexpr PrimitiveConstantBuffer kSlabMaterial{{1.0f, 0.9f, 0.7f, 1.0f}, 0.25f, 1.0f, 0.4f, 50.0f, 1.0f, vec3(0.0f)};

// g_instanceBuffer[ordinal] = {inverse(M), M} in row-vector form (§1.7).
void addProceduray(ProcedurayRig& rig, const RaytracingAABB& box, const Matrix3x4& m, uint32_t ordinal,
                   proceduray::SignedDistancePrimitive type, const PrimitiveConstantBuffer& material,
                   const std::string& name, bool probe) {
    rig.addAABB(box, m, ordinal, {rowVectorForm(*affineInverse(m)), rowVectorForm(m)}, {ordinal, uint32_t(type)},
                material, "HitGroup_" + name, "Intersection_" + name, probe);
}

// Pac-man A: S(50)·T(35,-35,0), AABB [-0.5,0.5]^3, ordinal 1.
void addPacmanA(ProcedurayRig& rig, bool probe = true) {
    addProceduray(rig, {-0.5f, -0.5f, -0.5f, 0.5f, 0.5f, 0.5f},
                  Matrix3x4::translation(vec3(35, -35, 0)) * Matrix3x4::scale(vec3(50)), 1,
                  proceduray::SignedDistancePrimitive::IntersectedRoundCube, kPacmanMaterial, "Pacman", probe);
}

// The Mandelbulb: S(40)·T(0,-50,115), AABB [-1.5,1.5]^3, ordinal 3.
void addMandelbulb(ProcedurayRig& rig, bool probe = true) {
    addProceduray(rig, {-1.5f, -1.5f, -1.5f, 1.5f, 1.5f, 1.5f},
                  Matrix3x4::translation(vec3(0, -50, 115)) * Matrix3x4::scale(vec3(40)), 3,
                  proceduray::SignedDistancePrimitive::Mandelbulb, kMandelbulbMaterial, "Mandelbulb", probe);
}

// The Julia with its exact float32 matrix S(100,30,100)·RotX(3.1421)·T(0,130,75), AABB [-3.5,3.5]^3, ordinal 0.
void addJulia(ProcedurayRig& rig, bool probe = true) {
    Matrix3x4 m;
    m.m[0] = {100.0f, 0.0f, 0.0f, 0.0f};
    m.m[1] = {0.0f, -29.9999962f, 0.0507354662f, 130.0f};
    m.m[2] = {0.0f, -0.0152206402f, -99.9999847f, 75.0f};
    addProceduray(rig, {-3.5f, -3.5f, -3.5f, 3.5f, 3.5f, 3.5f}, m, 0, proceduray::SignedDistancePrimitive::JuliaSets,
                  kJuliaMaterial, "Julia", probe);
}

// The rays of proceduray_shaders_test.cpp: H1 on Pac-man A's head, H14 into the Mandelbulb at T0, H9 up into
// the Julia's cut face.
const RayDesc kPacmanRay{vec3(35, -45, 50), 0.0f, vec3(0, 0, -1), 10000.0f};
const RayDesc kMandelbulbRay{vec3(35, -45, 100), 0.0f, vec3(0, 0, -1), 10000.0f};
const RayDesc kJuliaRay{vec3(0, 20, 74.96f), 0.0f, vec3(0, 1, 0), 10000.0f};

// ---- The D3D12 primitives of the fact sheet (§1.3, §1.4) ------------------------------------------------

// Primitive i in the AABB instance T(0,1,0): box (-7,-1,-7) + 4·offset, size `size`, grown by 0.5 (as the
// contract rig does); g_AABBPrimitiveAttributes[i] = {S·Tr, its inverse} at T = 0.
void addD3D12(D3D12Rig& rig, uint32_t i, vec3 offset, vec3 size, vec3 scale, uint32_t primitiveType,
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

void addMetaballs(D3D12Rig& rig) {
    addD3D12(rig, 2, vec3(0), vec3(3), vec3(1.5f), d3d12::VolumetricPrimitive::Metaballs, 1.0f,
             "MyHitGroup_AABB_VolumetricPrimitive", "MyIntersectionShader_VolumetricPrimitive", true);
}

void addRoundCube(D3D12Rig& rig) {
    addD3D12(rig, 4, vec3(0, 0, 2), vec3(2), vec3(1), uint32_t(d3d12::SignedDistancePrimitive::IntersectedRoundCube),
             1.0f, "MyHitGroup_AABB_SignedDistancePrimitive", "MyIntersectionShader_SignedDistancePrimitive", true);
}

// Past metaball 2's centre (a ray through it gets an exactly axial normal whatever the offset) and onto the round
// cube's frame.
const RayDesc kMetaballsRay{vec3(-5.5f, 1.35f, -15), 0.0f, vec3(0, 0, 1), 10000.0f};
const RayDesc kRoundCubeRay{vec3(-10, 1.85f, 2), 0.0f, vec3(1, 0, 0), 10000.0f};

// =======================================================================================================
// stepsFactor
// =======================================================================================================

// Counts the steps of a grazing march on the Pac-man's head: with exactly as many steps as it needs it hits, bit
// for bit as with 512; one step fewer and it misses.
TEST(AccuracyKnobsSteps, SphereTracingStopsAfterTheScaledStepCount) {
    const Ray<float> grazing{vec3(-2.0f, 0.49f, 0.0f), vec3(1, 0, 0)};
    const auto sdf = [](const vec3& p) { return math::pacman::pacMan(p, 0.0f); };
    const auto extent = math::fixtures::radianceExtent<float>();
    const auto full = math::RaySignedDistancePrimitiveTest(grazing, extent, sdf,
                                                           proceduray::sphereTraceParams(Accuracy{}, 1.0f));
    ASSERT_TRUE(full.hit);
    ASSERT_GT(full.steps, 5u);

    Accuracy exact;
    exact.stepsFactor = double(full.steps) / 512.0;
    const auto enough = proceduray::sphereTraceParams(exact, 1.0f);
    EXPECT_EQ(enough.maxSteps, full.steps);
    const auto justEnough = math::RaySignedDistancePrimitiveTest(grazing, extent, sdf, enough);
    ASSERT_TRUE(justEnough.hit);
    EXPECT_EQ(bitsOf(justEnough.thit), bitsOf(full.thit));

    Accuracy fewer;
    fewer.stepsFactor = double(full.steps - 1) / 512.0;
    const auto tooFew =
        math::RaySignedDistancePrimitiveTest(grazing, extent, sdf, d3d12::sphereTraceParams(fewer, 1.0f));
    EXPECT_FALSE(tooFew.hit);
    EXPECT_EQ(tooFew.steps, full.steps - 1);

    Accuracy doubled;
    doubled.stepsFactor = 2.0;
    EXPECT_EQ(proceduray::sphereTraceParams(doubled, 1.0f).maxSteps, 1024u);
    EXPECT_EQ(d3d12::sphereTraceParams(doubled, 1.0).maxSteps, 1024u);
}

// The Mandelbulb's animated iMax and Julia's 1024 march steps scale the same way.
TEST(AccuracyKnobsSteps, FractalStepCountsScale) {
    Accuracy a;
    a.stepsFactor = 8.0;
    EXPECT_EQ(proceduray::mandelbulbStepCount(4, a), 32);
    EXPECT_EQ(proceduray::mandelbulbStepCount(129, a), 1032);
    EXPECT_EQ(proceduray::mandelbulbStepCount(0, a), 0);  // the march does not run either way
    EXPECT_EQ(proceduray::juliaParams<float>(a).marchSteps, 8192);
    a.stepsFactor = 1e-6;
    EXPECT_EQ(proceduray::mandelbulbStepCount(129, a), 1);  // at least 1
    EXPECT_EQ(proceduray::juliaParams<double>(a).marchSteps, 1);
}

// H15: a Julia march that runs out of steps is a hit where it stopped; with a single step that is one step of
// min(d, 0.2) past the bounding sphere, well before the converged surface.
TEST(AccuracyKnobsSteps, JuliaMarchOfOneStepReportsWhereItStopped) {
    const dvec3 local(0, 1.25, -2.875);  // q-space (0, -0.5, -1.15), fractals_test.cpp's ray
    const dvec3 rd(0, 0, 1);
    const auto full = math::julia::JuliaDistance(local, rd);
    Accuracy one;
    one.stepsFactor = 1.0 / 1024.0;
    const auto params = proceduray::juliaParams<double>(one);
    ASSERT_EQ(params.marchSteps, 1);
    const auto oneStep = math::julia::JuliaDistance(local, rd, params);
    ASSERT_TRUE(full.hit);
    ASSERT_TRUE(oneStep.hit);
    const double entry = 1.15 - std::sqrt(1.44 - 0.25);  // the q-space sphere of radius 1.2
    EXPECT_GT(oneStep.resT.x, entry);
    EXPECT_LE(oneStep.resT.x, entry + 0.2 + 1e-12);
    EXPECT_LT(oneStep.resT.x, full.resT.x - 0.05);
}

// Through the library: a Pac-man or round-cube march cut to one step misses. The Mandelbulb's march of iMax = 4
// steps at T0 (H14) reports its unconverged shell at t = 0.02999; with stepsFactor 2 it takes 8 steps and reports
// t = 0.1483 (the math's march of 8 steps from the local ray (0.875, 0.125, -0.375), -z), with stepsFactor 8 it
// takes 32 and leaves the bounding sphere: no hit.
TEST(AccuracyKnobsSteps, IntersectionShadersMarchTheScaledStepCounts) {
    Accuracy tiny;
    tiny.stepsFactor = 0.001;
    {
        ProcedurayRig reference;
        addPacmanA(reference);
        const auto hit = reference.probe(kPacmanRay).probe;
        ASSERT_EQ(hit.closestHits, 1);
        EXPECT_NEAR(hit.t, 0.54173f, 1e-4f);
        ProcedurayRig cut(tiny);
        addPacmanA(cut);
        EXPECT_EQ(cut.probe(kPacmanRay).probe.closestHits, 0);
    }
    {
        D3D12Rig reference;
        addRoundCube(reference);
        ASSERT_EQ(reference.probe(kRoundCubeRay).probe.closestHits, 1);
        D3D12Rig cut(tiny);
        addRoundCube(cut);
        EXPECT_EQ(cut.probe(kRoundCubeRay).probe.closestHits, 0);
    }
    const auto mandelbulbT = [](double stepsFactor) {
        Accuracy a;
        a.stepsFactor = stepsFactor;
        ProcedurayRig rig(a);
        addMandelbulb(rig);
        const auto probe = rig.probe(kMandelbulbRay).probe;
        return probe.closestHits == 1 ? probe.t : -1.0f;
    };
    const auto mathT = [](int iMax) {
        const auto hit = math::mandelbulb::MandelbulbDistance(vec3(0.875f, 0.125f, -0.375f), vec3(0, 0, -1), iMax);
        return hit.hit ? hit.thit : -1.0f;
    };
    EXPECT_NEAR(mandelbulbT(1.0), 0.02999f, 1e-4f);
    EXPECT_NEAR(mandelbulbT(2.0), 0.1483f, 1e-4f);
    EXPECT_NEAR(mandelbulbT(2.0), mathT(8), 1e-5f);
    EXPECT_EQ(mathT(32), -1.0f);
    EXPECT_EQ(mandelbulbT(8.0), -1.0f);
}

// =======================================================================================================
// thresholdFactor
// =======================================================================================================

// A larger threshold stops every march earlier: the SDF (H1's ray on the Pac-man), the Mandelbulb (a converged
// march of 129 steps) and Julia (the ray of fractals_test.cpp).
TEST(AccuracyKnobsThreshold, LargerThresholdsStopTheMarchesEarlier) {
    Accuracy loose;
    loose.thresholdFactor = 1000.0;

    const auto sdf = [](const vec3& p) { return math::pacman::pacMan(p, 0.0f); };
    const Ray<float> h1{vec3(0, -0.2f, 1), vec3(0, 0, -1)};
    const auto extent = math::fixtures::radianceExtent<float>();
    const auto strictParams = proceduray::sphereTraceParams(Accuracy{}, 1.0f);
    const auto looseParams = proceduray::sphereTraceParams(loose, 1.0f);
    EXPECT_EQ(bitsOf(looseParams.threshold), bitsOf(0.0001f * 1000.0f));
    const auto strict = math::RaySignedDistancePrimitiveTest(h1, extent, sdf, strictParams);
    const auto early = math::RaySignedDistancePrimitiveTest(h1, extent, sdf, looseParams);
    ASSERT_TRUE(strict.hit);
    ASSERT_TRUE(early.hit);
    EXPECT_LT(early.thit, strict.thit - 1e-3f);
    EXPECT_LE(sdf(early.position), 0.1f * early.thit);

    namespace mb = math::mandelbulb;
    const dvec3 ro(0.05, 0.1, -1.4), rd(0, 0, 1);
    const auto mbStrict = mb::MandelbulbDistance(ro, rd, 129, proceduray::mandelbulbParams<double>(Accuracy{}));
    const auto mbParams = proceduray::mandelbulbParams<double>(loose);
    EXPECT_EQ(mbParams.threshold, 0.0001 * 1000.0);
    const auto mbEarly = mb::MandelbulbDistance(ro, rd, 129, mbParams);
    ASSERT_TRUE(mbStrict.hit);
    ASSERT_TRUE(mbEarly.hit);
    EXPECT_LT(mbEarly.thit, mbStrict.thit - 1e-4);

    namespace jl = math::julia;
    const dvec3 q(0, -0.5, -1.15);
    Accuracy looser;
    looser.thresholdFactor = 100.0;
    const auto jParams = proceduray::juliaParams<double>(looser);
    EXPECT_EQ(jParams.precis, double(0.00025f) * 100.0);
    const glm::dvec2 jStrict = jl::raycast(q, rd);
    const glm::dvec2 jEarly = jl::raycast(q, rd, jl::kc<double>(), 0.0, jParams.iterations, jParams.marchSteps,
                                          jParams.precis);
    ASSERT_GE(jStrict.x, 0.0);
    ASSERT_GE(jEarly.x, 0.0);
    EXPECT_LT(jEarly.x, jStrict.x);
    EXPECT_LT(jl::jdist(q + jEarly.x * rd, jl::kc<double>(), 200).x, 0.025);
}

// Julia's tmin stays kPrecis: with a huge threshold a march from inside the bounding sphere and between the cut
// planes stops at its first sample, t = kPrecis exactly (a scaled tmin would start beyond tmax and miss).
TEST(AccuracyKnobsThreshold, JuliaStartsAtTheUnscaledPrecis) {
    namespace jl = math::julia;
    const dvec3 q(0.0, -0.5, 0.8), rd(0, 0, 1);  // |q| < 1.2, -1.1 < y < 0
    const glm::dvec2 reference = jl::raycast(q, rd);
    ASSERT_GT(reference.x, jl::kPrecis<double>);  // outside the set: the HLSL march moves on
    Accuracy huge;
    huge.thresholdFactor = 1e9;
    const auto params = proceduray::juliaParams<double>(huge);
    const glm::dvec2 first =
        jl::raycast(q, rd, jl::kc<double>(), 0.0, params.iterations, params.marchSteps, params.precis);
    EXPECT_EQ(first.x, jl::kPrecis<double>);
}

// Through the library: the round cube's sphere tracing reports an earlier t.
TEST(AccuracyKnobsThreshold, SignedDistanceShaderReportsAnEarlierHit) {
    D3D12Rig reference;
    addRoundCube(reference);
    const auto strict = reference.probe(kRoundCubeRay).probe;
    Accuracy loose;
    loose.thresholdFactor = 1000.0;
    D3D12Rig rig(loose);
    addRoundCube(rig);
    const auto early = rig.probe(kRoundCubeRay).probe;
    ASSERT_EQ(strict.closestHits, 1);
    ASSERT_EQ(early.closestHits, 1);
    EXPECT_LT(early.t, strict.t - 1e-3f);
}

// =======================================================================================================
// mandelbulbIterations, juliaIterations
// =======================================================================================================

TEST(AccuracyKnobsIterations, MandelbulbIterationsChangeTheEstimator) {
    namespace mb = math::mandelbulb;
    Accuracy a;
    a.mandelbulbIterations = 8;
    EXPECT_EQ(proceduray::mandelbulbParams<double>(a).iterations, 8);
    a.mandelbulbIterations = 1;
    const auto one = proceduray::mandelbulbParams<double>(a);
    EXPECT_EQ(one.iterations, 1);

    // Near the surface the DE and the orbit trap depend on the iterations; one iteration is the closed form
    // 0.25·log(m1)·sqrt(m1)/dz1 with dz1 = 8·|p|^7 + 1.
    const dvec3 p(0.6, 0.3, -0.5);
    glm::dvec4 trap4, trap1;
    const double d4 = mb::mdist(p, trap4);
    const double d1 = mb::mdist(p, trap1, one.iterations);
    EXPECT_NE(d4, d1);
    EXPECT_NE(trap4, trap1);
    const double r = glm::length(p);
    const double b = 8.0 * std::acos(p.y / r), phi = 8.0 * std::atan2(p.x, p.z);
    const dvec3 w = p + std::pow(r, 8.0) * dvec3(std::sin(b) * std::sin(phi), std::cos(b), std::sin(b) * std::cos(phi));
    const double m1 = glm::dot(w, w);
    EXPECT_NEAR(d1, 0.25 * std::log(m1) * std::sqrt(m1) / (8.0 * std::pow(r, 7.0) + 1.0), 1e-9);

    const dvec3 ro(0.05, 0.1, -1.4), rd(0, 0, 1);
    const auto hit4 = mb::MandelbulbDistance(ro, rd, 129);
    const auto hit1 = mb::MandelbulbDistance(ro, rd, 129, one);
    ASSERT_TRUE(hit4.hit);
    ASSERT_TRUE(hit1.hit);
    EXPECT_GT(std::abs(hit1.thit - hit4.thit), 1e-3);
    EXPECT_NEAR(glm::length(hit1.normal), 1.0, 1e-9);
}

TEST(AccuracyKnobsIterations, JuliaIterationsChangeTheEstimatorAndTheCount) {
    namespace jl = math::julia;
    Accuracy a;
    a.juliaIterations = 5;
    const auto params = proceduray::juliaParams<double>(a);
    EXPECT_EQ(params.iterations, 5);

    // Inside the set the iteration count survives every iteration: n = iMax.
    const dvec3 inside(0.6, -0.2, 0.3);
    const glm::dvec2 inside200 = jl::jdist(inside, jl::kc<double>(), 200);
    const glm::dvec2 inside5 = jl::jdist(inside, jl::kc<double>(), params.iterations);
    EXPECT_EQ(inside200.y, 200.0);
    EXPECT_EQ(inside5.y, 5.0);
    EXPECT_NE(inside200.x, inside5.x);

    const dvec3 local(0, 1.25, -2.875), rd(0, 0, 1);
    const auto hit200 = jl::JuliaDistance(local, rd);
    const auto hit5 = jl::JuliaDistance(local, rd, params);
    ASSERT_TRUE(hit200.hit);
    ASSERT_TRUE(hit5.hit);
    EXPECT_LE(hit5.resT.y, 5.0);
    EXPECT_NE(hit5.resT.x, hit200.resT.x);
    EXPECT_NEAR(glm::length(hit5.normal), 1.0, 1e-9);
}

// Through the library: the Mandelbulb's report (t and orbit trap) and the Julia's iteration count follow the knobs.
TEST(AccuracyKnobsIterations, IntersectionShadersUseTheIterations) {
    ProcedurayRig reference;
    addMandelbulb(reference);
    addJulia(reference);
    const auto mandelbulb = reference.probe(kMandelbulbRay).probe;
    const auto julia = reference.probe(kJuliaRay).probe;
    ASSERT_EQ(mandelbulb.closestHits, 1);
    ASSERT_EQ(julia.closestHits, 1);
    EXPECT_GT(julia.attr.color.y, 5.0f);

    Accuracy a;
    a.mandelbulbIterations = 1;
    a.juliaIterations = 5;
    ProcedurayRig rig(a);
    addMandelbulb(rig);
    addJulia(rig);
    const auto mandelbulb1 = rig.probe(kMandelbulbRay).probe;
    const auto julia5 = rig.probe(kJuliaRay).probe;
    ASSERT_EQ(mandelbulb1.closestHits, 1);
    EXPECT_NE(mandelbulb1.attr.color, mandelbulb.attr.color);
    ASSERT_EQ(julia5.closestHits, 1);
    EXPECT_LE(julia5.attr.color.y, 5.0f);
}

// =======================================================================================================
// normalEpsilonFactor
// =======================================================================================================

// A normal that moved by more than rounding but less than `bound` radians, and is still unit length.
template <typename T>
void expectSlightlyMovedUnitNormal(const tvec3<T>& reference, const tvec3<T>& moved, double bound,
                                   const char* what) {
    const double angle = angleBetween(vec3(reference), vec3(moved));
    EXPECT_GT(angle, 1e-6) << what;
    EXPECT_LT(angle, bound) << what;
    EXPECT_NEAR(glm::length(glm::dvec3(moved)), 1.0, 1e-5) << what;
}

// The offsets scale. The smooth fields' normals (Pac-man's head, the metaballs) move by little for a hundred times
// the offset; the fractals' (at points of their surfaces) already move by a few hundredths of a radian for twice it.
TEST(AccuracyKnobsNormalEpsilon, OffsetsScaleAndNormalsMoveSlightly) {
    Accuracy wide;
    wide.normalEpsilonFactor = 100.0;
    const auto sdfParams = proceduray::sphereTraceParams(wide, 1.0);
    EXPECT_EQ(sdfParams.normalOffset, math::tetrahedralOffset<double>() * 100.0);
    EXPECT_EQ(d3d12::sphereTraceParams(wide, 1.0).normalOffset, sdfParams.normalOffset);
    EXPECT_EQ(proceduray::mandelbulbParams<double>(wide).normalOffset, math::tetrahedralOffset<double>() * 100.0);
    EXPECT_EQ(proceduray::juliaParams<double>(wide).normalOffset, math::julia::calcNormalOffset<double>() * 100.0);
    EXPECT_EQ(d3d12::metaballsParams<double>(wide).normalOffset, math::metaballsNormalOffset<double>() * 100.0);

    // The Pac-man's head (H1): the SDF normal at the same hit point.
    const auto sdf = [](const dvec3& p) { return math::pacman::pacMan(p, 0.0); };
    const Ray<double> h1{dvec3(0, -0.2, 1), dvec3(0, 0, -1)};
    const auto extent = math::fixtures::radianceExtent<double>();
    const auto narrow =
        math::RaySignedDistancePrimitiveTest(h1, extent, sdf, proceduray::sphereTraceParams(Accuracy{}, 1.0));
    const auto broad = math::RaySignedDistancePrimitiveTest(h1, extent, sdf, sdfParams);
    ASSERT_TRUE(narrow.hit);
    ASSERT_TRUE(broad.hit);
    EXPECT_EQ(broad.thit, narrow.thit);
    expectSlightlyMovedUnitNormal(narrow.normal, broad.normal, 0.05, "Pac-man");

    // The fractal normals where the converged marches of the tests above end, and the metaballs' inside the blend.
    Accuracy twice;
    twice.normalEpsilonFactor = 2.0;
    const auto mb = math::mandelbulb::MandelbulbDistance(dvec3(0.05, 0.1, -1.4), dvec3(0, 0, 1), 129);
    ASSERT_TRUE(mb.hit);
    const auto mbParams = proceduray::mandelbulbParams<double>(twice);
    expectSlightlyMovedUnitNormal(mb.normal, math::mandelbulb::calcNormal(mb.pos, mbParams.normalOffset), 0.1,
                                  "Mandelbulb");
    EXPECT_EQ(bitsOf(math::mandelbulb::MandelbulbDistance(dvec3(0.05, 0.1, -1.4), dvec3(0, 0, 1), 129, mbParams).thit),
              bitsOf(mb.thit));
    const dvec3 q(0, -0.5, -1.15), rd(0, 0, 1);
    const dvec3 pj = q + math::julia::raycast(q, rd).x * rd;
    const auto jParams = proceduray::juliaParams<double>(twice);
    expectSlightlyMovedUnitNormal(
        math::julia::calcNormal(pj), math::julia::calcNormal(pj, math::julia::kc<double>(), 200, jParams.normalOffset),
        0.1, "Julia");
    const auto blobs = math::InitializeAnimatedMetaballs(0.0, 12.0);
    const dvec3 pb(-0.2, -0.3, 0.1);
    const double e = d3d12::metaballsParams<double>(wide).normalOffset;
    expectSlightlyMovedUnitNormal(math::CalculateMetaballsNormal(pb, blobs),
                                  math::CalculateMetaballsNormal(pb, blobs, e), 0.05, "metaballs");
}

// Through the library: the Pac-man's and the metaballs' reported normals (world space) move slightly and stay unit
// length; the hits stay where they were.
TEST(AccuracyKnobsNormalEpsilon, IntersectionShadersReportTheMovedNormals) {
    Accuracy wide;
    wide.normalEpsilonFactor = 100.0;
    ProcedurayRig pacman, pacmanWide(wide);
    addPacmanA(pacman);
    addPacmanA(pacmanWide);
    const auto p = pacman.probe(kPacmanRay).probe;
    const auto pw = pacmanWide.probe(kPacmanRay).probe;
    ASSERT_EQ(p.closestHits, 1);
    ASSERT_EQ(pw.closestHits, 1);
    EXPECT_EQ(pw.t, p.t);
    expectSlightlyMovedUnitNormal(p.attr.normal, pw.attr.normal, 0.05, "Pac-man");

    D3D12Rig metaballs, metaballsWide(wide);
    addMetaballs(metaballs);
    addMetaballs(metaballsWide);
    const auto m = metaballs.probe(kMetaballsRay).probe;
    const auto mw = metaballsWide.probe(kMetaballsRay).probe;
    ASSERT_EQ(m.closestHits, 1);
    ASSERT_EQ(mw.closestHits, 1);
    EXPECT_EQ(mw.t, m.t);
    expectSlightlyMovedUnitNormal(m.attr.normal, mw.attr.normal, 0.05, "metaballs");
}

// =======================================================================================================
// metaballSteps
// =======================================================================================================

// Four times the samples: the first sample over the threshold comes about four times later in the count and no
// later along the ray (the coarse samples are among the fine ones), within one coarse step.
TEST(AccuracyKnobsMetaballSteps, MoreSamplesFindTheSurfaceOnAFinerGrid) {
    Accuracy fine;
    fine.metaballSteps = 512;
    const auto params = d3d12::metaballsParams<double>(fine);
    EXPECT_EQ(params.maxSteps, 512u);
    const Ray<double> ray{dvec3(-2, -0.3, -0.4), dvec3(1, 0, 0)};
    const RayExtent<double> extent{0, 100, true, false};
    const auto coarse = math::RayMetaballsIntersectionTest(ray, extent, 0.0);
    const auto finer = math::RayMetaballsIntersectionTest(ray, extent, 0.0, 12.0, params);
    ASSERT_TRUE(coarse.hit);
    ASSERT_TRUE(finer.hit);
    EXPECT_LT(finer.thit, coarse.thit);
    double tmin = 0, tmax = 0;
    math::FindIntersectingMetaballs(ray, extent, tmin, tmax, math::InitializeAnimatedMetaballs(0.0, 12.0));
    EXPECT_GT(finer.thit, coarse.thit - (tmax - tmin) / 128.0 - 1e-12);
    EXPECT_GE(int(finer.step), 4 * int(coarse.step) - 6);
    EXPECT_LE(int(finer.step), 4 * int(coarse.step));

    Accuracy few;
    few.metaballSteps = 1;  // one sample, at tmin, outside every ball: no hit
    EXPECT_FALSE(math::RayMetaballsIntersectionTest(ray, extent, 0.0, 12.0, d3d12::metaballsParams<double>(few)).hit);
}

// Through the library: the volumetric shader reports the hit of the finer march.
TEST(AccuracyKnobsMetaballSteps, VolumetricShaderMarchesTheSamples) {
    D3D12Rig reference;
    addMetaballs(reference);
    const auto coarse = reference.probe(kMetaballsRay).probe;
    Accuracy fine;
    fine.metaballSteps = 512;
    D3D12Rig rig(fine);
    addMetaballs(rig);
    const auto finer = rig.probe(kMetaballsRay).probe;
    ASSERT_EQ(coarse.closestHits, 1);
    ASSERT_EQ(finer.closestHits, 1);
    EXPECT_LT(finer.t, coarse.t);
}

// =======================================================================================================
// maxRecursionDepth
// =======================================================================================================

// Two mirrors facing each other (reflective slabs or ground planes, the lower one facing up, the upper one down)
// and a camera between them looking down at a slant: the reflections bounce far more often than any depth tested,
// so the recursion stops only at MAX_RAY_RECURSION_DEPTH. Each level's hit traces a shadow and a reflection ray.
const vec3 kMirrorEye(-50, 10, 0);
const vec3 kMirrorTarget(-49, 8, 0);

size_t procedurayMirrorLevels(const Accuracy& accuracy) {
    ProcedurayRig rig(accuracy);
    rig.addTriangles(Matrix3x4::scale(vec3(120, 15, 120)), kSlabMaterial);  // top face y = 3, facing up
    rig.addTriangles(Matrix3x4::translation(vec3(0, 20, 0)) * Matrix3x4::scale(vec3(120, 15, 120)),
                     kSlabMaterial);  // bottom face y = 17, facing down
    return rig.render(kMirrorEye, kMirrorTarget).levels();
}

size_t d3d12MirrorLevels(const Accuracy& accuracy) {
    const PrimitiveConstantBuffer mirror{vec4(0.9f, 0.9f, 0.9f, 1.0f), 0.5f, 0.5f, 0.4f, 50.0f, 1.0f, vec3(0.0f)};
    D3D12Rig rig(accuracy);
    Matrix3x4 floor;  // the unit quad grown to [-100, 100]^2 at y = 0
    floor.m[0] = {200.0f, 0.0f, 0.0f, -100.0f};
    floor.m[1] = {0.0f, 1.0f, 0.0f, 0.0f};
    floor.m[2] = {0.0f, 0.0f, 200.0f, -100.0f};
    Matrix3x4 ceiling;  // the same, turned over about x and raised to y = 14
    ceiling.m[0] = {200.0f, 0.0f, 0.0f, -100.0f};
    ceiling.m[1] = {0.0f, -1.0f, 0.0f, 14.0f};
    ceiling.m[2] = {0.0f, 0.0f, -200.0f, 100.0f};
    rig.addTriangles(floor, mirror);
    rig.addTriangles(ceiling, mirror);
    return rig.render(kMirrorEye, kMirrorTarget).levels();
}

TEST(AccuracyKnobsRecursion, MaxRecursionDepthSetsTheTraceRayLevels) {
    for (const uint32_t depth : {1u, 2u, 5u, 8u}) {
        Accuracy a;
        a.maxRecursionDepth = depth;
        EXPECT_EQ(proceduray::maxRayRecursionDepth(a), depth);
        EXPECT_EQ(d3d12::maxRayRecursionDepth(a), depth);
        EXPECT_EQ(procedurayMirrorLevels(a), depth) << "Proceduray, depth " << depth;
        EXPECT_EQ(d3d12MirrorLevels(a), depth) << "D3D12, depth " << depth;
    }
    EXPECT_EQ(procedurayMirrorLevels(Accuracy{}), 3u);
    EXPECT_EQ(d3d12MirrorLevels(Accuracy{}), 3u);
}

// ClosestHit_Julia brightens its albedo at recursionDepth == MAX_RAY_RECURSION_DEPTH - 1: a primary hit (depth 1)
// gets it with a depth of 2, not with the HLSL's 3; the rays traced are the same (the reflection misses).
TEST(AccuracyKnobsRecursion, JuliaColourTermFollowsTheDepth) {
    const vec3 eye = kJuliaRay.Origin;
    const vec3 target = eye + kJuliaRay.Direction;
    ProcedurayRig reference;
    addJulia(reference, false);
    const auto plain = reference.render(eye, target);
    Accuracy two;
    two.maxRecursionDepth = 2;
    ProcedurayRig rig(two);
    addJulia(rig, false);
    const auto bright = rig.render(eye, target);
    EXPECT_EQ(bright.stats.raysPerDepth, plain.stats.raysPerDepth);
    EXPECT_EQ(plain.levels(), 2u);
    for (int c = 0; c < 3; ++c) EXPECT_GT(bright.pixel[c], plain.pixel[c] + 0.01f) << "component " << c;
}

// =======================================================================================================
// Defaults through the factories
// =======================================================================================================

// A library built with the HLSL values spelled out renders what one built with Accuracy{} renders, bit for bit,
// in both precisions (the mirrors for the recursion, the fractals and the metaballs for the marches).
TEST(AccuracyKnobsDefaultLibraries, SpelledOutHlslValuesRenderTheDefaultPixels) {
    for (const Precision precision : {Precision::Float, Precision::Double}) {
        const auto renderProceduray = [precision](const Accuracy& a) {
            ProcedurayRig rig(a, precision);
            addPacmanA(rig, false);
            addMandelbulb(rig, false);
            addJulia(rig, false);
            std::vector<vec4> pixels;
            pixels.push_back(rig.render(kPacmanRay.Origin, kPacmanRay.Origin + kPacmanRay.Direction).pixel);
            pixels.push_back(rig.render(kMandelbulbRay.Origin, kMandelbulbRay.Origin + kMandelbulbRay.Direction).pixel);
            pixels.push_back(rig.render(kJuliaRay.Origin, kJuliaRay.Origin + kJuliaRay.Direction).pixel);
            return pixels;
        };
        const auto renderD3D12 = [precision](const Accuracy& a) {
            D3D12Rig rig(a, precision);
            addMetaballs(rig);
            addRoundCube(rig);
            std::vector<vec4> reports;  // (normal, t)
            for (const RayDesc& ray : {kMetaballsRay, kRoundCubeRay}) {
                const auto probe = rig.probe(ray).probe;
                EXPECT_EQ(probe.closestHits, 1);
                reports.push_back(vec4(probe.attr.normal, probe.t));
            }
            return reports;
        };
        const auto a = renderProceduray(Accuracy{});
        const auto b = renderProceduray(spelledOutHlslAccuracy());
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) expectSameBits(a[i], b[i], "Proceduray pixel " + std::to_string(i));
        const auto c = renderD3D12(Accuracy{});
        const auto d = renderD3D12(spelledOutHlslAccuracy());
        for (size_t i = 0; i < c.size(); ++i) expectSameBits(c[i], d[i], "D3D12 report " + std::to_string(i));
    }
}

}  // namespace
}  // namespace refray::procedural
