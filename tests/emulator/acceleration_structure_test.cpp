// Conformance tests for emulator/acceleration_structure.* and the AS builds of emulator/device.cpp:
// dxr-semantics.md section 3 (BLAS, INST, FACE, DEGEN, UPD).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "emulator/limits.h"
#include "harness.h"

namespace refray::test {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// The reference triangle: clockwise seen from -z, so front-facing for +z rays (FACE-1).
const std::vector<vec3> kTri = {{-1, -1, 0}, {0, 1, 0}, {1, -1, 0}};

RayDesc zRay(float x, float y, float oz = -5.0f, float tMax = 100.0f, float tMin = 0.0f) {
    return RayDesc{vec3(x, y, oz), tMin, vec3(0, 0, 1), tMax};
}
RayDesc negZRay(float x, float y, float oz = 5.0f) { return RayDesc{vec3(x, y, oz), 0.0f, vec3(0, 0, -1), 100.0f}; }

std::string hexOf(uint64_t v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%llX", static_cast<unsigned long long>(v));
    return buf;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }


#define EXPECT_MESSAGE_HAS(diagnostic, text) \
    EXPECT_TRUE(contains((diagnostic).format(), text)) << "missing '" << (text) << "' in: " << (diagnostic).format()

// A harness plus a 1D ray generation shader that traces `rays[i]` with `args`, and a few
// extra shaders that record what the probe shaders do not.
class Rig {
public:
    Harness h;
    std::vector<RayDesc> rays;
    std::vector<Probe> results;
    std::vector<std::vector<uint32_t>> isCalls;  // per launch: PrimitiveIndex of every IS_Record call
    std::vector<Matrix3x4> objectToWorld;        // per launch, from CH_Record
    std::vector<vec3> objectRayOrigin;           // per launch, from CH_Record
    Harness::TraceArgs args;
    StateObjectPtr so;

    Rig() {
        args.multiplier = 0;  // every geometry of a BLAS uses the same record unless a test says otherwise
        h.addProbeShaders();
        h.library->addRayGeneration("RG", [this](ShaderContext& ctx) {
            const uint32_t i = ctx.DispatchRaysIndex().x;
            Probe p;
            ctx.TraceRay(h.scene, args.flags, args.mask, args.rayContribution, args.multiplier, args.missIndex, rays[i], p);
            results[i] = p;
        });
        h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "CH_Record", [this](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
                recordHitValues(ctx, p);
                p.barycentrics = a.barycentrics;
                p.tag = 77;
                const uint32_t i = ctx.DispatchRaysIndex().x;
                objectToWorld[i] = ctx.ObjectToWorld3x4();
                objectRayOrigin[i] = ctx.ObjectRayOrigin();
            });
        h.library->addAnyHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "AH_Ignore", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
                p.anyHits++;
                ctx.IgnoreHit();
            });
        h.library->addAnyHit<Probe, ProbeAttributes>("AH_BoxIgnore", [](ShaderContext& ctx, Probe& p, const ProbeAttributes&) {
            p.anyHits++;
            ctx.IgnoreHit();
        });
        h.library->addIntersection<ProbeAttributes>("IS_Record", [this](ShaderContext& ctx) {
            isCalls[ctx.DispatchRaysIndex().x].push_back(ctx.PrimitiveIndex());
        });
        h.stateObject.hitGroups.push_back({"HG_TriRec", HitGroupType::Triangles, "", "CH_Record", ""});
        h.stateObject.hitGroups.push_back({"HG_TriIgnore", HitGroupType::Triangles, "AH_Ignore", "CH_Probe", ""});
        h.stateObject.hitGroups.push_back({"HG_BoxRec", HitGroupType::ProceduralPrimitive, "", "CH_ProbeAABB", "IS_Record"});
        h.stateObject.hitGroups.push_back(
            {"HG_BoxIgnore", HitGroupType::ProceduralPrimitive, "AH_BoxIgnore", "CH_ProbeAABB", "IS_Box"});
    }
    Rig(const Rig&) = delete;

    std::vector<Probe>& trace(const std::vector<RayDesc>& r, const std::vector<std::string>& hitGroups = {"HG_Tri"},
                              DispatchOptions options = {}) {
        if (!so) so = h.pipeline();
        rays = r;
        results.assign(r.size(), Probe{});
        isCalls.assign(r.size(), {});
        objectToWorld.assign(r.size(), Matrix3x4{});
        objectRayOrigin.assign(r.size(), vec3(NAN));
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, hitGroups), uvec3(uint32_t(r.size()), 1, 1), options);
        return results;
    }
    Probe traceOne(const RayDesc& r, const std::vector<std::string>& hitGroups = {"HG_Tri"}, DispatchOptions options = {}) {
        return trace({r}, hitGroups, options)[0];
    }

    // Geometry from raw vertex bytes.
    GeometryDesc rawTriangles(Format format, const std::vector<uint8_t>& bytes, uint64_t stride, uint32_t vertexCount,
                              uint32_t flags = GEOMETRY_FLAG_OPAQUE) {
        GeometryDesc g;
        g.Type = GeometryType::Triangles;
        g.Flags = flags;
        g.Triangles.VertexFormat = format;
        g.Triangles.VertexCount = vertexCount;
        g.Triangles.VertexBuffer = {h.device.memory().upload(bytes, "raw vertices"), stride};
        return g;
    }
    GeometryDesc indexed(const std::vector<vec3>& vertices, Format indexFormat, const std::vector<uint32_t>& indices,
                         uint32_t flags = GEOMETRY_FLAG_OPAQUE) {
        GeometryDesc g = h.triangles(vertices, flags);
        g.Triangles.IndexFormat = indexFormat;
        g.Triangles.IndexCount = uint32_t(indices.size());
        if (indexFormat == Format::R16_UINT) {
            std::vector<uint16_t> narrow(indices.begin(), indices.end());
            g.Triangles.IndexBuffer = h.device.memory().upload(narrow, "indices16");
        } else {
            g.Triangles.IndexBuffer = h.device.memory().upload(indices, "indices32");
        }
        return g;
    }
    GpuVirtualAddress uploadTransform(const Matrix3x4& m) { return h.device.memory().upload(&m.m, 48, "Transform3x4"); }
};

template <class T>
std::vector<uint8_t> bytesOf(const std::vector<T>& values) {
    std::vector<uint8_t> out(values.size() * sizeof(T));
    std::memcpy(out.data(), values.data(), out.size());
    return out;
}

uint32_t bitsOf(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

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

const std::vector<vec3> kQuad = {{-1, -1, 0}, {-1, 1, 0}, {1, 1, 0}, {1, -1, 0}};

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

std::vector<uint8_t> u16s(std::initializer_list<uint16_t> v) { return bytesOf(std::vector<uint16_t>(v)); }
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
