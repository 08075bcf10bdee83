#include "emulator/embree_bridge.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <exception>
#include <mutex>

#include <embree3/rtcore.h>

#include "core/error.h"
#include "emulator/intersection.h"

namespace refray::dxr::detail {

struct EmbreeDeviceImpl {
    RTCDevice device = nullptr;
    std::mutex errorMutex;
    std::string firstError;
};

namespace {

void onEmbreeError(void* userPtr, RTCError code, const char* message) {
    auto* impl = static_cast<EmbreeDeviceImpl*>(userPtr);
    std::lock_guard lock(impl->errorMutex);
    if (impl->firstError.empty())
        impl->firstError = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "(no message)");
}

void throwIfEmbreeFailed(EmbreeDeviceImpl& impl, const char* what) {
    std::lock_guard lock(impl.errorMutex);
    if (!impl.firstError.empty()) {
        std::string message = std::string(what) + ": " + impl.firstError;
        impl.firstError.clear();
        throw Error(message);
    }
}

}  // namespace

EmbreeDevice::EmbreeDevice() : impl_(std::make_unique<EmbreeDeviceImpl>()) {
    impl_->device = rtcNewDevice("verbose=0");
    REFRAY_CHECK(impl_->device, "cannot create an Embree device (error " << int(rtcGetDeviceError(nullptr)) << ")");
    rtcSetDeviceErrorFunction(impl_->device, onEmbreeError, impl_.get());
}

EmbreeDevice::~EmbreeDevice() {
    if (impl_->device) rtcReleaseDevice(impl_->device);
}

// What a user geometry's callbacks need: the built geometry and its index.
struct UserGeometry {
    const BuiltGeometry* geometry = nullptr;
    uint32_t geometryIndex = 0;
};

EmbreeScene::~EmbreeScene() {
    if (scene) rtcReleaseScene(static_cast<RTCScene>(scene));
}

namespace {

// What one ray of a gather carries through Embree's callbacks.
struct RayGather {
    const GatherRequest* request = nullptr;
    float nearestCommit = INFINITY;  // Closest: the smallest t of a triangle sure to commit
    std::exception_ptr error;        // the first exception a callback caught for this ray (style rule 9)
    // The object-space ray of the instance met last: its primitives share it.
    uint32_t objectRayInstance = ~0u;
    vec3 objectRayOrigin{0.0f}, objectRayDirection{0.0f};
};

// The extended intersect context (Embree's idiom): per-ray state rides along, never globals. A packet's rays are
// told apart by their ray id (the index into `rays`), not by their place in a callback's packet: Embree may call
// back with another packet size or order than it was given.
struct GatherContext {
    RTCIntersectContext embree;  // must be first
    RayGather* rays = nullptr;   // one, or a packet's
};

// Embree's own intervals are widened a little: the exact tests decide, Embree only culls.
float widenedFar(float t) { return std::isinf(t) ? t : t + std::fabs(t) * 1e-5f + 1e-30f; }

// Enlarge bounds by a relative margin so Embree's float traversal never culls a box
// that refray's exact test would touch (BLAS-7 allows conservative boxes).
void enlarge(RTCBounds& b) {
    const float ex = b.upper_x - b.lower_x, ey = b.upper_y - b.lower_y, ez = b.upper_z - b.lower_z;
    const float scale = std::max({std::fabs(b.lower_x), std::fabs(b.lower_y), std::fabs(b.lower_z), std::fabs(b.upper_x),
                                  std::fabs(b.upper_y), std::fabs(b.upper_z), ex, ey, ez});
    const float margin = scale * 1e-5f + 1e-30f;
    b.lower_x -= margin;
    b.lower_y -= margin;
    b.lower_z -= margin;
    b.upper_x += margin;
    b.upper_y += margin;
    b.upper_z += margin;
}

void boundsCallback(const RTCBoundsFunctionArguments* args) {
    const auto* user = static_cast<const UserGeometry*>(args->geometryUserPtr);
    const BuiltGeometry& g = *user->geometry;
    RTCBounds& b = *args->bounds_o;
    const uint32_t prim = args->primID;
    if (!g.active[prim]) {
        // Inactive (DEGEN-1): an empty box, which Embree's builder drops.
        b.lower_x = b.lower_y = b.lower_z = 1.0f;
        b.upper_x = b.upper_y = b.upper_z = -1.0f;
        return;
    }
    if (g.type == GeometryType::Triangles) {
        const vec3* v = &g.triangleVertices[size_t(prim) * 3];
        const vec3 lo = glm::min(v[0], glm::min(v[1], v[2])), hi = glm::max(v[0], glm::max(v[1], v[2]));
        b.lower_x = lo.x, b.lower_y = lo.y, b.lower_z = lo.z;
        b.upper_x = hi.x, b.upper_y = hi.y, b.upper_z = hi.z;
    } else {
        const RaytracingAABB& a = g.aabbs[prim];
        b.lower_x = a.MinX, b.lower_y = a.MinY, b.lower_z = a.MinZ;
        b.upper_x = a.MaxX, b.upper_y = a.MaxY, b.upper_z = a.MaxZ;
    }
    enlarge(b);
}

// refray's own object-space ray (TRV-8) of `gather`'s ray in instance `instanceIndex`: the exact inverse, not
// Embree's; once per instance met (the instance's primitives share it). Returned in registers on the way to the
// candidate (a copy read back from the gather was read with wide loads across its narrow stores).
[[gnu::always_inline]] inline void objectRay(RayGather& gather, uint32_t instanceIndex, vec3& origin, vec3& direction) {
    if (gather.objectRayInstance != instanceIndex) {
        const GatherRequest& req = *gather.request;
        const BuiltInstance& inst = req.tlas->instances()[instanceIndex];
        origin = inst.worldToObject.transformPoint(req.origin);
        direction = inst.worldToObject.transformVector(req.direction);
        gather.objectRayInstance = instanceIndex;
        gather.objectRayOrigin = origin;
        gather.objectRayDirection = direction;
    } else {
        origin = gather.objectRayOrigin;
        direction = gather.objectRayDirection;
    }
}

// Whether a triangle hit at t lies in the request's [tMin, tMax].
bool inInterval(const GatherRequest& req, float t) { return t >= req.tMin && t <= req.tMax; }

// `c` filled for a triangle hit `hit` of the ray of `req`, or false when its t lies outside [tMin, tMax].
[[gnu::always_inline]] inline bool triangleCandidate(const GatherRequest& req, const TriangleIntersection& hit,
                                                     Candidate& c) {
    if (!inInterval(req, hit.t)) return false;
    c.t = c.key = hit.t;
    c.barycentrics = hit.barycentrics;
    c.procedural = false;
    return true;
}

// refray's exact test of one primitive Embree reports: the candidate, or nothing if the ray misses it. `c` arrives
// value-initialised (in place in the request's list: a candidate put together on the stack and copied out was read
// back with wide loads across its narrow stores, a store-forwarding stall per candidate).
bool exactCandidate(RayGather& gather, uint32_t instanceIndex, void* geometryUserPtr, uint32_t prim, Candidate& c) {
    const GatherRequest& req = *gather.request;
    const auto* user = static_cast<const UserGeometry*>(geometryUserPtr);
    const BuiltGeometry& g = *user->geometry;
    if (!g.active[prim]) return false;
    const bool triangles = g.type == GeometryType::Triangles;
    if (triangles ? req.skipTriangles : req.skipProcedural) return false;

    vec3 objectOrigin, objectDirection;
    objectRay(gather, instanceIndex, objectOrigin, objectDirection);
    c.instanceIndex = instanceIndex;
    c.geometryIndex = user->geometryIndex;
    c.primitiveIndex = prim;
    c.objectRayOrigin = objectOrigin;
    c.objectRayDirection = objectDirection;

    if (triangles) {
        const vec3* v = &g.triangleVertices[size_t(prim) * 3];
        TriangleIntersection hit;
        return intersectTriangle(objectOrigin, objectDirection, v[0], v[1], v[2], req.alternateEdgeRule, hit) &&
               triangleCandidate(req, hit, c);
    }
    SlabInterval slab;
    if (!intersectAABB(objectOrigin, objectDirection, g.aabbs[prim], req.tMin, req.tMax, slab)) return false;
    c.procedural = true;
    c.key = slab.tEnter;
    return true;
}

// Closest, for the candidate just added to the ray's list: dropped where it starts beyond the nearest sure commit
// (the ordered loop would skip it, TRV-2); a triangle sure to commit shrinks Embree's tfar to its t.
void keepClosest(RayGather& gather, float& tfar) {
    const GatherRequest& req = *gather.request;
    std::vector<Candidate>& out = *req.out;
    const Candidate& c = out.back();
    if (c.key > gather.nearestCommit) {
        out.pop_back();
        return;
    }
    if (!c.procedural && req.tMin < c.t && c.t < req.tMax && req.commitsSurely(req.user, c)) {
        gather.nearestCommit = c.t;
        tfar = widenedFar(c.t);
    }
}

// All and Closest: collect. Closest also shrinks Embree's tfar to the nearest triangle sure to commit.
void gatherPrimitive(RayGather& gather, uint32_t instanceIndex, void* geometryUserPtr, uint32_t prim, float& tfar) {
    const GatherRequest& req = *gather.request;
    std::vector<Candidate>& out = *req.out;
    Candidate& c = out.emplace_back();
    if (!exactCandidate(gather, instanceIndex, geometryUserPtr, prim, c)) {
        out.pop_back();
        return;
    }
    if (req.mode == GatherMode::Closest) keepClosest(gather, tfar);
}

// A triangle met by a packet of rays: the exact test of all its rays at once (intersectTriangleLanes; a ray through an
// edge or vertex of it takes the one-ray test), then each ray's candidate as gatherPrimitive makes it, in the packet's
// order. Every ray's candidates are those it gets alone.
void gatherTrianglePacket(GatherContext& ctx, const RTCIntersectFunctionNArguments* args, RTCRayN* ray,
                          uint32_t instanceIndex, const UserGeometry& user) {
    const BuiltGeometry& g = *user.geometry;
    const uint32_t prim = args->primID;
    const vec3* v = &g.triangleVertices[size_t(prim) * 3];
    const unsigned N = args->N;
    RayLanes lanes;
    std::array<RayGather*, RayLanes::kCount> gathers{};
    uint32_t active = 0;
    int first = -1;
    for (unsigned i = 0; i < N; ++i) {
        if (!args->valid[i]) continue;
        RayGather& gather = ctx.rays[RTCRayN_id(ray, N, i)];
        if (gather.error || gather.request->skipTriangles) continue;  // FLAG-12: no candidate
        vec3 o, d;
        objectRay(gather, instanceIndex, o, d);
        lanes.ox[i] = o.x, lanes.oy[i] = o.y, lanes.oz[i] = o.z;
        lanes.dx[i] = d.x, lanes.dy[i] = d.y, lanes.dz[i] = d.z;
        gathers[i] = &gather;
        active |= 1u << i;
        if (first < 0) first = int(i);
    }
    if (!active) return;
    for (int i = 0; i < RayLanes::kCount; ++i)  // the lanes without a ray: the first ray's, never read
        if (!(active >> i & 1u)) {
            lanes.ox[i] = lanes.ox[first], lanes.oy[i] = lanes.oy[first], lanes.oz[i] = lanes.oz[first];
            lanes.dx[i] = lanes.dx[first], lanes.dy[i] = lanes.dy[first], lanes.dz[i] = lanes.dz[first];
        }
    intersectTriangleLanes(v[0], v[1], v[2], active, lanes);
    for (uint32_t rest = lanes.hit | lanes.exact; rest; rest &= rest - 1) {
        const int i = std::countr_zero(rest);
        RayGather& gather = *gathers[size_t(i)];
        const GatherRequest& req = *gather.request;
        float& tfar = RTCRayN_tfar(ray, N, unsigned(i));
        try {
            const vec3 o(lanes.ox[i], lanes.oy[i], lanes.oz[i]), d(lanes.dx[i], lanes.dy[i], lanes.dz[i]);
            TriangleIntersection hit;
            if (lanes.exact >> i & 1u) {
                if (!intersectTriangle(o, d, v[0], v[1], v[2], req.alternateEdgeRule, hit)) continue;
            } else {
                hit.t = lanes.t[i];
                hit.barycentrics = vec2(lanes.b1[i], lanes.b2[i]);
            }
            if (!inInterval(req, hit.t)) continue;
            Candidate& c = req.out->emplace_back();
            c.instanceIndex = instanceIndex;
            c.geometryIndex = user.geometryIndex;
            c.primitiveIndex = prim;
            c.objectRayOrigin = o;
            c.objectRayDirection = d;
            triangleCandidate(req, hit, c);
            if (req.mode == GatherMode::Closest) keepClosest(gather, tfar);
        } catch (...) {
            gather.error = std::current_exception();
            tfar = -INFINITY;
        }
    }
}

// Embree swallows exceptions, so the callbacks catch everything, stop the ray's traversal and leave the error
// for the gather to rethrow once Embree has returned.
void intersectCallback(const RTCIntersectFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<GatherContext*>(args->context);
    RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
    const uint32_t instanceIndex = ctx->embree.instID[0];
    const auto* user = static_cast<const UserGeometry*>(args->geometryUserPtr);
    if (args->N > 1 && args->N <= unsigned(RayLanes::kCount) && user->geometry->type == GeometryType::Triangles &&
        user->geometry->active[args->primID])
        return gatherTrianglePacket(*ctx, args, ray, instanceIndex, *user);
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        RayGather& gather = ctx->rays[RTCRayN_id(ray, args->N, i)];
        if (gather.error) continue;
        float& tfar = RTCRayN_tfar(ray, args->N, i);
        try {
            gatherPrimitive(gather, instanceIndex, args->geometryUserPtr, args->primID, tfar);
        } catch (...) {
            gather.error = std::current_exception();
            tfar = -INFINITY;
        }
    }
}

// FirstHit (one ray): process each candidate at once; tfar = -inf tells Embree the ray is done.
void occludedCallback(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    auto* ctx = reinterpret_cast<GatherContext*>(args->context);
    RayGather& gather = ctx->rays[0];
    if (gather.error) return;
    try {
        const GatherRequest& req = *gather.request;
        Candidate c;
        if (exactCandidate(gather, ctx->embree.instID[0], args->geometryUserPtr, args->primID, c) &&
            req.onCandidate(req.user, c))
            RTCRayN_tfar(args->ray, args->N, 0) = -INFINITY;
    } catch (...) {
        gather.error = std::current_exception();
        RTCRayN_tfar(args->ray, args->N, 0) = -INFINITY;
    }
}

}  // namespace

std::unique_ptr<EmbreeScene> buildBottomLevelScene(EmbreeDevice& device, const BottomLevelAS& blas) {
    auto& impl = device.impl();
    auto out = std::make_unique<EmbreeScene>();
    RTCScene scene = rtcNewScene(impl.device);
    out->scene = scene;
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    const auto& geometries = blas.geometries();
    for (uint32_t i = 0; i < geometries.size(); ++i) {
        auto user = std::make_unique<UserGeometry>();
        user->geometry = &geometries[i];
        user->geometryIndex = i;
        RTCGeometry geom = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geom, geometries[i].primitiveCount());
        rtcSetGeometryMask(geom, 0xFFFFFFFFu);
        rtcSetGeometryUserData(geom, user.get());
        rtcSetGeometryBoundsFunction(geom, boundsCallback, nullptr);
        rtcSetGeometryIntersectFunction(geom, intersectCallback);
        rtcSetGeometryOccludedFunction(geom, occludedCallback);
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(scene, geom, i);
        rtcReleaseGeometry(geom);
        out->userGeometries.push_back(std::move(user));
    }
    rtcCommitScene(scene);
    throwIfEmbreeFailed(impl, "building a bottom-level acceleration structure");
    return out;
}

std::unique_ptr<EmbreeScene> buildTopLevelScene(EmbreeDevice& device, const TopLevelAS& tlas) {
    auto& impl = device.impl();
    auto out = std::make_unique<EmbreeScene>();
    RTCScene scene = rtcNewScene(impl.device);
    out->scene = scene;
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    const auto& instances = tlas.instances();
    for (uint32_t i = 0; i < instances.size(); ++i) {
        const BuiltInstance& inst = instances[i];
        if (!inst.blas) continue;  // inactive: keeps its index, never intersected (INST-6, DEGEN-4)
        RTCGeometry geom = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(geom, static_cast<RTCScene>(inst.blas->embree().scene));
        rtcSetGeometryMask(geom, inst.desc.InstanceMask);
        rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &inst.desc.Transform[0][0]);
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(scene, geom, i);
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(scene);
    throwIfEmbreeFailed(impl, "building a top-level acceleration structure");
    return out;
}

namespace {

// Ray i of an N-ray packet (N = 1: a single RTCRay, whose fields lie as a packet of one) for `request`, with id i.
void setRay(RTCRayN* ray, unsigned N, unsigned i, const GatherRequest& request) {
    RTCRayN_org_x(ray, N, i) = request.origin.x;
    RTCRayN_org_y(ray, N, i) = request.origin.y;
    RTCRayN_org_z(ray, N, i) = request.origin.z;
    RTCRayN_dir_x(ray, N, i) = request.direction.x;
    RTCRayN_dir_y(ray, N, i) = request.direction.y;
    RTCRayN_dir_z(ray, N, i) = request.direction.z;
    RTCRayN_tnear(ray, N, i) = std::max(0.0f, request.tMin - (std::fabs(request.tMin) * 1e-5f + 1e-30f));
    RTCRayN_tfar(ray, N, i) = widenedFar(request.tMax);
    RTCRayN_time(ray, N, i) = 0.0f;
    RTCRayN_mask(ray, N, i) = request.instanceInclusionMask & 0xFF;
    RTCRayN_id(ray, N, i) = i;
    RTCRayN_flags(ray, N, i) = 0;
}

// After the traversal: Closest drops the candidates that start beyond the nearest sure commit found in the end (the
// ordered loop would skip them, TRV-2), so that a ray's candidates do not depend on the order in which Embree met
// them (one ray or a packet); then what a callback threw is rethrown.
void finishGather(RayGather& gather) {
    const GatherRequest& req = *gather.request;
    if (req.mode == GatherMode::Closest && gather.nearestCommit < INFINITY)
        std::erase_if(*req.out, [&](const Candidate& c) { return c.key > gather.nearestCommit; });
    if (gather.error) std::rethrow_exception(gather.error);
}

// `request` as one ray (ray id 0 of ctx.rays): rtcOccluded1 for FirstHit, else rtcIntersect1.
void traceOne(GatherContext& ctx, const GatherRequest& request) {
    RTCRayHit rayhit;
    setRay(reinterpret_cast<RTCRayN*>(&rayhit.ray), 1, 0, request);
    rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    RTCScene scene = static_cast<RTCScene>(request.tlas->embree().scene);
    if (request.mode == GatherMode::FirstHit) rtcOccluded1(scene, &ctx.embree, &rayhit.ray);
    else rtcIntersect1(scene, &ctx.embree, &rayhit);
}

}  // namespace

void gatherCandidates(const GatherRequest& request) {
    RayGather gather;
    gather.request = &request;
    GatherContext ctx;
    rtcInitIntersectContext(&ctx.embree);
    ctx.rays = &gather;
    traceOne(ctx, request);
    finishGather(gather);
}

namespace {

// The rays of `rays` (requests set) as one Embree packet of K rays (K = 4, 8 or 16), the first ones valid.
template <unsigned K, class RayHitK, class Intersect>
void tracePacket(GatherContext& ctx, const TopLevelAS& tlas, size_t count, Intersect intersect) {
    alignas(64) RayHitK rayhit;
    alignas(64) std::array<int, K> valid{};
    RTCRayN* ray = reinterpret_cast<RTCRayN*>(&rayhit.ray);
    for (size_t i = 0; i < count; ++i) {
        setRay(ray, K, unsigned(i), *ctx.rays[i].request);
        rayhit.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rayhit.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        valid[i] = -1;
    }
    intersect(valid.data(), static_cast<RTCScene>(tlas.embree().scene), &ctx.embree, &rayhit);
}

}  // namespace

void gatherCandidatesPacket(std::span<const GatherRequest* const> requests, std::span<std::exception_ptr> errors) {
    REFRAY_ASSERT(requests.size() <= size_t(kMaxGatherPacket) && errors.size() == requests.size(),
                  "a gather packet of " << requests.size() << " rays");
    if (requests.empty()) return;
    std::array<RayGather, kMaxGatherPacket> rays;
    GatherContext ctx;
    rtcInitIntersectContext(&ctx.embree);
    ctx.rays = rays.data();
    const TopLevelAS& tlas = *requests[0]->tlas;
    for (size_t i = 0; i < requests.size(); ++i) {
        REFRAY_ASSERT(requests[i]->tlas == &tlas && requests[i]->mode != GatherMode::FirstHit,
                      "a gather packet's rays share one TLAS and take no FirstHit");
        rays[i].request = requests[i];
    }
    // The narrowest packet that holds the rays.
    const size_t n = requests.size();
    if (n == 1) {
        traceOne(ctx, *requests[0]);
    } else if (n <= 4) {
        tracePacket<4, RTCRayHit4>(ctx, tlas, n, rtcIntersect4);
    } else if (n <= 8) {
        tracePacket<8, RTCRayHit8>(ctx, tlas, n, rtcIntersect8);
    } else {
        tracePacket<16, RTCRayHit16>(ctx, tlas, n, rtcIntersect16);
    }
    for (size_t i = 0; i < n; ++i) {
        try {
            finishGather(rays[i]);
        } catch (...) {
            errors[i] = std::current_exception();
        }
    }
}

}  // namespace refray::dxr::detail
