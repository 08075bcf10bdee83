#include "scenes/scene_loader.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

#include "core/file_input.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes {

namespace {

using json::ObjectReader;
using json::Value;

// The parts of a scene file, each read by its file in scenes/loader/, in the order they refer to each other.
void loadScene(const Value& root, SceneDesc& scene) {
    loader::ParseContext ctx(scene);
    ObjectReader top(root, "the scene");
    const Value& format = top.required("format");
    if (format.asString() != kSceneFormat)
        format.fail("unsupported format " + inQuotes(format.asString()) + "; this refray reads '" +
                    std::string(kSceneFormat) + "'");
    scene.name = loader::nonEmptyName(top.required("name"), "the scene's name");
    if (const Value* v = top.optional("description")) scene.description = v->asString();
    if (const Value* v = top.optional("source")) scene.source = v->asString();

    const Value& libraryValue = top.required("shaderLibrary");
    try {
        ctx.binding = &findShaderLibrary(libraryValue.asString());
    } catch (const Error& e) {
        libraryValue.fail(e.what());
    }
    scene.shaderLibrary = ctx.binding->name;
    ctx.library = ctx.binding->make(procedural::Precision::Float, ctx.binding->traceRayDefaults, {}, {});

    if (const Value* v = top.optional("layout")) {
        const uint32_t mode = loader::resolveName(*v, {"auto", "explicit"}, "layout");
        scene.layout = mode == 0 ? LayoutMode::Auto : LayoutMode::Explicit;
    }
    if (const Value* v = top.optional("structs")) loader::parseStructs(ctx, *v);
    if (const Value* v = top.optional("values")) ctx.values = v;
    loader::parsePipeline(ctx, top.required("pipeline"));
    loader::parseRayTypes(ctx, top.required("rayTypes"));
    loader::parseHitGroups(ctx, top.required("hitGroups"));
    loader::parseRootSignatures(ctx, top.required("rootSignatures"));
    if (const Value* v = top.optional("models")) loader::parseModels(ctx, *v);
    const Value& buffers = top.required("buffers");
    loader::parseDataBuffers(ctx, buffers);
    loader::parseBottomLevel(ctx, top.required("bottomLevel"));
    const Value& instances = top.required("instances");
    loader::parseInstances(ctx, instances);
    loader::parseGeneratedBuffers(ctx, buffers);
    if (scene.layout == LayoutMode::Auto) {
        if (const Value* v = top.optional("shaderTable"))
            v->fail("'shaderTable' belongs to \"layout\": \"explicit\"; in auto layout the records come from "
                    "each instance's 'records'");
        loader::buildAutoLayout(ctx);
    } else {
        loader::parseExplicitTable(ctx, top.required("shaderTable"));
    }
    loader::deriveAssociations(ctx);
    loader::parseGlobalArguments(ctx, top.required("globalArguments"));
    loader::parseCameras(ctx, top.required("cameras"), top.optional("defaultCamera"));
    if (ctx.binding->usesLight) {
        loader::parseLight(ctx, top.required("light"));
    } else if (const Value* v = top.optional("light")) {
        v->fail("the " + ctx.binding->name + " scene constants hold no light (a path tracer's lights are emissive "
                "triangles: a {\"generate\": \"lightTriangles\"} buffer); remove 'light'");
    }
    if (const Value* v = top.optional("time")) loader::parseTime(ctx, *v);
    if (const Value* v = top.optional("effects")) {
        if (!ctx.binding->configurable)
            v->fail("the " + ctx.binding->name + " shaders are built as written; there is no effect to switch off "
                    "(remove 'effects')");
        loader::parseEffects(ctx, *v);
    }
    if (const Value* v = top.optional("imageSize")) {
        const auto& a = v->asArray();
        if (a.size() != 2) v->fail("imageSize needs [width, height]");
        scene.defaultWidth = a[0].asUint32();
        scene.defaultHeight = a[1].asUint32();
        if (scene.defaultWidth == 0 || scene.defaultHeight == 0 || scene.defaultWidth > 16384 ||
            scene.defaultHeight > 16384)
            v->fail("imageSize must lie within 1x1 .. 16384x16384");
    }
    top.finish();
}

}  // namespace

const CameraDesc& SceneDesc::camera(const std::string& cameraName) const {
    if (cameraName.empty()) return cameras.at(defaultCamera);
    std::vector<std::string> names;
    for (const CameraDesc& c : cameras) {
        if (c.name == cameraName) return c;
        names.push_back(c.name);
    }
    throw Error("scene '" + name + "' has no camera '" + cameraName + "'" + didYouMean(cameraName, names) +
                "; its cameras: " + joined(names));
}

int32_t SceneDesc::findBuffer(const std::string& bufferName) const {
    for (size_t i = 0; i < buffers.size(); ++i)
        if (buffers[i].name == bufferName) return int32_t(i);
    return -1;
}

uint32_t SceneDesc::lightTriangleCount() const {
    for (const BufferDesc& b : buffers)
        if (b.kind == BufferDesc::Kind::LightTriangles) return uint32_t(b.bytes.size() / b.stride);
    return 0;
}

SceneDesc parseScene(std::string_view text, const std::string& fileName) {
    std::string hashed(text);
    LessonDesc lesson;
    const Value root = loader::resolveLesson(json::parse(text, fileName), fileName, 0, hashed, lesson);
    SceneDesc scene;
    scene.file = fileName;
    scene.fileHash = sha256Hex(hashed);
    scene.lesson = std::move(lesson);
    loadScene(root, scene);
    return scene;
}

SceneDesc loadSceneFile(const std::filesystem::path& path) {
    return parseScene(readInputFile(path.string(), "scene file"), path.string());
}

}  // namespace refray::scenes
