#include "scenes/scene_loader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "core/error.h"
#include "core/hash.h"
#include "core/json_writer.h"
#include "core/strings.h"
#include "emulator/root_signature.h"
#include "scenes/camera_models.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes {

namespace loader {

// The hit-group records and miss records: from each instance's "records" (auto layout) or from "shaderTable"
// (explicit layout), and the local root signature association each hit group gets from them.

namespace {

// ⟨hit group, local root signature, arguments⟩ from a record object (the keys other than hitGroup(s)).
void parseRecordBinding(const ParseContext& ctx, ObjectReader& r, RecordDesc& record, const std::string& what) {
    const Value* lrs = r.optional("localRootSignature");
    const Value* args = r.optional("arguments");
    if (!lrs) {
        if (args) args->fail(what + " has arguments but no 'localRootSignature'");
        return;
    }
    record.localRootSignature = int32_t(resolveName(*lrs, ctx.localNames, "local root signature"));
    const SignatureInfo& info = ctx.localInfo[size_t(record.localRootSignature)];
    const dxr::RootSignatureDesc& sig = ctx.scene.localSignatures[size_t(record.localRootSignature)];
    if (!args) {
        if (!info.parameters.empty())
            r.value().fail(what + " uses local root signature " + inQuotes(sig.name) + " but gives no 'arguments'");
        return;
    }
    ObjectReader ar(*args, "the arguments of " + what);
    for (size_t p = 0; p < info.parameters.size(); ++p) {
        const ParameterInfo& pi = info.parameters[p];
        const Value& v = ar.required(pi.name);
        RecordDesc::Argument a;
        a.parameter = uint32_t(p);
        const dxr::RootParameter& param = sig.parameters[p];
        if (param.parameterType == dxr::RootParameterType::Constants32Bit) {
            a.dwords = constantValue(ctx, v, pi.structIndex, param.num32BitValues, "argument " + inQuotes(pi.name));
            a.structIndex = pi.structIndex;
        } else if (param.parameterType == dxr::RootParameterType::DescriptorTable) {
            v.fail("local descriptor tables are not supported in scene files yet; bind buffers as root descriptors");
        } else {
            a.buffer = dataOrGeneratedBuffer(ctx, v);
        }
        record.arguments.push_back(std::move(a));
    }
    ar.finish();
}

// The hit group for a record of `geometry` (checks the geometry type against the hit group type).
void checkHitGroupFits(const ParseContext& ctx, const Value& where, const std::string& hitGroup,
                       const GeometryDescFile& geometry, const std::string& geometryWhat) {
    const dxr::HitGroupDesc& g = ctx.scene.hitGroups[resolveName(where, ctx.hitGroupNames, "hit group")];
    const bool triangles = geometry.type == dxr::GeometryType::Triangles;
    if (triangles != (g.Type == dxr::HitGroupType::Triangles))
        where.fail("hit group " + inQuotes(hitGroup) + " is a " + (triangles ? "procedural" : "triangles") +
                   " hit group, but " + geometryWhat + " holds " + (triangles ? "triangles" : "AABBs") + " (PIPE-4)");
}

}  // namespace

void buildAutoLayout(ParseContext& ctx) {
    uint32_t next = 0;
    for (size_t i = 0; i < ctx.scene.instances.size(); ++i) {
        InstanceDescFile& inst = ctx.scene.instances[i];
        const BlasDesc& blas = ctx.scene.blases[inst.blas];
        const Value& records = *ctx.recordValues[i];
        const auto& list = records.asArray();
        if (list.size() != blas.geometries.size())
            records.fail("instance " + inQuotes(inst.name) + " gives " + std::to_string(list.size()) +
                         " records but BLAS " + inQuotes(blas.name) + " has " + std::to_string(blas.geometries.size()) +
                         " geometries: one record entry per geometry, in geometry order");
        inst.contribution = next;
        for (size_t g = 0; g < list.size(); ++g) {
            const std::string geometryWhat = "geometry " + std::to_string(g) + " of BLAS " + inQuotes(blas.name);
            ObjectReader r(list[g], "the record of instance " + inQuotes(inst.name) + " " + geometryWhat);
            const Value& groups = r.required("hitGroups");
            ObjectReader gr(groups, "hitGroups (one per ray type)");
            RecordDesc binding;
            parseRecordBinding(ctx, r, binding, "instance " + inQuotes(inst.name) + " " + geometryWhat);
            for (const RayTypeDesc& rayType : ctx.scene.rayTypes) {
                const Value& hg = gr.required(rayType.name);
                RecordDesc record = binding;
                record.origin = "instance " + inQuotes(inst.name) + ", " + geometryWhat + ", ray type " + inQuotes(rayType.name);
                record.where = hg.location();
                if (!hg.isNull()) {
                    record.hitGroup = hg.asString();
                    checkHitGroupFits(ctx, hg, record.hitGroup, blas.geometries[g], geometryWhat);
                }
                ctx.recordWhere.push_back(&hg);
                ctx.scene.hitGroupRecords.push_back(std::move(record));
                ++next;
            }
            gr.finish();
            r.finish();
        }
        if (next > 0xFFFFFF) records.fail("the hit-group table outgrows the 24-bit instance contribution");
    }
    for (const RayTypeDesc& t : ctx.scene.rayTypes) ctx.scene.missRecords.push_back(t.miss);
}

void parseExplicitTable(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "shaderTable");
    for (const Value& m : r.required("miss").asArray()) {
        if (m.isNull()) {
            ctx.scene.missRecords.emplace_back();
            continue;
        }
        requireExport(ctx, m, dxr::ShaderStage::Miss);
        ctx.scene.missRecords.push_back(m.asString());
    }
    const auto& records = r.required("hitGroups").asArray();
    for (size_t i = 0; i < records.size(); ++i) {
        ObjectReader rr(records[i], "hit-group record " + std::to_string(i));
        RecordDesc record;
        record.origin = "hit-group record " + std::to_string(i);
        record.where = records[i].location();
        const Value& hg = rr.required("hitGroup");
        if (!hg.isNull()) {
            record.hitGroup = hg.asString();
            resolveName(hg, ctx.hitGroupNames, "hit group");
        }
        parseRecordBinding(ctx, rr, record, record.origin);
        rr.finish();
        ctx.recordWhere.push_back(&hg);
        ctx.scene.hitGroupRecords.push_back(std::move(record));
    }
    if (const Value* s = r.optional("hitGroupStride")) {
        ctx.scene.hitGroupStride = s->asUint32();
        if (ctx.scene.hitGroupStride % 32 != 0 || ctx.scene.hitGroupStride > 4096)
            s->fail("a hit-group stride is a multiple of 32 up to 4096 (REC-3), got " + std::to_string(ctx.scene.hitGroupStride));
    }
    r.finish();
}

void deriveAssociations(ParseContext& ctx) {
    std::map<std::string, std::pair<int32_t, const Value*>> byGroup;
    for (size_t i = 0; i < ctx.scene.hitGroupRecords.size(); ++i) {
        const RecordDesc& r = ctx.scene.hitGroupRecords[i];
        if (r.hitGroup.empty()) continue;
        const auto [it, inserted] = byGroup.emplace(r.hitGroup, std::make_pair(r.localRootSignature, ctx.recordWhere[i]));
        if (!inserted && it->second.first != r.localRootSignature) {
            auto name = [&](int32_t s) { return s < 0 ? std::string("none") : inQuotes(ctx.scene.localSignatures[size_t(s)].name); };
            ctx.recordWhere[i]->fail("hit group " + inQuotes(r.hitGroup) + " is used with local root signature " +
                                     name(r.localRootSignature) + " here but with " + name(it->second.first) + " at " +
                                     json::toString(it->second.second->location()) +
                                     "; a state object associates one local root signature with each export (ASSOC-3)");
        }
    }
    for (const auto& [group, sig] : byGroup)
        if (sig.first >= 0) ctx.scene.localAssociations[size_t(sig.first)].push_back(group);
}

// "globalArguments": what the global root signature's parameters are bound to: buffers, the TLAS, descriptor tables
// of buffers, the render target and the models' textures.

namespace {

// {"textures": "diffuse" | "normal"}: one Texture2D SRV per texture of the models' materials, in the order of
// GlobalModelBuffers (the indices MaterialGPU holds), or one null descriptor when there is none.
void appendTextures(const ParseContext& ctx, const Value& value, GlobalArgumentDesc::TableEntry entry,
                    std::vector<GlobalArgumentDesc::TableEntry>& table, const std::string& parameter) {
    ObjectReader r(value, "a textures entry of " + inQuotes(parameter));
    const Value& which = r.required("textures");
    r.finish();
    const uint32_t kind = resolveName(which, {"diffuse", "normal"}, "texture list");
    if (ctx.scene.models.empty())
        which.fail("{\"textures\": ...} binds the textures of the scene's 'models'; this scene has none");
    if (entry.type != dxr::DescriptorRangeType::SRV)
        which.fail("textures are SRVs; the unbounded range of " + inQuotes(parameter) + " holds " +
                   std::string(dxr::toString(entry.type)) + "s");
    const auto& paths = kind == 0 ? ctx.scene.modelBuffers.diffuseTextures : ctx.scene.modelBuffers.normalTextures;
    entry.isTexture = true;
    if (paths.empty()) table.push_back(entry);
    for (const std::filesystem::path& path : paths) {
        entry.texture = path;
        table.push_back(entry);
    }
}

}  // namespace

void parseGlobalArguments(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "globalArguments");
    const dxr::RootSignatureDesc& sig = ctx.scene.globalSignature;
    for (size_t p = 0; p < sig.parameters.size(); ++p) {
        const dxr::RootParameter& param = sig.parameters[p];
        const std::string& name = ctx.globalInfo.parameters[p].name;
        const Value& v = r.required(name);
        GlobalArgumentDesc a;
        a.parameter = uint32_t(p);
        switch (param.parameterType) {
            case dxr::RootParameterType::Constants32Bit:
                v.fail("global root constants are not supported in scene files yet; use a constant buffer");
            case dxr::RootParameterType::DescriptorTable: {
                a.kind = GlobalArgumentDesc::Kind::Table;
                std::vector<dxr::DescriptorRangeType> slots;
                const dxr::DescriptorRange* unbounded = nullptr;  // the last range, when it is unbounded
                for (const dxr::DescriptorRange& range : param.ranges) {
                    if (range.numDescriptors == dxr::kDescriptorRangeUnbounded) {
                        unbounded = &range;
                        break;
                    }
                    for (uint32_t k = 0; k < range.numDescriptors; ++k) slots.push_back(range.rangeType);
                }
                const auto& entries = v.asArray();
                if (unbounded && entries.size() <= slots.size()) {
                    std::string range = "(";
                    range += dxr::registerLetter(unbounded->rangeType);
                    range += std::to_string(unbounded->baseShaderRegister);
                    range += ".., space ";
                    range += std::to_string(unbounded->registerSpace);
                    range += ")";
                    v.fail("table " + inQuotes(name) + " ends in an unbounded range " + range + ", which needs " +
                           "at least one descriptor after the " + std::to_string(slots.size()) +
                           " of its other ranges; bind the models' textures with {\"textures\": \"diffuse\"} "
                           "or {\"textures\": \"normal\"}");
                }
                if (!unbounded && entries.size() != slots.size())
                    v.fail("table " + inQuotes(name) + " has " + std::to_string(slots.size()) + " descriptors; " +
                           std::to_string(entries.size()) + " given");
                for (size_t k = 0; k < entries.size(); ++k) {
                    GlobalArgumentDesc::TableEntry e;
                    e.type = k < slots.size() ? slots[k] : unbounded->rangeType;
                    if (entries[k].isObject() && entries[k].find("textures")) {
                        if (k < slots.size())
                            entries[k].fail("{\"textures\": ...} binds as many descriptors as the models have "
                                            "textures, so it belongs in an unbounded range; descriptor " +
                                            std::to_string(k) + " of " + inQuotes(name) + " is in a bounded one");
                        appendTextures(ctx, entries[k], e, a.table, name);
                        continue;
                    }
                    if (entries[k].isString()) {
                        if (entries[k].asString() != "@renderTarget")
                            entries[k].fail("a table entry is \"@renderTarget\" or {\"buffer\": NAME, \"stride\": N}");
                        if (e.type != dxr::DescriptorRangeType::UAV)
                            entries[k].fail("the render target is a UAV; descriptor " + std::to_string(k) + " of " +
                                            inQuotes(name) + " is a " + std::string(dxr::toString(e.type)));
                        e.renderTarget = true;
                    } else {
                        ObjectReader er(entries[k], "descriptor " + std::to_string(k) + " of " + inQuotes(name));
                        e.buffer = dataOrGeneratedBuffer(ctx, er.required("buffer"));
                        if (const Value* s = er.optional("stride")) e.stride = s->asUint32();
                        er.finish();
                    }
                    a.table.push_back(e);
                }
                break;
            }
            default:
                if (v.isString() && v.asString() == "@tlas") {
                    if (param.parameterType != dxr::RootParameterType::SRV)
                        v.fail("the acceleration structure binds to a root SRV; " + inQuotes(name) + " is a " +
                               std::string(dxr::toString(param.parameterType)));
                    a.kind = GlobalArgumentDesc::Kind::AccelerationStructure;
                } else {
                    a.kind = GlobalArgumentDesc::Kind::Buffer;
                    a.buffer = dataOrGeneratedBuffer(ctx, v);
                }
        }
        ctx.scene.globalArguments.push_back(std::move(a));
    }
    r.finish();
}

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
