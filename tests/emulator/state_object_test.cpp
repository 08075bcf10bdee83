// Conformance tests for emulator/state_object.cpp (and the root-signature rules it applies):
// dxr-semantics.md section 12 (PIPE, ASSOC) and section 13 (LIM-1).
#include <gtest/gtest.h>

#include <array>
#include <atomic>

#include "emulator/limits.h"
#include "harness.h"

namespace refray::test {
namespace {


// Runs `fn` expecting a refray::Error (any kind); returns its message.
std::string expectError(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a refray::Error, but nothing was thrown";
    return {};
}

RootSignaturePtr localSignature(const std::string& name, uint32_t shaderRegister = 0) {
    return RootSignature::create({name, {RootParameter::constants(1, shaderRegister)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
}

RootSignaturePtr globalSignature(const std::string& name, uint32_t shaderRegister = 0) {
    return RootSignature::create({name, {RootParameter::constants(1, shaderRegister)}, ROOT_SIGNATURE_FLAG_NONE});
}

std::vector<vec3> triangleAt(vec3 o) { return {o + vec3(-1, -1, 0), o + vec3(0, 1, 0), o + vec3(1, -1, 0)}; }
RayDesc hitRay(uvec3 = uvec3(0u)) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f}; }

void buildOneTriangleScene(Harness& h, uint32_t geometryFlags = GEOMETRY_FLAG_OPAQUE) {
    h.tlas({Harness::instance(h.blas({h.triangles(triangleAt({0, 0, 0}), geometryFlags)}), 0)});
}

struct Payload20 {
    float v[5];
};
struct Attributes16 {
    float v[4];
};
struct OtherPayload {
    uint32_t x = 0;
};
struct BigParameters {
    float v[32];  // 128 bytes
};

const ProgramEntry& entry(const StateObjectPtr& so, const std::string& name) {
    const ProgramEntry* e = so->findEntry(name);
    EXPECT_NE(e, nullptr) << name;
    static const ProgramEntry none;
    return e ? *e : none;
}

// ---------------------------------------------------------------------------------------
// LIM-1

TEST(StateObject, LIM_1_ConstantsMatchTheSpecTable) {
    EXPECT_EQ(kShaderIdentifierSizeInBytes, 32u);
    EXPECT_EQ(kShaderRecordByteAlignment, 32u);
    EXPECT_EQ(kShaderTableByteAlignment, 64u);
    EXPECT_EQ(kMaxShaderRecordStride, 4096u);
    EXPECT_EQ(kMaxAttributeSizeInBytes, 32u);
    EXPECT_EQ(kMaxDeclarableTraceRecursionDepth, 31u);
    EXPECT_EQ(kMaxRayGenerationShaderThreads, 1073741824ull);
    EXPECT_EQ(kAccelerationStructureByteAlignment, 256u);
    EXPECT_EQ(kInstanceDescsByteAlignment, 16u);
    EXPECT_EQ(kTransform3x4ByteAlignment, 16u);
    EXPECT_EQ(kAABBByteAlignment, 8u);
    EXPECT_EQ(kMaxGeometriesPerBottomLevelAS, 16777216ull);
    EXPECT_EQ(kMaxPrimitivesPerBottomLevelAS, 536870912ull);
    EXPECT_EQ(kMaxInstancesPerTopLevelAS, 16777216ull);
    // Derived: REC-4, and the field widths of IDX-2 / IDX-7.
    EXPECT_EQ(kMaxLocalRootArgumentBytes, 4064u);
    EXPECT_EQ(kRayContributionMask, 0xFu);
    EXPECT_EQ(kGeometryMultiplierMask, 0xFu);
    EXPECT_EQ(kMissShaderIndexMask, 0xFFFFu);
    EXPECT_EQ(kInstanceContributionMask, 0xFFFFFFu);
    EXPECT_EQ(sizeof(ShaderIdentifier), 32u);
}

// ---------------------------------------------------------------------------------------
// PIPE-1: shader config.

TEST(StateObject, PIPE_1_MismatchingShaderConfigCopiesAreRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.shaderConfigs = {{64, 32}, {64, 32}, {64, 16}};
    const Diagnostic d = expectDxrError("PIPE-1", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("state object 'test' has shader configs that differ"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "first"), "64/32");
    EXPECT_EQ(valueOf(d, "other"), "64/16");

    h.stateObject.shaderConfigs = {{64, 32}, {64, 32}};
    EXPECT_NO_THROW(h.pipeline());
}

TEST(StateObject, PIPE_1_MaxAttributeSizeAbove32IsRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.shaderConfigs = {{64, 36}};
    const Diagnostic d = expectDxrError("PIPE-1", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("MaxAttributeSizeInBytes is above the DXR maximum"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "MaxAttributeSizeInBytes"), "36");
    EXPECT_EQ(findValue(d, "MaxAttributeSizeInBytes") ? findValue(d, "MaxAttributeSizeInBytes")->limit : "", "32");
    h.stateObject.shaderConfigs = {{64, 32}};
    EXPECT_NO_THROW(h.pipeline());
}

TEST(StateObject, PIPE_1_PayloadLargerThanTheDeclaredMaximumIsRefused) {
    // PAY-2 names the rule: a payload struct larger than MaxPayloadSizeInBytes.
    Harness h;
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    h.library->addMiss<Payload20>("Miss20", [](ShaderContext&, Payload20&) {});
    h.stateObject.shaderConfigs = {{16, 8}};
    const Diagnostic d = expectDxrError("PAY-2", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("payload of export 'Miss20' is larger than MaxPayloadSizeInBytes"), std::string::npos)
        << d.message;
    EXPECT_EQ(valueOf(d, "payload bytes"), "20");
    EXPECT_EQ(findValue(d, "payload bytes") ? findValue(d, "payload bytes")->limit : "", "16");
    h.stateObject.shaderConfigs = {{20, 8}};  // exactly the size: legal
    EXPECT_NO_THROW(h.pipeline());
}

TEST(StateObject, PIPE_1_AttributesLargerThanTheDeclaredMaximumAreRefused) {
    // IS-5 at build: the IS reports 16-byte attributes, the config allows 8.
    Harness h;
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    h.library->addIntersection<Attributes16>("IS_Big", [](ShaderContext&) {});
    h.stateObject.shaderConfigs = {{64, 8}};
    const Diagnostic d = expectDxrError("IS-5", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("attributes of export 'IS_Big' are larger than MaxAttributeSizeInBytes"), std::string::npos)
        << d.message;
    EXPECT_EQ(valueOf(d, "attribute bytes"), "16");
    h.stateObject.shaderConfigs = {{64, 16}};
    EXPECT_NO_THROW(h.pipeline());
}

TEST(StateObject, PIPE_1_CallableParametersDoNotCountTowardThePayload) {
    Harness h;
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    h.library->addCallable<BigParameters>("CL_Big", [](ShaderContext&, BigParameters&) {});
    h.stateObject.shaderConfigs = {{4, 8}};
    StateObjectPtr so;
    ASSERT_NO_THROW(so = h.pipeline());
    EXPECT_EQ(so->shaderConfig().MaxPayloadSizeInBytes, 4u);
}

// ---------------------------------------------------------------------------------------
// PIPE-2: pipeline config.

TEST(StateObject, PIPE_2_RecursionDepthAbove31IsRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.pipelineConfigs = {{32, PIPELINE_FLAG_NONE}};
    const Diagnostic d = expectDxrError("PIPE-2", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("MaxTraceRecursionDepth is above the DXR maximum"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "MaxTraceRecursionDepth"), "32");
    h.stateObject.pipelineConfigs = {{31, PIPELINE_FLAG_NONE}};
    StateObjectPtr so;
    ASSERT_NO_THROW(so = h.pipeline());
    EXPECT_EQ(so->maxTraceRecursionDepth(), 31u);
    h.stateObject.pipelineConfigs = {{0, PIPELINE_FLAG_NONE}};
    EXPECT_NO_THROW(h.pipeline());
}

TEST(StateObject, PIPE_2_MismatchingPipelineConfigCopiesAreRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.pipelineConfigs = {{2, PIPELINE_FLAG_NONE}, {3, PIPELINE_FLAG_NONE}};
    const Diagnostic d = expectDxrError("PIPE-2", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("has pipeline configs that differ"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "first MaxTraceRecursionDepth"), "2");
    EXPECT_EQ(valueOf(d, "other MaxTraceRecursionDepth"), "3");

    h.stateObject.pipelineConfigs = {{2, PIPELINE_FLAG_NONE}, {2, PIPELINE_FLAG_SKIP_TRIANGLES}};
    expectDxrError("PIPE-2", [&] { h.pipeline(); });
}

// ---------------------------------------------------------------------------------------
// PIPE-3: pipeline flags.

TEST(StateObject, PIPE_3_SkipTrianglesPipelineMakesATriangleMissButRayFlagsHidesIt) {
    for (uint32_t pipelineFlags : {uint32_t(PIPELINE_FLAG_NONE), uint32_t(PIPELINE_FLAG_SKIP_TRIANGLES)}) {
        Harness h;
        h.addProbeShaders();
        h.library->addMiss<Probe>("Miss_Flags", [](ShaderContext& ctx, Probe& p) {
            p.misses++;
            p.tag = ctx.RayFlags();
        });
        std::vector<Probe> results(1);
        Harness::TraceArgs args;
        args.flags = RAY_FLAG_FORCE_OPAQUE;
        h.addTracingRayGen(hitRay, args, results);
        buildOneTriangleScene(h);
        h.stateObject.pipelineConfigs = {{1, pipelineFlags}};
        const auto so = h.pipeline();
        EXPECT_EQ(so->pipelineFlags(), pipelineFlags);
        h.dispatch(so, h.table(so, {"Miss_Flags"}), h.table(so, {"HG_Tri"}));
        if (pipelineFlags == PIPELINE_FLAG_NONE) {
            EXPECT_EQ(results[0].closestHits, 1u);
            EXPECT_EQ(results[0].misses, 0u);
        } else {
            EXPECT_EQ(results[0].closestHits, 0u);
            EXPECT_EQ(results[0].misses, 1u);
            EXPECT_EQ(results[0].tag, uint32_t(RAY_FLAG_FORCE_OPAQUE));  // no 0x100
        }
    }
}

TEST(StateObject, PIPE_3_SkipProceduralPipelineSkipsBoxesAndIsNotInRayFlags) {
    // A box in front of a triangle; the SKIP_PROCEDURAL_PRIMITIVES pipeline sees only the triangle.
    Harness h;
    h.addProbeShaders();
    h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Flags", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
            p.closestHits++;
            p.t = ctx.RayTCurrent();
            p.tag = ctx.RayFlags();
        });
    h.stateObject.hitGroups.push_back({"HG_Flags", HitGroupType::Triangles, "", "CH_Flags", ""});
    std::vector<Probe> results(1);
    Harness::TraceArgs args;
    args.flags = RAY_FLAG_FORCE_OPAQUE;
    h.addTracingRayGen(hitRay, args, results);
    const auto tri = h.blas({h.triangles(triangleAt({0, 0, 0}))});
    const auto box = h.blas({h.aabbs({unitBox()})});
    h.tlas({Harness::instance(tri, 0), Harness::instance(box, 1, Matrix3x4::translation({0, 0, -3}))});
    h.stateObject.pipelineConfigs = {{1, PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES}};
    const auto so = h.pipeline();
    h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Flags", "HG_Box"}));
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_FLOAT_EQ(results[0].t, 5.0f);
    EXPECT_EQ(results[0].tag, uint32_t(RAY_FLAG_FORCE_OPAQUE));  // no 0x200
}

TEST(StateObject, PIPE_3_UndefinedPipelineFlagBitsAreRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.pipelineConfigs = {{1, 0x1}};
    const Diagnostic d = expectDxrError("PIPE-3", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("undefined flag bits"), std::string::npos) << d.message;
}

// ---------------------------------------------------------------------------------------
// PIPE-4: hit groups.

TEST(StateObject, PIPE_4_TriangleHitGroupWithIntersectionShaderIsRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::Triangles, "", "CH_Probe", "IS_Box"});
    const Diagnostic d = expectDxrError("PIPE-4", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("triangle hit group 'HG_Bad' names an intersection shader 'IS_Box'"), std::string::npos)
        << d.message;
}

TEST(StateObject, PIPE_4_ProceduralHitGroupWithoutIntersectionShaderIsRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::ProceduralPrimitive, "", "CH_ProbeAABB", ""});
    const Diagnostic d = expectDxrError("PIPE-4", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("procedural hit group 'HG_Bad' has no intersection shader"), std::string::npos) << d.message;
}

TEST(StateObject, PIPE_4_UnknownImportSuggestsTheClosestName) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::Triangles, "", "CH_Prob", ""});
    const Diagnostic d = expectDxrError("PIPE-4", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("hit group 'HG_Bad' imports unknown export 'CH_Prob'"), std::string::npos) << d.message;
    EXPECT_NE(d.message.find("did you mean 'CH_Probe'?"), std::string::npos) << d.message;
}

TEST(StateObject, PIPE_4_ImportOfTheWrongStageIsRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::Triangles, "CH_Probe", "", ""});
    const Diagnostic d = expectDxrError("PIPE-4", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("imports 'CH_Probe' as anyhit but it is a closesthit shader"), std::string::npos) << d.message;
}

TEST(StateObject, PIPE_4_EmptySlotsAreLegal) {
    // AHS and CHS are optional: a procedural group with only an IS, a triangle group with nothing.
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_IsOnly", HitGroupType::ProceduralPrimitive, "", "", "IS_Box"});
    h.stateObject.hitGroups.push_back({"HG_Empty", HitGroupType::Triangles, "", "", ""});
    StateObjectPtr so;
    ASSERT_NO_THROW(so = h.pipeline());
    EXPECT_EQ(entry(so, "HG_IsOnly").hitGroupType, HitGroupType::ProceduralPrimitive);
    EXPECT_EQ(entry(so, "HG_IsOnly").closestHit, nullptr);
    EXPECT_NE(so->GetShaderIdentifier("HG_Empty"), nullptr);
}

TEST(StateObject, PIPE_4_ClosestHitAttributesMustMatchTheIntersectionShader) {
    // IS-5 at build: IS_Box reports ProbeAttributes, CH_Probe takes triangle attributes.
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::ProceduralPrimitive, "", "CH_Probe", "IS_Box"});
    const Diagnostic d = expectDxrError("IS-5", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("hit group 'HG_Bad': closesthit 'CH_Probe' takes attributes of another type"),
              std::string::npos)
        << d.message;
}

TEST(StateObject, PIPE_4_TriangleGroupNeedsBuiltInAttributes) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::Triangles, "", "CH_ProbeAABB", ""});
    const Diagnostic d = expectDxrError("IS-5", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("'CH_ProbeAABB' takes attributes of another type"), std::string::npos) << d.message;
}

TEST(StateObject, PIPE_4_AnyHitAndClosestHitPayloadsMustAgree) {
    Harness h;
    h.addProbeShaders();
    h.library->addAnyHit<OtherPayload, BuiltInTriangleIntersectionAttributes>(
        "AH_Other", [](ShaderContext&, OtherPayload&, const BuiltInTriangleIntersectionAttributes&) {});
    h.stateObject.hitGroups.push_back({"HG_Bad", HitGroupType::Triangles, "AH_Other", "CH_Probe", ""});
    const Diagnostic d = expectDxrError("PAY-1", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("hit group 'HG_Bad': any-hit and closest-hit shaders take different payload types"),
              std::string::npos)
        << d.message;
}

// ---------------------------------------------------------------------------------------
// PIPE-5: which exports have identifiers.

TEST(StateObject, PIPE_5_RayGenMissCallableAndHitGroupsHaveIdentifiers) {
    Harness h;
    h.addProbeShaders();
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    h.library->addCallable<BigParameters>("CL", [](ShaderContext&, BigParameters&) {});
    const auto so = h.pipeline();
    EXPECT_EQ(entry(so, "RG").kind, ProgramEntry::Kind::RayGeneration);
    EXPECT_EQ(entry(so, "Miss_Probe").kind, ProgramEntry::Kind::Miss);
    EXPECT_EQ(entry(so, "CL").kind, ProgramEntry::Kind::Callable);
    EXPECT_EQ(entry(so, "HG_Tri").kind, ProgramEntry::Kind::HitGroup);
    EXPECT_EQ(entry(so, "HG_Box").intersection, h.library->find("IS_Box"));
    EXPECT_EQ(so->findEntry("CH_Probe"), nullptr);
    EXPECT_EQ(so->findEntry("AH_Probe"), nullptr);
    EXPECT_EQ(so->findEntry("IS_Box"), nullptr);
    // 3 hit groups + RG + miss + callable.
    EXPECT_EQ(so->entries().size(), 6u);
}

TEST(StateObject, PIPE_5_UnknownExportIdentifierSuggestsTheClosestName) {
    // REC-9: an unresolved export has no identifier.
    Harness h;
    h.addProbeShaders();
    const auto so = h.pipeline();
    EXPECT_EQ(so->GetShaderIdentifier("HG_Tr"), nullptr);
    const std::string m = expectError([&] { so->shaderIdentifier("HG_Tr"); });
    EXPECT_NE(m.find("state object 'test' has no export 'HG_Tr'"), std::string::npos) << m;
    EXPECT_NE(m.find("did you mean 'HG_Tri'?"), std::string::npos) << m;
}

// ---------------------------------------------------------------------------------------
// PIPE-6: global root signatures at dispatch.

TEST(StateObject, PIPE_6_GlobalRootSignatureMismatchAtDispatch) {
    Harness h;
    const auto g1 = globalSignature("G1");
    const auto g2 = globalSignature("G2");
    std::atomic<uint32_t> seen{0};
    h.library->addRayGeneration("RG", [&seen](ShaderContext& ctx) { seen = ctx.globalRootConstants<uint32_t>(0); });
    h.stateObject.globalRootSignatures.push_back({g1, {"RG"}});
    const auto so = h.pipeline();
    EXPECT_EQ(entry(so, "RG").globalRootSignature, g1);

    Diagnostic d = expectDxrError("PIPE-6", [&] { h.dispatch(so, {}, {}); });
    EXPECT_NE(d.message.find("'RG' uses a global root signature other than the one bound"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "shader's"), "G1");
    EXPECT_EQ(valueOf(d, "bound"), "(none)");

    GlobalRootArguments wrong(g2);
    wrong.setConstants(0, 5u);
    d = expectDxrError("PIPE-6", [&] { h.dispatch(so, {}, {}, uvec3(1u), {}, &wrong); });
    EXPECT_EQ(valueOf(d, "bound"), "G2");

    GlobalRootArguments right(g1);
    right.setConstants(0, 17u);
    h.dispatch(so, {}, {}, uvec3(1u), {}, &right);
    EXPECT_EQ(seen.load(), 17u);
}

TEST(StateObject, PIPE_6_HitGroupGlobalRootSignatureIsChecked) {
    Harness h;
    h.addProbeShaders();
    const auto g1 = globalSignature("G1");
    const auto g2 = globalSignature("G2");
    h.stateObject.globalRootSignatures.push_back({g1, {"HG_Tri"}});
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    GlobalRootArguments wrong(g2);
    const Diagnostic d = expectDxrError("PIPE-6", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tri"}), uvec3(1u), {}, &wrong);
    });
    EXPECT_NE(d.message.find("'HG_Tri' uses a global root signature other than the one bound"), std::string::npos)
        << d.message;
    EXPECT_EQ(valueOf(d, "shader's"), "G1");
    EXPECT_EQ(valueOf(d, "bound"), "G2");
}

TEST(StateObject, PIPE_6_AnyHitOnlyHitGroupIsChecked) {
    // The group's AHS is reached in this DispatchRays, so its global root signature must be
    // the bound one, even though the group has no CHS.
    Harness h;
    h.addProbeShaders();
    const auto g1 = globalSignature("G1");
    const auto g2 = globalSignature("G2");
    h.stateObject.hitGroups.push_back({"HG_AhOnly", HitGroupType::Triangles, "AH_Probe", "", ""});
    h.stateObject.globalRootSignatures.push_back({g1, {"HG_AhOnly"}});
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h, GEOMETRY_FLAG_NONE);  // non-opaque: the AHS runs
    const auto so = h.pipeline();
    GlobalRootArguments wrong(g2);
    const Diagnostic d = expectDxrError("PIPE-6", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_AhOnly"}), uvec3(1u), {}, &wrong);
    });
    EXPECT_EQ(valueOf(d, "shader's"), "G1");
    EXPECT_EQ(valueOf(d, "bound"), "G2");
}

// ---------------------------------------------------------------------------------------
// PIPE-7: local root signatures.

TEST(StateObject, PIPE_7_LocalRootSignatureWithExtraFlagsIsRefused) {
    const Diagnostic d = expectDxrError("PIPE-7", [] {
        RootSignature::create({"Flagged", {RootParameter::constants(1, 0)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE | 0x1});
    });
    EXPECT_NE(d.message.find("local root signature 'Flagged' carries flags other than LOCAL_ROOT_SIGNATURE"),
              std::string::npos)
        << d.message;
    EXPECT_NE(findValue(d, "flags"), nullptr);
}

TEST(StateObject, PIPE_7_SignatureKindMustMatchItsUse) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.localRootSignatures.push_back({globalSignature("NotLocal"), {"Miss_Probe"}});
    Diagnostic d = expectDxrError("PIPE-7", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("'NotLocal' is used as a local root signature but is not flagged LOCAL_ROOT_SIGNATURE"),
              std::string::npos)
        << d.message;

    h.stateObject.localRootSignatures.clear();
    h.stateObject.globalRootSignatures.push_back({localSignature("IsLocal"), {"Miss_Probe"}});
    d = expectDxrError("PIPE-7", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("'IsLocal' is used as a global root signature but is flagged local"), std::string::npos)
        << d.message;
}

TEST(StateObject, PIPE_7_LocalSignatureBoundAsGlobalAtDispatchIsRefused) {
    Harness h;
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    const auto so = h.pipeline();
    GlobalRootArguments args(localSignature("L"));
    const Diagnostic d = expectDxrError("PIPE-7", [&] { h.dispatch(so, {}, {}, uvec3(1u), {}, &args); });
    EXPECT_NE(d.message.find("the root signature bound for the dispatch is a local root signature"), std::string::npos)
        << d.message;
}

TEST(StateObject, PIPE_7_LocalAndGlobalSignaturesMustNotShareRegisters) {
    // Both bind root constants to b0, space 0 for the same shader.
    Harness h;
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    h.stateObject.localRootSignatures.push_back({localSignature("L_b0", 0), {"RG"}});
    h.stateObject.globalRootSignatures.push_back({globalSignature("G_b0", 0), {"RG"}});
    const Diagnostic d = expectDxrError("PIPE-7", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("RG"), std::string::npos) << d.message;

    // Different registers are fine.
    h.stateObject.globalRootSignatures = {{globalSignature("G_b1", 1), {"RG"}}};
    EXPECT_NO_THROW(h.pipeline());
}

// ---------------------------------------------------------------------------------------
// ASSOC: associations.

TEST(StateObject, ASSOC_1_UnknownExportInAnAssociationIsRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.localRootSignatures.push_back({localSignature("L"), {"Miss_Prob"}});
    const Diagnostic d = expectDxrError("ASSOC-1", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("root signature 'L' is associated with unknown export 'Miss_Prob'"), std::string::npos)
        << d.message;
    EXPECT_NE(d.message.find("did you mean 'Miss_Probe'?"), std::string::npos) << d.message;
}

TEST(StateObject, ASSOC_1_UnknownLibraryExportSuggestsTheClosestName) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.libraries = {{h.library, {"CH_Probe", "Miss_Prob"}}};
    const std::string m = expectError([&] { StateObject::create(h.stateObject); });
    EXPECT_NE(m.find("the library has no export 'Miss_Prob'"), std::string::npos) << m;
    EXPECT_NE(m.find("did you mean 'Miss_Probe'?"), std::string::npos) << m;
}

TEST(StateObject, ASSOC_1_ExportSubsetLimitsTheStateObject) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.hitGroups.clear();
    h.stateObject.libraries = {{h.library, {"CH_Probe", "Miss_Probe"}}};
    StateObjectPtr so;
    ASSERT_NO_THROW(so = StateObject::create(h.stateObject));
    EXPECT_NE(so->GetShaderIdentifier("Miss_Probe"), nullptr);
    // IS_Box was not exported from the library subobject.
    h.stateObject.hitGroups.push_back({"HG_Box", HitGroupType::ProceduralPrimitive, "", "", "IS_Box"});
    expectDxrError("PIPE-4", [&] { StateObject::create(h.stateObject); });
}

TEST(StateObject, ASSOC_2_DefaultAssociationAppliesWhereNoExplicitOneExists) {
    Harness h;
    h.addProbeShaders();
    h.library->addRayGeneration("RG", [](ShaderContext&) {});
    const auto byDefault = localSignature("Default");
    const auto explicitOne = localSignature("Explicit");
    h.stateObject.localRootSignatures.push_back({byDefault, {}});  // empty list: default
    h.stateObject.localRootSignatures.push_back({explicitOne, {"Miss_Probe"}});
    const auto so = h.pipeline();
    EXPECT_EQ(entry(so, "RG").localRootSignature, byDefault);
    EXPECT_EQ(entry(so, "HG_Tri").localRootSignature, byDefault);
    EXPECT_EQ(entry(so, "HG_Box").localRootSignature, byDefault);
    EXPECT_EQ(entry(so, "Miss_Probe").localRootSignature, explicitOne);
}

TEST(StateObject, ASSOC_2_NoAssociationMeansNoLocalSignature) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.localRootSignatures.push_back({localSignature("OnlyMiss"), {"Miss_Probe"}});
    const auto so = h.pipeline();
    EXPECT_EQ(entry(so, "HG_Tri").localRootSignature, nullptr);
    EXPECT_NE(entry(so, "Miss_Probe").localRootSignature, nullptr);
}

TEST(StateObject, ASSOC_3_TwoExplicitLocalSignaturesOnOneExportAreRefused) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.localRootSignatures.push_back({localSignature("L1"), {"Miss_Probe"}});
    h.stateObject.localRootSignatures.push_back({localSignature("L2"), {"HG_Tri", "Miss_Probe"}});
    const Diagnostic d = expectDxrError("ASSOC-3", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("two different explicit local root signature associations on export 'Miss_Probe'"),
              std::string::npos)
        << d.message;
    EXPECT_EQ(valueOf(d, "first"), "L1");
    EXPECT_EQ(valueOf(d, "second"), "L2");
}

TEST(StateObject, ASSOC_3_TheSameSignatureTwiceIsNoConflict) {
    Harness h;
    h.addProbeShaders();
    const auto l = localSignature("L");
    h.stateObject.localRootSignatures.push_back({l, {"Miss_Probe"}});
    h.stateObject.localRootSignatures.push_back({l, {"Miss_Probe", "HG_Tri"}});
    StateObjectPtr so;
    ASSERT_NO_THROW(so = h.pipeline());
    EXPECT_EQ(entry(so, "Miss_Probe").localRootSignature, l);
}

TEST(StateObject, ASSOC_4_HitGroupAndComponentMustAgree) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.localRootSignatures.push_back({localSignature("OnGroup"), {"HG_Tri"}});
    h.stateObject.localRootSignatures.push_back({localSignature("OnComponent"), {"CH_Probe"}});
    const Diagnostic d = expectDxrError("ASSOC-4", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("hit group 'HG_Tri' would have two local root signatures"), std::string::npos) << d.message;
    EXPECT_EQ(valueOf(d, "hit group 'HG_Tri'"), "OnGroup");
    EXPECT_EQ(valueOf(d, "component 'CH_Probe'"), "OnComponent");
}

TEST(StateObject, ASSOC_4_ComponentsMustAgreeWhenTheGroupHasNone) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.localRootSignatures.push_back({localSignature("OnAnyHit"), {"AH_Probe"}});
    h.stateObject.localRootSignatures.push_back({localSignature("OnClosestHit"), {"CH_Probe"}});
    const Diagnostic d = expectDxrError("ASSOC-4", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("hit group 'HG_TriAH' would have two local root signatures"), std::string::npos) << d.message;
}

TEST(StateObject, ASSOC_4_AgreeingComponentsGiveTheGroupItsSignature) {
    Harness h;
    h.addProbeShaders();
    const auto l = localSignature("Shared");
    h.stateObject.localRootSignatures.push_back({l, {"AH_Probe", "CH_Probe", "HG_TriAH"}});
    const auto so = h.pipeline();
    EXPECT_EQ(entry(so, "HG_TriAH").localRootSignature, l);
    EXPECT_EQ(entry(so, "HG_Tri").localRootSignature, l);  // via its CHS
}

TEST(StateObject, ASSOC_5_ShaderAndPipelineConfigsAreRequired) {
    Harness h;
    h.addProbeShaders();
    h.stateObject.shaderConfigs.clear();
    Diagnostic d = expectDxrError("ASSOC-5", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("has no shader config subobject"), std::string::npos) << d.message;
    h.stateObject.shaderConfigs = {{64, 32}};
    h.stateObject.pipelineConfigs.clear();
    d = expectDxrError("ASSOC-5", [&] { h.pipeline(); });
    EXPECT_NE(d.message.find("has no pipeline config subobject"), std::string::npos) << d.message;
}

TEST(StateObject, ASSOC_6_ResolvedSignatureFixesTheRecordLayout) {
    // The signature reaches the hit group only through its CHS; the record layout (REC-5)
    // follows it: 36 bytes, so stride 32 is too small and the CHS reads its constant.
    Harness h;
    h.addProbeShaders();
    const auto sig = localSignature("ViaComponent");
    h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Tag", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
            p.closestHits++;
            p.tag = ctx.localRootConstants<uint32_t>(0);
        });
    h.stateObject.hitGroups.push_back({"HG_Tag", HitGroupType::Triangles, "", "CH_Tag", ""});
    h.stateObject.localRootSignatures.push_back({sig, {"CH_Tag"}});
    std::vector<Probe> results(1);
    h.addTracingRayGen(hitRay, {}, results);
    buildOneTriangleScene(h);
    const auto so = h.pipeline();
    ASSERT_EQ(entry(so, "HG_Tag").localRootSignature, sig);
    EXPECT_EQ(entry(so, "HG_Tag").localRootSignature->recordSize(), 36u);

    LocalRootArguments args(sig);
    args.setConstants(0, 4242u);
    const Diagnostic d = expectDxrError("IDX-10", [&] {
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tag", "HG_Tag"}, {&args, &args}, 32));
    });
    EXPECT_EQ(valueOf(d, "record bytes (REC-5)"), "36");

    h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tag"}, {&args}));
    ASSERT_EQ(results[0].closestHits, 1u);
    EXPECT_EQ(results[0].tag, 4242u);
}

}  // namespace
}  // namespace refray::test
