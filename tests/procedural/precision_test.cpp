// Float vs double agreement of the procedural math (issue 3), away from the fact sheets' hazards.
//
// The reference renders in float32 (Proceduray H18, D3D12 §2.12); every function is templated
// on T, so the same source evaluated in double is the yardstick for how much float rounding
// moves each distance estimator and each march. Inputs are generated from fixed seeds, rounded
// to float, and the double evaluation gets the *same* (exactly promoted) inputs, so only the
// arithmetic differs.
//
// Hazards kept out of the samples (each one has its own targeted test elsewhere):
//   Mandelbulb H4 (p = 0) and H5/H6 (the y axis, where acos sees |w.y/r| ~ 1): points and ray
//     samples stay off a cone around the y axis;
//   Julia H8 (p = 0), H9 (cut face: one sub-ulp change moves a hit by a whole 0.2 step) and H10
//     (rd.y = 0): the side-wall rays start between the cut planes and never hit the cut face;
//     the cut-face case is measured separately with the H9 bound;
//   D3D12 H15 (atan2 on the cog's axis): cog points stay off the y axis.
// Every measured number is printed ("[precision] ...") and recorded with RecordProperty.
// The bounds below are stated with their reasoning; u = 2^-24 ~ 6e-8 is the float unit roundoff.
#include "procedural/math/analytic.h"
#include "procedural/math/fractals.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/sdf.h"
#include "tests/procedural/sweep_support.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

namespace refray::procedural::math {
namespace {

using glm::dvec3;
using glm::vec3;
using fixtures::canonicalT1;
using fixtures::radianceExtent;
using fixtures::randomUnit;
using fixtures::RayPair;

constexpr int kPoints = 2000;
constexpr int kRays = 1000;
constexpr std::uint32_t kSeed = 20240603u;

// Distance of p from the y axis relative to |p|: sin of the angle to the axis.
double offAxis(const dvec3& p) { return std::sqrt(p.x * p.x + p.z * p.z) / glm::length(p); }

// kPoints float points with |p - centre| uniform in [rMin, rMax], accepted by `keep`.
std::vector<vec3> shellPoints(std::uint32_t seed, const dvec3& centre, double rMin, double rMax,
                              const std::function<bool(const dvec3&)>& keep = nullptr) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> r(rMin, rMax);
    std::vector<vec3> pts;
    while (int(pts.size()) < kPoints) {
        const vec3 p(centre + r(rng) * randomUnit(rng));
        if (!keep || keep(dvec3(p))) pts.push_back(p);
    }
    return pts;
}

void report(const std::string& key, const std::string& text) {
    std::printf("[precision] %-28s %s\n", key.c_str(), text.c_str());
    ::testing::Test::RecordProperty(key, text);
}

std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
    char buf[256];
    std::snprintf(buf, sizeof buf, f, a, b, c, d);
    return buf;
}

// ---- distance estimators --------------------------------------------------------------------------
struct DeBound {
    double rel;  // times |f_double|
    double abs;
};

// |f_float(p) - f_double(p)| <= rel*|f_double(p)| + abs at every point; prints the worst
// absolute error, the worst relative error (|err| / |f_double|, over |f_double| > 1e-3) and the
// worst fraction of the bound used.
void checkDe(const std::string& name, const std::vector<vec3>& pts, const std::function<float(const vec3&)>& ff,
             const std::function<double(const dvec3&)>& fd, DeBound bound) {
    double maxAbs = 0, maxRel = 0, maxUse = 0;
    int failures = 0;
    for (const vec3& p : pts) {
        const double vf = double(ff(p));
        const double vd = fd(dvec3(p));
        ASSERT_TRUE(std::isfinite(vd)) << name << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
        const double err = std::fabs(vf - vd);  // NaN in float fails the comparison below
        const double allowed = bound.rel * std::fabs(vd) + bound.abs;
        if (!(err <= allowed)) {
            if (++failures <= 5)
                ADD_FAILURE() << name << ": |" << vf << " - " << vd << "| = " << err << " > " << allowed << " at ("
                              << p.x << ", " << p.y << ", " << p.z << ")";
        }
        maxAbs = std::max(maxAbs, err);
        if (std::fabs(vd) > 1e-3) maxRel = std::max(maxRel, err / std::fabs(vd));
        maxUse = std::max(maxUse, err / allowed);
    }
    report("DE." + name, fmt("N=%.0f max|df|=%.3g max rel=%.3g worst bound use=%.3g", double(pts.size()), maxAbs,
                            maxRel, maxUse));
    EXPECT_EQ(failures, 0) << name;
}

// Mandelbulb mdist (4 iterations of w -> p + w^8): a relative error e in w becomes ~8e after one
// iteration (r^8, and the angles are multiplied by 8), so after 4 iterations the float result
// carries ~8^4 * (a few u) ~ 1e-3 relative in the worst case, usually far less; dz and log(m)
// are smooth. Points between radius 0.9 (inside the fractal's outer lobes) and 1.25 (bounding
// sphere), off a 10-degree cone around the y axis (H5/H6). Bound: 1e-3 relative + 1e-5 absolute
// (the absolute part covers DE values near 0, where log(m) crosses zero at |w| = 1).
TEST(PrecisionDE, MandelbulbMdist) {
    const auto pts = shellPoints(kSeed + 1, dvec3(0), 0.9, 1.25, [](const dvec3& p) { return offAxis(p) > 0.17; });
    checkDe("Mandelbulb_mdist", pts, [](const vec3& p) { return mandelbulb::mdist(p); },
            [](const dvec3& p) { return mandelbulb::mdist(p); }, {1e-3, 1e-5});
}

// Julia jdist (z -> z^3 + c, up to 200 iterations): the relative error of z grows ~3x per
// iteration, so points must escape quickly to be comparable; near the set (n large) float and
// double can escape at different iterations and the estimate changes by O(1) relative (that is
// the fractal, not a port error). The shell 1.15..1.5 in q-space lies outside the set (its
// extent is ~1.08, fact sheet §1.2), where every point escapes within a few iterations.
// Bound: 1e-4 relative + 1e-6 absolute (3^n * a few u with n <= 4 is ~1e-5).
TEST(PrecisionDE, JuliaJdist) {
    const glm::vec4 c = julia::kc<float>();
    const glm::dvec4 cd = julia::kc<double>();
    const auto pts = shellPoints(kSeed + 2, dvec3(0), 1.15, 1.5);
    checkDe("Julia_jdist", pts, [&c](const vec3& p) { return julia::jdist(p, c, 200).x; },
            [&cd](const dvec3& p) { return julia::jdist(p, cd, 200).x; }, {1e-4, 1e-6});
}

// Pac-man: lengths, abs, max/min of O(1) values, no amplification: ~30 roundings, each at most
// u * |intermediate| <= 2u, so at most ~60u = 3.6e-6. Bound: 4e-6 absolute + 1e-6 relative.
TEST(PrecisionDE, PacmanSdf) {
    const float tau = pacman::PacmanMouthInterpolant(canonicalT1());
    const auto pts = shellPoints(kSeed + 3, dvec3(0), 0.3, 0.8);
    checkDe("Pacman", pts, [tau](const vec3& p) { return pacman::pacMan(p, tau); },
            [tau](const dvec3& p) { return pacman::pacMan(p, double(tau)); }, {1e-6, 4e-6});
}

// D3D12 SDF composites, local space, shell 0.3..1.7 around the AABB centre. All are a few dozen
// roundings of O(1) values (the fractal pyramid scales by 2^4 and back by 2^-4; pow goes
// through exp2/log2 with error ~u*|log2|). The fmod repetitions are symmetric about each cell
// centre, so a cell boundary flipping between precisions does not change the distance.
// Same count as the Pac-man (<= ~60u = 3.6e-6 for |p| <= 1.7): 4e-6 absolute + 1e-6 relative
// for all. The cog stays off the y axis (H15).
struct SdfCase {
    const char* name;
    d3d12::SignedDistancePrimitive type;
};
const SdfCase kSdfCases[] = {
    {"MiniSpheres", d3d12::SignedDistancePrimitive::MiniSpheres},
    {"IntersectedRoundCube", d3d12::SignedDistancePrimitive::IntersectedRoundCube},
    {"SquareTorus", d3d12::SignedDistancePrimitive::SquareTorus},
    {"TwistedTorus", d3d12::SignedDistancePrimitive::TwistedTorus},
    {"Cog", d3d12::SignedDistancePrimitive::Cog},
    {"Cylinder", d3d12::SignedDistancePrimitive::Cylinder},
    {"FractalPyramid", d3d12::SignedDistancePrimitive::FractalPyramid},
};

TEST(PrecisionDE, D3D12Sdfs) {
    std::uint32_t seed = kSeed + 10;
    for (const SdfCase& c : kSdfCases) {
        const auto pts = shellPoints(seed++, dvec3(0), 0.3, 1.7, [&c](const dvec3& p) {
            return c.type != d3d12::SignedDistancePrimitive::Cog || offAxis(p) > 0.05;
        });
        const auto type = c.type;
        checkDe(std::string("D3D12_") + c.name, pts,
                [type](const vec3& p) { return d3d12::GetDistanceFromSignedDistancePrimitive(p, type); },
                [type](const dvec3& p) { return d3d12::GetDistanceFromSignedDistancePrimitive(p, type); }, {1e-6, 4e-6});
    }
}

// Metaball potential: a quintic in d/r per ball whose terms (<= 15 in size) cancel to <= 1, summed
// over 3 balls: ~30 roundings of values <= 10, at most 30*10*u = 1.8e-5 in the worst case.
// Bound: 2e-5 absolute + 1e-6 relative.
TEST(PrecisionDE, MetaballsPotential) {
    const Metaballs<float> bf = InitializeAnimatedMetaballs(0.0f, 12.0f);
    const Metaballs<double> bd = InitializeAnimatedMetaballs(0.0, 12.0);
    const auto pts = shellPoints(kSeed + 4, dvec3(0), 0.0, 1.2);
    checkDe("Metaballs_potential", pts, [&bf](const vec3& p) { return CalculateMetaballsPotential(p, bf); },
            [&bd](const dvec3& p) { return CalculateMetaballsPotential(p, bd); }, {1e-6, 2e-5});
}

// ---- marches ------------------------------------------------------------------------------------------
struct MarchResult {
    bool hit = false;
    double t = 0;
    double tol = 0;  // per-ray part of the t bound (e.g. one metaball step); 0 if none
};

struct MarchBound {
    double minAgreement;  // fraction of rays with the same hit/miss outcome
    double tAbs;          // |t_float - t_double| <= tAbs + tRel*t_double + result.tol on joint hits
    double tRel;
};

// kRays rays from the sphere of radius rOrigin around `centre`, aimed within rAim of `target`, each in
// float and promoted exactly to double (fixtures::rayPair).
std::vector<RayPair> rays(std::uint32_t seed, const dvec3& centre, double rOrigin, const dvec3& target, double rAim) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<RayPair> out;
    while (int(out.size()) < kRays) {
        const dvec3 o = centre + rOrigin * randomUnit(rng);
        const dvec3 aim = target + rAim * std::cbrt(u(rng)) * randomUnit(rng);
        out.push_back(fixtures::rayPair(o, aim));
    }
    return out;
}

void checkMarch(const std::string& name, const std::vector<RayPair>& rs,
                const std::function<MarchResult(const Ray<float>&)>& mf,
                const std::function<MarchResult(const Ray<double>&)>& md, MarchBound bound) {
    int agree = 0, hitsF = 0, hitsD = 0, joint = 0, tFailures = 0;
    double worstDt = 0, worstUse = 0;
    std::vector<double> dts;
    for (const RayPair& r : rs) {
        const MarchResult a = mf(r.f);
        const MarchResult b = md(r.d);
        hitsF += a.hit;
        hitsD += b.hit;
        if (a.hit == b.hit) ++agree;
        if (!(a.hit && b.hit)) continue;
        ++joint;
        const double dt = std::fabs(a.t - b.t);
        const double allowed = bound.tAbs + bound.tRel * std::fabs(b.t) + std::max(a.tol, b.tol);
        dts.push_back(dt);
        worstDt = std::max(worstDt, dt);
        worstUse = std::max(worstUse, dt / allowed);
        if (!(dt <= allowed) && ++tFailures <= 5)
            ADD_FAILURE() << name << ": |t_f - t_d| = |" << a.t << " - " << b.t << "| = " << dt << " > " << allowed
                          << " for o = (" << r.f.origin.x << ", " << r.f.origin.y << ", " << r.f.origin.z << "), d = ("
                          << r.f.direction.x << ", " << r.f.direction.y << ", " << r.f.direction.z << ")";
    }
    std::sort(dts.begin(), dts.end());
    const double median = dts.empty() ? 0 : dts[dts.size() / 2];
    const double rate = double(agree) / double(rs.size());
    report("March." + name, fmt("hits f/d=%.0f/%.0f agreement=%.4f", hitsF, hitsD, rate) +
                                fmt(" median|dt|=%.3g worst|dt|=%.3g worst bound use=%.3g", median, worstDt, worstUse));
    EXPECT_GE(rate, bound.minAgreement) << name;
    EXPECT_GT(joint, int(rs.size()) / 4) << name << ": too few joint hits to measure t";
    EXPECT_EQ(tFailures, 0) << name;
}

// Mandelbulb march, local rays from radius 2 aimed within 0.9 of the centre (a mix of hits and
// misses), rays passing within ~0.1 of the y axis skipped (H5/H6) and never at the centre (H4).
// A hit/miss flip needs a ray within rounding (~1e-6) of a tangency, of the bounding-sphere exit or
// of the stopping threshold; with 1000 rays the expected number of such rays is far below 1.
// iMax 4 (T0): the hit is (almost always) t after 4 DE steps, so t is a sum of 4 DE values and
// inherits their relative error (<= 1e-3, PrecisionDE.MandelbulbMdist): |dt| <= 1e-3*t + 1e-5,
// agreement >= 99.5% (at most 5 flips).
// iMax 129 (T1): the march stops at the first h < 1e-4*t. If rounding puts h on the other side of
// that threshold in one precision, that run takes one more step of h ~ 1e-4*t (and a few
// geometrically shrinking ones at oblique incidence): |dt| <= 3e-4*t + 1e-5. The fractal has many
// near-tangent lobes, so agreement >= 99%.
bool nearYAxis(const RayPair& r) {
    // closest approach of the ray line to the y axis, over the part inside radius 1.25
    const dvec3 o = r.d.origin, d = r.d.direction;
    const double a = d.x * d.x + d.z * d.z;
    if (a < 1e-12) return true;
    const double s = -(o.x * d.x + o.z * d.z) / a;
    const dvec3 q = o + s * d;
    return std::sqrt(q.x * q.x + q.z * q.z) < 0.1 && glm::length(q) < 1.3;
}

std::vector<RayPair> mandelbulbRays(std::uint32_t seed) {
    auto all = rays(seed, dvec3(0), 2.0, dvec3(0), 0.9);
    std::erase_if(all, nearYAxis);
    return all;
}

template <int IMax>
MarchResult mandelbulbMarch(const auto& r) {
    const auto h = mandelbulb::MandelbulbDistance(r.origin, r.direction, IMax);
    return {h.hit, double(h.thit), 0.0};
}

TEST(PrecisionMarch, MandelbulbIMax4) {
    checkMarch("Mandelbulb_iMax4", mandelbulbRays(kSeed + 100), mandelbulbMarch<4, Ray<float>>,
               mandelbulbMarch<4, Ray<double>>, {0.995, 1e-5, 1e-3});
}

TEST(PrecisionMarch, MandelbulbIMax129) {
    checkMarch("Mandelbulb_iMax129", mandelbulbRays(kSeed + 101), mandelbulbMarch<129, Ray<float>>,
               mandelbulbMarch<129, Ray<double>>, {0.99, 1e-5, 3e-4});
}

// Julia side wall: q-space origins on a circle of radius 1.6 between the cut planes
// (q.y in [-0.9, -0.2]), aimed within 0.5 of (0, -0.55, 0), so the rays enter through the
// side and never through the cut face (H9) and never have rd.y = 0 (H10). The march stops at
// d < kPrecis = 2.5e-4 after steps min(d, 0.2); if rounding puts the last d on the other side of
// kPrecis, that run takes one more step of ~kPrecis: |dt| <= 2*kPrecis = 5e-4. Agreement >= 99%
// (the same flip argument as the Mandelbulb, fractal surface).
std::vector<RayPair> juliaSideRays(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<RayPair> out;
    while (int(out.size()) < kRays) {
        const double phi = 2 * std::numbers::pi * u(rng);
        const dvec3 o(1.6 * std::cos(phi), -0.9 + 0.7 * u(rng), 1.6 * std::sin(phi));
        const dvec3 aim = dvec3(0, -0.55, 0) + 0.5 * std::cbrt(u(rng)) * randomUnit(rng);
        out.push_back(fixtures::rayPair(o, aim));
    }
    return out;
}

MarchResult juliaMarch(const auto& r) {
    const auto tn = julia::raycast(r.origin, r.direction);
    return {tn.x >= 0, double(tn.x), 0.0};
}

TEST(PrecisionMarch, JuliaRaycastSideWall) {
    checkMarch("Julia_raycast_side", juliaSideRays(kSeed + 102), juliaMarch<Ray<float>>, juliaMarch<Ray<double>>,
               {0.99, 5e-4, 0.0});
}

// Julia cut face (H9, measured, not a hazard-free case): q-space origins above the plane y = 0
// looking down into it. jdist >= 0.2 at the cut, so the march overshoots by whole 0.2 steps
// and a sub-ulp change can move the hit by one step: |dt| <= 0.2 + 20 kPrecis; agreement >= 99%.
TEST(PrecisionMarch, JuliaRaycastCutFaceH9) {
    auto all = rays(kSeed + 103, dvec3(0, 1.0, 0), 0.6, dvec3(0, -0.3, 0), 0.7);
    checkMarch("Julia_raycast_cut_H9", all, juliaMarch<Ray<float>>, juliaMarch<Ray<double>>, {0.99, 0.205, 0.0});
}

// Pac-man sphere trace at T1 (RaySignedDistancePrimitiveTest: 512 steps, hit when
// dist <= 1e-4*t). The SDF agrees to ~1e-6 (above); if rounding puts the last dist on the other
// side of 1e-4*t, that run takes one more step of ~1e-4*t (a few shrinking ones at oblique
// incidence): |dt| <= 3e-4*t + 1e-5. Agreement >= 99.5% (flips need rounding-level grazing).
TEST(PrecisionMarch, PacmanSphereTrace) {
    const float tau = pacman::PacmanMouthInterpolant(canonicalT1());
    auto march = [tau](const auto& r) {
        using T = std::remove_cvref_t<decltype(r.origin.x)>;
        const auto h = RaySignedDistancePrimitiveTest(
            r, radianceExtent<T>(), [tau](const math::vec3<T>& p) { return pacman::pacMan(p, T(tau)); });
        return MarchResult{h.hit, double(h.thit), 0.0};
    };
    checkMarch("Pacman_trace", rays(kSeed + 104, dvec3(0), 1.5, dvec3(0), 0.6), march, march, {0.995, 1e-5, 3e-4});
}

// D3D12 sphere tracing of each SDF primitive with its stepScale; local rays from radius 3 aimed
// within 1.0 of the primitive's middle. Same reasoning and t bound as the Pac-man (|dt| <=
// 3e-4*t + 1e-5, times stepScale <= 1); the fractal pyramid's estimate is discontinuous where the
// nearest vertex switches (H13) and the cog's slots make many silhouettes: agreement >= 99%.
struct SdfMarchCase {
    const char* name;
    d3d12::SignedDistancePrimitive type;
    double stepScale;
    dvec3 target;
};
const SdfMarchCase kSdfMarchCases[] = {
    {"MiniSpheres", d3d12::SignedDistancePrimitive::MiniSpheres, 1.0, dvec3(0)},
    {"IntersectedRoundCube", d3d12::SignedDistancePrimitive::IntersectedRoundCube, 1.0, dvec3(0)},
    {"SquareTorus", d3d12::SignedDistancePrimitive::SquareTorus, 1.0, dvec3(0.75, 0, 0)},
    {"TwistedTorus", d3d12::SignedDistancePrimitive::TwistedTorus, 0.5, dvec3(0.6, 0, 0)},
    {"Cog", d3d12::SignedDistancePrimitive::Cog, 1.0, dvec3(0.6, 0, 0)},
    {"Cylinder", d3d12::SignedDistancePrimitive::Cylinder, 1.0, dvec3(0.5, 0, 0.5)},
    {"FractalPyramid", d3d12::SignedDistancePrimitive::FractalPyramid, 0.8, dvec3(0, -0.5, 0)},
};

TEST(PrecisionMarch, D3D12SphereTrace) {
    std::uint32_t seed = kSeed + 110;
    for (const SdfMarchCase& c : kSdfMarchCases) {
        auto march = [&c](const auto& r) {
            using T = std::remove_cvref_t<decltype(r.origin.x)>;
            SphereTraceParams<T> params;
            params.stepScale = T(c.stepScale);
            const auto h = RaySignedDistancePrimitiveTest(
                r, radianceExtent<T>(),
                [&c](const math::vec3<T>& p) { return d3d12::GetDistanceFromSignedDistancePrimitive(p, c.type); }, params);
            return MarchResult{h.hit, double(h.thit), 0.0};
        };
        checkMarch(std::string("D3D12_") + c.name, rays(seed++, dvec3(0), 3.0, c.target, 1.0), march, march,
                   {0.99, 1e-5, 3e-4});
    }
}

// Metaball march (T = 0): 128 fixed samples between the bounding-sphere entry and exit; the hit
// is the first sample with potential >= 0.25, never refined. Float and double compute the
// sample positions with different rounding, so a sample lying within rounding of the iso-surface
// can fall on either side: t then differs by exactly one step (tmax - tmin)/128. Bound: one
// step (per ray) + 1e-5; agreement >= 99.5% (the same flip argument as the Mandelbulb).
TEST(PrecisionMarch, Metaballs) {
    auto march = [](const auto& r) {
        using T = std::remove_cvref_t<decltype(r.origin.x)>;
        const RayExtent<T> ext = radianceExtent<T>();
        const auto h = RayMetaballsIntersectionTest(r, ext, T(0));
        T tmin = 0, tmax = 0;
        FindIntersectingMetaballs(r, ext, tmin, tmax, InitializeAnimatedMetaballs(T(0), T(12)));
        return MarchResult{h.hit, double(h.thit), h.hit ? double(tmax - tmin) / 128.0 : 0.0};
    };
    checkMarch("Metaballs", rays(kSeed + 120, dvec3(0), 3.0, dvec3(0), 0.9), march, march, {0.995, 1e-5, 0.0});
}

}  // namespace
}  // namespace refray::procedural::math
