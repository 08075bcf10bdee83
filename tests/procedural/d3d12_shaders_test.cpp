// Tests procedural/d3d12/d3d12_shaders.cpp: the export table, the HLSL struct layouts, the root signatures and hit
// groups, the pure shading helpers and the sample's camera. End-to-end dispatches through tiny Device scenes built
// from the fact sheet (§1.2-1.4) are in d3d12_shaders_intersection_test.cpp and d3d12_shaders_shading_test.cpp; the
// rig they share is d3d12_shaders_rig.h.
#include "procedural/d3d12/d3d12_shaders.h"

#include <cmath>
#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "tests/procedural/d3d12_shaders_rig.h"

namespace refray::procedural::d3d12 {
namespace {

using namespace shaders_rig;

// ---- Exports, hit groups, layouts ------------------------------------------------------------------

TEST(D3D12Shaders, EveryHlslExportExistsWithItsStage) {
    const auto lib = makeD3D12ShaderLibrary();
    std::map<std::string, ShaderStage> expected = {
        {"MyRaygenShader", ShaderStage::RayGeneration},
        {"MyClosestHitShader_Triangle", ShaderStage::ClosestHit},
        {"MyClosestHitShader_AABB", ShaderStage::ClosestHit},
        {"MyMissShader", ShaderStage::Miss},
        {"MyMissShader_ShadowRay", ShaderStage::Miss},
        {"MyIntersectionShader_AnalyticPrimitive", ShaderStage::Intersection},
        {"MyIntersectionShader_VolumetricPrimitive", ShaderStage::Intersection},
        {"MyIntersectionShader_SignedDistancePrimitive", ShaderStage::Intersection},
        // scenes/inline/InlineShadows.hlsl and InlineAmbientOcclusion.hlsl (RQ-1, RQ-2).
        {"MyClosestHitShader_Triangle_InlineShadow", ShaderStage::ClosestHit},
        {"MyClosestHitShader_AABB_InlineShadow", ShaderStage::ClosestHit},
        {"InlineAmbientOcclusionCS", ShaderStage::Compute},
    };
    // The variants of the inline-tracing exports for the RayQuery lessons and mutants (InlineVariant): each of the
    // three with a suffix. SearchAllHits's shadow query lacks ACCEPT_FIRST_HIT_AND_END_SEARCH.
    for (const char* variant :
         {"_IgnoreProcedural", "_SearchAllHits", "_ReadCommittedAfterMiss", "_NoRangeCheck", "_CommittedTIsTMax"}) {
        expected[std::string("MyClosestHitShader_Triangle_InlineShadow") + variant] = ShaderStage::ClosestHit;
        expected[std::string("MyClosestHitShader_AABB_InlineShadow") + variant] = ShaderStage::ClosestHit;
        expected[std::string("InlineAmbientOcclusionCS") + variant] = ShaderStage::Compute;
    }
    EXPECT_EQ(lib->exports().size(), expected.size());
    for (const auto& [name, stage] : expected) {
        const ShaderExport* e = lib->find(name);
        ASSERT_NE(e, nullptr) << name;
        EXPECT_EQ(e->stage, stage) << name;
        // The RayQuery objects each export declares (the HLSL's template flags), and only those.
        const bool traceShadowsInline = name.find("_InlineShadow") != std::string::npos;
        const uint32_t acceptFirst =
            name.find("_SearchAllHits") != std::string::npos ? 0u : uint32_t(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH);
        if (traceShadowsInline) {
            EXPECT_EQ(e->rayQueryFlags,
                      std::vector<uint32_t>{RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE | acceptFirst})
                << name;
        } else if (stage == ShaderStage::Compute) {
            EXPECT_EQ(e->numThreads, uvec3(8, 8, 1)) << name;
            EXPECT_EQ(e->rayQueryFlags,
                      (std::vector<uint32_t>{RAY_FLAG_CULL_BACK_FACING_TRIANGLES, RAY_FLAG_CULL_BACK_FACING_TRIANGLES |
                                                                                     RAY_FLAG_FORCE_OPAQUE | acceptFirst}))
                << name;
        } else if (stage != ShaderStage::Compute) {
            EXPECT_TRUE(e->rayQueryFlags.empty()) << name;
        }
    }
    const ShaderExport* cs = lib->find("InlineAmbientOcclusionCS");
    ASSERT_NE(cs, nullptr);
    EXPECT_EQ(cs->numThreads, uvec3(8, 8, 1));  // [numthreads(8, 8, 1)]
    EXPECT_EQ(cs->rayQueryFlags.size(), 2u);
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

// ---- The sample's camera (§1.6), built in d3d12_shaders_rig.h -------------------------------------------

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

}  // namespace
}  // namespace refray::procedural::d3d12
