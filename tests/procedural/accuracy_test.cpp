// Tests procedural/accuracy.h as the two shader libraries apply it (issue 7): with Accuracy{} every march is the
// HLSL's bit for bit (the math with the knobs' default parameters equals the calls without them, in float and
// double), and each knob does what accuracy.h says: stepsFactor scales the SDF, Julia and Mandelbulb step limits,
// thresholdFactor the hit thresholds (not Julia's tmin), the iteration counts change the distance estimators,
// normalEpsilonFactor moves normals slightly, metaballSteps changes the metaballs' samples, and maxRecursionDepth
// the number of TraceRay levels.
//
// The math is checked through the libraries' own conversions (sphereTraceParams, mandelbulbParams, ...), the
// entry points through both factories in a small scene: the library's Raygen and hit groups, or a probe closest
// hit that records what the library's intersection shader reported.
//
// The knobs' effects are in accuracy_march_test.cpp (steps, thresholds, iterations) and accuracy_shading_test.cpp
// (normals, metaball samples, recursion); the rig they share is accuracy_rig.h.
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "tests/procedural/accuracy_rig.h"

namespace refray::procedural {
namespace {

using namespace accuracy_rig;

using Scalars = ::testing::Types<float, double>;

template <typename T, glm::length_t N>
void expectSameBits(const glm::vec<N, T>& a, const glm::vec<N, T>& b, const std::string& what) {
    for (glm::length_t i = 0; i < N; ++i) EXPECT_EQ(bitsOf(a[i]), bitsOf(b[i])) << what << " component " << i;
}

// ---- Seeded rays (sweep_support.h) ---------------------------------------------------------------------

template <typename T>
const Ray<T>& rayOf(const math::fixtures::RayPair& r) {
    if constexpr (std::is_same_v<T, float>) return r.f;
    else return r.d;
}

// `count` rays from the sphere of radius `from` about `centre`, each aimed at a point within `within` of it.
std::vector<math::fixtures::RayPair> raysAt(uint32_t seed, int count, const glm::dvec3& centre, double from,
                                            double within) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> radius(0.0, within);
    std::vector<math::fixtures::RayPair> rays;
    for (int i = 0; i < count; ++i) {
        const glm::dvec3 origin = centre + from * math::fixtures::randomUnit(rng);
        const glm::dvec3 aim = centre + radius(rng) * math::fixtures::randomUnit(rng);
        rays.push_back(math::fixtures::rayPair(origin, aim));
    }
    return rays;
}

// The Accuracy that spells out every HLSL value instead of leaving it unset.
Accuracy spelledOutHlslAccuracy() {
    Accuracy a;
    a.stepsFactor = 1.0;
    a.thresholdFactor = 1.0;
    a.mandelbulbIterations = 4;
    a.juliaIterations = 200;
    a.normalEpsilonFactor = 1.0;
    a.metaballSteps = 128;
    a.maxRecursionDepth = 3;
    return a;
}

// =======================================================================================================
// Helpers of accuracy.h
// =======================================================================================================

TEST(AccuracyKnobsHelpers, ScaledConstantKeepsTheConstantAtFactorOneAndMultipliesInT) {
    EXPECT_EQ(bitsOf(scaledConstant(0.0001f, 1.0)), bitsOf(0.0001f));
    EXPECT_EQ(bitsOf(scaledConstant(double(0.00025f), 1.0)), bitsOf(double(0.00025f)));
    EXPECT_EQ(bitsOf(scaledConstant(0.0001f, 0.1)), bitsOf(0.0001f * 0.1f));  // the factor rounded to float first
    EXPECT_EQ(bitsOf(scaledConstant(0.0001, 0.1)), bitsOf(0.0001 * 0.1));
}

TEST(AccuracyKnobsHelpers, LoopCountsStayInTheHlslIntRange) {
    EXPECT_EQ(hlslLoopCount(0), 0);
    EXPECT_EQ(hlslLoopCount(200), 200);
    EXPECT_EQ(hlslLoopCount(2147483647u), 2147483647);
    EXPECT_EQ(hlslLoopCount(4000000000u), 2147483647);
}

// =======================================================================================================
// Defaults: the HLSL's constants, bit for bit
// =======================================================================================================

template <typename T>
class AccuracyKnobsDefaults : public ::testing::Test {};
TYPED_TEST_SUITE(AccuracyKnobsDefaults, Scalars);

// Every parameter the libraries derive from Accuracy{} (or from the HLSL values spelled out) is the HLSL literal
// computed the way the HLSL computes it.
TYPED_TEST(AccuracyKnobsDefaults, LibraryParametersAreTheHlslConstants) {
    using T = TypeParam;
    for (const Accuracy& a : {Accuracy{}, spelledOutHlslAccuracy()}) {
        for (const math::SphereTraceParams<T>& sdf :
             {proceduray::sphereTraceParams<T>(a, T(0.8f)), d3d12::sphereTraceParams<T>(a, T(0.8f))}) {
            EXPECT_EQ(bitsOf(sdf.threshold), bitsOf(T(0.0001)));
            EXPECT_EQ(sdf.maxSteps, 512u);
            EXPECT_EQ(bitsOf(sdf.stepScale), bitsOf(T(0.8f)));
            EXPECT_EQ(bitsOf(sdf.normalOffset), bitsOf(T(T(0.5773) * T(0.0001))));
        }

        const auto mandelbulb = proceduray::mandelbulbParams<T>(a);
        EXPECT_EQ(bitsOf(mandelbulb.threshold), bitsOf(T(0.0001)));
        EXPECT_EQ(mandelbulb.iterations, 4);
        EXPECT_EQ(bitsOf(mandelbulb.normalOffset), bitsOf(T(T(0.5773) * T(0.0001))));
        for (int iMax = -300; iMax <= 300; ++iMax) ASSERT_EQ(proceduray::mandelbulbStepCount(iMax, a), iMax);

        const auto julia = proceduray::juliaParams<T>(a);
        EXPECT_EQ(julia.iterations, 200);
        EXPECT_EQ(julia.marchSteps, 1024);
        EXPECT_EQ(bitsOf(julia.precis), bitsOf(T(0.00025f)));
        EXPECT_EQ(bitsOf(julia.normalOffset), bitsOf(T(T(0.5773f) * T(0.00025f))));

        const auto metaballs = d3d12::metaballsParams<T>(a);
        EXPECT_EQ(metaballs.maxSteps, 128u);
        EXPECT_EQ(bitsOf(metaballs.normalOffset), bitsOf(static_cast<T>(0.5773 * 0.00001)));

        EXPECT_EQ(proceduray::maxRayRecursionDepth(a), 3u);
        EXPECT_EQ(d3d12::maxRayRecursionDepth(a), 3u);
    }
    // The public constants stay the HLSL's.
    EXPECT_EQ(proceduray::MAX_RAY_RECURSION_DEPTH, 3u);
    EXPECT_EQ(d3d12::MAX_RAY_RECURSION_DEPTH, 3u);
}

// The Mandelbulb: mdist, calcNormal and the march with the parameters of Accuracy{} against the old call forms.
TYPED_TEST(AccuracyKnobsDefaults, MandelbulbWithDefaultParametersIsBitIdentical) {
    using T = TypeParam;
    namespace mb = math::mandelbulb;
    const auto params = proceduray::mandelbulbParams<T>(Accuracy{});
    for (const auto& pair : raysAt(11, 8, glm::dvec3(0.0), 1.6, 0.8)) {
        const Ray<T>& r = rayOf<T>(pair);
        for (const int iMax : {4, 129}) {
            const mb::MandelbulbHit<T> old = mb::MandelbulbDistance(r.origin, r.direction, iMax);
            const int steps = proceduray::mandelbulbStepCount(iMax, Accuracy{});
            const mb::MandelbulbHit<T> knobs = mb::MandelbulbDistance(r.origin, r.direction, steps, params);
            ASSERT_EQ(old.hit, knobs.hit);
            EXPECT_EQ(bitsOf(old.thit), bitsOf(knobs.thit));
            expectSameBits(old.normal, knobs.normal, "normal");
            expectSameBits(old.color, knobs.color, "trap");
            expectSameBits(old.pos, knobs.pos, "pos");
        }
        const tvec3<T> p = r.origin * T(0.5);
        tvec4<T> oldTrap, knobsTrap;
        EXPECT_EQ(bitsOf(mb::mdist(p, oldTrap)), bitsOf(mb::mdist(p, knobsTrap, params.iterations)));
        expectSameBits(oldTrap, knobsTrap, "mdist trap");
        EXPECT_EQ(bitsOf(mb::mdist(p)), bitsOf(mb::mdist(p, params.iterations)));
        expectSameBits(mb::calcNormal(p), mb::calcNormal(p, params.normalOffset, params.iterations), "calcNormal");
    }
}

// The Julia set: raycast, calcNormal and JuliaDistance with the parameters of Accuracy{} against the old call forms.
TYPED_TEST(AccuracyKnobsDefaults, JuliaWithDefaultParametersIsBitIdentical) {
    using T = TypeParam;
    namespace jl = math::julia;
    const auto params = proceduray::juliaParams<T>(Accuracy{});
    for (const auto& pair : raysAt(12, 4, glm::dvec3(0, -0.5, 0), 1.5, 0.8)) {
        const Ray<T>& q = rayOf<T>(pair);  // in q-space
        const glm::vec<2, T> old = jl::raycast(q.origin, q.direction);
        const glm::vec<2, T> knobs = jl::raycast(q.origin, q.direction, jl::kc<T>(), T(0), params.iterations,
                                                 params.marchSteps, params.precis);
        expectSameBits(old, knobs, "raycast");
        const tvec3<T> p = q.origin * T(0.6);
        expectSameBits(jl::calcNormal(p), jl::calcNormal(p, jl::kc<T>(), params.iterations, params.normalOffset),
                       "calcNormal");

        // The same ray in local space: q = 0.4 * local + (0, -1, 0).
        const tvec3<T> local = (q.origin - tvec3<T>(T(0), T(-1), T(0))) / T(0.4);
        const jl::JuliaHit<T> oldHit = jl::JuliaDistance(local, q.direction);
        const jl::JuliaHit<T> knobsHit = jl::JuliaDistance(local, q.direction, params);
        ASSERT_EQ(oldHit.hit, knobsHit.hit);
        expectSameBits(oldHit.resT, knobsHit.resT, "resT");
        expectSameBits(oldHit.normal, knobsHit.normal, "normal");
    }
}

template <typename T, class Sdf>
void expectSameSphereTrace(const Ray<T>& r, Sdf&& sdf, T stepScale, const math::SphereTraceParams<T>& params) {
    math::SphereTraceParams<T> old;  // what the entry points passed before the knobs
    old.stepScale = stepScale;
    const auto a = math::RaySignedDistancePrimitiveTest(r, math::fixtures::radianceExtent<T>(), sdf, old);
    const auto b = math::RaySignedDistancePrimitiveTest(r, math::fixtures::radianceExtent<T>(), sdf, params);
    ASSERT_EQ(a.hit, b.hit);
    EXPECT_EQ(bitsOf(a.thit), bitsOf(b.thit));
    expectSameBits(a.normal, b.normal, "normal");
    expectSameBits(a.position, b.position, "position");
    EXPECT_EQ(a.steps, b.steps);
}

// The sphere tracing of both libraries: the Pac-man (at T0 and T1) and the seven D3D12 SDFs.
TYPED_TEST(AccuracyKnobsDefaults, SphereTracingWithDefaultParametersIsBitIdentical) {
    using T = TypeParam;
    for (const T time : {T(0), T(math::fixtures::canonicalT1())}) {
        const T mouth = math::pacman::PacmanMouthInterpolant(time);
        const auto pacman = [mouth](const tvec3<T>& p) { return math::pacman::pacMan(p, mouth); };
        for (const auto& pair : raysAt(13, 6, glm::dvec3(0.0), 1.2, 0.4))
            expectSameSphereTrace(rayOf<T>(pair), pacman, T(1), proceduray::sphereTraceParams<T>(Accuracy{}, T(1)));
    }
    for (uint32_t type = 0; type <= 6; ++type) {
        const auto sdf = [type](const tvec3<T>& p) {
            return math::d3d12::GetDistanceFromSignedDistancePrimitive(p, math::d3d12::SignedDistancePrimitive(type));
        };
        for (const auto& pair : raysAt(14 + type, 3, glm::dvec3(0.0), 2.5, 0.8))
            expectSameSphereTrace(rayOf<T>(pair), sdf, T(0.8f), d3d12::sphereTraceParams<T>(Accuracy{}, T(0.8f)));
    }
}

// The metaballs: the march and the normal with the parameters of Accuracy{} against the old call forms.
TYPED_TEST(AccuracyKnobsDefaults, MetaballsWithDefaultParametersAreBitIdentical) {
    using T = TypeParam;
    const auto params = d3d12::metaballsParams<T>(Accuracy{});
    for (const T time : {T(0), T(3)}) {
        const math::Metaballs<T> blobs = math::InitializeAnimatedMetaballs(time, T(12));
        for (const auto& pair : raysAt(21, 8, glm::dvec3(0.0), 2.0, 0.6)) {
            const Ray<T>& r = rayOf<T>(pair);
            const auto old = math::RayMetaballsIntersectionTest(r, math::fixtures::radianceExtent<T>(), time);
            const auto knobs =
                math::RayMetaballsIntersectionTest(r, math::fixtures::radianceExtent<T>(), time, T(12), params);
            ASSERT_EQ(old.hit, knobs.hit);
            EXPECT_EQ(bitsOf(old.thit), bitsOf(knobs.thit));
            expectSameBits(old.normal, knobs.normal, "normal");
            EXPECT_EQ(old.step, knobs.step);
            const tvec3<T> p = r.origin * T(0.2);
            expectSameBits(math::CalculateMetaballsNormal(p, blobs),
                           math::CalculateMetaballsNormal(p, blobs, params.normalOffset), "CalculateMetaballsNormal");
        }
    }
}

// =======================================================================================================
// Defaults through the factories
// =======================================================================================================

// A library built with the HLSL values spelled out renders what one built with Accuracy{} renders, bit for bit,
// in both precisions (the mirrors for the recursion, the fractals and the metaballs for the marches).
TEST(AccuracyKnobsDefaultLibraries, SpelledOutHlslValuesRenderTheDefaultPixels) {
    for (const Precision precision : {Precision::Float, Precision::Double}) {
        const auto renderProceduray = [precision](const Accuracy& a) {
            ProcedurayRig rig(a, precision);
            addPacmanA(rig, false);
            addMandelbulb(rig, false);
            addJulia(rig, false);
            std::vector<vec4> pixels;
            pixels.push_back(rig.render(kPacmanRay.Origin, kPacmanRay.Origin + kPacmanRay.Direction).pixel);
            pixels.push_back(rig.render(kMandelbulbRay.Origin, kMandelbulbRay.Origin + kMandelbulbRay.Direction).pixel);
            pixels.push_back(rig.render(kJuliaRay.Origin, kJuliaRay.Origin + kJuliaRay.Direction).pixel);
            return pixels;
        };
        const auto renderD3D12 = [precision](const Accuracy& a) {
            D3D12Rig rig(a, precision);
            addMetaballs(rig);
            addRoundCube(rig);
            std::vector<vec4> reports;  // (normal, t)
            for (const RayDesc& ray : {kMetaballsRay, kRoundCubeRay}) {
                const auto probe = rig.probe(ray).probe;
                EXPECT_EQ(probe.closestHits, 1);
                reports.push_back(vec4(probe.attr.normal, probe.t));
            }
            return reports;
        };
        const auto a = renderProceduray(Accuracy{});
        const auto b = renderProceduray(spelledOutHlslAccuracy());
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) expectSameBits(a[i], b[i], "Proceduray pixel " + std::to_string(i));
        const auto c = renderD3D12(Accuracy{});
        const auto d = renderD3D12(spelledOutHlslAccuracy());
        for (size_t i = 0; i < c.size(); ++i) expectSameBits(c[i], d[i], "D3D12 report " + std::to_string(i));
    }
}

}  // namespace
}  // namespace refray::procedural
