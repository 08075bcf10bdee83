// Conformance tests for emulator/shader_table.cpp and the record lookups of the dispatcher:
// dxr-semantics.md section 2 (REC). Record indexing (section 1, IDX) is in shader_table_indexing_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstring>

#include "emulator/limits.h"
#include "harness.h"
#include "shader_table_rig.h"

namespace refray::test {
namespace {

using namespace shader_table_rig;

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
