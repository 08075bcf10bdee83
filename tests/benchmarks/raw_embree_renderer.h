// The raw-Embree renderer of reference_overhead_bench.cpp: one flat Embree scene of a reference scene file's
// geometry, with the ports' intersection shaders, closest hits and misses called directly (see the comment at the
// top of reference_overhead_bench.cpp). Built in raw_embree_renderer.cpp, rendered in raw_embree_shaders.cpp.
#pragma once

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

namespace refray::bench {

using namespace refray;
namespace d3d12 = refray::procedural::d3d12;
namespace pray = refray::procedural::proceduray;
namespace math = refray::procedural::math;
namespace hlsl = refray::procedural::hlsl;
using procedural::Float4x4;
using procedural::PrimitiveConstantBuffer;
using procedural::PrimitiveInstanceConstantBuffer;

inline constexpr float kTMax = 10000.0f;  // both libraries' TraceRay TMax

[[noreturn]] inline void fail(const std::string& message) { throw std::runtime_error(message); }

// ---- The raw renderer ---------------------------------------------------------------------------------

enum class Library { D3D12, Proceduray };

// The port function a geometry's radiance hit group names.
enum class Intersection { None, D3D12Analytic, D3D12Volumetric, D3D12SignedDistance, Julia, Pacman, Mandelbulb };
enum class ClosestHit { D3D12Triangle, D3D12AABB, ProcedurayTriangle, Julia, Pacman, Mandelbulb };

inline Intersection intersectionOf(const std::string& name) {
    if (name == "MyIntersectionShader_AnalyticPrimitive") return Intersection::D3D12Analytic;
    if (name == "MyIntersectionShader_VolumetricPrimitive") return Intersection::D3D12Volumetric;
    if (name == "MyIntersectionShader_SignedDistancePrimitive") return Intersection::D3D12SignedDistance;
    if (name == "Intersection_Julia") return Intersection::Julia;
    if (name == "Intersection_Pacman") return Intersection::Pacman;
    if (name == "Intersection_Mandelbulb") return Intersection::Mandelbulb;
    fail("raw renderer: unknown intersection shader '" + name + "'");
}

inline ClosestHit closestHitOf(const std::string& name) {
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
inline constexpr bool kCullBackFacing = true;

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
inline bool boxOverlaps(const vec3& lo, const vec3& hi, const vec3& origin, const vec3& direction, float tMin, float tMax) {
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
inline std::pair<Float4x4, Float4x4> primitiveTransform(const scenes::PrimitiveTransformDesc& p, double time) {
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

}  // namespace refray::bench
