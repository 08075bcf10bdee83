// The raw-Embree renderer: Embree callbacks, and building the flat Embree scene from the scene file's data.
#include "tests/benchmarks/raw_embree_renderer.h"

namespace refray::bench {

// ---- Embree callbacks ----------------------------------------------------------------------------------

void onBounds(const RTCBoundsFunctionArguments* args) {
    const auto& g = *static_cast<const RawGeometry*>(args->geometryUserPtr);
    vec3 lo(INFINITY), hi(-INFINITY);
    for (int corner = 0; corner < 8; ++corner) {
        const vec3 p((corner & 1) ? g.boxMax.x : g.boxMin.x, (corner & 2) ? g.boxMax.y : g.boxMin.y,
                     (corner & 4) ? g.boxMax.z : g.boxMin.z);
        const vec3 w = g.objectToWorld.transformPoint(p);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
    // A small margin, so Embree's float traversal never drops a box the exact object-space test would accept.
    const float margin = 1e-5f * std::max({glm::length(hi - lo), std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z),
                                           std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)}) +
                         1e-30f;
    *args->bounds_o = RTCBounds{lo.x - margin, lo.y - margin, lo.z - margin, 0.0f,
                                hi.x + margin, hi.y + margin, hi.z + margin, 0.0f};
}

void onIntersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto& g = *static_cast<const RawGeometry*>(args->geometryUserPtr);
    auto* rayhit = reinterpret_cast<RTCRayHit*>(args->rayhit);  // rtcIntersect1: N = 1
    RTCRay& ray = rayhit->ray;
    float t = 0.0f;
    ProceduralAttributes attributes;
    if (!g.renderer->intersect(g, vec3(ray.org_x, ray.org_y, ray.org_z), vec3(ray.dir_x, ray.dir_y, ray.dir_z),
                               ray.tnear, ray.tfar, t, attributes))
        return;
    ray.tfar = t;
    rayhit->hit.geomID = args->geomID;
    rayhit->hit.primID = args->primID;
    rayhit->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    reinterpret_cast<RayContext*>(args->context)->attributes = attributes;
}

void onOccluded(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto& g = *static_cast<const RawGeometry*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);  // rtcOccluded1: N = 1
    float t = 0.0f;
    ProceduralAttributes attributes;
    if (g.renderer->intersect(g, vec3(ray->org_x, ray->org_y, ray->org_z), vec3(ray->dir_x, ray->dir_y, ray->dir_z),
                              ray->tnear, ray->tfar, t, attributes))
        ray->tfar = -INFINITY;
}

// RAY_FLAG_CULL_BACK_FACING_TRIANGLES: a triangle is front-facing when the object-space ray meets the clockwise
// side, dot(cross(v1 - v0, v2 - v0), d) < 0 (refray's FACE-1 rule); back faces are dropped.
void cullBackFaces(const RTCFilterFunctionNArguments* args) {
    const auto& g = *static_cast<const RawGeometry*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const vec3 direction(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                             RTCRayN_dir_z(args->ray, args->N, i));
        const dvec3& faceCross = g.faceCross[RTCHitN_primID(args->hit, args->N, i)];
        if (!(glm::dot(faceCross, dvec3(g.worldToObject.transformVector(direction))) < 0.0)) args->valid[i] = 0;
    }
}

// ---- Building: the scene file's data and the flat Embree scene --------------------------------------

RawRenderer::RawRenderer(const scenes::SceneDesc& desc, uint32_t width, uint32_t height)
    : width_(width), height_(height) {
    if (desc.shaderLibrary == "d3d12-procedural-geometry") library_ = Library::D3D12;
    else if (desc.shaderLibrary == "proceduray") library_ = Library::Proceduray;
    else fail("raw renderer: no raw shaders for library '" + desc.shaderLibrary + "'");
    // The knobs refray's library is built with by default (the scene's effects block applied).
    accuracy_ = scenes::libraryAccuracy(desc, procedural::Accuracy{});
    effects_ = scenes::libraryEffects(desc);
    maxDepth_ = library_ == Library::D3D12 ? d3d12::maxRayRecursionDepth(accuracy_)
                                           : pray::maxRayRecursionDepth(accuracy_);
    readFrameData(desc);
    buildScene(desc);
}

void RawRenderer::readFrameData(const scenes::SceneDesc& desc) {
    // Global root parameters 2, 3 and 4 of both samples: the scene constants, the per-primitive matrices and the
    // {indices, vertices} table.
    const bool isD3D12 = library_ == Library::D3D12;
    const uint32_t sceneConstantParameter =
        isD3D12 ? uint32_t(d3d12::kSceneConstant) : uint32_t(pray::kSceneConstantBuffer);
    const uint32_t perPrimitiveParameter =
        isD3D12 ? uint32_t(d3d12::kAABBattributeBuffer) : uint32_t(pray::kInstanceBuffer);
    const uint32_t vertexBuffersParameter =
        isD3D12 ? uint32_t(d3d12::kVertexBuffers) : uint32_t(pray::kVertexBuffers);
    const float time = desc.defaultTime;
    const scenes::CameraDesc& camera = desc.camera("");
    bool haveConstants = false;
    for (const scenes::GlobalArgumentDesc& a : desc.globalArguments) {
        if (a.parameter == sceneConstantParameter) {
            const scenes::BufferDesc& b = desc.buffers.at(size_t(a.buffer));
            if (b.kind != scenes::BufferDesc::Kind::SceneConstants)
                fail("raw renderer: b0 is not generated scene constants");
            if (b.debugFlag != 0) fail("raw renderer: the debug-flag paths are not reproduced");
            scenes::SceneConstantsInput in;
            in.projectionToWorld = scenes::projectionToWorld(camera, width_, height_);
            in.cameraPosition = vec4(vec3(camera.eye), 1.0f);
            in.light = desc.light;
            in.elapsedTime = time;
            in.debugFlag = b.debugFlag;
            const std::vector<uint8_t> bytes = scenes::findShaderLibrary(desc.shaderLibrary).sceneConstants(in);
            if (isD3D12) {
                if (bytes.size() < sizeof d3d12CB_) fail("raw renderer: short scene constants");
                std::memcpy(&d3d12CB_, bytes.data(), sizeof d3d12CB_);
                cameraPosition_ = vec3(d3d12CB_.cameraPosition);
                lightPosition_ = vec3(d3d12CB_.lightPosition);
                projectionToWorld_ = d3d12CB_.projectionToWorld;
                elapsedTime_ = d3d12CB_.elapsedTime;
            } else {
                if (bytes.size() < sizeof procedurayCB_) fail("raw renderer: short scene constants");
                std::memcpy(&procedurayCB_, bytes.data(), sizeof procedurayCB_);
                cameraPosition_ = vec3(procedurayCB_.cameraPosition);
                lightPosition_ = vec3(procedurayCB_.lightPosition);
                projectionToWorld_ = procedurayCB_.projectionToWorld;
                elapsedTime_ = procedurayCB_.elapsedTime;
            }
            haveConstants = true;
        } else if (a.parameter == perPrimitiveParameter) {
            const scenes::BufferDesc& b = desc.buffers.at(size_t(a.buffer));
            if (b.kind == scenes::BufferDesc::Kind::PrimitiveTransforms) {
                for (const scenes::PrimitiveTransformDesc& p : b.primitives) {
                    const auto [forward, inverse] = primitiveTransform(p, double(time));
                    perPrimitive_.push_back(forward);
                    perPrimitive_.push_back(inverse);
                }
            } else if (b.kind == scenes::BufferDesc::Kind::InstanceTransforms) {
                for (uint32_t i : b.instances) {
                    const Matrix3x4& m = desc.instances.at(i).transform;
                    const std::optional<Matrix3x4> inverse = affineInverse(m);
                    if (!inverse) fail("raw renderer: singular instance transform");
                    perPrimitive_.push_back(procedural::rowVectorForm(*inverse));  // world -> object
                    perPrimitive_.push_back(procedural::rowVectorForm(m));
                }
            } else {
                fail("raw renderer: t3 is not a generated transform buffer");
            }
        } else if (a.parameter == vertexBuffersParameter) {
            if (a.table.size() != 2 || a.table[0].buffer < 0 || a.table[1].buffer < 0)
                fail("raw renderer: the vertex-buffer table is not {indices, vertices}");
            indexBytes_ = desc.buffers.at(size_t(a.table[0].buffer)).bytes;
            vertexBytes_ = desc.buffers.at(size_t(a.table[1].buffer)).bytes;
        }
    }
    if (!haveConstants) fail("raw renderer: no scene constants bound");
}

void RawRenderer::buildScene(const scenes::SceneDesc& desc) {
    device_ = rtcNewDevice("verbose=0");
    if (!device_) fail("raw renderer: cannot create an Embree device");
    rtcSetDeviceErrorFunction(device_, onError, this);
    scene_ = rtcNewScene(device_);

    // Every geometry of every instance, with the record its radiance ray type reaches (contribution + geometry x
    // multiplier + ray contribution): the hit group's shaders and the local root arguments.
    const scenes::RayTypeDesc& radiance = desc.rayTypes.at(0);
    for (const scenes::InstanceDescFile& inst : desc.instances) {
        if (inst.flags != dxr::INSTANCE_FLAG_NONE) fail("raw renderer: instance flags are not reproduced");
        const std::optional<Matrix3x4> inverse = affineInverse(inst.transform);
        if (!inverse) fail("raw renderer: singular instance transform");
        const scenes::BlasDesc& blas = desc.blases.at(inst.blas);
        for (uint32_t geometryIndex = 0; geometryIndex < blas.geometries.size(); ++geometryIndex) {
            const scenes::GeometryDescFile& geometry = blas.geometries[geometryIndex];
            const scenes::RecordDesc& record = desc.hitGroupRecords.at(
                size_t(inst.contribution) + size_t(geometryIndex) * radiance.multiplier + radiance.rayContribution);
            const auto group =
                std::find_if(desc.hitGroups.begin(), desc.hitGroups.end(),
                             [&](const dxr::HitGroupDesc& h) { return h.HitGroupExport == record.hitGroup; });
            if (group == desc.hitGroups.end()) fail("raw renderer: record without a hit group");

            auto g = std::make_unique<RawGeometry>();
            g->renderer = this;
            g->closestHit = closestHitOf(group->ClosestHitShaderImport);
            g->objectToWorld = inst.transform;
            g->worldToObject = *inverse;
            for (const scenes::RecordDesc::Argument& a : record.arguments) {
                if (a.parameter == 0 && a.dwords.size() * 4 == sizeof g->material)
                    std::memcpy(&g->material, a.dwords.data(), sizeof g->material);  // l_materialCB
                else if (a.parameter == 1 && a.dwords.size() * 4 == sizeof g->aabbCB)
                    std::memcpy(&g->aabbCB, a.dwords.data(), sizeof g->aabbCB);  // l_aabbCB
                else
                    fail("raw renderer: unexpected local root argument");
            }
            if (geometry.type == dxr::GeometryType::Triangles) {
                addTriangles(desc, geometry, std::move(g));
                continue;
            }
            g->intersection = intersectionOf(group->IntersectionShaderImport);
            if (g->intersection == Intersection::Pacman && pray::SignedDistancePrimitive(g->aabbCB.primitiveType) !=
                                                               pray::SignedDistancePrimitive::IntersectedRoundCube)
                fail("raw renderer: a Pac-man record whose primitiveType is not IntersectedRoundCube");
            const size_t element = 2 * size_t(g->aabbCB.instanceIndex);
            if (element + 1 >= perPrimitive_.size()) fail("raw renderer: l_aabbCB.instanceIndex outside t3");
            g->localSpaceToBottomLevelAS = perPrimitive_[element];
            g->bottomLevelASToLocalSpace = perPrimitive_[element + 1];
            const std::vector<uint8_t>& aabbs = desc.buffers.at(geometry.aabbBuffer).bytes;
            for (uint32_t k = 0; k < geometry.aabbCount; ++k) {
                dxr::RaytracingAABB box;
                std::memcpy(&box, aabbs.data() + size_t(k) * sizeof box, sizeof box);
                addAABB(box, k + 1 < geometry.aabbCount ? std::make_unique<RawGeometry>(*g) : std::move(g));
            }
        }
    }
    rtcCommitScene(scene_);
    throwIfFailed("building the raw Embree scene");
}

void RawRenderer::addTriangles(const scenes::SceneDesc& desc, const scenes::GeometryDescFile& geometry,
                               std::unique_ptr<RawGeometry> g) {
    if (geometry.vertexFormat != dxr::Format::R32G32B32_FLOAT || geometry.indexBuffer < 0 ||
        geometry.indexFormat != dxr::Format::R16_UINT)
        fail("raw renderer: only indexed R32G32B32_FLOAT / R16_UINT triangles are reproduced");
    const std::vector<uint8_t>& vb = desc.buffers.at(geometry.vertexBuffer).bytes;
    const std::vector<uint8_t>& ib = desc.buffers.at(size_t(geometry.indexBuffer)).bytes;
    std::vector<vec3> vertices(geometry.vertexCount);
    for (uint32_t k = 0; k < geometry.vertexCount; ++k)
        std::memcpy(&vertices[k], vb.data() + geometry.vertexOffset + size_t(k) * geometry.vertexStride, sizeof(vec3));
    const uint32_t triangles = geometry.indexCount / 3;

    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), geometry.vertexCount));
    for (uint32_t k = 0; k < geometry.vertexCount; ++k) {
        const vec3 w = g->objectToWorld.transformPoint(vertices[k]);  // flat: world space
        v[3 * k] = w.x, v[3 * k + 1] = w.y, v[3 * k + 2] = w.z;
    }
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(unsigned), triangles));
    for (uint32_t i = 0; i < 3 * triangles; ++i) {
        uint16_t index = 0;
        std::memcpy(&index, ib.data() + geometry.indexOffset + 2 * size_t(i), sizeof index);
        if (index >= geometry.vertexCount) fail("raw renderer: index past the vertex buffer");
        idx[i] = index;
    }
    for (uint32_t t = 0; t < triangles; ++t) {
        const dvec3 v0(vertices[idx[3 * t]]), v1(vertices[idx[3 * t + 1]]), v2(vertices[idx[3 * t + 2]]);
        g->faceCross.push_back(glm::cross(v1 - v0, v2 - v0));
    }
    rtcSetGeometryUserData(geom, g.get());
    rtcSetGeometryIntersectFilterFunction(geom, cullBackFaces);
    rtcSetGeometryOccludedFilterFunction(geom, cullBackFaces);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene_, geom, unsigned(geometries_.size()));
    rtcReleaseGeometry(geom);
    geometries_.push_back(std::move(g));
}

void RawRenderer::addAABB(const dxr::RaytracingAABB& box, std::unique_ptr<RawGeometry> g) {
    g->boxMin = vec3(box.MinX, box.MinY, box.MinZ);
    g->boxMax = vec3(box.MaxX, box.MaxY, box.MaxZ);
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, g.get());
    rtcSetGeometryBoundsFunction(geom, onBounds, nullptr);
    rtcSetGeometryIntersectFunction(geom, onIntersect);
    rtcSetGeometryOccludedFunction(geom, onOccluded);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene_, geom, unsigned(geometries_.size()));
    rtcReleaseGeometry(geom);
    geometries_.push_back(std::move(g));
}

void RawRenderer::onError(void* user, RTCError code, const char* message) {
    auto* self = static_cast<RawRenderer*>(user);
    std::lock_guard lock(self->errorMutex_);
    if (self->error_.empty())
        self->error_ = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "(no message)");
}

void RawRenderer::throwIfFailed(const char* what) const {
    std::lock_guard lock(errorMutex_);
    if (!error_.empty()) fail(std::string(what) + ": " + error_);
}

}  // namespace refray::bench
