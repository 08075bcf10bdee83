// Conformance tests for emulator/shader_table.cpp and the record lookups of the dispatcher:
// dxr-semantics.md section 1 (IDX) and section 2 (REC).
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstring>

#include "emulator/limits.h"
#include "harness.h"

namespace refray::test {
namespace {

// ---------------------------------------------------------------------------------------
// Helpers: shaders whose record is identified by a local root constant (the "tag").


RootSignaturePtr tagSignature(const std::string& name = "Tag") {
    return RootSignature::create({name, {RootParameter::constants(1, 0)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
}

struct CallParams {
    uint32_t tag = 0;
    uint32_t calls = 0;
};

// "CH_Tag" / "HG_Tag" (triangles), "CH_TagBox" / "HG_TagBox" (IS_Box), "Miss_Tag", "CL_Tag":
// each writes its record's local constant into Probe::tag (CallParams::tag for the callable).
void addTagShaders(Harness& h, const RootSignaturePtr& sig) {
    h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Tag", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
            p.closestHits++;
            p.tag = ctx.localRootConstants<uint32_t>(0);
            p.t = ctx.RayTCurrent();
            p.instanceIndex = ctx.InstanceIndex();
            p.geometryIndex = ctx.GeometryIndex();
            p.primitiveIndex = ctx.PrimitiveIndex();
        });
    h.library->addClosestHit<Probe, ProbeAttributes>("CH_TagBox", [](ShaderContext& ctx, Probe& p, const ProbeAttributes&) {
        p.closestHits++;
        p.tag = ctx.localRootConstants<uint32_t>(0);
        p.geometryIndex = ctx.GeometryIndex();
    });
    h.library->addMiss<Probe>("Miss_Tag", [](ShaderContext& ctx, Probe& p) {
        p.misses++;
        p.tag = ctx.localRootConstants<uint32_t>(0);
    });
    h.library->addCallable<CallParams>("CL_Tag", [](ShaderContext& ctx, CallParams& c) {
        c.calls++;
        c.tag = ctx.localRootConstants<uint32_t>(0);
    });
    h.stateObject.hitGroups.push_back({"HG_Tag", HitGroupType::Triangles, "", "CH_Tag", ""});
    h.stateObject.hitGroups.push_back({"HG_TagBox", HitGroupType::ProceduralPrimitive, "", "CH_TagBox", "IS_Box"});
    h.stateObject.localRootSignatures.push_back({sig, {"HG_Tag", "HG_TagBox", "Miss_Tag", "CL_Tag"}});
}

// `count` records of `name`, record i tagged firstTag + i.
GpuVirtualAddressRangeAndStride tagTable(Harness& h, const StateObjectPtr& so, const RootSignaturePtr& sig,
                                         const std::string& name, uint32_t count, uint32_t firstTag = 100,
                                         uint64_t strideOverride = ~0ull) {
    ShaderTableBuilder builder("tag table " + name);
    for (uint32_t i = 0; i < count; ++i) {
        LocalRootArguments args(sig);
        args.setConstants(0, firstTag + i);
        builder.addRecord(so->shaderIdentifier(name), args);
    }
    return builder.upload(h.device.memory(), strideOverride);
}

std::vector<vec3> triangleAt(vec3 o) {
    return {o + vec3(-1, -1, 0), o + vec3(0, 1, 0), o + vec3(1, -1, 0)};
}

// The standard hitting ray: hits a triangleAt(0) at t = 5.
RayDesc hitRay(uvec3 = uvec3(0u)) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f}; }
RayDesc missRay(uvec3 = uvec3(0u)) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, -1), 100.0f}; }

// A TLAS of two instances: instance 0 far away (C = 0), instance 1 at the origin with
// contribution C over a BLAS of three geometries of which G = 2 lies at the origin.
void buildThreeGeometryScene(Harness& h, uint32_t c, uint32_t geometryFlags = GEOMETRY_FLAG_OPAQUE) {
    const auto blas = h.blas({h.triangles(triangleAt({10, 0, 0}), geometryFlags),
                              h.triangles(triangleAt({20, 0, 0}), geometryFlags),
                              h.triangles(triangleAt({0, 0, 0}), geometryFlags)});
    h.tlas({Harness::instance(blas, 0, Matrix3x4::translation({0, 100, 0})), Harness::instance(blas, c)});
}

// One triangle at the origin, instance contribution c.
void buildOneTriangleScene(Harness& h, uint32_t c = 0, uint32_t geometryFlags = GEOMETRY_FLAG_OPAQUE) {
    const auto blas = h.blas({h.triangles(triangleAt({0, 0, 0}), geometryFlags)});
    h.tlas({Harness::instance(blas, c)});
}

// A ray generation record built by hand (for NULL, misaligned or argument-carrying records).
DispatchRaysDesc descWithRayGen(GpuVirtualAddressRangeAndStride rg, uvec3 dims = uvec3(1u)) {
    DispatchRaysDesc desc;
    desc.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
    desc.Width = dims.x;
    desc.Height = dims.y;
    desc.Depth = dims.z;
    return desc;
}

// ---------------------------------------------------------------------------------------
// IDX: the indexing rule.

TEST(ShaderTable, IDX_1_AllFourTermsSelectTheRecord) {
    // R = 3, M = 4, G = 2, C = 5  ->  I = 3 + 4*2 + 5 = 16.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 3;
    args.multiplier = 4;
    h.addTracingRayGen(hitRay, args, results);
    buildThreeGeometryScene(h, 5);
    const auto so = h.pipeline();
    h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1, 900), tagTable(h, so, sig, "HG_Tag", 24));
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(results[0].instanceIndex, 1u);
    EXPECT_EQ(results[0].geometryIndex, 2u);
    EXPECT_EQ(results[0].tag, 100u + 16u);
}

TEST(ShaderTable, IDX_1_PureFunctionKeepsEveryTerm) {
    const HitGroupIndexTerms t = hitGroupRecordIndex(3, 4, 2, 5);
    EXPECT_EQ(t.rayContribution, 3u);
    EXPECT_EQ(t.multiplier, 4u);
    EXPECT_EQ(t.geometryIndex, 2u);
    EXPECT_EQ(t.instanceContribution, 5u);
    EXPECT_EQ(t.index, 16u);
    const GpuVirtualAddressRangeAndStride table{0x10000, 64 * 32, 64};
    EXPECT_EQ(recordAddress(table, t.index), 0x10000u + 64u * 16u);
}

TEST(ShaderTable, IDX_2_HighBitsOfRAndMAreMaskedWithAWarning) {
    // R = 0x13 -> 3, M = 0x24 -> 4; the record is the same as with clean arguments.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 0x13;
    args.multiplier = 0x24;
    h.addTracingRayGen(hitRay, args, results);
    buildThreeGeometryScene(h, 5);
    const auto so = h.pipeline();
    const DispatchResult r = h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1, 900), tagTable(h, so, sig, "HG_Tag", 24));
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(results[0].tag, 100u + 16u);

    const auto w = r.diagnostics.find("IDX-2");
    ASSERT_TRUE(w.has_value());
    EXPECT_EQ(w->severity, Severity::Warning);
    EXPECT_NE(w->message.find("low 4"), std::string::npos) << w->message;
    EXPECT_EQ(valueOf(*w, "RayContributionToHitGroupIndex"), "19");
    EXPECT_EQ(valueOf(*w, "MultiplierForGeometryContributionToHitGroupIndex"), "36");
    EXPECT_TRUE(r.diagnostics.errors().empty());
}

TEST(ShaderTable, IDX_2_NoWarningForCleanArguments) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 15;
    args.multiplier = 15;
    h.addTracingRayGen(missRay, args, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const DispatchResult r = h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tri"}));
    EXPECT_EQ(results[0].misses, 1u);
    EXPECT_FALSE(r.diagnostics.find("IDX-2").has_value());
}

TEST(ShaderTable, IDX_2_PureFunctionMasksEachTermToItsWidth) {
    const HitGroupIndexTerms t = hitGroupRecordIndex(0xFFFFFFF3u, 0x12345674u, 2, 0xAB000005u);
    EXPECT_EQ(t.rayContribution, 3u);
    EXPECT_EQ(t.multiplier, 4u);
    EXPECT_EQ(t.instanceContribution, 5u);
    EXPECT_EQ(t.rawRayContribution, 0xFFFFFFF3u);
    EXPECT_EQ(t.rawMultiplier, 0x12345674u);
    EXPECT_EQ(t.index, 16u);
}

TEST(ShaderTable, IDX_3_IndexAndOffsetUse64BitArithmetic) {
    constexpr uint32_t kMax24 = (1u << 24) - 1;
    // Largest legal index: 15 + 15*(2^24-1) + (2^24-1) = 2^28 - 1 (fits uint32, offset does not).
    const HitGroupIndexTerms t = hitGroupRecordIndex(15, 15, kMax24, kMax24);
    EXPECT_EQ(t.index, (1ull << 28) - 1);
    // Junk in the high bits changes nothing.
    EXPECT_EQ(hitGroupRecordIndex(0xFFFFFFFFu, 0xFFFFFFFFu, kMax24, 0xFFFFFFFFu).index, (1ull << 28) - 1);

    const GpuVirtualAddressRangeAndStride table{0x40000, 1ull << 41, kMaxShaderRecordStride};
    const uint64_t expected = 0x40000ull + 4096ull * ((1ull << 28) - 1);  // about 2^40: wraps in 32 bits
    EXPECT_EQ(recordAddress(table, t.index), expected);
    EXPECT_GT(recordAddress(table, t.index), uint64_t(UINT32_MAX));

    // Miss and callable indices: 16 bits, and all 32 bits (IDX-7, IDX-8).
    EXPECT_EQ(recordAddress(table, missRecordIndex(0xFFFFFFFFu)), 0x40000ull + 4096ull * 0xFFFF);
    EXPECT_EQ(recordAddress(table, callableRecordIndex(0xFFFFFFFFu)), 0x40000ull + 4096ull * 0xFFFFFFFFull);
}

TEST(ShaderTable, IDX_4_GeometryIndexIsTheBuildInputPosition) {
    // M = 1, R = 0, C = 0: geometry g selects record g.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(3);
    h.addTracingRayGen([](uvec3 i) { return RayDesc{vec3(10.0f * float(i.x), 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f}; },
                       {}, results);
    const auto blas = h.blas({h.triangles(triangleAt({20, 0, 0})), h.triangles(triangleAt({0, 0, 0})),
                              h.triangles(triangleAt({10, 0, 0}))});
    h.tlas({Harness::instance(blas, 0)});
    const auto so = h.pipeline();
    h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1, 900), tagTable(h, so, sig, "HG_Tag", 3), uvec3(3, 1, 1));
    const uint32_t expectedGeometry[3] = {1, 2, 0};  // x = 0, 10, 20
    for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(results[i].closestHits, 1u) << i;
        EXPECT_EQ(results[i].geometryIndex, expectedGeometry[i]);
        EXPECT_EQ(results[i].tag, 100u + expectedGeometry[i]);
    }
}

TEST(ShaderTable, IDX_5_TwoInstancesOfOneBLASSelectDifferentRecords) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(2);
    h.addTracingRayGen([](uvec3 i) { return RayDesc{vec3(10.0f * float(i.x), 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f}; },
                       {}, results);
    const auto blas = h.blas({h.triangles(triangleAt({0, 0, 0}))});
    h.tlas({Harness::instance(blas, 2), Harness::instance(blas, 7, Matrix3x4::translation({10, 0, 0}))});
    const auto so = h.pipeline();
    h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1, 900), tagTable(h, so, sig, "HG_Tag", 8), uvec3(2, 1, 1));
    EXPECT_EQ(results[0].tag, 102u);
    EXPECT_EQ(results[1].tag, 107u);
    EXPECT_EQ(results[1].instanceIndex, 1u);
}

TEST(ShaderTable, IDX_6_MultiplierZeroDropsTheGeometryTerm) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 1;
    args.multiplier = 0;
    h.addTracingRayGen(hitRay, args, results);
    buildThreeGeometryScene(h, 5);
    const auto so = h.pipeline();
    h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1, 900), tagTable(h, so, sig, "HG_Tag", 24));
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(results[0].geometryIndex, 2u);
    EXPECT_EQ(results[0].tag, 100u + 1u + 5u);
}

TEST(ShaderTable, IDX_7_MissIndexUsesOnlyTheLow16Bits) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.missIndex = 0x30002;  // -> 2
    args.rayContribution = 9;   // no R, M, G or C term for misses
    args.multiplier = 7;
    h.addTracingRayGen(missRay, args, results);
    buildOneTriangleScene(h, 3);
    const auto so = h.pipeline();
    const DispatchResult r = h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 4, 900), tagTable(h, so, sig, "HG_Tag", 1));
    ASSERT_EQ(results[0].misses, 1u);
    EXPECT_EQ(results[0].tag, 902u);
    EXPECT_TRUE(r.diagnostics.errors().empty());
    EXPECT_EQ(missRecordIndex(0x30002), 2u);
}

TEST(ShaderTable, IDX_8_CallableIndexSelectsTheRecord) {
    Harness h;
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    h.addProbeShaders();
    CallParams got[2];
    h.library->addRayGeneration("RG", [&got](ShaderContext& ctx) {
        ctx.CallShader(2, got[0]);
        ctx.CallShader(0, got[1]);
    });
    const auto so = h.pipeline();
    h.dispatch(so, {}, {}, uvec3(1u), {}, nullptr, tagTable(h, so, sig, "CL_Tag", 3, 500));
    EXPECT_EQ(got[0].tag, 502u);
    EXPECT_EQ(got[0].calls, 1u);
    EXPECT_EQ(got[1].tag, 500u);
    EXPECT_EQ(callableRecordIndex(0xFFFFFFFFu), 0xFFFFFFFFull);  // [SILENT]: all 32 bits
}

TEST(ShaderTable, IDX_8_CallableIndexIsNotMaskedTo16Bits) {
    // Index 0x10001 would be record 1 if masked like a miss index; with all 32 bits it lies
    // far past the end of a 2-record table.
    Harness h;
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    h.addProbeShaders();
    h.library->addRayGeneration("RG", [](ShaderContext& ctx) {
        CallParams c;
        ctx.CallShader(0x10001, c);
    });
    const auto so = h.pipeline();
    const auto callable = tagTable(h, so, sig, "CL_Tag", 2, 500);
    const Diagnostic d = expectDxrError("IDX-11", [&] { h.dispatch(so, {}, {}, uvec3(1u), {}, nullptr, callable); });
    EXPECT_NE(d.message.find("callable shader table"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "index"), "65537");
}

TEST(ShaderTable, IDX_9_EveryThreadSharesTheOneRayGenerationRecord) {
    Harness h;
    const auto sig = tagSignature();
    std::vector<uint32_t> tags(4, 0);
    h.library->addRayGeneration("RG_Tag", [&tags](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex();
        tags[i.y * 2 + i.x] = ctx.localRootConstants<uint32_t>(0);
    });
    h.stateObject.localRootSignatures.push_back({sig, {"RG_Tag"}});
    const auto so = h.pipeline();
    LocalRootArguments args(sig);
    args.setConstants(0, 77u);
    const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier("RG_Tag"), args).upload(h.device.memory());
    EXPECT_EQ(rg.SizeInBytes, 36u);
    h.device.dispatchRays(descWithRayGen(rg, uvec3(2, 2, 1)), so, nullptr);
    for (uint32_t t : tags) EXPECT_EQ(t, 77u);
}

TEST(ShaderTable, IDX_9_RayGenerationRecordMustCoverItsArguments) {
    Harness h;
    const auto sig = tagSignature();
    h.library->addRayGeneration("RG_Tag", [](ShaderContext&) {});
    h.stateObject.localRootSignatures.push_back({sig, {"RG_Tag"}});
    const auto so = h.pipeline();
    LocalRootArguments args(sig);
    args.setConstants(0, 77u);
    const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier("RG_Tag"), args).upload(h.device.memory());
    auto desc = descWithRayGen(rg);
    desc.RayGenerationShaderRecord.SizeInBytes = 32;  // identifier only; the layout needs 36
    const Diagnostic d = expectDxrError("IDX-9", [&] { h.device.dispatchRays(desc, so, nullptr); });
    EXPECT_EQ(findValue(d, "SizeInBytes") ? findValue(d, "SizeInBytes")->limit : "", ">= 36");

    desc.RayGenerationShaderRecord.SizeInBytes = 16;  // not even an identifier
    expectDxrError("IDX-9", [&] { h.device.dispatchRays(desc, so, nullptr); });
}

TEST(ShaderTable, IDX_10_StrideZeroResolvesEveryIndexToTheFirstRecord) {
    // R = 3, M = 4, G = 2, C = 5 -> I = 16, but stride 0 -> record 0.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 3;
    args.multiplier = 4;
    h.addTracingRayGen(hitRay, args, results);
    buildThreeGeometryScene(h, 5);
    const auto so = h.pipeline();
    const auto hit = tagTable(h, so, sig, "HG_Tag", 1, 300, /*stride*/ 0);
    EXPECT_EQ(hit.StrideInBytes, 0u);
    EXPECT_EQ(hit.SizeInBytes, 36u);
    const DispatchResult r = h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1, 900), hit);
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(results[0].tag, 300u);
    EXPECT_TRUE(r.diagnostics.errors().empty());
    EXPECT_EQ(recordAddress(hit, 16), hit.StartAddress);
}

TEST(ShaderTable, IDX_10_StrideSmallerThanTheRecordIsAnError) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const auto hit = tagTable(h, so, sig, "HG_Tag", 2, 100, /*stride*/ 32);  // records are 36 bytes
    const Diagnostic d = expectDxrError("IDX-10", [&] { h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1), hit); });
    EXPECT_NE(d.message.find("stride is smaller than the record of 'HG_Tag'"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "stride"), "32");
    EXPECT_EQ(valueOf(d, "record bytes (REC-5)"), "36");
}

TEST(ShaderTable, IDX_11_IndexPastTheTableEndNamesEveryTerm) {
    // Only launch (2,1) of 3x2 hits; R = 3, M = 4, G = 2, C = 5 -> I = 16 in a 4-record table.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(6);
    Harness::TraceArgs args;
    args.rayContribution = 3;
    args.multiplier = 4;
    h.addTracingRayGen([](uvec3 i) { return i.x == 2 && i.y == 1 ? hitRay() : missRay(); }, args, results);
    buildThreeGeometryScene(h, 5);
    const auto so = h.pipeline();
    const auto hit = tagTable(h, so, sig, "HG_Tag", 4);
    ASSERT_EQ(hit.StrideInBytes, 64u);
    ASSERT_EQ(hit.SizeInBytes, 3u * 64u + 36u);
    const Diagnostic d = expectDxrError("IDX-11", [&] {
        h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1), hit, uvec3(3, 2, 1));
    });
    EXPECT_NE(d.message.find("hit-group table"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "I = R + M*G + C"), "3 + 4*2 + 5 = 16");
    EXPECT_EQ(valueOf(d, "index"), "16");
    EXPECT_EQ(valueOf(d, "stride"), "64");
    ASSERT_NE(findValue(d, "record offset + 32"), nullptr);
    EXPECT_EQ(valueOf(d, "record offset + 32"), std::to_string(16 * 64 + 32));
    EXPECT_EQ(findValue(d, "record offset + 32")->limit, "SizeInBytes 228");
    EXPECT_EQ(valueOf(d, "InstanceIndex"), "1");
    EXPECT_EQ(valueOf(d, "GeometryIndex"), "2");
    EXPECT_EQ(valueOf(d, "PrimitiveIndex"), "0");
    ASSERT_TRUE(d.site.has_value());
    EXPECT_EQ(d.site->launchIndex.x, 2u);
    EXPECT_EQ(d.site->launchIndex.y, 1u);
    EXPECT_EQ(d.site->launchIndex.z, 0u);
    // The lookup belongs to the TraceRay call made by the ray generation shader.
    EXPECT_EQ(d.site->depth, 0u);
    EXPECT_EQ(d.site->stage, ShaderStage::RayGeneration);
    EXPECT_EQ(d.site->exportName, "RG");
}

TEST(ShaderTable, IDX_11_RecordArgumentsPastTheTableEnd) {
    // Record 1's identifier lies inside SizeInBytes, its local argument does not.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 1;
    h.addTracingRayGen(hitRay, args, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    auto hit = tagTable(h, so, sig, "HG_Tag", 2);
    hit.SizeInBytes = 64 + 32;
    const Diagnostic d = expectDxrError("IDX-11", [&] { h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1), hit); });
    EXPECT_NE(d.message.find("the record of 'HG_Tag' does not fit in the hit-group table"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "record offset"), "64");
    EXPECT_EQ(valueOf(d, "record bytes (REC-5)"), "36");
    EXPECT_EQ(valueOf(d, "SizeInBytes"), "96");
}

TEST(ShaderTable, IDX_11_ContinueModeRecordsTheErrorAndSkipsTheRecord) {
    // GEN-1 "continue" fallback: the failed lookup acts as a NULL record, so the hit commits
    // without a CHS; every launch's error folds into one record.
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(4);
    Harness::TraceArgs args;
    args.rayContribution = 2;
    h.addTracingRayGen(hitRay, args, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    DispatchOptions options;
    options.onError = OnError::Continue;
    DispatchResult r;
    ASSERT_NO_THROW(r = h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tri"}), uvec3(2, 2, 1), options));
    for (const Probe& p : results) {
        EXPECT_EQ(p.closestHits, 0u);
        EXPECT_EQ(p.misses, 0u);
    }
    const auto errors = r.diagnostics.errors();
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_EQ(errors[0].ruleId, "IDX-11");
    EXPECT_EQ(errors[0].count, 4u);
    ASSERT_TRUE(errors[0].site.has_value());
    EXPECT_EQ(errors[0].site->launchIndex.x, 0u);
    EXPECT_EQ(errors[0].site->launchIndex.y, 0u);
}

TEST(ShaderTable, IDX_11_MissIndexPastTheTableEnd) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.missIndex = 3;
    h.addTracingRayGen(missRay, args, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-11", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe", "Miss_Probe"}), h.table(so, {"HG_Tri"}));
    });
    EXPECT_NE(d.message.find("miss shader table"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "index"), "3");
}

TEST(ShaderTable, IDX_11_MissingHitGroupTable) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-11", [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), {}); });
    EXPECT_NE(d.message.find("hit-group table is missing"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "I = R + M*G + C"), "0 + 1*0 + 0 = 0");
}

TEST(ShaderTable, IDX_11_MissingMissTable) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(missRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-11", [&] { h.dispatch(so, {}, h.table(so, {"HG_Tri"})); });
    EXPECT_NE(d.message.find("miss shader table is missing"), std::string::npos) << d.message;
}

TEST(ShaderTable, IDX_11_UninitializedRecord) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 1;
    h.addTracingRayGen(hitRay, args, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    // Record 0 written, record 1 never written.
    const GpuVirtualAddress base = h.device.memory().allocate(128, "half-written table");
    const ShaderIdentifier id = so->shaderIdentifier("HG_Tri");
    h.device.memory().write(base, id.data(), id.size());
    const Diagnostic d = expectDxrError("IDX-11", [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), {base, 128, 64}); });
    EXPECT_NE(d.message.find("never written"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "index"), "1");
}

TEST(ShaderTable, IDX_12_NoLookupWhenNoShaderNeedsTheRecord) {
    // Opaque triangle + SKIP_CLOSEST_HIT_SHADER: no AHS, no CHS, so neither a too-short table
    // (I = 5 in one record) nor a missing one is an error.
    for (bool missing : {false, true}) {
        Harness h;
        h.addProbeShaders();
        std::vector<Probe> results(1);
        Harness::TraceArgs args;
        args.flags = RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
        args.rayContribution = 5;
        h.addTracingRayGen(hitRay, args, results);
        buildOneTriangleScene(h, 0, GEOMETRY_FLAG_OPAQUE);
        const auto so = h.pipeline();
        const auto hit = missing ? GpuVirtualAddressRangeAndStride{} : h.table(so, {"HG_Tri"});
        DispatchResult r;
        ASSERT_NO_THROW(r = h.dispatch(so, h.table(so, {"Miss_Probe"}), hit)) << "missing=" << missing;
        EXPECT_TRUE(r.diagnostics.errors().empty());
        EXPECT_EQ(results[0].closestHits, 0u);
        EXPECT_EQ(results[0].misses, 0u);  // the hit was committed
    }
}

TEST(ShaderTable, IDX_12_NonOpaqueTriangleNeedsItsRecordForTheAnyHit) {
    // The same trace on a non-opaque triangle needs the record (its AHS may run).
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.flags = RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    args.rayContribution = 5;
    h.addTracingRayGen(hitRay, args, results);
    buildOneTriangleScene(h, 0, GEOMETRY_FLAG_NONE);
    const auto so = h.pipeline();
    expectDxrError("IDX-11", [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_TriAH"})); });
}

TEST(ShaderTable, IDX_13_MissShaderInTheHitGroupTable) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-13", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"Miss_Probe"}));
    });
    EXPECT_NE(d.message.find("hit-group table record holds miss shader 'Miss_Probe'"), std::string::npos) << d.message;
}

TEST(ShaderTable, IDX_13_HitGroupInTheMissTable) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(missRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-13", [&] {
        h.dispatch(so, h.table(so, {"HG_Tri"}), h.table(so, {"HG_Tri"}));
    });
    EXPECT_NE(d.message.find("miss shader table record holds hit group 'HG_Tri'"), std::string::npos) << d.message;
}

TEST(ShaderTable, IDX_13_MissShaderAsTheRayGenerationRecord) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(missRay, {}, results);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-13", [&] {
        h.dispatch(so, {}, {}, uvec3(1u), {}, nullptr, {}, "Miss_Probe");
    });
    EXPECT_NE(d.message.find("ray generation record"), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("holds miss shader 'Miss_Probe'"), std::string::npos) << d.message;
}

TEST(ShaderTable, IDX_13_RayGenerationShaderInTheCallableTable) {
    Harness h;
    h.addProbeShaders();
    h.library->addRayGeneration("RG", [](ShaderContext& ctx) {
        CallParams c;
        ctx.CallShader(0, c);
    });
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-13", [&] {
        h.dispatch(so, {}, {}, uvec3(1u), {}, nullptr, h.table(so, {"RG"}));
    });
    EXPECT_NE(d.message.find("callable shader table record holds ray generation shader 'RG'"), std::string::npos)
        << d.message;
}

TEST(ShaderTable, IDX_14_ProceduralHitGroupOnTriangles) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-14", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Box"}));
    });
    EXPECT_NE(d.message.find("hit group 'HG_Box' (procedural) was selected for triangle geometry"), std::string::npos)
        << d.message;
    EXPECT_EQ(valueOf(d, "GeometryIndex"), "0");
}

TEST(ShaderTable, IDX_14_TriangleHitGroupOnAABBs) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    const auto box = h.blas({h.aabbs({unitBox()})});
    h.tlas({Harness::instance(box, 0)});
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("IDX-14", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tri"}));
    });
    EXPECT_NE(d.message.find("hit group 'HG_Tri' (triangle) was selected for AABB geometry"), std::string::npos)
        << d.message;
}

// ---------------------------------------------------------------------------------------
// REC: records and tables.

RootSignaturePtr rec5Signature() {
    // [4 constants][table][1 constant][root SRV]
    return RootSignature::create({"REC5",
                                  {RootParameter::constants(4, 0), RootParameter::table({{DescriptorRangeType::SRV, 1, 0}}),
                                   RootParameter::constants(1, 1), RootParameter::srv(1)},
                                  ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
}

TEST(ShaderTable, REC_5_ExampleLayoutOffsets) {
    const auto sig = rec5Signature();
    EXPECT_EQ(sig->argumentOffset(0), 32u);
    EXPECT_EQ(sig->argumentOffset(1), 48u);
    EXPECT_EQ(sig->argumentOffset(2), 56u);
    EXPECT_EQ(sig->argumentOffset(3), 64u);
    EXPECT_EQ(sig->argumentSize(0), 16u);
    EXPECT_EQ(sig->argumentSize(1), 8u);  // REC-6: a local descriptor table is a full 8-byte handle
    EXPECT_EQ(sig->argumentSize(2), 4u);
    EXPECT_EQ(sig->argumentSize(3), 8u);
    EXPECT_EQ(sig->recordSize(), 72u);
    ShaderTableBuilder builder("rec5");
    builder.addRecord(ShaderIdentifier{}, LocalRootArguments(sig));
    EXPECT_EQ(builder.naturalStride(), 96u);  // the smallest legal stride
}

TEST(ShaderTable, REC_5_ConstantsPackWithoutPadding) {
    // [1 constant][2 constants][CBV][1 constant]: 32, 36, 48 (8-aligned), 56; record 60.
    const auto sig = RootSignature::create({"Packed",
                                            {RootParameter::constants(1, 0), RootParameter::constants(2, 1),
                                             RootParameter::cbv(2), RootParameter::constants(1, 3)},
                                            ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
    EXPECT_EQ(sig->argumentOffset(0), 32u);
    EXPECT_EQ(sig->argumentOffset(1), 36u);
    EXPECT_EQ(sig->argumentOffset(2), 48u);
    EXPECT_EQ(sig->argumentOffset(3), 56u);
    EXPECT_EQ(sig->recordSize(), 60u);
}

TEST(ShaderTable, REC_1_IdentifierAtOffsetZeroArgumentsFrom32) {
    Harness h;
    h.addProbeShaders();
    const auto sig = rec5Signature();
    struct Seen {
        std::array<uint32_t, 4> c4{};
        uint64_t table = 0;
        uint32_t c1 = 0;
        uint64_t srv = 0;
    } seen;
    h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Rec5", [&seen](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
            p.closestHits++;
            seen.c4 = ctx.localRootConstants<std::array<uint32_t, 4>>(0);
            seen.table = ctx.localRootDescriptor(1);
            seen.c1 = ctx.localRootConstants<uint32_t>(2);
            seen.srv = ctx.localRootDescriptor(3);
        });
    h.stateObject.hitGroups.push_back({"HG_Rec5", HitGroupType::Triangles, "", "CH_Rec5", ""});
    h.stateObject.localRootSignatures.push_back({sig, {"HG_Rec5"}});
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();

    LocalRootArguments args(sig);
    const std::array<uint32_t, 4> c4{11, 22, 33, 44};
    args.setConstants(0, c4).setDescriptor(1, 0x1122334455667788ull).setConstants(2, 55u).setDescriptor(3, 0xAABBCCDD00ull);
    const ShaderIdentifier id = so->shaderIdentifier("HG_Rec5");
    const auto hit = ShaderTableBuilder("rec5").addRecord(id, args).upload(h.device.memory());
    EXPECT_EQ(hit.StrideInBytes, 96u);

    // The bytes in GPU memory.
    const uint8_t* bytes = h.device.memory().read(hit.StartAddress, 72, "test");
    EXPECT_EQ(std::memcmp(bytes, id.data(), 32), 0);
    uint32_t u32 = 0;
    uint64_t u64 = 0;
    std::memcpy(&u32, bytes + 32, 4);
    EXPECT_EQ(u32, 11u);
    std::memcpy(&u32, bytes + 44, 4);
    EXPECT_EQ(u32, 44u);
    std::memcpy(&u64, bytes + 48, 8);
    EXPECT_EQ(u64, 0x1122334455667788ull);
    std::memcpy(&u32, bytes + 56, 4);
    EXPECT_EQ(u32, 55u);
    std::memcpy(&u64, bytes + 64, 8);
    EXPECT_EQ(u64, 0xAABBCCDD00ull);
    EXPECT_FALSE(h.device.memory().isWritten(hit.StartAddress + 60, 4));  // padding stays unwritten

    // What the shader reads.
    h.dispatch(so, h.table(so, {"Miss_Probe"}), hit);
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(seen.c4, c4);
    EXPECT_EQ(seen.table, 0x1122334455667788ull);
    EXPECT_EQ(seen.c1, 55u);
    EXPECT_EQ(seen.srv, 0xAABBCCDD00ull);
}

TEST(ShaderTable, REC_2_MisalignedTableStartIsRefusedBeforeAnyThread) {
    Harness h;
    h.addProbeShaders();
    std::atomic<int> ran{0};
    h.library->addRayGeneration("RG", [&ran](ShaderContext&) { ran++; });
    const auto so = h.pipeline();
    auto hit = h.table(so, {"HG_Tri", "HG_Tri"});
    hit.StartAddress += 32;  // still inside the buffer, a multiple of 32 but not of 64
    hit.SizeInBytes -= 32;
    const Diagnostic d = expectDxrError("REC-2", [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), hit, uvec3(4, 4, 1)); });
    EXPECT_NE(d.message.find("HitGroupTable StartAddress is not a multiple of 64"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "StartAddress % 64"), "32");
    EXPECT_EQ(ran.load(), 0);

    auto miss = h.table(so, {"Miss_Probe", "Miss_Probe"});
    miss.StartAddress += 32;
    miss.SizeInBytes -= 32;
    expectDxrError("REC-2", [&] { h.dispatch(so, miss, {}, uvec3(4, 4, 1)); });
    auto callable = h.table(so, {"Miss_Probe", "Miss_Probe"});
    callable.StartAddress += 32;
    callable.SizeInBytes -= 32;
    expectDxrError("REC-2", [&] { h.dispatch(so, {}, {}, uvec3(4, 4, 1), {}, nullptr, callable); });
    EXPECT_EQ(ran.load(), 0);
}

TEST(ShaderTable, REC_2_MisalignedRayGenerationRecordIsRefused) {
    Harness h;
    std::atomic<int> ran{0};
    h.library->addRayGeneration("RG", [&ran](ShaderContext&) { ran++; });
    const auto so = h.pipeline();
    const ShaderIdentifier id = so->shaderIdentifier("RG");
    const auto rg = ShaderTableBuilder("raygen").addRecord(ShaderIdentifier{}).addRecord(id).upload(h.device.memory(), 32);
    auto desc = descWithRayGen({rg.StartAddress + 32, 32, 0});
    const Diagnostic d = expectDxrError("REC-2", [&] { h.device.dispatchRays(desc, so, nullptr); });
    EXPECT_NE(d.message.find("RayGenerationShaderRecord"), std::string::npos) << d.message;
    EXPECT_EQ(ran.load(), 0);
}

TEST(ShaderTable, REC_3_StrideMustBeAMultipleOf32AtMost4096) {
    Harness h;
    h.addProbeShaders();
    std::atomic<int> ran{0};
    h.library->addRayGeneration("RG", [&ran](ShaderContext&) { ran++; });
    const auto so = h.pipeline();
    for (uint64_t stride : {48ull, 16ull, 4128ull, 8192ull}) {
        auto hit = h.table(so, {"HG_Tri", "HG_Tri"}, {}, stride);
        const Diagnostic d = expectDxrError("REC-3", [&] { h.dispatch(so, {}, hit, uvec3(2, 2, 1)); });
        EXPECT_EQ(valueOf(d, "StrideInBytes"), std::to_string(stride));
        EXPECT_NE(d.message.find("multiple of 32 in [0, 4096]"), std::string::npos) << d.message;
    }
    auto miss = h.table(so, {"Miss_Probe", "Miss_Probe"}, {}, 96 + 8);
    expectDxrError("REC-3", [&] { h.dispatch(so, miss, {}, uvec3(2, 2, 1)); });
    EXPECT_EQ(ran.load(), 0);
}

TEST(ShaderTable, REC_3_Stride4096IsLegal) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.rayContribution = 1;
    h.addTracingRayGen(hitRay, args, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1), tagTable(h, so, sig, "HG_Tag", 2, 100, kMaxShaderRecordStride));
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(results[0].tag, 101u);
}

TEST(ShaderTable, REC_4_LocalArgumentsAtMost4064Bytes) {
    const auto ok = RootSignature::create({"Max", {RootParameter::constants(1016, 0)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
    EXPECT_EQ(ok->recordSize(), 4096u);
    const Diagnostic d = expectDxrError("REC-4", [] {
        RootSignature::create({"TooBig", {RootParameter::constants(1017, 0)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
    });
    EXPECT_NE(d.message.find("'TooBig'"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "argument bytes"), "4068");
    EXPECT_EQ(findValue(d, "argument bytes") ? findValue(d, "argument bytes")->limit : "", "4064");
    // Padding counts too: 1014 constants + an 8-byte argument = 4056 + 8 -> 4064 exactly,
    // 1015 constants + an 8-byte argument = 4060 + 4 padding + 8 -> 4072.
    EXPECT_NO_THROW(RootSignature::create(
        {"Edge", {RootParameter::constants(1014, 0), RootParameter::cbv(1)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE}));
    expectDxrError("REC-4", [] {
        RootSignature::create(
            {"Padded", {RootParameter::constants(1015, 0), RootParameter::cbv(1)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
    });
}

TEST(ShaderTable, REC_7_ReadingAnUnsetLocalArgumentIsAnError) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    LocalRootArguments unset(sig);  // parameter 0 never set
    const auto hit = h.table(so, {"HG_Tag"}, {&unset});
    const Diagnostic d = expectDxrError("REC-7", [&] { h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1), hit); });
    EXPECT_NE(d.message.find("local root parameter 0 of 'Tag', whose bytes were never written"), std::string::npos)
        << d.message;
    ASSERT_TRUE(d.site.has_value());
    EXPECT_EQ(d.site->stage, ShaderStage::ClosestHit);
    EXPECT_EQ(d.site->exportName, "CH_Tag");
    EXPECT_EQ(d.site->depth, 1u);
}

TEST(ShaderTable, REC_7_UnreadArgumentsNeedNotBeSet) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    // HG_Tri's CHS never reads its arguments; the record carries an unset one.
    h.stateObject.localRootSignatures.push_back({sig, {"HG_Tri"}});
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    LocalRootArguments unset(sig);
    const DispatchResult r = h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tri"}, {&unset}));
    EXPECT_EQ(results[0].closestHits, 1u);
    EXPECT_TRUE(r.diagnostics.errors().empty());
}

TEST(ShaderTable, REC_8_NullHitGroupCommitsWithoutRunningAnything) {
    // A non-opaque triangle with a NULL record: no AHS, no CHS, but the hit commits (no miss).
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h, 0, GEOMETRY_FLAG_NONE);
    const auto so = h.pipeline();
    const DispatchResult r = h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {""}));
    EXPECT_EQ(results[0].closestHits, 0u);
    EXPECT_EQ(results[0].anyHits, 0u);
    EXPECT_EQ(results[0].misses, 0u);
    EXPECT_TRUE(r.diagnostics.errors().empty());
    EXPECT_EQ(r.stats.invocationsOf(ShaderStage::AnyHit), 0u);
    EXPECT_EQ(r.stats.invocationsOf(ShaderStage::ClosestHit), 0u);
    EXPECT_EQ(r.stats.invocationsOf(ShaderStage::Miss), 0u);
}

TEST(ShaderTable, REC_8_NullHitGroupOnAABBsRunsNoIntersectionShader) {
    // No IS means no hit: the ray misses (OPQ-4).
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    const auto box = h.blas({h.aabbs({unitBox()})});
    h.tlas({Harness::instance(box, 0)});
    const auto so = h.pipeline();
    const DispatchResult r = h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {""}));
    EXPECT_EQ(results[0].closestHits, 0u);
    EXPECT_EQ(results[0].misses, 1u);
    EXPECT_EQ(r.stats.invocationsOf(ShaderStage::Intersection), 0u);
}

TEST(ShaderTable, REC_8_NullMissRunsNothing) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(missRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const DispatchResult r = h.dispatch(so, h.table(so, {""}), h.table(so, {"HG_Tri"}));
    EXPECT_EQ(results[0].misses, 0u);
    EXPECT_FLOAT_EQ(results[0].t, -1.0f);  // payload unchanged
    EXPECT_EQ(r.stats.invocationsOf(ShaderStage::Miss), 0u);
    EXPECT_TRUE(r.diagnostics.errors().empty());
}

TEST(ShaderTable, REC_8_NullCallableLeavesParametersUnchanged) {
    Harness h;
    CallParams got{42, 7};
    h.library->addRayGeneration("RG", [&got](ShaderContext& ctx) { ctx.CallShader(0, got); });
    const auto so = h.pipeline();
    h.dispatch(so, {}, {}, uvec3(1u), {}, nullptr, h.table(so, {""}));
    EXPECT_EQ(got.tag, 42u);
    EXPECT_EQ(got.calls, 7u);
}

TEST(ShaderTable, REC_8_NullRayGenerationDoesNothing) {
    Harness h;
    std::atomic<int> ran{0};
    h.library->addRayGeneration("RG", [&ran](ShaderContext&) { ran++; });
    const auto so = h.pipeline();
    const auto rg = ShaderTableBuilder("null raygen").addRecord(ShaderIdentifier{}).upload(h.device.memory());
    const DispatchResult r = h.device.dispatchRays(descWithRayGen(rg, uvec3(4, 4, 1)), so, nullptr);
    EXPECT_EQ(ran.load(), 0);
    EXPECT_TRUE(r.diagnostics.empty());
}

TEST(ShaderTable, REC_8_GarbageIdentifierIsAnError) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(missRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    ShaderIdentifier garbage{};
    garbage[5] = 0x5A;
    const auto miss = ShaderTableBuilder("garbage").addRecord(garbage).upload(h.device.memory());
    const Diagnostic d = expectDxrError("REC-8", [&] { h.dispatch(so, miss, h.table(so, {"HG_Tri"})); });
    EXPECT_NE(d.message.find("not an export of the bound state object 'test'"), std::string::npos) << d.message;
}

TEST(ShaderTable, REC_9_IntersectionExportHasNoIdentifier) {
    Harness h;
    h.addProbeShaders();
    const auto so = h.pipeline();
    EXPECT_EQ(so->GetShaderIdentifier("IS_Box"), nullptr);
    EXPECT_EQ(so->GetShaderIdentifier("CH_Probe"), nullptr);
    EXPECT_EQ(so->GetShaderIdentifier("AH_Probe"), nullptr);
    EXPECT_EQ(so->GetShaderIdentifier("NoSuchExport"), nullptr);
    EXPECT_NE(so->GetShaderIdentifier("HG_Box"), nullptr);
    EXPECT_NE(so->GetShaderIdentifier("Miss_Probe"), nullptr);
    try {
        so->shaderIdentifier("IS_Box");
        ADD_FAILURE() << "shaderIdentifier(\"IS_Box\") did not throw";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("'IS_Box' is a intersection shader: it has no shader identifier"), std::string::npos) << m;
        EXPECT_NE(m.find("REC-9"), std::string::npos) << m;
    }
}

TEST(ShaderTable, REC_10_IdentifiersDifferAcrossStateObjectsAndForeignOnesAreDiagnosed) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    h.stateObject.name = "first";
    const auto first = h.pipeline();
    h.stateObject.name = "second";
    const auto second = h.pipeline();
    EXPECT_NE(first->familyId(), second->familyId());
    for (const char* name : {"RG", "HG_Tri", "HG_Box", "Miss_Probe"})
        EXPECT_NE(first->shaderIdentifier(name), second->shaderIdentifier(name)) << name;
    // Within one state object every identifier is distinct too.
    EXPECT_NE(first->shaderIdentifier("HG_Tri"), first->shaderIdentifier("HG_TriAH"));

    // A table made from 'first' used with 'second' bound.
    const auto foreign = h.table(first, {"HG_Tri"});
    const Diagnostic d = expectDxrError("REC-8", [&] { h.dispatch(second, h.table(second, {"Miss_Probe"}), foreign); });
    EXPECT_NE(d.message.find("bound state object 'second'"), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("'HG_Tri' of state object 'first'"), std::string::npos) << d.message;
}

TEST(ShaderTable, REC_11_TypedAccessorMismatch) {
    Harness h;
    h.addProbeShaders();
    const auto sig = RootSignature::create(
        {"TwoConstants", {RootParameter::constants(2, 0), RootParameter::cbv(1)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
    int mode = 0;
    h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Wrong", [&mode](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
            if (mode == 0) p.tag = ctx.localRootConstants<uint32_t>(0);                 // 4 bytes of an 8-byte parameter
            if (mode == 1) p.tag = uint32_t(ctx.localRootDescriptor(0));                // constants read as a descriptor
            if (mode == 2) p.tag = ctx.localRootConstants<uint32_t>(1);                 // a CBV read as constants
            if (mode == 3) p.tag = ctx.localRootConstants<uint32_t>(2);                 // no such parameter
            if (mode == 4) p.tag = uint32_t(ctx.localRootConstants<uint64_t>(0) >> 32);  // correct
        });
    h.stateObject.hitGroups.push_back({"HG_Wrong", HitGroupType::Triangles, "", "CH_Wrong", ""});
    h.stateObject.localRootSignatures.push_back({sig, {"HG_Wrong"}});
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    LocalRootArguments args(sig);
    args.setConstants(0, uint64_t(0x0000000900000008ull)).setDescriptor(1, 0x1000);
    const auto miss = h.table(so, {"Miss_Probe"});
    const auto hit = h.table(so, {"HG_Wrong"}, {&args});

    const char* expected[4] = {"is root constants (8 bytes); the shader reads it as unsigned int (4 bytes)",
                               "is root constants (8 bytes); the shader reads it as a descriptor",
                               "is root CBV; the shader reads it as unsigned int (4 bytes)",
                               "has 2 parameters; the shader reads parameter 2"};
    for (mode = 0; mode < 4; ++mode) {
        const Diagnostic d = expectDxrError("REC-11", [&] { h.dispatch(so, miss, hit); });
        EXPECT_NE(d.message.find(expected[mode]), std::string::npos) << "mode " << mode << ": " << d.message;
    }
    mode = 4;
    h.dispatch(so, miss, hit);
    EXPECT_EQ(results[0].tag, 9u);
}

TEST(ShaderTable, REC_11_ShaderWithoutLocalSignatureReadsArguments) {
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    h.stateObject.localRootSignatures.clear();  // CH_Tag now has no local root signature
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("REC-11", [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tag"})); });
    EXPECT_NE(d.message.find("but has no local root signature"), std::string::npos) << d.message;
}

TEST(ShaderTable, REC_11_StrideZeroTableTooSmallForTheLayout) {
    // Stride 0: the bytes available are SizeInBytes - offset = 32, the layout needs 36.
    Harness h;
    h.addProbeShaders();
    const auto sig = tagSignature();
    addTagShaders(h, sig);
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    auto hit = tagTable(h, so, sig, "HG_Tag", 1, 100, 0);
    hit.SizeInBytes = 32;
    const Diagnostic d = expectDxrError("REC-11", [&] { h.dispatch(so, tagTable(h, so, sig, "Miss_Tag", 1), hit); });
    EXPECT_NE(d.message.find("the record of 'HG_Tag' does not fit in the hit-group table"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "record bytes (REC-5)"), "36");
}

TEST(ShaderTable, REC_12_WritingALockedTableDuringADispatch) {
    Harness h;
    h.addProbeShaders();
    GpuVirtualAddress hitTable = 0;
    h.library->addRayGeneration("RG", [&](ShaderContext&) {
        const ShaderIdentifier zero{};
        h.device.memory().write(hitTable, zero.data(), zero.size());
    });
    const auto so = h.pipeline();
    const auto hit = h.table(so, {"HG_Tri"});
    hitTable = hit.StartAddress;
    const Diagnostic d = expectDxrError("REC-12", [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), hit); });
    EXPECT_NE(d.message.find("written while a dispatch that uses it is executing"), std::string::npos) << d.message;
    // The table is unchanged, and unlocked again afterwards.
    const ShaderIdentifier id = so->shaderIdentifier("HG_Tri");
    EXPECT_EQ(std::memcmp(h.device.memory().read(hitTable, 32, "test"), id.data(), 32), 0);
    EXPECT_NO_THROW(h.device.memory().write(hitTable, id.data(), id.size()));
}

}  // namespace
}  // namespace refray::test
