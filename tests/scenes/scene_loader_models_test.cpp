// Tests what scenes/scene_loader.cpp (and scenes/loader/) and scenes/scene.cpp add for models and the path tracer: "models" from OBJ
// files, BLAS geometry from a model, the generated model buffers, InstanceID defaulting to the object index,
// unbounded texture ranges, static samplers, the dxr-path-tracer library's constants and its spp, and the errors of
// broken files (file:line:column, "did you mean"). The scene files are small and written here, beside a two-object
// OBJ file in a directory of each test's own.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "procedural/pathtracer/pathtracer_shaders.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"
#include "tests/test_output.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
namespace pt = refray::procedural::pathtracer;

// A floor quad (white) and a small lamp quad above it facing down (emission 5), as two OBJ objects.
const char* kObj = R"(mtllib tiny.mtl
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
v -0.25 1 -0.25
v 0.25 1 -0.25
v 0.25 1 0.25
v -0.25 1 0.25
o floor
usemtl white
f 1 4 3 2
o lamp
usemtl light
f 5 6 7 8
)";
const char* kMtl = R"(newmtl white
Kd 0.8 0.8 0.8
newmtl light
Kd 0 0 0
Ke 5 5 5
)";

// Two instances of two models, auto layout, InstanceIDs left to the default.
const char* kScene = R"({
  "format": "refray-scene/1",
  "name": "tiny-room",
  "shaderLibrary": "dxr-path-tracer",
  "pipeline": {"rayGeneration": "PT_RayGen", "maxRecursionDepth": 1, "maxPayloadBytes": 96, "maxAttributeBytes": 8},
  "rayTypes": [
    {"name": "Radiance", "miss": "PT_Miss", "payload": "RadiancePayload"},
    {"name": "Shadow", "miss": "PT_ShadowMiss", "payload": "ShadowPayload"}
  ],
  "hitGroups": [
    {"name": "PT_HitGroup", "type": "triangles", "closestHit": "PT_ClosestHit"},
    {"name": "PT_ShadowHitGroup", "type": "triangles"}
  ],
  "rootSignatures": {
    "global": {"name": "PathTracerGlobal", "parameters": [
      {"name": "g_output", "kind": "table", "ranges": [{"type": "UAV", "register": "u0"}]},
      {"name": "g_scene", "kind": "srv", "register": "t0"},
      {"name": "g_constants", "kind": "cbv", "register": "b0"},
      {"name": "g_sceneBuffers", "kind": "table", "ranges": [
        {"type": "SRV", "register": "t0", "space": 1}, {"type": "SRV", "register": "t0", "space": 2},
        {"type": "SRV", "register": "t0", "space": 3}, {"type": "SRV", "register": "t1", "space": 3},
        {"type": "SRV", "register": "t0", "space": 4}, {"type": "SRV", "register": "t0", "space": 7}]},
      {"name": "g_diffuseTextures", "kind": "table", "ranges": [{"type": "SRV", "register": "t0", "space": 5, "count": "unbounded"}]},
      {"name": "g_normalTextures", "kind": "table", "ranges": [{"type": "SRV", "register": "t0", "space": 6, "count": "unbounded"}]}
    ],
    "staticSamplers": [{"register": "s0", "filter": "anisotropic", "address": "wrap"}]}
  },
  "models": [
    {"name": "floor", "file": "tiny.obj", "object": "floor"},
    {"name": "lamp", "file": "tiny.obj", "object": "lamp"}
  ],
  "buffers": {
    "vertices": {"generate": "modelVertices"},
    "indices": {"generate": "modelIndices"},
    "materials": {"generate": "modelMaterials"},
    "triangleMaterials": {"generate": "modelTriangleMaterials"},
    "objects": {"generate": "modelObjects"},
    "lights": {"generate": "lightTriangles"},
    "constants": {"generate": "sceneConstants", "backgroundColor": [0.25, 0.5, 1], "maxBounces": 3}
  },
  "bottomLevel": [
    {"name": "floorBLAS", "geometries": [{"type": "triangles", "flags": ["OPAQUE"], "model": "floor"}]},
    {"name": "lampBLAS", "geometries": [{"type": "triangles", "flags": ["OPAQUE"], "model": "lamp"}]}
  ],
  "instances": [
    {"name": "floor", "blas": "floorBLAS",
     "records": [{"hitGroups": {"Radiance": "PT_HitGroup", "Shadow": "PT_ShadowHitGroup"}}]},
    {"name": "lamp", "blas": "lampBLAS", "transform": {"translate": [0, 0.5, 0]},
     "records": [{"hitGroups": {"Radiance": "PT_HitGroup", "Shadow": "PT_ShadowHitGroup"}}]}
  ],
  "globalArguments": {
    "g_output": ["@renderTarget"],
    "g_scene": "@tlas",
    "g_constants": "constants",
    "g_sceneBuffers": [{"buffer": "vertices", "stride": 48}, {"buffer": "indices", "stride": 4},
                       {"buffer": "materials", "stride": 64}, {"buffer": "triangleMaterials", "stride": 4},
                       {"buffer": "objects", "stride": 32}, {"buffer": "lights", "stride": 64}],
    "g_diffuseTextures": [{"textures": "diffuse"}],
    "g_normalTextures": [{"textures": "normal"}]
  },
  "cameras": [{"name": "above", "model": "miniengine", "eye": [0, 3, 0], "target": [0, 0, 0], "up": [0, 0, -1],
               "fovYDegrees": 50, "near": 0.01, "far": 100}],
  "imageSize": [16, 16]
}
)";

class SceneLoaderModels : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = refray::testing::testOutputDirectory("scene_loader_models");  // every test writes tiny.obj
        write("tiny.obj", kObj);
        write("tiny.mtl", kMtl);
    }

    void write(const std::string& name, const std::string& text) const {
        std::ofstream(directory_ / name, std::ios::binary) << text;
    }
    std::string path() const { return (directory_ / "scene.json").string(); }

    SceneDesc load(const std::string& text) const { return parseScene(text, path()); }
    // The loader's message for `text`, "" if it loads.
    std::string error(const std::string& text) const {
        try {
            load(text);
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    }
    // The message of `from` -> `to` in the scene above, which must point at the line that holds `to` (its first
    // line, for a replacement of several lines).
    std::string errorAtEdit(const std::string& from, const std::string& to) const {
        const std::string text = testing::edited(kScene, from, to);
        const std::string message = error(text);
        const size_t at = text.find(to);
        const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n'));
        const std::string prefix = path() + ":" + std::to_string(line) + ":";
        EXPECT_EQ(message.rfind(prefix, 0), 0u) << "expected the message at " << prefix << "\n" << message;
        return message;
    }

    fs::path directory_;
};

const BufferDesc& buffer(const SceneDesc& desc, const std::string& name) {
    const int32_t i = desc.findBuffer(name);
    if (i < 0) throw Error("no buffer " + name);
    return desc.buffers[size_t(i)];
}

TEST_F(SceneLoaderModels, ModelsBecomeBuffersGeometryAndObjects) {
    const SceneDesc desc = load(kScene);
    ASSERT_EQ(desc.models.size(), 2u);
    EXPECT_EQ(desc.models[1].name, "lamp");
    EXPECT_EQ(desc.models[1].object, "lamp");
    EXPECT_EQ(desc.models[1].file, directory_ / "tiny.obj");

    // Each quad is 2 triangles of 3 vertices (no vn: flat shading, corners unshared); the model buffers hold both
    // models, floor first.
    EXPECT_EQ(buffer(desc, "vertices").kind, BufferDesc::Kind::ModelVertices);
    EXPECT_EQ(buffer(desc, "vertices").stride, 48u);
    EXPECT_EQ(buffer(desc, "vertices").bytes.size(), 12u * 48u);
    EXPECT_EQ(buffer(desc, "indices").bytes.size(), 12u * 4u);
    EXPECT_EQ(buffer(desc, "materials").bytes.size(), 2u * 64u);
    EXPECT_EQ(buffer(desc, "triangleMaterials").bytes.size(), 4u * 4u);
    EXPECT_EQ(buffer(desc, "objects").bytes.size(), 2u * 32u);
    EXPECT_TRUE(buffer(desc, "objects").isStatic());
    EXPECT_FALSE(buffer(desc, "constants").isStatic());

    // The lamp's BLAS reads its range of the global buffers: vertices 6.., indices 6.. (stride 48, R32_UINT).
    const GeometryDescFile& lamp = desc.blases[1].geometries[0];
    EXPECT_EQ(lamp.model, 1);
    EXPECT_EQ(lamp.vertexBuffer, uint32_t(desc.findBuffer("vertices")));
    EXPECT_EQ(lamp.vertexOffset, 6u * 48u);
    EXPECT_EQ(lamp.vertexStride, 48u);
    EXPECT_EQ(lamp.vertexCount, 6u);
    EXPECT_EQ(lamp.indexBuffer, desc.findBuffer("indices"));
    EXPECT_EQ(lamp.indexOffset, 6u * 4u);
    EXPECT_EQ(lamp.indexCount, 6u);
    EXPECT_EQ(lamp.indexFormat, dxr::Format::R32_UINT);

    // InstanceID defaults to the object index; the objects buffer holds each instance's model ranges.
    EXPECT_EQ(desc.instances[0].instanceID, 0u);
    EXPECT_EQ(desc.instances[1].instanceID, 1u);
    ObjectGPU objects[2];
    std::memcpy(objects, buffer(desc, "objects").bytes.data(), sizeof objects);
    EXPECT_EQ(objects[1].vertexOffset, 6u);
    EXPECT_EQ(objects[1].indexOffset, 6u);
    EXPECT_EQ(objects[1].modelIndex, 1u);

    // The lamp's two triangles, moved by its instance transform (y 1 + 0.5), emission 5, area 0.125 each.
    ASSERT_EQ(desc.lightTriangleCount(), 2u);
    pt::LightTriangleGPU light;
    std::memcpy(&light, buffer(desc, "lights").bytes.data(), sizeof light);
    EXPECT_EQ(light.v0.y, 1.5f);
    EXPECT_EQ(vec3(light.emission), vec3(5.0f));
    EXPECT_FLOAT_EQ(light.emission.w, 0.125f);

    // No textures: each texture table holds one null Texture2D descriptor.
    const GlobalArgumentDesc& diffuse = desc.globalArguments[4];
    ASSERT_EQ(diffuse.table.size(), 1u);
    EXPECT_TRUE(diffuse.table[0].isTexture);
    EXPECT_TRUE(diffuse.table[0].texture.empty());

    // The static sampler and the unbounded ranges reach the root signature.
    ASSERT_EQ(desc.globalSignature.staticSamplers.size(), 1u);
    EXPECT_EQ(desc.globalSignature.staticSamplers[0].Filter, dxr::FILTER_ANISOTROPIC);
    EXPECT_EQ(desc.globalSignature.staticSamplers[0].AddressV, dxr::TEXTURE_ADDRESS_MODE_WRAP);
    EXPECT_EQ(desc.globalSignature.parameters[5].ranges[0].numDescriptors, dxr::kDescriptorRangeUnbounded);
    EXPECT_EQ(desc.globalSignature.parameters[5].ranges[0].registerSpace, 6u);

    // The constants' extra keys.
    EXPECT_EQ(buffer(desc, "constants").backgroundColor, vec3(0.25f, 0.5f, 1.0f));
    EXPECT_EQ(buffer(desc, "constants").maxBounces, 3u);
}

TEST_F(SceneLoaderModels, AnInstanceIDInTheFileWins) {
    const SceneDesc desc = load(testing::edited(kScene, "\"blas\": \"lampBLAS\",", "\"blas\": \"lampBLAS\", \"instanceID\": 7,"));
    EXPECT_EQ(desc.instances[0].instanceID, 0u);
    EXPECT_EQ(desc.instances[1].instanceID, 7u);
}

// The debug mode shows (InstanceID, PrimitiveIndex, material) of the first hit, seen from straight above: the lamp
// in the middle (its back side), the floor around it, the background at the corners.
TEST_F(SceneLoaderModels, RendersThroughTheInstanceIDIndirection) {
    Scene scene(load(testing::edited(kScene, "\"maxBounces\": 3}", "\"maxBounces\": 3, \"debugMode\": 5}")));
    RenderSettings settings;
    settings.width = settings.height = 16;
    settings.threads = 2;
    const Image ids = scene.render(settings).image;
    EXPECT_EQ(ids.at(8, 8).r, 1.0f);           // the lamp: InstanceID 1
    EXPECT_EQ(ids.at(8, 8).b, 1.0f);           // its material: global index 1
    EXPECT_EQ(ids.at(8, 12).r, 0.0f);          // the floor beside it
    EXPECT_EQ(ids.at(8, 12).b, 0.0f);
    EXPECT_EQ(vec3(ids.at(0, 0)), vec3(0.25f, 0.5f, 1.0f));  // a miss: the background
}

// spp is the shader's path count: any N, one dispatch of the image size; the progressive mean of N paths.
TEST_F(SceneLoaderModels, SppIsThePathCount) {
    Scene scene(load(kScene));
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.threads = 2;
    settings.spp = 3;
    const RenderResult r = scene.render(settings);
    EXPECT_EQ(r.image.width(), 8u);
    EXPECT_EQ(r.dispatch.stats.invocations[size_t(dxr::ShaderStage::RayGeneration)], 64u);
    EXPECT_EQ(r.image.metadata.at("spp"), "3");

    settings.spp = 0;
    try {
        scene.render(settings);
        ADD_FAILURE() << "spp 0 rendered";
    } catch (const Error& e) {
        EXPECT_CONTAINS(e.what(), "--spp for library 'dxr-path-tracer' is the number of random paths per pixel");
        EXPECT_CONTAINS(e.what(), "1 to 1048576; got 0");
    }
    settings.spp = 1;
    settings.precision = procedural::Precision::Double;
    try {
        scene.render(settings);
        ADD_FAILURE() << "double precision rendered";
    } catch (const Error& e) {
        EXPECT_CONTAINS(e.what(), "the dxr-path-tracer shaders exist in float only");
    }
}

TEST_F(SceneLoaderModels, ModelErrorsNameTheFileAndLine) {
    EXPECT_CONTAINS(errorAtEdit("{\"name\": \"floor\", \"file\": \"tiny.obj\",", "{\"name\": \"floor\", \"file\": \"nothere.obj\","),
                    "model 'floor': ");
    EXPECT_CONTAINS(error(testing::edited(kScene, "\"file\": \"tiny.obj\", \"object\": \"floor\"",
                                          "\"file\": \"nothere.obj\", \"object\": \"floor\"")),
                    "nothere.obj");
    EXPECT_CONTAINS(errorAtEdit("\"object\": \"lamp\"}", "\"object\": \"lmap\"}"),
                    "has no object 'lmap' (did you mean 'lamp'?); its objects: floor, lamp");
    EXPECT_CONTAINS(errorAtEdit("\"model\": \"lamp\"}", "\"model\": \"lamb\"}"),
                    "unknown model 'lamb' (did you mean 'lamp'?); defined: floor, lamp");
    EXPECT_CONTAINS(errorAtEdit("{\"name\": \"lamp\", \"file\"", "{\"name\": \"lamp\", \"fiel\": \"x\", \"file\""),
                    "unknown key 'fiel' in model 'lamp' (did you mean 'file'?)");
    EXPECT_CONTAINS(errorAtEdit("{\"name\": \"lamp\", \"file\": \"tiny.obj\", \"object\": \"lamp\"}",
                                "{\"name\": \"floor\", \"file\": \"tiny.obj\", \"object\": \"lamp\"}"),
                    "two models are named 'floor'");
    // Geometry from a model reads the model buffers, which the file must declare: the message points at the first
    // geometry that needs them.
    const std::string text = testing::edited(kScene, "\"vertices\": {\"generate\": \"modelVertices\"},", "");
    const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + std::ptrdiff_t(text.find("\"model\": \"floor\"}")), '\n'));
    const std::string message = error(text);
    EXPECT_EQ(message.rfind(path() + ":" + std::to_string(line) + ":", 0), 0u) << message;
    EXPECT_CONTAINS(message, "a geometry from a model reads the models' vertex and index buffers; declare them in 'buffers'");
}

TEST_F(SceneLoaderModels, ModelBufferErrors) {
    EXPECT_CONTAINS(errorAtEdit("\"indices\": {\"generate\": \"modelIndices\"},",
                                "\"indices\": {\"generate\": \"modelIndices\"}, \"more\": {\"generate\": \"modelIndices\"},"),
                    "buffer 'indices' already is the scene's modelIndices buffer; a scene has one of each");
    EXPECT_CONTAINS(errorAtEdit("\"objects\": {\"generate\": \"modelObjects\"},", "\"objects\": {\"generate\": \"modelObject\"},"),
                    "unknown generated buffer kind 'modelObject' (did you mean 'modelObjects'?)");
    EXPECT_CONTAINS(errorAtEdit("\"lights\": {\"generate\": \"lightTriangles\"},",
                                "\"lights\": {\"generate\": \"lightTriangles\", \"stride\": 64},"),
                    "unknown key 'stride' in buffer 'lights'");
    EXPECT_CONTAINS(errorAtEdit("\"maxBounces\": 3}", "\"maxBounces\": 3, \"debugFlag\": 1}"),
                    "the dxr-path-tracer scene constants have no debugFlag; their debug switch is 'debugMode'");
}

TEST_F(SceneLoaderModels, TextureTableErrors) {
    EXPECT_CONTAINS(errorAtEdit("\"g_diffuseTextures\": [{\"textures\": \"diffuse\"}]", "\"g_diffuseTextures\": []"),
                    "table 'g_diffuseTextures' ends in an unbounded range (t0.., space 5), which needs at least one "
                    "descriptor after the 0 of its other ranges");
    EXPECT_CONTAINS(errorAtEdit("[{\"textures\": \"normal\"}]", "[{\"textures\": \"normals\"}]"),
                    "unknown texture list 'normals' (did you mean 'normal'?)");
    EXPECT_CONTAINS(errorAtEdit("{\"buffer\": \"lights\", \"stride\": 64}]", "{\"textures\": \"diffuse\"}]"),
                    "{\"textures\": ...} binds as many descriptors as the models have textures, so it belongs in an "
                    "unbounded range; descriptor 5 of 'g_sceneBuffers' is in a bounded one");
    EXPECT_CONTAINS(errorAtEdit("\"space\": 5, \"count\": \"unbounded\"}", "\"space\": 5, \"count\": \"unbound\"}"),
                    "a range's count is a number or \"unbounded\", got 'unbound'");
    EXPECT_CONTAINS(errorAtEdit("[{\"type\": \"SRV\", \"register\": \"t0\", \"space\": 6, \"count\": \"unbounded\"}]",
                                "[{\"type\": \"SRV\", \"register\": \"t0\", \"space\": 6, \"count\": \"unbounded\"}, "
                                "{\"type\": \"SRV\", \"register\": \"t0\", \"space\": 8}]"),
                    "an unbounded range must be the last of its table (BIND-9)");
}

TEST_F(SceneLoaderModels, StaticSamplerErrors) {
    const std::string sampler = "{\"register\": \"s0\", \"filter\": \"anisotropic\", \"address\": \"wrap\"}";
    EXPECT_CONTAINS(errorAtEdit(sampler, "{\"register\": \"s0\", \"filter\": \"anisotropik\", \"address\": \"wrap\"}"),
                    "unknown sampler filter 'anisotropik' (did you mean 'anisotropic'?)");
    EXPECT_CONTAINS(errorAtEdit(sampler, "{\"register\": \"s0\", \"filter\": \"anisotropic\", \"adress\": \"wrap\"}"),
                    "unknown key 'adress' in static sampler 0 of root signature 'PathTracerGlobal' (did you mean "
                    "'address'?)");
    EXPECT_CONTAINS(errorAtEdit(sampler, "{\"register\": \"s0\", \"filter\": \"anisotropic\", \"address\": \"warp\"}"),
                    "unknown texture address mode 'warp' (did you mean 'wrap'?)");
    EXPECT_CONTAINS(errorAtEdit(sampler, "{\"register\": \"t0\", \"filter\": \"anisotropic\", \"address\": \"wrap\"}"),
                    "a static sampler binds a 's' register, got 't0'");
    EXPECT_CONTAINS(errorAtEdit(sampler, "{\"register\": \"s0\", \"address\": \"wrap\", \"addressU\": \"clamp\"}"),
                    "give 'address' (all three) or 'addressU' / 'addressV' / 'addressW', not both");
    EXPECT_CONTAINS(errorAtEdit(sampler, "{\"register\": \"s0\", \"filter\": \"anisotropic\", \"maxAnisotropy\": 17}"),
                    "BIND-10");
}

TEST_F(SceneLoaderModels, WhatThePathTracerDoesNotTake) {
    EXPECT_CONTAINS(errorAtEdit("\"imageSize\": [16, 16]",
                                "\"light\": {\"position\": [0, 1, 0, 1], \"ambientColor\": [0, 0, 0, 1], "
                                "\"diffuseColor\": [1, 1, 1, 1]}, \"imageSize\": [16, 16]"),
                    "the dxr-path-tracer scene constants hold no light");
    EXPECT_CONTAINS(errorAtEdit("\"payload\": \"ShadowPayload\"}",
                                "\"payload\": \"ShadowPayload\", \"traceRay\": {\"multiplier\": 1}}"),
                    "the dxr-path-tracer shaders pass fixed TraceRay arguments; remove 'traceRay'");
    EXPECT_CONTAINS(errorAtEdit("\"imageSize\": [16, 16]", "\"effects\": {\"shadows\": false}, \"imageSize\": [16, 16]"),
                    "the dxr-path-tracer shaders are built as written");
    // The objects buffer needs every instance to hold one model.
    EXPECT_CONTAINS(error(testing::edited(kScene, "{\"name\": \"lampBLAS\", \"geometries\": [{\"type\": \"triangles\", \"flags\": [\"OPAQUE\"], \"model\": \"lamp\"}]}",
                                          "{\"name\": \"lampBLAS\", \"geometries\": [{\"type\": \"triangles\", \"vertices\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}]}")),
                    "holds one object per instance, so every instance needs a BLAS of one geometry from a model; "
                    "instance 'lamp' holds BLAS 'lampBLAS', which is not one");
}

TEST_F(SceneLoaderModels, ModelBuffersNeedModels) {
    // The D3D12 documented example with a model buffer added.
    const std::string d3d12 = testing::readText(std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json");
    const std::string text = testing::edited(d3d12, "\"buffers\": {", "\"buffers\": {\"vertices\": {\"generate\": \"modelVertices\"},");
    try {
        parseScene(text, path());
        ADD_FAILURE() << "loaded";
    } catch (const Error& e) {
        EXPECT_CONTAINS(e.what(), "buffer 'vertices' is generated from the scene's 'models'; this scene has none");
    }
}

}  // namespace
}  // namespace refray::scenes
