// Tests procedural/d3d12/d3d12_shaders.cpp end to end, its closest hits and miss shaders through MyRaygenShader
// in tiny Device scenes built from the fact sheet (§1.2-1.4): the ground plane's grid, shadow and fog, the red box
// in Phong, the whole scene; and the PORT tests of makeD3D12ShaderLibrary. The rig is d3d12_shaders_rig.h.
#include "procedural/d3d12/d3d12_shaders.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "tests/procedural/d3d12_shaders_rig.h"

namespace refray::procedural::d3d12 {
namespace {

using namespace shaders_rig;

// ---- The closest hits and miss shaders through MyRaygenShader -------------------------------------------

// The ground colour of §2.9/§2.11 in double for a ray straight down (D = -y) that hits P at distance t, with the
// background as the reflection (nothing above P) and N the normal the shader read from g_vertices.
dvec4 expectedGroundColor(dvec3 P, double t, bool inShadow, double checkers, dvec3 N = dvec3(0, 1, 0)) {
    const dvec3 D(0, -1, 0), light(0, 18, -20);
    const dvec4 albedo(0.9, 0.9, 0.9, 1.0), background(0.8, 0.9, 1.0, 1.0);
    const dvec3 L = glm::normalize(P - light);
    const double Kd = std::clamp(glm::dot(-L, N), 0.0, 1.0);
    const dvec4 diffuse = (inShadow ? 0.35 : 1.0) * 1.0 * Kd * dvec4(0.6, 0.6, 0.6, 1.0) * albedo;
    const dvec3 R = glm::normalize(L - 2.0 * glm::dot(N, L) * N);
    const dvec4 specular(inShadow ? 0.0 : 0.4 * std::pow(std::clamp(glm::dot(R, -D), 0.0, 1.0), 50.0));
    const double a = 1.0 - std::clamp(-N.y, 0.0, 1.0);
    const dvec4 ambient = albedo * (dvec4(0.25, 0.25, 0.25, 1.0) - 0.1 + 0.1 * a);  // lerp(A - 0.1, A, a)
    const double cosi = std::clamp(glm::dot(-D, N), 0.0, 1.0);
    const dvec4 fresnel(dvec3(0.9) + 0.1 * std::pow(1.0 - cosi, 5.0), 1.0);
    const dvec4 reflected = 0.25 * fresnel * background;
    const dvec4 color = checkers * (ambient + diffuse + specular + reflected);
    const double f = 1.0 - std::exp(-0.000002 * t * t * t);
    return color + f * (background - color);
}

// A 1×1 camera 10 above (3.01, 0, 7.5) looking down; its neighbour rays land 0.04 away, so the box filter covers
// [2.99, 3.03] in u: the whole 0.02-wide line at u = 3 is half of it, i.e. a grid factor of 0.5. The shadow ray and
// the reflection ray both miss.
TEST(D3D12Shaders, GroundPlaneGridShadingAndFog) {
    D3D12Rig rig(true, {});
    rig.setPointCamera(vec3(3.01f, 10.0f, 7.5f), vec3(0, -1, 0), vec3(0.002f, 0, 0), vec3(0, 0, 0.002f));
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 3u);  // primary, shadow, reflection
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 2u);
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::ClosestHit), 1u);

    EXPECT_NEAR(AnalyticalCheckersTexture(vec3(3.01f, 0.0f, 7.5f), vec3(0, 1, 0), vec3(rig.scene.cameraPosition),
                                          rig.scene.projectionToWorld, uvec2(0), uvec2(1)),
                0.5f, 1e-4f);
    const dvec4 expected = expectedGroundColor(dvec3(3.01, 0, 7.5), 10.0, false, 0.5);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
}

// MyClosestHitShader_Triangle takes its normal from the bound g_vertices[g_indices[3·PrimitiveIndex()]]: with
// downward normals there the same hit shades with the 0.15 ambient, no diffuse and a Fresnel factor of 1.
TEST(D3D12Shaders, GroundPlaneNormalComesFromTheBoundVertexBuffer) {
    D3D12Rig rig(true, {});
    for (Vertex& v : rig.boundVertices) v.normal = vec3(0, -1, 0);
    rig.setPointCamera(vec3(7.2f, 10.0f, -3.2f), vec3(0, -1, 0), vec3(1e-4f, 0, 0), vec3(0, 0, 1e-4f));
    rig.dispatch("MyRaygenShader", false);
    const dvec4 expected = expectedGroundColor(dvec3(7.2, 0, -3.2), 10.0, false, 1.0, dvec3(0, -1, 0));
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
}

// The red box shadows the ground at (7.2, 0, -3.2): the shadow ray towards the light enters the box's +z face.
// The grid factor is 1 there (frac 0.2 and 0.8, tiny footprint).
TEST(D3D12Shaders, GroundPlaneInTheRedBoxShadow) {
    D3D12Rig rig(true, {0});
    rig.setPointCamera(vec3(7.2f, 10.0f, -3.2f), vec3(0, -1, 0), vec3(1e-4f, 0, 0), vec3(0, 0, 1e-4f));
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 3u);
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 1u);  // only the reflection misses

    const dvec4 expected = expectedGroundColor(dvec3(7.2, 0, -3.2), 10.0, true, 1.0);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-4) << "component " << c;
    // Lit, the same point would be brighter by 0.65 of the diffuse term.
    EXPECT_LT(got.x, float(expectedGroundColor(dvec3(7.2, 0, -3.2), 10.0, false, 1.0).x) - 0.05f);
}

// MyClosestHitShader_AABB on the red box's -x face, lit (the shadow ray starts on the face and leaves it), no
// reflection (reflectanceCoef 0): Phong plus fog at t = 5.
TEST(D3D12Shaders, RedBoxShadedWithPhongAndFog) {
    D3D12Rig rig(false, {0});
    rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 2u);  // primary and shadow
    EXPECT_EQ(result.stats.invocationsOf(ShaderStage::Miss), 1u);

    const dvec3 P(5, 1.5, -6), N(-1, 0, 0), D(1, 0, 0);
    const dvec3 L = glm::normalize(P - dvec3(0, 18, -20));
    const double Kd = std::clamp(glm::dot(-L, N), 0.0, 1.0);
    const dvec3 R = glm::normalize(L - 2.0 * glm::dot(N, L) * N);
    const double Ks = std::pow(std::clamp(glm::dot(R, -D), 0.0, 1.0), 50.0);
    const dvec4 albedo(1.0, 0.5, 0.5, 1.0), background(0.8, 0.9, 1.0, 1.0);
    const dvec4 color = albedo * dvec4(0.25, 0.25, 0.25, 1.0) + 0.9 * Kd * dvec4(0.6, 0.6, 0.6, 1.0) * albedo + dvec4(0.7 * Ks);
    const double f = 1.0 - std::exp(-0.000002 * 125.0);
    const dvec4 expected = color + f * (background - color);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5) << "component " << c;
}

// MyMissShader writes BackgroundColor; a small render of the whole scene stays finite, with sky in the top corner.
TEST(D3D12Shaders, WholeSceneRenderMissColourAndFiniteness) {
    D3D12Rig rig(true, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
    const Camera camera = sampleCamera(32, 18);
    rig.scene.projectionToWorld = camera.projectionToWorld;
    rig.scene.cameraPosition = camera.position;
    rig.dispatch("MyRaygenShader", false, 32, 18);
    EXPECT_EQ(rig.output.at(0, 0), BackgroundColor);
    int ground = 0;
    for (uint32_t y = 0; y < 18; ++y)
        for (uint32_t x = 0; x < 32; ++x) {
            const vec4 c = rig.output.at(x, y);
            for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(c[k])) << x << "," << y;
            if (c != BackgroundColor) ++ground;
        }
    EXPECT_GT(ground, 32 * 18 / 2);  // the horizon is near the top (rows 88-89 of 720)
}

// ---- PORT tests ----------------------------------------------------------------------------------------

// PORT (makeD3D12ShaderLibrary's traceRay): the shaders pass the library's TraceRay arguments, not the HLSL's
// constants. The red box is geometry 1 of the AABB instance (C = 2), seen as in RedBoxShadedWithPhongAndFog: the
// HLSL's radiance ray reads record R + M·G + C = 0 + 2·1 + 2 = 4. With R = 2, M = 0 it reads 2 + 0·1 + 2 = 4 too and
// the shadow ray with R = 3, M = 0 reads record 5 like the HLSL's, so the pixel is unchanged while the trace shows
// the arguments as passed, the mask's and miss index's unused high bits included (INST-4, IDX-7). A multiplier of 1
// with two ray types sends the radiance ray to record 0 + 1·1 + 2 = 3: geometry 0's shadow hit group.
TEST(D3D12Shaders, PORT_TraceRayArgumentsComeFromTheLibrary) {
    D3D12Rig reference(false, {4, 0});
    reference.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    TraceRayRecorder defaults;
    reference.observer = &defaults;
    reference.dispatch("MyRaygenShader", false);
    ASSERT_FALSE(defaults.lookups.empty());
    EXPECT_EQ(defaults.lookups[0].terms.index, 4u);
    EXPECT_EQ(defaults.lookups[0].terms.multiplier, 2u);

    D3D12Rig rig(false, {4, 0});
    rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    rig.traceRay[RayType::Radiance] = {2, 0, 0x10000, 0xFFFFFF03};
    rig.traceRay[RayType::Shadow] = {3, 0, 0x10001, 0x105};
    TraceRayRecorder recorder;
    rig.observer = &recorder;
    const DispatchResult result = rig.dispatch("MyRaygenShader", false);
    EXPECT_EQ(result.stats.raysTraced, 2u);  // primary and shadow (the red box does not reflect)
    ASSERT_EQ(recorder.calls.size(), 2u);
    EXPECT_EQ(recorder.calls[0].payloadSize, sizeof(RayPayload));
    EXPECT_EQ(recorder.calls[0].arguments, rig.traceRay[RayType::Radiance]);
    EXPECT_EQ(recorder.calls[1].payloadSize, sizeof(ShadowRayPayload));
    EXPECT_EQ(recorder.calls[1].arguments, rig.traceRay[RayType::Shadow]);
    ASSERT_FALSE(recorder.lookups.empty());
    const HitGroupIndexTerms& primary = recorder.lookups[0].terms;
    EXPECT_EQ(primary.rayContribution, 2u);
    EXPECT_EQ(primary.multiplier, 0u);
    EXPECT_EQ(primary.geometryIndex, 1u);
    EXPECT_EQ(primary.instanceContribution, 2u);
    EXPECT_EQ(primary.index, 4u);
    EXPECT_EQ(recorder.lookups[0].hitGroup, "MyHitGroup_AABB_AnalyticPrimitive");
    EXPECT_EQ(rig.output.at(0, 0), reference.output.at(0, 0));

    D3D12Rig lesson(false, {4, 0});
    lesson.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    lesson.traceRay[RayType::Radiance].multiplier = 1;
    TraceRayRecorder wrong;
    lesson.observer = &wrong;
    lesson.dispatch("MyRaygenShader", false);
    ASSERT_FALSE(wrong.lookups.empty());
    EXPECT_EQ(wrong.lookups[0].terms.index, 3u);
    EXPECT_EQ(wrong.lookups[0].hitGroup, "MyHitGroup_AABB_SignedDistancePrimitive_ShadowRay");
}

// PORT (MyRaygenShader): the render target keeps the float colour; the R8G8B8A8_UNORM conversion happens only when
// the image is written out (H20). The red box's shaded components are not multiples of 1/255.
TEST(D3D12Shaders, PORT_RaygenStoresUnquantisedFloats) {
    D3D12Rig rig(false, {0});
    rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
    rig.dispatch("MyRaygenShader", false);
    const vec4 got = rig.output.at(0, 0);
    for (int c = 0; c < 3; ++c) {
        const float quantised = std::round(std::clamp(got[c], 0.0f, 1.0f) * 255.0f) / 255.0f;
        EXPECT_GT(std::fabs(got[c] - quantised), 1e-5f) << "component " << c;
    }
}

// PORT (ShadowRayPayload): the payload mirrors the HLSL's 32-bit bool, not the C++ header's 1-byte bool (I11):
// MyMissShader_ShadowRay clears the whole word, and a shadow hit (closest hit skipped) leaves it untouched.
TEST(D3D12Shaders, PORT_ShadowRayPayloadIsAWholeWord) {
    static_assert(sizeof(ShadowRayPayload) == 4);
    D3D12Rig rig(false, {0});
    rig.probeRay = {vec3(0.0f, 1.5f, -6.0f), 0.0f, vec3(0, 1, 0), 10000.0f};  // misses the red box
    rig.dispatch("RG_ShadowProbe", false);
    EXPECT_EQ(rig.shadowPayloadWord, 0u);
    rig.probeRay = {vec3(0.0f, 1.5f, -6.0f), 0.0f, vec3(1, 0, 0), 10000.0f};  // enters its -x face
    rig.dispatch("RG_ShadowProbe", false);
    EXPECT_EQ(rig.shadowPayloadWord, 0xffffffffu);
}

// PORT (the helpers' intrinsics are parameters): a 3×2 dispatch over the bare ground; every pixel's colour is what
// the exported helpers give when handed that pixel's DispatchRaysIndex(), DispatchRaysDimensions() and
// WorldRayDirection(): grid filter from the neighbours' primary rays (I7), Phong, Fresnel reflection of the
// background (the reflection and the shadow ray both miss), then the fog.
TEST(D3D12Shaders, PORT_HelpersWithIntrinsicsAsParametersReproduceTheShader) {
    D3D12Rig rig(true, {});
    rig.setPointCamera(vec3(3.01f, 10.0f, 7.5f), vec3(0, -1, 0), vec3(0.5f, 0, 0), vec3(0, 0, 0.5f));
    const uvec2 dims(3, 2);
    rig.dispatch("MyRaygenShader", false, dims.x, dims.y);
    const vec3 N(0, 1, 0);
    for (uint32_t y = 0; y < dims.y; ++y)
        for (uint32_t x = 0; x < dims.x; ++x) {
            vec3 origin, D;
            GenerateCameraRay(uvec2(x, y), dims, vec3(rig.scene.cameraPosition), rig.scene.projectionToWorld, origin, D);
            const float t = -origin.y / D.y;
            const vec3 P = origin + t * D;
            const float checkers = AnalyticalCheckersTexture(P, N, vec3(rig.scene.cameraPosition),
                                                             rig.scene.projectionToWorld, uvec2(x, y), dims);
            const vec4 phong = CalculatePhongLighting(rig.scene, kPlaneMaterial.albedo, N, false, kPlaneMaterial.diffuseCoef,
                                                      kPlaneMaterial.specularCoef, kPlaneMaterial.specularPower, P, D);
            const vec4 reflected = kPlaneMaterial.reflectanceCoef *
                                   vec4(FresnelReflectanceSchlick(D, N, vec3(kPlaneMaterial.albedo)), 1.0f) * BackgroundColor;
            const vec4 expected = ApplyVisibilityFalloff(checkers * (phong + reflected), t);
            const vec4 got = rig.output.at(x, y);
            for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5f) << x << "," << y << " component " << c;
        }
    // The pixels really differ in their grid footprint (the index and dimensions matter).
    EXPECT_NE(rig.output.at(0, 0), rig.output.at(2, 1));
}

// PORT (makeD3D12ShaderLibrary's precision): the double library has the same exports and interface types, and
// renders the same shading; d3d12_contract_test.cpp runs every intersection shader in both and bounds the
// differences. The double run is also free of the float run's rounding: the red box colour agrees to 1e-6 (float
// rounding of a colour ~0.5 through ~30 operations is ~1e-7 relative).
TEST(D3D12Shaders, PORT_DoublePrecisionLibraryHasTheSameInterfaceAndShading) {
    const auto f = makeD3D12ShaderLibrary(Precision::Float);
    const auto d = makeD3D12ShaderLibrary(Precision::Double);
    ASSERT_EQ(f->exports().size(), d->exports().size());
    for (const auto& [name, e] : f->exports()) {
        const ShaderExport* other = d->find(name);
        ASSERT_NE(other, nullptr) << name;
        EXPECT_EQ(other->stage, e.stage) << name;
        EXPECT_EQ(other->payload, e.payload) << name;
        EXPECT_EQ(other->attributes, e.attributes) << name;
    }
    vec4 colour[2];
    for (int k = 0; k < 2; ++k) {
        D3D12Rig rig(false, {0});
        rig.precision = k == 0 ? Precision::Float : Precision::Double;
        rig.setPointCamera(vec3(0.0f, 1.5f, -6.0f), vec3(1, 0, 0), vec3(0.0f), vec3(0.0f));
        rig.dispatch("MyRaygenShader", false);
        colour[k] = rig.output.at(0, 0);
    }
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(colour[0][c], colour[1][c], 1e-6f) << "component " << c;
    // The ground's grid and fog in double, against the double-precision expectation of GroundPlaneGridShadingAndFog.
    D3D12Rig ground(true, {});
    ground.precision = Precision::Double;
    ground.setPointCamera(vec3(3.01f, 10.0f, 7.5f), vec3(0, -1, 0), vec3(0.002f, 0, 0), vec3(0, 0, 0.002f));
    ground.dispatch("MyRaygenShader", false);
    const dvec4 expected = expectedGroundColor(dvec3(3.01, 0, 7.5), 10.0, false, 0.5);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(ground.output.at(0, 0)[c], expected[c], 1e-4) << "component " << c;
}

// The double helpers instantiate and agree with the float ones on the fact-sheet values.
TEST(D3D12Shaders, HelpersInDoubleMatchTheFloatOnes) {
    EXPECT_NEAR(CheckersTextureBoxFilter(glm::dvec2(3.005, 7.5), glm::dvec2(0.02, 0.0), glm::dvec2(0.0, 0.02), 50), 0.25,
                1e-6);
    EXPECT_NEAR(ApplyVisibilityFalloff(dvec4(0.0), 70.24).z, 0.5, 1e-3);
    EXPECT_NEAR(FresnelReflectanceSchlick(dvec3(0, -1, 0), dvec3(0, 1, 0), dvec3(0.9)).x, 0.9, 1e-12);
}

}  // namespace
}  // namespace refray::procedural::d3d12
