// Emulation overhead (issue: the DXR pipeline emulator): rays/s through DispatchRays on the
// built-in scene against raw Embree on the same geometry — native triangles for the plane,
// a plain user-geometry callback that calls the same sphere intersection function, and the
// same shading functions called directly (no shader table, no dispatch, no DXR rules).
#include <benchmark/benchmark.h>

#include <embree3/rtcore.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>

#include "procedural/builtin/builtin_shaders.h"
#include "scenes/builtin_scene.h"

namespace {

using namespace refray;
namespace builtin = refray::procedural::builtin;
using scenes::BuiltinScene;

constexpr uint32_t kWidth = 320, kHeight = 180;
constexpr float kTMax = 10000.0f;

class RawEmbreeScene {
public:
    RawEmbreeScene() {
        device_ = rtcNewDevice("verbose=0");
        scene_ = rtcNewScene(device_);
        const float s = BuiltinScene::kPlaneHalfSize;
        RTCGeometry plane = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(plane, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 4));
        const float vertices[12] = {-s, 0, -s, s, 0, -s, s, 0, s, -s, 0, s};
        std::copy(vertices, vertices + 12, v);
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(plane, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, 2));
        const unsigned indices[6] = {0, 2, 1, 0, 3, 2};
        std::copy(indices, indices + 6, idx);
        rtcCommitGeometry(plane);
        rtcAttachGeometryByID(scene_, plane, 0);
        rtcReleaseGeometry(plane);

        RTCGeometry sphere = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(sphere, 1);
        rtcSetGeometryBoundsFunction(sphere, bounds, nullptr);
        rtcSetGeometryIntersectFunction(sphere, intersect);
        rtcSetGeometryOccludedFunction(sphere, occluded);
        rtcCommitGeometry(sphere);
        rtcAttachGeometryByID(scene_, sphere, 1);
        rtcReleaseGeometry(sphere);
        rtcCommitScene(scene_);
        constants_ = BuiltinScene::sceneConstants(kWidth, kHeight);
    }
    ~RawEmbreeScene() {
        rtcReleaseScene(scene_);
        rtcReleaseDevice(device_);
    }

    uint64_t render(uint32_t threads) {
        std::atomic<uint64_t> rays{0};
        tbb::task_arena arena{int(threads)};
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, kHeight, 8, 0, kWidth, 8), [&](const auto& r) {
                uint64_t local = 0;
                for (uint32_t y = r.rows().begin(); y < r.rows().end(); ++y)
                    for (uint32_t x = r.cols().begin(); x < r.cols().end(); ++x) {
                        const vec3 d = builtin::primaryDirection(constants_, uvec3(x, y, 0), uvec3(kWidth, kHeight, 1));
                        benchmark::DoNotOptimize(radiance(vec3(constants_.cameraPosition), d, 0, local));
                    }
                rays += local;
            });
        });
        return rays.load();
    }

private:
    static vec3 centre() { return BuiltinScene::kSphereCentre; }

    static void bounds(const RTCBoundsFunctionArguments* args) {
        const vec3 c = centre();
        const float r = BuiltinScene::kSphereRadius;
        *args->bounds_o = RTCBounds{c.x - r, c.y - r, c.z - r, 0, c.x + r, c.y + r, c.z + r, 0};
    }
    static void intersect(const RTCIntersectFunctionNArguments* args) {
        auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
        const vec3 o = vec3(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z) - centre();
        const vec3 d(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z);
        float t;
        if (!builtin::intersectSphere(o, d, BuiltinScene::kSphereRadius, rh->ray.tnear, rh->ray.tfar, t)) return;
        const vec3 n = (o + t * d) / BuiltinScene::kSphereRadius;
        rh->ray.tfar = t;
        rh->hit.Ng_x = n.x, rh->hit.Ng_y = n.y, rh->hit.Ng_z = n.z;
        rh->hit.geomID = args->geomID;
        rh->hit.primID = 0;
    }
    static void occluded(const RTCOccludedFunctionNArguments* args) {
        auto* ray = reinterpret_cast<RTCRay*>(args->ray);
        const vec3 o = vec3(ray->org_x, ray->org_y, ray->org_z) - centre();
        float t;
        if (builtin::intersectSphere(o, vec3(ray->dir_x, ray->dir_y, ray->dir_z), BuiltinScene::kSphereRadius, ray->tnear,
                                     ray->tfar, t))
            ray->tfar = -INFINITY;
    }

    bool inShadow(vec3 p, vec3 l, float distance, uint32_t depth, uint64_t& rays) const {
        if (depth >= builtin::kMaxRecursionDepth) return false;
        ++rays;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRay ray{p.x, p.y, p.z, 0.001f, l.x, l.y, l.z, 0.0f, distance, 0xFFFFFFFFu, 0, 0};
        rtcOccluded1(scene_, &ctx, &ray);
        return ray.tfar < 0.0f;
    }

    vec3 shade(vec3 albedo, vec3 n, vec3 p, uint32_t depth, uint64_t& rays) const {
        const vec3 toLight = vec3(constants_.lightPosition) - p;
        const float distance = glm::length(toLight);
        const vec3 l = toLight / distance;
        const bool shadowed = glm::dot(n, l) > 0.0f && inShadow(p, l, distance, depth + 1, rays);
        return builtin::lambert(albedo, n, l, shadowed);
    }

    vec4 radiance(vec3 o, vec3 d, uint32_t depth, uint64_t& rays) const {
        if (depth >= builtin::kMaxRecursionDepth) return vec4(0.0f);
        ++rays;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh{};
        rh.ray = RTCRay{o.x, o.y, o.z, 0.001f, d.x, d.y, d.z, 0.0f, kTMax, 0xFFFFFFFFu, 0, 0};
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return builtin::skyColor(d);
        const vec3 p = o + rh.ray.tfar * d;
        if (rh.hit.geomID == 0)
            return vec4(shade(builtin::checkerAlbedo(p, vec3(BuiltinScene::kPlaneAlbedo)), vec3(0, 1, 0), p, depth + 1, rays), 1.0f);
        const vec3 n = glm::normalize(vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
        vec3 color = shade(vec3(BuiltinScene::kSphereAlbedo), n, p, depth + 1, rays);
        color += BuiltinScene::kSphereAlbedo.w * vec3(radiance(p, glm::reflect(d, n), depth + 1, rays));
        return vec4(color, 1.0f);
    }

    RTCDevice device_;
    RTCScene scene_;
    builtin::SceneConstants constants_;
};

void BM_DispatchRays_BuiltinScene(benchmark::State& state) {
    BuiltinScene scene;
    scenes::RenderSettings settings;
    settings.width = kWidth;
    settings.height = kHeight;
    settings.threads = uint32_t(state.range(0));
    uint64_t rays = 0;
    for (auto _ : state) rays += scene.render(settings).dispatch.stats.raysTraced;
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}

void BM_RawEmbree_BuiltinScene(benchmark::State& state) {
    RawEmbreeScene scene;
    uint64_t rays = 0;
    for (auto _ : state) rays += scene.render(uint32_t(state.range(0)));
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_DispatchRays_BuiltinScene)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RawEmbree_BuiltinScene)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();
