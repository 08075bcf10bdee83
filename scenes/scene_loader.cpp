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
#include "scenes/mesh.h"
#include "scenes/path_tracer_scene.h"

namespace refray::scenes {

namespace loader {

// "models" (OBJ files read into Model) and the buffers a scene generates from them: {"generate": "modelVertices"}
// and the other model buffer kinds.

namespace {

template <class T>
void setElements(BufferDesc& b, const std::vector<T>& elements) {
    b.stride = uint32_t(sizeof(T));
    b.bytes.resize(elements.size() * sizeof(T));
    if (!elements.empty()) std::memcpy(b.bytes.data(), elements.data(), b.bytes.size());
}

// One object per instance, in instance order (ObjectGPU and the light list read them): each instance must hold
// a BLAS of one geometry made from a model.
void buildModelObjects(ParseContext& ctx, const Value& where, const std::string& buffer) {
    if (!ctx.scene.modelBuffers.objectDescs.empty()) return;
    std::vector<ModelObjectDesc> objects;
    for (const InstanceDescFile& inst : ctx.scene.instances) {
        const BlasDesc& blas = ctx.scene.blases[inst.blas];
        if (blas.geometries.size() != 1 || blas.geometries[0].model < 0)
            where.fail("buffer " + inQuotes(buffer) + " holds one object per instance, so every instance needs a "
                       "BLAS of one geometry from a model; instance " + inQuotes(inst.name) + " holds BLAS " +
                       inQuotes(blas.name) + ", which is not one");
        objects.push_back({inst.name, uint32_t(blas.geometries[0].model), inst.transform});
    }
    try {
        ctx.scene.modelBuffers = buildGlobalModelBuffers(ctx.models, objects);
    } catch (const Error& e) {
        where.fail(e.what());
    }
}

}  // namespace

// "models": [{"name", "file": an OBJ relative to the scene file, "object": one OBJ object of it}], in the order
// of the global model buffers.
void parseModels(ParseContext& ctx, const Value& value) {
    std::map<std::filesystem::path, std::vector<Model>> files;  // loadObjModels per file, read once
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a model");
        ModelDesc desc;
        desc.name = nonEmptyName(r.required("name"), "a model's name");
        r.setWhat("model " + inQuotes(desc.name));
        for (const ModelDesc& o : ctx.scene.models)
            if (o.name == desc.name) v.fail("two models are named " + inQuotes(desc.name));
        desc.where = v.location();
        const Value& file = r.required("file");
        // Relative to the file that wrote the value (a lesson's base keeps its own directory).
        desc.file = std::filesystem::path(file.location().file).parent_path() / file.asString();
        const Value* object = r.optional("object");
        r.finish();
        Model model;
        const std::vector<Model>* objects = nullptr;
        try {
            if (!object) {
                model = loadObjModel(desc.file);
            } else {
                auto it = files.find(desc.file);
                if (it == files.end()) it = files.emplace(desc.file, loadObjModels(desc.file)).first;
                objects = &it->second;
            }
        } catch (const Error& e) {
            file.fail("model " + inQuotes(desc.name) + ": " + e.what());
        }
        if (objects) {
            desc.object = object->asString();
            std::vector<std::string> names;
            for (const Model& m : *objects) names.push_back(m.name);
            const auto found = std::find(names.begin(), names.end(), desc.object);
            if (found == names.end())
                object->fail("OBJ file " + desc.file.string() + " has no object " + inQuotes(desc.object) +
                             didYouMean(desc.object, names) + "; its objects: " + joined(names));
            model = (*objects)[size_t(found - names.begin())];
        }
        model.name = desc.name;
        ctx.modelNames.push_back(desc.name);
        ctx.models.push_back(std::move(model));
        ctx.scene.models.push_back(std::move(desc));
    }
    if (ctx.scene.models.empty()) value.fail("'models' lists no model; leave it out instead");
    try {
        ctx.scene.modelBuffers = buildGlobalModelBuffers(ctx.models, {});
    } catch (const Error& e) {
        value.fail(e.what());
    }
}

const std::vector<std::pair<std::string, BufferDesc::Kind>>& modelBufferKinds() {
    static const std::vector<std::pair<std::string, BufferDesc::Kind>> kinds = {
        {"modelVertices", BufferDesc::Kind::ModelVertices},
        {"modelIndices", BufferDesc::Kind::ModelIndices},
        {"modelMaterials", BufferDesc::Kind::ModelMaterials},
        {"modelTriangleMaterials", BufferDesc::Kind::ModelTriangleMaterials},
        {"modelObjects", BufferDesc::Kind::ModelObjects},
        {"lightTriangles", BufferDesc::Kind::LightTriangles}};
    return kinds;
}

void addModelBuffer(ParseContext& ctx, const json::Member& m, BufferDesc::Kind kind) {
    ObjectReader r(m.value, "buffer " + inQuotes(m.key));
    const Value& generate = r.required("generate");
    r.finish();
    if (ctx.scene.models.empty())
        generate.fail("buffer " + inQuotes(m.key) + " is generated from the scene's 'models'; this scene has none");
    for (const BufferDesc& other : ctx.scene.buffers)
        if (other.kind == kind)
            generate.fail("buffer " + inQuotes(other.name) + " already is the scene's " + generate.asString() +
                          " buffer; a scene has one of each");
    BufferDesc b;
    b.name = m.key;
    b.kind = kind;
    const GlobalModelBuffers& g = ctx.scene.modelBuffers;
    switch (kind) {
        case BufferDesc::Kind::ModelVertices: setElements(b, g.vertices); break;
        case BufferDesc::Kind::ModelIndices: setElements(b, g.indices); break;
        case BufferDesc::Kind::ModelMaterials: setElements(b, g.materials); break;
        case BufferDesc::Kind::ModelTriangleMaterials: setElements(b, g.triangleMaterials); break;
        case BufferDesc::Kind::ModelObjects:
            buildModelObjects(ctx, generate, m.key);
            setElements(b, ctx.scene.modelBuffers.objects);
            break;
        case BufferDesc::Kind::LightTriangles:
            buildModelObjects(ctx, generate, m.key);
            setElements(b, buildLightTriangles(ctx.scene.modelBuffers));
            break;
        default: REFRAY_ASSERT(false, "not a model buffer kind");
    }
    addBuffer(ctx, std::move(b), m.value);
}

std::optional<BufferDesc::Kind> staticModelKind(const Value& buffer) {
    const Value* generate = buffer.find("generate");
    if (!generate || !generate->isString()) return std::nullopt;
    for (const auto& [name, kind] : modelBufferKinds())
        if (name == generate->asString() && kind != BufferDesc::Kind::ModelObjects &&
            kind != BufferDesc::Kind::LightTriangles)
            return kind;
    return std::nullopt;
}

// "buffers": data buffers, and the buffers generated each frame (scene constants, instance and primitive
// transforms) or from the models (models.cpp).

uint32_t addBuffer(ParseContext& ctx, BufferDesc buffer, const Value& where) {
    if (buffer.name.empty() || buffer.name[0] == '@') where.fail("buffer names must not be empty or start with '@'");
    if (ctx.scene.findBuffer(buffer.name) >= 0) where.fail("two buffers are named " + inQuotes(buffer.name));
    buffer.where = where.location();
    ctx.scene.buffers.push_back(std::move(buffer));
    return uint32_t(ctx.scene.buffers.size() - 1);
}

void parseDataBuffers(ParseContext& ctx, const Value& value) {
    for (const json::Member& m : value.asObject()) {
        if (!m.value.isObject()) m.value.fail("expected an object for buffer " + inQuotes(m.key) + ", got " +
                                              std::string(m.value.kindName()));
        if (const std::optional<BufferDesc::Kind> kind = staticModelKind(m.value)) {
            addModelBuffer(ctx, m, *kind);  // before the geometry that reads it
            continue;
        }
        if (m.value.find("generate")) continue;  // after the instances
        ObjectReader r(m.value, "buffer " + inQuotes(m.key));
        BufferDesc b;
        b.name = m.key;
        const uint32_t format = resolveName(r.required("format"), {"uint16", "uint32", "int32", "float32"}, "buffer format");
        for (const Value& v : r.required("data").asArray()) {
            uint32_t bits = 0;
            if (format == 0) {
                const uint32_t u = v.asUint32();
                if (u > 0xFFFF) v.fail("a uint16 buffer holds values up to 65535, got " + std::to_string(u));
                const uint16_t h = uint16_t(u);
                b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&h), reinterpret_cast<const uint8_t*>(&h) + 2);
                continue;
            }
            bits = encodeScalar(v, format == 1 ? ScalarKind::Uint : format == 2 ? ScalarKind::Int : ScalarKind::Float,
                                "an element of buffer " + inQuotes(m.key));
            b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&bits), reinterpret_cast<const uint8_t*>(&bits) + 4);
        }
        if (b.bytes.empty()) m.value.fail("buffer " + inQuotes(m.key) + " has no data");
        if (const Value* s = r.optional("stride")) {
            b.stride = s->asUint32();
            if (b.stride == 0 || b.bytes.size() % b.stride != 0)
                s->fail("buffer " + inQuotes(m.key) + " holds " + std::to_string(b.bytes.size()) +
                        " bytes, not a multiple of its stride " + std::to_string(b.stride));
        }
        r.finish();
        addBuffer(ctx, std::move(b), m.value);
    }
}

void parseGeneratedBuffers(ParseContext& ctx, const Value& value) {
    std::vector<std::string> kinds = {"sceneConstants", "instanceTransforms", "primitiveTransforms"};
    for (const auto& k : modelBufferKinds()) kinds.push_back(k.first);
    for (const json::Member& m : value.asObject()) {
        if (!m.value.find("generate") || staticModelKind(m.value)) continue;
        const uint32_t kind = resolveName(*m.value.find("generate"), kinds, "generated buffer kind");
        if (kind >= 3) {
            addModelBuffer(ctx, m, modelBufferKinds()[kind - 3].second);
            continue;
        }
        ObjectReader r(m.value, "buffer " + inQuotes(m.key));
        r.required("generate");
        BufferDesc b;
        b.name = m.key;
        if (kind == 0) {
            b.kind = BufferDesc::Kind::SceneConstants;
            const std::string flagKey = ctx.binding->hasDebugFlag ? ctx.binding->debugFlagName : "debugFlag";
            if (const Value* d = r.optional(flagKey)) {
                if (!ctx.binding->hasDebugFlag)
                    d->fail("the " + ctx.binding->name + " scene constants have no debugFlag");
                const int64_t flag = d->asInt();
                if (flag < INT32_MIN || flag > INT32_MAX) d->fail(flagKey + " does not fit in a 32-bit int");
                b.debugFlag = int32_t(flag);
            }
            if (flagKey != "debugFlag")
                if (const Value* d = r.optional("debugFlag"))
                    d->fail("the " + ctx.binding->name + " scene constants have no debugFlag; their debug switch "
                            "is '" + flagKey + "'");
            const auto takes = [&](const char* key) {
                const auto& keys = ctx.binding->constantsKeys;
                return std::find(keys.begin(), keys.end(), key) != keys.end();
            };
            if (takes("backgroundColor"))
                if (const Value* c = r.optional("backgroundColor"))
                    b.backgroundColor = floatVector<3>(*c, "backgroundColor");
            if (takes("maxBounces"))
                if (const Value* n = r.optional("maxBounces")) b.maxBounces = n->asUint32();
        } else if (kind == 1) {
            b.kind = BufferDesc::Kind::InstanceTransforms;
            for (const Value& v : r.required("instances").asArray())
                b.instances.push_back(resolveName(v, ctx.instanceNames, "instance"));
            if (b.instances.empty()) m.value.fail("an instanceTransforms buffer lists at least one instance");
        } else {
            b.kind = BufferDesc::Kind::PrimitiveTransforms;
            const Value& blasValue = r.required("blas");
            const BlasDesc& blas = ctx.scene.blases[resolveName(blasValue, ctx.blasNames, "bottom-level structure")];
            for (const Value& e : r.required("elements").asArray()) {
                ObjectReader er(e, "an element of buffer " + inQuotes(m.key));
                const Value& g = er.required("geometry");
                const uint32_t gi = g.asUint32();
                if (gi >= blas.geometries.size())
                    g.fail("BLAS " + inQuotes(blas.name) + " has " + std::to_string(blas.geometries.size()) +
                           " geometries; there is no geometry " + std::to_string(gi));
                const GeometryDescFile& geometry = blas.geometries[gi];
                if (geometry.type != dxr::GeometryType::ProceduralPrimitiveAABBs)
                    g.fail("geometry " + std::to_string(gi) + " of BLAS " + inQuotes(blas.name) + " holds triangles, not AABBs");
                dxr::RaytracingAABB box;
                std::memcpy(&box, ctx.scene.buffers[geometry.aabbBuffer].bytes.data(), sizeof box);
                PrimitiveTransformDesc p;
                p.centre = vec3(0.5f * (box.MinX + box.MaxX), 0.5f * (box.MinY + box.MaxY), 0.5f * (box.MinZ + box.MaxZ));
                if (const Value* s = er.optional("scale")) p.scale = floatVector<3>(*s, "scale");
                if (const Value* s = er.optional("spinYPerSecond")) p.spinYPerSecond = finiteNumber(*s, "spinYPerSecond");
                er.finish();
                b.primitives.push_back(p);
            }
            if (b.primitives.empty()) m.value.fail("a primitiveTransforms buffer lists at least one element");
        }
        r.finish();
        addBuffer(ctx, std::move(b), m.value);
    }
}

int32_t dataBuffer(const ParseContext& ctx, const Value& nameValue) {
    std::vector<std::string> names;
    for (const BufferDesc& b : ctx.scene.buffers) names.push_back(b.name);
    const uint32_t i = resolveName(nameValue, names, "buffer");
    if (!ctx.scene.buffers[i].isStatic())
        nameValue.fail("buffer " + inQuotes(nameValue.asString()) + " is generated each frame; geometry needs a data buffer");
    return int32_t(i);
}

int32_t dataOrGeneratedBuffer(const ParseContext& ctx, const Value& nameValue) {
    std::vector<std::string> names;
    for (const BufferDesc& b : ctx.scene.buffers) names.push_back(b.name);
    return int32_t(resolveName(nameValue, names, "buffer"));
}

// "bottomLevel": the bottom-level structures and their geometries: triangles (inline, from a buffer, an OBJ mesh or a
// model) and AABBs.

namespace {

// The scene's model buffer of `kind`, or an error at `where` saying to declare it.
uint32_t modelBuffer(const ParseContext& ctx, BufferDesc::Kind kind, const Value& where) {
    for (size_t i = 0; i < ctx.scene.buffers.size(); ++i)
        if (ctx.scene.buffers[i].kind == kind) return uint32_t(i);
    where.fail("a geometry from a model reads the models' vertex and index buffers; declare them in 'buffers': "
               "\"vertices\": {\"generate\": \"modelVertices\"}, \"indices\": {\"generate\": \"modelIndices\"}");
}

GeometryDescFile parseTriangles(ParseContext& ctx, ObjectReader& r, const std::string& prefix) {
    GeometryDescFile g;
    g.type = dxr::GeometryType::Triangles;
    if (const Value* model = r.optional("model")) {
        // The model's range of the global buffers, as a DXR path tracer's host builds one BLAS per model:
        // positions at byte 0 of each 48-byte VertexGPU, 32-bit indices local to the model.
        if (r.optional("mesh") || r.optional("vertices") || r.optional("indices"))
            model->fail("a triangle geometry takes 'model', 'mesh' or 'vertices' (and 'indices'), one of them");
        g.model = int32_t(resolveName(*model, ctx.modelNames, "model"));
        const ObjectGPU& range = ctx.scene.modelBuffers.modelRanges[size_t(g.model)];
        g.vertexBuffer = modelBuffer(ctx, BufferDesc::Kind::ModelVertices, *model);
        g.vertexOffset = uint64_t(range.vertexOffset) * sizeof(VertexGPU);
        g.vertexStride = uint32_t(sizeof(VertexGPU));
        g.vertexCount = range.vertexCount;
        g.vertexFormat = dxr::Format::R32G32B32_FLOAT;
        g.indexBuffer = int32_t(modelBuffer(ctx, BufferDesc::Kind::ModelIndices, *model));
        g.indexOffset = uint64_t(range.indexOffset) * sizeof(uint32_t);
        g.indexCount = range.indexCount;
        g.indexFormat = dxr::Format::R32_UINT;
        return g;
    }
    if (const Value* mesh = r.optional("mesh")) {
        // An OBJ file, relative to the scene file: its positions and triangulated faces become two buffers.
        if (r.optional("vertices") || r.optional("indices"))
            mesh->fail("a triangle geometry takes 'mesh' or 'vertices' (and 'indices'), not both");
        // Relative to the file that wrote the value (a lesson's base keeps its own directory).
        const std::filesystem::path path = std::filesystem::path(mesh->location().file).parent_path() / mesh->asString();
        TriangleMesh data;
        try {
            data = loadObjMesh(path);
        } catch (const Error& e) {
            mesh->fail(e.what());
        }
        BufferDesc positions;
        positions.name = prefix + "/mesh positions";
        positions.stride = 12;
        positions.bytes.resize(data.positions.size() * sizeof(vec3));
        std::memcpy(positions.bytes.data(), data.positions.data(), positions.bytes.size());
        g.vertexCount = uint32_t(data.positions.size());
        g.vertexBuffer = addBuffer(ctx, std::move(positions), *mesh);
        BufferDesc indices;
        indices.name = prefix + "/mesh indices";
        indices.bytes.resize(data.indices.size() * 4);
        std::memcpy(indices.bytes.data(), data.indices.data(), indices.bytes.size());
        g.indexCount = uint32_t(data.indices.size());
        g.indexFormat = dxr::Format::R32_UINT;
        g.indexBuffer = int32_t(addBuffer(ctx, std::move(indices), *mesh));
        return g;
    }
    const Value& vertices = r.required("vertices");
    if (vertices.isArray()) {
        BufferDesc b;
        b.name = prefix + "/vertices";
        b.stride = 12;
        for (const Value& v : vertices.asArray()) {
            const vec3 p = floatVector<3>(v, "a vertex position");
            b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&p), reinterpret_cast<const uint8_t*>(&p) + 12);
        }
        if (b.bytes.empty()) vertices.fail("a triangle geometry needs vertices");
        g.vertexCount = uint32_t(b.bytes.size() / 12);
        g.vertexBuffer = addBuffer(ctx, std::move(b), vertices);
    } else {
        ObjectReader vr(vertices, "vertices");
        g.vertexBuffer = uint32_t(dataBuffer(ctx, vr.required("buffer")));
        const BufferDesc& b = ctx.scene.buffers[g.vertexBuffer];
        g.vertexStride = vr.required("stride").asUint32();
        if (const Value* o = vr.optional("offset")) g.vertexOffset = o->asUint32();
        if (const Value* f = vr.optional("format")) {
            const uint32_t fi = resolveName(*f, {"R32G32B32_FLOAT", "R32G32_FLOAT"}, "vertex format");
            g.vertexFormat = fi == 0 ? dxr::Format::R32G32B32_FLOAT : dxr::Format::R32G32_FLOAT;
        }
        if (g.vertexStride == 0) vertices.fail("the vertex stride must not be 0");
        const uint64_t available = b.bytes.size() > g.vertexOffset ? (b.bytes.size() - g.vertexOffset) / g.vertexStride : 0;
        g.vertexCount = uint32_t(available);
        if (const Value* c = vr.optional("count")) {
            g.vertexCount = c->asUint32();
            if (g.vertexCount > available)
                c->fail(std::to_string(g.vertexCount) + " vertices of stride " + std::to_string(g.vertexStride) +
                        " do not fit in buffer " + inQuotes(b.name) + " (" + std::to_string(b.bytes.size()) + " bytes)");
        }
        vr.finish();
    }
    if (const Value* indices = r.optional("indices")) {
        if (indices->isArray()) {
            BufferDesc b;
            b.name = prefix + "/indices";
            for (const Value& v : indices->asArray()) {
                const uint32_t i = v.asUint32();
                b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&i), reinterpret_cast<const uint8_t*>(&i) + 4);
            }
            g.indexCount = uint32_t(indices->asArray().size());
            g.indexFormat = dxr::Format::R32_UINT;
            g.indexBuffer = int32_t(addBuffer(ctx, std::move(b), *indices));
        } else {
            ObjectReader ir(*indices, "indices");
            g.indexBuffer = dataBuffer(ctx, ir.required("buffer"));
            const uint32_t fi = resolveName(ir.required("format"), {"R16_UINT", "R32_UINT"}, "index format");
            g.indexFormat = fi == 0 ? dxr::Format::R16_UINT : dxr::Format::R32_UINT;
            if (const Value* o = ir.optional("offset")) g.indexOffset = o->asUint32();
            const uint64_t size = fi == 0 ? 2 : 4;
            const BufferDesc& b = ctx.scene.buffers[size_t(g.indexBuffer)];
            const uint64_t available = b.bytes.size() > g.indexOffset ? (b.bytes.size() - g.indexOffset) / size : 0;
            g.indexCount = uint32_t(available);
            if (const Value* c = ir.optional("count")) {
                g.indexCount = c->asUint32();
                if (g.indexCount > available)
                    c->fail(std::to_string(g.indexCount) + " indices do not fit in buffer " + inQuotes(b.name));
            }
            ir.finish();
        }
        if (g.indexCount == 0 || g.indexCount % 3 != 0)
            indices->fail("a triangle list needs a positive multiple of 3 indices, got " + std::to_string(g.indexCount));
    } else if (g.vertexCount % 3 != 0) {
        vertices.fail("without indices, a triangle list needs a multiple of 3 vertices, got " +
                      std::to_string(g.vertexCount));
    }
    return g;
}

}  // namespace

void parseBottomLevel(ParseContext& ctx, const Value& value) {
    static const std::vector<std::pair<std::string, uint32_t>> buildFlags = {
        {"PREFER_FAST_TRACE", dxr::BUILD_FLAG_PREFER_FAST_TRACE},
        {"PREFER_FAST_BUILD", dxr::BUILD_FLAG_PREFER_FAST_BUILD},
        {"ALLOW_UPDATE", dxr::BUILD_FLAG_ALLOW_UPDATE},
        {"ALLOW_COMPACTION", dxr::BUILD_FLAG_ALLOW_COMPACTION},
        {"MINIMIZE_MEMORY", dxr::BUILD_FLAG_MINIMIZE_MEMORY}};
    static const std::vector<std::pair<std::string, uint32_t>> geometryFlags = {
        {"OPAQUE", dxr::GEOMETRY_FLAG_OPAQUE},
        {"NO_DUPLICATE_ANYHIT_INVOCATION", dxr::GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION}};
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a bottom-level structure");
        BlasDesc blas;
        blas.name = nonEmptyName(r.required("name"), "a BLAS name");
        r.setWhat("bottom-level structure " + inQuotes(blas.name));
        if (std::find(ctx.blasNames.begin(), ctx.blasNames.end(), blas.name) != ctx.blasNames.end())
            v.fail("two bottom-level structures are named " + inQuotes(blas.name));
        blas.where = v.location();
        if (const Value* f = r.optional("flags")) blas.buildFlags = flagSet(*f, buildFlags, "build flag");
        const Value& geometries = r.required("geometries");
        for (const Value& gv : geometries.asArray()) {
            const std::string prefix = blas.name + "/" + std::to_string(blas.geometries.size());
            ObjectReader gr(gv, "geometry " + std::to_string(blas.geometries.size()) + " of BLAS " + inQuotes(blas.name));
            const uint32_t type = resolveName(gr.required("type"), {"triangles", "aabbs"}, "geometry type");
            GeometryDescFile g;
            if (type == 0) {
                g = parseTriangles(ctx, gr, prefix);
            } else {
                g.type = dxr::GeometryType::ProceduralPrimitiveAABBs;
                const Value& boxes = gr.required("aabbs");
                BufferDesc b;
                b.name = prefix + "/aabbs";
                b.stride = sizeof(dxr::RaytracingAABB);
                for (const Value& bv : boxes.asArray()) {
                    const auto& a = bv.asArray();
                    if (a.size() != 6) bv.fail("an AABB is [minX, minY, minZ, maxX, maxY, maxZ]");
                    for (const Value& n : a) {
                        const float f = n.asFloat();
                        b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&f),
                                       reinterpret_cast<const uint8_t*>(&f) + 4);
                    }
                }
                g.aabbCount = uint32_t(boxes.asArray().size());
                if (g.aabbCount == 0) boxes.fail("an AABB geometry needs at least one box");
                g.aabbBuffer = addBuffer(ctx, std::move(b), boxes);
            }
            if (const Value* f = gr.optional("flags")) g.flags = flagSet(*f, geometryFlags, "geometry flag");
            gr.finish();
            blas.geometries.push_back(g);
        }
        if (blas.geometries.empty()) geometries.fail("BLAS " + inQuotes(blas.name) + " has no geometries");
        r.finish();
        ctx.blasNames.push_back(blas.name);
        ctx.scene.blases.push_back(std::move(blas));
    }
}

// "instances": the top-level instances, their transforms, IDs, masks and flags.

namespace {

Matrix3x4 parseTransform(const Value& value) {
    ObjectReader r(value, "a transform");
    Matrix3x4 m = Matrix3x4::identity();
    if (const Value* rows = r.optional("rowVectorMatrix")) {
        // DirectXMath layout: p' = p·M, translation in row 3; DXR stores the transpose of the 3x4 part.
        const auto& a = rows->asArray();
        if (a.size() != 4) rows->fail("rowVectorMatrix has 4 rows of 4 numbers");
        for (int i = 0; i < 4; ++i) {
            const vec4 row = floatVector<4>(a[size_t(i)], "a matrix row");
            for (int j = 0; j < 3; ++j) m.m[size_t(j)][size_t(i)] = row[j];
            if (row.w != (i == 3 ? 1.0f : 0.0f))
                a[size_t(i)].fail("the last column of an affine rowVectorMatrix is (0, 0, 0, 1)");
        }
    } else if (const Value* rows3 = r.optional("matrix3x4")) {
        const auto& a = rows3->asArray();
        if (a.size() != 3) rows3->fail("matrix3x4 (the DXR Transform) has 3 rows of 4 numbers");
        for (int i = 0; i < 3; ++i) {
            const vec4 row = floatVector<4>(a[size_t(i)], "a matrix row");
            for (int j = 0; j < 4; ++j) m.m[size_t(i)][size_t(j)] = row[j];
        }
    } else {
        // M = S · R · T in row-vector terms: scale, then rotate, then translate.
        Matrix3x4 s = Matrix3x4::identity(), rot = Matrix3x4::identity(), t = Matrix3x4::identity();
        if (const Value* v = r.optional("scale")) s = Matrix3x4::scale(floatVector<3>(*v, "scale"));
        if (const Value* v = r.optional("rotate")) {
            ObjectReader rr(*v, "rotate");
            const uint32_t axis = resolveName(rr.required("axis"), {"x", "y", "z"}, "rotation axis");
            const float radians = float(finiteNumber(rr.required("radians"), "radians"));
            vec3 a(0.0f);
            a[int(axis)] = 1.0f;
            rot = Matrix3x4::rotation(a, radians);
            rr.finish();
        }
        if (const Value* v = r.optional("translate")) t = Matrix3x4::translation(floatVector<3>(*v, "translate"));
        m = t * rot * s;
    }
    r.finish();
    if (!m.allFinite()) value.fail("the transform is not finite");
    return m;
}

}  // namespace

void parseInstances(ParseContext& ctx, const Value& value) {
    static const std::vector<std::pair<std::string, uint32_t>> instanceFlags = {
        {"TRIANGLE_CULL_DISABLE", dxr::INSTANCE_FLAG_TRIANGLE_CULL_DISABLE},
        {"TRIANGLE_FRONT_COUNTERCLOCKWISE", dxr::INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE},
        {"FORCE_OPAQUE", dxr::INSTANCE_FLAG_FORCE_OPAQUE},
        {"FORCE_NON_OPAQUE", dxr::INSTANCE_FLAG_FORCE_NON_OPAQUE}};
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "an instance");
        InstanceDescFile inst;
        inst.name = nonEmptyName(r.required("name"), "an instance name");
        r.setWhat("instance " + inQuotes(inst.name));
        if (std::find(ctx.instanceNames.begin(), ctx.instanceNames.end(), inst.name) != ctx.instanceNames.end())
            v.fail("two instances are named " + inQuotes(inst.name));
        inst.where = v.location();
        inst.blas = resolveName(r.required("blas"), ctx.blasNames, "bottom-level structure");
        if (const Value* t = r.optional("transform")) inst.transform = parseTransform(*t);
        // With models, InstanceID is the object index (= the instance index) that the shaders look objects
        // up by, as a path tracer's host writes it.
        if (!ctx.scene.models.empty()) inst.instanceID = uint32_t(ctx.scene.instances.size());
        if (const Value* id = r.optional("instanceID")) {
            inst.instanceID = id->asUint32();
            if (inst.instanceID > 0xFFFFFF) id->fail("InstanceID has 24 bits (INST-1), got " + std::to_string(inst.instanceID));
        }
        if (const Value* mask = r.optional("mask")) {
            inst.mask = mask->asUint32();
            if (inst.mask > 0xFF) mask->fail("InstanceMask has 8 bits (INST-1), got " + std::to_string(inst.mask));
        }
        if (const Value* f = r.optional("flags")) inst.flags = flagSet(*f, instanceFlags, "instance flag");
        if (ctx.scene.layout == LayoutMode::Explicit) {
            const Value& c = r.required("contribution");
            inst.contribution = c.asUint32();
            if (inst.contribution > 0xFFFFFF)
                c.fail("InstanceContributionToHitGroupIndex has 24 bits (INST-1), got " + std::to_string(inst.contribution));
            if (r.optional("records"))
                v.fail("instance 'records' belong to \"layout\": \"auto\"; explicit scenes list records in 'shaderTable'");
        } else {
            if (const Value* c = r.optional("contribution"))
                c->fail("in auto layout the instance contribution is computed; use \"layout\": \"explicit\" to set it");
            ctx.recordValues.push_back(&r.required("records"));
        }
        r.finish();
        ctx.instanceNames.push_back(inst.name);
        ctx.scene.instances.push_back(std::move(inst));
    }
    if (ctx.scene.instances.empty()) value.fail("a scene needs at least one instance");
}

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
