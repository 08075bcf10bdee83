// Tests scenes/path_tracer_scene.cpp end to end with procedural/pathtracer: the InstanceID -> object -> material
// indirection, a furnace with a known radiance, determinism across thread counts and seeds, and texture and
// normal-map sampling. Small images, fixed seeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

#include "core/image.h"
#include "scenes/path_tracer_scene.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
namespace pt = refray::procedural::pathtracer;

const fs::path kScenes = fs::path(REFRAY_SOURCE_DIR) / "scenes";

// Objects of the Cornell box, in file order (InstanceID = object index).
enum CornellObject : uint32_t { kWalls = 0, kShortBlock = 1, kTallBlock = 2, kLight = 3 };

Image renderDebug(PathTracerScene& scene, uint32_t size, pt::DebugMode mode) {
    PathTracerRenderOptions options;
    options.debugMode = mode;
    return scene.render(size, size, 1, 0, 2, options).image;
}

bool near(vec3 a, vec3 b, float tolerance = 1e-6f) {
    return glm::all(glm::lessThanEqual(glm::abs(a - b), vec3(tolerance)));
}

bool sameBytes(const Image& a, const Image& b) {
    return a.pixels().size() == b.pixels().size() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(vec4)) == 0;
}

// Mean of the red channel and its standard error, treating pixels as independent samples.
struct PixelStatistics {
    double mean = 0.0, standardError = 0.0;
};
PixelStatistics statistics(const std::vector<double>& values) {
    double sum = 0.0, squares = 0.0;
    for (double v : values) sum += v, squares += v * v;
    const double n = double(values.size()), mean = sum / n;
    return {mean, std::sqrt(std::max(0.0, squares / n - mean * mean) / (n - 1.0))};
}
std::vector<double> redChannel(const Image& image) {
    std::vector<double> values;
    for (const vec4& p : image.pixels()) values.push_back(p.r);
    return values;
}

// Checks the debug renders of `scene` against its buffers: every pixel that hits an object shows that object's
// material for the triangle hit (albedo and emission), found on the host through the same offsets. Returns the
// pixels per InstanceID.
std::map<uint32_t, int> expectMaterialsMatchInstances(PathTracerScene& scene, uint32_t size) {
    const Image ids = renderDebug(scene, size, pt::kDebugInstanceID);
    const Image albedo = renderDebug(scene, size, pt::kDebugAlbedo);
    const Image emission = renderDebug(scene, size, pt::kDebugEmission);
    const GlobalModelBuffers& buffers = scene.buffers();
    std::map<uint32_t, int> pixels;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            const vec4 id = ids.at(x, y);
            if (vec3(id) == scene.desc().backgroundColor) continue;  // a miss
            const uint32_t object = uint32_t(id.r), primitive = uint32_t(id.g), material = uint32_t(id.b);
            EXPECT_LT(object, buffers.objects.size());
            if (object >= buffers.objects.size()) continue;
            ++pixels[object];
            const uint32_t expected = buffers.triangleMaterials[buffers.objects[object].triangleOffset + primitive];
            EXPECT_EQ(material, expected) << "pixel " << x << ", " << y << ", object " << object;
            EXPECT_TRUE(near(vec3(albedo.at(x, y)), vec3(buffers.materials[expected].albedo)))
                << "pixel " << x << ", " << y << ", object " << object;
            EXPECT_TRUE(near(vec3(emission.at(x, y)), vec3(buffers.materials[expected].emission)))
                << "pixel " << x << ", " << y << ", object " << object;
        }
    return pixels;
}

// Known pixels of the Cornell box at 64 x 64 (classic camera): the left wall is red, the right wall green, the
// blocks white and the ceiling light emissive.
void expectCornellColours(PathTracerScene& scene) {
    const Image ids = renderDebug(scene, 64, pt::kDebugInstanceID);
    const Image albedo = renderDebug(scene, 64, pt::kDebugAlbedo);
    const Image emission = renderDebug(scene, 64, pt::kDebugEmission);
    const vec3 red(0.63f, 0.065f, 0.05f), green(0.14f, 0.45f, 0.091f), white(0.725f, 0.71f, 0.68f);
    const auto objectAt = [&](uint32_t x, uint32_t y) { return uint32_t(ids.at(x, y).r); };
    const auto objectName = [&](uint32_t x, uint32_t y) { return scene.desc().objects[objectAt(x, y)].name; };
    EXPECT_EQ(objectName(3, 32), "walls");
    EXPECT_TRUE(near(vec3(albedo.at(3, 32)), red)) << "left wall";
    EXPECT_EQ(objectName(60, 32), "walls");
    EXPECT_TRUE(near(vec3(albedo.at(60, 32)), green)) << "right wall";
    EXPECT_EQ(objectName(40, 50), "short-block");  // front right
    EXPECT_TRUE(near(vec3(albedo.at(40, 50)), white));
    EXPECT_EQ(objectName(24, 35), "tall-block");  // back left
    EXPECT_TRUE(near(vec3(albedo.at(24, 35)), white));
    EXPECT_EQ(objectName(32, 8), "light");
    EXPECT_TRUE(near(vec3(emission.at(32, 8)), vec3(17.0f, 12.0f, 4.0f)));
    EXPECT_TRUE(near(vec3(albedo.at(32, 8)), vec3(0.0f)));
}

TEST(PathTracerScene, InstanceIDSelectsEachObjectsMaterial) {
    PathTracerScene scene = PathTracerScene::cornellBox(kScenes);
    ASSERT_EQ(scene.desc().objects.size(), 4u);
    EXPECT_EQ(scene.lights().size(), 2u);  // the light quad
    const std::map<uint32_t, int> pixels = expectMaterialsMatchInstances(scene, 48);
    for (uint32_t object : {kWalls, kShortBlock, kTallBlock, kLight})
        EXPECT_GT(pixels.count(object) ? pixels.at(object) : 0, 0) << "object " << object << " is never seen";
    expectCornellColours(scene);
}

TEST(PathTracerScene, InstanceIDIsTheObjectIndexNotTheModelIndex) {
    // The Cornell models with the objects listed backwards, plus a second tall block, scaled down and moved to the
    // front left: every InstanceID differs from its model index, and one model serves two instances.
    PathTracerSceneDesc desc;
    desc.name = "cornell-box, objects reversed";
    desc.models = loadObjModels(kScenes / "cornell-box" / "cornell-box.obj");
    for (uint32_t m = 4; m-- > 0;) desc.objects.push_back({desc.models[m].name, m, Matrix3x4::identity()});
    desc.objects.push_back(
        {"tall-block-2", 2, Matrix3x4::translation(vec3(330.0f, 0.0f, -90.0f)) * Matrix3x4::scale(vec3(0.4f))});
    desc.camera = {vec3(278.0f, 273.0f, -800.0f), vec3(278.0f, 273.0f, 0.0f), vec3(0.0f, 1.0f, 0.0f), 39.3077f};
    PathTracerScene scene(std::move(desc));
    const std::map<uint32_t, int> pixels = expectMaterialsMatchInstances(scene, 48);
    EXPECT_EQ(pixels.size(), 5u) << "every instance is seen";
    // The walls are object 3 now; their colours come through its own ObjectGPU.
    const Image ids = renderDebug(scene, 64, pt::kDebugInstanceID);
    const Image albedo = renderDebug(scene, 64, pt::kDebugAlbedo);
    EXPECT_EQ(uint32_t(ids.at(3, 32).r), 3u);
    EXPECT_TRUE(near(vec3(albedo.at(3, 32)), vec3(0.63f, 0.065f, 0.05f)));
    EXPECT_TRUE(near(vec3(albedo.at(60, 32)), vec3(0.14f, 0.45f, 0.091f)));
}

// ---- Furnace -----------------------------------------------------------------------------------------------------

// A closed UV sphere seen from inside: triangles wind counter-clockwise seen from the centre (so they emit inwards),
// flat shaded (each corner carries its triangle's inward normal: with smooth normals the shading hemisphere
// differs from the geometric one and a furnace loses a little energy), one material of albedo `albedo` and
// emission `emission`. Corners at the same place have bit-identical positions, so the mesh is watertight.
Model insideOutSphere(float radius, uint32_t segments, uint32_t rings, float albedo, float emission) {
    std::vector<vec3> positions = {vec3(0.0f, radius, 0.0f)};
    for (uint32_t r = 1; r < rings; ++r) {
        const double theta = 3.14159265358979 * r / rings;
        for (uint32_t s = 0; s < segments; ++s) {
            const double phi = 2.0 * 3.14159265358979 * s / segments;
            const glm::dvec3 unit(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            positions.push_back(vec3(double(radius) * unit));
        }
    }
    positions.push_back(vec3(0.0f, -radius, 0.0f));
    const uint32_t north = 0, south = uint32_t(positions.size() - 1);
    const auto ringVertex = [&](uint32_t r, uint32_t s) { return 1 + (r - 1) * segments + s % segments; };

    Model model;
    model.name = "furnace";
    const auto triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
        vec3 pa = positions[a], pb = positions[b], pc = positions[c];
        if (glm::dot(glm::cross(pb - pa, pc - pa), pa + pb + pc) > 0.0f) std::swap(pb, pc);  // face the centre
        const vec3 normal = glm::normalize(glm::cross(pb - pa, pc - pa));
        for (const vec3& p : {pa, pb, pc}) {
            model.indices.push_back(uint32_t(model.vertices.size()));
            model.vertices.push_back(ModelVertex{p, normal, vec2(0.0f), vec4(0.0f)});
        }
        model.triangleMaterials.push_back(0);
    };
    for (uint32_t s = 0; s < segments; ++s) {
        triangle(north, ringVertex(1, s), ringVertex(1, s + 1));
        triangle(south, ringVertex(rings - 1, s), ringVertex(rings - 1, s + 1));
        for (uint32_t r = 1; r + 1 < rings; ++r) {
            triangle(ringVertex(r, s), ringVertex(r + 1, s), ringVertex(r + 1, s + 1));
            triangle(ringVertex(r, s), ringVertex(r + 1, s + 1), ringVertex(r, s + 1));
        }
    }
    ModelMaterial material;
    material.name = "furnace";
    material.albedo = vec3(albedo);
    material.emission = vec3(emission);
    material.type = MaterialType::Emissive;
    model.materials.push_back(material);
    return model;
}

PathTracerScene furnaceScene(float albedo, float emission) {
    PathTracerSceneDesc desc;
    desc.name = "furnace";
    desc.models.push_back(insideOutSphere(1.0f, 24, 12, albedo, emission));
    desc.objects.push_back({"sphere", 0, Matrix3x4::identity()});
    desc.camera = {vec3(0.0f), vec3(0.3f, -0.2f, -1.0f), vec3(0.0f, 1.0f, 0.0f), 70.0f};
    desc.backgroundColor = vec3(0.0f);
    return PathTracerScene(std::move(desc));
}

TEST(PathTracerScene, FurnaceGivesEmissionOverOneMinusAlbedo) {
    // Every surface emits E and reflects a: L = E (1 + a + ... + a^B) for B bounces, E / (1 - a) in the limit.
    constexpr float a = 0.5f, E = 1.0f;
    constexpr uint32_t kBounces = 24;
    PathTracerScene scene = furnaceScene(a, E);
    EXPECT_EQ(scene.lights().size(), scene.buffers().indices.size() / 3) << "every triangle is a light";
    PathTracerRenderOptions options;
    options.maxBounces = kBounces;
    const RenderResult r = scene.render(16, 16, 16, 1, 2, options);
    EXPECT_EQ(r.dispatch.stats.invocationsOf("PT_Miss", dxr::ShaderStage::Miss), 0u) << "the sphere is closed";
    const double expected = E * (1.0 - std::pow(double(a), kBounces + 1)) / (1.0 - a);
    const PixelStatistics s = statistics(redChannel(r.image));
    EXPECT_NEAR(s.mean, expected, 4.0 * s.standardError) << "standard error " << s.standardError;
    // Far from the answers of a path tracer that drops the bounces (E) or the camera's emission (E a / (1 - a)).
    EXPECT_LT(s.standardError, 0.02);
    EXPECT_GT(std::abs(s.mean - E), 20.0 * s.standardError);
    EXPECT_GT(std::abs(s.mean - E * a / (1.0 - a)), 20.0 * s.standardError);
    for (const vec4& p : r.image.pixels()) {
        EXPECT_EQ(p.r, p.g);
        EXPECT_EQ(p.r, p.b);
        EXPECT_EQ(p.a, 1.0f);
    }
}

TEST(PathTracerScene, FurnaceWithoutBouncesSeesOnlyTheEmission) {
    PathTracerScene scene = furnaceScene(0.5f, 1.0f);
    PathTracerRenderOptions options;
    options.maxBounces = 0;
    const RenderResult r = scene.render(8, 8, 2, 1, 1, options);
    for (const vec4& p : r.image.pixels()) EXPECT_EQ(p, vec4(1.0f));
    EXPECT_EQ(r.dispatch.stats.invocationsOf("PT_ShadowMiss", dxr::ShaderStage::Miss), 0u) << "no NEE at bounce 0";
}

// ---- Determinism -------------------------------------------------------------------------------------------------

TEST(PathTracerScene, SameSeedIsBitIdenticalAcrossThreadsAnotherSeedAgreesInTheMean) {
    PathTracerScene scene = PathTracerScene::cornellBox(kScenes);
    const RenderResult one = scene.render(24, 24, 4, 7, 1);
    const RenderResult two = scene.render(24, 24, 4, 7, 2);
    const RenderResult other = scene.render(24, 24, 4, 8, 2);
    EXPECT_TRUE(sameBytes(one.image, two.image));
    EXPECT_EQ(one.dispatch.stats.raysTraced, two.dispatch.stats.raysTraced);
    EXPECT_FALSE(sameBytes(one.image, other.image));
    // Per-pixel differences of two independent seeds have mean zero.
    std::vector<double> differences;
    for (size_t i = 0; i < one.image.pixels().size(); ++i) {
        const vec4 d = one.image.pixels()[i] - other.image.pixels()[i];
        differences.push_back((d.r + d.g + d.b) / 3.0);
    }
    const PixelStatistics s = statistics(differences);
    EXPECT_GT(s.standardError, 0.0);
    EXPECT_NEAR(s.mean, 0.0, 4.0 * s.standardError);
    EXPECT_TRUE(one.dispatch.diagnostics.empty());
}

// ---- Textures and normal maps ------------------------------------------------------------------------------------

TEST(PathTracerScene, TexturedRoomSamplesDiffuseTextures) {
    PathTracerScene scene = PathTracerScene::texturedRoom(kScenes);
    const uint32_t floor = 0, sphere = 2;
    ASSERT_EQ(scene.desc().objects[floor].name, "floor");
    ASSERT_EQ(scene.desc().objects[sphere].name, "sphere");
    const Image ids = renderDebug(scene, 48, pt::kDebugInstanceID);
    const Image albedo = renderDebug(scene, 48, pt::kDebugAlbedo);
    int light = 0, dark = 0;
    std::set<float> sphereValues;
    for (uint32_t y = 0; y < 48; ++y)
        for (uint32_t x = 0; x < 48; ++x) {
            const float value = albedo.at(x, y).g;
            if (uint32_t(ids.at(x, y).r) == floor) {
                // The checker texture's two cells (0.84 and 0.23 in green), Kd = 1.
                light += std::abs(value - 0.84f) < 0.02f;
                dark += std::abs(value - 0.23f) < 0.02f;
            }
            if (uint32_t(ids.at(x, y).r) == sphere) sphereValues.insert(value);
        }
    EXPECT_GT(light, 10);
    EXPECT_GT(dark, 10);
    EXPECT_GT(sphereValues.size(), 20u) << "the marble texture varies over the sphere";
}

TEST(PathTracerScene, NormalMapsChangeTheShading) {
    PathTracerSceneDesc flat;
    flat.name = "textured-room without normal maps";
    flat.models = loadObjModels(kScenes / "textured-room" / "textured-room.obj");
    PathTracerScene mapped = PathTracerScene::texturedRoom(kScenes);
    flat.camera = mapped.desc().camera;
    flat.backgroundColor = mapped.desc().backgroundColor;
    flat.objects = mapped.desc().objects;
    for (Model& model : flat.models)
        for (ModelMaterial& material : model.materials) material.normalTexture.clear();
    PathTracerScene plain(std::move(flat));
    ASSERT_TRUE(plain.buffers().normalTextures.empty());
    ASSERT_EQ(mapped.buffers().normalTextures.size(), 2u);

    const uint32_t backWall = 1;
    const Image ids = renderDebug(mapped, 40, pt::kDebugInstanceID);
    const Image mappedNormals = renderDebug(mapped, 40, pt::kDebugShadingNormal);
    const Image plainNormals = renderDebug(plain, 40, pt::kDebugShadingNormal);
    int wallPixels = 0, tilted = 0;
    for (uint32_t y = 0; y < 40; ++y)
        for (uint32_t x = 0; x < 40; ++x) {
            if (uint32_t(ids.at(x, y).r) != backWall) continue;
            ++wallPixels;
            EXPECT_TRUE(near(vec3(plainNormals.at(x, y)), vec3(0.5f, 0.5f, 1.0f), 1e-5f)) << x << ", " << y;
            tilted += !near(vec3(mappedNormals.at(x, y)), vec3(0.5f, 0.5f, 1.0f), 0.02f);
        }
    EXPECT_GT(wallPixels, 100);
    EXPECT_GT(tilted, wallPixels / 4) << "the brick normal map tilts the wall's normals";

    // And the path-traced images differ on the wall.
    const RenderResult withMaps = mapped.render(24, 24, 2, 3, 2);
    const RenderResult withoutMaps = plain.render(24, 24, 2, 3, 2);
    const Image smallIds = renderDebug(mapped, 24, pt::kDebugInstanceID);
    int differing = 0;
    for (uint32_t y = 0; y < 24; ++y)
        for (uint32_t x = 0; x < 24; ++x)
            if (uint32_t(smallIds.at(x, y).r) == backWall)
                differing += withMaps.image.at(x, y) != withoutMaps.image.at(x, y);
    EXPECT_GT(differing, 20);
}

// ---- Previews and throughput (not run by default) ------------------------------------------------------------------
// Renders docs/images/path-tracer/{cornell-box,textured-room}.png (256 x 256, 64 paths per pixel, 8 bounces; the
// radiance clamped to [0, 1] and sRGB-encoded for viewing) and prints paths/s on the Cornell box (128 x 128, 16 spp)
// at 1 and 2 threads. Run it on an optimised build:
//   refray_scenes_tests --gtest_also_run_disabled_tests --gtest_filter=PathTracerScene.DISABLED_PreviewsAndThroughput
TEST(PathTracerScene, DISABLED_PreviewsAndThroughput) {
    const fs::path folder = fs::path(REFRAY_SOURCE_DIR) / "docs" / "images" / "path-tracer";
    fs::create_directories(folder);
    const auto srgb = [](float linear) {
        const float c = std::clamp(std::isfinite(linear) ? linear : 0.0f, 0.0f, 1.0f);
        return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    };
    for (const char* name : {"cornell-box", "textured-room"}) {
        PathTracerScene scene = std::string(name) == "cornell-box" ? PathTracerScene::cornellBox(kScenes)
                                                                   : PathTracerScene::texturedRoom(kScenes);
        RenderResult r = scene.render(256, 256, 64, 1, 0);
        for (vec4& p : r.image.pixels()) p = vec4(srgb(p.r), srgb(p.g), srgb(p.b), 1.0f);
        r.image.metadata["refray:encoding"] = "sRGB transfer of the radiance clamped to [0, 1]";
        writeImage((folder / (std::string(name) + ".png")).string(), r.image);
        std::printf("%s: 256 x 256, 64 spp in %.2f s\n", name, r.dispatch.seconds);
    }
    PathTracerScene cornell = PathTracerScene::cornellBox(kScenes);
    for (uint32_t threads : {1u, 2u}) {
        const RenderResult r = cornell.render(128, 128, 16, 1, threads);
        const double paths = 128.0 * 128.0 * 16.0;
        const double seconds = r.dispatch.seconds;
        std::printf("cornell-box 128 x 128 x 16 spp, %u thread(s): %.3f s, %.0f paths/s, %.0f rays/s\n", threads,
                    seconds, paths / seconds, double(r.dispatch.stats.raysTraced) / seconds);
    }
}

}  // namespace
}  // namespace refray::scenes
