// The global model buffers of a DXR path tracer: every model's vertices, indices and materials concatenated into one
// buffer each, the texture lists, and one ObjectGPU per TLAS instance holding its model's offsets into them.
//
// How a closest-hit shader finds its data (object = InstanceID(), which must be the object's index):
//   ObjectGPU o       = objects[InstanceID()];
//   uint3 corner      = indices[o.indexOffset + 3 * PrimitiveIndex() + {0, 1, 2}];   // local to the model
//   VertexGPU v       = vertices[o.vertexOffset + corner.k];
//   MaterialGPU m     = materials[triangleMaterials[o.triangleOffset + PrimitiveIndex()]];
//   Texture2D albedo  = diffuseTextures[m.diffuseTextureIndex];    // when >= 0
//   Texture2D normals = normalTextures[m.normalTextureIndex];      // when >= 0
// Each model is stored once, however many objects use it; a model's BLAS reads its range of `vertices` (position at
// byte 0 of each 48-byte VertexGPU, DXGI_FORMAT_R32G32B32_FLOAT) and of `indices` (R32_UINT, local indices).
//
// The GPU structs below are what the HLSL side reads from StructuredBuffers: every field is 4 bytes, vectors are
// float4-aligned, and the sizes and offsets are fixed by static_asserts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "core/math.h"
#include "scenes/model.h"

namespace refray::scenes {

// HLSL: struct Vertex { float3 position; float u; float3 normal; float v; float4 tangent; };   48 bytes
// The texcoord is split over the two pads so that the position stays at byte 0 for the BLAS build.
struct alignas(16) VertexGPU {
    vec3 position;   //  0
    float u;         // 12: ModelVertex::texcoord.x (D3D convention: origin top-left)
    vec3 normal;     // 16: unit
    float v;         // 28: ModelVertex::texcoord.y
    vec4 tangent;    // 32: xyz unit along +u, w = handedness (+v = w * cross(normal, tangent)); 0 when none
};
static_assert(sizeof(VertexGPU) == 48 && std::is_standard_layout_v<VertexGPU> &&
              std::is_trivially_copyable_v<VertexGPU>);
static_assert(offsetof(VertexGPU, position) == 0 && offsetof(VertexGPU, u) == 12 && offsetof(VertexGPU, normal) == 16 &&
              offsetof(VertexGPU, v) == 28 && offsetof(VertexGPU, tangent) == 32);

// HLSL: struct Material { float4 albedo; float4 emission; float4 specularRoughness; int diffuseTextureIndex;
//                         int normalTextureIndex; uint type; float shininess; };                      64 bytes
struct alignas(16) MaterialGPU {
    vec4 albedo;                   //  0: Kd, w = 0
    vec4 emission;                 // 16: Ke, w = 0
    vec4 specularRoughness;        // 32: Ks, w = roughness (roughnessFromShininess(Ns))
    int32_t diffuseTextureIndex;   // 48: into GlobalModelBuffers::diffuseTextures, -1 for none
    int32_t normalTextureIndex;    // 52: into GlobalModelBuffers::normalTextures, -1 for none
    uint32_t type;                 // 56: MaterialType (0 diffuse, 1 glossy, 2 emissive)
    float shininess;               // 60: Ns as the MTL gives it
};
static_assert(sizeof(MaterialGPU) == 64 && std::is_standard_layout_v<MaterialGPU> &&
              std::is_trivially_copyable_v<MaterialGPU>);
static_assert(offsetof(MaterialGPU, albedo) == 0 && offsetof(MaterialGPU, emission) == 16 &&
              offsetof(MaterialGPU, specularRoughness) == 32 && offsetof(MaterialGPU, diffuseTextureIndex) == 48 &&
              offsetof(MaterialGPU, normalTextureIndex) == 52 && offsetof(MaterialGPU, type) == 56 &&
              offsetof(MaterialGPU, shininess) == 60);

// HLSL: struct Object { uint vertexOffset; uint indexOffset; uint materialOffset; uint triangleOffset;
//                       uint vertexCount; uint indexCount; uint materialCount; uint modelIndex; };    32 bytes
// One per object (TLAS instance), indexed by InstanceID(); all offsets are element counts, not bytes.
struct alignas(16) ObjectGPU {
    uint32_t vertexOffset;    //  0: the model's first vertex in `vertices`
    uint32_t indexOffset;     //  4: the model's first index in `indices`
    uint32_t materialOffset;  //  8: the model's first material in `materials`
    uint32_t triangleOffset;  // 12: the model's first entry in `triangleMaterials` (indexOffset / 3)
    uint32_t vertexCount;     // 16
    uint32_t indexCount;      // 20
    uint32_t materialCount;   // 24
    uint32_t modelIndex;      // 28: which model (BLAS) the object instances
};
static_assert(sizeof(ObjectGPU) == 32 && std::is_standard_layout_v<ObjectGPU> &&
              std::is_trivially_copyable_v<ObjectGPU>);
static_assert(offsetof(ObjectGPU, vertexOffset) == 0 && offsetof(ObjectGPU, indexOffset) == 4 &&
              offsetof(ObjectGPU, materialOffset) == 8 && offsetof(ObjectGPU, triangleOffset) == 12 &&
              offsetof(ObjectGPU, vertexCount) == 16 && offsetof(ObjectGPU, indexCount) == 20 &&
              offsetof(ObjectGPU, materialCount) == 24 && offsetof(ObjectGPU, modelIndex) == 28);

// One object of the scene: a TLAS instance of a model. Its index in the list is its InstanceID.
struct ModelObjectDesc {
    std::string name;
    uint32_t model = 0;                             // index into the models given to buildGlobalModelBuffers
    Matrix3x4 transform = Matrix3x4::identity();    // object to world, the instance's Transform
};

struct GlobalModelBuffers {
    std::vector<VertexGPU> vertices;            // every model's vertices, models in order
    std::vector<uint32_t> indices;              // every model's indices, local to the model
    std::vector<uint32_t> triangleMaterials;    // per triangle of every model: global index into `materials`
    std::vector<MaterialGPU> materials;         // every model's materials, models in order
    std::vector<ObjectGPU> objects;             // per object, in TLAS instance order
    std::vector<ModelObjectDesc> objectDescs;   // the objects as given (model and transform for the TLAS)
    std::vector<ObjectGPU> modelRanges;         // per model, its ranges (modelIndex = itself): the BLAS inputs
    // Texture paths in order of first use (models, then materials, in order), each once. They are the two
    // descriptor ranges Texture2D diffuseTextures[] and Texture2D normalTextures[].
    std::vector<std::filesystem::path> diffuseTextures;
    std::vector<std::filesystem::path> normalTextures;
};

// Concatenates `models` and lays out one ObjectGPU per object. Throws refray::Error naming the object when it
// refers to a model that does not exist or its transform is not finite, when a model is empty or has a triangle
// whose material or vertex index is out of range, and when a buffer would need more than 2^32 elements.
GlobalModelBuffers buildGlobalModelBuffers(std::span<const Model> models, std::span<const ModelObjectDesc> objects);

MaterialGPU toMaterialGPU(const ModelMaterial& material, int32_t diffuseTextureIndex, int32_t normalTextureIndex);
VertexGPU toVertexGPU(const ModelVertex& vertex);

}  // namespace refray::scenes
