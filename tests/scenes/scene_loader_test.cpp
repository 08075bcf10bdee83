// Tests scenes/scene_loader.cpp (and scenes/loader/): the two reference scene files as the fact sheets describe them, and the
// errors a broken file gets (file:line:column, what was expected, "did you mean").
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <utility>

#include "core/error.h"
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/proceduray/proceduray_shaders.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";
const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

using testing::loadError;
using testing::readText;

// The Proceduray file with `from` replaced by `to` (which must occur exactly once).
std::string edited(const std::string& from, const std::string& to, const std::string& path = kProceduray) {
    return testing::edited(readText(path), from, to);
}

TEST(SceneLoader, ProceduraySceneFollowsTheFactSheet) {
    const SceneDesc s = loadSceneFile(kProceduray);
    EXPECT_EQ(s.name, "proceduray-mandel-julia-pac");
    EXPECT_EQ(s.fileHash.size(), 64u);
    ASSERT_EQ(s.instances.size(), 5u);
    // §1.2: contributions 0, 2, 4, 6, 8 (auto layout: two ray types per geometry, instances in order).
    for (size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(s.instances[i].contribution, 2 * i) << s.instances[i].name;
        EXPECT_EQ(s.instances[i].mask, 1u);
    }
    // The Julia transform is the fact sheet's float32 matrix, transposed into the DXR 3x4.
    const Matrix3x4& julia = s.instances[1].transform;
    EXPECT_EQ(julia.m[1][1], -29.9999962f);
    EXPECT_EQ(julia.m[2][1], -0.0152206402f);
    EXPECT_EQ(julia.m[1][2], 0.0507354662f);
    EXPECT_EQ(julia.m[2][2], -99.9999847f);
    EXPECT_EQ(julia.m[1][3], 130.0f);
    EXPECT_EQ(julia.m[2][3], 75.0f);
    EXPECT_EQ(s.instances[2].transform.m[0][3], 35.0f);
    EXPECT_EQ(s.instances[2].transform.m[0][0], 50.0f);
    // §1.5: ten records.
    ASSERT_EQ(s.hitGroupRecords.size(), 10u);
    const char* groups[10] = {"HitGroup_Triangle",   "HitGroup_Triangle_Shadow", "HitGroup_Julia",  "HitGroup_Julia_Shadow",
                              "HitGroup_Pacman",     "HitGroup_Pacman_Shadow",   "HitGroup_Pacman", "HitGroup_Pacman_Shadow",
                              "HitGroup_Mandelbulb", "HitGroup_Mandelbulb_Shadow"};
    for (size_t i = 0; i < 10; ++i) EXPECT_EQ(s.hitGroupRecords[i].hitGroup, groups[i]) << i;
    const RecordDesc& pacmanB = s.hitGroupRecords[7];
    ASSERT_EQ(pacmanB.arguments.size(), 2u);
    EXPECT_EQ(pacmanB.arguments[1].dwords, (std::vector<uint32_t>{2, 1}));  // aabbCB {instanceIndex 2, type 1}
    float albedo[4];
    std::memcpy(albedo, s.hitGroupRecords[0].arguments[0].dwords.data(), 16);
    EXPECT_EQ(albedo[1], 0.9f);
    // Associations derived from the records: Triangle with 2 hit groups, Procedural with 6.
    ASSERT_EQ(s.localAssociations.size(), 2u);
    EXPECT_EQ(s.localAssociations[0].size(), 2u);
    EXPECT_EQ(s.localAssociations[1].size(), 6u);
    EXPECT_EQ(s.missRecords, (std::vector<std::string>{"Miss", "Miss_Shadow"}));
    // The slab's buffers are the ones the port's tests use.
    const BufferDesc& indices = s.buffers[size_t(s.findBuffer("slabIndices"))];
    const BufferDesc& vertices = s.buffers[size_t(s.findBuffer("slabVertices"))];
    ASSERT_EQ(indices.bytes.size(), sizeof(procedural::proceduray::kSlabIndices));
    EXPECT_EQ(std::memcmp(indices.bytes.data(), procedural::proceduray::kSlabIndices.data(), indices.bytes.size()), 0);
    ASSERT_EQ(vertices.bytes.size(), sizeof(procedural::proceduray::kSlabVertices));
    EXPECT_EQ(std::memcmp(vertices.bytes.data(), procedural::proceduray::kSlabVertices.data(), vertices.bytes.size()), 0);
    // Cameras and times of the fact sheet.
    EXPECT_EQ(s.camera("").name, "overview");
    EXPECT_EQ(s.camera("julia").eye, glm::dvec3(0, 15, 300));
    EXPECT_EQ(s.camera("mandelbulb").target, glm::dvec3(0, -50, 115));
    EXPECT_EQ(s.defaultTime, 15.8429795f);
    EXPECT_EQ(s.canonicalTimes, (std::vector<float>{0.0f, 15.8429795f}));
}

TEST(SceneLoader, D3D12SceneFollowsTheFactSheet) {
    const SceneDesc s = loadSceneFile(kD3D12);
    ASSERT_EQ(s.instances.size(), 2u);
    EXPECT_EQ(s.instances[0].contribution, 0u);
    EXPECT_EQ(s.instances[1].contribution, 2u);  // §1.2: BLAS type 1 x 2 ray types
    ASSERT_EQ(s.blases[1].geometries.size(), 10u);
    // §1.8: 22 records; record 2 + 2i + r belongs to primitive i and ray type r.
    ASSERT_EQ(s.hitGroupRecords.size(), 22u);
    EXPECT_EQ(s.hitGroupRecords[5].hitGroup, "MyHitGroup_AABB_AnalyticPrimitive_ShadowRay");
    EXPECT_EQ(s.hitGroupRecords[6].hitGroup, "MyHitGroup_AABB_VolumetricPrimitive");
    EXPECT_EQ(s.hitGroupRecords[21].hitGroup, "MyHitGroup_AABB_SignedDistancePrimitive_ShadowRay");
    EXPECT_EQ(s.hitGroupRecords[21].arguments[1].dwords, (std::vector<uint32_t>{9, 6}));
    const BufferDesc& transforms = s.buffers[size_t(s.findBuffer("aabbPrimitiveAttributes"))];
    ASSERT_EQ(transforms.primitives.size(), 10u);
    EXPECT_EQ(transforms.primitives[1].spinYPerSecond, -2.0);  // the spheres rotate
    EXPECT_EQ(transforms.primitives[0].spinYPerSecond, 0.0);
    EXPECT_EQ(transforms.primitives[9].centre, vec3(4, 2, 4));  // the pyramid's BLAS box centre
    EXPECT_EQ(s.camera("").name, "default");
    EXPECT_NEAR(s.camera("").eye.x, -12.020815, 1e-6);
    EXPECT_NEAR(s.camera("").up.y, 0.954680, 1e-6);
    EXPECT_EQ(s.defaultTime, 0.0f);
}

// Without "traceRay" a ray type gets what the library's HLSL passes to TraceRay: R = r, M = 2, miss index r and
// the full 32-bit mask ~0.
TEST(SceneLoader, TraceRayArgumentsDefaultToTheLibrarysValues) {
    const std::pair<std::string, procedural::TraceRayArgumentSet> libraries[] = {
        {kProceduray, procedural::proceduray::defaultTraceRayArguments()},
        {kD3D12, procedural::d3d12::defaultTraceRayArguments()}};
    for (const auto& [path, expected] : libraries) {
        const SceneDesc s = loadSceneFile(path);
        const ShaderLibraryBinding& binding = findShaderLibrary(s.shaderLibrary);
        ASSERT_EQ(s.rayTypes.size(), 2u) << path;
        ASSERT_EQ(binding.traceRayDefaults.size(), 2u) << path;
        for (uint32_t r = 0; r < 2; ++r) {
            const RayTypeDesc& t = s.rayTypes[r];
            const procedural::TraceRayArguments read{t.rayContribution, t.multiplier, t.missShaderIndex,
                                                     t.instanceInclusionMask};
            EXPECT_EQ(read, expected[r]) << path << " ray type " << r;
            EXPECT_EQ(read, binding.traceRayDefaults[r]) << path << " ray type " << r;
            EXPECT_EQ(read, (procedural::TraceRayArguments{r, 2, r, 0xFFFFFFFFu})) << path << " ray type " << r;
        }
    }
}

// "traceRay" replaces the keys it gives and keeps the others; values past DXR's bit widths are kept as the shader
// would pass them (the emulator masks R and M and warns, IDX-2).
TEST(SceneLoader, TraceRayArgumentsAreReadPerRayType) {
    const SceneDesc s = parseScene(
        edited("{\"name\": \"Shadow\", \"miss\": \"Miss_Shadow\", \"payload\": \"ShadowRayPayload\"}",
               "{\"name\": \"Shadow\", \"miss\": \"Miss_Shadow\", \"payload\": \"ShadowRayPayload\",\n"
               "     \"traceRay\": {\"multiplier\": 1, \"rayContribution\": 17, \"instanceInclusionMask\": 4278190081}}"),
        "lesson.json");
    const RayTypeDesc& radiance = s.rayTypes[0];
    EXPECT_EQ(radiance.multiplier, 2u);
    EXPECT_EQ(radiance.instanceInclusionMask, 0xFFFFFFFFu);
    const RayTypeDesc& shadow = s.rayTypes[1];
    EXPECT_EQ(shadow.rayContribution, 17u);
    EXPECT_EQ(shadow.multiplier, 1u);
    EXPECT_EQ(shadow.missShaderIndex, 1u);
    EXPECT_EQ(shadow.instanceInclusionMask, 0xFF000001u);
}

TEST(SceneLoader, MisspeltTraceRayKeyGetsDidYouMean) {
    const std::string text =
        edited("{\"name\": \"Radiance\", \"miss\": \"Miss\", \"payload\": \"RayPayload\"}",
               "{\"name\": \"Radiance\", \"miss\": \"Miss\", \"payload\": \"RayPayload\", \"traceRay\": {\"multiplyer\": 1}}");
    const size_t at = text.find("\"multiplyer\"");
    const size_t lineStart = text.rfind('\n', at) + 1;
    std::string where = "broken.json:";
    where += std::to_string(std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n') + 1);
    where += ":";
    where += std::to_string(at - lineStart + 1);
    where += ": ";
    const std::string message = loadError(text);
    EXPECT_CONTAINS(message, where);
    EXPECT_CONTAINS(message, "unknown key 'multiplyer' in traceRay of ray type 'Radiance' (did you mean 'multiplier'?); "
                             "expected one of: rayContribution, multiplier, missShaderIndex, instanceInclusionMask");
    EXPECT_CONTAINS(loadError(edited("\"payload\": \"RayPayload\"}",
                                     "\"payload\": \"RayPayload\", \"traceRay\": {\"missShaderIndex\": 4294967296}}")),
                    "4294967296 does not fit in a 32-bit unsigned integer");
}

TEST(SceneLoader, SyntaxErrorsNameFileLineAndColumn) {
    const std::string message = loadError(edited("\"layout\": \"auto\",", "\"layout\": \"auto\",,"));
    EXPECT_CONTAINS(message, "broken.json:7:");
}

TEST(SceneLoader, UnknownKeyGetsDidYouMean) {
    const std::string message = loadError(edited("\"defaultCamera\": \"overview\"", "\"defaultCamra\": \"overview\""));
    EXPECT_CONTAINS(message, "unknown key 'defaultCamra' in the scene (did you mean 'defaultCamera'?)");
    EXPECT_CONTAINS(message, "broken.json:");
}

TEST(SceneLoader, UnknownExportGetsDidYouMean) {
    const std::string message = loadError(edited("\"closestHit\": \"ClosestHit_Julia\"", "\"closestHit\": \"ClosestHit_Julai\""));
    EXPECT_CONTAINS(message, "shader library 'proceduray' has no export 'ClosestHit_Julai' (did you mean 'ClosestHit_Julia'?)");
}

TEST(SceneLoader, ExportOfTheWrongStageIsNamed) {
    const std::string message = loadError(edited("\"miss\": \"Miss_Shadow\"", "\"miss\": \"ClosestHit_Julia\""));
    EXPECT_CONTAINS(message, "export 'ClosestHit_Julia' is a closesthit shader, not a miss shader");
}

TEST(SceneLoader, PayloadMustMatchTheMissShader) {
    const std::string message = loadError(edited("\"payload\": \"ShadowRayPayload\"", "\"payload\": \"RayPayload\""));
    EXPECT_CONTAINS(message, "ray type 'Shadow' says its payload is 'RayPayload', but its miss shader 'Miss_Shadow' takes "
                             "'ShadowRayPayload'");
}

TEST(SceneLoader, UnknownShaderLibraryIsNamed) {
    const std::string message = loadError(edited("\"shaderLibrary\": \"proceduray\"", "\"shaderLibrary\": \"procedural\""));
    EXPECT_CONTAINS(message, "unknown shader library 'procedural' (did you mean 'proceduray'?)");
}

TEST(SceneLoader, TrianglesHitGroupOnAnAABBIsRefused) {
    const std::string message = loadError(edited("{\"Radiance\": \"HitGroup_Julia\", \"Shadow\": \"HitGroup_Julia_Shadow\"}",
                                                 "{\"Radiance\": \"HitGroup_Triangle\", \"Shadow\": \"HitGroup_Julia_Shadow\"}"));
    EXPECT_CONTAINS(message, "hit group 'HitGroup_Triangle' is a triangles hit group, but geometry 0 of BLAS 'Julia' holds AABBs");
}

TEST(SceneLoader, RecordCountMustMatchTheGeometries) {
    const std::string message =
        loadError(edited("\"localRootSignature\": \"Triangle\", \"arguments\": {\"l_materialCB\": \"plane\"}}",
                         "\"localRootSignature\": \"Triangle\", \"arguments\": {\"l_materialCB\": \"plane\"}}, {}"));
    EXPECT_CONTAINS(message, "instance 'slab' gives 2 records but BLAS 'GlobalGeometry' has 1 geometries");
}

TEST(SceneLoader, UnknownFieldOfAValueIsNamed) {
    const std::string message = loadError(edited("\"reflectanceCoef\": 0.25,", "\"reflectanceCoeff\": 0.25,"));
    EXPECT_CONTAINS(message, "unknown key 'reflectanceCoeff' in value 'plane' (a PrimitiveConstantBuffer) (did you mean "
                             "'reflectanceCoef'?)");
}

TEST(SceneLoader, MissingArgumentIsNamed) {
    const std::string message = loadError(edited("\"arguments\": {\"l_materialCB\": \"julia\", \"l_aabbCB\": {\"instanceIndex\": 0, \"primitiveType\": 0}}",
                                                 "\"arguments\": {\"l_materialCB\": \"julia\"}"));
    EXPECT_CONTAINS(message, "has no 'l_aabbCB'");
}

TEST(SceneLoader, OneLocalRootSignaturePerHitGroup) {
    // Pac-man B's records name "Triangle" while Pac-man A's name "Procedural" for the same hit groups.
    std::string text = edited("\"arguments\": {\"l_materialCB\": \"pacman\", \"l_aabbCB\": {\"instanceIndex\": 2, \"primitiveType\": 1}}",
                              "\"arguments\": {\"l_materialCB\": \"pacman\"}");
    const size_t at = text.find("\"localRootSignature\": \"Procedural\",\n        \"arguments\": {\"l_materialCB\": \"pacman\"}}");
    ASSERT_NE(at, std::string::npos);
    text.replace(text.find("Procedural", at), 10, "Triangle");
    const std::string message = loadError(text);
    EXPECT_CONTAINS(message, "hit group 'HitGroup_Pacman' is used with local root signature 'Triangle' here but with "
                             "'Procedural' at broken.json:");
    EXPECT_CONTAINS(message, "(ASSOC-3)");
}

TEST(SceneLoader, BadRegisterAndCameraAreNamed) {
    EXPECT_CONTAINS(loadError(edited("\"register\": \"t3\"", "\"register\": \"b3\"")),
                    "parameter 'g_instanceBuffer' binds a 't' register, got 'b3'");
    EXPECT_CONTAINS(loadError(edited("\"eye\": [90, 5, 215], \"target\": [0, -50, 115]", "\"eye\": [0, -50, 115], \"target\": [0, -50, 115]")),
                    "broken.json:133:83: camera 'mandelbulb': eye and target are the same point (0, -50, 115), so the "
                    "camera has no view direction");
    EXPECT_CONTAINS(loadError(edited("\"defaultCamera\": \"overview\"", "\"defaultCamera\": \"overveiw\"")),
                    "unknown camera 'overveiw' (did you mean 'overview'?)");
}

TEST(SceneLoader, MisspeltRequiredKeyIsPointedAt) {
    const std::string message = loadError(edited("\"eye\": [90, 5, 215]", "\"eyes\": [90, 5, 215]"));
    EXPECT_CONTAINS(message, "camera 'mandelbulb' has no 'eye'; is 'eyes' a misspelling of it?");
}

TEST(SceneLoader, ExplicitLayoutTakesRecordsAndContributionsByHand) {
    // The D3D12 ground plane alone, with the table written out and a deliberately odd contribution.
    const std::string text = R"({
      "format": "refray-scene/1", "name": "explicit", "shaderLibrary": "d3d12-procedural-geometry", "layout": "explicit",
      "pipeline": {"rayGeneration": "MyRaygenShader", "maxRecursionDepth": 3, "maxPayloadBytes": 20, "maxAttributeBytes": 12},
      "rayTypes": [{"name": "Radiance", "miss": "MyMissShader", "payload": "RayPayload"},
                   {"name": "Shadow", "miss": "MyMissShader_ShadowRay", "payload": "ShadowRayPayload"}],
      "hitGroups": [{"name": "HG", "type": "triangles", "closestHit": "MyClosestHitShader_Triangle"}],
      "structs": {"Material": [["float4", "albedo"], ["float", "reflectanceCoef"], ["float", "diffuseCoef"],
                               ["float", "specularCoef"], ["float", "specularPower"], ["float", "stepScale"], ["float3", "padding"]]},
      "rootSignatures": {"global": {"name": "G", "parameters": []},
                         "local": [{"name": "L", "parameters": [{"name": "m", "kind": "constants", "register": "b1", "struct": "Material"}]}]},
      "buffers": {},
      "bottomLevel": [{"name": "plane", "geometries": [{"type": "triangles", "vertices": [[0,0,0],[1,0,0],[1,0,1]]}]}],
      "instances": [{"name": "p", "blas": "plane", "contribution": 1}],
      "shaderTable": {"miss": ["MyMissShader", null],
                      "hitGroups": [{"hitGroup": null}, {"hitGroup": "HG", "localRootSignature": "L", "arguments": {"m": {"albedo": [1, 1, 1, 1]}}}],
                      "hitGroupStride": 96},
      "globalArguments": {},
      "cameras": [{"name": "c", "model": "directxmath-lh", "eye": [0, 5, -5], "target": [0, 0, 0], "up": [0, 1, 0], "fovYDegrees": 45, "near": 0.01, "far": 125}],
      "light": {"position": [0, 18, -20, 0], "ambientColor": [0.25, 0.25, 0.25, 1], "diffuseColor": [0.6, 0.6, 0.6, 1]}
    })";
    const SceneDesc s = parseScene(text, "explicit.json");
    EXPECT_EQ(s.instances[0].contribution, 1u);
    ASSERT_EQ(s.hitGroupRecords.size(), 2u);
    EXPECT_TRUE(s.hitGroupRecords[0].hitGroup.empty());
    EXPECT_EQ(s.hitGroupStride, 96u);
    EXPECT_EQ(s.missRecords[1], "");
    EXPECT_EQ(s.blases[0].geometries[0].vertexCount, 3u);
}

}  // namespace
}  // namespace refray::scenes
