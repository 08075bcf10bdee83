#include "scenes/model_buffers.h"

#include <algorithm>
#include <limits>

#include "core/error.h"

namespace refray::scenes {

namespace {

constexpr size_t kMaxElements = std::numeric_limits<uint32_t>::max();

// The index of `path` in `list`, appending it on first use; -1 for an empty path.
int32_t textureIndex(std::vector<std::filesystem::path>& list, const std::filesystem::path& path) {
    if (path.empty()) return -1;
    const std::filesystem::path key = path.lexically_normal();
    const auto it = std::find(list.begin(), list.end(), key);
    if (it != list.end()) return int32_t(it - list.begin());
    list.push_back(key);
    return int32_t(list.size() - 1);
}

}  // namespace

VertexGPU toVertexGPU(const ModelVertex& vertex) {
    return VertexGPU{vertex.position, vertex.texcoord.x, vertex.normal, vertex.texcoord.y, vertex.tangent};
}

MaterialGPU toMaterialGPU(const ModelMaterial& material, int32_t diffuseTextureIndex, int32_t normalTextureIndex) {
    return MaterialGPU{vec4(material.albedo, 0.0f),
                       vec4(material.emission, 0.0f),
                       vec4(material.specular, material.roughness),
                       diffuseTextureIndex,
                       normalTextureIndex,
                       uint32_t(material.type),
                       material.shininess};
}

GlobalModelBuffers buildGlobalModelBuffers(std::span<const Model> models, std::span<const ModelObjectDesc> objects) {
    GlobalModelBuffers out;

    // Models, each once, in order.
    for (size_t m = 0; m < models.size(); ++m) {
        const Model& model = models[m];
        const std::string name = "model " + std::to_string(m) + " ('" + model.name + "')";
        REFRAY_CHECK(!model.indices.empty() && model.indices.size() % 3 == 0 &&
                         model.triangleMaterials.size() == model.indices.size() / 3,
                     name << " has " << model.indices.size() << " indices and " << model.triangleMaterials.size()
                          << " triangle materials; it needs 3 indices and one material per triangle");
        REFRAY_CHECK(out.vertices.size() + model.vertices.size() <= kMaxElements &&
                         out.indices.size() + model.indices.size() <= kMaxElements &&
                         out.materials.size() + model.materials.size() <= kMaxElements,
                     name << " does not fit: the global buffers hold at most 2^32 - 1 elements each");
        ObjectGPU range{};
        range.vertexOffset = uint32_t(out.vertices.size());
        range.indexOffset = uint32_t(out.indices.size());
        range.materialOffset = uint32_t(out.materials.size());
        range.triangleOffset = uint32_t(out.triangleMaterials.size());
        range.vertexCount = uint32_t(model.vertices.size());
        range.indexCount = uint32_t(model.indices.size());
        range.materialCount = uint32_t(model.materials.size());
        range.modelIndex = uint32_t(m);

        for (const ModelVertex& v : model.vertices) out.vertices.push_back(toVertexGPU(v));
        for (size_t i = 0; i < model.indices.size(); ++i) {
            REFRAY_CHECK(model.indices[i] < model.vertices.size(),
                         name << ": index " << i << " is " << model.indices[i] << ", but the model has "
                              << model.vertices.size() << " vertices");
            out.indices.push_back(model.indices[i]);
        }
        for (size_t t = 0; t < model.triangleMaterials.size(); ++t) {
            REFRAY_CHECK(model.triangleMaterials[t] < model.materials.size(),
                         name << ": triangle " << t << " uses material " << model.triangleMaterials[t]
                              << ", but the model has " << model.materials.size() << " materials");
            out.triangleMaterials.push_back(range.materialOffset + model.triangleMaterials[t]);
        }
        for (const ModelMaterial& material : model.materials)
            out.materials.push_back(toMaterialGPU(material, textureIndex(out.diffuseTextures, material.diffuseTexture),
                                                  textureIndex(out.normalTextures, material.normalTexture)));
        out.modelRanges.push_back(range);
    }

    // Objects: InstanceID = position in the list.
    REFRAY_CHECK(objects.size() <= (1u << 24), "there are " << objects.size()
                                                << " objects; InstanceID has 24 bits, so at most 2^24 fit");
    for (size_t o = 0; o < objects.size(); ++o) {
        const ModelObjectDesc& object = objects[o];
        REFRAY_CHECK(object.model < models.size(), "object " << o << " ('" << object.name << "') refers to model "
                                                             << object.model << ", but there are " << models.size()
                                                             << " models");
        REFRAY_CHECK(object.transform.allFinite(),
                     "object " << o << " ('" << object.name << "') has a transform that is not finite");
        out.objects.push_back(out.modelRanges[object.model]);
        out.objectDescs.push_back(object);
    }
    return out;
}

}  // namespace refray::scenes
