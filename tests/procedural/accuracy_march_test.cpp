// Tests of procedural/accuracy.h's marching knobs as the two shader libraries apply them (issue 7): stepsFactor
// scales the SDF, Julia and Mandelbulb step limits, thresholdFactor the hit thresholds (not Julia's tmin), and the
// iteration counts change the distance estimators. The rig is accuracy_rig.h; the defaults are in accuracy_test.cpp.
#include <gtest/gtest.h>

#include "tests/procedural/accuracy_rig.h"

namespace refray::procedural {
namespace {

using namespace accuracy_rig;

// =======================================================================================================
// stepsFactor
// =======================================================================================================

// Counts the steps of a grazing march on the Pac-man's head: with exactly as many steps as it needs it hits, bit
// for bit as with 512; one step fewer and it misses.
TEST(AccuracyKnobsSteps, SphereTracingStopsAfterTheScaledStepCount) {
    const Ray<float> grazing{vec3(-2.0f, 0.49f, 0.0f), vec3(1, 0, 0)};
    const auto sdf = [](const vec3& p) { return math::pacman::pacMan(p, 0.0f); };
    const auto extent = math::fixtures::radianceExtent<float>();
    const auto full = math::RaySignedDistancePrimitiveTest(grazing, extent, sdf,
                                                           proceduray::sphereTraceParams(Accuracy{}, 1.0f));
    ASSERT_TRUE(full.hit);
    ASSERT_GT(full.steps, 5u);

    Accuracy exact;
    exact.stepsFactor = double(full.steps) / 512.0;
    const auto enough = proceduray::sphereTraceParams(exact, 1.0f);
    EXPECT_EQ(enough.maxSteps, full.steps);
    const auto justEnough = math::RaySignedDistancePrimitiveTest(grazing, extent, sdf, enough);
    ASSERT_TRUE(justEnough.hit);
    EXPECT_EQ(bitsOf(justEnough.thit), bitsOf(full.thit));

    Accuracy fewer;
    fewer.stepsFactor = double(full.steps - 1) / 512.0;
    const auto tooFew =
        math::RaySignedDistancePrimitiveTest(grazing, extent, sdf, d3d12::sphereTraceParams(fewer, 1.0f));
    EXPECT_FALSE(tooFew.hit);
    EXPECT_EQ(tooFew.steps, full.steps - 1);

    Accuracy doubled;
    doubled.stepsFactor = 2.0;
    EXPECT_EQ(proceduray::sphereTraceParams(doubled, 1.0f).maxSteps, 1024u);
    EXPECT_EQ(d3d12::sphereTraceParams(doubled, 1.0).maxSteps, 1024u);
}

// The Mandelbulb's animated iMax and Julia's 1024 march steps scale the same way.
TEST(AccuracyKnobsSteps, FractalStepCountsScale) {
    Accuracy a;
    a.stepsFactor = 8.0;
    EXPECT_EQ(proceduray::mandelbulbStepCount(4, a), 32);
    EXPECT_EQ(proceduray::mandelbulbStepCount(129, a), 1032);
    EXPECT_EQ(proceduray::mandelbulbStepCount(0, a), 0);  // the march does not run either way
    EXPECT_EQ(proceduray::juliaParams<float>(a).marchSteps, 8192);
    a.stepsFactor = 1e-6;
    EXPECT_EQ(proceduray::mandelbulbStepCount(129, a), 1);  // at least 1
    EXPECT_EQ(proceduray::juliaParams<double>(a).marchSteps, 1);
}

// H15: a Julia march that runs out of steps is a hit where it stopped; with a single step that is one step of
// min(d, 0.2) past the bounding sphere, well before the converged surface.
TEST(AccuracyKnobsSteps, JuliaMarchOfOneStepReportsWhereItStopped) {
    const dvec3 local(0, 1.25, -2.875);  // q-space (0, -0.5, -1.15), fractals_test.cpp's ray
    const dvec3 rd(0, 0, 1);
    const auto full = math::julia::JuliaDistance(local, rd);
    Accuracy one;
    one.stepsFactor = 1.0 / 1024.0;
    const auto params = proceduray::juliaParams<double>(one);
    ASSERT_EQ(params.marchSteps, 1);
    const auto oneStep = math::julia::JuliaDistance(local, rd, params);
    ASSERT_TRUE(full.hit);
    ASSERT_TRUE(oneStep.hit);
    const double entry = 1.15 - std::sqrt(1.44 - 0.25);  // the q-space sphere of radius 1.2
    EXPECT_GT(oneStep.resT.x, entry);
    EXPECT_LE(oneStep.resT.x, entry + 0.2 + 1e-12);
    EXPECT_LT(oneStep.resT.x, full.resT.x - 0.05);
}

// Through the library: a Pac-man or round-cube march cut to one step misses. The Mandelbulb's march of iMax = 4
// steps at T0 (H14) reports its unconverged shell at t = 0.02999; with stepsFactor 2 it takes 8 steps and reports
// t = 0.1483 (the math's march of 8 steps from the local ray (0.875, 0.125, -0.375), -z), with stepsFactor 8 it
// takes 32 and leaves the bounding sphere: no hit.
TEST(AccuracyKnobsSteps, IntersectionShadersMarchTheScaledStepCounts) {
    Accuracy tiny;
    tiny.stepsFactor = 0.001;
    {
        ProcedurayRig reference;
        addPacmanA(reference);
        const auto hit = reference.probe(kPacmanRay).probe;
        ASSERT_EQ(hit.closestHits, 1);
        EXPECT_NEAR(hit.t, 0.54173f, 1e-4f);
        ProcedurayRig cut(tiny);
        addPacmanA(cut);
        EXPECT_EQ(cut.probe(kPacmanRay).probe.closestHits, 0);
    }
    {
        D3D12Rig reference;
        addRoundCube(reference);
        ASSERT_EQ(reference.probe(kRoundCubeRay).probe.closestHits, 1);
        D3D12Rig cut(tiny);
        addRoundCube(cut);
        EXPECT_EQ(cut.probe(kRoundCubeRay).probe.closestHits, 0);
    }
    const auto mandelbulbT = [](double stepsFactor) {
        Accuracy a;
        a.stepsFactor = stepsFactor;
        ProcedurayRig rig(a);
        addMandelbulb(rig);
        const auto probe = rig.probe(kMandelbulbRay).probe;
        return probe.closestHits == 1 ? probe.t : -1.0f;
    };
    const auto mathT = [](int iMax) {
        const auto hit = math::mandelbulb::MandelbulbDistance(vec3(0.875f, 0.125f, -0.375f), vec3(0, 0, -1), iMax);
        return hit.hit ? hit.thit : -1.0f;
    };
    EXPECT_NEAR(mandelbulbT(1.0), 0.02999f, 1e-4f);
    EXPECT_NEAR(mandelbulbT(2.0), 0.1483f, 1e-4f);
    EXPECT_NEAR(mandelbulbT(2.0), mathT(8), 1e-5f);
    EXPECT_EQ(mathT(32), -1.0f);
    EXPECT_EQ(mandelbulbT(8.0), -1.0f);
}

// =======================================================================================================
// thresholdFactor
// =======================================================================================================

// A larger threshold stops every march earlier: the SDF (H1's ray on the Pac-man), the Mandelbulb (a converged
// march of 129 steps) and Julia (the ray of fractals_test.cpp).
TEST(AccuracyKnobsThreshold, LargerThresholdsStopTheMarchesEarlier) {
    Accuracy loose;
    loose.thresholdFactor = 1000.0;

    const auto sdf = [](const vec3& p) { return math::pacman::pacMan(p, 0.0f); };
    const Ray<float> h1{vec3(0, -0.2f, 1), vec3(0, 0, -1)};
    const auto extent = math::fixtures::radianceExtent<float>();
    const auto strictParams = proceduray::sphereTraceParams(Accuracy{}, 1.0f);
    const auto looseParams = proceduray::sphereTraceParams(loose, 1.0f);
    EXPECT_EQ(bitsOf(looseParams.threshold), bitsOf(0.0001f * 1000.0f));
    const auto strict = math::RaySignedDistancePrimitiveTest(h1, extent, sdf, strictParams);
    const auto early = math::RaySignedDistancePrimitiveTest(h1, extent, sdf, looseParams);
    ASSERT_TRUE(strict.hit);
    ASSERT_TRUE(early.hit);
    EXPECT_LT(early.thit, strict.thit - 1e-3f);
    EXPECT_LE(sdf(early.position), 0.1f * early.thit);

    namespace mb = math::mandelbulb;
    const dvec3 ro(0.05, 0.1, -1.4), rd(0, 0, 1);
    const auto mbStrict = mb::MandelbulbDistance(ro, rd, 129, proceduray::mandelbulbParams<double>(Accuracy{}));
    const auto mbParams = proceduray::mandelbulbParams<double>(loose);
    EXPECT_EQ(mbParams.threshold, 0.0001 * 1000.0);
    const auto mbEarly = mb::MandelbulbDistance(ro, rd, 129, mbParams);
    ASSERT_TRUE(mbStrict.hit);
    ASSERT_TRUE(mbEarly.hit);
    EXPECT_LT(mbEarly.thit, mbStrict.thit - 1e-4);

    namespace jl = math::julia;
    const dvec3 q(0, -0.5, -1.15);
    Accuracy looser;
    looser.thresholdFactor = 100.0;
    const auto jParams = proceduray::juliaParams<double>(looser);
    EXPECT_EQ(jParams.precis, double(0.00025f) * 100.0);
    const glm::dvec2 jStrict = jl::raycast(q, rd);
    const glm::dvec2 jEarly = jl::raycast(q, rd, jl::kc<double>(), 0.0, jParams.iterations, jParams.marchSteps,
                                          jParams.precis);
    ASSERT_GE(jStrict.x, 0.0);
    ASSERT_GE(jEarly.x, 0.0);
    EXPECT_LT(jEarly.x, jStrict.x);
    EXPECT_LT(jl::jdist(q + jEarly.x * rd, jl::kc<double>(), 200).x, 0.025);
}

// Julia's tmin stays kPrecis: with a huge threshold a march from inside the bounding sphere and between the cut
// planes stops at its first sample, t = kPrecis exactly (a scaled tmin would start beyond tmax and miss).
TEST(AccuracyKnobsThreshold, JuliaStartsAtTheUnscaledPrecis) {
    namespace jl = math::julia;
    const dvec3 q(0.0, -0.5, 0.8), rd(0, 0, 1);  // |q| < 1.2, -1.1 < y < 0
    const glm::dvec2 reference = jl::raycast(q, rd);
    ASSERT_GT(reference.x, jl::kPrecis<double>);  // outside the set: the HLSL march moves on
    Accuracy huge;
    huge.thresholdFactor = 1e9;
    const auto params = proceduray::juliaParams<double>(huge);
    const glm::dvec2 first =
        jl::raycast(q, rd, jl::kc<double>(), 0.0, params.iterations, params.marchSteps, params.precis);
    EXPECT_EQ(first.x, jl::kPrecis<double>);
}

// Through the library: the round cube's sphere tracing reports an earlier t.
TEST(AccuracyKnobsThreshold, SignedDistanceShaderReportsAnEarlierHit) {
    D3D12Rig reference;
    addRoundCube(reference);
    const auto strict = reference.probe(kRoundCubeRay).probe;
    Accuracy loose;
    loose.thresholdFactor = 1000.0;
    D3D12Rig rig(loose);
    addRoundCube(rig);
    const auto early = rig.probe(kRoundCubeRay).probe;
    ASSERT_EQ(strict.closestHits, 1);
    ASSERT_EQ(early.closestHits, 1);
    EXPECT_LT(early.t, strict.t - 1e-3f);
}

// =======================================================================================================
// mandelbulbIterations, juliaIterations
// =======================================================================================================

TEST(AccuracyKnobsIterations, MandelbulbIterationsChangeTheEstimator) {
    namespace mb = math::mandelbulb;
    Accuracy a;
    a.mandelbulbIterations = 8;
    EXPECT_EQ(proceduray::mandelbulbParams<double>(a).iterations, 8);
    a.mandelbulbIterations = 1;
    const auto one = proceduray::mandelbulbParams<double>(a);
    EXPECT_EQ(one.iterations, 1);

    // Near the surface the DE and the orbit trap depend on the iterations; one iteration is the closed form
    // 0.25·log(m1)·sqrt(m1)/dz1 with dz1 = 8·|p|^7 + 1.
    const dvec3 p(0.6, 0.3, -0.5);
    glm::dvec4 trap4, trap1;
    const double d4 = mb::mdist(p, trap4);
    const double d1 = mb::mdist(p, trap1, one.iterations);
    EXPECT_NE(d4, d1);
    EXPECT_NE(trap4, trap1);
    const double r = glm::length(p);
    const double b = 8.0 * std::acos(p.y / r), phi = 8.0 * std::atan2(p.x, p.z);
    const dvec3 w = p + std::pow(r, 8.0) * dvec3(std::sin(b) * std::sin(phi), std::cos(b), std::sin(b) * std::cos(phi));
    const double m1 = glm::dot(w, w);
    EXPECT_NEAR(d1, 0.25 * std::log(m1) * std::sqrt(m1) / (8.0 * std::pow(r, 7.0) + 1.0), 1e-9);

    const dvec3 ro(0.05, 0.1, -1.4), rd(0, 0, 1);
    const auto hit4 = mb::MandelbulbDistance(ro, rd, 129);
    const auto hit1 = mb::MandelbulbDistance(ro, rd, 129, one);
    ASSERT_TRUE(hit4.hit);
    ASSERT_TRUE(hit1.hit);
    EXPECT_GT(std::abs(hit1.thit - hit4.thit), 1e-3);
    EXPECT_NEAR(glm::length(hit1.normal), 1.0, 1e-9);
}

TEST(AccuracyKnobsIterations, JuliaIterationsChangeTheEstimatorAndTheCount) {
    namespace jl = math::julia;
    Accuracy a;
    a.juliaIterations = 5;
    const auto params = proceduray::juliaParams<double>(a);
    EXPECT_EQ(params.iterations, 5);

    // Inside the set the iteration count survives every iteration: n = iMax.
    const dvec3 inside(0.6, -0.2, 0.3);
    const glm::dvec2 inside200 = jl::jdist(inside, jl::kc<double>(), 200);
    const glm::dvec2 inside5 = jl::jdist(inside, jl::kc<double>(), params.iterations);
    EXPECT_EQ(inside200.y, 200.0);
    EXPECT_EQ(inside5.y, 5.0);
    EXPECT_NE(inside200.x, inside5.x);

    const dvec3 local(0, 1.25, -2.875), rd(0, 0, 1);
    const auto hit200 = jl::JuliaDistance(local, rd);
    const auto hit5 = jl::JuliaDistance(local, rd, params);
    ASSERT_TRUE(hit200.hit);
    ASSERT_TRUE(hit5.hit);
    EXPECT_LE(hit5.resT.y, 5.0);
    EXPECT_NE(hit5.resT.x, hit200.resT.x);
    EXPECT_NEAR(glm::length(hit5.normal), 1.0, 1e-9);
}

// Through the library: the Mandelbulb's report (t and orbit trap) and the Julia's iteration count follow the knobs.
TEST(AccuracyKnobsIterations, IntersectionShadersUseTheIterations) {
    ProcedurayRig reference;
    addMandelbulb(reference);
    addJulia(reference);
    const auto mandelbulb = reference.probe(kMandelbulbRay).probe;
    const auto julia = reference.probe(kJuliaRay).probe;
    ASSERT_EQ(mandelbulb.closestHits, 1);
    ASSERT_EQ(julia.closestHits, 1);
    EXPECT_GT(julia.attr.color.y, 5.0f);

    Accuracy a;
    a.mandelbulbIterations = 1;
    a.juliaIterations = 5;
    ProcedurayRig rig(a);
    addMandelbulb(rig);
    addJulia(rig);
    const auto mandelbulb1 = rig.probe(kMandelbulbRay).probe;
    const auto julia5 = rig.probe(kJuliaRay).probe;
    ASSERT_EQ(mandelbulb1.closestHits, 1);
    EXPECT_NE(mandelbulb1.attr.color, mandelbulb.attr.color);
    ASSERT_EQ(julia5.closestHits, 1);
    EXPECT_LE(julia5.attr.color.y, 5.0f);
}

}  // namespace
}  // namespace refray::procedural
