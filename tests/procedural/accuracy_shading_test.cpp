// Tests of procedural/accuracy.h's shading knobs as the two shader libraries apply them (issue 7):
// normalEpsilonFactor moves normals slightly, metaballSteps changes the metaballs' samples, and maxRecursionDepth
// the number of TraceRay levels. The rig is accuracy_rig.h; the defaults are in accuracy_test.cpp.
#include <gtest/gtest.h>

#include "tests/procedural/accuracy_rig.h"

namespace refray::procedural {
namespace {

using namespace accuracy_rig;

// =======================================================================================================
// normalEpsilonFactor
// =======================================================================================================

// A normal that moved by more than rounding but less than `bound` radians, and is still unit length.
template <typename T>
void expectSlightlyMovedUnitNormal(const tvec3<T>& reference, const tvec3<T>& moved, double bound,
                                   const char* what) {
    const double angle = angleBetween(vec3(reference), vec3(moved));
    EXPECT_GT(angle, 1e-6) << what;
    EXPECT_LT(angle, bound) << what;
    EXPECT_NEAR(glm::length(glm::dvec3(moved)), 1.0, 1e-5) << what;
}

// The offsets scale. The smooth fields' normals (Pac-man's head, the metaballs) move by little for a hundred times
// the offset; the fractals' (at points of their surfaces) already move by a few hundredths of a radian for twice it.
TEST(AccuracyKnobsNormalEpsilon, OffsetsScaleAndNormalsMoveSlightly) {
    Accuracy wide;
    wide.normalEpsilonFactor = 100.0;
    const auto sdfParams = proceduray::sphereTraceParams(wide, 1.0);
    EXPECT_EQ(sdfParams.normalOffset, math::tetrahedralOffset<double>() * 100.0);
    EXPECT_EQ(d3d12::sphereTraceParams(wide, 1.0).normalOffset, sdfParams.normalOffset);
    EXPECT_EQ(proceduray::mandelbulbParams<double>(wide).normalOffset, math::tetrahedralOffset<double>() * 100.0);
    EXPECT_EQ(proceduray::juliaParams<double>(wide).normalOffset, math::julia::calcNormalOffset<double>() * 100.0);
    EXPECT_EQ(d3d12::metaballsParams<double>(wide).normalOffset, math::metaballsNormalOffset<double>() * 100.0);

    // The Pac-man's head (H1): the SDF normal at the same hit point.
    const auto sdf = [](const dvec3& p) { return math::pacman::pacMan(p, 0.0); };
    const Ray<double> h1{dvec3(0, -0.2, 1), dvec3(0, 0, -1)};
    const auto extent = math::fixtures::radianceExtent<double>();
    const auto narrow =
        math::RaySignedDistancePrimitiveTest(h1, extent, sdf, proceduray::sphereTraceParams(Accuracy{}, 1.0));
    const auto broad = math::RaySignedDistancePrimitiveTest(h1, extent, sdf, sdfParams);
    ASSERT_TRUE(narrow.hit);
    ASSERT_TRUE(broad.hit);
    EXPECT_EQ(broad.thit, narrow.thit);
    expectSlightlyMovedUnitNormal(narrow.normal, broad.normal, 0.05, "Pac-man");

    // The fractal normals where the converged marches of the tests above end, and the metaballs' inside the blend.
    Accuracy twice;
    twice.normalEpsilonFactor = 2.0;
    const auto mb = math::mandelbulb::MandelbulbDistance(dvec3(0.05, 0.1, -1.4), dvec3(0, 0, 1), 129);
    ASSERT_TRUE(mb.hit);
    const auto mbParams = proceduray::mandelbulbParams<double>(twice);
    expectSlightlyMovedUnitNormal(mb.normal, math::mandelbulb::calcNormal(mb.pos, mbParams.normalOffset), 0.1,
                                  "Mandelbulb");
    EXPECT_EQ(bitsOf(math::mandelbulb::MandelbulbDistance(dvec3(0.05, 0.1, -1.4), dvec3(0, 0, 1), 129, mbParams).thit),
              bitsOf(mb.thit));
    const dvec3 q(0, -0.5, -1.15), rd(0, 0, 1);
    const dvec3 pj = q + math::julia::raycast(q, rd).x * rd;
    const auto jParams = proceduray::juliaParams<double>(twice);
    expectSlightlyMovedUnitNormal(
        math::julia::calcNormal(pj), math::julia::calcNormal(pj, math::julia::kc<double>(), 200, jParams.normalOffset),
        0.1, "Julia");
    const auto blobs = math::InitializeAnimatedMetaballs(0.0, 12.0);
    const dvec3 pb(-0.2, -0.3, 0.1);
    const double e = d3d12::metaballsParams<double>(wide).normalOffset;
    expectSlightlyMovedUnitNormal(math::CalculateMetaballsNormal(pb, blobs),
                                  math::CalculateMetaballsNormal(pb, blobs, e), 0.05, "metaballs");
}

// Through the library: the Pac-man's and the metaballs' reported normals (world space) move slightly and stay unit
// length; the hits stay where they were.
TEST(AccuracyKnobsNormalEpsilon, IntersectionShadersReportTheMovedNormals) {
    Accuracy wide;
    wide.normalEpsilonFactor = 100.0;
    ProcedurayRig pacman, pacmanWide(wide);
    addPacmanA(pacman);
    addPacmanA(pacmanWide);
    const auto p = pacman.probe(kPacmanRay).probe;
    const auto pw = pacmanWide.probe(kPacmanRay).probe;
    ASSERT_EQ(p.closestHits, 1);
    ASSERT_EQ(pw.closestHits, 1);
    EXPECT_EQ(pw.t, p.t);
    expectSlightlyMovedUnitNormal(p.attr.normal, pw.attr.normal, 0.05, "Pac-man");

    D3D12Rig metaballs, metaballsWide(wide);
    addMetaballs(metaballs);
    addMetaballs(metaballsWide);
    const auto m = metaballs.probe(kMetaballsRay).probe;
    const auto mw = metaballsWide.probe(kMetaballsRay).probe;
    ASSERT_EQ(m.closestHits, 1);
    ASSERT_EQ(mw.closestHits, 1);
    EXPECT_EQ(mw.t, m.t);
    expectSlightlyMovedUnitNormal(m.attr.normal, mw.attr.normal, 0.05, "metaballs");
}

// =======================================================================================================
// metaballSteps
// =======================================================================================================

// Four times the samples: the first sample over the threshold comes about four times later in the count and no
// later along the ray (the coarse samples are among the fine ones), within one coarse step.
TEST(AccuracyKnobsMetaballSteps, MoreSamplesFindTheSurfaceOnAFinerGrid) {
    Accuracy fine;
    fine.metaballSteps = 512;
    const auto params = d3d12::metaballsParams<double>(fine);
    EXPECT_EQ(params.maxSteps, 512u);
    const Ray<double> ray{dvec3(-2, -0.3, -0.4), dvec3(1, 0, 0)};
    const RayExtent<double> extent{0, 100, true, false};
    const auto coarse = math::RayMetaballsIntersectionTest(ray, extent, 0.0);
    const auto finer = math::RayMetaballsIntersectionTest(ray, extent, 0.0, 12.0, params);
    ASSERT_TRUE(coarse.hit);
    ASSERT_TRUE(finer.hit);
    EXPECT_LT(finer.thit, coarse.thit);
    double tmin = 0, tmax = 0;
    math::FindIntersectingMetaballs(ray, extent, tmin, tmax, math::InitializeAnimatedMetaballs(0.0, 12.0));
    EXPECT_GT(finer.thit, coarse.thit - (tmax - tmin) / 128.0 - 1e-12);
    EXPECT_GE(int(finer.step), 4 * int(coarse.step) - 6);
    EXPECT_LE(int(finer.step), 4 * int(coarse.step));

    Accuracy few;
    few.metaballSteps = 1;  // one sample, at tmin, outside every ball: no hit
    EXPECT_FALSE(math::RayMetaballsIntersectionTest(ray, extent, 0.0, 12.0, d3d12::metaballsParams<double>(few)).hit);
}

// Through the library: the volumetric shader reports the hit of the finer march.
TEST(AccuracyKnobsMetaballSteps, VolumetricShaderMarchesTheSamples) {
    D3D12Rig reference;
    addMetaballs(reference);
    const auto coarse = reference.probe(kMetaballsRay).probe;
    Accuracy fine;
    fine.metaballSteps = 512;
    D3D12Rig rig(fine);
    addMetaballs(rig);
    const auto finer = rig.probe(kMetaballsRay).probe;
    ASSERT_EQ(coarse.closestHits, 1);
    ASSERT_EQ(finer.closestHits, 1);
    EXPECT_LT(finer.t, coarse.t);
}

// =======================================================================================================
// maxRecursionDepth
// =======================================================================================================

// Two mirrors facing each other (reflective slabs or ground planes, the lower one facing up, the upper one down)
// and a camera between them looking down at a slant: the reflections bounce far more often than any depth tested,
// so the recursion stops only at MAX_RAY_RECURSION_DEPTH. Each level's hit traces a shadow and a reflection ray.
const vec3 kMirrorEye(-50, 10, 0);
const vec3 kMirrorTarget(-49, 8, 0);

size_t procedurayMirrorLevels(const Accuracy& accuracy) {
    ProcedurayRig rig(accuracy);
    rig.addTriangles(Matrix3x4::scale(vec3(120, 15, 120)), kSlabMaterial);  // top face y = 3, facing up
    rig.addTriangles(Matrix3x4::translation(vec3(0, 20, 0)) * Matrix3x4::scale(vec3(120, 15, 120)),
                     kSlabMaterial);  // bottom face y = 17, facing down
    return rig.render(kMirrorEye, kMirrorTarget).levels();
}

size_t d3d12MirrorLevels(const Accuracy& accuracy) {
    const PrimitiveConstantBuffer mirror{vec4(0.9f, 0.9f, 0.9f, 1.0f), 0.5f, 0.5f, 0.4f, 50.0f, 1.0f, vec3(0.0f)};
    D3D12Rig rig(accuracy);
    Matrix3x4 floor;  // the unit quad grown to [-100, 100]^2 at y = 0
    floor.m[0] = {200.0f, 0.0f, 0.0f, -100.0f};
    floor.m[1] = {0.0f, 1.0f, 0.0f, 0.0f};
    floor.m[2] = {0.0f, 0.0f, 200.0f, -100.0f};
    Matrix3x4 ceiling;  // the same, turned over about x and raised to y = 14
    ceiling.m[0] = {200.0f, 0.0f, 0.0f, -100.0f};
    ceiling.m[1] = {0.0f, -1.0f, 0.0f, 14.0f};
    ceiling.m[2] = {0.0f, 0.0f, -200.0f, 100.0f};
    rig.addTriangles(floor, mirror);
    rig.addTriangles(ceiling, mirror);
    return rig.render(kMirrorEye, kMirrorTarget).levels();
}

TEST(AccuracyKnobsRecursion, MaxRecursionDepthSetsTheTraceRayLevels) {
    for (const uint32_t depth : {1u, 2u, 5u, 8u}) {
        Accuracy a;
        a.maxRecursionDepth = depth;
        EXPECT_EQ(proceduray::maxRayRecursionDepth(a), depth);
        EXPECT_EQ(d3d12::maxRayRecursionDepth(a), depth);
        EXPECT_EQ(procedurayMirrorLevels(a), depth) << "Proceduray, depth " << depth;
        EXPECT_EQ(d3d12MirrorLevels(a), depth) << "D3D12, depth " << depth;
    }
    EXPECT_EQ(procedurayMirrorLevels(Accuracy{}), 3u);
    EXPECT_EQ(d3d12MirrorLevels(Accuracy{}), 3u);
}

// ClosestHit_Julia brightens its albedo at recursionDepth == MAX_RAY_RECURSION_DEPTH - 1: a primary hit (depth 1)
// gets it with a depth of 2, not with the HLSL's 3; the rays traced are the same (the reflection misses).
TEST(AccuracyKnobsRecursion, JuliaColourTermFollowsTheDepth) {
    const vec3 eye = kJuliaRay.Origin;
    const vec3 target = eye + kJuliaRay.Direction;
    ProcedurayRig reference;
    addJulia(reference, false);
    const auto plain = reference.render(eye, target);
    Accuracy two;
    two.maxRecursionDepth = 2;
    ProcedurayRig rig(two);
    addJulia(rig, false);
    const auto bright = rig.render(eye, target);
    EXPECT_EQ(bright.stats.raysPerDepth, plain.stats.raysPerDepth);
    EXPECT_EQ(plain.levels(), 2u);
    for (int c = 0; c < 3; ++c) EXPECT_GT(bright.pixel[c], plain.pixel[c] + 0.01f) << "component " << c;
}

}  // namespace
}  // namespace refray::procedural
