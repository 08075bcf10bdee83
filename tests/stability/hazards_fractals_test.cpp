// Stability: one focused test per numerical hazard of the two reference scenes (issue 6).
//
// Each test drives one hazard of the fact sheets (reference-scene-proceduray.md §4 "H*", reference-scene-d3d12-
// procedural.md §3 "H*") on purpose and checks either float against the double version of the same math (or a
// closed form) under a bound justified next to it, or the faithful HLSL behaviour the sheets document (a NaN that
// must stay a NaN, a step that must stay clamped). Every measured number is printed as "[hazard] ..." and recorded
// with RecordProperty, so docs/numerical-stability.md can quote it. Fixed seeds throughout; u = 2^-24 ~ 6e-8.
//
// This file: the Proceduray fractals (Mandelbulb, Julia).
// Suites: HazardMandelbulb, HazardJulia. Shared helpers: hazards.h.
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
// 1. Mandelbulb (Proceduray H4, H5, H11; the bailout |w|^2 > 256)
// =================================================================================================

// H4: at p = 0, w.y / r = 0/0 makes acos NaN and the DE NaN. Close to the origin the iteration leaves w = p
// (r^8 <= 1e-24 for |p| <= 1e-3, dz = 1 + O(r^7)), so DE = 0.25 ln(|p|^2) |p| = 0.5 |p| ln|p| exactly up to
// O(|p|^7): a closed form. Float stays within a few u of it until |p|^2 underflows; the float renders run with
// FTZ/DAZ (H18), so that happens at |p|^2 < FLT_MIN = 2^-126, i.e. |p| < 2^-63 = 1.1e-19, where log(0) * 0 is
// NaN again. The march never samples such a point from outside: the ball |p| < rho (rho = 0.698, measured below)
// has DE < 0, so the first sample that enters it stops the march (DE < 1e-4 t), and the steps before it are
// distance estimates that do not overshoot the surface by a whole rho: over 800 rays aimed exactly at the origin
// no sample comes nearer than rho. Only a ray that starts at the centre samples p = 0, and it misses: t becomes NaN
// and "t < dis.y" is false (fact sheet H4: "a miss, no crash").
TEST(HazardMandelbulb, NaNAtTheOriginAndTheMarchNeverSamplesIt) {
    // The closed form near the origin, in float (with the renders' FTZ) and in double.
    const dvec3 u = glm::normalize(dvec3(0.3, 0.5, -0.8));
    double worstFloat = 0, worstDouble = 0;
    for (const double e : {1e-3, 1e-6, 1e-10, 1e-15, 1e-18}) {
        const glm::vec3 pf = glm::vec3(e * u);
        const dvec3 p = dvec3(pf);
        const double exact = 0.5 * glm::length(p) * std::log(glm::length(p));
        float f = 0;
        {
            hlsl::ScopedFlushDenormals ftz;
            f = pm::mandelbulb::mdist(pf);
        }
        worstFloat = std::max(worstFloat, relative(f, exact));
        worstDouble = std::max(worstDouble, relative(pm::mandelbulb::mdist(p), exact));
    }
    report("Mandelbulb.near_origin", fmt("DE vs 0.5|p|ln|p| for |p| in [1e-18, 1e-3]: float %.2g, double %.2g", worstFloat,
                                         worstDouble));
    // Float: a few roundings through log, sqrt and the division (measured 6.6e-8). Double: the O(|p|^7) terms.
    EXPECT_LE(worstFloat, 1e-6);
    EXPECT_LE(worstDouble, 1e-12);

    // Where float turns NaN: |p| = 2^-62 is finite, 2^-63 is NaN under FTZ; double stays finite far below.
    {
        hlsl::ScopedFlushDenormals ftz;
        const glm::vec3 dir(0.6f, 0.8f, 0.0f);
        EXPECT_TRUE(std::isfinite(pm::mandelbulb::mdist(std::ldexp(1.0f, -62) * dir)));
        if (hlsl::ScopedFlushDenormals::active()) {
            EXPECT_TRUE(std::isnan(pm::mandelbulb::mdist(std::ldexp(1.0f, -63) * dir)));
        }
    }
    EXPECT_TRUE(std::isfinite(pm::mandelbulb::mdist(1e-150 * u)));
    EXPECT_TRUE(std::isnan(pm::mandelbulb::mdist(glm::vec3(0.0f))));
    EXPECT_TRUE(std::isnan(pm::mandelbulb::mdist(dvec3(0.0))));

    // rho: how far the set's inner ball reaches, along 200 seeded directions (steps of 1e-3).
    std::mt19937 rng(1101);
    double rho = 10;
    std::vector<dvec3> dirs;
    for (int i = 0; i < 200; ++i) dirs.push_back(randomUnit(rng));
    for (const dvec3& d : dirs) {
        double s = 1e-3;
        while (pm::mandelbulb::mdist(s * d) < 0 && s < 2) s += 1e-3;
        rho = std::min(rho, s);
    }
    // Rays aimed exactly at the origin from radius 3, at iMax 4 (T0) and 129 (T1), float and double.
    double nearest = 10, worstT = 0;
    int hits = 0, rays = 0;
    for (const dvec3& d : dirs)
        for (const int iMax : {4, 129}) {
            const RayPair r = rayPair(3.0 * d, dvec3(0));
            const auto f = pm::mandelbulb::MandelbulbDistance(r.f.origin, r.f.direction, iMax);
            const auto g = pm::mandelbulb::MandelbulbDistance(r.d.origin, r.d.direction, iMax);
            rays += 2;
            hits += f.hit + g.hit;
            nearest = std::min({nearest, double(glm::length(f.pos)), glm::length(g.pos)});
            if (f.hit && g.hit) worstT = std::max(worstT, relative(f.thit, g.thit));
        }
    report("Mandelbulb.rays_through_origin",
           fmt("inner ball rho = %.3f; %g of %g rays hit; nearest sample to the origin %.3f;", rho, hits, rays, nearest) +
               fmt(" float vs double worst relative t %.2g", worstT));
    EXPECT_GT(rho, 0.5);
    EXPECT_EQ(hits, rays);
    EXPECT_GE(nearest, 0.9 * rho) << "a march sample came close to the NaN at the origin";
    EXPECT_LE(worstT, 2e-4);  // the threshold flip of OracleSweep.MandelbulbIMax129

    // The one ray that samples p = 0: from the centre (world eye at the instance centre). A miss, in both.
    for (const dvec3& d : {dvec3(1, 0, 0), dvec3(0, 1, 0), dvec3(0, 0, -1), glm::normalize(dvec3(1, 2, 3))})
        for (const int iMax : {1, 4, 129}) {
            EXPECT_FALSE(pm::mandelbulb::MandelbulbDistance(glm::vec3(0.0f), glm::vec3(d), iMax).hit);
            EXPECT_FALSE(pm::mandelbulb::MandelbulbDistance(dvec3(0.0), d, iMax).hit);
        }
}

// H5: on the y axis atan2(w.x, w.z) = atan2(0, 0), pi/2 in DXC, 0 in libm. For y > 0, b = 8 acos(1) = 0 and
// sin b = 0 exactly, so the angle a never matters and w stays on the axis: w <- y + |w|^8, dz <- 8|w|^7 dz + 1,
// a closed form evaluated here in long double. For y < 0, b = 8 acos(-1) = 8 pi and sin(8 pi) rounds to 7e-7 in
// float (1e-15 in double), so w leaves the axis by 7e-7 r^8 and a does reach the result, but only at second
// order. The error is measured against the DE's own scale: |DE - exact| / (|exact| + 0.25 sqrt(m)/dz), which is
// the relative error away from the zero set and the absolute error of ln(m) on it (where DE = 0.25 ln(m)
// sqrt(m)/dz passes through 0 and a relative error means nothing). Bound: float 5e-6 (each of the 4 iterations
// raises r to the 8th through exp2(8 log2 r), 8 times the input's relative error plus a few u: ~32 u per
// iteration on the orbit's worst step; measured 1.3e-6), double 1e-13. The fact sheet's check value at y = 0.7
// is included.
TEST(HazardMandelbulb, YAxisAtan2OfZeroZeroLeavesTheDEOnItsClosedForm) {
    EXPECT_EQ(hlsl::atan2(0.0f, 0.0f), hlsl::kPi<float> / 2);
    EXPECT_EQ(std::atan2(0.0f, 0.0f), 0.0f);
    double worstFloat = 0, worstDouble = 0;
    int points = 0;
    for (int k = -120; k <= 120; ++k) {
        const float y = 0.01f * float(k) + 0.003f;
        const long double py = y;
        long double w = py, m = py * py, dz = 1;
        for (int i = 0; i < 4; ++i) {
            dz = 8 * std::pow(std::sqrt(m), 7.0L) * dz + 1;
            w = py + std::pow(std::fabs(w), 8.0L);
            m = w * w;
            if (m > 256) break;
        }
        const long double exact = 0.25L * std::log(m) * std::sqrt(m) / dz;
        const long double scale = std::fabs(exact) + 0.25L * std::sqrt(m) / dz;
        const float f = pm::mandelbulb::mdist(glm::vec3(0.0f, y, 0.0f));
        const double d = pm::mandelbulb::mdist(dvec3(0.0, double(y), 0.0));
        worstFloat = std::max(worstFloat, double(std::fabs(f - exact) / scale));
        worstDouble = std::max(worstDouble, double(std::fabs(d - exact) / scale));
        ++points;
    }
    report("Mandelbulb.y_axis", fmt("%g points y in [-1.2, 1.2]: float vs closed form %.2g, double %.2g (of the DE's "
                                    "scale)",
                                    points, worstFloat, worstDouble));
    EXPECT_LE(worstFloat, 5e-6);
    EXPECT_LE(worstDouble, 1e-13);
    glm::vec4 trap;
    EXPECT_NEAR(pm::mandelbulb::mdist(glm::vec3(0.0f, 0.7f, 0.0f), trap), 0.00162148f, 1e-8f);
}

// The bailout |w|^2 > 256. Where the orbit crosses it on iteration k < 4, breaking leaves m ~ 256 and dz_k;
// going on gives m' ~ 256^8 and dz' ~ 8 * 16^7 dz_k, and the DE 0.25 ln(m) sqrt(m)/dz takes the same value on both
// sides up to |p|/16^8 and 1/dz' (the estimator is built to be continuous there): measured 3.3e-10 relative in
// double across the 116 crossings found below. So where float and double break on different iterations (a band
// of rounding width around each crossing), their DEs differ only by the usual float error (bound 1e-4,
// PrecisionDE.MandelbulbMdist), and the march cannot tell: radial rays through such points (head-on towards the
// centre, at iMax 4 and 129) agree within the threshold flip (2e-4 relative). What does jump is the orbit trap's
// x = final m, read by ClosestHit_Mandelbulb as occ = clamp(0.05 ln m): 0.277 on one side and 1 on the other. That
// is a shading discontinuity of the HLSL itself; float and double disagree on it only inside the rounding band.
// (A ray that merely grazes the fractal can land on a different thin feature in float and double for reasons that
// have nothing to do with the bailout: measured once at 0.45% in t, on a ray aimed from a random direction at such
// a point. HighIterationCountsStayOnTheSameSurface covers grazing rays.)
TEST(HazardMandelbulb, BailoutCrossingKeepsTheDEContinuousAndTheMarchOnTheSameSurface) {
    std::mt19937 rng(1103);
    int crossings = 0, disagreements = 0, marches = 0;
    double worstJump = 0, worstDE = 0, worstOcc = 0, worstT = 0;
    auto finalM = [](const dvec3& p) {
        dvec4 trap;
        pm::mandelbulb::mdist(p, trap);
        return trap.x;
    };
    for (int n = 0; n < 40; ++n) {
        const dvec3 u = randomUnit(rng);
        // Scan s along the radial line s*u; a crossing is where the final m jumps from <= 256-ish to >= 1e8
        // because the loop broke one iteration earlier or later.
        const int kSteps = 400;
        double prevS = 0.3;
        bool prevBig = finalM(prevS * u) > 1e8;
        for (int k = 1; k <= kSteps; ++k) {
            const double s = 0.3 + 2.2 * k / kSteps;
            const bool big = finalM(s * u) > 1e8;
            if (big != prevBig) {
                double a = prevS, b = s;
                for (int it = 0; it < 80; ++it) {
                    const double mid = 0.5 * (a + b);
                    if (mid == a || mid == b) break;
                    if ((finalM(mid * u) > 1e8) == prevBig) a = mid;
                    else b = mid;
                }
                dvec4 ta, tb;
                const double da = pm::mandelbulb::mdist(a * u, ta), db = pm::mandelbulb::mdist(b * u, tb);
                if (std::min(ta.x, tb.x) <= 300) {  // a break crossing, not m growing past 1e8 on iteration 4
                    ++crossings;
                    worstJump = std::max(worstJump, std::fabs(da - db) / std::max(std::fabs(da), std::fabs(db)));
                    // Float points in the rounding band: step the float x coordinate by ulps.
                    glm::vec3 q = glm::vec3(a * u);
                    for (int j = 0; j < 12; ++j) q.x = std::nextafter(q.x, -10.0f);
                    for (int j = 0; j < 24; ++j, q.x = std::nextafter(q.x, 10.0f)) {
                        glm::vec4 tf;
                        dvec4 td;
                        const float df = pm::mandelbulb::mdist(q, tf);
                        const double dd = pm::mandelbulb::mdist(dvec3(q), td);
                        if ((tf.x > 1e8f) == (td.x > 1e8)) continue;
                        ++disagreements;
                        worstDE = std::max(worstDE, relative(df, dd));
                        const double occF = std::clamp(0.05 * std::log(double(tf.x)), 0.0, 1.0);
                        const double occD = std::clamp(0.05 * std::log(td.x), 0.0, 1.0);
                        worstOcc = std::max(worstOcc, std::fabs(occF - occD));
                        // The radial ray through the point towards the centre: its samples cross the same bailout
                        // surface, and it meets the fractal head-on, so only the band can make the runs differ.
                        const RayPair r = rayPair(dvec3(q) * (1.0 + 3.0 / glm::length(dvec3(q))), dvec3(0.0));
                        for (const int iMax : {4, 129}) {
                            const auto hf = pm::mandelbulb::MandelbulbDistance(r.f.origin, r.f.direction, iMax);
                            const auto hd = pm::mandelbulb::MandelbulbDistance(r.d.origin, r.d.direction, iMax);
                            EXPECT_EQ(hf.hit, hd.hit);
                            if (hf.hit && hd.hit) {
                                ++marches;
                                worstT = std::max(worstT, relative(hf.thit, hd.thit));
                            }
                        }
                    }
                }
            }
            prevS = s;
            prevBig = big;
        }
    }
    report("Mandelbulb.bailout", fmt("%g crossings: DE jump across one (double) %.2g relative; ", crossings, worstJump) +
                                     fmt("%g float points break on another iteration than double: DE %.2g relative, "
                                         "occ jump %.3f; ",
                                         disagreements, worstDE, worstOcc) +
                                     fmt("%g radial marches through them: worst relative t %.2g", marches, worstT));
    EXPECT_GT(crossings, 50);
    EXPECT_GT(disagreements, 0) << "no float point broke on another iteration: the band was not found";
    EXPECT_LE(worstJump, 1e-8);
    EXPECT_LE(worstDE, 1e-4);
    EXPECT_GE(worstOcc, 0.7);  // 1 - 0.05 ln 256 = 0.7227: the trap's discontinuity, faithful
    EXPECT_LE(worstT, 2e-4);
}

// High iteration counts (H11, H14). At T1 the step count is 0.5 T1^2 + 3 = 128.5 -> 129 in float and double, half
// a step from either integer edge. Near an edge float and double can truncate to different counts: a scan of every
// float T in [1, 23) (not repeated here: 37 million evaluations) found 62 such T, one or two per integer crossing,
// e.g. T = 1.41421354f, where 0.5 T^2 + 3 is 4.0 in float and 3.99999997 in double. Then 129 steps: rays grazing the fractal (aimed at points just
// outside its 1.2-radius hull) are the ones that exhaust the steps. A run that ends unconverged reports thit one
// step past pos (H14); float and double must still agree on hit/miss for all but a few and on t within the
// threshold flip.
TEST(HazardMandelbulb, HighIterationCountsStayOnTheSameSurface) {
    const float t1 = pm::fixtures::canonicalT1();
    EXPECT_EQ(pm::mandelbulb::MandelbulbIterationCount(t1, 3), 129);
    EXPECT_EQ(pm::mandelbulb::MandelbulbIterationCount(double(t1), 3), 129);
    const float edge = 1.41421354f;
    EXPECT_EQ(pm::mandelbulb::MandelbulbIterationCount(edge, 3), 5);
    EXPECT_EQ(pm::mandelbulb::MandelbulbIterationCount(double(edge), 3), 4);

    std::mt19937 rng(1104);
    int rays = 0, hitsF = 0, flips = 0, unconverged = 0;
    double worstT = 0;
    for (int n = 0; n < 300; ++n) {
        const dvec3 o = 4.0 * randomUnit(rng);
        // Aim at a point on the sphere of radius 1.05..1.2 seen from o: near-tangent rays.
        const dvec3 aim = (1.05 + 0.15 * std::uniform_real_distribution<double>(0, 1)(rng)) * randomUnit(rng);
        const RayPair r = rayPair(o, aim);
        const auto hf = pm::mandelbulb::MandelbulbDistance(r.f.origin, r.f.direction, 129);
        const auto hd = pm::mandelbulb::MandelbulbDistance(r.d.origin, r.d.direction, 129);
        ++rays;
        hitsF += hf.hit;
        flips += hf.hit != hd.hit;
        if (hd.hit && !(pm::mandelbulb::mdist(hd.pos) < 1e-4 * hd.thit)) ++unconverged;
        if (hf.hit && hd.hit) worstT = std::max(worstT, relative(hf.thit, hd.thit));
    }
    report("Mandelbulb.iMax129_grazing", fmt("%g rays, %g hits, %g hit/miss flips, %g unconverged double hits, ", rays,
                                             hitsF, flips, unconverged) +
                                             fmt("worst relative t %.2g", worstT));
    EXPECT_GT(hitsF, 30);
    EXPECT_LE(flips, 3);       // silhouette rays within rounding of tangency (OracleSweep allows 1e-3 of rays)
    EXPECT_LE(worstT, 3e-4);   // OracleSweep.MandelbulbIMax129's bound
}

// =================================================================================================
// 2. Julia (Proceduray H8, H10, H16; jdist's logarithm)
// =================================================================================================

// H10: a q-space ray with rd.y = +-0 divides by zero at both cut planes: tpS = -ro.y / rd.y is +-inf, or NaN when
// ro.y = 0 (0/0). Every branch is an IEEE comparison, so NaN and inf fall through to the right case. Checked here:
// (1) float and double take the same branches (same hit/miss) for rd.y = +0, -0, +-1e-30, +-1e-38 and 1e-45 (the
// smallest denormal), with ro.y on either side of both planes, in them, and an ulp away, and agree on t within
// the kPrecis flip of OracleSweep.JuliaRaycast (5e-4 relative); (2) the limit rd.y -> 0 is continuous: wherever
// the plane crossing -ro.y/rd.y lies far beyond the march (> 100 q-units), a tiny rd.y gives bit-identically the
// rd.y = +0 result (it moves no sample); where it lies inside (ro.y an ulp from the plane and rd.y = 1e-30 points
// across it), the ray genuinely crosses the plane and the double oracle decides; (3) a ray lying in the cut plane
// y = 0 (tpS = 0/0 = NaN) behaves like one an ulp below it. A ray an ulp above the plane misses with either sign of
// zero (with rd.y = -0 through tmin = +inf, a march from infinity whose iteration count then differs between float,
// where the sample overflows to NaN, and double; the count of a miss is unused).
TEST(HazardJulia, CutPlanesWithZeroAndTinyRayDirectionY) {
    const float ys[] = {-0.5f, -0.3f, -1e-6f, std::nextafter(0.0f, -1.0f), -0.0f, 0.0f, std::nextafter(0.0f, 1.0f),
                        1e-6f, -1.1f, std::nextafter(-1.1f, -2.0f), -1.05f};
    const float dys[] = {0.0f, -0.0f, 1e-30f, -1e-30f, 1e-38f, -1e-38f, 1e-45f};
    int rays = 0, hits = 0, limitRays = 0;
    double worstLimit = 0, worstFD = 0, worstPlane = 0;
    for (const float phi : {0.0f, 0.4f, 1.3f, 2.9f})
        for (const float y : ys) {
            const glm::vec3 ro(-1.5f * std::cos(phi), y, -1.5f * std::sin(phi) + 0.3f);
            const glm::vec2 reference = pm::julia::raycast(ro, glm::vec3(std::cos(phi), 0.0f, std::sin(phi)));
            for (const float dy : dys) {
                const glm::vec3 rd(std::cos(phi), dy, std::sin(phi));
                const glm::vec2 f = pm::julia::raycast(ro, rd);
                const dvec2 d = pm::julia::raycast(dvec3(ro), dvec3(rd));
                ++rays;
                ASSERT_EQ(f.x >= 0, d.x >= 0) << "y=" << y << " dy=" << dy << " phi=" << phi;
                const double crossing = std::min(std::fabs(double(y)), std::fabs(-1.1 - double(y))) / std::fabs(double(dy));
                if (crossing > 100) {
                    ++limitRays;
                    ASSERT_EQ(f.x >= 0, reference.x >= 0) << "y=" << y << " dy=" << dy << " phi=" << phi;
                    if (f.x >= 0) worstLimit = std::max(worstLimit, relative(f.x, reference.x));
                }
                if (f.x < 0) continue;
                ++hits;
                worstFD = std::max(worstFD, relative(f.x, d.x));
            }
            if (y == 0.0f && !std::signbit(y)) {  // in the plane against an ulp below it
                const glm::vec3 below(ro.x, std::nextafter(0.0f, -1.0f), ro.z);
                const glm::vec2 b = pm::julia::raycast(below, glm::vec3(std::cos(phi), 0.0f, std::sin(phi)));
                ASSERT_EQ(b.x >= 0, reference.x >= 0);
                if (b.x >= 0) worstPlane = std::max(worstPlane, relative(reference.x, b.x));
            }
        }
    report("Julia.cut_planes_rd_y_zero",
           fmt("%g rays, %g hits; float vs double %.2g relative; %g rays whose crossing lies beyond the march",
               rays, hits, worstFD, limitRays) +
               fmt(": t vs rd.y = +0 %.2g; in-plane vs an ulp below %.2g", worstLimit, worstPlane));
    EXPECT_GT(hits, 100);
    EXPECT_GT(limitRays, 200);
    EXPECT_EQ(worstLimit, 0.0);  // a tiny rd.y moves no sample: bit-identical
    EXPECT_LE(worstFD, 5e-4);
    EXPECT_LE(worstPlane, 1e-5);  // one ulp of ro.y moves the hit by about that much over t ~ 1
    // Above the upper plane: a miss for either sign of zero.
    EXPECT_LT(pm::julia::raycast(glm::vec3(-1.5f, 1e-6f, 0.3f), glm::vec3(1.0f, 0.0f, 0.0f)).x, 0.0f);
    EXPECT_LT(pm::julia::raycast(glm::vec3(-1.5f, 1e-6f, 0.3f), glm::vec3(1.0f, -0.0f, 0.0f)).x, 0.0f);
}

// jdist's quantities in long double (an oracle of the same loop, to look inside it): the final m2 = |z|^2 under
// the logarithm, dz2, and the iteration count.
struct JuliaTerms {
    long double d = 0, m2 = 0, dz2 = 1;
    int n = 0;
};
JuliaTerms juliaTerms(const dvec3& p) {
    using LD = long double;
    const LD c[4] = {LD(-2) / 22, LD(6) / 22, LD(15) / 22, LD(-6) / 22};
    LD z[4] = {LD(p.x), LD(p.y), LD(p.z), 0};
    JuliaTerms r;
    for (int i = 0; i < 200; ++i) {
        const LD x2 = z[0] * z[0], y2 = z[1] * z[1], zz2 = z[2] * z[2], w2 = z[3] * z[3];
        const LD sq0 = x2 - y2 - zz2 - w2;
        const LD sqLen2 = sq0 * sq0 + 4 * x2 * (y2 + zz2 + w2);  // |z^2|^2
        r.dz2 *= 9 * sqLen2;
        const LD re = z[0] * (x2 - 3 * y2 - 3 * zz2 - 3 * w2);
        const LD im = 3 * x2 - y2 - zz2 - w2;
        z[0] = re + c[0];
        for (int k = 1; k < 4; ++k) z[k] = z[k] * im + c[k];
        r.m2 = z[0] * z[0] + z[1] * z[1] + z[2] * z[2] + z[3] * z[3];
        if (r.m2 > 256) break;
        r.n += 1;
    }
    r.d = 0.25L * std::log(r.m2) * std::sqrt(r.m2 / r.dz2);
    return r;
}

// The logarithms of the Julia set. (1) jdist's log(m2): an escaped orbit has m2 > 256, so log(m2) > 5.5; only a
// bounded orbit (n = 200) can end with a small m2, and over 20 000 seeded points of the marched region (the slab
// -1.1 < y < 0 inside the radius-1.2 sphere) the smallest such m2 is measured and bounded away from 0 (log(0)
// would give -inf * 0 = NaN, which min(d, 0.2) would turn into a blind 0.2 step). dz2 stays inside float's range
// there (an underflow to 0 would make d +-inf, an overflow to inf would make it 0). Float and double agree on the march's decision
// d < kPrecis at every point where either is finite. (2) H8: near q = 0, dz2 = 9|q|^4 -> 0 and d grows like
// 1/|q|^2; float reaches +inf below |q| ~ 1e-10 while double stays finite, but both exceed the 0.2 step clamp, so
// the march steps identically. (3) ClosestHit_Julia's log2(n): every hit has n >= 1 (inside the sphere of radius
// 1.2, |z^3 + c|^2 < 256 on the first iteration), so log2(n) >= 0, never log2(0).
TEST(HazardJulia, LogarithmsStayAwayFromZero) {
    std::mt19937 rng(1202);
    std::uniform_real_distribution<double> uni(-1.2, 1.2);
    int points = 0, bounded = 0, decisionFlips = 0, minN = 1000;
    long double minBoundedM2 = 1e9L, minDz2 = 1e300L, maxDz2 = 0;
    while (points < 20000) {
        const dvec3 p(uni(rng), -0.55 + 0.55 * uni(rng) / 1.2, uni(rng));
        if (glm::length(p) > 1.2) continue;
        ++points;
        const glm::vec3 pf(p);
        const JuliaTerms t = juliaTerms(dvec3(pf));
        minN = std::min(minN, t.n);
        minDz2 = std::min(minDz2, t.dz2);
        maxDz2 = std::max(maxDz2, t.dz2);
        if (t.n >= 200) {
            ++bounded;
            minBoundedM2 = std::min(minBoundedM2, t.m2);
        }
        const float df = pm::julia::jdist(pf, pm::julia::kc<float>(), 200).x;
        const double dd = pm::julia::jdist(dvec3(pf), pm::julia::kc<double>(), 200).x;
        ASSERT_TRUE(std::isfinite(df) && std::isfinite(dd)) << pf.x << "," << pf.y << "," << pf.z;
        if ((df < pm::julia::kPrecis<float>) != (dd < pm::julia::kPrecis<double>)) ++decisionFlips;
    }
    report("Julia.log_m2", fmt("%g points: %g bounded orbits, smallest m2 under their log %.3g; dz2 in [%.2g, ", points,
                               bounded, double(minBoundedM2), double(minDz2)) +
                               fmt("%.2g]; fewest iterations %g; float/double d < kPrecis flips %g", double(maxDz2), minN,
                                   decisionFlips));
    EXPECT_GT(bounded, 0);
    EXPECT_GT(minBoundedM2, 1e-3L);
    EXPECT_GT(minDz2, 1.2e-38L);  // float's FTZ floor (FLT_MIN): below it d would be +-inf
    EXPECT_LT(maxDz2, 3.4e38L);   // FLT_MAX: above it float's d would be 0 (measured 5.4e32, 6 decades below)
    EXPECT_GE(minN, 1);          // colorSurface's log2(n) is never log2(0) for points inside the sphere
    EXPECT_LE(decisionFlips, 2); // a point within rounding of d = kPrecis (none measured)

    // H8 near q = 0: both precisions clamp the step to 0.2.
    for (const double e : {1e-3, 1e-6, 1e-10, 1e-20, 1e-30}) {
        const glm::vec3 pf(float(e), 0.0f, 0.0f);
        const float df = pm::julia::jdist(pf, pm::julia::kc<float>(), 200).x;
        const double dd = pm::julia::jdist(dvec3(pf), pm::julia::kc<double>(), 200).x;
        EXPECT_GE(df, 0.2f) << e;
        EXPECT_GE(dd, 0.2) << e;
        EXPECT_EQ(hlsl::min(df, 0.2f), 0.2f);
    }
    EXPECT_EQ(pm::julia::jdist(glm::vec3(1e-20f, 0.0f, 0.0f), pm::julia::kc<float>(), 200).x,
              std::numeric_limits<float>::infinity());
    EXPECT_TRUE(std::isfinite(pm::julia::jdist(dvec3(1e-20, 0, 0), pm::julia::kc<double>(), 200).x));
}

// H16 for the Julia: the tetrahedral normal normalize(sum k_i d(p + k_i)) is NaN where the four samples agree
// (or any is NaN/inf). The only such place in the marched region is q = 0 (d = +inf there, H8), and the march
// never stops near it (d >= 0.2 around it). Over a seeded sweep of rays from radius 8 (local space, as
// OracleSweep.JuliaRaycast), every hit's normal is finite, and the unnormalised gradient estimate |sum| / (4 e^2)
// (e = 0.5773 kPrecis) at the hits is measured and bounded away from 0: float's rounding of d (~1e-7 absolute
// near the surface) is far below e * |grad|, so no hit comes near a vanishing gradient, and float's normal stays
// within a few degrees of double's.
TEST(HazardJulia, NormalNeverMeetsAVanishingGradientAtAHit) {
    std::mt19937 rng(1203);
    std::uniform_real_distribution<double> uni(0, 1);
    int hits = 0, nanNormals = 0;
    double minGrad = 1e30, worstAngle = 0;
    const double e = 0.5773 * 0.00025;
    const dvec3 k[4] = {dvec3(1, -1, -1), dvec3(-1, -1, 1), dvec3(-1, 1, -1), dvec3(1, 1, 1)};
    for (int n = 0; n < 400; ++n) {
        const dvec3 o = 8.0 * randomUnit(rng);
        const dvec3 aim(-3.5 + 7 * uni(rng), -3.5 + 7 * uni(rng), -3.5 + 7 * uni(rng));
        const RayPair r = rayPair(o, aim);
        const auto hf = pm::julia::JuliaDistance(r.f.origin, r.f.direction);
        const auto hd = pm::julia::JuliaDistance(r.d.origin, r.d.direction);
        if (!hf.hit || !hd.hit) continue;
        ++hits;
        if (!allFinite(hf.normal)) ++nanNormals;
        // The gradient estimate at the double hit, in q-space.
        const dvec3 q = 0.4 * r.d.origin + dvec3(0, -1, 0) + hd.resT.x * r.d.direction;
        dvec3 sum(0);
        for (const dvec3& ki : k) sum += e * ki * pm::julia::jdist(q + e * ki, pm::julia::kc<double>(), 200).x;
        minGrad = std::min(minGrad, glm::length(sum) / (4 * e * e));
        if (std::fabs(hf.resT.x - hd.resT.x) < 1e-4 * hd.resT.x)
            worstAngle = std::max(worstAngle, procedural::fixtures::angleBetween(hf.normal, glm::vec3(hd.normal)));
    }
    report("Julia.normal", fmt("%g hits: %g NaN normals; smallest |gradient| at a hit %.3g; worst float/double "
                               "normal angle (same hit) %.2g rad",
                               hits, nanNormals, minGrad, worstAngle));
    EXPECT_GT(hits, 50);
    EXPECT_EQ(nanNormals, 0);
    EXPECT_GT(minGrad, 1e-3);
    // Float's d near the surface carries ~3^n u relative error (n ~ 8 iterations at a hit: ~4e-4 of d ~ kPrecis,
    // ~1e-7 absolute); the tetrahedral sum turns an absolute error eps into an angle ~ eps / (2 e |grad|), which
    // with the smallest gradient measured above is ~2e-2 rad. Bound 5e-2 rad (measured 3.6e-3).
    EXPECT_LE(worstAngle, 5e-2);
    // H16 itself, where it does happen: a constant field (the four samples agree) gives a NaN normal.
    const glm::vec3 flat = pm::sdCalculateNormal(glm::vec3(0.3f), [](const glm::vec3&) { return 0.25f; });
    EXPECT_TRUE(std::isnan(flat.x) && std::isnan(flat.y) && std::isnan(flat.z));
}

}  // namespace
}  // namespace refray
