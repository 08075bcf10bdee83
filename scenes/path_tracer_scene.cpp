#include "scenes/path_tracer_scene.h"

#include <cmath>
#include <cstddef>

#include "core/error.h"
#include "emulator/texture.h"
#include "procedural/pathtracer/pt_math.h"
#include "scenes/camera_models.h"

namespace refray::scenes {

using namespace refray::dxr;
namespace pt = refray::procedural::pathtracer;

// The shaders declare the structured-buffer elements themselves (as HLSL would); they must match the host's bytes.
static_assert(sizeof(pt::VertexGPU) == sizeof(VertexGPU) &&
              offsetof(pt::VertexGPU, position) == offsetof(VertexGPU, position) &&
              offsetof(pt::VertexGPU, u) == offsetof(VertexGPU, u) &&
              offsetof(pt::VertexGPU, normal) == offsetof(VertexGPU, normal) &&
              offsetof(pt::VertexGPU, v) == offsetof(VertexGPU, v) &&
              offsetof(pt::VertexGPU, tangent) == offsetof(VertexGPU, tangent));
static_assert(sizeof(pt::MaterialGPU) == sizeof(MaterialGPU) &&
              offsetof(pt::MaterialGPU, albedo) == offsetof(MaterialGPU, albedo) &&
              offsetof(pt::MaterialGPU, emission) == offsetof(MaterialGPU, emission) &&
              offsetof(pt::MaterialGPU, specularRoughness) == offsetof(MaterialGPU, specularRoughness) &&
              offsetof(pt::MaterialGPU, diffuseTextureIndex) == offsetof(MaterialGPU, diffuseTextureIndex) &&
              offsetof(pt::MaterialGPU, normalTextureIndex) == offsetof(MaterialGPU, normalTextureIndex) &&
              offsetof(pt::MaterialGPU, type) == offsetof(MaterialGPU, type) &&
              offsetof(pt::MaterialGPU, shininess) == offsetof(MaterialGPU, shininess));
static_assert(sizeof(pt::ObjectGPU) == sizeof(ObjectGPU) &&
              offsetof(pt::ObjectGPU, vertexOffset) == offsetof(ObjectGPU, vertexOffset) &&
              offsetof(pt::ObjectGPU, indexOffset) == offsetof(ObjectGPU, indexOffset) &&
              offsetof(pt::ObjectGPU, materialOffset) == offsetof(ObjectGPU, materialOffset) &&
              offsetof(pt::ObjectGPU, triangleOffset) == offsetof(ObjectGPU, triangleOffset) &&
              offsetof(pt::ObjectGPU, modelIndex) == offsetof(ObjectGPU, modelIndex));

struct PathTracerScene::State {
    PathTracerSceneDesc desc;
    GlobalModelBuffers buffers;
    std::vector<pt::LightTriangleGPU> lights;
    std::unique_ptr<Device> device = std::make_unique<Device>();
    RootSignaturePtr globalSignature;
    StateObjectPtr pipeline;
    DispatchRaysDesc tables;
    GpuVirtualAddress tlas = 0;
    DescriptorHeap* heap = nullptr;
    uint32_t diffuseTableStart = 0, normalTableStart = 0;
};

namespace {

// Uploads `values` (at least one element's worth of bytes, so an empty list still has an address) and describes it
// as a structured-buffer SRV of stride sizeof(T). An empty list gets a null descriptor.
template <class T>
BufferView structuredView(GpuMemory& memory, const std::vector<T>& values, const std::string& name) {
    if (values.empty()) return BufferView{};
    return BufferView{memory.upload(values, name), values.size() * sizeof(T), uint32_t(sizeof(T))};
}

// Writes one Texture2D SRV per path from `start` on, or one null descriptor for an empty list.
void writeTextures(DescriptorHeap& heap, uint32_t start, const std::vector<std::filesystem::path>& paths) {
    if (paths.empty()) {
        heap.setTexture2D(start, Texture2DPtr{});
        return;
    }
    for (size_t i = 0; i < paths.size(); ++i)
        heap.setTexture2D(start + uint32_t(i), Texture2D::fromFile(paths[i].string()));
}

}  // namespace

std::vector<pt::LightTriangleGPU> buildLightTriangles(const GlobalModelBuffers& buffers) {
    std::vector<pt::LightTriangleGPU> lights;
    for (size_t o = 0; o < buffers.objects.size(); ++o) {
        const ObjectGPU& object = buffers.objects[o];
        const Matrix3x4& transform = buffers.objectDescs[o].transform;
        for (uint32_t t = 0; t < object.indexCount / 3; ++t) {
            const MaterialGPU& material = buffers.materials[buffers.triangleMaterials[object.triangleOffset + t]];
            if (vec3(material.emission) == vec3(0.0f)) continue;
            vec3 p[3];
            for (uint32_t k = 0; k < 3; ++k)
                p[k] = transform.transformPoint(
                    buffers.vertices[object.vertexOffset + buffers.indices[object.indexOffset + 3 * t + k]].position);
            // The closest hit computes a hit emitter's area the same way, from the same world-space vertices.
            const float area = 0.5f * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
            if (!(area > 0.0f)) continue;
            lights.push_back(pt::LightTriangleGPU{vec4(p[0], 0.0f), vec4(p[1], 0.0f), vec4(p[2], 0.0f),
                                                  vec4(vec3(material.emission), area)});
        }
    }
    return lights;
}

PathTracerScene::PathTracerScene(PathTracerSceneDesc desc) : state_(std::make_unique<State>()) {
    State& s = *state_;
    s.desc = std::move(desc);
    REFRAY_CHECK(!s.desc.objects.empty(), "path tracer scene '" << s.desc.name << "' has no objects");
    s.buffers = buildGlobalModelBuffers(s.desc.models, s.desc.objects);
    s.lights = buildLightTriangles(s.buffers);
    Device& device = *s.device;
    GpuMemory& memory = device.memory();

    // The global buffers.
    const BufferView vertices = structuredView(memory, s.buffers.vertices, "g_vertices");
    const BufferView indices = structuredView(memory, s.buffers.indices, "g_indices");
    const BufferView materials = structuredView(memory, s.buffers.materials, "g_materials");
    const BufferView triangleMaterials = structuredView(memory, s.buffers.triangleMaterials, "g_triangleMaterials");
    const BufferView objects = structuredView(memory, s.buffers.objects, "g_objects");
    const BufferView lights = structuredView(memory, s.lights, "g_lights");

    // One BLAS per model over its range of the global vertex and index buffers.
    std::vector<GpuVirtualAddress> blas;
    for (const ObjectGPU& range : s.buffers.modelRanges) {
        GeometryDesc geometry;
        geometry.Type = GeometryType::Triangles;
        geometry.Flags = GEOMETRY_FLAG_OPAQUE;
        geometry.Triangles.IndexFormat = Format::R32_UINT;
        geometry.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
        geometry.Triangles.IndexCount = range.indexCount;
        geometry.Triangles.VertexCount = range.vertexCount;
        geometry.Triangles.IndexBuffer = indices.address + uint64_t(range.indexOffset) * sizeof(uint32_t);
        geometry.Triangles.VertexBuffer = {vertices.address + uint64_t(range.vertexOffset) * sizeof(VertexGPU),
                                           sizeof(VertexGPU)};
        blas.push_back(device.buildBottomLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, {geometry}}));
    }

    // One instance per object: InstanceID = the object's index, every instance on hit-group records 0 and 1.
    std::vector<InstanceDesc> instances;
    for (size_t o = 0; o < s.buffers.objectDescs.size(); ++o) {
        const ModelObjectDesc& object = s.buffers.objectDescs[o];
        instances.push_back(
            makeInstanceDesc(object.transform, uint32_t(o), 0xFF, 0, INSTANCE_FLAG_NONE, blas[object.model]));
    }
    s.tlas = device.buildTopLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, uint32_t(instances.size()), ElementsLayout::Array,
                                     memory.upload(instances, "instance descs")});

    // The descriptor heap: output, buffers, diffuse textures, normal textures.
    const auto tableSize = [](size_t n) { return uint32_t(std::max<size_t>(n, 1)); };
    s.diffuseTableStart = 1 + pt::kSceneBufferDescriptorCount;
    s.normalTableStart = s.diffuseTableStart + tableSize(s.buffers.diffuseTextures.size());
    s.heap = &device.createDescriptorHeap(s.normalTableStart + tableSize(s.buffers.normalTextures.size()),
                                          "path tracer heap");
    const uint32_t buffersStart = 1;
    s.heap->setBuffer(buffersStart + pt::kVerticesDescriptor, DescriptorRangeType::SRV, vertices);
    s.heap->setBuffer(buffersStart + pt::kIndicesDescriptor, DescriptorRangeType::SRV, indices);
    s.heap->setBuffer(buffersStart + pt::kMaterialsDescriptor, DescriptorRangeType::SRV, materials);
    s.heap->setBuffer(buffersStart + pt::kTriangleMaterialsDescriptor, DescriptorRangeType::SRV, triangleMaterials);
    s.heap->setBuffer(buffersStart + pt::kObjectsDescriptor, DescriptorRangeType::SRV, objects);
    s.heap->setBuffer(buffersStart + pt::kLightsDescriptor, DescriptorRangeType::SRV, lights);
    writeTextures(*s.heap, s.diffuseTableStart, s.buffers.diffuseTextures);
    writeTextures(*s.heap, s.normalTableStart, s.buffers.normalTextures);

    // The pipeline: one library, two hit groups, the global root signature, no local ones.
    s.globalSignature = RootSignature::create(pt::globalRootSignatureDesc());
    StateObjectDesc so;
    so.name = "path tracer";
    so.libraries = {{pt::makePathTracerShaderLibrary(), {}}};
    so.hitGroups = pt::pathTracerHitGroups();
    so.globalRootSignatures = {{s.globalSignature, {}}};
    so.shaderConfigs = {pt::pathTracerShaderConfig()};
    so.pipelineConfigs = {pt::pathTracerPipelineConfig()};
    s.pipeline = StateObject::create(so);

    // Shader tables.
    const auto rayGen =
        ShaderTableBuilder("raygen").addRecord(s.pipeline->shaderIdentifier("PT_RayGen")).upload(memory);
    s.tables.RayGenerationShaderRecord = {rayGen.StartAddress, rayGen.SizeInBytes};
    s.tables.MissShaderTable = ShaderTableBuilder("miss")
                                   .addRecord(s.pipeline->shaderIdentifier("PT_Miss"))
                                   .addRecord(s.pipeline->shaderIdentifier("PT_ShadowMiss"))
                                   .upload(memory);
    s.tables.HitGroupTable = ShaderTableBuilder("hit groups")
                                 .addRecord(s.pipeline->shaderIdentifier("PT_HitGroup"))
                                 .addRecord(s.pipeline->shaderIdentifier("PT_ShadowHitGroup"))
                                 .upload(memory);
}

PathTracerScene::PathTracerScene(PathTracerScene&&) noexcept = default;
PathTracerScene& PathTracerScene::operator=(PathTracerScene&&) noexcept = default;
PathTracerScene::~PathTracerScene() = default;

pt::PathTracerConstants PathTracerScene::constants(uint32_t width, uint32_t height, uint32_t spp, uint32_t seed,
                                                   const PathTracerRenderOptions& options) const {
    const PathTracerCamera& c = state_->desc.camera;
    CameraDesc camera;
    camera.name = state_->desc.name;
    camera.model = CameraModel::MiniEngine;  // right-handed: screen right = forward x up
    camera.eye = c.eye;
    camera.target = c.target;
    camera.up = c.up;
    camera.fovYRadians = c.fovYDegrees * 3.14159265358979323846 / 180.0;  // as the scene loader converts it
    camera.nearZ = c.nearZ;
    camera.farZ = c.farZ;

    pt::PathTracerConstants cb{};
    cb.projectionToWorld = projectionToWorld(camera, width, height);
    cb.cameraPosition = vec4(vec3(c.eye), 1.0f);
    cb.backgroundColor = vec4(state_->desc.backgroundColor, 1.0f);
    cb.samplesPerPixel = spp;
    cb.maxBounces = options.maxBounces;
    cb.seed = seed;
    cb.lightCount = uint32_t(state_->lights.size());
    cb.debugMode = options.debugMode;
    return cb;
}

RenderResult PathTracerScene::render(uint32_t width, uint32_t height, uint32_t spp, uint32_t seed, uint32_t threads,
                                     const PathTracerRenderOptions& options) {
    State& s = *state_;
    RenderResult result;
    result.image = Image(width, height);
    s.heap->setTexture2D(0, DescriptorRangeType::UAV, &result.image);

    const pt::PathTracerConstants cb = constants(width, height, spp, seed, options);
    const GpuVirtualAddress cbAddress = s.device->memory().upload(&cb, sizeof cb, "PathTracerConstants");

    GlobalRootArguments globals(s.globalSignature);
    globals.setDescriptor(pt::kOutputTable, s.heap->gpuHandle(0));
    globals.setDescriptor(pt::kAccelerationStructure, s.tlas);
    globals.setDescriptor(pt::kConstants, cbAddress);
    globals.setDescriptor(pt::kSceneBuffers, s.heap->gpuHandle(1));
    globals.setDescriptor(pt::kDiffuseTextures, s.heap->gpuHandle(s.diffuseTableStart));
    globals.setDescriptor(pt::kNormalTextures, s.heap->gpuHandle(s.normalTableStart));

    DispatchRaysDesc desc = s.tables;
    desc.Width = width;
    desc.Height = height;
    desc.Depth = 1;
    DispatchOptions dispatchOptions;
    dispatchOptions.threads = threads;
    result.dispatch = s.device->dispatchRays(desc, s.pipeline, &globals, dispatchOptions);
    result.image.metadata["refray:scene"] = s.desc.name;
    result.image.metadata["refray:spp"] = std::to_string(spp);
    result.image.metadata["refray:seed"] = std::to_string(seed);
    result.image.metadata["refray:maxBounces"] = std::to_string(options.maxBounces);
    return result;
}

namespace {

// Every OBJ object of `path` as a model, each instanced once with the identity transform (the files are in world
// space), objects named as their models.
PathTracerSceneDesc sceneFromObj(const std::filesystem::path& path, std::string name) {
    PathTracerSceneDesc desc;
    desc.name = std::move(name);
    desc.models = loadObjModels(path);
    for (uint32_t m = 0; m < desc.models.size(); ++m)
        desc.objects.push_back({desc.models[m].name, m, Matrix3x4::identity()});
    return desc;
}

}  // namespace

PathTracerScene PathTracerScene::cornellBox(const std::filesystem::path& scenesDirectory) {
    PathTracerSceneDesc desc = sceneFromObj(scenesDirectory / "cornell-box" / "cornell-box.obj", "cornell-box");
    desc.camera = {{278.0, 273.0, -800.0}, {278.0, 273.0, 0.0}, {0.0, 1.0, 0.0}, 39.3077, 8.0, 8000.0};
    desc.backgroundColor = vec3(0.0f);
    return PathTracerScene(std::move(desc));
}

PathTracerScene PathTracerScene::texturedRoom(const std::filesystem::path& scenesDirectory) {
    PathTracerSceneDesc desc = sceneFromObj(scenesDirectory / "textured-room" / "textured-room.obj", "textured-room");
    desc.camera = {{0.0, 2.4, 5.6}, {0.0, 0.9, -0.6}, {0.0, 1.0, 0.0}, 50.0, 0.05, 100.0};
    desc.backgroundColor = vec3(0.05f, 0.06f, 0.08f);
    return PathTracerScene(std::move(desc));
}

const PathTracerSceneDesc& PathTracerScene::desc() const { return state_->desc; }
const GlobalModelBuffers& PathTracerScene::buffers() const { return state_->buffers; }
const std::vector<pt::LightTriangleGPU>& PathTracerScene::lights() const { return state_->lights; }
Device& PathTracerScene::device() { return *state_->device; }
const StateObjectPtr& PathTracerScene::pipeline() const { return state_->pipeline; }
const DispatchRaysDesc& PathTracerScene::tables() const { return state_->tables; }
GpuVirtualAddress PathTracerScene::tlas() const { return state_->tlas; }

}  // namespace refray::scenes
