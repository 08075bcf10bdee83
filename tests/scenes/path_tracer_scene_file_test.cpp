// Tests scenes/cornell-box.json and scenes/textured-room.json against their C++ twins (PathTracerScene,
// scenes/path_tracer_scene.h): the scene files describe the same DXR objects as the C++ host code, so the global
// buffers, the light list, the instances and the renders agree bit for bit at the same settings.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "core/image.h"
#include "scenes/effects.h"
#include "scenes/path_tracer_scene.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
namespace pt = refray::procedural::pathtracer;

const fs::path kScenes = fs::path(REFRAY_SOURCE_DIR) / "scenes";

template <class T>
bool sameBytes(const std::vector<T>& a, const std::vector<uint8_t>& bytes) {
    return a.size() * sizeof(T) == bytes.size() && (a.empty() || std::memcmp(a.data(), bytes.data(), bytes.size()) == 0);
}

bool sameImage(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(vec4)) == 0;
}

const BufferDesc& bufferOf(const SceneDesc& desc, BufferDesc::Kind kind) {
    for (const BufferDesc& b : desc.buffers)
        if (b.kind == kind) return b;
    throw Error("no buffer of that kind");
}

RenderSettings settings(uint32_t size, uint32_t spp, uint32_t seed) {
    RenderSettings s;
    s.width = s.height = size;
    s.spp = spp;
    s.seed = seed;
    s.threads = 2;
    return s;
}

// The file's buffers are the C++ scene's global buffers and light list, byte for byte, and its instances are the
// C++ scene's objects: InstanceID = object index, the object's model as the BLAS, its transform.
void expectSameObjects(const SceneDesc& file, PathTracerScene& cpp) {
    const GlobalModelBuffers& g = cpp.buffers();
    EXPECT_TRUE(sameBytes(g.vertices, bufferOf(file, BufferDesc::Kind::ModelVertices).bytes));
    EXPECT_TRUE(sameBytes(g.indices, bufferOf(file, BufferDesc::Kind::ModelIndices).bytes));
    EXPECT_TRUE(sameBytes(g.materials, bufferOf(file, BufferDesc::Kind::ModelMaterials).bytes));
    EXPECT_TRUE(sameBytes(g.triangleMaterials, bufferOf(file, BufferDesc::Kind::ModelTriangleMaterials).bytes));
    EXPECT_TRUE(sameBytes(g.objects, bufferOf(file, BufferDesc::Kind::ModelObjects).bytes));
    EXPECT_TRUE(sameBytes(cpp.lights(), bufferOf(file, BufferDesc::Kind::LightTriangles).bytes));
    EXPECT_EQ(file.lightTriangleCount(), cpp.lights().size());
    EXPECT_EQ(file.modelBuffers.diffuseTextures, g.diffuseTextures);
    EXPECT_EQ(file.modelBuffers.normalTextures, g.normalTextures);
    ASSERT_EQ(file.instances.size(), g.objectDescs.size());
    for (size_t i = 0; i < file.instances.size(); ++i) {
        const InstanceDescFile& inst = file.instances[i];
        EXPECT_EQ(inst.instanceID, i) << inst.name;
        EXPECT_EQ(inst.contribution, 0u) << inst.name;
        EXPECT_EQ(inst.mask, 0xFFu) << inst.name;
        EXPECT_EQ(file.blases[inst.blas].geometries.at(0).model, int32_t(g.objectDescs[i].model)) << inst.name;
        EXPECT_EQ(std::memcmp(&inst.transform, &g.objectDescs[i].transform, sizeof(Matrix3x4)), 0) << inst.name;
    }
}

TEST(PathTracerSceneFile, CornellBoxDescribesTheCppScene) {
    Scene file(loadSceneFile(kScenes / "cornell-box.json"));
    PathTracerScene cpp = PathTracerScene::cornellBox(kScenes);
    expectSameObjects(file.desc(), cpp);
    EXPECT_EQ(file.desc().defaultWidth, 512u);
    EXPECT_EQ(file.desc().defaultHeight, 512u);

    const RenderResult fromFile = file.render(settings(40, 3, 11));
    const RenderResult fromCpp = cpp.render(40, 40, 3, 11, 2);
    EXPECT_TRUE(sameImage(fromFile.image, fromCpp.image));
    EXPECT_EQ(fromFile.dispatch.stats.raysTraced, fromCpp.dispatch.stats.raysTraced);
}

TEST(PathTracerSceneFile, TexturedRoomDescribesTheCppScene) {
    Scene file(loadSceneFile(kScenes / "textured-room.json"));
    PathTracerScene cpp = PathTracerScene::texturedRoom(kScenes);
    expectSameObjects(file.desc(), cpp);
    EXPECT_FALSE(file.desc().modelBuffers.diffuseTextures.empty());
    EXPECT_FALSE(file.desc().modelBuffers.normalTextures.empty());

    EXPECT_TRUE(sameImage(file.render(settings(32, 2, 5)).image, cpp.render(32, 32, 2, 5, 2).image));
}

// The scene constants' debugMode reaches PT_RayGen as the C++ scene's PathTracerRenderOptions::debugMode does.
TEST(PathTracerSceneFile, DebugModeMatchesTheCppScene) {
    const std::string text = testing::edited(testing::readText((kScenes / "cornell-box.json").string()),
                                             "\"maxBounces\": 8}", "\"maxBounces\": 8, \"debugMode\": 5}");
    Scene file(parseScene(text, (kScenes / "cornell-box.json").string()));
    PathTracerScene cpp = PathTracerScene::cornellBox(kScenes);
    PathTracerRenderOptions options;
    options.debugMode = pt::kDebugInstanceID;
    EXPECT_TRUE(sameImage(file.render(settings(24, 1, 0)).image, cpp.render(24, 24, 1, 0, 2, options).image));
}

// What `refray render --stats` reports for the path tracer: rays traced by PT_RayGen at depth 1, bounded by
// maxBounces and the light triangles, the in-shader spp, and the textured room's textures.
TEST(PathTracerSceneFile, Effects) {
    RenderSettings settings;
    settings.spp = 7;
    const EffectSet cornell = computeEffects(loadSceneFile(kScenes / "cornell-box.json"), settings);
    EXPECT_TRUE(cornell.triangles.on);
    EXPECT_TRUE(cornell.shadowRays.on);
    EXPECT_EQ(cornell.shadowRays.reason, "PT_RayGen (next-event estimation) traces 'Shadow' rays from every path "
                                         "vertex to a point on one of 2 light triangles");
    EXPECT_TRUE(cornell.reflections.on);
    EXPECT_CONTAINS(cornell.reflections.reason, "up to maxBounces 8 per path (buffer 'constants')");
    EXPECT_TRUE(cornell.supersampling.on);
    EXPECT_CONTAINS(cornell.supersampling.reason, "spp 7: 7 random paths per pixel (samplesPerPixel)");
    EXPECT_FALSE(cornell.textures.on);
    EXPECT_FALSE(cornell.normalMaps.on);
    EXPECT_FALSE(cornell.debugColours.on);
    EXPECT_EQ(cornell.debugColours.reason, "debugMode is 0 in 'constants'");
    EXPECT_FALSE(cornell.animation.on);

    const EffectSet room = computeEffects(loadSceneFile(kScenes / "textured-room.json"), settings);
    EXPECT_TRUE(room.textures.on);
    EXPECT_EQ(room.textures.reason, "PT_ClosestHit samples 4 diffuse textures (map_Kd)");
    EXPECT_TRUE(room.normalMaps.on);
    EXPECT_EQ(room.normalMaps.reason, "PT_ClosestHit perturbs normals with 2 normal maps (norm, map_Bump)");

    // Paths of one segment: no light sampling, no bounces.
    const std::string text = testing::edited(testing::readText((kScenes / "cornell-box.json").string()),
                                             "\"maxBounces\": 8}", "\"maxBounces\": 0}");
    const EffectSet direct = computeEffects(parseScene(text, (kScenes / "cornell-box.json").string()), settings);
    EXPECT_FALSE(direct.shadowRays.on);
    EXPECT_FALSE(direct.reflections.on);
    EXPECT_CONTAINS(direct.reflections.reason, "maxBounces is 0 in buffer 'constants'");
}

}  // namespace
}  // namespace refray::scenes
