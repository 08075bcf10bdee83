// Tests procedural/d3d12/d3d12_shaders.cpp: the export table, the HLSL struct layouts, the root signatures and hit
// groups, the pure shading helpers, and end-to-end dispatches through tiny Device scenes built from the fact sheet
// (§1.2-1.4): the red box, the analytic spheres, animated metaballs, two SDF primitives, the ground plane's grid,
// shadow and fog, and the first hits of §6 in the whole scene.
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

namespace refray::procedural::d3d12 {
namespace {

using namespace refray::dxr;
using glm::dvec4;

// ---- Exports, hit groups, layouts ------------------------------------------------------------------

TEST(D3D12Shaders, EveryHlslExportExistsWithItsStage) {
    const auto lib = makeD3D12ShaderLibrary();
    const std::map<std::string, ShaderStage> expected = {
        {"MyRaygenShader", ShaderStage::RayGeneration},
        {"MyClosestHitShader_Triangle", ShaderStage::ClosestHit},
        {"MyClosestHitShader_AABB", ShaderStage::ClosestHit},
        {"MyMissShader", ShaderStage::Miss},
        {"MyMissShader_ShadowRay", ShaderStage::Miss},
        {"MyIntersectionShader_AnalyticPrimitive", ShaderStage::Intersection},
        {"MyIntersectionShader_VolumetricPrimitive", ShaderStage::Intersection},
        {"MyIntersectionShader_SignedDistancePrimitive", ShaderStage::Intersection},
    };
    EXPECT_EQ(lib->exports().size(), expected.size());
    for (const auto& [name, stage] : expected) {
        const ShaderExport* e = lib->find(name);
        ASSERT_NE(e, nullptr) << name;
        EXPECT_EQ(e->stage, stage) << name;
    }
}

TEST(D3D12Shaders, ExportsDeclareTheHlslPayloadAndAttributeTypes) {
    const auto lib = makeD3D12ShaderLibrary();
    EXPECT_EQ(lib->find("MyMissShader")->payload, typeTag<RayPayload>());
    EXPECT_EQ(lib->find("MyMissShader_ShadowRay")->payload, typeTag<ShadowRayPayload>());
    EXPECT_EQ(lib->find("MyClosestHitShader_Triangle")->payload, typeTag<RayPayload>());
    EXPECT_EQ(lib->find("MyClosestHitShader_Triangle")->attributes, typeTag<BuiltInTriangleIntersectionAttributes>());
    EXPECT_EQ(lib->find("MyClosestHitShader_AABB")->payload, typeTag<RayPayload>());
    EXPECT_EQ(lib->find("MyClosestHitShader_AABB")->attributes, typeTag<ProceduralPrimitiveAttributes>());
    for (const char* is : {"MyIntersectionShader_AnalyticPrimitive", "MyIntersectionShader_VolumetricPrimitive",
                           "MyIntersectionShader_SignedDistancePrimitive"})
        EXPECT_EQ(lib->find(is)->attributes, typeTag<ProceduralPrimitiveAttributes>()) << is;
}

TEST(D3D12Shaders, HitGroupsFollowCreateHitGroupSubobjects) {
    const auto lib = makeD3D12ShaderLibrary();
    const auto groups = d3d12HitGroups();
    ASSERT_EQ(groups.size(), 8u);
    EXPECT_EQ(groups[0].HitGroupExport, "MyHitGroup_Triangle");
    EXPECT_EQ(groups[0].Type, HitGroupType::Triangles);
    EXPECT_EQ(groups[0].ClosestHitShaderImport, "MyClosestHitShader_Triangle");
    EXPECT_EQ(groups[1].HitGroupExport, "MyHitGroup_Triangle_ShadowRay");
    EXPECT_TRUE(groups[1].ClosestHitShaderImport.empty());
    const char* kinds[3] = {"AnalyticPrimitive", "VolumetricPrimitive", "SignedDistancePrimitive"};
    for (int k = 0; k < 3; ++k) {
        const HitGroupDesc& radiance = groups[2 + 2 * k];
        const HitGroupDesc& shadow = groups[3 + 2 * k];
        EXPECT_EQ(radiance.HitGroupExport, std::string("MyHitGroup_AABB_") + kinds[k]);
        EXPECT_EQ(shadow.HitGroupExport, radiance.HitGroupExport + "_ShadowRay");
        EXPECT_EQ(radiance.Type, HitGroupType::ProceduralPrimitive);
        EXPECT_EQ(shadow.Type, HitGroupType::ProceduralPrimitive);
        EXPECT_EQ(radiance.IntersectionShaderImport, std::string("MyIntersectionShader_") + kinds[k]);
        EXPECT_EQ(shadow.IntersectionShaderImport, radiance.IntersectionShaderImport);
        EXPECT_EQ(radiance.ClosestHitShaderImport, "MyClosestHitShader_AABB");
        EXPECT_TRUE(shadow.ClosestHitShaderImport.empty());
    }
    for (const HitGroupDesc& g : groups) {
        EXPECT_TRUE(g.AnyHitShaderImport.empty()) << g.HitGroupExport;
        for (const std::string& import : {g.ClosestHitShaderImport, g.IntersectionShaderImport})
            if (!import.empty()) {
                EXPECT_NE(lib->find(import), nullptr) << g.HitGroupExport << " imports " << import;
            }
    }
    EXPECT_EQ(triangleHitGroupNames().size(), 2u);
    EXPECT_EQ(aabbHitGroupNames().size(), 6u);
}

TEST(D3D12Shaders, StructLayoutsMatchTheHlsl) {
    EXPECT_EQ(sizeof(RayPayload), 20u);
    EXPECT_EQ(offsetof(RayPayload, recursionDepth), 16u);
    EXPECT_EQ(sizeof(ShadowRayPayload), 4u);
    EXPECT_EQ(sizeof(ProceduralPrimitiveAttributes), 12u);
    EXPECT_EQ(kMaxPayloadSizeInBytes, 20u);
    EXPECT_EQ(kMaxAttributeSizeInBytes, 12u);
    EXPECT_EQ(sizeof(SceneConstantBuffer), 144u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, cameraPosition), 64u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, lightDiffuseColor), 112u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, reflectance), 128u);
    EXPECT_EQ(offsetof(SceneConstantBuffer, elapsedTime), 132u);
    EXPECT_EQ(sizeof(PrimitiveConstantBuffer), 48u);
    EXPECT_EQ(offsetof(PrimitiveConstantBuffer, reflectanceCoef), 16u);
    EXPECT_EQ(offsetof(PrimitiveConstantBuffer, stepScale), 32u);
    EXPECT_EQ(sizeof(PrimitiveInstanceConstantBuffer), 8u);
    EXPECT_EQ(sizeof(PrimitiveInstancePerFrameBuffer), 128u);
    EXPECT_EQ(offsetof(PrimitiveInstancePerFrameBuffer, bottomLevelASToLocalSpace), 64u);
    EXPECT_EQ(sizeof(Vertex), 24u);
    EXPECT_EQ(sizeof(TriangleRootArguments), 48u);
    EXPECT_EQ(sizeof(AABBRootArguments), 56u);
    EXPECT_EQ(offsetof(AABBRootArguments, aabbCB), 48u);
}

TEST(D3D12Shaders, RootSignaturesFollowCreateRootSignatures) {
    const auto global = RootSignature::create(globalRootSignatureDesc());
    ASSERT_EQ(global->parameterCount(), 5u);
    EXPECT_EQ(global->parameter(kOutputView).parameterType, RootParameterType::DescriptorTable);
    EXPECT_EQ(global->parameter(kAccelerationStructure).parameterType, RootParameterType::SRV);
    EXPECT_EQ(global->parameter(kSceneConstant).parameterType, RootParameterType::CBV);
    EXPECT_EQ(global->parameter(kAABBattributeBuffer).parameterType, RootParameterType::SRV);
    EXPECT_EQ(global->parameter(kAABBattributeBuffer).shaderRegister, 3u);
    EXPECT_EQ(global->parameter(kVertexBuffers).ranges.at(0).numDescriptors, 2u);
    EXPECT_EQ(global->parameter(kVertexBuffers).ranges.at(0).baseShaderRegister, 1u);

    const auto triangle = RootSignature::create(triangleLocalRootSignatureDesc());
    EXPECT_EQ(triangle->recordSize(), 32u + 48u);
    const auto aabb = RootSignature::create(aabbLocalRootSignatureDesc());
    EXPECT_EQ(aabb->argumentOffset(kGeometryIndex), 32u + 48u);
    EXPECT_EQ(aabb->recordSize(), 32u + 56u);  // rounds up to the 96-byte hit-group stride of §1.8
}

// ---- Pure helpers ----------------------------------------------------------------------------------

TEST(D3D12Shaders, PlaneIndicesGiveTheUpNormal) {
    const auto* bytes = reinterpret_cast<const uint8_t*>(kPlaneIndices.data());
    EXPECT_EQ(Load3x16BitIndices(0, bytes, sizeof(kPlaneIndices)), uvec3(3, 1, 0));
    EXPECT_EQ(Load3x16BitIndices(6, bytes, sizeof(kPlaneIndices)), uvec3(2, 1, 3));  // not dword aligned
    for (const Vertex& v : kPlaneVertices) EXPECT_EQ(v.normal, vec3(0, 1, 0));
    // FACE-1: both triangles wind so that cross(v1 - v0, v2 - v0) points up.
    for (int tri = 0; tri < 2; ++tri) {
        const vec3 v0 = kPlaneVertices[kPlaneIndices[tri * 3]].position;
        const vec3 v1 = kPlaneVertices[kPlaneIndices[tri * 3 + 1]].position;
        const vec3 v2 = kPlaneVertices[kPlaneIndices[tri * 3 + 2]].position;
        EXPECT_GT(glm::cross(v1 - v0, v2 - v0).y, 0.0f) << "triangle " << tri;
    }
}

TEST(D3D12Shaders, FresnelAndVisibilityFalloff) {
    const vec3 f = FresnelReflectanceSchlick(vec3(0, -1, 0), vec3(0, 1, 0), vec3(0.9f));
    EXPECT_NEAR(f.x, 0.9f, 1e-6f);  // head-on: f0
    const vec3 grazing = FresnelReflectanceSchlick(vec3(1, 0, 0), vec3(0, 1, 0), vec3(0.0f));
    EXPECT_NEAR(grazing.x, 1.0f, 1e-6f);

    const vec4 c(0.2f, 0.4f, 0.6f, 1.0f);
    EXPECT_EQ(ApplyVisibilityFalloff(c, 0.0f), c);
    // §2.11: f = 50% at t = 70.24, 86% at t = 100.
    const vec4 half = ApplyVisibilityFalloff(vec4(0.0f), 70.24f);
    EXPECT_NEAR(half.x, 0.4f, 1e-3f);
    EXPECT_NEAR(half.z, 0.5f, 1e-3f);
    EXPECT_NEAR(ApplyVisibilityFalloff(vec4(0.0f), 100.0f).z, 1.0 - std::exp(-2.0), 1e-4);
}

// The box filter of §2.9: lines 0.02 wide starting at every integer.
TEST(D3D12Shaders, CheckersTextureBoxFilterIntegratesTheGridLines) {
    // Footprint 0.02 centred at u = 3.005 covers [2.995, 3.015]: 0.015 of line, i.e. i_x = 0.75; v = 7.5 sees no line.
    EXPECT_NEAR(CheckersTextureBoxFilter(vec2(3.005f, 7.5f), vec2(0.02f, 0.0f), vec2(0.0f, 0.02f), 50), 0.25f, 1e-4f);
    // Footprint 0.04 over [2.99, 3.03] holds the whole line: i_x = 0.5.
    EXPECT_NEAR(CheckersTextureBoxFilter(vec2(3.01f, 7.5f), vec2(0.0f, 0.04f), vec2(0.04f, 0.0f), 50), 0.5f, 1e-4f);
    // Cell interior and a point on a line, both with a tiny footprint.
    EXPECT_NEAR(CheckersTextureBoxFilter(vec2(0.5f, 0.5f), vec2(1e-3f, 0.0f), vec2(0.0f, 1e-3f), 50), 1.0f, 1e-5f);
    EXPECT_NEAR(CheckersTextureBoxFilter(vec2(4.01f, 0.5f), vec2(1e-3f, 0.0f), vec2(0.0f, 1e-3f), 50), 0.0f, 1e-3f);
    // A footprint of whole cells averages to the line coverage: (1 - 0.02)^2.
    EXPECT_NEAR(CheckersTextureBoxFilter(vec2(10.3f, 20.7f), vec2(4.0f, 0.0f), vec2(0.0f, 4.0f), 50), 0.98f * 0.98f,
                1e-4f);
    // H3: a zero footprint component is 0/0.
    EXPECT_TRUE(std::isnan(CheckersTextureBoxFilter(vec2(0.5f), vec2(0.0f), vec2(0.0f), 50)));
}

TEST(D3D12Shaders, PhongAmbientDiffuseAndShadow) {
    SceneConstantBuffer scene{};
    scene.lightPosition = vec4(0, 18, -20, 0);
    scene.lightAmbientColor = vec4(0.25f, 0.25f, 0.25f, 1.0f);
    scene.lightDiffuseColor = vec4(0.6f, 0.6f, 0.6f, 1.0f);
    const vec4 albedo(1.0f, 0.5f, 0.5f, 1.0f);
    // A downward normal under the light: Kd = 0 and ambient = 0.15·albedo; in shadow there is no specular (I8).
    const vec4 down = CalculatePhongLighting(scene, albedo, vec3(0, -1, 0), true, 0.9f, 0.7f, 50.0f, vec3(0, 1, -20),
                                             vec3(0, 1, 0));
    EXPECT_NEAR(down.x, 0.15f, 1e-6f);
    EXPECT_NEAR(down.y, 0.075f, 1e-6f);
    // Straight below the light, looking down at an up normal: Kd = 1, specular = 1 when lit, 0.35·diffuse in shadow.
    const vec4 lit = CalculatePhongLighting(scene, albedo, vec3(0, 1, 0), false, 0.9f, 0.7f, 50.0f, vec3(0, 0, -20),
                                            vec3(0, -1, 0));
    EXPECT_NEAR(lit.y, 0.5f * 0.25f + 0.9f * 0.6f * 0.5f + 0.7f, 1e-5f);
    const vec4 shadowed = CalculatePhongLighting(scene, albedo, vec3(0, 1, 0), true, 0.9f, 0.7f, 50.0f,
                                                 vec3(0, 0, -20), vec3(0, -1, 0));
    EXPECT_NEAR(shadowed.y, 0.5f * 0.25f + 0.35f * 0.9f * 0.6f * 0.5f, 1e-6f);
}

// ---- The sample's camera (§1.6), built here in double --------------------------------------------------

using DMat4 = glm::dmat4;  // indexed [row][column] in row-vector form; glm::inverse does not care which

DMat4 multiply(const DMat4& a, const DMat4& b) {
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
Camera sampleCamera(double width, double height) {
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

// §6: projectionToWorld and the ray directions of three pixels at 1280×720.
TEST(D3D12Shaders, GenerateCameraRayMatchesTheCheckDirections) {
    const Camera camera = sampleCamera(1280, 720);
    EXPECT_NEAR(camera.projectionToWorld.m[0][0], 0.5206991f, 1e-6f);
    EXPECT_NEAR(camera.projectionToWorld.m[1][1], 0.3954412f, 1e-6f);
    EXPECT_NEAR(camera.projectionToWorld.m[2][0], 1201.985f, 2e-3f);
    EXPECT_NEAR(camera.projectionToWorld.m[3][3], 100.0f, 1e-3f);
    const std::pair<uvec2, vec3> checks[] = {{{0, 0}, {0.184791f, 0.074320f, 0.979964f}},
                                             {{640, 360}, {0.675346f, -0.298185f, 0.674532f}},
                                             {{1279, 719}, {0.846917f, -0.529202f, 0.051744f}}};
    for (const auto& [pixel, expected] : checks) {
        vec3 origin, direction;
        GenerateCameraRay(pixel, uvec2(1280, 720), vec3(camera.position), camera.projectionToWorld, origin, direction);
        EXPECT_EQ(origin, vec3(camera.position));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(direction[k], expected[k], 1e-3f) << pixel.x << "," << pixel.y;
    }
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

constexpr vec4 kGreen{0.1f, 1.0f, 0.5f, 1.0f}, kRed{1.0f, 0.5f, 0.5f, 1.0f}, kYellow{1.0f, 1.0f, 0.5f, 1.0f},
    kChrome{0.549f, 0.556f, 0.554f, 1.0f};
constexpr PrimitiveConstantBuffer material(vec4 albedo, float reflectanceCoef = 0.0f, float diffuseCoef = 0.9f,
                                           float specularCoef = 0.7f, float specularPower = 50.0f,
                                           float stepScale = 1.0f) {
    return {albedo, reflectanceCoef, diffuseCoef, specularCoef, specularPower, stepScale, vec3(0.0f)};
}
constexpr PrimitiveConstantBuffer kPlaneMaterial = material({0.9f, 0.9f, 0.9f, 1.0f}, 0.25f, 1.0f, 0.4f, 50.0f);

// §1.3 and §1.4.
const PrimitiveSpec kPrimitives[10] = {
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

RaytracingAABB primitiveAABB(int i) {
    const vec3 lo = vec3(-7.0f, -1.0f, -7.0f) + kPrimitives[i].offset * 4.0f;
    const vec3 hi = lo + kPrimitives[i].size;
    return {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z};
}

// localSpaceToBottomLevelAS = S·R·Tr (row vectors), R = RotationY(-2T) for the rotating primitives.
DMat4 localSpaceToBottomLevelAS(int i, double T) {
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

PrimitiveInstancePerFrameBuffer primitiveTransforms(int i, double T) {
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
dvec3 transform(const DMat4& M, dvec3 v, double w) {
    dvec3 r;
    for (int j = 0; j < 3; ++j) r[j] = v.x * M[0][j] + v.y * M[1][j] + v.z * M[2][j] + w * M[3][j];
    return r;
}

const char* kRadianceGroups[3] = {"MyHitGroup_AABB_AnalyticPrimitive", "MyHitGroup_AABB_VolumetricPrimitive",
                                  "MyHitGroup_AABB_SignedDistancePrimitive"};
const char* kIntersectionShaders[3] = {"MyIntersectionShader_AnalyticPrimitive",
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

void expectNear(vec3 got, vec3 expected, float tolerance, const char* what) {
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

// ---- Intersection shaders through the probe hit groups ---------------------------------------------------

// FACE-1: a ray going down meets the plane's front face; one coming from below is back-facing and culled.
TEST(D3D12Shaders, FACE_1_GroundPlaneIsHitFromAboveOnly) {
    D3D12Rig down(true, {});
    down.probeRay = {vec3(0.3f, 5.0f, 0.7f), 0.0f, vec3(0, -1, 0), 10000.0f};
    down.dispatch("RG_Probe", true);
    ASSERT_EQ(down.probe.closestHits, 1);
    EXPECT_NEAR(down.probe.t, 5.0f, 1e-5f);
    EXPECT_EQ(down.probe.hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);

    D3D12Rig up(true, {});
    up.probeRay = {vec3(0.3f, -5.0f, 0.7f), 0.0f, vec3(0, 1, 0), 10000.0f};
    up.dispatch("RG_Probe", true);
    EXPECT_EQ(up.probe.closestHits, 0);
    EXPECT_EQ(up.probe.misses, 1);
}

// The red box (i = 0): world box x ∈ [5, 7], y ∈ [0, 3], z ∈ [-7, -5]; scale (1, 1.5, 1).
TEST(D3D12Shaders, AnalyticBoxReportsItsEntryFaceAndIsHollow) {
    D3D12Rig rig(false, {0});
    rig.probeRay = {vec3(0.0f, 1.5f, -6.0f), 0.0f, vec3(1, 0, 0), 10000.0f};
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 5.0f, 1e-5f);
    EXPECT_EQ(rig.probe.hitKind, 0u);
    expectNear(rig.probe.normal, vec3(-1, 0, 0), 1e-6f, "normal");

    // From above, onto the top face (local +y, world y = 3).
    D3D12Rig top(false, {0});
    top.probeRay = {vec3(6.5f, 10.0f, -5.5f), 0.0f, vec3(0, -1, 0), 10000.0f};
    top.dispatch("RG_Probe", true);
    ASSERT_EQ(top.probe.closestHits, 1);
    EXPECT_NEAR(top.probe.t, 7.0f, 1e-5f);
    expectNear(top.probe.normal, vec3(0, 1, 0), 1e-6f, "normal");

    // §2.3 step 5: a ray starting inside the box never hits it.
    D3D12Rig inside(false, {0});
    inside.probeRay = {vec3(6.0f, 1.5f, -6.0f), 0.0f, vec3(1, 0, 0), 10000.0f};
    inside.dispatch("RG_Probe", true);
    EXPECT_EQ(inside.probe.closestHits, 0);
    EXPECT_EQ(inside.probe.misses, 1);
}

// Sphere A of the Spheres primitive (i = 1): local centre (-0.3)³, r 0.6, scale 1.5 -> world r 0.9. A ray 0.45 off
// its centre meets it at dz = sqrt(0.81 - 0.2025) before the centre, with the normal (0, 0.5, -sqrt(3)/2).
TEST(D3D12Shaders, AnalyticSpheresAtT0AndRotatedByTheAnimation) {
    const float dz = std::sqrt(0.81f - 0.2025f);
    {
        D3D12Rig rig(false, {1}, 0.0f);
        // At T = 0 sphere A is centred at (3.05, 1.05, -2.95) (§2.4).
        rig.probeRay = {vec3(3.05f, 1.5f, -10.0f), 0.0f, vec3(0, 0, 1), 10000.0f};
        rig.dispatch("RG_Probe", true);
        ASSERT_EQ(rig.probe.closestHits, 1);
        EXPECT_NEAR(rig.probe.t, 10.0f - 2.95f - dz, 1e-4f);
        expectNear(rig.probe.normal, vec3(0.0f, 0.5f, -dz / 0.9f), 1e-4f, "normal");
    }
    {
        // At T = π/4 the rotation is -π/2: x' = -z, z' = x, so sphere A's offset (-0.45, -0.45, -0.45) from the box
        // centre (3.5, 1.5, -2.5) becomes (0.45, -0.45, -0.45).
        D3D12Rig rig(false, {1}, float(std::numbers::pi / 4));
        rig.probeRay = {vec3(3.95f, 1.5f, -10.0f), 0.0f, vec3(0, 0, 1), 10000.0f};
        rig.dispatch("RG_Probe", true);
        ASSERT_EQ(rig.probe.closestHits, 1);
        EXPECT_NEAR(rig.probe.t, 10.0f - 2.95f - dz, 1e-4f);
        expectNear(rig.probe.normal, vec3(0.0f, 0.5f, -dz / 0.9f), 1e-4f, "normal");
    }
}

// An independent double-precision metaball field (§2.5) for the keyframe interpolant s.
struct Metaballs {
    dvec3 centre[3];
    double radius[3] = {0.45, 0.55, 0.45};
    explicit Metaballs(double s) {
        const dvec3 k0[3] = {{-0.3, -0.3, -0.4}, {0.0, -0.2, 0.5}, {0.4, 0.4, 0.4}};
        const dvec3 k1[3] = {{0.3, -0.3, 0.0}, {0.0, 0.4, 0.5}, {-0.4, 0.2, -0.4}};
        for (int j = 0; j < 3; ++j) centre[j] = k0[j] + s * (k1[j] - k0[j]);
    }
    double field(dvec3 p) const {
        double sum = 0.0;
        for (int j = 0; j < 3; ++j) {
            const double rho = glm::length(p - centre[j]);
            if (rho > radius[j]) continue;
            const double x = (radius[j] - rho) / radius[j];
            sum += x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
        }
        return sum;
    }
};

// The local ray (0, 0.4, -19/3) + t·(0, 0, 2/3): at T = 0 it passes outside balls 0 and 1 and grazes ball 2 (field
// < 0.25); at T = 6 (s = 1) ball 1 sits on it. The reported t is the first of 128 samples with field >= 0.25 (§2.5),
// so it lies within one step after the true surface, which is found here by bisection. The world ray is made from
// the local one with the primitive's transform at T (θ = -12 rad at T = 6), so t is the same in both.
TEST(D3D12Shaders, MetaballsAnimateWithElapsedTime) {
    const dvec3 o(0.0, 0.4, (-15.0 + 5.5) / 1.5), d(0.0, 0.0, 1.0 / 1.5);
    const auto worldRay = [&](double T) {
        const DMat4 M = localSpaceToBottomLevelAS(2, T);
        return RayDesc{vec3(transform(M, o, 1.0) + dvec3(0, 1, 0)), 0.0f, vec3(transform(M, d, 0.0)), 10000.0f};
    };
    {
        D3D12Rig rig(false, {2}, 0.0f);
        rig.probeRay = worldRay(0.0);
        rig.dispatch("RG_Probe", true);
        EXPECT_EQ(rig.probe.closestHits, 0);
        EXPECT_EQ(rig.probe.misses, 1);
    }
    D3D12Rig rig(false, {2}, 6.0f);
    rig.probeRay = worldRay(6.0);
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);

    const Metaballs balls(1.0);
    // The bounding-sphere span and the step.
    double tmin = std::numeric_limits<double>::infinity(), tmax = -tmin;
    for (int j = 0; j < 3; ++j) {
        const dvec3 L = o - balls.centre[j];
        const double a = glm::dot(d, d), b = 2.0 * glm::dot(d, L), c = glm::dot(L, L) - balls.radius[j] * balls.radius[j];
        const double disc = b * b - 4.0 * a * c;
        if (disc < 0.0) continue;
        tmin = std::min(tmin, std::max((-b - std::sqrt(disc)) / (2.0 * a), 0.0));
        tmax = std::max(tmax, (-b + std::sqrt(disc)) / (2.0 * a));
    }
    const double step = (tmax - tmin) / 128.0;
    double lo = tmin, hi = tmax;  // the first crossing of 0.25 from the entry
    for (double t = tmin; t < tmax; t += step / 16)
        if (balls.field(o + t * d) >= 0.25) {
            hi = t;
            break;
        }
    lo = hi - step / 16;
    for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (balls.field(o + mid * d) >= 0.25 ? hi : lo) = mid;
    }
    EXPECT_GE(rig.probe.t, hi - 1e-4);
    EXPECT_LE(rig.probe.t, hi + step + 1e-4);

    // The normal: minus the field gradient at the reported point, through the forward matrix.
    const dvec3 p = o + double(rig.probe.t) * d;
    const double e = 1e-6;
    const dvec3 g(balls.field(p - dvec3(e, 0, 0)) - balls.field(p + dvec3(e, 0, 0)),
                  balls.field(p - dvec3(0, e, 0)) - balls.field(p + dvec3(0, e, 0)),
                  balls.field(p - dvec3(0, 0, e)) - balls.field(p + dvec3(0, 0, e)));
    expectNear(rig.probe.normal, vec3(glm::normalize(transform(localSpaceToBottomLevelAS(2, 6.0), g, 0.0))), 2e-2f,
               "normal");
}

// MiniSpheres (i = 3, unscaled, box centre (2, 1, -6)): the sphere at local (-0.75, 0.25, 0.25), radius 0.1625, is
// met at local x = -0.9125 by a ray along +x.
TEST(D3D12Shaders, SignedDistanceMiniSpheres) {
    D3D12Rig rig(false, {3});
    rig.probeRay = {vec3(-5.0f, 1.25f, -5.75f), 0.0f, vec3(1, 0, 0), 10000.0f};
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 7.0f - 0.9125f, 1e-3f);
    expectNear(rig.probe.normal, vec3(-1, 0, 0), 1e-3f, "normal");
}

// FractalPyramid (i = 9, scale 3, box centre (4, 3, 4) in the world): in the pyramid's frame q = local + (0, 1, 0)
// the point (0.975, 0.05, 0.9375) lies on the +x face 2x + y = 2 and inside the corner sub-pyramid of every
// iteration, so a ray along -x meets the outer face there (world (6.925, 0.15, 6.8125)), normal (2, 1, 0)/√5.
TEST(D3D12Shaders, SignedDistanceFractalPyramid) {
    D3D12Rig rig(false, {9});
    rig.probeRay = {vec3(10.0f, 0.15f, 6.8125f), 0.0f, vec3(-1, 0, 0), 10000.0f};
    rig.dispatch("RG_Probe", true);
    ASSERT_EQ(rig.probe.closestHits, 1);
    EXPECT_NEAR(rig.probe.t, 10.0f - 6.925f, 2e-3f);
    expectNear(rig.probe.normal, vec3(2.0f, 1.0f, 0.0f) / std::sqrt(5.0f), 1e-2f, "normal");
}

// §6: first hits of the whole scene at T = 0, 1280×720.
TEST(D3D12Shaders, WholeSceneFirstHitsMatchTheCheckValues) {
    const Camera camera = sampleCamera(1280, 720);
    struct Check {
        uvec2 pixel;
        uint32_t instance, geometry;
        float t, tolerance;
    };
    const Check checks[] = {
        {{640, 360}, 1, 2, 10.146f, 0.03f},  // metaballs (sampled: one step ≈ 0.02)
        {{1000, 300}, 1, 0, 18.787f, 2e-3f},  // the red box's -x face
        {{640, 100}, 1, 9, 21.98f, 0.01f},   // fractal pyramid
        {{200, 500}, 0, 0, 13.277f, 2e-3f},  // ground
        {{640, 700}, 0, 0, 8.475f, 2e-3f},   // ground
    };
    for (const Check& check : checks) {
        D3D12Rig rig(true, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
        vec3 origin, direction;
        GenerateCameraRay(check.pixel, uvec2(1280, 720), vec3(camera.position), camera.projectionToWorld, origin,
                          direction);
        rig.probeRay = {origin, 0.0f, direction, 10000.0f};
        rig.dispatch("RG_Probe", true);
        ASSERT_EQ(rig.probe.closestHits, 1) << check.pixel.x << "," << check.pixel.y;
        EXPECT_EQ(rig.probe.instanceIndex, check.instance) << check.pixel.x << "," << check.pixel.y;
        EXPECT_EQ(rig.probe.geometryIndex, check.geometry) << check.pixel.x << "," << check.pixel.y;
        EXPECT_NEAR(rig.probe.t, check.t, check.tolerance) << check.pixel.x << "," << check.pixel.y;
        if (check.pixel == uvec2(1000, 300)) {
            expectNear(rig.probe.position, vec3(5.000f, 1.277f, -5.160f), 2e-3f, "position");
            expectNear(rig.probe.normal, vec3(-1, 0, 0), 1e-6f, "normal");
        }
    }
}

// ---- The closest hits and miss shaders through MyRaygenShader -------------------------------------------

// The ground colour of §2.9/§2.11 in double for a ray straight down (D = -y) that hits P at distance t, with the
// background as the reflection (nothing above P) and N the normal the shader read from g_vertices.
dvec4 expectedGroundColor(dvec3 P, double t, bool inShadow, double checkers, dvec3 N = dvec3(0, 1, 0)) {
    const dvec3 D(0, -1, 0), light(0, 18, -20);
    const dvec4 albedo(0.9, 0.9, 0.9, 1.0), background(0.8, 0.9, 1.0, 1.0);
    const dvec3 L = glm::normalize(P - light);
    const double Kd = std::clamp(glm::dot(-L, N), 0.0, 1.0);
    const dvec4 diffuse = (inShadow ? 0.35 : 1.0) * 1.0 * Kd * dvec4(0.6, 0.6, 0.6, 1.0) * albedo;
    const dvec3 R = glm::normalize(L - 2.0 * glm::dot(N, L) * N);
    const dvec4 specular(inShadow ? 0.0 : 0.4 * std::pow(std::clamp(glm::dot(R, -D), 0.0, 1.0), 50.0));
    const double a = 1.0 - std::clamp(-N.y, 0.0, 1.0);
    const dvec4 ambient = albedo * (dvec4(0.25, 0.25, 0.25, 1.0) - 0.1 + 0.1 * a);  // lerp(A - 0.1, A, a)
    const double cosi = std::clamp(glm::dot(-D, N), 0.0, 1.0);
    const dvec4 fresnel(dvec3(0.9) + 0.1 * std::pow(1.0 - cosi, 5.0), 1.0);
    const dvec4 reflected = 0.25 * fresnel * background;
    const dvec4 color = checkers * (ambient + diffuse + specular + reflected);
    const double f = 1.0 - std::exp(-0.000002 * t * t * t);
    return color + f * (background - color);
}

// A 1×1 camera 10 above (3.01, 0, 7.5) looking down; its neighbour rays land 0.04 away, so the box filter covers
// [2.99, 3.03] in u: the whole 0.02-wide line at u = 3 is half of it, i.e. a grid factor of 0.5. The shadow ray and
// the reflection ray both miss.
TEST(D3D12Shaders, GroundPlaneGridShadingAndFog) {
    D3D12Rig rig(true, {});
    rig.setPointCamera(vec3(3.01f, 10.0f, 7.5f), vec3(0, -1, 0), vec3(0.002f, 0, 0), vec3(0, 0, 0.002f));
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 3u);  // primary, shadow, reflection
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 2u);
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::ClosestHit), 1u);

    EXPECT_NEAR(AnalyticalCheckersTexture(vec3(3.01f, 0.0f, 7.5f), vec3(0, 1, 0), vec3(rig.scene.cameraPosition),
                                          rig.scene.projectionToWorld, uvec2(0), uvec2(1)),
                0.5f, 1e-4f);
    const dvec4 expected = expectedGroundColor(dvec3(3.01, 0, 7.5), 10.0, false, 0.5);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
}

// MyClosestHitShader_Triangle takes its normal from the bound g_vertices[g_indices[3·PrimitiveIndex()]]: with
// downward normals there the same hit shades with the 0.15 ambient, no diffuse and a Fresnel factor of 1.
TEST(D3D12Shaders, GroundPlaneNormalComesFromTheBoundVertexBuffer) {
    D3D12Rig rig(true, {});
    for (Vertex& v : rig.boundVertices) v.normal = vec3(0, -1, 0);
    rig.setPointCamera(vec3(7.2f, 10.0f, -3.2f), vec3(0, -1, 0), vec3(1e-4f, 0, 0), vec3(0, 0, 1e-4f));
    rig.dispatch("MyRaygenShader", false);
    const dvec4 expected = expectedGroundColor(dvec3(7.2, 0, -3.2), 10.0, false, 1.0, dvec3(0, -1, 0));
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
}

// The red box shadows the ground at (7.2, 0, -3.2): the shadow ray towards the light enters the box's +z face.
// The grid factor is 1 there (frac 0.2 and 0.8, tiny footprint).
TEST(D3D12Shaders, GroundPlaneInTheRedBoxShadow) {
    D3D12Rig rig(true, {0});
    rig.setPointCamera(vec3(7.2f, 10.0f, -3.2f), vec3(0, -1, 0), vec3(1e-4f, 0, 0), vec3(0, 0, 1e-4f));
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 3u);
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 1u);  // only the reflection misses

    const dvec4 expected = expectedGroundColor(dvec3(7.2, 0, -3.2), 10.0, true, 1.0);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
    // Lit, the same point would be brighter by 0.65 of the diffuse term.
    EXPECT_LT(got.x, float(expectedGroundColor(dvec3(7.2, 0, -3.2), 10.0, false, 1.0).x) - 0.05f);
}

// MyClosestHitShader_AABB on the red box's -x face, lit (the shadow ray starts on the face and leaves it), no
// reflection (reflectanceCoef 0): Phong plus fog at t = 5.
TEST(D3D12Shaders, RedBoxShadedWithPhongAndFog) {
    D3D12Rig rig(false, {0});
    rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 2u);  // primary and shadow
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 1u);

    const dvec3 P(5, 1.5, -6), N(-1, 0, 0), D(1, 0, 0);
    const dvec3 L = glm::normalize(P - dvec3(0, 18, -20));
    const double Kd = std::clamp(glm::dot(-L, N), 0.0, 1.0);
    const dvec3 R = glm::normalize(L - 2.0 * glm::dot(N, L) * N);
    const double Ks = std::pow(std::clamp(glm::dot(R, -D), 0.0, 1.0), 50.0);
    const dvec4 albedo(1.0, 0.5, 0.5, 1.0), background(0.8, 0.9, 1.0, 1.0);
    const dvec4 color = albedo * dvec4(0.25, 0.25, 0.25, 1.0) + 0.9 * Kd * dvec4(0.6, 0.6, 0.6, 1.0) * albedo + dvec4(0.7 * Ks);
    const double f = 1.0 - std::exp(-0.000002 * 125.0);
    const dvec4 expected = color + f * (background - color);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5) << "component " << c;
}

// MyMissShader writes BackgroundColor; a small render of the whole scene stays finite, with sky in the top corner.
TEST(D3D12Shaders, WholeSceneRenderMissColourAndFiniteness) {
    D3D12Rig rig(true, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
    const Camera camera = sampleCamera(32, 18);
    rig.scene.projectionToWorld = camera.projectionToWorld;
    rig.scene.cameraPosition = camera.position;
    rig.dispatch("MyRaygenShader", false, 32, 18);
    EXPECT_EQ(rig.output.at(0, 0), BackgroundColor);
    int ground = 0;
    for (uint32_t y = 0; y < 18; ++y)
        for (uint32_t x = 0; x < 32; ++x) {
            const vec4 c = rig.output.at(x, y);
            for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(c[k])) << x << "," << y;
            if (c != BackgroundColor) ++ground;
        }
    EXPECT_GT(ground, 32 * 18 / 2);  // the horizon is near the top (rows 88-89 of 720)
}

// ---- PORT tests ----------------------------------------------------------------------------------------

// PORT (makeD3D12ShaderLibrary's traceRay): the shaders pass the library's TraceRay arguments, not the HLSL's
// constants. The red box is geometry 1 of the AABB instance (C = 2), seen as in RedBoxShadedWithPhongAndFog: the
// HLSL's radiance ray reads record R + M·G + C = 0 + 2·1 + 2 = 4. With R = 2, M = 0 it reads 2 + 0·1 + 2 = 4 too and
// the shadow ray with R = 3, M = 0 reads record 5 like the HLSL's, so the pixel is unchanged while the trace shows
// the arguments as passed, the mask's and miss index's unused high bits included (INST-4, IDX-7). A multiplier of 1
// with two ray types sends the radiance ray to record 0 + 1·1 + 2 = 3: geometry 0's shadow hit group.
TEST(D3D12Shaders, PORT_TraceRayArgumentsComeFromTheLibrary) {
    D3D12Rig reference(false, {4, 0});
    reference.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    TraceRayRecorder defaults;
    reference.observer = &defaults;
    reference.dispatch("MyRaygenShader", false);
    ASSERT_FALSE(defaults.lookups.empty());
    EXPECT_EQ(defaults.lookups[0].terms.index, 4u);
    EXPECT_EQ(defaults.lookups[0].terms.multiplier, 2u);

    D3D12Rig rig(false, {4, 0});
    rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    rig.traceRay[RayType::Radiance] = {2, 0, 0x10000, 0xFFFFFF03};
    rig.traceRay[RayType::Shadow] = {3, 0, 0x10001, 0x105};
    TraceRayRecorder recorder;
    rig.observer = &recorder;
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 2u);  // primary and shadow (the red box does not reflect)
    ASSERT_EQ(recorder.calls.size(), 2u);
    EXPECT_EQ(recorder.calls[0].payloadSize, sizeof(RayPayload));
    EXPECT_EQ(recorder.calls[0].arguments, rig.traceRay[RayType::Radiance]);
    EXPECT_EQ(recorder.calls[1].payloadSize, sizeof(ShadowRayPayload));
    EXPECT_EQ(recorder.calls[1].arguments, rig.traceRay[RayType::Shadow]);
    ASSERT_FALSE(recorder.lookups.empty());
    const HitGroupIndexTerms& primary = recorder.lookups[0].terms;
    EXPECT_EQ(primary.rayContribution, 2u);
    EXPECT_EQ(primary.multiplier, 0u);
    EXPECT_EQ(primary.geometryIndex, 1u);
    EXPECT_EQ(primary.instanceContribution, 2u);
    EXPECT_EQ(primary.index, 4u);
    EXPECT_EQ(recorder.lookups[0].hitGroup, "MyHitGroup_AABB_AnalyticPrimitive");
    EXPECT_EQ(rig.output.at(0, 0), reference.output.at(0, 0));

    D3D12Rig lesson(false, {4, 0});
    lesson.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    lesson.traceRay[RayType::Radiance].multiplier = 1;
    TraceRayRecorder wrong;
    lesson.observer = &wrong;
    lesson.dispatch("MyRaygenShader", false);
    ASSERT_FALSE(wrong.lookups.empty());
    EXPECT_EQ(wrong.lookups[0].terms.index, 3u);
    EXPECT_EQ(wrong.lookups[0].hitGroup, "MyHitGroup_AABB_SignedDistancePrimitive_ShadowRay");
}

// PORT (MyRaygenShader): the render target keeps the float colour; the R8G8B8A8_UNORM conversion happens only when
// the image is written out (H20). The red box's shaded components are not multiples of 1/255.
TEST(D3D12Shaders, PORT_RaygenStoresUnquantisedFloats) {
    D3D12Rig rig(false, {0});
    rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    rig.dispatch("MyRaygenShader", false);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 3; ++c) {
        const float quantised = std::round(std::clamp(got[c], 0.0f, 1.0f) * 255.0f) / 255.0f;
        EXPECT_GT(std::fabs(got[c] - quantised), 1e-5f) << "component " << c;
    }
}

// PORT (ShadowRayPayload): the payload mirrors the HLSL's 32-bit bool, not the C++ header's 1-byte bool (I11):
// MyMissShader_ShadowRay clears the whole word, and a shadow hit (closest hit skipped) leaves it untouched.
TEST(D3D12Shaders, PORT_ShadowRayPayloadIsAWholeWord) {
    static_assert(sizeof(ShadowRayPayload) == 4);
    D3D12Rig rig(false, {0});
    rig.probeRay = {vec3(0.0f, 1.5f, -6.0f), 0.0f, vec3(0, 1, 0), 10000.0f};  // misses the red box
    rig.dispatch("RG_ShadowProbe", false);
    EXPECT_EQ(rig.shadowPayloadWord, 0u);
    rig.probeRay = {vec3(0.0f, 1.5f, -6.0f), 0.0f, vec3(1, 0, 0), 10000.0f};  // enters its -x face
    rig.dispatch("RG_ShadowProbe", false);
    EXPECT_EQ(rig.shadowPayloadWord, 0xffffffffu);
}

// PORT (the helpers' intrinsics are parameters): a 3×2 dispatch over the bare ground; every pixel's colour is what
// the exported helpers give when handed that pixel's DispatchRaysIndex(), DispatchRaysDimensions() and
// WorldRayDirection(): grid filter from the neighbours' primary rays (I7), Phong, Fresnel reflection of the
// background (the reflection and the shadow ray both miss), then the fog.
TEST(D3D12Shaders, PORT_HelpersWithIntrinsicsAsParametersReproduceTheShader) {
    D3D12Rig rig(true, {});
    rig.setPointCamera(vec3(3.01f, 10.0f, 7.5f), vec3(0, -1, 0), vec3(0.5f, 0, 0), vec3(0, 0, 0.5f));
    const uvec2 dims(3, 2);
    rig.dispatch("MyRaygenShader", false, dims.x, dims.y);
    const vec3 N(0, 1, 0);
    for (uint32_t y = 0; y < dims.y; ++y)
        for (uint32_t x = 0; x < dims.x; ++x) {
            vec3 origin, D;
            GenerateCameraRay(uvec2(x, y), dims, vec3(rig.scene.cameraPosition), rig.scene.projectionToWorld, origin, D);
            const float t = -origin.y / D.y;
            const vec3 P = origin + t * D;
            const float checkers = AnalyticalCheckersTexture(P, N, vec3(rig.scene.cameraPosition),
                                                             rig.scene.projectionToWorld, uvec2(x, y), dims);
            const vec4 phong = CalculatePhongLighting(rig.scene, kPlaneMaterial.albedo, N, false, kPlaneMaterial.diffuseCoef,
                                                      kPlaneMaterial.specularCoef, kPlaneMaterial.specularPower, P, D);
            const vec4 reflected = kPlaneMaterial.reflectanceCoef *
                                   vec4(FresnelReflectanceSchlick(D, N, vec3(kPlaneMaterial.albedo)), 1.0f) * BackgroundColor;
            const vec4 expected = ApplyVisibilityFalloff(checkers * (phong + reflected), t);
            const vec4 got = rig.output.at(x, y);
            for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5f) << x << "," << y << " component " << c;
        }
    // The pixels really differ in their grid footprint (the index and dimensions matter).
    EXPECT_NE(rig.output.at(0, 0), rig.output.at(2, 1));
}

// PORT (makeD3D12ShaderLibrary's precision): the double library has the same exports and interface types, and
// renders the same shading; d3d12_contract_test.cpp runs every intersection shader in both and bounds the
// differences. The double run is also free of the float run's rounding: the red box colour agrees to 1e-6 (float
// rounding of a colour ~0.5 through ~30 operations is ~1e-7 relative).
TEST(D3D12Shaders, PORT_DoublePrecisionLibraryHasTheSameInterfaceAndShading) {
    const auto f = makeD3D12ShaderLibrary(Precision::Float);
    const auto d = makeD3D12ShaderLibrary(Precision::Double);
    ASSERT_EQ(f->exports().size(), d->exports().size());
    for (const auto& [name, e] : f->exports()) {
        const ShaderExport* other = d->find(name);
        ASSERT_NE(other, nullptr) << name;
        EXPECT_EQ(other->stage, e.stage) << name;
        EXPECT_EQ(other->payload, e.payload) << name;
        EXPECT_EQ(other->attributes, e.attributes) << name;
    }
    vec4 colour[2];
    for (int k = 0; k < 2; ++k) {
        D3D12Rig rig(false, {0});
        rig.precision = k == 0 ? Precision::Float : Precision::Double;
        rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
        rig.dispatch("MyRaygenShader", false);
        colour[k] = rig.output.at(0, 0);
    }
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(colour[0][c], colour[1][c], 1e-6f) << "component " << c;
    // The ground's grid and fog in double, against the double-precision expectation of GroundPlaneGridShadingAndFog.
    D3D12Rig ground(true, {});
    ground.precision = Precision::Double;
    ground.setPointCamera(vec3(3.01f, 10.0f, 7.5f), vec3(0, -1, 0), vec3(0.002f, 0, 0), vec3(0, 0, 0.002f));
    ground.dispatch("MyRaygenShader", false);
    const dvec4 expected = expectedGroundColor(dvec3(3.01, 0, 7.5), 10.0, false, 0.5);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(ground.output.at(0, 0)[c], expected[c], 1e-4) << "component " << c;
}

// The double helpers instantiate and agree with the float ones on the fact-sheet values.
TEST(D3D12Shaders, HelpersInDoubleMatchTheFloatOnes) {
    EXPECT_NEAR(CheckersTextureBoxFilter(glm::dvec2(3.005, 7.5), glm::dvec2(0.02, 0.0), glm::dvec2(0.0, 0.02), 50), 0.25,
                1e-6);
    EXPECT_NEAR(ApplyVisibilityFalloff(dvec4(0.0), 70.24).z, 0.5, 1e-3);
    EXPECT_NEAR(FresnelReflectanceSchlick(dvec3(0, -1, 0), dvec3(0, 1, 0), dvec3(0.9)).x, 0.9, 1e-12);
}

}  // namespace
}  // namespace refray::procedural::d3d12
