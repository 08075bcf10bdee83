// Determinism of DispatchRays (DET-1, GEN-2, GEN-3): a 64x64 dispatch over a small scene of
// triangles and boxes, with shadow-like secondary rays from the closest-hit shaders, must
// write the same bytes whatever the thread count and tile size.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "emulator/intersection.h"
#include "harness.h"

namespace refray::test {
namespace {

struct ShadePayload {
    float value = 0.0f;
    uint32_t bounces = 0;
};
struct ShadowPayload {
    float visible = 0.0f;
};
struct SphereAttributes {
    float normalY = 0.0f;
};

constexpr uint32_t kSize = 64;

// Records per geometry: [primary, shadow] (M = 2). Triangle instances use C = 0, boxes C = 2.
class DeterminismScene {
public:
    DeterminismScene() {
        auto& lib = *h.library;
        lib.addRayGeneration("RG", [this](ShaderContext& ctx) {
            const uvec3 i = ctx.DispatchRaysIndex();
            const float u = (float(i.x) + 0.5f) / kSize * 2.0f - 1.0f, v = (float(i.y) + 0.5f) / kSize * 2.0f - 1.0f;
            ShadePayload p;
            const RayDesc ray{vec3(0.0f, 0.0f, -6.0f), 0.0f, vec3(u * 0.6f, v * 0.6f, 1.0f), 1000.0f};
            ctx.TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 2, 0, ray, p);
            image[size_t(i.y) * kSize + i.x] = p.value + float(p.bounces) * 1e-3f;
        });
        auto shade = [this](ShaderContext& ctx, ShadePayload& p, vec3 normal) {
            const vec3 hit = ctx.WorldRayOrigin() + ctx.RayTCurrent() * ctx.WorldRayDirection();
            const vec3 toLight = glm::normalize(vec3(3.0f, 5.0f, -4.0f) - hit);
            ShadowPayload s;
            const RayDesc shadow{hit + normal * 1e-3f, 1e-3f, toLight, 100.0f};
            ctx.TraceRay(scene, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, 0xFF, 1, 2, 1,
                         shadow, s);
            p.value = 0.1f + s.visible * std::fabs(glm::dot(normal, toLight)) + 0.01f * float(ctx.InstanceIndex()) +
                      0.001f * float(ctx.PrimitiveIndex());
            p.bounces++;
        };
        lib.addClosestHit<ShadePayload, BuiltInTriangleIntersectionAttributes>(
            "CH_Tri", [shade](ShaderContext& ctx, ShadePayload& p, const BuiltInTriangleIntersectionAttributes& a) {
                shade(ctx, p, vec3(0, 0, -1));
                p.value += 0.05f * a.barycentrics.x;
            });
        lib.addClosestHit<ShadePayload, SphereAttributes>(
            "CH_Sphere", [shade](ShaderContext& ctx, ShadePayload& p, const SphereAttributes& a) {
                shade(ctx, p, vec3(0, 1, 0));
                p.value += 0.05f * a.normalY;
            });
        // Alpha-test-like any hit: ignore a checkerboard of the triangle's barycentric space.
        lib.addAnyHit<ShadePayload, BuiltInTriangleIntersectionAttributes>(
            "AH_Cutout", [](ShaderContext& ctx, ShadePayload&, const BuiltInTriangleIntersectionAttributes& a) {
                if ((int(a.barycentrics.x * 8.0f) + int(a.barycentrics.y * 8.0f)) % 2) ctx.IgnoreHit();
            });
        lib.addAnyHit<ShadowPayload, BuiltInTriangleIntersectionAttributes>(
            "AH_ShadowCutout", [](ShaderContext& ctx, ShadowPayload&, const BuiltInTriangleIntersectionAttributes& a) {
                if ((int(a.barycentrics.x * 8.0f) + int(a.barycentrics.y * 8.0f)) % 2) ctx.IgnoreHit();
            });
        // A sphere of radius 0.9 inside the unit box: order-independent.
        lib.addIntersection<SphereAttributes>("IS_Sphere", [](ShaderContext& ctx) {
            const vec3 o = ctx.ObjectRayOrigin(), d = ctx.ObjectRayDirection();
            const float a = glm::dot(d, d), b = glm::dot(o, d), c = glm::dot(o, o) - 0.81f;
            const float disc = b * b - a * c;
            if (disc < 0.0f) return;
            const float s = std::sqrt(disc);
            for (float t : {(-b - s) / a, (-b + s) / a}) {
                if (t >= ctx.RayTMin() && t <= ctx.RayTCurrent()) {
                    const vec3 n = glm::normalize(o + t * d);
                    ctx.ReportHit(t, 1, SphereAttributes{n.y});
                    return;
                }
            }
        });
        lib.addMiss<ShadePayload>("Miss_Sky", [](ShaderContext& ctx, ShadePayload& p) {
            p.value = 0.5f + 0.25f * ctx.WorldRayDirection().y;
        });
        lib.addMiss<ShadowPayload>("Miss_Shadow", [](ShaderContext&, ShadowPayload& s) { s.visible = 1.0f; });
        auto& hg = h.stateObject.hitGroups;
        hg.push_back({"HG_Tri", HitGroupType::Triangles, "AH_Cutout", "CH_Tri", ""});
        hg.push_back({"HG_TriShadow", HitGroupType::Triangles, "AH_ShadowCutout", "", ""});
        hg.push_back({"HG_Sphere", HitGroupType::ProceduralPrimitive, "", "CH_Sphere", "IS_Sphere"});
        hg.push_back({"HG_SphereShadow", HitGroupType::ProceduralPrimitive, "", "", "IS_Sphere"});

        // Triangles: a floor quad (opaque), two cut-out panels (non-opaque) crossing the view.
        const std::vector<vec3> floor = {{-4, -1, -2}, {-4, -1, 6}, {4, -1, 6}, {-4, -1, -2}, {4, -1, 6}, {4, -1, -2}};
        const std::vector<vec3> panels = {{-2, -1, 1}, {-0.5f, 2, 1.5f}, {1, -1, 2}, {0, -1, 3}, {1.5f, 2, 2.5f}, {3, -1, 3}};
        const auto triBLAS = h.blas({h.triangles(floor, GEOMETRY_FLAG_OPAQUE), h.triangles(panels, GEOMETRY_FLAG_NONE)});
        // Boxes: three unit boxes (spheres inside), one shared BLAS instanced three times.
        const auto boxBLAS = h.blas({h.aabbs({unitBox()}, GEOMETRY_FLAG_OPAQUE)});
        // Geometry 1 of the triangle BLAS: records 2, 3 under C = 0; boxes take C = 4.
        h.tlas({Harness::instance(triBLAS, 0),
                Harness::instance(boxBLAS, 4, Matrix3x4::translation({-1.5f, 0.0f, 2.0f})),
                Harness::instance(boxBLAS, 4, Matrix3x4::translation({1.2f, 0.5f, 4.0f}) * Matrix3x4::scale({0.7f, 1.3f, 0.7f})),
                Harness::instance(boxBLAS, 4, Matrix3x4::translation({0.3f, -0.4f, 0.5f}) * Matrix3x4::scale({0.4f, 0.4f, 0.4f}))});
        so = h.pipeline();
        miss = h.table(so, {"Miss_Sky", "Miss_Shadow"});
        hits = h.table(so, {"HG_Tri", "HG_TriShadow", "HG_Tri", "HG_TriShadow", "HG_Sphere", "HG_SphereShadow"});
        scene = h.scene;
    }

    std::vector<float> render(DispatchOptions options) {
        image.assign(size_t(kSize) * kSize, -1.0f);
        const auto result = h.dispatch(so, miss, hits, uvec3(kSize, kSize, 1), options);
        EXPECT_TRUE(result.diagnostics.empty());
        return image;
    }

    Harness h;
    StateObjectPtr so;
    GpuVirtualAddressRangeAndStride miss, hits;
    GpuVirtualAddress scene = 0;
    std::vector<float> image;
};

DispatchOptions options(uint32_t threads, uint32_t tile, TraversalOrder order = TraversalOrder::Ordered, uint64_t seed = 0) {
    DispatchOptions o;
    o.threads = threads;
    o.tileSize = tile;
    o.order = order;
    o.adversarialSeed = seed;
    return o;
}

bool sameBytes(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(Determinism, DET_1_SameBytesForEveryThreadCountAndTileSize) {
    DeterminismScene s;
    const auto reference = s.render(options(1, 8));
    // The image is not trivial: every pixel was written, with many distinct values.
    for (float v : reference) ASSERT_GE(v, 0.0f);
    std::vector<float> distinct = reference;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    EXPECT_GT(distinct.size(), 500u);
    for (auto [threads, tile] : {std::pair{2u, 8u}, std::pair{1u, 3u}, std::pair{2u, 3u}, std::pair{0u, 5u}}) {
        SCOPED_TRACE("threads " + std::to_string(threads) + " tile " + std::to_string(tile));
        EXPECT_TRUE(sameBytes(s.render(options(threads, tile)), reference));
    }
}

TEST(Determinism, DET_1_RepeatedDispatchesAreIdentical) {
    DeterminismScene s;
    const auto first = s.render(options(2, 8));
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(sameBytes(s.render(options(2, 8)), first));
}

TEST(Determinism, GEN_3_AdversarialOrderIsDeterministicPerSeedAcrossThreads) {
    DeterminismScene s;
    for (uint64_t seed : {3ull, 4ull}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const auto a = s.render(options(1, 8, TraversalOrder::Adversarial, seed));
        const auto b = s.render(options(2, 3, TraversalOrder::Adversarial, seed));
        EXPECT_TRUE(sameBytes(a, b));
    }
}

}  // namespace
}  // namespace refray::test
