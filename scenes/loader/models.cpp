// "models" (OBJ files read into Model) and the buffers a scene generates from them: {"generate": "modelVertices"}
// and the other model buffer kinds.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>

#include "core/error.h"
#include "core/strings.h"
#include "scenes/loader/parse_context.h"
#include "scenes/path_tracer_scene.h"

namespace refray::scenes::loader {

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

}  // namespace refray::scenes::loader
