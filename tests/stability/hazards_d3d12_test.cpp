// Stability: one focused test per numerical hazard of the two reference scenes (issue 6).
//
// Each test drives one hazard of the fact sheets (reference-scene-proceduray.md §4 "H*", reference-scene-d3d12-
// procedural.md §3 "H*") on purpose and checks either float against the double version of the same math (or a
// closed form) under a bound justified next to it, or the faithful HLSL behaviour the sheets document (a NaN that
// must stay a NaN, a step that must stay clamped). Every measured number is printed as "[hazard] ..." and recorded
// with RecordProperty, so docs/numerical-stability.md can quote it. Fixed seeds throughout; u = 2^-24 ~ 6e-8.
//
// This file: the D3D12 procedural scene (metaballs, the ground's grid filter, hlsl::fmod).
// Suites: HazardMetaballs, HazardGridFilter, HazardFmod. Shared helpers: hazards.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "emulator/device.h"
#include "emulator/intersection.h"
#include "emulator/shader_api.h"
#include "emulator/trace.h"
#include "procedural/d3d12/d3d12_shaders.h"
#include "procedural/math/fractals.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/sdf.h"
#include "scenes/camera_models.h"
#include "scenes/render_settings.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/emulator/harness.h"
#include "tests/stability/hazards.h"
#include "tests/procedural/contract_support.h"
#include "tests/procedural/sweep_support.h"
#include "tests/scenes/scene_test_support.h"

namespace refray {
namespace {

using namespace hazards;

// =================================================================================================
// 3. Metaballs at the threshold (D3D12 H10, H11)
// =================================================================================================

// The march samples t_k = tmin + (k - 1) step, step = (tmax - tmin)/128, and the first sample with potential
// >= 0.25 (whose normal passes IsAValidHit) is the hit, with no refinement. Where a sample's potential lies
// within rounding (~1e-7) of 0.25, float and double pick neighbouring samples. Such rays are made on purpose: a
// family of parallel rays o + s e is scanned for s where the double hit sample changes by exactly one (a
// threshold edge, not a grazing one), the edge is bisected to ~1e-16, and the float-rounded rays around it are
// traced in both precisions. Bound: |t_f - t_d| <= step_d + |tmin_f - tmin_d| + k |step_f - step_d| (one
// sample, plus the drift of the grid itself, which comes from the bounding spheres' roots). When the two grids
// agree that is exactly one step (measured ratio 0.99999); the drift term matters only where a ray grazes a
// bounding sphere and float and double disagree about its span. Edges where the hit sample jumps by more than one
// (the ray grazes the iso-surface or a bounding sphere, and the normal test or the span decides) are counted
// separately: there the precisions can differ like any silhouette.
TEST(HazardMetaballs, ThresholdFlipMovesTheHitByOneStep) {
    const auto extent = pm::fixtures::radianceExtent<double>();
    const auto extentF = pm::fixtures::radianceExtent<float>();
    const auto blobs = pm::InitializeAnimatedMetaballs(0.0, 12.0);
    const auto blobsF = pm::InitializeAnimatedMetaballs(0.0f, 12.0f);
    std::mt19937 rng(1301);
    std::uniform_real_distribution<double> uni(-0.6, 0.6);
    int edges = 0, grazingEdges = 0, flips = 0, oneStep = 0;
    double worstRatio = 0, worstDrift = 0;
    for (int n = 0; n < 60; ++n) {
        const dvec3 o = 3.0 * randomUnit(rng);
        const dvec3 dir = glm::normalize(dvec3(uni(rng), uni(rng), uni(rng)) - o);
        const dvec3 e = glm::normalize(glm::cross(dir, dvec3(0.3, 1, 0.2)));
        auto step = [&](double s) {
            const pm::Ray<double> r{o + s * e, dir};
            const auto h = pm::RayMetaballsIntersectionTest(r, extent, 0.0);
            return h.hit ? int(h.step) : -1;
        };
        // The first threshold edge along s in [-0.5, 0.5].
        int previous = step(-0.5);
        for (int k = 1; k <= 40; ++k) {
            const double s = -0.5 + k / 40.0;
            const int current = step(s);
            if (current == previous) continue;
            const int before = previous;
            previous = current;
            double a = s - 1 / 40.0, b = s;
            int ca = before, cb = current;
            for (int it = 0; it < 60; ++it) {
                const double mid = 0.5 * (a + b);
                if (mid == a || mid == b) break;
                const int sm = step(mid);
                if (sm == ca) a = mid;
                else {
                    b = mid;
                    cb = sm;
                }
            }
            if (!(ca > 0 && cb > 0 && std::abs(ca - cb) == 1)) {
                ++grazingEdges;
                continue;
            }
            ++edges;
            for (int j = -6; j <= 6; ++j) {
                const dvec3 oj = o + (0.5 * (a + b) + j * 1e-8) * e;
                const RayPair r = rayPair(oj, oj + dir);
                const auto hf = pm::RayMetaballsIntersectionTest(r.f, extentF, 0.0f);
                const auto hd = pm::RayMetaballsIntersectionTest(r.d, extent, 0.0);
                ASSERT_EQ(hf.hit, hd.hit);
                if (!hf.hit || hf.step == hd.step) continue;
                ++flips;
                EXPECT_EQ(std::abs(int(hf.step) - int(hd.step)), 1);
                double tmin = 0, tmax = 0;
                float tminF = 0, tmaxF = 0;
                pm::FindIntersectingMetaballs(r.d, extent, tmin, tmax, blobs);
                pm::FindIntersectingMetaballs(r.f, extentF, tminF, tmaxF, blobsF);
                const double stepD = (tmax - tmin) / 128, stepF = (double(tmaxF) - double(tminF)) / 128;
                const double drift = std::fabs(double(tminF) - tmin) + std::max(hf.step, hd.step) * std::fabs(stepF - stepD);
                const double ratio = (std::fabs(double(hf.thit) - hd.thit) - drift) / stepD;
                worstRatio = std::max(worstRatio, ratio);
                worstDrift = std::max(worstDrift, drift / stepD);
                if (drift < 1e-3 * stepD) ++oneStep;
            }
            break;
        }
    }
    report("Metaballs.threshold", fmt("%g threshold edges (%g grazing), %g float/double flips: worst (|dt| - drift)/step ",
                                      edges, grazingEdges, flips) +
                                      fmt("%.6f, worst drift %.3g steps; %g flips on an identical grid", worstRatio,
                                          worstDrift, oneStep));
    EXPECT_GT(edges, 30);
    EXPECT_GT(flips, 20) << "the rays did not straddle the threshold";
    EXPECT_LE(worstRatio, 1.0 + 1e-4);  // + the float accumulation of t += step over <= 128 samples
}

// =================================================================================================
// 4. The D3D12 ground's grid filter (D3D12 H2, H3, H4)
// =================================================================================================

// CalculateRayDifferentials intersects the neighbouring pixels' primary rays with the ground plane:
// t = dot(o - p, n) / dot(d, n). A neighbour ray parallel to the plane divides by zero. The filter then sees a
// footprint w = max(|dpdx|, |dpdy|) (HLSL max ignores a NaN operand) and forms i = (floor(a) + min(frac(a) r, 1) -
// floor(b) - min(frac(b) r, 1)) / (r w) with r = 50 and a, b = uv +- w/2. A projectionToWorld is built here so that
// the ddy neighbour's direction has y = delta exactly (world = (sx, delta - sy, 1), eye at the origin, the ground 2
// below; 9 x 9 dispatch, pixel (4, 3), whose neighbour row 4 has sy = 0), and delta is swept towards 0 from both
// sides. What the HLSL does, and the port with it:
//   delta = 0: the footprint is inf and NaN, i = inf/inf, the checker factor NaN in float and double: the pixel
//     is NaN and the render target stores 0 (H2). Faithful; the render reports it (GEN-4).
//   0 < |delta| << 1: the footprint grows like 2/|delta|; the integral tends to the grid's mean, i -> 1/r, the
//     factor to (1 - 1/50)^2 = 0.9604 (the blur of H4) and float follows double within 1e-5 (a few u of
//     frac(a) r over r w; measured 8e-8).
//   |delta| <= 2e-37 in float only: r w overflows to inf (w > 6.8e36), i.y = finite/inf = 0 and the factor is
//     1 - 1/50 = 0.98 instead of 0.9604; at a denormal delta the division itself overflows and the factor is NaN.
//     Double goes on to 1e-300. No real camera reaches that band: a direction from the unprojection has components
//     that are 0 or multiples of ulp(p)/near for the near-plane point p (~5e-5 for the sample's camera; see
//     ExactlyHorizontalRowsMakeNaNOnlyThroughAReflection).
TEST(HazardGridFilter, NeighbourRayParallelToThePlane) {
    using procedural::d3d12::AnalyticalCheckersTexture;
    const uvec2 dims(9, 9), index(4, 3);
    auto checkers = [&](auto zero, double delta) {
        using T = decltype(zero);
        procedural::Float4x4 m{};
        m.m[0][0] = 1;
        m.m[1][1] = -1;
        m.m[3][1] = float(delta);
        m.m[3][2] = 1;
        m.m[3][3] = 1;
        const glm::vec<3, T> eye(T(0));
        glm::vec<3, T> o, d;
        procedural::GenerateCameraRay(index, dims, eye, m, o, d);
        glm::vec<3, T> hit = o + (T(-2) / d.y) * d;
        hit.y = T(-2);
        return AnalyticalCheckersTexture<T>(hit, glm::vec<3, T>(T(0), T(1), T(0)), eye, m, index, dims);
    };
    const double mean = (1 - 1 / 50.0) * (1 - 1 / 50.0);
    double worstFD = 0, worstMean = 0;
    int finite = 0;
    for (const double sign : {1.0, -1.0})
        for (const double delta : {1e-1, 1e-3, 1e-6, 1e-9, 1e-12, 1e-20, 1e-30, 1e-36}) {
            const float f = checkers(0.0f, sign * delta);
            const double d = checkers(0.0, sign * delta);
            ASSERT_TRUE(std::isfinite(f) && std::isfinite(d)) << sign * delta;
            EXPECT_GE(f, 0.0f);
            EXPECT_LE(f, 1.0f);
            ++finite;
            worstFD = std::max(worstFD, std::fabs(f - d));
            if (delta <= 1e-9) worstMean = std::max(worstMean, std::fabs(d - mean));
        }
    const float overflow = checkers(0.0f, 1e-37);
    const double overflowD = checkers(0.0, 1e-37);
    const float denormal = checkers(0.0f, 1e-39);
    const double denormalD = checkers(0.0, 1e-39);
    const float parallel = checkers(0.0f, 0.0);
    const double parallelD = checkers(0.0, 0.0);
    report("GridFilter.parallel_neighbour",
           fmt("%g finite cases: float vs double %.2g, double vs 0.9604 (w -> inf) %.2g; ", finite, worstFD, worstMean) +
               fmt("delta 1e-37: float %.7g, double %.7g; ", overflow, overflowD) +
               fmt("delta 1e-39: float %g, double %.7g; delta 0: float %g, double %g", denormal, denormalD, parallel,
                   parallelD));
    EXPECT_LE(worstFD, 1e-5);
    EXPECT_LE(worstMean, 1e-6);
    EXPECT_FLOAT_EQ(overflow, 0.98f);
    EXPECT_NEAR(overflowD, mean, 1e-9);
    EXPECT_TRUE(std::isnan(denormal));
    EXPECT_NEAR(denormalD, mean, 1e-9);
    EXPECT_TRUE(std::isnan(parallel));
    EXPECT_TRUE(std::isnan(parallelD));
}

// Where an exactly parallel neighbour comes from in a real render. The unprojection of row j gives a direction
// whose y is a multiple of the quantum ulp(eye.y)/near, so a row can come out exactly horizontal (d.y = 0) when the
// view direction is horizontal and the row's screen y is 0 (odd heights), or at some sizes by rounding.
//  (a) The D3D12 sample's own camera (eye 5.3 above the ground, looking down): among the 16:9 sizes with heights
//      2..1100, rows with d.y = 0 exist at some sizes (counted here, first one rendered). There they never reach
//      the grid: the row and its neighbours point at the horizon, beyond the ground's far edge (1784+ units,
//      H16), and nothing reflective stands above the eye, so no ground hit uses them. The rendered rows are finite.
//  (b) A level camera at the chrome spheres' height (eye (3.5, 1.5, -12) looking along +z), odd height: the centre
//      row is exactly horizontal, its rays hit the chrome spheres, their reflections hit the ground, and the
//      ground's filter uses that row's neighbour (I7: always the primary rays of DispatchRaysIndex() + 1), which
//      is parallel to the ground: NaN, as on a GPU (H2). The render reports it as GEN-4. At an even height there is
//      no such row and no NaN.
TEST(HazardGridFilter, ExactlyHorizontalRowsMakeNaNOnlyThroughAReflection) {
    scenes::SceneDesc desc =
        scenes::loadSceneFile(std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json");
    const scenes::CameraDesc sampleCamera = desc.cameras.at(desc.defaultCamera);
    const glm::vec3 eye(sampleCamera.eye);
    int sizes = 0, withZeroRow = 0;
    uint32_t firstW = 0, firstH = 0, firstRow = 0;
    for (uint32_t h = 2; h <= 1100; ++h) {
        const uint32_t w = (h * 16 + 8) / 9;
        const procedural::Float4x4 m = scenes::projectionToWorld(sampleCamera, w, h);
        auto dirY = [&](uint32_t row) {
            glm::vec3 o, d;
            procedural::GenerateCameraRay(uvec2(w / 2, row), uvec2(w, h), eye, m, o, d);
            return d.y;
        };
        // The horizon row: the last row whose ray does not point down (rows go down the screen).
        uint32_t lo = 0, hi = h - 1;
        if (!(dirY(lo) >= 0.0f) || dirY(hi) >= 0.0f) continue;
        while (hi - lo > 1) {
            const uint32_t mid = (lo + hi) / 2;
            (dirY(mid) >= 0.0f ? lo : hi) = mid;
        }
        ++sizes;
        if (dirY(lo) == 0.0f) {
            if (withZeroRow++ == 0) firstW = w, firstH = h, firstRow = lo;
        }
    }
    ASSERT_GT(withZeroRow, 0) << "no 16:9 size has an exactly horizontal row: update the doc";
    scenes::RenderSettings settings;
    settings.threads = 2;
    settings.width = firstW;
    settings.height = firstH;
    settings.region = dxr::LaunchRegion{0, firstRow - 1, firstW, 3};
    size_t nonFiniteSample = 0;
    {
        scenes::Scene scene(desc);
        const scenes::RenderResult r = scene.render(settings);
        for (uint32_t y = firstRow - 1; y <= firstRow + 1; ++y)
            for (uint32_t x = 0; x < firstW; ++x) nonFiniteSample += !allFinite(vec3(r.image.at(x, y)));
    }

    // (b) The level camera.
    scenes::CameraDesc& level = desc.cameras.at(desc.defaultCamera);
    level.eye = dvec3(3.5, 1.5, -12);
    level.target = dvec3(3.5, 1.5, -2.5);
    level.up = dvec3(0, 1, 0);
    scenes::Scene scene(desc);
    auto nanPixels = [&](uint32_t w, uint32_t h, size_t& warned) {
        scenes::RenderSettings s;
        s.threads = 2;
        s.width = w;
        s.height = h;
        s.region = dxr::LaunchRegion{0, h / 2 - 1, w, 3};
        const scenes::RenderResult r = scene.render(s);
        size_t n = 0;
        for (uint32_t y = h / 2 - 1; y <= h / 2 + 1; ++y)
            for (uint32_t x = 0; x < w; ++x) n += !allFinite(vec3(r.image.at(x, y)));
        warned = r.dispatch.diagnostics.find("GEN-4").has_value();
        return n;
    };
    size_t warnedOdd = 0, warnedEven = 0;
    const size_t odd = nanPixels(65, 37, warnedOdd);
    const size_t even = nanPixels(64, 36, warnedEven);
    report("GridFilter.horizontal_rows",
           fmt("sample camera: %g of %g 16:9 sizes have an exactly horizontal row (first %gx%g", withZeroRow, sizes,
               firstW, firstH) +
               fmt("), its rows render %g non-finite pixels; level camera: 65x37 %g NaN pixels, 64x36 %g", double(nonFiniteSample),
                   double(odd), double(even)));
    EXPECT_EQ(nonFiniteSample, 0u);
    EXPECT_GT(odd, 0u) << "the level camera's centre row no longer makes the reflected grid NaN (H2)";
    EXPECT_TRUE(warnedOdd);
    EXPECT_EQ(even, 0u);
    EXPECT_FALSE(warnedEven);
}

// =================================================================================================
// 5. hlsl::fmod at cell edges and for negative arguments (D3D12 §2.12, H14)
// =================================================================================================

// DXC lowers fmod(x, y) to q = x/y, f = frac(|q|), (q >= -q ? f : -f) * y: the sign of x, like C fmod, but not the
// exact remainder r = x - y trunc(x/y) (which std::fmod returns exactly). The error has two parts:
//   - away from cell edges, the rounding of q (u |q|) times y, plus the final product: |f - r| <= 2u (|x| + |y|);
//   - at a cell edge, q can round onto the integer (or off it): f is then 0 where r is ~y, or ~y where r is ~0 -- a
//     whole period ("wrap"). It happens only where r or y - |r| is within u |x| of 0.
// For periods that are powers of two (MiniSpheres 0.5, Cylinder 1 and 2) q is exact and f == r always. For 0.05 and
// 0.075 (the Cog) and 12 (the metaballs' animation cycle, over T up to 1e4) the wraps appear; both sides of a wrap
// are cell edges, and every repeated object of the samples is symmetric in its cell (it sees |fmod - c/2|), so the
// distance functions never notice for x >= 0: the folded coordinate ||f - c/2| - |r - c/2|| stays within the
// rounding bound. Negative x: f lies in (-y, 0], so opRep = f - c/2 lies in (-1.5c, -0.5c] and never reaches the
// cell centre: no object for negative arguments (H14), in float and double alike; a wrap there moves opRep by a
// whole c between -0.5c and -1.5c, but at a distance of at least c/2 from any object. fmod(-0, y) is +0
// (q = -0 >= +0), where C gives -0.
TEST(HazardFmod, CellEdgesNegativeArgumentsAndFloatAgainstDouble) {
    constexpr double u = 1.0 / (1 << 24);
    struct Period {
        float y;
        float lo, hi;
    };
    const Period periods[] = {{0.5f, -3, 3}, {1.0f, -3, 3}, {2.0f, -3, 3}, {0.05f, -3, 3}, {0.075f, -3, 3}, {12.0f, 0, 1e4f}};
    std::mt19937 rng(1501);
    std::string text;
    int totalWraps = 0, powerOfTwoWraps = 0;
    for (const Period& p : periods) {
        std::uniform_real_distribution<float> uni(p.lo, p.hi);
        std::vector<float> xs;
        for (int i = 0; i < 20000; ++i) xs.push_back(uni(rng));
        for (int k = int(p.lo / p.y); k <= int(p.hi / p.y) && xs.size() < 40000; ++k) {  // the edges themselves
            const float edge = float(k) * p.y;
            xs.insert(xs.end(), {edge, std::nextafter(edge, -1e9f), std::nextafter(edge, 1e9f)});
        }
        int wraps = 0, floatDoubleWraps = 0, negativeWraps = 0;
        double worst = 0, worstFolded = 0, worstFD = 0;
        for (const float x : xs) {
            const float f = hlsl::fmod(x, p.y);
            const double d = hlsl::fmod(double(x), double(p.y));
            const float r = std::fmod(x, p.y);  // exact
            const double tol = 2 * u * (std::fabs(x) + p.y);
            // Sign of the dividend.
            if (x > 0) {
                EXPECT_GE(f, 0.0f) << x;
            }
            if (x < 0) {
                EXPECT_LE(f, 0.0f) << x;
                EXPECT_GE(std::fabs(f - 0.5f * p.y), 0.5 * p.y - tol) << "a negative argument reached a cell centre";
            }
            const double err = std::fabs(double(f) - double(r));
            if (err > tol) {
                ++wraps;
                EXPECT_NEAR(err, p.y, tol) << "neither the exact remainder nor a whole period off: x = " << x;
                EXPECT_LE(std::min(std::fabs(double(r)), p.y - std::fabs(double(r))), tol) << "a wrap away from a cell edge";
            } else {
                worst = std::max(worst, err / tol);
            }
            if (x >= 0) {
                const double folded = std::fabs(std::fabs(double(f) - 0.5 * p.y) - std::fabs(double(r) - 0.5 * p.y));
                worstFolded = std::max(worstFolded, folded / tol);
            } else if (err > tol) {
                ++negativeWraps;
            }
            const double fd = std::fabs(double(f) - d);
            if (fd > tol) ++floatDoubleWraps;
            else worstFD = std::max(worstFD, fd / tol);
        }
        totalWraps += wraps;
        if (p.y == 0.5f || p.y == 1.0f || p.y == 2.0f) powerOfTwoWraps += wraps;
        text += fmt("y=%g: %g wraps (%g at x < 0, %g float/double), ", p.y, wraps, negativeWraps, floatDoubleWraps) +
                fmt("error/bound %.2f, folded %.2f; ", worst, worstFolded);
        EXPECT_LE(worstFolded, 1.0) << p.y;
        EXPECT_LE(worstFD, 1.0) << p.y;
    }
    report("Fmod.cells", text.substr(0, text.size() - 2));
    EXPECT_EQ(powerOfTwoWraps, 0);
    EXPECT_GT(totalWraps, 0) << "no wrap found: the sweep missed the cell edges";
    // The exact values the fact sheet names.
    EXPECT_EQ(hlsl::fmod(1.0f, 0.05f), 0.0f);
    EXPECT_NEAR(std::fmod(1.0f, 0.05f), 0.05f, 1e-6f);
    EXPECT_FALSE(std::signbit(hlsl::fmod(-0.0f, 0.5f)));
    EXPECT_TRUE(std::signbit(std::fmod(-0.0f, 0.5f)));
    EXPECT_EQ(hlsl::fmod(-1.25f, 0.5f), -0.25f);
    EXPECT_EQ(hlsl::fmod(1.0f, 0.5f), 0.0f);
}

}  // namespace
}  // namespace refray
