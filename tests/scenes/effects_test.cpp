// Tests scenes/effects.cpp: the effect set of each reference scene, field by field with its reasons; the scene
// file's "effects" block (loader errors, what it switches off in a render, counted with a TraceObserver); and that
// an absent or default block leaves renders bit-identical.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "emulator/trace.h"
#include "scenes/effects.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

using testing::edited;
using testing::loadError;
using testing::readText;

const std::string kSourceDir = REFRAY_SOURCE_DIR;
const std::string kProceduray = kSourceDir + "/scenes/proceduray-mandel-julia-pac.json";
const std::string kD3D12 = kSourceDir + "/scenes/d3d12-procedural-geometry.json";
const std::string kImageSize = "\"imageSize\": [1280, 720]";

// The scene file `path` with `block` as its "effects" (inserted before "imageSize").
std::string withEffects(const std::string& path, const std::string& block) {
    return edited(readText(path), kImageSize, "\"effects\": " + block + ", " + kImageSize);
}

void expectEffect(const Effect& e, const std::string& name, bool on, const std::string& reason) {
    EXPECT_EQ(e.name, name);
    EXPECT_EQ(e.on, on) << name << ": " << e.reason;
    EXPECT_EQ(e.reason, reason) << name;
}

// ---- The effect sets of the reference scenes ------------------------------------------------------------------------

TEST(EffectSet, ProceduraySceneFieldByField) {
    const EffectSet e = computeEffects(loadSceneFile(kProceduray));
    expectEffect(e.triangles, "triangles", true, "BLAS 'GlobalGeometry' (1 triangle geometry) under instance 'slab'");
    expectEffect(e.procedural, "procedural primitives", true,
                 "BLASes 'Julia', 'Pacman', 'Mandelbulb' (3 AABB geometries) under 4 instances");
    expectEffect(e.anyHit, "any-hit shaders", false,
                 "none of the 8 hit groups the records name has an any-hit shader");
    expectEffect(e.triangleCulling, "triangle culling", true,
                 "'Radiance', 'Shadow' rays cull back-facing triangles of instance 'slab'");
    expectEffect(e.geometrySkip, "geometry-skipping pipeline flag", false, "rays reach both triangle and AABB geometry");
    expectEffect(e.shadowRays, "shadow rays", true,
                 "ClosestHit_Triangle, ClosestHit_Pacman trace 'Shadow' rays towards the light from hits at depth "
                 "1..2, MAX_RAY_RECURSION_DEPTH 3 (the HLSL's)");
    expectEffect(e.reflections, "reflections", true,
                 "ClosestHit_Triangle, ClosestHit_Pacman, ClosestHit_Mandelbulb, ClosestHit_Julia trace them "
                 "(reflectanceCoef > 0.001 in 4 of 4 records), 2 bounces: MAX_RAY_RECURSION_DEPTH 3 (the HLSL's), "
                 "pipeline MaxTraceRecursionDepth 3");
    expectEffect(e.animation, "animation", true,
                 "Intersection_Mandelbulb (the Mandelbulb's step count), Intersection_Pacman (the Pac-man's mouth) "
                 "read elapsedTime");
    expectEffect(e.supersampling, "supersampling", false, "spp 1: one camera ray per pixel");
    expectEffect(e.distanceFog, "distance fog", false, "no shader of library 'proceduray' applies distance fog");
    expectEffect(e.rayDifferentials, "ray-differential checkers", false,
                 "no shader of library 'proceduray' filters a texture with ray differentials");
    expectEffect(e.debugColours, "debug colours", false, "debugFlag is 0 in 'sceneCB'");
    EXPECT_EQ(e.recursionDepth, 3u);
    EXPECT_EQ(e.pipelineRecursionDepth, 3u);
    EXPECT_EQ(e.spp, 1u);
}

TEST(EffectSet, D3D12SceneFieldByField) {
    const EffectSet e = computeEffects(loadSceneFile(kD3D12));
    expectEffect(e.triangles, "triangles", true, "BLAS 'Plane' (1 triangle geometry) under instance 'ground'");
    expectEffect(e.procedural, "procedural primitives", true,
                 "BLAS 'ProceduralPrimitives' (10 AABB geometries) under instance 'primitives'");
    expectEffect(e.anyHit, "any-hit shaders", false,
                 "none of the 8 hit groups the records name has an any-hit shader");
    expectEffect(e.triangleCulling, "triangle culling", true,
                 "'Radiance', 'Shadow' rays cull back-facing triangles of instance 'ground'");
    expectEffect(e.geometrySkip, "geometry-skipping pipeline flag", false, "rays reach both triangle and AABB geometry");
    EXPECT_EQ(e.pipelineFlags, dxr::PIPELINE_FLAG_NONE);
    expectEffect(e.shadowRays, "shadow rays", true,
                 "MyClosestHitShader_Triangle, MyClosestHitShader_AABB trace 'Shadow' rays towards the light from "
                 "hits at depth 1..2, MAX_RAY_RECURSION_DEPTH 3 (the HLSL's)");
    expectEffect(e.reflections, "reflections", true,
                 "MyClosestHitShader_Triangle, MyClosestHitShader_AABB trace them (reflectanceCoef > 0.001 in 4 of 11 "
                 "records), 2 bounces: MAX_RAY_RECURSION_DEPTH 3 (the HLSL's), pipeline MaxTraceRecursionDepth 3");
    expectEffect(e.animation, "animation", true,
                 "buffer 'aabbPrimitiveAttributes' spins 4 primitives; MyIntersectionShader_VolumetricPrimitive (the "
                 "metaballs' centres) reads elapsedTime");
    expectEffect(e.supersampling, "supersampling", false, "spp 1: one camera ray per pixel");
    expectEffect(e.distanceFog, "distance fog", true,
                 "MyClosestHitShader_Triangle, MyClosestHitShader_AABB blend towards the background by hit distance "
                 "(visibility falloff)");
    expectEffect(e.rayDifferentials, "ray-differential checkers", true,
                 "MyClosestHitShader_Triangle (the grid lines) filters over the footprint of the neighbouring pixels' "
                 "camera rays");
    expectEffect(e.debugColours, "debug colours", false, "library 'd3d12-procedural-geometry' has no debugFlag");
    EXPECT_EQ(e.recursionDepth, 3u);
    EXPECT_EQ(e.pipelineRecursionDepth, 3u);
}

// The RayQuery lessons' variant closest hits (procedural/d3d12 InlineVariant) have the effects of the closest hits
// they vary: shadow rays (traced inline), reflections, fog and the grid lines.
TEST(EffectSet, TheInlineVariantsHaveTheEffectsOfTheShadersTheyVary) {
    const EffectSet e = computeEffects(loadSceneFile(kSourceDir + "/scenes/lessons/accept-first-hit-for-shadows.json"));
    EXPECT_TRUE(e.shadowRays.on) << e.shadowRays.reason;
    EXPECT_NE(e.shadowRays.reason.find("MyClosestHitShader_Triangle_InlineShadow_SearchAllHits, "
                                       "MyClosestHitShader_AABB_InlineShadow_SearchAllHits trace 'Shadow' rays"),
              std::string::npos)
        << e.shadowRays.reason;
    EXPECT_TRUE(e.reflections.on) << e.reflections.reason;
    EXPECT_TRUE(e.distanceFog.on) << e.distanceFog.reason;
    EXPECT_TRUE(e.rayDifferentials.on) << e.rayDifferentials.reason;
}

// A pipeline flag skips the geometry type no ray reaches, unless a ray type's flags make it undefined. The Cornell
// box's pipeline gets SKIP_PROCEDURAL_PRIMITIVES; PathTracerSceneFile.* checks its render is bit-identical to the
// C++-built twin, whose pipeline has no flags.
TEST(EffectSet, GeometrySkippingPipelineFlag) {
    const SceneDesc cornell = loadSceneFile(kSourceDir + "/scenes/cornell-box.json");
    const EffectSet c = computeEffects(cornell);
    expectEffect(c.geometrySkip, "geometry-skipping pipeline flag", true,
                 "pipeline flag SKIP_PROCEDURAL_PRIMITIVES: no instance a ray can reach holds AABB geometry");
    EXPECT_EQ(c.pipelineFlags, dxr::PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES);
    EXPECT_EQ(geometrySkipPipelineFlags(cornell), dxr::PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES);
    EXPECT_EQ(geometrySkipPipelineFlags(loadSceneFile(kD3D12)), dxr::PIPELINE_FLAG_NONE);

    // The D3D12 scene without its ground: only AABBs, but its rays cull back faces, which SKIP_TRIANGLES excludes.
    SceneDesc boxesOnly = loadSceneFile(kD3D12);
    boxesOnly.instances.erase(std::remove_if(boxesOnly.instances.begin(), boxesOnly.instances.end(),
                                             [](const InstanceDescFile& i) { return i.name == "ground"; }),
                              boxesOnly.instances.end());
    const EffectSet b = computeEffects(boxesOnly);
    expectEffect(b.geometrySkip, "geometry-skipping pipeline flag", false,
                 "pipeline flag SKIP_TRIANGLES would be undefined with the CULL_BACK_FACING_TRIANGLES of ray type "
                 "'Radiance' (FLAG-4, FLAG-5)");
    EXPECT_EQ(b.pipelineFlags, dxr::PIPELINE_FLAG_NONE);
}

TEST(EffectSet, DescribeListsSimulatedThenSkipped) {
    const std::string text = describeEffects(computeEffects(loadSceneFile(kD3D12)));
    EXPECT_EQ(text.rfind("simulated: triangles - BLAS 'Plane'", 0), 0u) << text;
    EXPECT_CONTAINS(text, "\nskipped: any-hit shaders - none of the 8 hit groups");
    EXPECT_LT(text.rfind("simulated: "), text.find("skipped: "));
    size_t lines = 0;
    for (const char c : text) lines += c == '\n' ? 1 : 0;
    EXPECT_EQ(lines, EffectSet{}.list().size());
}

TEST(EffectSet, SupersamplingAndRecursionKnobCount) {
    const SceneDesc desc = loadSceneFile(kD3D12);
    RenderSettings settings;
    settings.spp = 4;
    settings.accuracy.maxRecursionDepth = 5;
    const EffectSet e = computeEffects(desc, settings);
    expectEffect(e.supersampling, "supersampling", true, "spp 4: 2x2 camera rays per pixel, averaged");
    EXPECT_EQ(e.recursionDepth, 5u);
    EXPECT_EQ(e.pipelineRecursionDepth, 5u);
    EXPECT_CONTAINS(e.reflections.reason, "4 bounces: MAX_RAY_RECURSION_DEPTH 5 (the recursion-depth knob)");
}

TEST(EffectSet, SceneWithoutAnyHitReportsAnyHitSkippedAndWithOneSimulated) {
    SceneDesc desc = loadSceneFile(kProceduray);
    for (RecordDesc& r : desc.hitGroupRecords)
        if (r.hitGroup != "HitGroup_Triangle") r.hitGroup.clear();  // only the slab's radiance record is left
    expectEffect(computeEffects(desc).anyHit, "any-hit shaders", false,
                 "hit group 'HitGroup_Triangle' has no any-hit shader");
    desc.hitGroups[0].AnyHitShaderImport = "AnyHit_Cutout";
    expectEffect(computeEffects(desc).anyHit, "any-hit shaders", true,
                 "hit group 'HitGroup_Triangle' (AnyHit_Cutout) run an any-hit shader");
}

TEST(EffectSet, ReflectionsFollowTheMaterials) {
    // The D3D12 closest hits reflect only where reflectanceCoef > 0.001: with every material at 0, none does.
    std::string text = readText(kD3D12);
    for (const char* from : {"\"reflectanceCoef\": 0.25", "\"reflectanceCoef\": 1,"})
        text = edited(text, from, std::string(from).find("0.25") != std::string::npos ? "\"reflectanceCoef\": 0"
                                                                                       : "\"reflectanceCoef\": 0,");
    expectEffect(computeEffects(parseScene(text, "dull.json")).reflections, "reflections", false,
                 "no record that runs a shader which traces reflection rays has reflectanceCoef > 0.001");
}

TEST(EffectSet, NothingAnimatesWithoutTimeReadersOrSpin) {
    SceneDesc desc = loadSceneFile(kD3D12);
    for (BufferDesc& b : desc.buffers)
        for (PrimitiveTransformDesc& p : b.primitives) p.spinYPerSecond = 0;
    for (RecordDesc& r : desc.hitGroupRecords)
        if (r.hitGroup.find("Volumetric") != std::string::npos) r.hitGroup.clear();
    expectEffect(computeEffects(desc).animation, "animation", false,
                 "no shader the scene runs reads elapsedTime and no primitiveTransforms buffer spins");
}

// ---- The effects block in scene files -------------------------------------------------------------------------------

TEST(EffectsBlock, LoadsIntoTheSceneDesc) {
    const SceneDesc plain = loadSceneFile(kProceduray);
    EXPECT_FALSE(plain.effects.present);
    EXPECT_TRUE(plain.effects.shadows);
    EXPECT_FALSE(plain.effects.reflectionDepth.has_value());

    const SceneDesc desc = parseScene(withEffects(kProceduray, R"({"shadows": false, "reflectionDepth": 2})"), "e.json");
    EXPECT_TRUE(desc.effects.present);
    EXPECT_FALSE(desc.effects.shadows);
    EXPECT_EQ(desc.effects.reflectionDepth, 2u);
    EXPECT_EQ(describeEffectsBlock(desc.effects), "shadows=off,reflectionDepth=2");
    EXPECT_EQ(describeEffectsBlock(plain.effects), "defaults");
    EXPECT_EQ(libraryEffects(desc).traceShadowRays, false);
    EXPECT_EQ(libraryAccuracy(desc, {}).maxRecursionDepth, 2u);
    procedural::Accuracy knob;
    knob.maxRecursionDepth = 5;
    EXPECT_EQ(libraryAccuracy(desc, knob).maxRecursionDepth, 5u);  // the render's knob wins

    const EffectSet e = computeEffects(desc);
    expectEffect(e.shadowRays, "shadow rays", false,
                 "the scene's effects block sets \"shadows\": false, so ClosestHit_Triangle, ClosestHit_Pacman take "
                 "every point as lit");
    EXPECT_EQ(e.recursionDepth, 2u);
    EXPECT_EQ(e.pipelineRecursionDepth, 3u);  // the scene's pipeline keeps its 3
    EXPECT_CONTAINS(e.reflections.reason, "1 bounce: MAX_RAY_RECURSION_DEPTH 2 (the scene's reflectionDepth)");
    const EffectSet lit = computeEffects(parseScene(withEffects(kProceduray, R"({"reflectionDepth": 2})"), "e.json"));
    expectEffect(lit.shadowRays, "shadow rays", true,
                 "ClosestHit_Triangle, ClosestHit_Pacman trace 'Shadow' rays towards the light from hits at depth 1, "
                 "MAX_RAY_RECURSION_DEPTH 2 (the scene's reflectionDepth)");
}

TEST(EffectsBlock, UnknownKeyHasDidYouMean) {
    const std::string error = loadError(withEffects(kD3D12, R"({"shadow": false})"));
    EXPECT_CONTAINS(error, "broken.json:");
    EXPECT_CONTAINS(error, "unknown key 'shadow' in effects (did you mean 'shadows'?); expected one of: shadows, "
                           "reflectionDepth");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, R"({"reflectiondepth": 1})")), "(did you mean 'reflectionDepth'?)");
    EXPECT_CONTAINS(loadError(edited(readText(kD3D12), kImageSize, "\"effect\": {}, " + kImageSize)),
                    "unknown key 'effect' in the scene (did you mean 'effects'?)");
}

TEST(EffectsBlock, WrongTypesAndRangesFail) {
    const std::string text = readText(kD3D12);
    const size_t line = size_t(std::count(text.begin(), text.begin() + long(text.find(kImageSize)), '\n')) + 1;
    const std::string at = "broken.json:" + std::to_string(line) + ":";
    const std::string shadows = loadError(withEffects(kD3D12, R"({"shadows": "no"})"));
    EXPECT_CONTAINS(shadows, at);
    EXPECT_CONTAINS(shadows, "'shadows' in effects is true or false, got a string");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, R"({"shadows": 0})")), "is true or false, got a number");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, R"({"reflectionDepth": true})")),
                    "'reflectionDepth' in effects is an integer 1..31, got a boolean");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, R"({"reflectionDepth": 0})")),
                    "reflectionDepth is the shaders' MAX_RAY_RECURSION_DEPTH, 1..31 (1: camera rays only), got 0");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, R"({"reflectionDepth": 32})")), "1..31");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, R"({"reflectionDepth": 1.5})")), "expected an integer, got 1.5");
    EXPECT_CONTAINS(loadError(withEffects(kD3D12, "[]")), "expected an object for effects, got an array");
    EXPECT_EQ(loadError(withEffects(kD3D12, "{}")), "");
}

// ---- What the block switches off in a render ------------------------------------------------------------------------

// Counts the TraceRay calls of a dispatch by ray type and depth, and the launch indices where a shadow ray hit
// something (the point was in shadow). Events arrive concurrently from worker threads.
class RayCounter : public dxr::TraceObserver {
public:
    explicit RayCounter(uint32_t shadowContribution) : shadowContribution_(shadowContribution) {}

    void onEvent(const dxr::TraceEvent& event) override {
        const bool shadow = event.rayContribution == shadowContribution_;
        std::lock_guard<std::mutex> lock(mutex_);
        if (event.kind == dxr::TraceEvent::Kind::TraceRay) {
            ++(shadow ? shadowRays : otherRays);
            deepest = std::max(deepest, event.depth);  // the ray's level: camera rays are 1
        } else if (event.kind == dxr::TraceEvent::Kind::TraceRayEnd && shadow && event.committed) {
            shadowedLaunches.insert((uint64_t(event.launchIndex.y) << 32) | event.launchIndex.x);
        }
    }

    uint64_t shadowRays = 0, otherRays = 0;
    uint32_t deepest = 0;
    std::set<uint64_t> shadowedLaunches;

private:
    uint32_t shadowContribution_;
    std::mutex mutex_;
};

struct CountedRender {
    Image image;
    uint64_t shadowRays = 0, otherRays = 0;
    uint32_t deepest = 0;
    std::set<uint64_t> shadowedLaunches;
};

CountedRender render(const std::string& text, uint32_t width, uint32_t height, const std::string& camera = "") {
    Scene scene(parseScene(text, "effects.json"));
    RayCounter counter(scene.desc().rayTypes[1].rayContribution);
    RenderSettings settings;
    settings.camera = camera;
    settings.width = width;
    settings.height = height;
    settings.observer = &counter;
    RenderResult result = scene.render(settings);
    EXPECT_TRUE(result.dispatch.diagnostics.empty());
    return {std::move(result.image), counter.shadowRays, counter.otherRays, counter.deepest, counter.shadowedLaunches};
}

// Shadows off: no shadow ray is traced, and only pixels some shadow ray darkened change. `camera` is added to the
// scene's cameras and used when given.
void expectShadowsOffChangesOnlyShadowedPixels(const std::string& path, const std::string& camera = "") {
    const std::string cameras = "\"cameras\": [";
    const std::string text = camera.empty() ? readText(path) : edited(readText(path), cameras, cameras + camera + ",");
    const std::string name = camera.empty() ? "" : "added";
    const CountedRender with = render(text, 48, 27, name);
    const CountedRender without =
        render(edited(text, kImageSize, "\"effects\": {\"shadows\": false}, " + kImageSize), 48, 27, name);
    EXPECT_GT(with.shadowRays, 0u);
    EXPECT_EQ(without.shadowRays, 0u);
    EXPECT_GT(without.otherRays, 0u);
    ASSERT_FALSE(with.shadowedLaunches.empty()) << path << ": nothing in shadow at this size";
    size_t changed = 0;
    for (uint32_t y = 0; y < 27; ++y)
        for (uint32_t x = 0; x < 48; ++x) {
            if (std::memcmp(&with.image.at(x, y), &without.image.at(x, y), sizeof(vec4)) == 0) continue;
            ++changed;
            EXPECT_TRUE(with.shadowedLaunches.count((uint64_t(y) << 32) | x))
                << path << ": pixel " << x << "," << y << " changed without a shadow ray hitting anything";
        }
    EXPECT_GT(changed, 0u) << path;
}

TEST(EffectsRender, ShadowsOffTracesNoShadowRaysD3D12) { expectShadowsOffChangesOnlyShadowedPixels(kD3D12); }

TEST(EffectsRender, ShadowsOffTracesNoShadowRaysProceduray) {
    // The canonical cameras see only faces turned away from the light (the scene's visual up is -y), where a shadow
    // changes nothing; this one looks down on the slab's lit top, which the Julia shadows (H12).
    expectShadowsOffChangesOnlyShadowedPixels(
        kProceduray, R"({"name": "added", "model": "miniengine", "eye": [0, 20, 80], "target": [0, 3, 0],
                        "up": [0, -1, 0], "fovYDegrees": 45, "near": 0.01, "far": 125})");
}

TEST(EffectsRender, ReflectionDepthOneTracesNoDeeperRays) {
    const CountedRender full = render(readText(kD3D12), 32, 18);
    EXPECT_EQ(full.deepest, 3u);
    const CountedRender one = render(withEffects(kD3D12, R"({"reflectionDepth": 1})"), 32, 18);
    EXPECT_EQ(one.deepest, 1u);
    EXPECT_EQ(one.shadowRays, 0u);  // shadow rays are level 2
    EXPECT_EQ(one.otherRays, 32u * 18u);
    const CountedRender two = render(withEffects(kD3D12, R"({"reflectionDepth": 2})"), 32, 18);
    EXPECT_EQ(two.deepest, 2u);

    const EffectSet e = computeEffects(parseScene(withEffects(kD3D12, R"({"reflectionDepth": 1})"), "e.json"));
    expectEffect(e.reflections, "reflections", false,
                 "MAX_RAY_RECURSION_DEPTH 1 (the scene's reflectionDepth): hits at depth 1 trace no reflection rays");
    expectEffect(e.shadowRays, "shadow rays", false,
                 "MAX_RAY_RECURSION_DEPTH 1 (the scene's reflectionDepth): hits at depth 1 trace no shadow rays");
}

TEST(EffectsRender, DefaultBlockIsBitIdenticalAndNamedInMetadata) {
    const CountedRender plain = render(readText(kD3D12), 32, 18);
    const std::string text = withEffects(kD3D12, R"({"shadows": true, "reflectionDepth": 3})");
    const CountedRender defaults = render(text, 32, 18);
    EXPECT_EQ(plain.shadowRays, defaults.shadowRays);
    EXPECT_EQ(plain.otherRays, defaults.otherRays);
    ASSERT_EQ(plain.image.pixels().size(), defaults.image.pixels().size());
    EXPECT_EQ(std::memcmp(plain.image.pixels().data(), defaults.image.pixels().data(),
                          plain.image.pixels().size() * sizeof(vec4)),
              0);

    Scene scene(parseScene(withEffects(kD3D12, R"({"shadows": false})"), "e.json"));
    RenderSettings settings;
    settings.width = 4;
    settings.height = 4;
    EXPECT_EQ(scene.render(settings).image.metadata.at("effects"), "shadows=off");
    Scene plainScene(loadSceneFile(kD3D12));
    EXPECT_EQ(plainScene.render(settings).image.metadata.count("effects"), 0u);
}

}  // namespace
}  // namespace refray::scenes
