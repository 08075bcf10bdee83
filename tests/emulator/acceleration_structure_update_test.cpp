// Conformance tests for acceleration structure updates (emulator/acceleration_structure.*, dxr-semantics.md
// section 3: UPD). The rig is acceleration_structure_rig.h.
#include <gtest/gtest.h>

#include <vector>

#include "acceleration_structure_rig.h"

namespace refray::test {
namespace {

using namespace acceleration_structure_rig;

// ---------------------------------------------------------------------------------------
// UPD

TEST(AccelerationStructure, UPD_1_UpdateWithoutAllowUpdateRefused) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    const auto blas = r.h.blas({g});
    const auto d = expectDxrError("UPD-1", [&] {
        r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas);
    });
    EXPECT_MESSAGE_HAS(d, "ALLOW_UPDATE");
    const std::vector<InstanceDesc> inst = {Harness::instance(blas)};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_NONE, 1, ElementsLayout::Array, descs});
    expectDxrError("UPD-1", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 1, ElementsLayout::Array, descs}, tlas);
    });
}

TEST(AccelerationStructure, UPD_1_UpdateWithOtherBuildFlagsRefused) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PREFER_FAST_TRACE);
    const auto d = expectDxrError("UPD-1", [&] {
        r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE | BUILD_FLAG_MINIMIZE_MEMORY, {g}}, blas);
    });
    EXPECT_EQ(valueOf(d, "source Flags"), "0x5");
    EXPECT_EQ(valueOf(d, "update Flags"), "0x31");
    EXPECT_NO_THROW(r.h.device.buildBottomLevelAS(
        {BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE | BUILD_FLAG_PREFER_FAST_TRACE, {g}}, blas));
}

TEST(AccelerationStructure, UPD_1_UpdateSourceMustBeAStructureOfThatLevel) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    const auto tlas = r.h.tlas({Harness::instance(blas)}, BUILD_FLAG_ALLOW_UPDATE);
    expectDxrError("UPD-1", [&] { r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, tlas); });
    const auto descs = r.h.device.memory().upload(std::vector<InstanceDesc>{Harness::instance(blas)}, "i");
    expectDxrError("UPD-1", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 1, ElementsLayout::Array, descs}, blas);
    });
}

TEST(AccelerationStructure, UPD_2_ValidUpdateMovesVerticesTransformsAndBoxes) {
    Rig r;
    GeometryDesc tri = r.h.triangles(kTri);
    tri.Triangles.Transform3x4 = r.uploadTransform(Matrix3x4::identity());
    GeometryDesc box = r.h.aabbs({unitBox()});
    const auto triBlas = r.h.blas({tri}, BUILD_FLAG_ALLOW_UPDATE);
    const auto boxBlas = r.h.blas({box}, BUILD_FLAG_ALLOW_UPDATE);
    const Matrix3x4 up = Matrix3x4::translation({0, 0, 1});
    r.h.device.memory().write(tri.Triangles.Transform3x4, &up.m, 48);
    const RaytracingAABB moved{-1, -1, 1, 1, 1, 3};
    r.h.device.memory().write(box.AABBs.AABBs.StartAddress, &moved, sizeof moved);
    EXPECT_NO_THROW(r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {tri}}, triBlas));
    EXPECT_NO_THROW(r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {box}}, boxBlas));
    r.h.tlas({Harness::instance(triBlas), Harness::instance(boxBlas, 0, Matrix3x4::translation({10, 0, 0}))});
    EXPECT_FLOAT_EQ(r.traceOne(zRay(0, 0), {"HG_TriRec"}).t, 6.0f);
    r.trace({zRay(10, 0), zRay(10, 0, -5, 5.5f)}, {"HG_BoxRec"});
    EXPECT_EQ(r.isCalls[0], std::vector<uint32_t>{0});
    EXPECT_TRUE(r.isCalls[1].empty()) << "the box moved to z in [1, 3]";
}

TEST(AccelerationStructure, UPD_2_ChangedCountsFormatsFlagsRefusedNamingField) {
    Rig r;
    std::vector<vec3> six = kTri;
    six.insert(six.end(), kTri.begin(), kTri.end());
    const GeometryDesc base = r.indexed(six, Format::R16_UINT, {0, 1, 2, 3, 4, 5}, GEOMETRY_FLAG_OPAQUE);
    const auto blas = r.h.blas({base}, BUILD_FLAG_ALLOW_UPDATE);
    const uint32_t update = BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE;
    auto refuse = [&](const GeometryDesc& changed, const std::string& field) {
        SCOPED_TRACE(field);
        const auto d = expectDxrError("UPD-2", [&] { r.h.device.buildBottomLevelAS({update, {changed}}, blas); });
        EXPECT_MESSAGE_HAS(d, field);
    };
    GeometryDesc g = base;
    g.Triangles.VertexCount = 7;
    refuse(g, "VertexCount");
    g = base;
    g.Triangles.IndexCount = 3;
    refuse(g, "IndexCount");
    g = base;
    g.Flags = GEOMETRY_FLAG_NONE;
    refuse(g, "flags");
    g = r.indexed(six, Format::R32_UINT, {0, 1, 2, 3, 4, 5});
    refuse(g, "IndexFormat");
    g = base;
    g.Triangles.Transform3x4 = r.uploadTransform(Matrix3x4::identity());
    refuse(g, "Transform3x4");
    g = base;
    g.Triangles.VertexFormat = Format::R32G32_FLOAT;
    refuse(g, "VertexFormat");
    const auto d = expectDxrError("UPD-2", [&] { r.h.device.buildBottomLevelAS({update, {base, base}}, blas); });
    EXPECT_MESSAGE_HAS(d, "number of geometries");
    // And the unchanged desc is accepted.
    EXPECT_NO_THROW(r.h.device.buildBottomLevelAS({update, {base}}, blas));
}

TEST(AccelerationStructure, UPD_2_ChangedAABBCountRefused) {
    Rig r;
    const GeometryDesc base = r.h.aabbs({unitBox(), unitBox()});
    const auto blas = r.h.blas({base}, BUILD_FLAG_ALLOW_UPDATE);
    GeometryDesc g = base;
    g.AABBs.AABBCount = 1;
    const auto d = expectDxrError("UPD-2", [&] {
        r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas);
    });
    EXPECT_MESSAGE_HAS(d, "AABBCount");
}

TEST(AccelerationStructure, UPD_2_ChangedIndexDataRefused) {
    // The index buffer's contents are part of the inputs an update may not change.
    Rig r;
    const GeometryDesc g = r.indexed(kQuad, Format::R16_UINT, {0, 1, 2, 0, 2, 3});
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    const std::vector<uint16_t> other = {0, 1, 3, 1, 2, 3};
    r.h.device.memory().write(g.Triangles.IndexBuffer, other.data(), 12);
    const auto d = expectDxrError("UPD-2", [&] {
        r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas);
    });
    EXPECT_MESSAGE_HAS(d, "index");
}

TEST(AccelerationStructure, UPD_3_TlasUpdateMayChangeInstancesButNotTheirNumber) {
    Rig r;
    const auto a = r.h.blas({r.h.triangles(kTri)});
    const auto b = r.h.blas({r.h.triangles({{-1, -1, 2}, {0, 1, 2}, {1, -1, 2}})});
    std::vector<InstanceDesc> inst = {Harness::instance(a, 0, Matrix3x4::identity(), 0xFF, 0, 1)};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 1, ElementsLayout::Array, descs});
    r.h.scene = tlas;
    EXPECT_FLOAT_EQ(r.traceOne(zRay(0, 0)).t, 5.0f);
    inst[0] = Harness::instance(b, 0, Matrix3x4::translation({0, 0, 1}), 0xFF, 0, 9);
    r.h.device.memory().write(descs, inst.data(), sizeof(InstanceDesc));
    r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 1, ElementsLayout::Array, descs}, tlas);
    const Probe p = r.traceOne(zRay(0, 0));
    EXPECT_FLOAT_EQ(p.t, 8.0f);
    EXPECT_EQ(p.instanceID, 9u);

    const auto two = r.h.device.memory().upload(std::vector<InstanceDesc>{inst[0], inst[0]}, "two");
    const auto d = expectDxrError("UPD-3", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 2, ElementsLayout::Array, two}, tlas);
    });
    EXPECT_EQ(valueOf(d, "before"), "1");
    EXPECT_EQ(valueOf(d, "after"), "2");
}

TEST(AccelerationStructure, UPD_4_PreferFastTraceAndFastBuildRefused) {
    Rig r;
    const uint32_t both = BUILD_FLAG_PREFER_FAST_TRACE | BUILD_FLAG_PREFER_FAST_BUILD;
    expectDxrError("UPD-4", [&] { r.h.blas({r.h.triangles(kTri)}, both); });
    const auto blas = r.h.blas({r.h.triangles(kTri)}, BUILD_FLAG_PREFER_FAST_BUILD);
    expectDxrError("UPD-4", [&] { r.h.tlas({Harness::instance(blas)}, both | BUILD_FLAG_ALLOW_UPDATE); });
    EXPECT_NO_THROW(r.h.tlas({Harness::instance(blas)}, BUILD_FLAG_PREFER_FAST_TRACE));
}

}  // namespace
}  // namespace refray::test
