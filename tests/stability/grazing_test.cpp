// Stability: grazing rays, swept on purpose (issue 6). The oracle sweep (oracle_sweep_test.cpp) aims random rays at
// random points, so few of them graze; here every ray does.
//
// 1. Analytic spheres: the D3D12 sample's three hollow spheres (back faces culled, as its radiance rays are) and
//    Proceduray's isphere (the Mandelbulb's bounding sphere). Rays tangent to the sphere are moved in or out by
//    k = 0, ±1, ±2, ±4, ..., ±4096 float ulps of the radius, then rounded to float. Each rounded ray's true offset
//    is recomputed in long double, and the float and double results are compared with the closed form for it.
// 2. Fractal silhouettes: families of parallel rays cross the Mandelbulb (iMax 4 and 129) and the Julia set. The
//    double march's hit/miss edge is found by bisection, and the float-rounded rays within ±kWindow origin ulps of
//    it are marched in float and in double.
//
// Every measurement is printed as "[grazing] ..." and recorded with RecordProperty. Fixed seeds; u = 2^-24.
// Numbers and their discussion: docs/numerical-stability.md, "Grazing rays".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "procedural/math/analytic.h"
#include "procedural/math/fractals.h"
#include "tests/procedural/sweep_support.h"

namespace refray::procedural::math {
namespace {

using glm::dvec3;
using LD = long double;
using fixtures::radianceExtent;
using fixtures::randomUnit;
using fixtures::RayPair;

constexpr double kU = 0x1p-24;

void report(const std::string& key, const std::string& text) {
    std::printf("[grazing] %-26s %s\n", key.c_str(), text.c_str());
    ::testing::Test::RecordProperty(key, text);
}

std::string fmt(const char* format, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
    char buffer[320];
    std::snprintf(buffer, sizeof buffer, format, a, b, c, d, e);
    return buffer;
}

// A uniformly distributed unit vector perpendicular to the unit vector d.
dvec3 randomPerpendicular(std::mt19937& rng, const dvec3& d) {
    for (;;) {
        const dvec3 v = randomUnit(rng);
        const dvec3 p = v - glm::dot(v, d) * d;
        const double l = glm::length(p);
        if (l > 1e-3) return p / l;
    }
}

double floatUlp(float x) {
    return double(std::nextafter(std::fabs(x), std::numeric_limits<float>::infinity())) - double(std::fabs(x));
}

// =================================================================================================
// 1. Analytic spheres
// =================================================================================================

struct LVec {
    LD x, y, z;
};
LVec lvec(const dvec3& v) { return {LD(v.x), LD(v.y), LD(v.z)}; }
LD ldot(const LVec& a, const LVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
LVec lsub(const LVec& a, const LVec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

// One ray against one sphere, exactly: the inputs are floats (or doubles) promoted without rounding, and the sums
// and products below round at 2^-64, far below either precision's error.
struct Exact {
    bool hit = false;
    LD t = 0;      // the near root, when hit
    LD gap = 0;    // r^2 - p^2, p the distance from the centre to the line (> 0: the line enters the sphere)
    LD L2 = 0;     // |origin - centre|^2
};

// unitContract: isphere assumes |d| = 1 and solves t^2 + 2bt + c = 0 as written; the D3D12 solver divides by
// a = d.d. Either way the closed form is the exact value of that formula for this ray.
Exact exactSphere(const dvec3& origin, const dvec3& direction, const dvec3& centre, double radius, bool unitContract) {
    const LVec L = lsub(lvec(origin), lvec(centre));
    const LVec D = lvec(direction);
    const LD dd = ldot(D, D);
    const LD a = unitContract ? LD(1) : dd;
    const LD b = ldot(D, L);
    const LD c = ldot(L, L) - LD(radius) * LD(radius);
    Exact e;
    e.L2 = ldot(L, L);
    e.gap = LD(radius) * LD(radius) - (e.L2 - b * b / dd);
    const LD disc = b * b - a * c;
    if (disc < 0 || b >= 0 || c <= 0) return e;  // missed, behind, or origin inside (none of the rays below)
    e.hit = true;
    e.t = c / (-b + std::sqrt(disc));  // without cancellation
    return e;
}

// Spheres 0..2: the D3D12 Spheres primitive's; 3: Proceduray's isphere (centre 0, radius 1.25). Each precision
// has its own values: the double shaders use the double values of the HLSL literals (0.3, not 0.3f).
template <typename T>
vec3<T> sphereCentre(int index) {
    return index < 3 ? AnalyticSpheres<T>::center(index) : vec3<T>(T(0));
}
template <typename T>
T sphereRadius(int index) {
    return index < 3 ? AnalyticSpheres<T>::radius(index) : T(1.25);
}

struct Traced {
    bool hit = false;
    double t = 0;
    bool culled = false;  // D3D12: the equation had roots, but both failed IsAValidHit
};

template <typename T>
Traced traceSphere(int index, const Ray<T>& ray) {
    Traced r;
    if (index < 3) {
        T tmax = T(0);
        const AnalyticHit<T> h = RaySphereIntersectionTest(ray, radianceExtent<T>(), tmax, sphereCentre<T>(index),
                                                           sphereRadius<T>(index));
        r.hit = h.hit;
        r.t = double(h.thit);
        T t0 = T(0), t1 = T(0);
        r.culled = !h.hit && SolveRaySphereIntersectionEquation(ray, t0, t1, sphereCentre<T>(index), sphereRadius<T>(index));
    } else {
        const vec2<T> tt = isphere(vec4<T>(sphereCentre<T>(index), sphereRadius<T>(index)), ray.origin, ray.direction);
        r.hit = !(tt.x == T(-1) && tt.y == T(-1));
        r.t = double(tt.x);
    }
    return r;
}

constexpr int kMaxExponent = 12;  // offsets up to 2^12 ulps of the radius
constexpr int kRaysPerOffset = 64;
constexpr double kBack = 3;  // the origin's distance from the tangent point, back along the ray

// The bounds (see the test's comment).
constexpr double kGammaBound = 8;                 // flips only where |r^2 - p^2| <= 8 u |L|^2
const double kWorstTBound = std::sqrt(8 * kU) * 1.1;  // relative t at tangency; |L|/t <= 1.09 for these rays

struct SphereStats {
    int rays = 0, inBand = 0, flips = 0, culledFlips = 0, flipsNearTangent = 0, nearTangent = 0;
    int doubleFlips = 0;
    double widestGamma = 0;  // max |r^2 - p^2| / (u |L|^2) over float's flips
    double widestUlps = 0;   // the same flip's offset |p - r| in ulps of r
    double worstT = 0;       // max |t_float - t_exact| / t_exact over joint hits
    double worstTDouble = 0;
};

SphereStats grazeSphere(int index, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const float rf = sphereRadius<float>(index);
    const double ulpR = floatUlp(rf);
    const bool unitContract = index == 3;
    const dvec3 centre(sphereCentre<double>(index));
    SphereStats s;
    for (int e = -1; e <= kMaxExponent; ++e)
        for (const int sign : {-1, 1}) {
            if (e < 0 && sign > 0) continue;  // k = 0 once
            const double k = e < 0 ? 0.0 : sign * std::ldexp(1.0, e);
            for (int n = 0; n < kRaysPerOffset; ++n) {
                const dvec3 d = randomUnit(rng);
                const dvec3 touch = centre + (double(rf) + k * ulpR) * randomPerpendicular(rng, d);
                const RayPair r = fixtures::rayPair(touch - kBack * d, touch);
                const Exact ef = exactSphere(dvec3(r.d.origin), dvec3(r.d.direction), dvec3(sphereCentre<float>(index)),
                                             rf, unitContract);
                const Exact ed = exactSphere(dvec3(r.d.origin), dvec3(r.d.direction), centre, sphereRadius<double>(index),
                                             unitContract);
                const Traced tf = traceSphere(index, r.f);
                const Traced td = traceSphere(index, r.d);
                const double gamma = double(std::fabs(ef.gap) / (LD(kU) * ef.L2));
                const bool nearTangent = double(std::fabs(ef.gap)) <= 2 * double(rf) * ulpR;  // within an ulp of r
                ++s.rays;
                s.inBand += gamma <= kGammaBound;
                s.nearTangent += nearTangent;
                s.doubleFlips += td.hit != ed.hit;
                if (tf.hit != ef.hit) {
                    ++s.flips;
                    s.culledFlips += tf.culled;
                    s.flipsNearTangent += nearTangent;
                    if (gamma > s.widestGamma) {
                        s.widestGamma = gamma;
                        s.widestUlps = double(std::fabs(ef.gap)) / (2 * double(rf) * ulpR);
                    }
                }
                if (tf.hit && ef.hit) s.worstT = std::max(s.worstT, double(std::fabs(LD(tf.t) - ef.t) / ef.t));
                if (td.hit && ed.hit) s.worstTDouble = std::max(s.worstTDouble, double(std::fabs(LD(td.t) - ed.t) / ed.t));
            }
        }
    return s;
}

// Both intersections solve t^2 |d|^2 + 2t d.L + |L|^2 - r^2 = 0 (L = o - c), whose reduced discriminant is
// |d|^2 (r^2 - p^2), p the distance from the centre to the line. In float, (d.L)^2 and |d|^2 (|L|^2 - r^2) are
// each near |L|^2 at a grazing ray and round within a few u of it, so the computed discriminant is off by
// gamma u |L|^2 with gamma a small constant (the D3D12 form 4 times that, with a 4 times larger discriminant).
// Hit and miss can therefore disagree only where |r^2 - p^2| <= gamma u |L|^2, i.e. within
// gamma u |L|^2 / (2 r ulp(r)) ulps of the radius: ~60 ulps for r = 0.6 and ~1000 for r = 0.15 at gamma = 8,
// which is the bound (measured gamma: 2.1 for the D3D12 form, 4.2 for isphere's). The D3D12 sphere can also
// miss by culling: at a tangent ray the true dot(d, n) at the near root is -sqrt(r^2 - p^2)/r, and the root's
// error moves the computed normal by as much, so both roots may face away; that needs the same band.
// At tangency t = -b/a -+ sqrt(disc)/a, so an error e in the discriminant moves t by up to sqrt(e)/|d|:
// relative to t ~ |L|, at most sqrt(gamma u) |L|/t = sqrt(8u) * 1.09 = 7.5e-4 here (measured 5.4e-4); away
// from the band t is good to a few u. Double: the same with 2^-53, so no flip and t within ~1e-10.
TEST(Grazing, AnalyticSpheresDisagreeOnlyWithinTheDiscriminantsRoundingBand) {
    const char* names[] = {"D3D12_sphere_r0.6", "D3D12_sphere_r0.3", "D3D12_sphere_r0.15", "Proceduray_isphere_r1.25"};
    for (int index = 0; index < 4; ++index) {
        const SphereStats s = grazeSphere(index, 700 + std::uint32_t(index));
        report(names[index], fmt("%g rays, %g in the band; float flips %g (%g by culling), ", s.rays, s.inBand, s.flips,
                                 s.culledFlips) +
                                 fmt("widest at gamma %.2f (%.1f ulps of r); %g of the %g rays within an ulp of "
                                     "tangency flip; ",
                                     s.widestGamma, s.widestUlps, s.flipsNearTangent, s.nearTangent) +
                                 fmt("worst relative t %.2g; double flips %g, worst t %.2g", s.worstT, s.doubleFlips,
                                     s.worstTDouble));
        EXPECT_GT(s.flips, 0) << names[index] << ": the sweep no longer reaches the rounding band";
        EXPECT_LE(s.widestGamma, kGammaBound) << names[index] << ": a flip outside the discriminant's rounding band";
        EXPECT_LE(s.worstT, kWorstTBound) << names[index];
        EXPECT_EQ(s.doubleFlips, 0) << names[index];
        EXPECT_LE(s.worstTDouble, 1e-9) << names[index];
    }
}

// =================================================================================================
// 2. Fractal silhouettes
// =================================================================================================

enum class Fractal { Mandelbulb4, Mandelbulb129, Julia };

struct March {
    bool hit = false;
    double t = 0;
};

// The fractal's intersection as the shader calls it (t in local units for the Mandelbulb, q-space for the Julia).
template <typename T>
March marchFractal(Fractal f, const Ray<T>& ray) {
    if (f == Fractal::Julia) {
        const auto h = julia::JuliaDistance(ray.origin, ray.direction);
        return {h.hit, double(h.resT.x)};
    }
    const auto h = mandelbulb::MandelbulbDistance(ray.origin, ray.direction, f == Fractal::Mandelbulb4 ? 4 : 129);
    return {h.hit, double(h.thit)};
}

struct FractalSetup {
    const char* name;
    Fractal fractal;
    dvec3 centre;    // local space: the Mandelbulb's bounding sphere; the middle of the Julia's cut slab
    double bound;    // a radius around `centre` that holds the whole set
    double distance; // of the origins from `centre`
    double tau;      // the same-surface tolerance: the oracle sweep's bound on one threshold flip, relative
    std::uint32_t seed;
    int edges;
};

constexpr int kWindow = 8;  // rays at -kWindow..kWindow origin ulps around each bisected edge
constexpr double kNear = 1.5;  // "at an edge": the neighbouring ray or the next one

struct SilhouetteStats {
    int edges = 0, rays = 0, doubleEdges = 0, flips = 0, joint = 0, jumps = 0, edgesWithDisagreement = 0;
    int edgesBeyondNear = 0;  // edges with a disagreement more than kNear ulps from every double edge
    double farthest = 0;      // max distance, in origin ulps, from a disagreement to the nearest double edge
    double worstT = 0;        // max relative t between float and double over joint hits
    double worstAway = 0;     // ... over joint hits more than kNear ulps from every double edge
};

// A double edge lies between neighbouring rays j, j+1 whose double results differ in hit, or in t by more than
// tau (the front and the back of a step in depth). A disagreement is a ray whose float result differs from its
// double one in the same way.
SilhouetteStats skimSilhouettes(const FractalSetup& f) {
    std::mt19937 rng(f.seed);
    SilhouetteStats s;
    const double h = floatUlp(float(f.distance));  // >= the spacing of the origins' float grid
    for (int family = 0; s.edges < f.edges && family < 4 * f.edges; ++family) {
        const dvec3 d = randomUnit(rng);
        const dvec3 e = randomPerpendicular(rng, d);
        const dvec3 base = f.centre - f.distance * d;
        auto hitD = [&](double at) { return marchFractal(f.fractal, Ray<double>{base + at * e, d}).hit; };
        // The line through the centre normally hits and the one past the bound misses: bisect between them.
        double lo = 0, hi = 1.01 * f.bound;
        if (!hitD(lo) || hitD(hi)) continue;
        while (hi - lo > h / 64) {
            const double mid = 0.5 * (lo + hi);
            (hitD(mid) ? lo : hi) = mid;
        }
        ++s.edges;
        std::vector<March> mf, md;
        for (int j = -kWindow; j <= kWindow; ++j) {
            const dvec3 o = base + (lo + j * h) * e;
            const RayPair r = fixtures::rayPair(o, o + d);
            mf.push_back(marchFractal(f.fractal, r.f));
            md.push_back(marchFractal(f.fractal, r.d));
        }
        auto differ = [&f](const March& a, const March& b) {
            return a.hit != b.hit || (a.hit && std::fabs(a.t - b.t) > f.tau * b.t);
        };
        std::vector<double> edgesAt;  // j + 0.5 for an edge between j and j + 1
        for (int i = 0; i + 1 < int(md.size()); ++i)
            if (differ(md[i + 1], md[i])) edgesAt.push_back(i + 0.5);
        s.doubleEdges += int(edgesAt.size());
        bool disagreement = false, beyond = false;
        for (int i = 0; i < int(md.size()); ++i) {
            ++s.rays;
            double nearest = HUGE_VAL;
            for (const double at : edgesAt) nearest = std::min(nearest, std::fabs(at - i));
            if (mf[i].hit && md[i].hit) {
                ++s.joint;
                const double rel = std::fabs(mf[i].t - md[i].t) / md[i].t;
                s.worstT = std::max(s.worstT, rel);
                if (nearest > kNear) s.worstAway = std::max(s.worstAway, rel);
            }
            if (!differ(mf[i], md[i])) continue;
            disagreement = true;
            beyond = beyond || nearest > kNear;
            s.flips += mf[i].hit != md[i].hit;
            s.jumps += mf[i].hit && md[i].hit;
            s.farthest = std::max(s.farthest, nearest);
        }
        s.edgesWithDisagreement += disagreement;
        s.edgesBeyondNear += beyond;
    }
    return s;
}

// Why float and double disagree only next to the double march's own edges. The verdict is decided at the sample
// of closest approach: DE(pos) < 1e-4 t for iMax 129 and the Julia (kPrecis), t < exit after four steps for iMax 4.
// Float evaluates that sample at a position rounded to ulp(|pos|) <= 1.2e-7, with the DE's relative error
// <= 7.6e-5 (precision_test.cpp) of a DE near the threshold (3e-4): a few 1e-7 in the decided quantity, about
// 1e-6 t for iMax 4's four-step sum. Moving the ray by one origin ulp h (4.8e-7 at distance 4, 9.5e-7 at 8)
// moves its closest approach by h |cos a|, a the angle between the family's direction and the surface normal
// there. So float's edge lies within about one h of double's, and only the rays next to an edge can disagree:
// with ~1 edge in a window of 17 rays, at most ~3 of them, hence the share bound 3/17 (measured 1-5%).
// Where the family runs nearly along the surface (|cos a| << 1), the band widens to noise / (h |cos a|): such
// edges are rare (P(|cos a| < x) ~ x) and are counted; at most 10% of the edges may have a disagreement more
// than 1.5 h from every double edge (measured 0 of 104 here; 9 of 1200 in a run with 400 edges per fractal, up
// to 7.5 h away, 11.5 h with a window of ±16). An edge can also separate two surfaces at different depths, where
// one precision hits the front one and the other the one behind; that t jump is the depth step of the geometry,
// limited only by the bounding sphere's chord (the bound below; one such jump, 5.9e-4 relative, appeared among
// the 13 200 rays of the ±16 run, none here).
// Away from the edges, float's t stays on double's surface within the oracle sweep's threshold-flip bound tau.
TEST(Grazing, FractalSilhouettesDisagreeOnlyNextToTheDoubleEdges) {
    const FractalSetup setups[] = {
        {"Mandelbulb_iMax4", Fractal::Mandelbulb4, dvec3(0), 1.25, 4.0, 1e-4, 710, 40},
        {"Mandelbulb_iMax129", Fractal::Mandelbulb129, dvec3(0), 1.25, 4.0, 3e-4, 711, 40},
        // q = 0.4 local - (0, 1, 0): the set lies in |q| < 1.2 between the cut planes q.y = 0 and -1.1.
        {"Julia", Fractal::Julia, dvec3(0, 1.125, 0), 3.3, 8.0, 5e-4, 712, 24},
    };
    for (const FractalSetup& f : setups) {
        const SilhouetteStats s = skimSilhouettes(f);
        const double share = double(s.flips + s.jumps) / s.rays;
        // The chord of the bounding sphere over the nearest possible hit (q-space units scale both for the Julia).
        const double chordBound = 2 * f.bound / (f.distance - f.bound);
        report(f.name, fmt("%g edges, %g rays, %g double edges; disagreements: %g hit/miss, %g depth jumps ", s.edges,
                           s.rays, s.doubleEdges, s.flips, s.jumps) +
                           fmt("(%.2g%% of rays) at %g edges, %g of them beyond 1.5 ulps, farthest %.1f ulps; ",
                               100 * share, s.edgesWithDisagreement, s.edgesBeyondNear, s.farthest) +
                           fmt("worst relative t %.2g, away from edges %.2g", s.worstT, s.worstAway));
        EXPECT_EQ(s.edges, f.edges) << f.name << ": too few families hit at the centre";
        EXPECT_GT(s.flips, 0) << f.name << ": the windows no longer straddle the silhouette";
        EXPECT_LE(share, 3.0 / (2 * kWindow + 1)) << f.name;
        EXPECT_LE(s.edgesBeyondNear, f.edges / 10) << f.name << ": float and double disagree away from the edges";
        EXPECT_LE(s.worstAway, f.tau) << f.name;
        EXPECT_LE(s.worstT, chordBound) << f.name;
    }
}

}  // namespace
}  // namespace refray::procedural::math
