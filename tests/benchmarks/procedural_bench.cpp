// Cost of the procedural shader math (issue 3): ns per call of every distance estimator / SDF
// the two reference scenes evaluate, of the analytic intersections, and of one full march per
// ray type, each for float (what the reference renders with) and double.
//
// Inputs are fixed: points and rays come from std::mt19937 with constant seeds, are generated
// once (in double, rounded to float, so both precisions see the same inputs), and are cycled
// through one per benchmark iteration, so "Time" is ns per call. March rays are kept only if
// they hit in the precision being measured, so every timed march ends on a surface.
// Parameters follow docs reference-scene-proceduray.md §3 and reference-scene-d3d12-procedural.md
// §2: Mandelbulb iMax 4 (T0) and 129 (T1), Julia kc/200 iterations/1024 steps, Pac-man mouth at
// T1, D3D12 512-step sphere tracing with each primitive's stepScale, metaballs at T = 0.
// Results and their reading: docs/procedural-costs.md.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "procedural/math/analytic.h"
#include "procedural/math/fractals.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/sdf.h"
#include "tests/procedural/sweep_support.h"

namespace {

using namespace refray::procedural::math;
namespace hlsl = refray::procedural::hlsl;
using glm::dvec3;
using fixtures::canonicalT1;
using fixtures::radianceExtent;
using fixtures::randomUnit;

constexpr std::size_t kSetSize = 256;  // points / rays per set (a power of two)

// ---- fixed inputs --------------------------------------------------------------------------------

// Points with |p - centre| in [rMin, rMax] (uniform radius, uniform direction), rounded to T.
template <typename T>
std::vector<vec3<T>> shellPoints(std::uint32_t seed, const dvec3& centre, double rMin, double rMax) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> r(rMin, rMax);
    std::vector<vec3<T>> pts;
    pts.reserve(kSetSize);
    while (pts.size() < kSetSize) pts.push_back(vec3<T>(centre + r(rng) * randomUnit(rng)));
    return pts;
}

// Candidate ray k of a seeded stream: origin on the sphere (centre, rOrigin), aimed at a point
// within rAim of `target`; unit direction. Rounded to T, so T = float and T = double see
// the same stream up to float rounding.
template <typename T>
Ray<T> candidateRay(std::mt19937& rng, const dvec3& centre, double rOrigin, const dvec3& target, double rAim) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const dvec3 o = centre + rOrigin * randomUnit(rng);
    const dvec3 aim = target + rAim * std::cbrt(u(rng)) * randomUnit(rng);
    Ray<T> ray;
    ray.origin = vec3<T>(o);
    ray.direction = hlsl::normalize(vec3<T>(glm::normalize(aim - o)));
    return ray;
}

// kSetSize rays of the stream that `hits` accepts.
template <typename T, class Hits>
std::vector<Ray<T>> hittingRays(std::uint32_t seed, const dvec3& centre, double rOrigin, const dvec3& target,
                                double rAim, Hits&& hits) {
    std::mt19937 rng(seed);
    std::vector<Ray<T>> rays;
    rays.reserve(kSetSize);
    for (int tries = 0; rays.size() < kSetSize && tries < 100000; ++tries) {
        const Ray<T> ray = candidateRay<T>(rng, centre, rOrigin, target, rAim);
        if (hits(ray)) rays.push_back(ray);
    }
    return rays;
}

template <typename T>
const char* typeName() {
    return sizeof(T) == sizeof(float) ? "float" : "double";
}

// ---- runners ---------------------------------------------------------------------------------------

// One call of f per iteration, cycling through `inputs`.
template <class Input, class F>
void runOverSet(benchmark::State& state, const std::vector<Input>& inputs, F f) {
    if (inputs.size() != kSetSize) {
        state.SkipWithError("could not generate a full input set");
        return;
    }
    std::size_t i = 0;
    for (auto _ : state) {
        auto r = f(inputs[i]);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & (kSetSize - 1);
    }
    state.SetItemsProcessed(state.iterations());
}

// Average of `steps(input)` over the set, reported as the counter "steps" (a property of the
// inputs, computed once outside the timed loop).
template <class Input, class Steps>
void reportSteps(benchmark::State& state, const std::vector<Input>& inputs, Steps steps) {
    double sum = 0;
    for (const Input& in : inputs) sum += double(steps(in));
    state.counters["steps"] = inputs.empty() ? 0.0 : sum / double(inputs.size());
}

// ---- distance estimators ---------------------------------------------------------------------------

// Mandelbulb (Proceduray §3.4): local points between the fractal (|p| <~ 1.05) and its bounding
// sphere (1.25), i.e. where the march samples.
template <typename T>
void BM_Mandelbulb_mdist(benchmark::State& state) {
    const auto pts = shellPoints<T>(101, dvec3(0), 0.9, 1.25);
    runOverSet(state, pts, [](const vec3<T>& p) {
        vec4<T> trap;
        return mandelbulb::mdist(p, trap);
    });
}

// Quaternion Julia (Proceduray §3.5): q-space points in the upper part of the radius-1.2 sphere.
template <typename T>
void BM_Julia_jdist(benchmark::State& state) {
    const auto pts = shellPoints<T>(102, dvec3(0), 0.8, 1.2);
    const vec4<T> c = julia::kc<T>();
    runOverSet(state, pts, [&c](const vec3<T>& p) { return julia::jdist(p, c, 200); });
}

// Pac-man (Proceduray §3.3) at the T1 mouth opening; points around the radius-0.5 head.
template <typename T>
void BM_Pacman_sdf(benchmark::State& state) {
    const auto pts = shellPoints<T>(103, dvec3(0), 0.3, 0.8);
    const T tau = T(pacman::PacmanMouthInterpolant(canonicalT1()));
    runOverSet(state, pts, [tau](const vec3<T>& p) { return pacman::pacMan(p, tau); });
}

// D3D12 sample SDF primitives (§2.7–2.8) through the IS's switch; local AABB space [-1,1]^3.
template <typename T>
void BM_D3D12_sdf(benchmark::State& state, d3d12::SignedDistancePrimitive type) {
    const auto pts = shellPoints<T>(104, dvec3(0), 0.2, 1.6);
    runOverSet(state, pts, [type](const vec3<T>& p) { return d3d12::GetDistanceFromSignedDistancePrimitive(p, type); });
}

// Metaball field (D3D12 §2.5): the 3-ball potential sum at T = 0, points in the local box.
template <typename T>
void BM_Metaballs_potential(benchmark::State& state) {
    const auto pts = shellPoints<T>(105, dvec3(0), 0.0, 1.0);
    const Metaballs<T> blobs = InitializeAnimatedMetaballs(T(0), T(12));
    runOverSet(state, pts, [&blobs](const vec3<T>& p) { return CalculateMetaballsPotential(p, blobs); });
}

// ---- analytic intersections ------------------------------------------------------------------------

// D3D12 "Spheres" primitive: closest of the three hollow spheres (§2.4).
template <typename T>
void BM_Analytic_spheres(benchmark::State& state) {
    const RayExtent<T> ext = radianceExtent<T>();
    const auto rays = hittingRays<T>(201, dvec3(0), 3.0, dvec3(0), 0.5,
                                     [&ext](const Ray<T>& r) { return RaySpheresIntersectionTest(r, ext).hit; });
    runOverSet(state, rays, [&ext](const Ray<T>& r) { return RaySpheresIntersectionTest(r, ext); });
}

// One hollow unit sphere with culling (RaySphereIntersectionTest).
template <typename T>
void BM_Analytic_sphere(benchmark::State& state) {
    const RayExtent<T> ext = radianceExtent<T>();
    auto test = [&ext](const Ray<T>& r) {
        T tmax = T(0);
        return RaySphereIntersectionTest(r, ext, tmax);
    };
    const auto rays = hittingRays<T>(202, dvec3(0), 3.0, dvec3(0), 0.8, [&test](const Ray<T>& r) { return test(r).hit; });
    runOverSet(state, rays, test);
}

// Proceduray isphere (the Mandelbulb's bounding-sphere clip).
template <typename T>
void BM_Analytic_isphere(benchmark::State& state) {
    const auto rays = hittingRays<T>(203, dvec3(0), 3.0, dvec3(0), 1.0, [](const Ray<T>&) { return true; });
    const vec4<T> sph(T(0), T(0), T(0), T(1.25));
    runOverSet(state, rays, [&sph](const Ray<T>& r) { return isphere(sph, r.origin, r.direction); });
}

// D3D12 analytic box (§2.3): slab test plus the face normal, local cube [-1,1]^3.
template <typename T>
void BM_Analytic_aabb(benchmark::State& state) {
    const RayExtent<T> ext = radianceExtent<T>();
    const auto rays = hittingRays<T>(204, dvec3(0), 3.0, dvec3(0), 0.9,
                                     [&ext](const Ray<T>& r) { return RayUnitCubeIntersectionTest(r, ext).hit; });
    runOverSet(state, rays, [&ext](const Ray<T>& r) { return RayUnitCubeIntersectionTest(r, ext); });
}

// The bare slab test (the bool overload), as the D3D12 box and any AABB clip use it.
template <typename T>
void BM_Analytic_slab(benchmark::State& state) {
    const RayExtent<T> ext = radianceExtent<T>();
    const vec3<T> box[2] = {vec3<T>(T(-1)), vec3<T>(T(1))};
    auto test = [&ext, &box](const Ray<T>& r) {
        T tmin = T(0);
        T tmax = T(0);
        const bool hit = RayAABBIntersectionTest(r, box, ext, tmin, tmax);
        return hit ? tmin : T(-1);
    };
    const auto rays = hittingRays<T>(205, dvec3(0), 3.0, dvec3(0), 0.9, [&test](const Ray<T>& r) { return test(r) >= T(0); });
    runOverSet(state, rays, test);
}

// ---- marches -----------------------------------------------------------------------------------------

// Mandelbulb march (Proceduray §3.4) with iMax 4 (T0) or 129 (T1): local rays from radius 2,
// aimed within 0.3 of the centre (never at it: H4), kept when they hit.
template <typename T>
void BM_March_mandelbulb(benchmark::State& state, int iMax) {
    const auto rays = hittingRays<T>(301, dvec3(0), 2.0, dvec3(0), 0.3, [iMax](const Ray<T>& r) {
        return mandelbulb::MandelbulbDistance(r.origin, r.direction, iMax).hit;
    });
    runOverSet(state, rays, [iMax](const Ray<T>& r) { return mandelbulb::MandelbulbDistance(r.origin, r.direction, iMax); });
}

// Julia raycast (Proceduray §3.5) in q-space: origins on a sphere of radius 1.6 around the
// q-space centre, aimed within 0.4 of (0, -0.4, 0), kept when raycast returns t >= 0.
template <typename T>
void BM_March_julia_raycast(benchmark::State& state) {
    const dvec3 target(0, -0.4, 0);
    const auto rays = hittingRays<T>(302, dvec3(0), 1.6, target, 0.4,
                                     [](const Ray<T>& r) { return julia::raycast(r.origin, r.direction).x >= T(0); });
    runOverSet(state, rays, [](const Ray<T>& r) { return julia::raycast(r.origin, r.direction); });
}

// The whole Julia intersection (local -> q-space, raycast, tetrahedral normal = 4 more jdist).
// Local rays: q = 0.4*local + (0,-1,0), so the q-space set above maps to centre (0, 2.5, 0).
template <typename T>
void BM_March_julia_intersection(benchmark::State& state) {
    const auto rays = hittingRays<T>(303, dvec3(0, 2.5, 0), 4.0, dvec3(0, 1.5, 0), 1.0,
                                     [](const Ray<T>& r) { return julia::JuliaDistance(r.origin, r.direction).hit; });
    runOverSet(state, rays, [](const Ray<T>& r) { return julia::JuliaDistance(r.origin, r.direction); });
}

// Pac-man sphere trace (RaySignedDistancePrimitiveTest, 512 steps, threshold 1e-4*t) at T1.
template <typename T>
void BM_March_pacman(benchmark::State& state) {
    const RayExtent<T> ext = radianceExtent<T>();
    const T tau = T(pacman::PacmanMouthInterpolant(canonicalT1()));
    auto sdf = [tau](const vec3<T>& p) { return pacman::pacMan(p, tau); };
    auto trace = [&ext, &sdf](const Ray<T>& r) { return RaySignedDistancePrimitiveTest(r, ext, sdf); };
    const auto rays = hittingRays<T>(304, dvec3(0), 1.5, dvec3(0), 0.3, [&trace](const Ray<T>& r) { return trace(r).hit; });
    reportSteps(state, rays, [&trace](const Ray<T>& r) { return trace(r).steps; });
    runOverSet(state, rays, trace);
}

// D3D12 sphere tracing of one SDF primitive (§2.6), with the primitive's stepScale (§1.4):
// local rays from radius 3 (outside [-1,1]^3), aimed within 0.6 of the primitive's middle.
template <typename T>
void BM_March_d3d12_sdf(benchmark::State& state, d3d12::SignedDistancePrimitive type, double stepScale, dvec3 target) {
    const RayExtent<T> ext = radianceExtent<T>();
    SphereTraceParams<T> params;
    params.stepScale = T(stepScale);
    auto sdf = [type](const vec3<T>& p) { return d3d12::GetDistanceFromSignedDistancePrimitive(p, type); };
    auto trace = [&](const Ray<T>& r) { return RaySignedDistancePrimitiveTest(r, ext, sdf, params); };
    const auto rays = hittingRays<T>(305 + std::uint32_t(type), dvec3(0), 3.0, target, 0.6,
                                     [&trace](const Ray<T>& r) { return trace(r).hit; });
    reportSteps(state, rays, [&trace](const Ray<T>& r) { return trace(r).steps; });
    runOverSet(state, rays, trace);
}

// Metaball march (D3D12 §2.5): 128 fixed samples over the union of the bounding spheres, T = 0.
template <typename T>
void BM_March_metaballs(benchmark::State& state) {
    const RayExtent<T> ext = radianceExtent<T>();
    auto march = [&ext](const Ray<T>& r) { return RayMetaballsIntersectionTest(r, ext, T(0)); };
    const auto rays = hittingRays<T>(320, dvec3(0), 3.0, dvec3(0), 0.4, [&march](const Ray<T>& r) { return march(r).hit; });
    reportSteps(state, rays, [&march](const Ray<T>& r) { return march(r).step; });
    runOverSet(state, rays, march);
}

// ---- registration ------------------------------------------------------------------------------------

struct SdfCase {
    const char* name;
    d3d12::SignedDistancePrimitive type;
    double stepScale;  // D3D12 fact sheet §1.4
    dvec3 target;      // where the march rays aim (local space)
};

const SdfCase kSdfCases[] = {
    {"MiniSpheres", d3d12::SignedDistancePrimitive::MiniSpheres, 1.0, dvec3(0)},
    {"IntersectedRoundCube", d3d12::SignedDistancePrimitive::IntersectedRoundCube, 1.0, dvec3(0)},
    {"SquareTorus", d3d12::SignedDistancePrimitive::SquareTorus, 1.0, dvec3(0.75, 0, 0)},
    {"TwistedTorus", d3d12::SignedDistancePrimitive::TwistedTorus, 0.5, dvec3(0.6, 0, 0)},
    {"Cog", d3d12::SignedDistancePrimitive::Cog, 1.0, dvec3(0.6, 0, 0)},
    {"Cylinder", d3d12::SignedDistancePrimitive::Cylinder, 1.0, dvec3(0.5, 0, 0.5)},
    {"FractalPyramid", d3d12::SignedDistancePrimitive::FractalPyramid, 0.8, dvec3(0, -0.5, 0)},
};

template <typename T>
void registerFor() {
    const std::string t = typeName<T>();
    auto reg = [&t](const std::string& name, auto fn) { benchmark::RegisterBenchmark((name + "/" + t).c_str(), fn); };

    reg("DE/Mandelbulb_mdist", BM_Mandelbulb_mdist<T>);
    reg("DE/Julia_jdist", BM_Julia_jdist<T>);
    reg("DE/Pacman", BM_Pacman_sdf<T>);
    for (const SdfCase& c : kSdfCases)
        reg(std::string("DE/D3D12_") + c.name, [type = c.type](benchmark::State& s) { BM_D3D12_sdf<T>(s, type); });
    reg("DE/Metaballs_potential", BM_Metaballs_potential<T>);

    reg("Analytic/Spheres3", BM_Analytic_spheres<T>);
    reg("Analytic/Sphere", BM_Analytic_sphere<T>);
    reg("Analytic/isphere", BM_Analytic_isphere<T>);
    reg("Analytic/AABB_box", BM_Analytic_aabb<T>);
    reg("Analytic/AABB_slab", BM_Analytic_slab<T>);

    reg("March/Mandelbulb_iMax4", [](benchmark::State& s) { BM_March_mandelbulb<T>(s, 4); });
    reg("March/Mandelbulb_iMax129", [](benchmark::State& s) { BM_March_mandelbulb<T>(s, 129); });
    reg("March/Julia_raycast", BM_March_julia_raycast<T>);
    reg("March/Julia_intersection", BM_March_julia_intersection<T>);
    reg("March/Pacman", BM_March_pacman<T>);
    for (const SdfCase& c : kSdfCases)
        reg(std::string("March/D3D12_") + c.name,
            [c](benchmark::State& s) { BM_March_d3d12_sdf<T>(s, c.type, c.stepScale, c.target); });
    reg("March/Metaballs", BM_March_metaballs<T>);
}

[[maybe_unused]] const bool kRegistered = [] {
    registerFor<float>();
    registerFor<double>();
    return true;
}();

}  // namespace

BENCHMARK_MAIN();
