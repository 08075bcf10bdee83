#include "scenes/scene_loader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "core/hash.h"
#include "core/json_writer.h"
#include "core/strings.h"
#include "scenes/camera_models.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes {

namespace loader {

// "cameras", and the rest of what a frame is rendered with: "light", "time" and "effects".

void parseCameras(ParseContext& ctx, const Value& value, const Value* defaultCamera) {
    std::vector<std::string> names;
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a camera");
        CameraDesc c;
        c.name = nonEmptyName(r.required("name"), "a camera name");
        r.setWhat("camera " + inQuotes(c.name));
        if (std::find(names.begin(), names.end(), c.name) != names.end()) v.fail("two cameras are named " + inQuotes(c.name));
        const uint32_t model = resolveName(r.required("model"), {"miniengine", "directxmath-lh"}, "camera model");
        c.model = model == 0 ? CameraModel::MiniEngine : CameraModel::DirectXMathLH;
        c.eye = doubleVector3(r.required("eye"), "eye");
        c.target = doubleVector3(r.required("target"), "target");
        const Value* up = r.optional("up");
        const Value* upFromRight = r.optional("upFromRight");
        if (up && upFromRight) upFromRight->fail("give 'up' or 'upFromRight', not both");
        if (up) {
            c.up = doubleVector3(*up, "up");
        } else if (upFromRight) {
            // up = normalize(cross(normalize(target - eye), right)), as both samples' hosts compute it.
            const glm::dvec3 right = doubleVector3(*upFromRight, "upFromRight");
            const glm::dvec3 forward = glm::normalize(c.target - c.eye);
            const glm::dvec3 u = glm::cross(forward, right);
            if (!(glm::length(u) > 0.0)) upFromRight->fail("upFromRight is parallel to the view direction");
            c.up = glm::normalize(u);
        } else {
            v.fail("camera " + inQuotes(c.name) + " needs 'up' or 'upFromRight'");
        }
        if (const Value* rot = r.optional("rotateYDegrees")) {
            // XMMatrixRotationY applied to eye and up (row vectors): x' = x·cos + z·sin, z' = -x·sin + z·cos.
            const double a = finiteNumber(*rot, "rotateYDegrees") * 3.14159265358979323846 / 180.0;
            auto rotate = [a](glm::dvec3 p) {
                return glm::dvec3(p.x * std::cos(a) + p.z * std::sin(a), p.y, -p.x * std::sin(a) + p.z * std::cos(a));
            };
            c.eye = rotate(c.eye);
            c.up = rotate(c.up);
            c.target = rotate(c.target);
        }
        c.fovYRadians = finiteNumber(r.required("fovYDegrees"), "fovYDegrees") * 3.14159265358979323846 / 180.0;
        c.nearZ = finiteNumber(r.required("near"), "near");
        c.farZ = finiteNumber(r.required("far"), "far");
        r.finish();
        try {
            projectionToWorld(c, 16, 9);  // validates the camera here, where its file position is known
        } catch (const Error& e) {
            v.fail(e.what());
        }
        names.push_back(c.name);
        ctx.scene.cameras.push_back(c);
    }
    if (ctx.scene.cameras.empty()) value.fail("a scene needs at least one camera");
    if (defaultCamera) ctx.scene.defaultCamera = resolveName(*defaultCamera, names, "camera");
}

void parseLight(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "light");
    ctx.scene.light.position = floatVector<4>(r.required("position"), "position");
    ctx.scene.light.ambientColor = floatVector<4>(r.required("ambientColor"), "ambientColor");
    ctx.scene.light.diffuseColor = floatVector<4>(r.required("diffuseColor"), "diffuseColor");
    r.finish();
}

void parseTime(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "time");
    if (const Value* d = r.optional("default")) {
        ctx.scene.defaultTime = d->asFloat();
        ctx.scene.defaultTimeText = d->numberText();
        if (ctx.scene.defaultTime < 0.0f) d->fail("time must not be negative (the samples' time only grows)");
    }
    if (const Value* c = r.optional("canonical"))
        for (const Value& t : c->asArray()) {
            ctx.scene.canonicalTimes.push_back(t.asFloat());
            if (ctx.scene.canonicalTimes.back() < 0.0f) t.fail("time must not be negative");
        }
    r.finish();
}

void parseEffects(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "effects");
    ctx.scene.effects.present = true;
    ctx.scene.effects.where = value.location();
    if (const Value* v = r.optional("shadows")) {
        if (!v->isBool()) v->fail("'shadows' in effects is true or false, got " + std::string(v->kindName()));
        ctx.scene.effects.shadows = v->asBool();
    }
    if (const Value* v = r.optional("reflectionDepth")) {
        if (!v->isNumber())
            v->fail("'reflectionDepth' in effects is an integer 1..31, got " + std::string(v->kindName()));
        const uint32_t depth = v->asUint32();
        if (depth < 1 || depth > 31)
            v->fail("reflectionDepth is the shaders' MAX_RAY_RECURSION_DEPTH, 1..31 (1: camera rays only), got " +
                    std::to_string(depth));
        ctx.scene.effects.reflectionDepth = depth;
    }
    r.finish();
}

// Lesson files (refray-lesson/1, docs/tutorial-indexing.md): a base scene or lesson with a JSON Patch applied.

Value resolveLesson(Value root, const std::string& fileName, uint32_t depth, std::string& hashed, LessonDesc& lesson) {
    const Value* format = root.isObject() ? root.find("format") : nullptr;
    if (!format || !format->isString() || format->asString() != kLessonFormat) return root;
    if (depth >= 8) root.fail("lessons are based on each other more than 8 deep (a cycle?)");
    ObjectReader r(root, "a lesson");
    r.required("format");
    const Value& name = r.required("name");
    const Value& base = r.required("base");
    const Value& title = r.required("title");
    const Value* teaches = r.optional("teaches");
    const Value& patch = r.required("patch");
    const Value* expect = r.optional("expect");
    r.finish();
    const std::filesystem::path basePath = std::filesystem::path(fileName).parent_path() / base.asString();
    std::ifstream in(basePath, std::ios::binary);
    if (!in) base.fail("cannot read the lesson's base " + basePath.string() + ": " + std::strerror(errno));
    const std::string baseText((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    hashed += baseText;
    LessonDesc inner;
    Value document = resolveLesson(json::parse(baseText, basePath.string()), basePath.string(), depth + 1, hashed, inner);
    json::applyPatch(document, patch);
    if (depth == 0) {
        lesson.title = title.asString();
        if (teaches) lesson.teaches = teaches->asString();
        lesson.base = base.asString();
        if (expect) {
            ObjectReader er(*expect, "the lesson's 'expect'");
            if (const Value* v = er.optional("table")) lesson.expectTable = v->asString();
            if (const Value* v = er.optional("render")) {
                ObjectReader rr(*v, "the lesson's expected render");
                if (const Value* c = rr.optional("camera")) lesson.renderCamera = c->asString();
                if (const Value* z = rr.optional("size")) lesson.renderSize = z->asString();
                lesson.expectRender = rr.required("diagnostic").asString();
                rr.finish();
            }
            er.finish();
        }
    }
    // The lesson's name replaces the base's (renders and messages name the lesson).
    const std::string nameJson = "[{\"op\": \"replace\", \"path\": \"/name\", \"value\": " + json::quoted(name.asString()) + "}]";
    json::applyPatch(document, json::parse(nameJson, fileName));
    return document;
}

}  // namespace loader

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
    std::ifstream in(path, std::ios::binary);
    REFRAY_CHECK(in, "cannot read scene file " << path.string() << ": " << std::strerror(errno));
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return parseScene(text, path.string());
}

}  // namespace refray::scenes
