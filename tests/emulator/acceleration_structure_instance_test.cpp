// Conformance tests for instances and the TLAS (emulator/acceleration_structure.*, dxr-semantics.md section 3: INST)
// and for triangle facing (FACE). The rig is acceleration_structure_rig.h.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "acceleration_structure_rig.h"
#include "emulator/limits.h"

namespace refray::test {
namespace {

using namespace acceleration_structure_rig;

constexpr float kInf = std::numeric_limits<float>::infinity();

RayDesc negZRay(float x, float y, float oz = 5.0f) { return RayDesc{vec3(x, y, oz), 0.0f, vec3(0, 0, -1), 100.0f}; }

std::string hexOf(uint64_t v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(v));
    return buf;
}

uint32_t bitsOf(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

// ---------------------------------------------------------------------------------------
// INST-1

TEST(AccelerationStructure, INST_1_InstanceDescIs64BytesWithDxrBitLayout) {
    static_assert(sizeof(InstanceDesc) == 64);
    Matrix3x4 m;
    for (int i = 0; i < 12; ++i) m.m[i / 4][i % 4] = float(i + 1);
    const InstanceDesc d = makeInstanceDesc(m, 0xABCDEF, 0x5A, 0x123456, 0xC3, 0x1122334455667700ull);
    uint32_t dw[16];
    std::memcpy(dw, &d, 64);
    for (int i = 0; i < 12; ++i) EXPECT_EQ(dw[i], bitsOf(float(i + 1))) << "dword " << i;  // row-major, translation col 3
    EXPECT_EQ(dw[12], 0xABCDEFu | 0x5Au << 24);
    EXPECT_EQ(dw[13], 0x123456u | 0xC3u << 24);
    uint64_t blas;
    std::memcpy(&blas, reinterpret_cast<const uint8_t*>(&d) + 56, 8);
    EXPECT_EQ(blas, 0x1122334455667700ull);
    // Fields wider than their bits are truncated, never spill into the neighbour.
    const InstanceDesc t = makeInstanceDesc(m, 0x1FFFFFF, 0x1FF, 0x1FFFFFF, 0x1FF, 0);
    std::memcpy(dw, &t, 64);
    EXPECT_EQ(dw[12], 0xFFFFFFFFu);
    EXPECT_EQ(dw[13], 0xFFFFFFFFu);
    EXPECT_EQ(kInstanceDescsByteAlignment, 16u);
}

TEST(AccelerationStructure, INST_1_TlasReadsHandPackedBytes) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    uint32_t dw[16] = {};
    const Matrix3x4 t = Matrix3x4::translation({3, 0, 0});
    std::memcpy(dw, &t.m, 48);
    dw[12] = 0x00ABCDu | 0x02u << 24;                                      // InstanceID, InstanceMask
    dw[13] = 1u | uint32_t(INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE) << 24;  // contribution 1, flags
    std::memcpy(&dw[14], &blas, 8);
    r.h.scene = r.h.device.buildTopLevelAS({BUILD_FLAG_NONE, 1, ElementsLayout::Array, r.h.device.memory().upload(dw, 64, "raw")});
    r.args.mask = 0x02;
    const Probe p = r.traceOne(zRay(3, 0), {"HG_Tri", "HG_TriRec"});
    ASSERT_EQ(p.closestHits, 1u);
    EXPECT_EQ(p.instanceID, 0xABCDu);
    EXPECT_EQ(p.tag, 77u);                          // record 1: the contribution was read
    EXPECT_EQ(p.hitKind, HIT_KIND_TRIANGLE_BACK_FACE);  // FRONT_COUNTERCLOCKWISE was read
    r.args.mask = 0xFD;
    EXPECT_EQ(r.traceOne(zRay(3, 0), {"HG_Tri", "HG_TriRec"}).misses, 1u);  // the mask was read
}

TEST(AccelerationStructure, INST_1_MisalignedInstanceDescsRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    std::vector<InstanceDesc> two = {Harness::instance(blas), Harness::instance(blas)};
    const auto addr = r.h.device.memory().upload(two, "instances");
    expectDxrError("INST-1", [&] { r.h.device.buildTopLevelAS({BUILD_FLAG_NONE, 1, ElementsLayout::Array, addr + 8}); });
}

// ---------------------------------------------------------------------------------------
// INST-2

TEST(AccelerationStructure, INST_2_TransformMapsObjectToWorld) {
    Rig r;
    // Rotate 90 degrees about z (object +x -> world +y), then translate by (5, 0, 2).
    Matrix3x4 m;
    m.m[0] = {0, -1, 0, 5};
    m.m[1] = {1, 0, 0, 0};
    m.m[2] = {0, 0, 1, 2};
    // A small triangle around object (1, 0, 0): world (5, 1, 2).
    const std::vector<vec3> small = {{0.9f, -0.1f, 0}, {1.0f, 0.1f, 0}, {1.1f, -0.1f, 0}};
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(small)}), 0, m)});
    const auto& p = r.trace({zRay(5, 1), zRay(6, 0), zRay(1, 0)}, {"HG_TriRec"});
    ASSERT_EQ(p[0].closestHits, 1u);
    EXPECT_FLOAT_EQ(p[0].t, 7.0f);
    EXPECT_EQ(r.objectToWorld[0], m);  // bit-exact
    EXPECT_NEAR(r.objectRayOrigin[0].x, 1.0f, 1e-6);
    EXPECT_NEAR(r.objectRayOrigin[0].y, 0.0f, 1e-6);
    EXPECT_NEAR(r.objectRayOrigin[0].z, -7.0f, 1e-6);
    EXPECT_EQ(p[1].misses, 1u);  // the inverse mapping would put it here
    EXPECT_EQ(p[2].misses, 1u);  // the untransformed position
}

// ---------------------------------------------------------------------------------------
// INST-3

TEST(AccelerationStructure, INST_3_InstanceIndexCountsInactiveInstances) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    r.h.tlas({Harness::instance(0, 0, Matrix3x4::identity(), 0xFF, 0, 7),
              Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}), 0xFF, 0, 0xABCDEF),
              Harness::instance(blas, 0, Matrix3x4::translation({20, 0, 0}), 0xFF, 0, 3)});
    const auto& p = r.trace({zRay(10, 0), zRay(20, 0), zRay(0, 0)});
    EXPECT_EQ(p[0].instanceIndex, 1u);
    EXPECT_EQ(p[0].instanceID, 0xABCDEFu);
    EXPECT_EQ(p[1].instanceIndex, 2u);
    EXPECT_EQ(p[1].instanceID, 3u);
    EXPECT_EQ(p[2].misses, 1u);
}

TEST(AccelerationStructure, INST_3_ArrayOfPointersIndexIsPointerPosition) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    auto& mem = r.h.device.memory();
    const auto a = mem.upload(std::vector<InstanceDesc>{Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF, 0, 100)}, "a");
    const auto b = mem.upload(
        std::vector<InstanceDesc>{Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}), 0xFF, 0, 200)}, "b");
    const std::vector<uint64_t> pointers = {b, a};
    r.h.scene = r.h.device.buildTopLevelAS({BUILD_FLAG_NONE, 2, ElementsLayout::ArrayOfPointers, mem.upload(pointers, "ptrs")});
    const auto& p = r.trace({zRay(0, 0), zRay(10, 0)});
    EXPECT_EQ(p[0].instanceIndex, 1u);
    EXPECT_EQ(p[0].instanceID, 100u);
    EXPECT_EQ(p[1].instanceIndex, 0u);
    EXPECT_EQ(p[1].instanceID, 200u);
}

// ---------------------------------------------------------------------------------------
// INST-4

TEST(AccelerationStructure, INST_4_MaskZeroNeverHits) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(kTri)}), 0, Matrix3x4::identity(), 0x00)});
    for (uint32_t mask : {0xFFu, 0x01u, 0x80u, 0xFFFFFFFFu}) {
        r.args.mask = mask;
        EXPECT_EQ(r.traceOne(zRay(0, 0)).misses, 1u) << "ray mask " << mask;
    }
}

TEST(AccelerationStructure, INST_4_PartialMaskOverlap) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(kTri)}), 0, Matrix3x4::identity(), 0x0F)});
    const std::vector<std::pair<uint32_t, bool>> cases = {
        {0xF0, false}, {0x18, true}, {0x08, true}, {0x01, true}, {0x100, false}, {0x1F0, false}, {0x00, false}, {0x310, false}};
    for (auto [mask, hit] : cases) {
        r.args.mask = mask;
        const Probe p = r.traceOne(zRay(0, 0));
        EXPECT_EQ(p.closestHits, hit ? 1u : 0u) << "ray mask " << std::hex << mask;
        EXPECT_EQ(p.misses, hit ? 0u : 1u) << "ray mask " << std::hex << mask;
    }
}

TEST(AccelerationStructure, INST_4_MaskedInstanceSkippedSilentlyBehindVisibleOne) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    r.h.tlas({Harness::instance(blas, 0, Matrix3x4::identity(), 0x02),
              Harness::instance(blas, 0, Matrix3x4::translation({0, 0, 3}), 0x01)});
    r.args.mask = 0x01;
    const Probe p = r.traceOne(zRay(0, 0));
    EXPECT_EQ(p.instanceIndex, 1u);
    EXPECT_FLOAT_EQ(p.t, 8.0f);
    EXPECT_TRUE(r.h.device.buildDiagnostics().empty());
}

// ---------------------------------------------------------------------------------------
// INST-5

TEST(AccelerationStructure, INST_5_ForceOpaqueWithForceNonOpaqueRefusedNamingInstance) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    const auto d = expectDxrError("INST-5", [&] {
        r.h.tlas({Harness::instance(blas), Harness::instance(blas), Harness::instance(0), 
                  Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF,
                                    INSTANCE_FLAG_FORCE_OPAQUE | INSTANCE_FLAG_FORCE_NON_OPAQUE)});
    });
    EXPECT_MESSAGE_HAS(d, "instance 3");
    EXPECT_EQ(valueOf(d, "InstanceIndex"), "3");
}

TEST(AccelerationStructure, INST_5_ForceFlagsOverrideGeometryOpacity) {
    Rig r;
    const auto opaque = r.h.blas({r.h.triangles(kTri, GEOMETRY_FLAG_OPAQUE)});
    const auto nonOpaque = r.h.blas({r.h.triangles(kTri, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(opaque, 0, Matrix3x4::identity(), 0xFF, INSTANCE_FLAG_FORCE_NON_OPAQUE),
              Harness::instance(nonOpaque, 0, Matrix3x4::translation({10, 0, 0}), 0xFF, INSTANCE_FLAG_FORCE_OPAQUE)});
    const auto& p = r.trace({zRay(0, 0), zRay(10, 0)}, {"HG_TriAH"});
    EXPECT_EQ(p[0].anyHits, 1u);
    EXPECT_EQ(p[1].anyHits, 0u);
    EXPECT_EQ(p[1].closestHits, 1u);
}

TEST(AccelerationStructure, INST_5_UnsupportedFlagBitsRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    const auto d = expectDxrError("INST-5", [&] {
        r.h.tlas({Harness::instance(blas, 0, Matrix3x4::identity(), 0xFF, 0x10)});
    });
    EXPECT_MESSAGE_HAS(d, "instance 0");
}

// ---------------------------------------------------------------------------------------
// INST-6

TEST(AccelerationStructure, INST_6_NullAddressIsInactive) {
    Rig r;
    r.h.tlas({Harness::instance(0), Harness::instance(0, 0, Matrix3x4::translation({1, 0, 0}))});
    const Probe p = r.traceOne(zRay(0, 0));
    EXPECT_EQ(p.misses, 1u);
    EXPECT_TRUE(r.h.device.buildDiagnostics().empty());
}

TEST(AccelerationStructure, INST_6_TlasAsInstanceAddressRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    const auto inner = r.h.tlas({Harness::instance(blas)});
    const auto d = expectDxrError("INST-6", [&] { r.h.tlas({Harness::instance(blas), Harness::instance(inner)}); });
    EXPECT_MESSAGE_HAS(d, "instance 1");
    EXPECT_MESSAGE_HAS(d, "TLAS");
    EXPECT_EQ(valueOf(d, "InstanceIndex"), "1");
    EXPECT_EQ(valueOf(d, "AccelerationStructure"), hexOf(inner));
}

TEST(AccelerationStructure, INST_6_GarbageAddressRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    for (GpuVirtualAddress bad : {GpuVirtualAddress(0xDEAD00), blas + 256, GpuVirtualAddress(r.h.device.memory().upload(kTri, "v"))}) {
        const auto d = expectDxrError("INST-6", [&] { r.h.tlas({Harness::instance(bad)}); });
        EXPECT_MESSAGE_HAS(d, "instance 0");
        EXPECT_EQ(valueOf(d, "AccelerationStructure"), hexOf(bad));
    }
}

// ---------------------------------------------------------------------------------------
// INST-7: 2^24 + 1 instances is refused before any desc is read.

TEST(AccelerationStructure, INST_7_TooManyInstancesRefused) {
    EXPECT_EQ(kMaxInstancesPerTopLevelAS, 1ull << 24);
    Rig r;
    const auto addr = r.h.device.memory().upload(std::vector<InstanceDesc>{Harness::instance(0)}, "one");
    const auto d = expectDxrError("INST-7", [&] {
        r.h.device.buildTopLevelAS({BUILD_FLAG_NONE, (1u << 24) + 1, ElementsLayout::Array, addr});
    });
    EXPECT_EQ(valueOf(d, "NumDescs"), std::to_string((1u << 24) + 1));
}

// ---------------------------------------------------------------------------------------
// INST-8

TEST(AccelerationStructure, INST_8_StaleTlasAfterBlasUpdateIsAnErrorAtTrace) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    const auto other = r.h.blas({r.h.triangles(kTri)});
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    const auto tlas = r.h.tlas({Harness::instance(other, 0, Matrix3x4::translation({10, 0, 0})), Harness::instance(blas)});
    EXPECT_EQ(r.traceOne(zRay(0, 0)).closestHits, 1u);

    const std::vector<vec3> moved = {{-1, -1, 2}, {0, 1, 2}, {1, -1, 2}};
    r.h.device.memory().write(g.Triangles.VertexBuffer.StartAddress, moved.data(), sizeof(vec3) * 3);
    r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas);
    const auto d = expectDxrError("INST-8", [&] { r.traceOne(zRay(0, 0)); });
    EXPECT_EQ(valueOf(d, "InstanceIndex"), "1");
    EXPECT_EQ(valueOf(d, "BLAS"), hexOf(blas));
    // Still stale on a second dispatch.
    expectDxrError("INST-8", [&] { r.traceOne(zRay(10, 0)); });

    // Rebuilding the TLAS makes it current, and it sees the moved triangle.
    r.h.tlas({Harness::instance(other, 0, Matrix3x4::translation({10, 0, 0})), Harness::instance(blas)});
    EXPECT_FLOAT_EQ(r.traceOne(zRay(0, 0)).t, 7.0f);
    (void)tlas;
}

TEST(AccelerationStructure, INST_8_TlasUpdateAfterBlasUpdateIsCurrent) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    const auto blas = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    const std::vector<InstanceDesc> inst = {Harness::instance(blas)};
    const auto descs = r.h.device.memory().upload(inst, "instances");
    const auto tlas = r.h.device.buildTopLevelAS({BUILD_FLAG_ALLOW_UPDATE, 1, ElementsLayout::Array, descs});
    r.h.scene = tlas;
    EXPECT_FLOAT_EQ(r.traceOne(zRay(0, 0)).t, 5.0f);
    const std::vector<vec3> moved = {{-1, -1, 1}, {0, 1, 1}, {1, -1, 1}};
    r.h.device.memory().write(g.Triangles.VertexBuffer.StartAddress, moved.data(), sizeof(vec3) * 3);
    r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, blas);
    expectDxrError("INST-8", [&] { r.traceOne(zRay(0, 0)); });
    EXPECT_EQ(r.h.device.buildTopLevelAS(
                  {BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, 1, ElementsLayout::Array, descs}, tlas),
              tlas);
    EXPECT_FLOAT_EQ(r.traceOne(zRay(0, 0)).t, 6.0f);
}

TEST(AccelerationStructure, INST_8_UpdatingAnUnreferencedBlasLeavesTlasCurrent) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    const auto unrelated = r.h.blas({g}, BUILD_FLAG_ALLOW_UPDATE);
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(kTri)}))});
    r.h.device.buildBottomLevelAS({BUILD_FLAG_ALLOW_UPDATE | BUILD_FLAG_PERFORM_UPDATE, {g}}, unrelated);
    EXPECT_EQ(r.traceOne(zRay(0, 0)).closestHits, 1u);
}

// ---------------------------------------------------------------------------------------
// INST-9

TEST(AccelerationStructure, INST_9_SingularTransformWarnsAndIsInactive) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    // Squash z: the triangle (z = 0) would still be "there" if the instance were traversed.
    r.h.tlas({Harness::instance(blas, 0, Matrix3x4::scale({1, 1, 0})),
              Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}))});
    const auto w = r.h.device.buildDiagnostics().find("INST-9");
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(w->severity, Severity::Warning);
    EXPECT_EQ(valueOf(*w, "InstanceIndex"), "0");
    const auto& p = r.trace({zRay(0, 0), zRay(10, 0)});
    EXPECT_EQ(p[0].misses, 1u);
    EXPECT_EQ(p[1].instanceIndex, 1u);
}

TEST(AccelerationStructure, INST_9_NonFiniteTransformWarnsAndIsInactive) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    Matrix3x4 nan = Matrix3x4::identity();
    nan.m[0][3] = kNaN;
    Matrix3x4 inf = Matrix3x4::identity();
    inf.m[1][1] = kInf;
    r.h.tlas({Harness::instance(blas, 0, nan), Harness::instance(blas, 0, inf)});
    const auto warnings = r.h.device.buildDiagnostics().warnings();
    ASSERT_EQ(warnings.size(), 2u);
    EXPECT_EQ(warnings[0].ruleId, "INST-9");
    EXPECT_EQ(warnings[1].ruleId, "INST-9");
    EXPECT_EQ(r.traceOne(zRay(0, 0)).misses, 1u);
}

// ---------------------------------------------------------------------------------------
// INST-10

TEST(AccelerationStructure, INST_10_BlasPassedToTraceRayRefused) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    r.h.tlas({Harness::instance(blas)});
    r.h.scene = blas;
    const auto d = expectDxrError("INST-10", [&] { r.traceOne(zRay(0, 0)); });
    EXPECT_EQ(valueOf(d, "AccelerationStructure"), hexOf(blas));
}

// ---------------------------------------------------------------------------------------
// FACE

TEST(AccelerationStructure, FACE_1_ClockwiseFromOriginIsFrontFacing) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(kTri)}))});
    const auto& p = r.trace({zRay(0, 0), negZRay(0, 0), RayDesc{vec3(3, 2, -5), 0, vec3(-0.6f, -0.4f, 1), 100}});
    EXPECT_EQ(p[0].hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
    EXPECT_EQ(p[1].hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
    EXPECT_EQ(p[2].hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
    // Reversing the app's vertex order reverses the facing.
    Rig q;
    q.h.tlas({Harness::instance(q.h.blas({q.h.triangles({kTri[0], kTri[2], kTri[1]})}))});
    EXPECT_EQ(q.traceOne(zRay(0, 0)).hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
}

TEST(AccelerationStructure, FACE_2_FrontCounterclockwiseSwapsFacing) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(kTri)}), 0, Matrix3x4::identity(), 0xFF,
                                INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE)});
    const auto& p = r.trace({zRay(0, 0), negZRay(0, 0)});
    EXPECT_EQ(p[0].hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
    EXPECT_EQ(p[1].hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
}

TEST(AccelerationStructure, FACE_3_MirroringInstanceTransformDoesNotFlipFacing) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    r.h.tlas({Harness::instance(blas, 0, Matrix3x4::scale({-1, 1, 1})),
              Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}) * Matrix3x4::scale({1, 1, -1}))});
    const auto& p = r.trace({zRay(0, 0), negZRay(0, 0), zRay(10, 0)});
    EXPECT_EQ(p[0].hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
    EXPECT_EQ(p[1].hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
    // Mirror in z: the world +z ray is an object -z ray, which sees the back.
    EXPECT_EQ(p[2].hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
}

TEST(AccelerationStructure, FACE_3_MirroringGeometryTransformFlipsFacing) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    g.Triangles.Transform3x4 = r.uploadTransform(Matrix3x4::scale({-1, 1, 1}));
    r.h.tlas({Harness::instance(r.h.blas({g}))});
    const auto& p = r.trace({zRay(0, 0), negZRay(0, 0)});
    EXPECT_EQ(p[0].hitKind, HIT_KIND_TRIANGLE_BACK_FACE);
    EXPECT_EQ(p[1].hitKind, HIT_KIND_TRIANGLE_FRONT_FACE);
}

TEST(AccelerationStructure, FACE_4_CullDisableDoesNotChangeHitKind) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(kTri)}), 0, Matrix3x4::identity(), 0xFF,
                                INSTANCE_FLAG_TRIANGLE_CULL_DISABLE)});
    EXPECT_EQ(r.traceOne(zRay(0, 0)).hitKind, 0xFEu);
    EXPECT_EQ(r.traceOne(negZRay(0, 0)).hitKind, 0xFFu);
    r.args.flags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
    const Probe p = r.traceOne(negZRay(0, 0));
    EXPECT_EQ(p.closestHits, 1u);
    EXPECT_EQ(p.hitKind, 0xFFu);
}

TEST(AccelerationStructure, FACE_5_CullingUsesFacingAndCullDisableSwitchesItOff) {
    Rig r;
    const auto blas = r.h.blas({r.h.triangles(kTri)});
    r.h.tlas({Harness::instance(blas),
              Harness::instance(blas, 0, Matrix3x4::translation({10, 0, 0}), 0xFF, INSTANCE_FLAG_TRIANGLE_CULL_DISABLE),
              Harness::instance(blas, 0, Matrix3x4::translation({20, 0, 0}) * Matrix3x4::scale({-1, 1, 1}))});
    r.args.flags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES;
    auto p = r.trace({zRay(0, 0), negZRay(0, 0), negZRay(10, 0), zRay(20, 0), negZRay(20, 0)});
    EXPECT_EQ(p[0].closestHits, 1u);
    EXPECT_EQ(p[1].misses, 1u);
    EXPECT_EQ(p[2].closestHits, 1u);
    EXPECT_EQ(p[3].closestHits, 1u);  // mirrored instance: still front for +z
    EXPECT_EQ(p[4].misses, 1u);
    r.args.flags = RAY_FLAG_CULL_FRONT_FACING_TRIANGLES;
    p = r.trace({zRay(0, 0), negZRay(0, 0), zRay(10, 0)});
    EXPECT_EQ(p[0].misses, 1u);
    EXPECT_EQ(p[1].closestHits, 1u);
    EXPECT_EQ(p[2].closestHits, 1u);
}

TEST(AccelerationStructure, FACE_5_CullingDoesNotApplyToProcedurals) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({unitBox()})}))});
    for (uint32_t f : {uint32_t(RAY_FLAG_CULL_BACK_FACING_TRIANGLES), uint32_t(RAY_FLAG_CULL_FRONT_FACING_TRIANGLES)}) {
        r.args.flags = f;
        EXPECT_EQ(r.traceOne(zRay(0, 0), {"HG_Box"}).closestHits, 1u);
        EXPECT_EQ(r.traceOne(negZRay(0, 0), {"HG_Box"}).closestHits, 1u);
    }
}

}  // namespace
}  // namespace refray::test
