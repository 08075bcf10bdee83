// Models from Wavefront OBJ + MTL files (tinyobjloader): indexed triangles with normals, texcoords and tangents,
// one material per triangle, for the global model buffers of a DXR path tracer (scenes/model_buffers.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/math.h"

namespace refray::scenes {

// One corner of the model: a unique (v, vn, vt) triple of the OBJ file.
struct ModelVertex {
    vec3 position{0.0f};
    vec3 normal{0.0f};    // unit length: the file's vn, or the triangle's geometric normal where the corner has none
    vec2 texcoord{0.0f};  // D3D convention (origin top-left, v down the image): (vt.u, 1 - vt.v); (0, 0) without vt
    // xyz: unit, orthogonal to `normal`, along +u; w: handedness, so that the direction of +v (down the image) is
    // w * cross(normal, xyz). All zero when no material of the model has a normal map (Model::hasTangents).
    vec4 tangent{0.0f};

    bool operator==(const ModelVertex&) const = default;
};

// What a shader does with a material. Decided from the MTL colours: Ke != 0 is Emissive, else Ks != 0 is Glossy,
// else Diffuse.
enum class MaterialType : uint32_t { Diffuse = 0, Glossy = 1, Emissive = 2 };

const char* toString(MaterialType type);

struct ModelMaterial {
    std::string name;                         // newmtl; "(default)" for faces that follow no usemtl
    std::filesystem::path library;            // the MTL file it came from; empty for the default material
    vec3 albedo{0.8f};                        // Kd (the default material: 0.8 grey)
    vec3 specular{0.0f};                      // Ks
    float shininess = 0.0f;                   // Ns, the Phong exponent as the file gives it
    float roughness = 1.0f;                   // roughnessFromShininess(Ns)
    vec3 emission{0.0f};                      // Ke
    std::filesystem::path diffuseTexture;     // map_Kd, resolved against the MTL file's folder; empty for none
    std::filesystem::path normalTexture;      // norm, else map_Bump / map_bump / bump (read as a normal map)
    MaterialType type = MaterialType::Diffuse;
};

struct Model {
    std::string name;                             // the OBJ object's name (loadObjModels), else the file's stem
    std::filesystem::path path;                   // the OBJ file
    std::vector<ModelVertex> vertices;            // in order of first use by the triangles
    std::vector<uint32_t> indices;                // a triangle list into `vertices`, the file's winding
    std::vector<uint32_t> triangleMaterials;      // per triangle, into `materials`
    std::vector<ModelMaterial> materials;         // those the triangles use, in MTL order; "(default)" last
    bool hasTangents = false;                     // a material has a normal map, so ModelVertex::tangent is set

    size_t triangleCount() const { return indices.size() / 3; }
};

// The whole OBJ file as one model. Polygons are triangulated by tinyobjloader. Vertices are the unique (v, vn, vt)
// triples in order of first use; a corner without vn takes its triangle's geometric normal (flat shading) and is
// shared with no other triangle. Throws refray::Error naming the file and, where there is one, the line, when:
// the OBJ, an mtllib file or a texture file cannot be read; a face refers to a vertex, normal or texcoord that does
// not exist (or to index 0); usemtl names a material that no earlier mtllib defines; a value is not finite; a normal
// has zero length; the file holds no triangle.
Model loadObjModel(const std::filesystem::path& path);

// One model per OBJ object, in file order: faces are grouped by the name tinyobjloader gives their shape (the last
// `o` or `g` statement before them; faces before any get the file's stem). Each model has its own vertices and
// materials. Errors as loadObjModel.
std::vector<Model> loadObjModels(const std::filesystem::path& path);

// The MTL's Phong exponent Ns as a microfacet roughness: the Beckmann alpha whose distribution matches a
// Blinn-Phong lobe of exponent Ns, alpha = sqrt(2 / (Ns + 2)) (Walter et al. 2007, "Microfacet Models for
// Refraction through Rough Surfaces", section 5.2). Ns = 0 gives 1 (rough), Ns = 1000 about 0.045. Negative Ns
// counts as 0.
float roughnessFromShininess(float shininess);

}  // namespace refray::scenes
