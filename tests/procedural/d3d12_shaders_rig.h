// The D3D12 shader tests' rig (d3d12_shaders_test.cpp, d3d12_shaders_intersection_test.cpp,
// d3d12_shaders_shading_test.cpp): the sample's camera in double, and a tiny Device scene of the ground plane and
// any subset of the ten AABB primitives of the fact sheet (§1.2-1.4), with probe hit groups and a TraceRay recorder.
#pragma once

#include "procedural/d3d12/d3d12_shaders.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "emulator/device.h"
#include "emulator/shader_api.h"
#include "emulator/trace.h"

// Its own namespace: other test files of this binary have a Probe, a Camera and a transform of their own.
namespace refray::procedural::d3d12::shaders_rig {

using namespace refray::dxr;
using glm::dvec4;

// ---- The sample's camera (§1.6), built here in double --------------------------------------------------

using DMat4 = glm::dmat4;  // indexed [row][column] in row-vector form; glm::inverse does not care which

inline DMat4 multiply(const DMat4& a, const DMat4& b) {
    DMat4 r(0.0);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) r[i][j] += a[i][k] * b[k][j];
    return r;
}

struct Camera {
    Float4x4 projectionToWorld;
    vec4 position;
};

// XMMatrixLookAtLH · XMMatrixPerspectiveFovLH(45°, aspect, 0.01, 125), inverted; eye and up rotated by 45° about y.
inline Camera sampleCamera(double width, double height) {
    const dvec3 eye0(0.0, 5.3, -17.0), right(1, 0, 0);
    const dvec3 dir0 = glm::normalize(-eye0);
    const dvec3 up0 = glm::normalize(glm::cross(dir0, right));
    const double c = std::cos(std::numbers::pi / 4), s = std::sin(std::numbers::pi / 4);
    const auto rotateY = [&](dvec3 p) { return dvec3(p.x * c + p.z * s, p.y, -p.x * s + p.z * c); };
    const dvec3 eye = rotateY(eye0), up = rotateY(up0);

    const dvec3 zAxis = glm::normalize(-eye);
    const dvec3 xAxis = glm::normalize(glm::cross(up, zAxis));
    const dvec3 yAxis = glm::cross(zAxis, xAxis);
    DMat4 view(0.0);
    for (int i = 0; i < 3; ++i) view[i] = dvec4(xAxis[i], yAxis[i], zAxis[i], 0.0);
    view[3] = dvec4(-glm::dot(xAxis, eye), -glm::dot(yAxis, eye), -glm::dot(zAxis, eye), 1.0);

    const double n = 0.01, f = 125.0;
    const double h = 1.0 / std::tan(std::numbers::pi / 8), r = f / (f - n);
    DMat4 proj(0.0);
    proj[0][0] = h / (width / height);
    proj[1][1] = h;
    proj[2][2] = r;
    proj[2][3] = 1.0;
    proj[3][2] = -r * n;

    const DMat4 inverse = glm::inverse(multiply(view, proj));
    Camera camera;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) camera.projectionToWorld.m[i][j] = float(inverse[i][j]);
    camera.position = vec4(vec3(eye), 1.0f);
    return camera;
}

// ---- A scene rig: the ground plane and any subset of the ten AABB primitives ---------------------------

enum class IS { Analytic = 0, Volumetric = 1, SignedDistance = 2 };

struct PrimitiveSpec {
    vec3 offset, size, scale;
    bool rotates;
    IS is;
    uint32_t primitiveType;
    PrimitiveConstantBuffer material;
};

inline constexpr vec4 kGreen{0.1f, 1.0f, 0.5f, 1.0f}, kRed{1.0f, 0.5f, 0.5f, 1.0f}, kYellow{1.0f, 1.0f, 0.5f, 1.0f},
    kChrome{0.549f, 0.556f, 0.554f, 1.0f};
constexpr PrimitiveConstantBuffer material(vec4 albedo, float reflectanceCoef = 0.0f, float diffuseCoef = 0.9f,
                                           float specularCoef = 0.7f, float specularPower = 50.0f,
                                           float stepScale = 1.0f) {
    return {albedo, reflectanceCoef, diffuseCoef, specularCoef, specularPower, stepScale, vec3(0.0f)};
}
inline constexpr PrimitiveConstantBuffer kPlaneMaterial = material({0.9f, 0.9f, 0.9f, 1.0f}, 0.25f, 1.0f, 0.4f, 50.0f);

// §1.3 and §1.4.
inline const PrimitiveSpec kPrimitives[10] = {
    {{3, 0, 0}, {2, 3, 2}, {1, 1.5f, 1}, false, IS::Analytic, 0, material(kRed)},
    {{2.25f, 0, 0.75f}, {3, 3, 3}, vec3(1.5f), true, IS::Analytic, 1, material(kChrome, 1.0f)},
    {{0, 0, 0}, {3, 3, 3}, vec3(1.5f), true, IS::Volumetric, 0, material(kChrome, 1.0f)},
    {{2, 0, 0}, {2, 2, 2}, vec3(1), false, IS::SignedDistance, 0, material(kGreen)},
    {{0, 0, 2}, {2, 2, 2}, vec3(1), false, IS::SignedDistance, 1, material(kGreen)},
    {{0.75f, -0.1f, 2.25f}, {3, 3, 3}, vec3(1.5f), false, IS::SignedDistance, 2, material(kChrome, 1.0f)},
    {{0, 0, 1}, {2, 2, 2}, vec3(1), true, IS::SignedDistance, 3, material(kYellow, 0.0f, 1.0f, 0.7f, 50.0f, 0.5f)},
    {{1, 0, 0}, {2, 2, 2}, vec3(1), true, IS::SignedDistance, 4, material(kYellow, 0.0f, 1.0f, 0.1f, 2.0f)},
    {{0, 0, 3}, {2, 3, 2}, {1, 1.5f, 1}, false, IS::SignedDistance, 5, material(kRed)},
    {{2, 0, 2}, {6, 6, 6}, vec3(3), false, IS::SignedDistance, 6, material(kGreen, 0.0f, 1.0f, 0.1f, 4.0f, 0.8f)},
};

inline RaytracingAABB primitiveAABB(int i) {
    const vec3 lo = vec3(-7.0f, -1.0f, -7.0f) + kPrimitives[i].offset * 4.0f;
    const vec3 hi = lo + kPrimitives[i].size;
    return {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z};
}

// localSpaceToBottomLevelAS = S·R·Tr (row vectors), R = RotationY(-2T) for the rotating primitives.
inline DMat4 localSpaceToBottomLevelAS(int i, double T) {
    const PrimitiveSpec& p = kPrimitives[i];
    const RaytracingAABB box = primitiveAABB(i);
    const dvec3 centre(0.5 * (double(box.MinX) + box.MaxX), 0.5 * (double(box.MinY) + box.MaxY),
                       0.5 * (double(box.MinZ) + box.MaxZ));
    const double theta = p.rotates ? -2.0 * T : 0.0;
    DMat4 R(1.0);
    R[0][0] = std::cos(theta), R[0][2] = -std::sin(theta);
    R[2][0] = std::sin(theta), R[2][2] = std::cos(theta);
    DMat4 S(1.0), Tr(1.0);
    for (int k = 0; k < 3; ++k) S[k][k] = p.scale[k], Tr[3][k] = centre[k];
    return multiply(multiply(S, R), Tr);
}

inline PrimitiveInstancePerFrameBuffer primitiveTransforms(int i, double T) {
    const DMat4 forward = localSpaceToBottomLevelAS(i, T);
    const DMat4 inverse = glm::inverse(forward);
    PrimitiveInstancePerFrameBuffer out;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
            out.localSpaceToBottomLevelAS.m[r][c] = float(forward[r][c]);
            out.bottomLevelASToLocalSpace.m[r][c] = float(inverse[r][c]);
        }
    return out;
}

// Row vector times the 3x3 part, plus the translation row when w = 1.
inline dvec3 transform(const DMat4& M, dvec3 v, double w) {
    dvec3 r;
    for (int j = 0; j < 3; ++j) r[j] = v.x * M[0][j] + v.y * M[1][j] + v.z * M[2][j] + w * M[3][j];
    return r;
}

inline const char* kRadianceGroups[3] = {"MyHitGroup_AABB_AnalyticPrimitive", "MyHitGroup_AABB_VolumetricPrimitive",
                                  "MyHitGroup_AABB_SignedDistancePrimitive"};
inline const char* kIntersectionShaders[3] = {"MyIntersectionShader_AnalyticPrimitive",
                                       "MyIntersectionShader_VolumetricPrimitive",
                                       "MyIntersectionShader_SignedDistancePrimitive"};

// What the probe closest hits saw of the radiance ray's committed hit.
struct Probe {
    int closestHits = 0;
    int misses = 0;
    float t = -1.0f;
    uint32_t instanceIndex = ~0u;
    uint32_t geometryIndex = ~0u;
    uint32_t hitKind = ~0u;
    vec3 position{0.0f};
    vec3 normal{0.0f};  // the attributes' normal (AABBs only)
};

class D3D12Rig {
public:
    // TLAS instance 0 is the plane (if `withPlane`), then the AABB instance whose geometries are `primitives`, in
    // that order (GeometryIndex = position). Every record follows §1.8: 2 + 2·g + r for the AABB geometries.
    D3D12Rig(bool withPlane, std::vector<int> primitives, float T = 0.0f)
        : withPlane_(withPlane), primitives_(std::move(primitives)) {
        GpuMemory& memory = device.memory();
        std::vector<InstanceDesc> instances;
        if (withPlane_) {
            GeometryDesc g;
            g.Type = GeometryType::Triangles;
            g.Flags = GEOMETRY_FLAG_OPAQUE;
            g.Triangles.IndexFormat = Format::R16_UINT;
            g.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
            g.Triangles.IndexCount = uint32_t(kPlaneIndices.size());
            g.Triangles.VertexCount = uint32_t(kPlaneVertices.size());
            g.Triangles.IndexBuffer = memory.upload(kPlaneIndices.data(), sizeof(kPlaneIndices), "plane indices");
            g.Triangles.VertexBuffer = {memory.upload(kPlaneVertices.data(), sizeof(kPlaneVertices), "plane vertices"),
                                        sizeof(Vertex)};
            const GpuVirtualAddress blas = device.buildBottomLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, {g}});
            const Matrix3x4 transform =
                Matrix3x4::translation(vec3(-979.3f, 0.0f, -979.3f)) * Matrix3x4::scale(vec3(2798.0f, 2.0f, 2798.0f));
            instances.push_back(makeInstanceDesc(transform, 0, 1, 0, INSTANCE_FLAG_NONE, blas));
        }
        if (!primitives_.empty()) {
            BottomLevelInputs inputs{BUILD_FLAG_PREFER_FAST_TRACE, {}};
            for (int i : primitives_) {
                const RaytracingAABB box = primitiveAABB(i);
                GeometryDesc g;
                g.Type = GeometryType::ProceduralPrimitiveAABBs;
                g.Flags = GEOMETRY_FLAG_OPAQUE;
                g.AABBs.AABBCount = 1;
                g.AABBs.AABBs = {memory.upload(&box, sizeof box, "AABB"), sizeof box};
                inputs.GeometryDescs.push_back(g);
            }
            const GpuVirtualAddress blas = device.buildBottomLevelAS(inputs);
            instances.push_back(makeInstanceDesc(Matrix3x4::translation(vec3(0, 1, 0)), 0, 1,
                                                 /*BLAS type AABB x ray type count*/ 2, INSTANCE_FLAG_NONE, blas));
        }
        tlas_ = device.buildTopLevelAS(
            {BUILD_FLAG_NONE, uint32_t(instances.size()), ElementsLayout::Array, memory.upload(instances, "instances")});

        std::vector<PrimitiveInstancePerFrameBuffer> perFrame;
        for (int i = 0; i < 10; ++i) perFrame.push_back(primitiveTransforms(i, T));
        attributeBuffer_ = memory.upload(perFrame, "g_AABBPrimitiveAttributes");

        scene.lightPosition = vec4(0.0f, 18.0f, -20.0f, 0.0f);
        scene.lightAmbientColor = vec4(0.25f, 0.25f, 0.25f, 1.0f);
        scene.lightDiffuseColor = vec4(0.6f, 0.6f, 0.6f, 1.0f);
        scene.elapsedTime = T;
        addProbeShaders();
    }

    // A camera at `position` whose pixel centre of a 1×1 dispatch looks along `forward` (projectionToWorld row 3 is
    // the point one unit ahead); NDC s and t move that point by `right` and `up` per unit.
    void setPointCamera(vec3 position, vec3 forward, vec3 right, vec3 up) {
        scene.cameraPosition = vec4(position, 1.0f);
        scene.projectionToWorld = Float4x4{};
        scene.projectionToWorld.m[0] = {right.x, right.y, right.z, 0.0f};
        scene.projectionToWorld.m[1] = {up.x, up.y, up.z, 0.0f};
        const vec3 ahead = position + forward;
        scene.projectionToWorld.m[3] = {ahead.x, ahead.y, ahead.z, 1.0f};
    }

    // Dispatches width×height with ray generation `rayGen`. With `useProbes`, the radiance records use probe closest
    // hits (the library's intersection shaders stay) and the radiance miss is a probe.
    DispatchResult dispatch(const std::string& rayGen, bool useProbes, uint32_t width = 1, uint32_t height = 1) {
        StateObjectDesc desc;
        desc.name = "d3d12 test";
        desc.libraries = {{makeD3D12ShaderLibrary(precision, traceRay), {}}, {probes_, {}}};
        desc.hitGroups = d3d12HitGroups();
        std::vector<std::string> triangleGroups = triangleHitGroupNames();
        std::vector<std::string> aabbGroups = aabbHitGroupNames();
        desc.hitGroups.push_back({"Probe_Triangle", HitGroupType::Triangles, "", "CH_ProbeTriangle", ""});
        triangleGroups.push_back("Probe_Triangle");
        for (int k = 0; k < 3; ++k) {
            desc.hitGroups.push_back({std::string("Probe_") + kRadianceGroups[k], HitGroupType::ProceduralPrimitive, "",
                                      "CH_ProbeAABB", kIntersectionShaders[k]});
            aabbGroups.push_back(std::string("Probe_") + kRadianceGroups[k]);
        }
        const RootSignaturePtr triangleSignature = RootSignature::create(triangleLocalRootSignatureDesc());
        const RootSignaturePtr aabbSignature = RootSignature::create(aabbLocalRootSignatureDesc());
        const RootSignaturePtr globalSignature = RootSignature::create(globalRootSignatureDesc());
        desc.localRootSignatures = {{triangleSignature, triangleGroups}, {aabbSignature, aabbGroups}};
        desc.globalRootSignatures = {{globalSignature, {}}};
        desc.shaderConfigs = {{kMaxPayloadSizeInBytes, kMaxAttributeSizeInBytes}};
        desc.pipelineConfigs = {{MAX_RAY_RECURSION_DEPTH, PIPELINE_FLAG_NONE}};
        const StateObjectPtr so = StateObject::create(desc);

        GpuMemory& memory = device.memory();
        const std::string prefix = useProbes ? "Probe_" : "";
        ShaderTableBuilder hitGroups("hit groups");
        LocalRootArguments planeArguments(triangleSignature);
        planeArguments.setConstants(kMaterialConstant, kPlaneMaterial);
        hitGroups.addRecord(so->shaderIdentifier(useProbes ? "Probe_Triangle" : "MyHitGroup_Triangle"), planeArguments);
        hitGroups.addRecord(so->shaderIdentifier("MyHitGroup_Triangle_ShadowRay"), planeArguments);
        for (int i : primitives_) {
            const PrimitiveSpec& p = kPrimitives[i];
            LocalRootArguments arguments(aabbSignature);
            arguments.setConstants(kMaterialConstant, p.material);
            arguments.setConstants(kGeometryIndex, PrimitiveInstanceConstantBuffer{uint32_t(i), p.primitiveType});
            const std::string radiance = kRadianceGroups[int(p.is)];
            hitGroups.addRecord(so->shaderIdentifier(prefix + radiance), arguments);
            hitGroups.addRecord(so->shaderIdentifier(radiance + "_ShadowRay"), arguments);
        }

        const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier(rayGen)).upload(memory);
        DispatchRaysDesc rays;
        rays.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
        rays.MissShaderTable = ShaderTableBuilder("miss")
                                   .addRecord(so->shaderIdentifier(useProbes ? "Miss_Probe" : "MyMissShader"))
                                   .addRecord(so->shaderIdentifier("MyMissShader_ShadowRay"))
                                   .upload(memory);
        rays.HitGroupTable = hitGroups.upload(memory);
        rays.Width = width;
        rays.Height = height;
        rays.Depth = 1;

        output = Image(width, height);
        DescriptorHeap& heap = device.createDescriptorHeap(3, "d3d12 test heap");
        heap.setTexture2D(0, DescriptorRangeType::UAV, &output);
        heap.setBuffer(1, DescriptorRangeType::SRV,
                       {memory.upload(kPlaneIndices.data(), sizeof(kPlaneIndices), "g_indices"), sizeof(kPlaneIndices), 0});
        heap.setBuffer(2, DescriptorRangeType::SRV,
                       {memory.upload(boundVertices.data(), sizeof(boundVertices), "g_vertices"),
                        sizeof(boundVertices), sizeof(Vertex)});

        GlobalRootArguments globals(globalSignature);
        globals.setDescriptor(kOutputView, heap.gpuHandle(0));
        globals.setDescriptor(kAccelerationStructure, tlas_);
        globals.setDescriptor(kSceneConstant, memory.upload(&scene, sizeof scene, "g_sceneCB"));
        globals.setDescriptor(kAABBattributeBuffer, attributeBuffer_);
        globals.setDescriptor(kVertexBuffers, heap.gpuHandle(1));
        DispatchOptions options;
        options.threads = 1;
        options.observer = observer;
        return device.dispatchRays(rays, so, &globals, options);
    }

    Device device;
    Precision precision = Precision::Float;  // of the library under test
    TraceRayArgumentSet traceRay = defaultTraceRayArguments();  // of the library under test
    TraceObserver* observer = nullptr;                           // of the dispatch
    SceneConstantBuffer scene{};
    RayDesc probeRay;
    Probe probe;
    uint32_t shadowPayloadWord = 0;  // what RG_ShadowProbe's payload held after its TraceRay
    Image output;
    std::array<Vertex, 4> boundVertices = kPlaneVertices;  // what g_vertices holds (the BLAS uses kPlaneVertices)

private:
    void addProbeShaders() {
        // A shadow ray as TraceShadowRayAndReportIfHit traces it, but with every bit of the payload set.
        probes_->addRayGeneration("RG_ShadowProbe", [this](ShaderContext& ctx) {
            ShadowRayPayload payload{0xffffffffu};
            ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure),
                         RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH |
                             RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
                         TraceRayParameters::InstanceMask, RayType::Shadow, TraceRayParameters::GeometryStride,
                         RayType::Shadow, probeRay, payload);
            shadowPayloadWord = payload.hit;
        });
        probes_->addRayGeneration("RG_Probe", [this](ShaderContext& ctx) {
            RayPayload payload{vec4(0.0f), 1};
            ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure), RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
                         TraceRayParameters::InstanceMask, RayType::Radiance, TraceRayParameters::GeometryStride,
                         RayType::Radiance, probeRay, payload);
        });
        const auto record = [this](ShaderContext& ctx) {
            probe.closestHits++;
            probe.t = ctx.RayTCurrent();
            probe.instanceIndex = ctx.InstanceIndex();
            probe.geometryIndex = ctx.GeometryIndex();
            probe.hitKind = ctx.HitKind();
            probe.position = ctx.WorldRayOrigin() + ctx.RayTCurrent() * ctx.WorldRayDirection();
        };
        probes_->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>(
            "CH_ProbeAABB", [this, record](ShaderContext& ctx, RayPayload&, const ProceduralPrimitiveAttributes& attr) {
                record(ctx);
                probe.normal = attr.normal;
            });
        probes_->addClosestHit<RayPayload, BuiltInTriangleIntersectionAttributes>(
            "CH_ProbeTriangle",
            [record](ShaderContext& ctx, RayPayload&, const BuiltInTriangleIntersectionAttributes&) { record(ctx); });
        probes_->addMiss<RayPayload>("Miss_Probe", [this](ShaderContext&, RayPayload&) { probe.misses++; });
    }

    bool withPlane_;
    std::vector<int> primitives_;
    std::shared_ptr<ShaderLibrary> probes_ = std::make_shared<ShaderLibrary>();
    GpuVirtualAddress tlas_ = 0;
    GpuVirtualAddress attributeBuffer_ = 0;
};

inline void expectNear(vec3 got, vec3 expected, float tolerance, const char* what) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], expected[k], tolerance) << what << " component " << k;
}

// What the TraceRay calls of a dispatch passed, and the hit-group records they read (in program order: the rigs
// dispatch on one thread).
class TraceRayRecorder final : public TraceObserver {
public:
    struct Call {
        uint32_t payloadSize = 0;
        TraceRayArguments arguments;
    };
    struct Lookup {
        HitGroupIndexTerms terms;
        std::string hitGroup;
    };
    void onEvent(const TraceEvent& e) override {
        if (e.kind == TraceEvent::Kind::TraceRay)
            calls.push_back({e.payloadSize, {e.rayContribution, e.multiplier, e.missShaderIndex, e.instanceInclusionMask}});
        else if (e.kind == TraceEvent::Kind::RecordLookup && e.hasTerms)
            lookups.push_back({e.terms, std::string(e.exportName)});
    }
    std::vector<Call> calls;
    std::vector<Lookup> lookups;
};

}  // namespace refray::procedural::d3d12::shaders_rig
