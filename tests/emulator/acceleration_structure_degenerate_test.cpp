// Conformance tests for degenerate and inactive primitives and instances (emulator/acceleration_structure.*,
// dxr-semantics.md section 3: DEGEN). The rig is acceleration_structure_rig.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "acceleration_structure_rig.h"

namespace refray::test {
namespace {

using namespace acceleration_structure_rig;

// ---------------------------------------------------------------------------------------
// DEGEN

TEST(AccelerationStructure, DEGEN_1_NaNXMakesTriangleInactiveAndLaterIndicesKeepSlots) {
    Rig r;
    std::vector<vec3> v = {{-1, -1, 0}, {0, 1, 0}, {kNaN, -1, 0}};  // triangle 0: inactive
    for (vec3 p : kTri) v.push_back(p + vec3(0, 0, 2));            // triangle 1
    v.insert(v.end(), {{kNaN, kNaN, kNaN}, {0, 0, 0}, {1, 1, 1}});  // triangle 2: inactive (all NaN is fine too)
    for (vec3 p : kTri) v.push_back(p + vec3(0, 0, 3));            // triangle 3
    const auto blas = r.h.blas({r.h.triangles(v)});
    const auto& active = r.h.device.findBottomLevelAS(blas)->geometries()[0].active;
    EXPECT_EQ(active, (std::vector<uint8_t>{0, 1, 0, 1}));
    r.h.tlas({Harness::instance(blas)});
    const auto& p = r.trace({zRay(0, 0), zRay(0, 0, 2.5f)});
    EXPECT_EQ(p[0].primitiveIndex, 1u);
    EXPECT_FLOAT_EQ(p[0].t, 7.0f);
    EXPECT_EQ(p[1].primitiveIndex, 3u);
    EXPECT_TRUE(r.h.device.buildDiagnostics().empty());
}

TEST(AccelerationStructure, DEGEN_1_InactiveJudgedAfterGeometryTransform) {
    Rig r;
    // Geometry 0's transform makes every x NaN (and only x): all its triangles become inactive.
    Matrix3x4 nanX = Matrix3x4::identity();
    nanX.m[0][0] = kNaN;
    GeometryDesc g0 = r.h.triangles(kTri);
    g0.Triangles.Transform3x4 = r.uploadTransform(nanX);
    const auto blas = r.h.blas({g0, r.h.triangles(kTri)});
    EXPECT_EQ(r.h.device.findBottomLevelAS(blas)->geometries()[0].active, std::vector<uint8_t>{0});
    r.h.tlas({Harness::instance(blas)});
    EXPECT_EQ(r.traceOne(zRay(0, 0)).geometryIndex, 1u);
    // A transform that makes y NaN while x stays a number is DEGEN-2.
    Matrix3x4 nanY = Matrix3x4::identity();
    nanY.m[1][3] = kNaN;
    GeometryDesc g1 = r.h.triangles(kTri);
    g1.Triangles.Transform3x4 = r.uploadTransform(nanY);
    expectDxrError("DEGEN-2", [&] { r.h.blas({g1}); });
}

TEST(AccelerationStructure, DEGEN_1_NaNMinXMakesAABBInactive) {
    Rig r;
    const auto blas = r.h.blas({r.h.aabbs({{kNaN, -1, -1, 1, 1, 1}, unitBox()})});
    EXPECT_EQ(r.h.device.findBottomLevelAS(blas)->geometries()[0].active, (std::vector<uint8_t>{0, 1}));
    r.h.tlas({Harness::instance(blas)});
    r.trace({zRay(0, 0)}, {"HG_BoxRec"});
    EXPECT_EQ(r.isCalls[0], std::vector<uint32_t>{1});
}

TEST(AccelerationStructure, DEGEN_2_NaNYWithFiniteXRefusedNamingEverything) {
    Rig r;
    std::vector<vec3> v;
    for (int i = 0; i < 3; ++i) v.insert(v.end(), kTri.begin(), kTri.end());
    v[2 * 3 + 1].y = kNaN;  // triangle 2, vertex 1, y
    const auto d = expectDxrError("DEGEN-2", [&] { r.h.blas({r.h.triangles(kTri), r.h.triangles(v)}); });
    EXPECT_EQ(valueOf(d, "geometry"), "1");
    EXPECT_EQ(valueOf(d, "primitive"), "2");
    EXPECT_EQ(valueOf(d, "vertex"), "1");
    EXPECT_EQ(valueOf(d, "component"), "y");
    v[2 * 3 + 1].y = 1;
    v[0 * 3 + 2].z = kNaN;
    const auto dz = expectDxrError("DEGEN-2", [&] { r.h.blas({r.h.triangles(v)}); });
    EXPECT_EQ(valueOf(dz, "primitive"), "0");
    EXPECT_EQ(valueOf(dz, "vertex"), "2");
    EXPECT_EQ(valueOf(dz, "component"), "z");
}

TEST(AccelerationStructure, DEGEN_2_NaNInAABBWithFiniteMinXRefused) {
    Rig r;
    const auto d = expectDxrError("DEGEN-2", [&] { r.h.blas({r.h.aabbs({unitBox(), {-1, -1, -1, 1, kNaN, 1}})}); });
    EXPECT_EQ(valueOf(d, "geometry"), "0");
    EXPECT_EQ(valueOf(d, "primitive"), "1");
    EXPECT_EQ(valueOf(d, "component"), "MaxY");
}

TEST(AccelerationStructure, DEGEN_3_NormFormatsAreNeverInactive) {
    // Bit patterns that would be NaN as half floats are ordinary numbers in SNORM/UNORM.
    Rig r;
    const auto snorm = r.rawTriangles(Format::R16G16_SNORM, u16s({0x8000, 0x8000, 0, 0x7FFF, 0x7E00, 0x8000}), 4, 3);
    const auto unorm = r.rawTriangles(Format::R16G16_UNORM, u16s({0x7E00, 0, 0x7E00, 0xFFFF, 0xFFFF, 0}), 4, 3);
    const auto blas = r.h.blas({snorm, unorm});
    for (const auto& g : r.h.device.findBottomLevelAS(blas)->geometries()) EXPECT_EQ(g.active, std::vector<uint8_t>{1});
    r.h.tlas({Harness::instance(blas)});
    EXPECT_EQ(r.traceOne(zRay(0.0f, -0.5f)).closestHits, 1u);
}

TEST(AccelerationStructure, DEGEN_4_InactiveInstanceKeepsItsIndex) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    r.h.tlas({Harness::instance(blas, 0, Matrix3x4::translation({-10, 0, 0})), Harness::instance(0),
              Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}))});
    EXPECT_EQ(r.traceOne(zRay(10, 0)).instanceIndex, 2u);
}

TEST(AccelerationStructure, DEGEN_5_BlasUpdateFlippingActiveStatusRefused) {
    Rig r;
    std::vector<vec3> v = kTri;
    v.insert(v.end(), kTri.begin(), kTri.end());
    GeometryDesc g = r.h.triangles(v);
    const auto blas = r.h.blas({r.h.triangles(kTri), g}, BUILD_FLAG_ALLOW_UPDATE);
    const uint32_t update = BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE;
    const GeometryDesc g0 = r.h.triangles(kTri);
    // Active -> inactive.
    const vec3 nanVertex(kNaN, 0, 0);
    r.h.device.memory().write(g.Triangles.VertexBuffer.StartAddress + 4 * sizeof(vec3), &nanVertex, sizeof(vec3));
    auto d = expectDxrError("DEGEN-5", [&] { r.h.device.buildBottomLevelAS({update, {g0, g}}, blas); });
    EXPECT_EQ(valueOf(d, "geometry"), "1");
    EXPECT_EQ(valueOf(d, "primitive"), "1");
    // Inactive -> active.
    std::vector<vec3> inactiveFirst = v;
    inactiveFirst[0].x = kNaN;
    GeometryDesc h0 = r.h.triangles(inactiveFirst);
    const auto blas2 = r.h.blas({h0}, BUILD_FLAG_ALLOW_UPDATE);
    const vec3 fixedVertex = kTri[0];
    r.h.device.memory().write(h0.Triangles.VertexBuffer.StartAddress, &fixedVertex, sizeof(vec3));
    d = expectDxrError("DEGEN-5", [&] { r.h.device.buildBottomLevelAS({update, {h0}}, blas2); });
    EXPECT_EQ(valueOf(d, "primitive"), "0");
}

TEST(AccelerationStructure, DEGEN_5_AABBUpdateFlippingActiveStatusRefused) {
    Rig r;
    GeometryDesc g = r.h.aabbs({unitBox(), unitBox()});
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    const float nan = kNaN;
    r.h.device.memory().write(g.AABBs.AABBs.StartAddress + sizeof(RaytracingAABB), &nan, 4);
    const auto d = expectDxrError("DEGEN-5", [&] {
        r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas);
    });
    EXPECT_EQ(valueOf(d, "primitive"), "1");
}

TEST(AccelerationStructure, DEGEN_5_TlasUpdateFlippingInstanceActiveStatusRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    std::vector<InstanceDesc> inst = {Harness::instance(blas), Harness::instance(blas)};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 2, ElementsLayout::Array, descs});
    inst[1].AccelerationStructure = 0;
    r.h.device.memory().write(descs, inst.data(), sizeof(InstanceDesc) * 2);
    const auto d = expectDxrError("DEGEN-5", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 2, ElementsLayout::Array, descs}, tlas);
    });
    EXPECT_EQ(valueOf(d, "InstanceIndex"), "1");
}

TEST(AccelerationStructure, DEGEN_5_TlasUpdateMakingInactiveInstanceActiveRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    std::vector<InstanceDesc> inst = {Harness::instance(blas), Harness::instance(0)};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 2, ElementsLayout::Array, descs});
    inst[1].AccelerationStructure = blas;
    r.h.device.memory().write(descs, inst.data(), sizeof(InstanceDesc) * 2);
    const auto d = expectDxrError("DEGEN-5", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 2, ElementsLayout::Array, descs}, tlas);
    });
    EXPECT_EQ(valueOf(d, "InstanceIndex"), "1");
}

TEST(AccelerationStructure, DEGEN_5_InstanceActivityFollowsItsAddressNotItsTransform) {
    // DEGEN-1: only a BLAS address of 0 makes an instance inactive. An instance with a
    // singular transform (INST-9: traversed as if inactive) is still active, so an update that
    // sets its address to 0 makes an active instance inactive, and the reverse too.
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    std::vector<InstanceDesc> inst = {Harness::instance(blas, 0, Matrix3x4::scale({1, 1, 0}))};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 1, ElementsLayout::Array, descs});
    inst[0].AccelerationStructure = 0;
    r.h.device.memory().write(descs, inst.data(), sizeof(InstanceDesc));
    const uint32_t update = BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE;
    expectDxrError("DEGEN-5", [&] { r.h.device.buildTopLevelAS({update, 1, ElementsLayout::Array, descs}, tlas); });

    std::vector<InstanceDesc> nullFirst = {Harness::instance(0)};
    const auto descs2 = r.h.device.memory().upload(nullFirst, "instances2");
    const auto tlas2 = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 1, ElementsLayout::Array, descs2});
    nullFirst[0] = Harness::instance(blas, 0, Matrix3x4::scale({0, 0, 0}));
    r.h.device.memory().write(descs2, nullFirst.data(), sizeof(InstanceDesc));
    expectDxrError("DEGEN-5", [&] { r.h.device.buildTopLevelAS({update, 1, ElementsLayout::Array, descs2}, tlas2); });
}

TEST(AccelerationStructure, DEGEN_6_InstanceOfBlasWithoutActivePrimitiveStaysActive) {
    // Degenerate (its BLAS has no active primitive) but active: making it null is DEGEN-5.
    Rig r;
    const auto empty = r.h.blas({r.h.triangles({{kNaN, 0, 0}, {0, 1, 0}, {1, 0, 0}})});
    EXPECT_FALSE(r.h.device.findBottomLevelAS(empty)->hasActivePrimitive());
    std::vector<InstanceDesc> inst = {Harness::instance(empty)};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 1, ElementsLayout::Array, descs});
    r.h.scene = tlas;
    EXPECT_EQ(r.traceOne(zRay(0.5f, 0.25f)).misses, 1u);
    inst[0].AccelerationStructure = 0;
    r.h.device.memory().write(descs, inst.data(), sizeof(InstanceDesc));
    expectDxrError("DEGEN-5", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 1, ElementsLayout::Array, descs}, tlas);
    });
}

TEST(AccelerationStructure, DEGEN_6_UpdateMayMoveTriangleOutOfDegeneracy) {
    Rig r;
    GeometryDesc g = r.h.triangles({{-1, 0, 0}, {0, 0, 0}, {1, 0, 0}});  // collinear: degenerate but active
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    EXPECT_EQ(r.h.device.findBottomLevelAS(blas)->geometries()[0].active, std::vector<uint8_t>{1});
    r.h.device.memory().write(g.Triangles.VertexBuffer.StartAddress, kTri.data(), sizeof(vec3) * 3);
    EXPECT_NO_THROW(r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas));
    r.h.tlas({Harness::instance(blas)});
    EXPECT_EQ(r.traceOne(zRay(0, 0)).closestHits, 1u);
}

TEST(AccelerationStructure, DEGEN_6_PointAABBStaysActiveAndIsEnumerated) {
    Rig r;
    const auto blas = r.h.blas({r.h.aabbs({{0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}})});
    EXPECT_EQ(r.h.device.findBottomLevelAS(blas)->geometries()[0].active, std::vector<uint8_t>{1});
    r.h.tlas({Harness::instance(blas)});
    r.trace({zRay(0.5f, 0.5f)}, {"HG_BoxRec"});
    EXPECT_EQ(r.isCalls[0], std::vector<uint32_t>{0});
}

TEST(AccelerationStructure, DEGEN_7_CollinearAndRepeatedIndexTrianglesNeverHit) {
    Rig r;
    GeometryDesc line = r.h.triangles({{-1, -1, 0}, {0, 0, 0}, {1, 1, 0}});
    GeometryDesc point = r.h.triangles({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
    GeometryDesc repeated = r.indexed(kTri, Format::R16_UINT, {0, 0, 1});
    r.h.tlas({Harness::instance(r.h.blas({line, point, repeated}))});
    const auto& p = r.trace({zRay(0, 0), zRay(0.5f, 0.5f), zRay(-1, -1), RayDesc{vec3(-2, -2, 0), 0, vec3(1, 1, 0), 100},
                             zRay(-0.5f, 0.0f)});
    for (size_t i = 0; i < p.size(); ++i) EXPECT_EQ(p[i].misses, 1u) << "ray " << i;
}

TEST(AccelerationStructure, DEGEN_8_InvertedAABBBecomesCentrePointWithWarning) {
    Rig r;
    // Inverted in x only: the box becomes the point (1, 0, 0).
    const auto blas = r.h.blas({r.h.aabbs({unitBox()}), r.h.aabbs({{50, 50, 50, 51, 51, 51}, {2, -1, -1, 0, 1, 1}})});
    const auto w = r.h.device.buildDiagnostics().find("DEGEN-8");
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(w->severity, Severity::Warning);
    EXPECT_EQ(valueOf(*w, "geometry"), "1");
    EXPECT_EQ(valueOf(*w, "primitive"), "1");
    EXPECT_EQ(r.h.device.buildDiagnostics().diagnostics().size(), 1u);
    r.h.tlas({Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}))});
    r.trace({zRay(11, 0), RayDesc{vec3(11, 0, 5), 0, vec3(0, 0, -1), 5.0f}}, {"HG_BoxRec"});
    // Geometry 0's unit box spans x in [9, 11], so it is touched at its face as well.
    std::vector<uint32_t> seen = r.isCalls[0];
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, (std::vector<uint32_t>{0, 1})) << "the centre point (TMax-inclusive too) is enumerated";
    seen = r.isCalls[1];
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, (std::vector<uint32_t>{0, 1}));
}

}  // namespace
}  // namespace refray::test
