// Emulation overhead on the reference scenes (issue 8): refray against raw Embree calling the same shader functions
// directly. Each reference scene file (D3D12 procedural geometry, Proceduray Mandelbulb/Julia/Pac-man) renders its
// default camera at its default time, float, 1 spp, two ways:
//
// - refray: scenes::Scene::render — DispatchRays through the shader tables, the state object, Embree and every DXR
//   rule, with the ported shaders as the scene's library builds them.
// - raw Embree: one flat Embree scene of the same geometry, built here from the same SceneDesc. Triangle meshes are
//   native RTC_GEOMETRY_TYPE_TRIANGLE (world-space vertices; back faces dropped by a filter function, which is what
//   the shaders' RAY_FLAG_CULL_BACK_FACING_TRIANGLES asks for); every AABB is an RTC_GEOMETRY_TYPE_USER primitive
//   whose callbacks test the object-space box against [tnear, tfar] (the test DXR traversal makes before it calls an
//   intersection shader), take the ray into the primitive's local space as the port does, and call the same math the
//   ports' intersection shaders call (math::RayUnitCubeIntersectionTest / RaySpheresIntersectionTest /
//   RayMetaballsIntersectionTest / RaySignedDistancePrimitiveTest, mandelbulb::MandelbulbDistance,
//   julia::JuliaDistance, with the ports' params functions). Ray generation, closest hit and miss are a plain C++
//   recursion that calls the ports' exported shading helpers (d3d12::CalculatePhongLighting,
//   AnalyticalCheckersTexture, ApplyVisibilityFalloff, FresnelReflectanceSchlick, GenerateCameraRay,
//   proceduray::CalculatePhongLighting, colorSurface, MandelbulbSurfaceColor, ...) with the same recursion depth,
//   the same shadow rays (rtcOccluded1, TMax 10000) and reflection rays. Materials, transforms, camera, light and
//   time come from the scene file through the loader.
// - Raw leaves out: shader tables and records, root signatures and resource views (the data are plain C++ values),
//   payload and attribute copies through the emulator, std::function dispatch, the candidate gather and ordered
//   processing of DXR rule TRV-2 (Embree's own traversal order decides which primitive is met first), refray's own
//   watertight triangle test (Embree's native kernel here), validation, statistics and diagnostics.
//
// Before anything is timed both images are compared: the largest difference of any channel and the fraction of
// pixels whose R8G8B8A8_UNORM value (clamp, NaN -> 0) differs by more than 1/255 in any channel are printed, with
// the ray counts of both. Over 1% of differing pixels marks the harness as wrong and every benchmark of that scene
// fails (SkipWithError) instead of timing it.
//
// Size: 320x180 by default; --size=WxH or REFRAY_BENCH_SIZE=WxH (e.g. 1280x720) changes it. REFRAY_BENCH_IMAGES=dir
// also writes both images of each scene there as EXR. BM_Ratio renders refray and raw alternately in one body (at
// least 2 s of pairs), so machine noise hits both equally; its counter "ratio" is refray time / raw time (take the
// median over --benchmark_repetitions).
#include <benchmark/benchmark.h>

#include <embree3/rtcore.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/math.h"
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/math/analytic.h"
#include "procedural/math/fractals.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/sdf.h"
#include "procedural/precision.h"
#include "procedural/proceduray/proceduray_shaders.h"
#include "scenes/camera_models.h"
#include "scenes/effects.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "scenes/shader_libraries.h"

namespace {

using namespace refray;
namespace d3d12 = refray::procedural::d3d12;
namespace pray = refray::procedural::proceduray;
namespace math = refray::procedural::math;
namespace hlsl = refray::procedural::hlsl;
using procedural::Float4x4;
using procedural::PrimitiveConstantBuffer;
using procedural::PrimitiveInstanceConstantBuffer;

constexpr float kTMax = 10000.0f;  // both libraries' TraceRay TMax

[[noreturn]] void fail(const std::string& message) { throw std::runtime_error(message); }

// ---- The raw renderer ---------------------------------------------------------------------------------

enum class Library { D3D12, Proceduray };

// The port function a geometry's radiance hit group names.
enum class Intersection { None, D3D12Analytic, D3D12Volumetric, D3D12SignedDistance, Julia, Pacman, Mandelbulb };
enum class ClosestHit { D3D12Triangle, D3D12AABB, ProcedurayTriangle, Julia, Pacman, Mandelbulb };

Intersection intersectionOf(const std::string& name) {
    if (name == "MyIntersectionShader_AnalyticPrimitive") return Intersection::D3D12Analytic;
    if (name == "MyIntersectionShader_VolumetricPrimitive") return Intersection::D3D12Volumetric;
    if (name == "MyIntersectionShader_SignedDistancePrimitive") return Intersection::D3D12SignedDistance;
    if (name == "Intersection_Julia") return Intersection::Julia;
    if (name == "Intersection_Pacman") return Intersection::Pacman;
    if (name == "Intersection_Mandelbulb") return Intersection::Mandelbulb;
    fail("raw renderer: unknown intersection shader '" + name + "'");
}

ClosestHit closestHitOf(const std::string& name) {
    if (name == "MyClosestHitShader_Triangle") return ClosestHit::D3D12Triangle;
    if (name == "MyClosestHitShader_AABB") return ClosestHit::D3D12AABB;
    if (name == "ClosestHit_Triangle") return ClosestHit::ProcedurayTriangle;
    if (name == "ClosestHit_Julia") return ClosestHit::Julia;
    if (name == "ClosestHit_Pacman") return ClosestHit::Pacman;
    if (name == "ClosestHit_Mandelbulb") return ClosestHit::Mandelbulb;
    fail("raw renderer: unknown closest-hit shader '" + name + "'");
}

// Both libraries trace both ray types with RAY_FLAG_CULL_BACK_FACING_TRIANGLES, which their intersection shaders apply
// to procedural hits themselves (math::RayExtent) and which the triangles' filter function applies here.
static_assert((d3d12::kTraceRayFlags[d3d12::RayType::Radiance] & dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES) &&
              (d3d12::kTraceRayFlags[d3d12::RayType::Shadow] & dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES) &&
              (pray::kTraceRayFlags[pray::Radiance] & dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES) &&
              (pray::kTraceRayFlags[pray::Shadow] & dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES));
constexpr bool kCullBackFacing = true;

class RawRenderer;

// One geometry of the flat Embree scene (a triangle mesh, or one AABB), with what its radiance record holds.
struct RawGeometry {
    const RawRenderer* renderer = nullptr;
    ClosestHit closestHit = ClosestHit::D3D12Triangle;
    Intersection intersection = Intersection::None;
    PrimitiveConstantBuffer material{};
    PrimitiveInstanceConstantBuffer aabbCB{};
    Matrix3x4 objectToWorld = Matrix3x4::identity();
    Matrix3x4 worldToObject = Matrix3x4::identity();
    // Triangles: cross(v1 - v0, v2 - v0) in object space, per triangle (the facing rule).
    std::vector<dvec3> faceCross;
    // AABBs: the object-space box, and the element of g_AABBPrimitiveAttributes / g_instanceBuffer that the record's
    // l_aabbCB.instanceIndex selects.
    vec3 boxMin{0.0f}, boxMax{0.0f};
    Float4x4 localSpaceToBottomLevelAS, bottomLevelASToLocalSpace;
};

// What a procedural hit hands its closest hit: the fields of both libraries' attribute structs.
struct ProceduralAttributes {
    vec3 normal{0.0f};
    vec4 color{0.0f, 0.0f, 0.0f, 1.0f};  // Proceduray's initial attributes
};

// Embree's extended intersect context: the attributes of the hit committed so far ride along with the ray.
struct RayContext {
    RTCIntersectContext embree;  // must be first
    ProceduralAttributes attributes;
};

struct PixelState {
    uvec2 index{0u};       // DispatchRaysIndex()
    uvec2 dimensions{0u};  // DispatchRaysDimensions()
    uint64_t rays = 0;
};

// The committed hit as a closest hit sees it.
struct RawHit {
    vec3 origin{0.0f}, direction{0.0f};  // WorldRayOrigin(), WorldRayDirection()
    float t = 0.0f;                      // RayTCurrent()
    uint32_t primitiveIndex = 0;
    ProceduralAttributes attributes;
    vec3 position() const { return origin + t * direction; }  // HitWorldPosition()
};

// The slab test of an object-space box over [tMin, tMax]: DXR calls an intersection shader only for a box that
// overlaps the current interval.
bool boxOverlaps(const vec3& lo, const vec3& hi, const vec3& origin, const vec3& direction, float tMin, float tMax) {
    float tEnter = tMin, tExit = tMax;
    for (glm::length_t axis = 0; axis < 3; ++axis) {
        const float o = origin[axis], d = direction[axis];
        if (d == 0.0f) {
            if (o < lo[axis] || o > hi[axis]) return false;
            continue;
        }
        float t0 = (lo[axis] - o) / d, t1 = (hi[axis] - o) / d;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > tEnter) tEnter = t0;
        if (t1 < tExit) tExit = t1;
        if (!(tEnter <= tExit)) return false;
    }
    return true;
}

// The host's S·R·Tr of a primitiveTransforms element and its inverse (the D3D12 sample's per-frame buffer), in double
// and rounded once, as scenes::Scene fills g_AABBPrimitiveAttributes.
std::pair<Float4x4, Float4x4> primitiveTransform(const scenes::PrimitiveTransformDesc& p, double time) {
    using procedural::DMat4;
    using procedural::multiply;
    const double theta = p.spinYPerSecond * time;
    const double c = std::cos(theta), s = std::sin(theta);
    const DMat4 R = {{{c, 0, -s, 0}, {0, 1, 0, 0}, {s, 0, c, 0}, {0, 0, 0, 1}}};
    const DMat4 Rt = {{{c, 0, s, 0}, {0, 1, 0, 0}, {-s, 0, c, 0}, {0, 0, 0, 1}}};
    DMat4 S{}, Si{}, T{}, Ti{};
    for (size_t k = 0; k < 4; ++k) S[k][k] = Si[k][k] = T[k][k] = Ti[k][k] = 1;
    for (size_t k = 0; k < 3; ++k) {
        const glm::length_t c3 = glm::length_t(k);
        S[k][k] = p.scale[c3];
        Si[k][k] = 1.0 / double(p.scale[c3]);
        T[3][k] = p.centre[c3];
        Ti[3][k] = -double(p.centre[c3]);
    }
    return {procedural::toFloat4x4(multiply(multiply(S, R), T)),
            procedural::toFloat4x4(multiply(multiply(Ti, Rt), Si))};
}

class RawRenderer {
public:
    RawRenderer(const scenes::SceneDesc& desc, uint32_t width, uint32_t height);
    ~RawRenderer() {
        if (scene_) rtcReleaseScene(scene_);
        if (device_) rtcReleaseDevice(device_);
    }
    RawRenderer(const RawRenderer&) = delete;
    RawRenderer& operator=(const RawRenderer&) = delete;

    // Renders the frame into `image` (width x height, row order) on `threads` threads; returns the rays traced.
    uint64_t render(uint32_t threads, std::vector<vec4>& image) const;

    // The intersection shader of `g` for a world ray over [tMin, tCurrent]: true, with the hit's t and attributes, if
    // it reports a hit that ReportHit accepts (TMin <= t <= RayTCurrent).
    bool intersect(const RawGeometry& g, const vec3& origin, const vec3& direction, float tMin, float tCurrent,
                   float& tHit, ProceduralAttributes& attributes) const;

private:
    void readFrameData(const scenes::SceneDesc& desc);
    void buildScene(const scenes::SceneDesc& desc);
    void addTriangles(const scenes::SceneDesc& desc, const scenes::GeometryDescFile& geometry,
                      std::unique_ptr<RawGeometry> g);
    void addAABB(const dxr::RaytracingAABB& box, std::unique_ptr<RawGeometry> g);
    void throwIfFailed(const char* what) const;

    vec4 traceRadianceRay(const vec3& origin, const vec3& direction, uint32_t currentRayRecursionDepth,
                          PixelState& px) const;
    bool traceShadowRayAndReportIfHit(const vec3& origin, const vec3& direction, uint32_t currentRayRecursionDepth,
                                      PixelState& px) const;
    bool traceShadowRayTowardsLight(const vec3& hitPosition, uint32_t recursionDepth, PixelState& px) const;
    vec4 reflectedColor(const RawHit& hit, const vec3& normal, float reflectanceCoef, const vec3& f0,
                        uint32_t recursionDepth, PixelState& px) const;
    vec3 storedVertexNormal(uint32_t primitiveIndex) const;

    vec4 closestHitD3D12Triangle(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                 PixelState& px) const;
    vec4 closestHitD3D12AABB(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth, PixelState& px) const;
    vec4 closestHitProcedurayTriangle(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                      PixelState& px) const;
    vec4 closestHitPacman(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth, PixelState& px) const;
    vec4 closestHitMandelbulb(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth, PixelState& px) const;
    vec4 closestHitJulia(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth, PixelState& px) const;

    static void onError(void* user, RTCError code, const char* message);

    Library library_ = Library::D3D12;
    uint32_t width_ = 0, height_ = 0;
    procedural::Accuracy accuracy_;
    procedural::Effects effects_;
    uint32_t maxDepth_ = 0;  // MAX_RAY_RECURSION_DEPTH
    d3d12::SceneConstantBuffer d3d12CB_{};
    pray::SceneConstantBuffer procedurayCB_{};
    vec3 cameraPosition_{0.0f}, lightPosition_{0.0f};
    Float4x4 projectionToWorld_;
    float elapsedTime_ = 0.0f;
    std::vector<uint8_t> indexBytes_, vertexBytes_;  // g_indices, g_vertices
    // g_AABBPrimitiveAttributes (D3D12) or g_instanceBuffer (Proceduray): localSpaceToBottomLevelAS,
    // bottomLevelASToLocalSpace per element.
    std::vector<Float4x4> perPrimitive_;
    std::vector<std::unique_ptr<RawGeometry>> geometries_;  // by Embree geometry ID
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    mutable std::mutex errorMutex_;
    mutable std::string error_;
};

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

// ---- Intersection: the ports' intersection shaders without the shader API ----------------------------

bool RawRenderer::intersect(const RawGeometry& g, const vec3& origin, const vec3& direction, float tMin,
                            float tCurrent, float& tHit, ProceduralAttributes& attributes) const {
    const vec3 objectRayOrigin = g.worldToObject.transformPoint(origin);
    const vec3 objectRayDirection = g.worldToObject.transformVector(direction);
    if (!boxOverlaps(g.boxMin, g.boxMax, objectRayOrigin, objectRayDirection, tMin, tCurrent)) return false;
    const math::RayExtent<float> extent{tMin, tCurrent, kCullBackFacing, false};

    // D3D12: the object ray through bottomLevelASToLocalSpace, not renormalised; NormalToWorld through
    // localSpaceToBottomLevelAS and ObjectToWorld3x4.
    const auto d3d12LocalRay = [&] {
        return math::Ray<float>{vec3(procedural::mul(vec4(objectRayOrigin, 1.0f), g.bottomLevelASToLocalSpace)),
                                procedural::mul3x3(objectRayDirection, g.bottomLevelASToLocalSpace)};
    };
    const auto d3d12NormalToWorld = [&](const vec3& localNormal) {
        const vec3 n = procedural::mul3x3(localNormal, g.localSpaceToBottomLevelAS);
        const Matrix3x4& o2w = g.objectToWorld;
        vec3 r;
        for (size_t i = 0; i < 3; ++i)
            r[glm::length_t(i)] = o2w.m[i][0] * n.x + o2w.m[i][1] * n.y + o2w.m[i][2] * n.z;
        return hlsl::normalize(r);
    };
    // Proceduray: the world ray through g_instanceBuffer's world -> object matrix, direction normalised (H1);
    // normalize(mul(n, (float3x3)WorldToObject3x4())).
    const auto procedurayLocalRay = [&] {
        return math::Ray<float>{vec3(procedural::mul(vec4(origin, 1.0f), g.localSpaceToBottomLevelAS)),
                                hlsl::normalize(procedural::mul3x3(direction, g.localSpaceToBottomLevelAS))};
    };
    const auto procedurayNormalToWorld = [&](const vec3& n) {
        const Matrix3x4& w = g.worldToObject;
        vec3 r;
        for (int j = 0; j < 3; ++j)
            r[j] = n.x * w.m[0][size_t(j)] + n.y * w.m[1][size_t(j)] + n.z * w.m[2][size_t(j)];
        return hlsl::normalize(r);
    };

    bool hit = false;
    float t = 0.0f;
    attributes = ProceduralAttributes{};
    switch (g.intersection) {
        case Intersection::D3D12Analytic: {
            const math::Ray<float> localRay = d3d12LocalRay();
            math::AnalyticHit<float> test;
            switch (d3d12::AnalyticPrimitive::Enum(g.aabbCB.primitiveType)) {
                case d3d12::AnalyticPrimitive::AABB: test = math::RayUnitCubeIntersectionTest(localRay, extent); break;
                case d3d12::AnalyticPrimitive::Spheres:
                    test = math::RaySpheresIntersectionTest(localRay, extent);
                    break;
                default: break;
            }
            if (test.hit) {
                hit = true;
                t = test.thit;
                attributes.normal = d3d12NormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::D3D12Volumetric: {
            math::MetaballsHit<float> test;
            if (d3d12::VolumetricPrimitive::Enum(g.aabbCB.primitiveType) == d3d12::VolumetricPrimitive::Metaballs)
                test = math::RayMetaballsIntersectionTest(d3d12LocalRay(), extent, elapsedTime_, 12.0f,
                                                          d3d12::metaballsParams<float>(accuracy_));
            if (test.hit) {
                hit = true;
                t = test.thit;
                attributes.normal = d3d12NormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::D3D12SignedDistance: {
            const auto primitiveType = d3d12::SignedDistancePrimitive(g.aabbCB.primitiveType);
            const math::SphereTraceParams<float> params =
                d3d12::sphereTraceParams(accuracy_, float(g.material.stepScale));
            const auto sdf = [primitiveType](const vec3& position) {
                return math::d3d12::GetDistanceFromSignedDistancePrimitive(position, primitiveType);
            };
            const math::SphereTraceResult<float> test =
                math::RaySignedDistancePrimitiveTest(d3d12LocalRay(), extent, sdf, params);
            if (test.hit) {
                hit = true;
                t = test.thit;
                attributes.normal = d3d12NormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::Pacman: {
            const float mouth = math::pacman::PacmanMouthInterpolant(elapsedTime_);
            const math::SphereTraceParams<float> params =
                pray::sphereTraceParams(accuracy_, float(g.material.stepScale));
            // The port's GetDistanceFromSignedDistancePrimitive for IntersectedRoundCube, the only live case.
            const auto sdf = [mouth](const vec3& p) { return math::pacman::pacMan(p, mouth); };
            const math::SphereTraceResult<float> test =
                math::RaySignedDistancePrimitiveTest(procedurayLocalRay(), extent, sdf, params);
            if (test.hit && test.thit < tCurrent) {
                hit = true;
                t = test.thit;
                attributes.color = math::pacman::PacmanHitColor(test.normal, test.position);
                attributes.normal = procedurayNormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::Mandelbulb: {
            const math::Ray<float> localRay = procedurayLocalRay();
            const int iMax = pray::mandelbulbStepCount(
                math::mandelbulb::MandelbulbIterationCount(elapsedTime_, int(g.aabbCB.instanceIndex)), accuracy_);
            const math::mandelbulb::MandelbulbHit<float> test = math::mandelbulb::MandelbulbDistance(
                localRay.origin, localRay.direction, iMax, pray::mandelbulbParams<float>(accuracy_));
            if (test.hit && test.thit < tCurrent) {
                hit = true;
                t = test.thit;
                attributes.color = test.color;
                attributes.normal = procedurayNormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::Julia: {
            const math::Ray<float> localRay = procedurayLocalRay();
            const math::julia::JuliaHit<float> test =
                math::julia::JuliaDistance(localRay.origin, localRay.direction, pray::juliaParams<float>(accuracy_));
            const vec2 thit = test.resT;
            if (test.hit && thit.x < tCurrent) {
                hit = true;
                t = thit.x;
                attributes.normal = procedurayNormalToWorld(test.normal);
                attributes.color = vec4(thit, 0.0f, 0.0f);  // (t, iteration count) for the closest hit
            }
            break;
        }
        case Intersection::None: break;
    }
    // ReportHit accepts TMin <= t <= RayTCurrent.
    if (!hit || !(t >= tMin && t <= tCurrent)) return false;
    tHit = t;
    return true;
}

// ---- Ray generation, TraceRay, closest hits and misses ------------------------------------------------

uint64_t RawRenderer::render(uint32_t threads, std::vector<vec4>& image) const {
    image.assign(size_t(width_) * height_, vec4(0.0f));
    std::atomic<uint64_t> rays{0};
    tbb::task_arena arena{int(threads)};
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, height_, 8, 0, width_, 8), [&](const auto& r) {
            [[maybe_unused]] procedural::PrecisionScope<float> scope;  // float shader math flushes denormals
            PixelState px;
            px.dimensions = uvec2(width_, height_);
            for (uint32_t y = r.rows().begin(); y < r.rows().end(); ++y)
                for (uint32_t x = r.cols().begin(); x < r.cols().end(); ++x) {
                    px.index = uvec2(x, y);
                    vec3 origin, direction;
                    procedural::GenerateCameraRay(px.index, px.dimensions, cameraPosition_, projectionToWorld_, origin,
                                                  direction);
                    image[size_t(y) * width_ + x] = traceRadianceRay(origin, direction, 0, px);
                }
            rays += px.rays;
        });
    });
    throwIfFailed("rendering with raw Embree");
    return rays.load();
}

vec4 RawRenderer::traceRadianceRay(const vec3& origin, const vec3& direction, uint32_t currentRayRecursionDepth,
                                   PixelState& px) const {
    if (currentRayRecursionDepth >= maxDepth_) return vec4(0.0f);
    ++px.rays;
    RayContext context;
    rtcInitIntersectContext(&context.embree);
    RTCRayHit rayhit;
    rayhit.ray = RTCRay{origin.x, origin.y, origin.z, 0.0f, direction.x, direction.y, direction.z, 0.0f, kTMax,
                        0xFFFFFFFFu, 0, 0};
    rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context.embree, &rayhit);
    if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID)  // MyMissShader / Miss
        return library_ == Library::D3D12 ? d3d12::BackgroundColor : pray::kBackgroundColor;

    const RawGeometry& g = *geometries_[rayhit.hit.geomID];
    const RawHit hit{origin, direction, rayhit.ray.tfar, rayhit.hit.primID, context.attributes};
    const uint32_t recursionDepth = currentRayRecursionDepth + 1;  // the payload's recursionDepth
    switch (g.closestHit) {
        case ClosestHit::D3D12Triangle: return closestHitD3D12Triangle(g, hit, recursionDepth, px);
        case ClosestHit::D3D12AABB: return closestHitD3D12AABB(g, hit, recursionDepth, px);
        case ClosestHit::ProcedurayTriangle: return closestHitProcedurayTriangle(g, hit, recursionDepth, px);
        case ClosestHit::Pacman: return closestHitPacman(g, hit, recursionDepth, px);
        case ClosestHit::Mandelbulb: return closestHitMandelbulb(g, hit, recursionDepth, px);
        case ClosestHit::Julia: return closestHitJulia(g, hit, recursionDepth, px);
    }
    return vec4(0.0f);
}

// TMax 10000 as in both libraries; a hit anywhere is a shadow (no closest hit; the miss clears it).
bool RawRenderer::traceShadowRayAndReportIfHit(const vec3& origin, const vec3& direction,
                                               uint32_t currentRayRecursionDepth, PixelState& px) const {
    if (currentRayRecursionDepth >= maxDepth_) return false;
    if (!effects_.traceShadowRays) return false;
    ++px.rays;
    RayContext context;
    rtcInitIntersectContext(&context.embree);
    RTCRay ray{origin.x, origin.y, origin.z, 0.0f, direction.x, direction.y, direction.z, 0.0f, kTMax,
               0xFFFFFFFFu, 0, 0};
    rtcOccluded1(scene_, &context.embree, &ray);
    return ray.tfar < 0.0f;
}

bool RawRenderer::traceShadowRayTowardsLight(const vec3& hitPosition, uint32_t recursionDepth, PixelState& px) const {
    return traceShadowRayAndReportIfHit(hitPosition, hlsl::normalize(lightPosition_ - hitPosition), recursionDepth, px);
}

// reflectanceCoef·(Fresnel, 1)·(reflection ray colour), the reflection ray leaving HitWorldPosition().
vec4 RawRenderer::reflectedColor(const RawHit& hit, const vec3& normal, float reflectanceCoef, const vec3& f0,
                                 uint32_t recursionDepth, PixelState& px) const {
    const vec3 D = hit.direction;
    const vec4 reflectionColor = traceRadianceRay(hit.position(), hlsl::reflect(D, normal), recursionDepth, px);
    const vec3 fresnelR = procedural::FresnelReflectanceSchlick(D, normal, f0);
    return reflectanceCoef * vec4(fresnelR, 1.0f) * reflectionColor;
}

// The normal of the triangle's first vertex, read as the closest hits read it: g_indices at PrimitiveIndex() x 6
// bytes (Load2 of the aligned dwords), then g_vertices[index].normal; reads past the end give 0.
vec3 RawRenderer::storedVertexNormal(uint32_t primitiveIndex) const {
    const uint32_t baseIndex = primitiveIndex * 3 * 2;
    const uvec3 indices = procedural::Load3x16BitIndices(baseIndex, indexBytes_.data(), indexBytes_.size());
    const size_t offset = size_t(indices[0]) * sizeof(procedural::Vertex) + offsetof(procedural::Vertex, normal);
    vec3 normal(0.0f);
    if (offset + sizeof normal <= vertexBytes_.size())
        std::memcpy(&normal, vertexBytes_.data() + offset, sizeof normal);
    return normal;
}

vec4 RawRenderer::closestHitD3D12Triangle(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                          PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 triangleNormal = storedVertexNormal(hit.primitiveIndex);
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    const float checkers = d3d12::AnalyticalCheckersTexture(hit.position(), triangleNormal, cameraPosition_,
                                                            projectionToWorld_, px.index, px.dimensions);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected = reflectedColor(hit, triangleNormal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo),
                                   recursionDepth, px);
    const vec4 phongColor = d3d12::CalculatePhongLighting(
        d3d12CB_, l_materialCB.albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef,
        l_materialCB.specularCoef, l_materialCB.specularPower, hit.position(), hit.direction);
    const vec4 color = checkers * (phongColor + reflected);
    return d3d12::ApplyVisibilityFalloff(color, hit.t);
}

vec4 RawRenderer::closestHitD3D12AABB(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                      PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 normal = hit.attributes.normal;
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected =
            reflectedColor(hit, normal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo), recursionDepth, px);
    const vec4 phongColor = d3d12::CalculatePhongLighting(
        d3d12CB_, l_materialCB.albedo, normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef,
        l_materialCB.specularPower, hit.position(), hit.direction);
    const vec4 color = phongColor + reflected;
    return d3d12::ApplyVisibilityFalloff(color, hit.t);
}

// The Proceduray closest hits add the payload's colour, still the vec4(0) TraceRadianceRay starts it with.
vec4 RawRenderer::closestHitProcedurayTriangle(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                               PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 triangleNormal = -storedVertexNormal(hit.primitiveIndex);
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    const vec4 albedo = l_materialCB.albedo;
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected = reflectedColor(hit, triangleNormal, l_materialCB.reflectanceCoef, vec3(albedo), recursionDepth, px);
    const vec4 phongColor = pray::CalculatePhongLighting(
        procedurayCB_, albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef,
        l_materialCB.specularPower, hit.position(), hit.direction);
    vec4 color = phongColor + reflected;
    color += vec4(0.0f);
    return color;
}

vec4 RawRenderer::closestHitPacman(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                   PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 normal = hit.attributes.normal;
    const vec4 albedo = l_materialCB.albedo;
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected = reflectedColor(hit, normal, l_materialCB.reflectanceCoef, vec3(albedo), recursionDepth, px);
    const vec4 phongColor = pray::CalculatePhongLighting(
        procedurayCB_, albedo, normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef,
        l_materialCB.specularPower, hit.position(), hit.direction);
    vec4 color = hit.attributes.color * (phongColor + reflected);
    color += vec4(0.0f);
    return color;
}

vec4 RawRenderer::closestHitMandelbulb(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                       PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 normal = hit.attributes.normal;
    vec4 color = pray::MandelbulbSurfaceColor(hit.direction, normal, hit.attributes.color);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected =
            reflectedColor(hit, normal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo), recursionDepth, px);
    color = color + reflected;
    color += vec4(0.0f);
    return color;
}

vec4 RawRenderer::closestHitJulia(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                  PixelState& px) const {
    const vec3 normal = hit.attributes.normal;
    const bool shadowRayHit = false;  // commented out in the HLSL
    // H1: with the local-unit t this point lies near the object-space ray origin.
    const vec3 objectRayOrigin = g.worldToObject.transformPoint(hit.origin);
    const vec3 objectRayDirection = g.worldToObject.transformVector(hit.direction);
    const vec3 pos = objectRayOrigin + hit.t * objectRayDirection;
    vec4 albedo = vec4(3.5f * pray::colorSurface(pos, vec2(hit.attributes.color)), 1.0f);
    if (recursionDepth == maxDepth_ - 1) albedo += 1.65f * hlsl::step(0.0f, hlsl::abs(pos.y));
    const float reflecCoef = 0.1f;
    vec4 reflected(0.0f);
    if (reflecCoef > 0.001f) reflected = reflectedColor(hit, normal, reflecCoef, vec3(albedo), recursionDepth, px);
    const float diffuseCoef = 0.6f, specularCoef = 0.08f, specularPower = 0.2f;
    const vec4 phongColor = pray::CalculatePhongLighting(procedurayCB_, albedo, normal, shadowRayHit, diffuseCoef,
                                                         specularCoef, specularPower, hit.position(), hit.direction);
    vec4 color = phongColor + reflected;
    color += vec4(0.0f);
    return color;
}

// ---- The benchmark harness ------------------------------------------------------------------------------

struct FrameSize {
    uint32_t width = 320, height = 180;
};
FrameSize gSize;

struct ImageComparison {
    float maxAbsDifference = 0.0f;  // any channel, as the shaders wrote it (both NaN counts as equal)
    uint64_t differingPixels = 0;   // R8G8B8A8_UNORM values more than 1/255 apart in some channel
    double differingFraction = 0.0;
    uint64_t refrayRays = 0, rawRays = 0;
};

// The value an R8G8B8A8_UNORM target holds, before the x255: NaN -> 0, clamp to [0, 1].
float unorm(float v) { return std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f); }

ImageComparison compareImages(const Image& refray, const std::vector<vec4>& raw) {
    ImageComparison c;
    for (size_t i = 0; i < raw.size(); ++i) {
        const vec4& a = refray.pixels()[i];
        const vec4& b = raw[i];
        bool differs = false;
        for (glm::length_t k = 0; k < 4; ++k) {
            if (!(std::isnan(a[k]) && std::isnan(b[k]))) {
                const float d = std::fabs(a[k] - b[k]);
                c.maxAbsDifference = std::isnan(d) ? INFINITY : std::max(c.maxAbsDifference, d);
            }
            if (std::fabs(unorm(a[k]) - unorm(b[k])) > 1.0f / 255.0f) differs = true;
        }
        if (differs) ++c.differingPixels;
    }
    c.differingFraction = raw.empty() ? 0.0 : double(c.differingPixels) / double(raw.size());
    return c;
}

// One reference scene: its refray Scene and its raw renderer, built once, compared once.
class SceneBench {
public:
    SceneBench(const std::string& name, const std::filesystem::path& file)
        : name_(name), desc_(scenes::loadSceneFile(file)), refray_(desc_), raw_(desc_, gSize.width, gSize.height) {
        settings_.width = gSize.width;
        settings_.height = gSize.height;
        compare();
    }

    uint64_t renderRefray(uint32_t threads) {
        settings_.threads = threads;
        return refray_.render(settings_).dispatch.stats.raysTraced;
    }
    uint64_t renderRaw(uint32_t threads) { return raw_.render(threads, rawImage_); }
    const ImageComparison& comparison() const { return comparison_; }

private:
    void compare() {
        settings_.threads = 2;
        const scenes::RenderResult reference = refray_.render(settings_);
        const uint64_t rawRays = raw_.render(2, rawImage_);
        comparison_ = compareImages(reference.image, rawImage_);
        comparison_.refrayRays = reference.dispatch.stats.raysTraced;
        comparison_.rawRays = rawRays;
        std::fprintf(stderr,
                     "%s %ux%u: max |refray - raw| = %.9g, pixels differing by more than 1/255: %llu (%.4f%%); "
                     "rays: refray %llu, raw %llu\n",
                     name_.c_str(), gSize.width, gSize.height, double(comparison_.maxAbsDifference),
                     static_cast<unsigned long long>(comparison_.differingPixels),
                     100.0 * comparison_.differingFraction,
                     static_cast<unsigned long long>(comparison_.refrayRays),
                     static_cast<unsigned long long>(comparison_.rawRays));
        if (const char* dir = std::getenv("REFRAY_BENCH_IMAGES")) {
            Image raw(gSize.width, gSize.height);
            raw.pixels() = rawImage_;
            const std::string base = std::string(dir) + "/" + name_ + "-" + std::to_string(gSize.width) + "x" +
                                     std::to_string(gSize.height);
            writeImage(base + "-refray.exr", reference.image);
            writeImage(base + "-raw.exr", raw);
        }
    }

    std::string name_;
    scenes::SceneDesc desc_;
    scenes::Scene refray_;
    RawRenderer raw_;
    scenes::RenderSettings settings_;
    std::vector<vec4> rawImage_;
    ImageComparison comparison_;
};

// Built on first use (outside any timing) and kept for the run; a failure is kept as its message.
SceneBench* sceneBench(benchmark::State& state, const std::string& name) {
    static std::map<std::string, std::unique_ptr<SceneBench>> benches;
    static std::map<std::string, std::string> errors;
    if (!benches.count(name) && !errors.count(name)) {
        try {
            benches[name] = std::make_unique<SceneBench>(name, std::filesystem::path(REFRAY_SOURCE_DIR) / "scenes" /
                                                                   (name + ".json"));
        } catch (const std::exception& e) {
            errors[name] = e.what();
        }
    }
    if (auto it = errors.find(name); it != errors.end()) {
        state.SkipWithError(it->second.c_str());
        return nullptr;
    }
    SceneBench* bench = benches[name].get();
    const ImageComparison& c = bench->comparison();
    if (c.differingFraction > 0.01) {
        static std::string message;
        message = "the raw renderer's image differs from refray's in " + std::to_string(100.0 * c.differingFraction) +
                  "% of the pixels (over 1%): the harness is wrong, nothing is timed";
        state.SkipWithError(message.c_str());
        return nullptr;
    }
    return bench;
}

void addImageCounters(benchmark::State& state, const ImageComparison& c) {
    state.counters["img_maxdiff"] = c.maxAbsDifference;
    state.counters["img_px>1/255"] = c.differingFraction;
}

void BM_Refray(benchmark::State& state, const std::string& name, uint32_t threads) {
    SceneBench* bench = sceneBench(state, name);
    if (!bench) return;
    uint64_t rays = 0;
    for (auto _ : state) rays += bench->renderRefray(threads);
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}

void BM_RawEmbree(benchmark::State& state, const std::string& name, uint32_t threads) {
    SceneBench* bench = sceneBench(state, name);
    if (!bench) return;
    uint64_t rays = 0;
    for (auto _ : state) rays += bench->renderRaw(threads);
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
    addImageCounters(state, bench->comparison());
}

// Both renders in one body, alternating which goes first, each timed on its own.
void BM_Ratio(benchmark::State& state, const std::string& name, uint32_t threads) {
    SceneBench* bench = sceneBench(state, name);
    if (!bench) return;
    using Clock = std::chrono::steady_clock;
    double refraySeconds = 0.0, rawSeconds = 0.0;
    uint64_t refrayRays = 0, rawRays = 0;
    bool refrayFirst = true;
    for (auto _ : state) {
        for (int pass = 0; pass < 2; ++pass) {
            const bool refray = (pass == 0) == refrayFirst;
            const auto start = Clock::now();
            if (refray) refrayRays += bench->renderRefray(threads);
            else rawRays += bench->renderRaw(threads);
            const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
            (refray ? refraySeconds : rawSeconds) += seconds;
        }
        refrayFirst = !refrayFirst;
    }
    const double iterations = double(state.iterations());
    state.counters["refray_ms"] = 1e3 * refraySeconds / iterations;
    state.counters["raw_ms"] = 1e3 * rawSeconds / iterations;
    state.counters["ratio"] = refraySeconds / rawSeconds;
    state.counters["refray_rays/s"] = double(refrayRays) / refraySeconds;
    state.counters["raw_rays/s"] = double(rawRays) / rawSeconds;
    addImageCounters(state, bench->comparison());
}

bool parseSize(const std::string& text, FrameSize& size) {
    unsigned w = 0, h = 0;
    char x = 0;
    if (std::sscanf(text.c_str(), "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w == 0 || h == 0) return false;
    size = {w, h};
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (const char* env = std::getenv("REFRAY_BENCH_SIZE"); env && !parseSize(env, gSize)) {
        std::fprintf(stderr, "REFRAY_BENCH_SIZE must be WxH, got '%s'\n", env);
        return 1;
    }
    // --size=WxH, taken out before Google Benchmark reads the rest.
    int kept = 1;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.rfind("--size=", 0) == 0) {
            if (!parseSize(arg.substr(7), gSize)) {
                std::fprintf(stderr, "--size must be WxH, got '%s'\n", arg.c_str());
                return 1;
            }
            continue;
        }
        argv[kept++] = argv[i];
    }
    argc = kept;

    for (const std::string name : {"d3d12-procedural-geometry", "proceduray-mandel-julia-pac"})
        for (uint32_t threads : {1u, 2u}) {
            const std::string suffix = "/" + name + "/threads:" + std::to_string(threads);
            benchmark::RegisterBenchmark(("BM_Refray" + suffix).c_str(),
                                         [name, threads](benchmark::State& s) { BM_Refray(s, name, threads); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            benchmark::RegisterBenchmark(("BM_RawEmbree" + suffix).c_str(),
                                         [name, threads](benchmark::State& s) { BM_RawEmbree(s, name, threads); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            // Several alternations per repetition, so one slow frame weighs less in the ratio.
            benchmark::RegisterBenchmark(("BM_Ratio" + suffix).c_str(),
                                         [name, threads](benchmark::State& s) { BM_Ratio(s, name, threads); })
                ->Unit(benchmark::kMillisecond)
                ->MinTime(2.0)
                ->UseRealTime();
        }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
