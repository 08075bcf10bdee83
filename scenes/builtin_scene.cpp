#include "scenes/builtin_scene.h"

#include <cmath>

#include "procedural/builtin/builtin_shaders.h"

namespace refray::scenes {

using namespace refray::dxr;
namespace builtin = refray::procedural::builtin;

BuiltinScene::BuiltinScene(const BuiltinSceneOptions& options) : options_(options) {
    GpuMemory& memory = device_.memory();

    // BLAS 0: the plane, two triangles at y = 0 whose cross(v1-v0, v2-v0) points up, so rays
    // from above see front faces (FACE-1).
    const float s = kPlaneHalfSize;
    const std::vector<vec3> vertices = {{-s, 0, -s}, {s, 0, -s}, {s, 0, s}, {-s, 0, s}};
    const std::vector<uint16_t> indices = {0, 2, 1, 0, 3, 2};
    GeometryDesc plane;
    plane.Type = GeometryType::Triangles;
    plane.Flags = GEOMETRY_FLAG_OPAQUE;
    plane.Triangles.IndexFormat = Format::R16_UINT;
    plane.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
    plane.Triangles.IndexCount = uint32_t(indices.size());
    plane.Triangles.VertexCount = uint32_t(vertices.size());
    plane.Triangles.IndexBuffer = memory.upload(indices, "plane indices");
    plane.Triangles.VertexBuffer = {memory.upload(vertices, "plane vertices"), sizeof(vec3)};
    const GpuVirtualAddress planeBlas = device_.buildBottomLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, {plane}});

    // BLAS 1: the sphere's AABB (object space, centred at the origin).
    const RaytracingAABB box{-kSphereRadius, -kSphereRadius, -kSphereRadius, kSphereRadius, kSphereRadius, kSphereRadius};
    GeometryDesc sphere;
    sphere.Type = GeometryType::ProceduralPrimitiveAABBs;
    sphere.Flags = GEOMETRY_FLAG_OPAQUE;
    sphere.AABBs.AABBCount = 1;
    sphere.AABBs.AABBs = {memory.upload(&box, sizeof box, "sphere AABB"), sizeof box};
    const GpuVirtualAddress sphereBlas = device_.buildBottomLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, {sphere}});

    // TLAS: instance contributions 0 and 2 (two records per geometry, one per ray type).
    const std::vector<InstanceDesc> instances = {
        makeInstanceDesc(Matrix3x4::translation(options.worldOffset), 0, 0xFF, 0, INSTANCE_FLAG_NONE, planeBlas),
        makeInstanceDesc(Matrix3x4::translation(kSphereCentre + options.worldOffset), 1, 0xFF, 2, INSTANCE_FLAG_NONE,
                         sphereBlas),
    };
    tlas_ = device_.buildTopLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, uint32_t(instances.size()), ElementsLayout::Array,
                                     memory.upload(instances, "instance descs")});

    // Root signatures.
    RootSignatureDesc global;
    global.name = "Global";
    global.parameters = {RootParameter::table({DescriptorRange{DescriptorRangeType::UAV, 1, 0, 0, 0}}),
                         RootParameter::srv(0), RootParameter::cbv(0)};
    globalSignature_ = RootSignature::create(global);
    RootSignatureDesc material;
    material.name = "Material";
    material.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    material.parameters = {RootParameter::constants(sizeof(builtin::MaterialConstants) / 4, 1)};
    const RootSignaturePtr materialSignature = RootSignature::create(material);

    // The pipeline.
    StateObjectDesc so;
    so.name = "builtin";
    so.libraries = {{builtin::makeShaderLibrary(options.secondaryRays), {}}};
    so.hitGroups = {
        {"HitGroup_Plane", HitGroupType::Triangles, "", "ClosestHit_Plane", ""},
        {"HitGroup_Plane_Shadow", HitGroupType::Triangles, "", "", ""},
        {"HitGroup_Sphere", HitGroupType::ProceduralPrimitive, "", "ClosestHit_Sphere", "Intersection_Sphere"},
        {"HitGroup_Sphere_Shadow", HitGroupType::ProceduralPrimitive, "", "", "Intersection_Sphere"},
    };
    so.localRootSignatures = {{materialSignature, {"HitGroup_Plane", "HitGroup_Plane_Shadow", "HitGroup_Sphere", "HitGroup_Sphere_Shadow"}}};
    so.globalRootSignatures = {{globalSignature_, {}}};
    so.shaderConfigs = {{sizeof(builtin::RadiancePayload), sizeof(builtin::SphereAttributes)}};
    so.pipelineConfigs = {{builtin::kMaxRecursionDepth, PIPELINE_FLAG_NONE}};
    pipeline_ = StateObject::create(so);

    // Shader tables.
    auto materialArgs = [&](vec4 albedo) {
        LocalRootArguments args(materialSignature);
        args.setConstants(builtin::kMaterialParameter, builtin::MaterialConstants{albedo});
        return args;
    };
    const vec4 planeAlbedo = kPlaneAlbedo, sphereAlbedo = kSphereAlbedo;
    const auto rayGen = ShaderTableBuilder("raygen").addRecord(pipeline_->shaderIdentifier("RayGen")).upload(memory);
    tables_.RayGenerationShaderRecord = {rayGen.StartAddress, rayGen.SizeInBytes};
    tables_.MissShaderTable = ShaderTableBuilder("miss")
                                  .addRecord(pipeline_->shaderIdentifier("Miss"))
                                  .addRecord(pipeline_->shaderIdentifier("Miss_Shadow"))
                                  .upload(memory);
    tables_.HitGroupTable = ShaderTableBuilder("hit groups")
                                .addRecord(pipeline_->shaderIdentifier("HitGroup_Plane"), materialArgs(planeAlbedo))
                                .addRecord(pipeline_->shaderIdentifier("HitGroup_Plane_Shadow"), materialArgs(planeAlbedo))
                                .addRecord(pipeline_->shaderIdentifier("HitGroup_Sphere"), materialArgs(sphereAlbedo))
                                .addRecord(pipeline_->shaderIdentifier("HitGroup_Sphere_Shadow"), materialArgs(sphereAlbedo))
                                .upload(memory);
}

builtin::SceneConstants BuiltinScene::sceneConstants(uint32_t width, uint32_t height, vec3 worldOffset) {
    // Camera: eye up and to the side, looking at the sphere; 45 degree vertical field of view.
    const vec3 eye = vec3(4.5f, 3.0f, 6.0f) + worldOffset, target = vec3(0.0f, 0.8f, 0.0f) + worldOffset;
    const vec3 forward = glm::normalize(target - eye);
    const vec3 right = glm::normalize(glm::cross(forward, vec3(0, 1, 0)));
    const vec3 up = glm::cross(right, forward);
    const float tanHalf = std::tan(0.5f * 0.7853982f);
    const float aspect = float(width) / float(height);
    return {vec4(eye, 1),     vec4(right * tanHalf * aspect, 0), vec4(up * tanHalf, 0),
            vec4(forward, 0), vec4(vec3(-3.0f, 7.0f, 4.0f) + worldOffset, 1.0f), vec4(0, 0, 0, kSphereRadius)};
}

RenderResult BuiltinScene::render(const RenderSettings& settings) {
    RenderResult result;
    result.image = Image(settings.width, settings.height);
    if (!outputHeap_) outputHeap_ = &device_.createDescriptorHeap(1, "output heap");
    DescriptorHeap& heap = *outputHeap_;
    heap.setTexture2D(0, DescriptorRangeType::UAV, &result.image);

    const builtin::SceneConstants constants = sceneConstants(settings.width, settings.height, options_.worldOffset);
    const GpuVirtualAddress cb = device_.memory().upload(&constants, sizeof constants, "scene constants");

    GlobalRootArguments globals(globalSignature_);
    globals.setDescriptor(builtin::kOutputTable, heap.gpuHandle(0));
    globals.setDescriptor(builtin::kAccelerationStructure, tlas_);
    globals.setDescriptor(builtin::kSceneConstants, cb);

    DispatchRaysDesc desc = tables_;
    desc.Width = settings.width;
    desc.Height = settings.height;
    desc.Depth = 1;
    result.dispatch = dispatchWithSettings(device_, desc, pipeline_, &globals, settings);
    return result;
}

}  // namespace refray::scenes
