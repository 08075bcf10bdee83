// Conformance tests for emulator/acceleration_structure.* and the AS builds of emulator/device.cpp: the BLAS
// (dxr-semantics.md section 3, BLAS). Instances and the TLAS, facing, degenerate primitives and updates are in
// acceleration_structure_instance_test.cpp, acceleration_structure_degenerate_test.cpp and
// acceleration_structure_update_test.cpp; the rig is acceleration_structure_rig.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "acceleration_structure_rig.h"
#include "emulator/limits.h"

namespace refray::test {
namespace {

using namespace acceleration_structure_rig;

// ---------------------------------------------------------------------------------------
// BLAS-1

TEST(AccelerationStructure, BLAS_1_MixedGeometryRefusedNamingFirstOtherType) {
    Rig r;
    const auto d = expectDxrError("BLAS-1", [&] {
        r.h.blas({r.h.triangles(kTri), r.h.triangles(kTri), r.h.aabbs({unitBox()}), r.h.triangles(kTri)});
    });
    EXPECT_MESSAGE_HAS(d, "geometry 2");
    EXPECT_EQ(valueOf(d, "first other"), "2");
    const auto d2 = expectDxrError("BLAS-1", [&] { r.h.blas({r.h.aabbs({unitBox()}), r.h.triangles(kTri)}); });
    EXPECT_MESSAGE_HAS(d2, "geometry 1");
    EXPECT_EQ(valueOf(d2, "first other"), "1");
}

TEST(AccelerationStructure, BLAS_1_AllTrianglesOrAllAABBsBuild) {
    Rig r;
    EXPECT_NO_THROW(r.h.blas({r.h.triangles(kTri), r.h.triangles(kTri)}));
    EXPECT_NO_THROW(r.h.blas({r.h.aabbs({unitBox()}), r.h.aabbs({unitBox()})}));
}

// ---------------------------------------------------------------------------------------
// BLAS-2

TEST(AccelerationStructure, BLAS_2_OpaqueGeometryRunsNoAnyHit) {
    Rig r;
    const auto opaque = r.h.blas({r.h.triangles(kTri, GEOMETRY_FLAG_OPAQUE)});
    const auto nonOpaque = r.h.blas({r.h.triangles(kTri, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(opaque), Harness::instance(nonOpaque, 0, Matrix3x4::translation({10, 0, 0}))});
    const auto& p = r.trace({zRay(0, 0), zRay(10, 0)}, {"HG_TriAH"});
    EXPECT_EQ(p[0].anyHits, 0u);
    EXPECT_EQ(p[0].closestHits, 1u);
    EXPECT_EQ(p[1].anyHits, 1u);
    EXPECT_EQ(p[1].closestHits, 1u);
}

TEST(AccelerationStructure, BLAS_2_NoDuplicateAnyHitAtMostOncePerTriangleEvenAdversarial) {
    // Two stacked non-opaque triangles; the AHS ignores every hit, so a duplicate would be
    // presented again. With NO_DUPLICATE_ANYHIT_INVOCATION: exactly one call per triangle.
    Rig r;
    const uint32_t flags = GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION;
    std::vector<vec3> two = kTri;
    for (vec3 v : kTri) two.push_back(v + vec3(0, 0, 1));
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(two, flags)}))});
    for (uint64_t seed = 0; seed < 32; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        const Probe p = r.traceOne(zRay(0, 0), {"HG_TriIgnore"}, o);
        EXPECT_EQ(p.anyHits, 2u) << "seed " << seed;
        EXPECT_EQ(p.misses, 1u);
    }
}

TEST(AccelerationStructure, BLAS_2_NoDuplicateAnyHitAtMostOncePerProceduralHit) {
    Rig r;
    const auto with = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION)});
    const auto without = r.h.blas({r.h.aabbs({unitBox()}, GEOMETRY_FLAG_NONE)});
    r.h.tlas({Harness::instance(with), Harness::instance(without, 0, Matrix3x4::translation({10, 0, 0}))});
    uint32_t maxWithout = 0;
    for (uint64_t seed = 0; seed < 32; ++seed) {
        DispatchOptions o;
        o.order = TraversalOrder::Adversarial;
        o.adversarialSeed = seed;
        const auto& p = r.trace({zRay(0, 0), zRay(10, 0)}, {"HG_BoxIgnore"}, o);
        EXPECT_EQ(p[0].anyHits, 1u) << "seed " << seed;
        EXPECT_GE(p[1].anyHits, 1u) << "seed " << seed;  // duplicates are legal without the flag
        maxWithout = std::max(maxWithout, p[1].anyHits);
    }
    // Not a DXR requirement, only a sanity check that the adversarial mode exercises duplicates.
    EXPECT_GE(maxWithout, 1u);
}

TEST(AccelerationStructure, BLAS_2_UndefinedGeometryFlagBitsRefused) {
    Rig r;
    const auto d = expectDxrError("BLAS-2", [&] { r.h.blas({r.h.triangles(kTri), r.h.triangles(kTri, 0x4)}); });
    EXPECT_MESSAGE_HAS(d, "geometry 1");
}

// ---------------------------------------------------------------------------------------
// BLAS-3

TEST(AccelerationStructure, BLAS_3_R16IndicesSelectTrianglesInAppOrder) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.indexed(kQuad, Format::R16_UINT, {0, 1, 2, 0, 2, 3})}))});
    const auto& p = r.trace({zRay(-0.5f, 0.5f), zRay(0.5f, -0.5f)});
    EXPECT_EQ(p[0].primitiveIndex, 0u);
    EXPECT_EQ(p[1].primitiveIndex, 1u);
    // Triangle 1 = (p0, p2, p3): (0.5,-0.5) = p0 + 0.25*(p2-p0) + 0.5*(p3-p0).
    EXPECT_FLOAT_EQ(p[1].barycentrics.x, 0.25f);
    EXPECT_FLOAT_EQ(p[1].barycentrics.y, 0.5f);
}

TEST(AccelerationStructure, BLAS_3_R32IndicesSelectTrianglesInAppOrder) {
    Rig r;
    // Triangle 1 starts at p3: (p3, p0, p2).
    r.h.tlas({Harness::instance(r.h.blas({r.indexed(kQuad, Format::R32_UINT, {0, 1, 2, 3, 0, 2})}))});
    const auto& p = r.trace({zRay(-0.5f, 0.5f), zRay(0.5f, -0.5f)});
    EXPECT_EQ(p[0].primitiveIndex, 0u);
    EXPECT_EQ(p[1].primitiveIndex, 1u);
    // (0.5,-0.5) = p3 + b1*(p0-p3) + b2*(p2-p3) = (1,-1) + b1*(-2,0) + b2*(0,2): b1 = 0.25, b2 = 0.25.
    EXPECT_FLOAT_EQ(p[1].barycentrics.x, 0.25f);
    EXPECT_FLOAT_EQ(p[1].barycentrics.y, 0.25f);
}

TEST(AccelerationStructure, BLAS_3_NonIndexedUsesConsecutiveVertices) {
    Rig r;
    std::vector<vec3> v = {kQuad[0], kQuad[1], kQuad[2], kQuad[0], kQuad[2], kQuad[3]};
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v)}))});
    const auto& p = r.trace({zRay(-0.5f, 0.5f), zRay(0.5f, -0.5f)});
    EXPECT_EQ(p[0].primitiveIndex, 0u);
    EXPECT_EQ(p[1].primitiveIndex, 1u);
}

TEST(AccelerationStructure, BLAS_3_IndexCountNotMultipleOf3WarnsAndIgnoresTrailing) {
    Rig r;
    // The 7th index (99) is past VertexCount; it is a trailing entry, so it must be ignored.
    const auto blas = r.h.blas({r.indexed(kQuad, Format::R32_UINT, {0, 1, 2, 0, 2, 3, 99})});
    EXPECT_EQ(r.h.device.findBottomLevelAS(blas)->geometries()[0].primitiveCount(), 2u);
    const auto w = r.h.device.buildDiagnostics().find("BLAS-3");
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(w->severity, Severity::Warning);
    EXPECT_EQ(valueOf(*w, "count"), "7");
    r.h.tlas({Harness::instance(blas)});
    EXPECT_EQ(r.traceOne(zRay(0.5f, -0.5f)).primitiveIndex, 1u);
}

TEST(AccelerationStructure, BLAS_3_VertexCountNotMultipleOf3WarnsWhenNonIndexed) {
    Rig r;
    std::vector<vec3> v = kTri;
    v.push_back({5, 5, 5});
    v.push_back({6, 6, 6});
    const auto blas = r.h.blas({r.h.triangles(v)});
    EXPECT_EQ(r.h.device.findBottomLevelAS(blas)->geometries()[0].primitiveCount(), 1u);
    const auto w = r.h.device.buildDiagnostics().find("BLAS-3");
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(w->severity, Severity::Warning);
    EXPECT_EQ(valueOf(*w, "count"), "5");
}

TEST(AccelerationStructure, BLAS_3_WellFormedBuildHasNoWarning) {
    Rig r;
    r.h.blas({r.indexed(kQuad, Format::R16_UINT, {0, 1, 2, 0, 2, 3})});
    EXPECT_TRUE(r.h.device.buildDiagnostics().empty());
}

TEST(AccelerationStructure, BLAS_3_NonIndexedWithIndexCountRefused) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    g.Triangles.IndexCount = 3;
    const auto d = expectDxrError("BLAS-3", [&] { r.h.blas({g}); });
    EXPECT_EQ(valueOf(d, "IndexCount"), "3");
}

TEST(AccelerationStructure, BLAS_3_IndexFormatOtherThanR16R32UnknownRefused) {
    Rig r;
    GeometryDesc g = r.indexed(kQuad, Format::R32_UINT, {0, 1, 2});
    g.Triangles.IndexFormat = Format::R32G32B32_FLOAT;
    const auto d = expectDxrError("BLAS-3", [&] { r.h.blas({g}); });
    EXPECT_EQ(valueOf(d, "IndexFormat"), "R32G32B32_FLOAT");
}

TEST(AccelerationStructure, BLAS_3_MisalignedIndexBufferRefused) {
    Rig r;
    GeometryDesc g = r.indexed(kQuad, Format::R32_UINT, {0, 1, 2, 0, 2, 3});
    g.Triangles.IndexBuffer += 2;
    g.Triangles.IndexCount = 3;
    expectDxrError("BLAS-3", [&] { r.h.blas({g}); });
}

TEST(AccelerationStructure, BLAS_3_IndexPastVertexCountRefused) {
    Rig r;
    GeometryDesc g = r.indexed(kQuad, Format::R16_UINT, {0, 1, 4});
    const auto d = expectDxrError("BLAS-3", [&] { r.h.blas({g}); });
    EXPECT_EQ(valueOf(d, "index"), "4");
}

// ---------------------------------------------------------------------------------------
// BLAS-4: every vertex format decodes by the D3D rules. Signed formats encode the triangle
// (-1,-1) (0,1) (1,-1), unsigned ones (0,0) (0,1) (1,0); a +z ray from z = -5 through a
// known point gives t = 5 + z and known barycentrics.

struct FormatCase {
    Format format;
    std::vector<uint8_t> bytes;
    uint64_t stride;
    bool isSigned;
    float z;  // the decoded z every vertex shares
};

std::vector<uint8_t> u8s(std::initializer_list<int> v) {
    std::vector<uint8_t> out;
    for (int x : v) out.push_back(uint8_t(x));
    return out;
}
std::vector<uint8_t> u32s(std::initializer_list<uint32_t> v) { return bytesOf(std::vector<uint32_t>(v)); }
uint32_t r10g10b10a2(uint32_t x, uint32_t y, uint32_t z, uint32_t a) { return x | y << 10 | z << 20 | a << 30; }

std::vector<FormatCase> formatCases() {
    const uint16_t hm1 = 0xBC00, h0 = 0x0000, h1 = 0x3C00, hThird = 0x3555, hNaN = 0x7E00;
    std::vector<FormatCase> c;
    // 32-bit float, 3 components.
    c.push_back({Format::R32G32B32_FLOAT, bytesOf(std::vector<float>{-1, -1, 0.75f, 0, 1, 0.75f, 1, -1, 0.75f}), 12, true, 0.75f});
    // 2 components with a 12-byte stride: the third float (3.0) must be ignored, z = 0.
    c.push_back({Format::R32G32_FLOAT, bytesOf(std::vector<float>{-1, -1, 3, 0, 1, 3, 1, -1, 3}), 12, true, 0.0f});
    // Half floats; A is a NaN and must be ignored. 0x3555 = 0.333251953125.
    c.push_back({Format::R16G16B16A16_FLOAT, u16s({hm1, hm1, hThird, hNaN, h0, h1, hThird, hNaN, h1, hm1, hThird, hNaN}), 8, true,
                 0.333251953125f});
    c.push_back({Format::R16G16_FLOAT, u16s({hm1, hm1, hNaN, hNaN, h0, h1, hNaN, hNaN, h1, hm1, hNaN, hNaN}), 8, true, 0.0f});
    // SNORM16: -32768 and -32767 both decode to -1; z = -32768 -> -1.
    c.push_back({Format::R16G16B16A16_SNORM,
                 u16s({0x8000, 0x8001, 0x8000, 0x1234, 0, 32767, 0x8000, 0x1234, 32767, 0x8000, 0x8000, 0x1234}), 8, true, -1.0f});
    c.push_back({Format::R16G16_SNORM, u16s({0x8000, 0x8000, 0, 32767, 32767, 0x8001}), 4, true, 0.0f});
    // UNORM16: 13107/65535 = 0.2.
    c.push_back({Format::R16G16B16A16_UNORM, u16s({0, 0, 13107, 0xFFFF, 0, 0xFFFF, 13107, 0, 0xFFFF, 0, 13107, 7}), 8, false,
                 float(13107.0 / 65535.0)});
    c.push_back({Format::R16G16_UNORM, u16s({0, 0, 0, 0xFFFF, 0xFFFF, 0}), 4, false, 0.0f});
    // R10G10B10A2: z = 341/1023 = 1/3; A is ignored.
    c.push_back({Format::R10G10B10A2_UNORM,
                 u32s({r10g10b10a2(0, 0, 341, 3), r10g10b10a2(0, 1023, 341, 0), r10g10b10a2(1023, 0, 341, 2)}), 4, false,
                 float(341.0 / 1023.0)});
    // UNORM8: 51/255 = 0.2.
    c.push_back({Format::R8G8B8A8_UNORM, u8s({0, 0, 51, 255, 0, 255, 51, 0, 255, 0, 51, 9}), 4, false, float(51.0 / 255.0)});
    c.push_back({Format::R8G8_UNORM, u8s({0, 0, 0, 255, 255, 0}), 2, false, 0.0f});
    // SNORM8: -128 and -127 both decode to -1.
    c.push_back({Format::R8G8B8A8_SNORM, u8s({0x80, 0x81, 0x80, 5, 0, 127, 0x80, 5, 127, 0x80, 0x80, 5}), 4, true, -1.0f});
    c.push_back({Format::R8G8_SNORM, u8s({0x80, 0x80, 0, 127, 127, 0x81}), 2, true, 0.0f});
    return c;
}

TEST(AccelerationStructure, BLAS_4_EveryVertexFormatDecodes) {
    for (const FormatCase& fc : formatCases()) {
        SCOPED_TRACE(std::string(toString(fc.format)));
        Rig r;
        r.h.tlas({Harness::instance(r.h.blas({r.rawTriangles(fc.format, fc.bytes, fc.stride, 3)}))});
        // Signed: (0,-0.5) = v0 + 0.25*(v1-v0) + 0.375*(v2-v0). Unsigned: (0.25,0.5) -> (0.5, 0.25).
        const Probe p = r.traceOne(fc.isSigned ? zRay(0.0f, -0.5f) : zRay(0.25f, 0.5f));
        ASSERT_EQ(p.closestHits, 1u);
        EXPECT_NEAR(p.t, double(fc.z) + 5.0, 1e-6);
        EXPECT_NEAR(p.barycentrics.x, fc.isSigned ? 0.25 : 0.5, 1e-6);
        EXPECT_NEAR(p.barycentrics.y, fc.isSigned ? 0.375 : 0.25, 1e-6);
        EXPECT_TRUE(r.h.device.buildDiagnostics().empty());
    }
}

TEST(AccelerationStructure, BLAS_4_SnormMinusMaxAndMinCodeBothDecodeToMinusOne) {
    // z = -32768 alone: -32768/32767 would be -1.00003 and move the plane.
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.rawTriangles(
        Format::R16G16B16A16_SNORM, u16s({0x8000, 0x8000, 0x8000, 0, 0, 32767, 0x8000, 0, 32767, 0x8000, 0x8000, 0}), 8, 3)}))});
    const Probe p = r.traceOne(zRay(0.0f, -0.5f));
    ASSERT_EQ(p.closestHits, 1u);
    EXPECT_EQ(p.t, 4.0f);
}

TEST(AccelerationStructure, BLAS_4_HalfFloatSubnormalDecodes) {
    // z = half 0x0200 = 2^-15 (subnormal): t from z = 0 is exactly 2^-15.
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.rawTriangles(
        Format::R16G16B16A16_FLOAT, u16s({0xBC00, 0xBC00, 0x0200, 0, 0, 0x3C00, 0x0200, 0, 0x3C00, 0xBC00, 0x0200, 0}), 8, 3)}))});
    const Probe p = r.traceOne(zRay(0.0f, -0.5f, 0.0f));
    ASSERT_EQ(p.closestHits, 1u);
    EXPECT_EQ(p.t, std::ldexp(1.0f, -15));
}

TEST(AccelerationStructure, BLAS_4_TwoComponentFormatsHaveZeroZ) {
    // R32G32 with stride 16: bytes 8..15 hold 7.0 twice and must not become z.
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.rawTriangles(
        Format::R32G32_FLOAT, bytesOf(std::vector<float>{-1, -1, 7, 7, 0, 1, 7, 7, 1, -1, 7, 7}), 16, 3)}))});
    const Probe p = r.traceOne(zRay(0.0f, -0.5f, -2.0f));
    ASSERT_EQ(p.closestHits, 1u);
    EXPECT_EQ(p.t, 2.0f);
}

TEST(AccelerationStructure, BLAS_4_R10G10B10A2NeedsStride4) {
    Rig r;
    const auto bytes = u32s({r10g10b10a2(0, 0, 0, 0), 0, r10g10b10a2(0, 1023, 0, 0), 0, r10g10b10a2(1023, 0, 0, 0), 0});
    const auto d = expectDxrError("BLAS-4", [&] { r.h.blas({r.rawTriangles(Format::R10G10B10A2_UNORM, bytes, 8, 3)}); });
    EXPECT_EQ(valueOf(d, "StrideInBytes"), "8");
}

TEST(AccelerationStructure, BLAS_4_OnlyLow32BitsOfStrideUsed) {
    Rig r;
    const auto bytes = bytesOf(kTri);
    r.h.tlas({Harness::instance(r.h.blas({r.rawTriangles(Format::R32G32B32_FLOAT, bytes, (1ull << 32) | 12u, 3)}))});
    const Probe p = r.traceOne(zRay(0.0f, -0.5f));
    EXPECT_EQ(p.closestHits, 1u);
    EXPECT_EQ(p.t, 5.0f);
}

TEST(AccelerationStructure, BLAS_4_StrideAndAddressMustBeMultiplesOfComponentSize) {
    Rig r;
    const auto bytes = bytesOf(std::vector<float>(16, 0.0f));
    expectDxrError("BLAS-4", [&] { r.h.blas({r.rawTriangles(Format::R32G32B32_FLOAT, bytes, 14, 3)}); });
    expectDxrError("BLAS-4", [&] { r.h.blas({r.rawTriangles(Format::R16G16_FLOAT, bytes, 5, 3)}); });
    GeometryDesc g = r.rawTriangles(Format::R32G32B32_FLOAT, bytes, 12, 3);
    g.Triangles.VertexBuffer.StartAddress += 2;
    expectDxrError("BLAS-4", [&] { r.h.blas({g}); });
    // A 16-bit format only needs 2-byte alignment; an odd stride of 6 for 3 halves is fine.
    EXPECT_NO_THROW(r.h.blas({r.rawTriangles(Format::R16G16_FLOAT, bytes, 6, 3)}));
}

TEST(AccelerationStructure, BLAS_4_ZeroStrideIsLegalAndDegenerate) {
    Rig r;
    const auto blas = r.h.blas({r.rawTriangles(Format::R32G32B32_FLOAT, bytesOf(kTri), 0, 3)});
    r.h.tlas({Harness::instance(blas)});
    EXPECT_EQ(r.traceOne(zRay(-1.0f, -1.0f)).closestHits, 0u);
}

TEST(AccelerationStructure, BLAS_4_IndexFormatAsVertexFormatRefused) {
    Rig r;
    const auto d = expectDxrError("BLAS-4", [&] { r.h.blas({r.rawTriangles(Format::R16_UINT, bytesOf(kTri), 12, 3)}); });
    EXPECT_EQ(valueOf(d, "VertexFormat"), "R16_UINT");
}

// ---------------------------------------------------------------------------------------
// BLAS-5

TEST(AccelerationStructure, BLAS_5_Transform3x4AppliedAtBuildAndNotInObjectToWorld) {
    Rig r;
    Matrix3x4 geometryTransform;  // scale x by 2, then move +3 in z
    geometryTransform.m[0] = {2, 0, 0, 0};
    geometryTransform.m[1] = {0, 1, 0, 0};
    geometryTransform.m[2] = {0, 0, 1, 3};
    GeometryDesc g = r.h.triangles(kTri);
    g.Triangles.Transform3x4 = r.uploadTransform(geometryTransform);
    const Matrix3x4 instanceTransform = Matrix3x4::translation({10, 0, 0});
    r.h.tlas({Harness::instance(r.h.blas({g}), 0, instanceTransform)});
    // x = 11.5 is object x = 1.5: only inside the triangle once it is scaled by 2.
    const auto& p = r.trace({zRay(11.5f, -0.9f), zRay(10.0f, 0.0f)}, {"HG_TriRec"});
    ASSERT_EQ(p[0].closestHits, 1u);
    EXPECT_FLOAT_EQ(p[0].t, 8.0f);
    EXPECT_EQ(r.objectToWorld[0], instanceTransform);
    EXPECT_EQ(r.objectRayOrigin[0], vec3(1.5f, -0.9f, -5.0f));  // after the instance transform only
    EXPECT_FLOAT_EQ(p[1].t, 8.0f);
}

TEST(AccelerationStructure, BLAS_5_Transform3x4AppliesToTwoComponentFormatsWithZZero) {
    Rig r;
    GeometryDesc g = r.rawTriangles(Format::R32G32_FLOAT, bytesOf(std::vector<float>{-1, -1, 0, 1, 1, -1}), 8, 3);
    g.Triangles.Transform3x4 = r.uploadTransform(Matrix3x4::translation({0, 0, 3}));
    r.h.tlas({Harness::instance(r.h.blas({g}))});
    const Probe p = r.traceOne(zRay(0.0f, -0.5f));
    ASSERT_EQ(p.closestHits, 1u);
    EXPECT_FLOAT_EQ(p.t, 8.0f);
}

TEST(AccelerationStructure, BLAS_5_MisalignedTransform3x4Refused) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    std::vector<float> buffer(16, 0.0f);
    g.Triangles.Transform3x4 = r.h.device.memory().upload(buffer, "transform") + 8;
    expectDxrError("BLAS-5", [&] { r.h.blas({g}); });
}

// ---------------------------------------------------------------------------------------
// BLAS-6

TEST(AccelerationStructure, BLAS_6_ZeroStrideEveryEntryReadsFirstBox) {
    Rig r;
    // Box 0 at the origin, later array entries elsewhere: with stride 0 they must be ignored.
    const std::vector<RaytracingAABB> boxes = {unitBox(), {9, -1, -1, 11, 1, 1}, {19, -1, -1, 21, 1, 1}};
    GeometryDesc g;
    g.Type = GeometryType::ProceduralPrimitiveAABBs;
    g.Flags = GEOMETRY_FLAG_OPAQUE;
    g.AABBs.AABBCount = 3;
    g.AABBs.AABBs = {r.h.device.memory().upload(boxes, "boxes"), 0};
    r.h.tlas({Harness::instance(r.h.blas({g}))});
    r.trace({zRay(0, 0), zRay(10, 0), zRay(20, 0)}, {"HG_BoxRec"});
    std::vector<uint32_t> seen = r.isCalls[0];
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_TRUE(r.isCalls[1].empty());
    EXPECT_TRUE(r.isCalls[2].empty());
}

TEST(AccelerationStructure, BLAS_6_PrimitiveIndexIsArrayPositionWithLargeStride) {
    Rig r;
    // Stride 32: 8 bytes of padding after each box, filled with NaNs that must not be read.
    std::vector<float> raw;
    auto add = [&](RaytracingAABB b) {
        raw.insert(raw.end(), {b.MinX, b.MinY, b.MinZ, b.MaxX, b.MaxY, b.MaxZ, kNaN, kNaN});
    };
    add({-11, -1, -1, -9, 1, 1});
    add(unitBox());
    add({9, -1, -1, 11, 1, 1});
    GeometryDesc g;
    g.Type = GeometryType::ProceduralPrimitiveAABBs;
    g.Flags = GEOMETRY_FLAG_OPAQUE;
    g.AABBs.AABBCount = 3;
    g.AABBs.AABBs = {r.h.device.memory().upload(raw, "boxes"), 32};
    r.h.tlas({Harness::instance(r.h.blas({g}))});
    r.trace({zRay(-10, 0), zRay(0, 0), zRay(10, 0)}, {"HG_BoxRec"});
    EXPECT_EQ(r.isCalls[0], std::vector<uint32_t>{0});
    EXPECT_EQ(r.isCalls[1], std::vector<uint32_t>{1});
    EXPECT_EQ(r.isCalls[2], std::vector<uint32_t>{2});
}

TEST(AccelerationStructure, BLAS_6_AddressAndStrideMustBeMultiplesOf8) {
    Rig r;
    GeometryDesc g = r.h.aabbs({unitBox(), unitBox()});
    g.AABBs.AABBs.StrideInBytes = 28;
    expectDxrError("BLAS-6", [&] { r.h.blas({g}); });
    g = r.h.aabbs({unitBox(), unitBox()});
    g.AABBs.AABBs.StartAddress += 4;
    g.AABBs.AABBCount = 1;
    expectDxrError("BLAS-6", [&] { r.h.blas({g}); });
}

TEST(AccelerationStructure, BLAS_6_AABBCountIs64Bit) {
    static_assert(sizeof(GeometryAABBsDesc::AABBCount) == 8);
    static_assert(sizeof(RaytracingAABB) == 24);
    SUCCEED();
}

// ---------------------------------------------------------------------------------------
// BLAS-7

TEST(AccelerationStructure, BLAS_7_RayTouchingBoxFaceIsEnumerated) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({{0, 0, 0, 1, 1, 1}})}))});
    r.trace(
        {
            RayDesc{vec3(-2, 1, 0.5f), 0, vec3(1, 0, 0), 100},       // grazes the y = MaxY face
            RayDesc{vec3(-2, 0, 0.5f), 0, vec3(1, -0.0f, 0), 100},   // grazes y = MinY with a -0 component
            RayDesc{vec3(0.5f, 0.5f, 1), 0, vec3(0, 0, 1), 100},      // origin on the MaxZ face, leaving
            RayDesc{vec3(1, 1, -3), 0, vec3(0, 0, 1), 100},           // along the edge x = y = 1
            RayDesc{vec3(1.0f, 2, 0.5f), 0, vec3(0, -1, 0), 100},     // along the x = MaxX face, moving in y
        },
        {"HG_BoxRec"});
    for (size_t i = 0; i < r.isCalls.size(); ++i) EXPECT_EQ(r.isCalls[i], std::vector<uint32_t>{0}) << "ray " << i;
}

TEST(AccelerationStructure, BLAS_7_BoxTouchedOnlyAtTMaxOrTMinIsEnumerated) {
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({{0, -1, -1, 1, 1, 1}})}))});
    r.trace(
        {
            RayDesc{vec3(-2, 0, 0), 0, vec3(1, 0, 0), 2.0f},     // reaches MinX exactly at TMax
            RayDesc{vec3(-2, 0, 0), 3.0f, vec3(1, 0, 0), 10.0f},  // leaves MaxX exactly at TMin
            RayDesc{vec3(-2, 0, 0), 2.0f, vec3(1, 0, 0), 2.0f},   // TMin == TMax on the face
        },
        {"HG_BoxRec"});
    for (size_t i = 0; i < r.isCalls.size(); ++i) EXPECT_EQ(r.isCalls[i], std::vector<uint32_t>{0}) << "ray " << i;
}

TEST(AccelerationStructure, BLAS_7_InstancedBoxFacesInclusive) {
    // The same through an instance transform with exact (power-of-two) scaling.
    Rig r;
    r.h.tlas({Harness::instance(r.h.blas({r.h.aabbs({{0, 0, 0, 1, 1, 1}})}), 0, Matrix3x4::scale({2, 2, 2}))});
    r.trace({RayDesc{vec3(-3, 2, 1), 0, vec3(1, 0, 0), 100}, RayDesc{vec3(-4, 1, 1), 0, vec3(2, 0, 0), 2.0f}}, {"HG_BoxRec"});
    EXPECT_EQ(r.isCalls[0], std::vector<uint32_t>{0});
    EXPECT_EQ(r.isCalls[1], std::vector<uint32_t>{0});
}

// ---------------------------------------------------------------------------------------
// BLAS-8

TEST(AccelerationStructure, BLAS_8_EditingInputBuffersAfterBuildChangesNothing) {
    Rig r;
    GeometryDesc tri = r.indexed(kQuad, Format::R32_UINT, {0, 1, 2, 0, 2, 3});
    tri.Triangles.Transform3x4 = r.uploadTransform(Matrix3x4::identity());
    GeometryDesc box = r.h.aabbs({unitBox()});
    const auto triBlas = r.h.blas({tri});
    const auto boxBlas = r.h.blas({box});
    r.h.tlas({Harness::instance(triBlas), Harness::instance(boxBlas, 1, Matrix3x4::translation({10, 0, 0}))});

    // Scribble over every input: vertices, indices, transform and boxes.
    auto& mem = r.h.device.memory();
    const std::vector<vec3> moved(4, vec3(50, 50, 50));
    mem.write(tri.Triangles.VertexBuffer.StartAddress, moved.data(), sizeof(vec3) * 4);
    const std::vector<uint32_t> idx(6, 0);
    mem.write(tri.Triangles.IndexBuffer, idx.data(), 24);
    const Matrix3x4 far = Matrix3x4::translation({0, 0, 40});
    mem.write(tri.Triangles.Transform3x4, &far.m, 48);
    const RaytracingAABB gone{100, 100, 100, 101, 101, 101};
    mem.write(box.AABBs.AABBs.StartAddress, &gone, sizeof gone);

    const auto& p = r.trace({zRay(0.5f, -0.5f), zRay(10, 0)}, {"HG_Tri", "HG_Box"});
    EXPECT_EQ(p[0].closestHits, 1u);
    EXPECT_EQ(p[0].primitiveIndex, 1u);
    EXPECT_FLOAT_EQ(p[0].t, 5.0f);
    EXPECT_EQ(p[1].closestHits, 1u);
    EXPECT_FLOAT_EQ(p[1].t, 4.0f);
}

// ---------------------------------------------------------------------------------------
// BLAS-9: 2^24 geometries cannot be built in a unit test (gigabytes of descs); only the
// constants and the per-geometry primitive count (checked before any data is read).

TEST(AccelerationStructure, BLAS_9_LimitConstants) {
    EXPECT_EQ(kMaxGeometriesPerBottomLevelAS, 1ull << 24);
    EXPECT_EQ(kMaxPrimitivesPerBottomLevelAS, 1ull << 29);
}

TEST(AccelerationStructure, BLAS_9_TooManyAABBsRefused) {
    Rig r;
    GeometryDesc g = r.h.aabbs({unitBox()});
    g.AABBs.AABBCount = (1ull << 29) + 1;
    const auto d = expectDxrError("BLAS-9", [&] { r.h.blas({g}); });
    EXPECT_EQ(valueOf(d, "AABBCount"), std::to_string((1ull << 29) + 1));
}

TEST(AccelerationStructure, BLAS_9_TooManyTrianglesRefused) {
    Rig r;
    GeometryDesc g = r.h.triangles(kTri);
    g.Triangles.VertexCount = 3u * ((1u << 29) + 1u);
    expectDxrError("BLAS-9", [&] { r.h.blas({g}); });
}

// ---------------------------------------------------------------------------------------
// BLAS-10

TEST(AccelerationStructure, BLAS_10_EachTriangleReportedOnceWithAppPrimitiveIndex) {
    // A strip of 8 separate, stacked non-opaque triangles: a ray through all of them sees
    // each exactly once (the AHS ignores, so nothing shrinks the interval), in app numbering.
    Rig r;
    std::vector<vec3> v;
    for (int i = 0; i < 8; ++i)
        for (vec3 p : kTri) v.push_back(p + vec3(0, 0, float(7 - i)));
    r.h.tlas({Harness::instance(r.h.blas({r.h.triangles(v, GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION)}))});
    const Probe all = r.traceOne(zRay(0, 0), {"HG_TriIgnore"});
    EXPECT_EQ(all.anyHits, 8u);
    for (int i = 0; i < 8; ++i) {
        const Probe p = r.traceOne(zRay(0, 0, float(7 - i) - 0.5f, 1.0f), {"HG_Tri"});
        EXPECT_EQ(p.primitiveIndex, uint32_t(i));
    }
}

}  // namespace
}  // namespace refray::test
