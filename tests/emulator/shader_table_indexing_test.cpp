// Conformance tests for the record indexing of emulator/shader_table.cpp and the record lookups of the
// dispatcher: dxr-semantics.md section 1 (IDX).
#include <gtest/gtest.h>

#include "emulator/limits.h"
#include "harness.h"
#include "shader_table_rig.h"

namespace refray::test {
namespace {

using namespace shader_table_rig;

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

}  // namespace
}  // namespace refray::test
