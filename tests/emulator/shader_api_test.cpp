// System values read through ShaderContext (SV-4, SV-6, SV-8) and the procedural limits (LIM-4).
#include <gtest/gtest.h>

#include "harness.h"

namespace refray::test {

namespace {

struct Seen {
    float tMinInIS = -1, tMinInCH = -1, tMinInMiss = -1;
    uint32_t flagsInIS = 0, flagsInCH = 0;
    vec3 objectOrigin{0.0f}, objectDirection{0.0f};
};

// A box instance scaled by (2, 4, 0.5) and translated by (10, 0, 0); one ray through it and one past it.
struct SystemValueScene {
    Harness h;
    Seen hit, miss;
    const Matrix3x4 transform = Matrix3x4::translation({10, 0, 0}) * Matrix3x4::scale({2, 4, 0.5f});
    uint32_t traceFlags = RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_FORCE_OPAQUE;

    SystemValueScene() {
        h.library->addIntersection<ProbeAttributes>("IS_Seen", [this](ShaderContext& ctx) {
            hit.tMinInIS = ctx.RayTMin();
            hit.flagsInIS = ctx.RayFlags();
            ctx.ReportHit(ctx.RayTMin() + 1.0f, 0, ProbeAttributes{});
        });
        h.library->addClosestHit<Probe, ProbeAttributes>("CH_Seen", [this](ShaderContext& ctx, Probe&, const ProbeAttributes&) {
            hit.tMinInCH = ctx.RayTMin();
            hit.flagsInCH = ctx.RayFlags();
            hit.objectOrigin = ctx.ObjectRayOrigin();
            hit.objectDirection = ctx.ObjectRayDirection();
        });
        h.library->addMiss<Probe>("Miss_Seen", [this](ShaderContext& ctx, Probe&) { miss.tMinInMiss = ctx.RayTMin(); });
        h.library->addRayGeneration("RG", [this](ShaderContext& ctx) {
            Probe p;
            const float x = ctx.DispatchRaysIndex().x == 0 ? 10.5f : 50.0f;
            ctx.TraceRay(h.scene, traceFlags, 0xFF, 0, 1, 0, RayDesc{vec3(x, 1.0f, -8.0f), 0.25f, vec3(0.5f, 0.0f, 3.0f), 100.0f}, p);
        });
        h.stateObject.hitGroups.push_back({"HG_Seen", HitGroupType::ProceduralPrimitive, "", "CH_Seen", "IS_Seen"});
        h.stateObject.pipelineConfigs = {{1, 0}};
        h.tlas({Harness::instance(h.blas({h.aabbs({unitBox()})}), 0, transform)});
    }
    void run() {
        const auto so = h.pipeline();
        h.dispatch(so, h.table(so, {"Miss_Seen"}), h.table(so, {"HG_Seen"}), uvec3(2, 1, 1));
    }
};

}  // namespace

TEST(ShaderApi, SV_4_RayTMinIsTheRayDescTMinInEveryStage) {
    SystemValueScene s;
    s.run();
    EXPECT_EQ(s.hit.tMinInIS, 0.25f);
    EXPECT_EQ(s.hit.tMinInCH, 0.25f);
    EXPECT_EQ(s.miss.tMinInMiss, 0.25f);
}

TEST(ShaderApi, SV_6_RayFlagsIsTheTraceRayArgument) {
    SystemValueScene s;
    s.h.stateObject.pipelineConfigs = {{1, PIPELINE_FLAG_SKIP_TRIANGLES}};
    s.traceFlags = RAY_FLAG_FORCE_OPAQUE;  // SKIP_TRIANGLES excludes the culling flags (FLAG-4)
    s.run();
    EXPECT_EQ(s.hit.flagsInIS, uint32_t(RAY_FLAG_FORCE_OPAQUE));  // the pipeline SKIP_TRIANGLES never shows
    EXPECT_EQ(s.hit.flagsInCH, uint32_t(RAY_FLAG_FORCE_OPAQUE));
}

TEST(ShaderApi, SV_8_ObjectRayIsTheWorldRayUnderWorldToObjectNotNormalized) {
    SystemValueScene s;
    s.run();
    const Matrix3x4 inverse = *affineInverse(s.transform);
    const vec3 expectedOrigin = inverse.transformPoint({10.5f, 1.0f, -8.0f});
    const vec3 expectedDirection = inverse.transformVector({0.5f, 0.0f, 3.0f});
    EXPECT_EQ(s.hit.objectOrigin, expectedOrigin);
    EXPECT_EQ(s.hit.objectDirection, expectedDirection);
    EXPECT_FLOAT_EQ(s.hit.objectDirection.z, 6.0f);  // 3 / 0.5: no renormalization
}

TEST(ShaderApi, LIM_4_ProceduralHitKindIsAtMost127) {
    for (uint32_t kind : {127u, 128u}) {
        Harness h;
        h.addProbeShaders();
        h.library->addIntersection<ProbeAttributes>("IS_Kind", [kind](ShaderContext& ctx) {
            ctx.ReportHit(ctx.RayTMin() + 1.0f, kind, ProbeAttributes{});
        });
        h.stateObject.hitGroups.push_back({"HG_Kind", HitGroupType::ProceduralPrimitive, "", "CH_ProbeAABB", "IS_Kind"});
        std::vector<Probe> results(1);
        h.addTracingRayGen([](uvec3) { return RayDesc{vec3(0, 0, -5), 0.0f, vec3(0, 0, 1), 100.0f}; }, {}, results);
        h.tlas({Harness::instance(h.blas({h.aabbs({unitBox()})}))});
        const auto so = h.pipeline();
        auto run = [&] { h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Kind"})); };
        if (kind == 127) {
            run();
            EXPECT_EQ(results[0].hitKind, 127u);
        } else {
            const Diagnostic d = expectDxrError("IS-4", run);
            EXPECT_NE(d.format().find("HitKind = 128 (limit 0..127)"), std::string::npos) << d.format();
        }
    }
}

TEST(ShaderApi, LIM_4_AttributesAboveThirtyTwoBytesAreRefused) {
    struct Big {
        float v[9];
    };
    Harness h;
    h.library->addIntersection<Big>("IS_Big", [](ShaderContext&) {});
    h.stateObject.shaderConfigs = {{64, 32}};
    expectDxrError("IS-5", [&] { h.pipeline(); });
}

TEST(RootSignature, REC_6_LocalDescriptorTableTakesAFullEightByteHandle) {
    RootSignatureDesc desc;
    desc.name = "Local";
    desc.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    desc.parameters = {RootParameter::constants(1, 0), RootParameter::table({DescriptorRange{DescriptorRangeType::SRV, 4, 0, 0, 0}})};
    const auto sig = RootSignature::create(desc);
    EXPECT_EQ(sig->argumentSize(1), 8u);
    EXPECT_EQ(sig->argumentOffset(1), 40u);  // 32 + 4, aligned up to 8
    EXPECT_EQ(sig->recordSize(), 48u);
}

}  // namespace refray::test

namespace refray::test {

TEST(ShaderApi, BufferViewsInADescriptorTableReadZeroPastTheirEnd) {
    Harness h;
    const std::vector<uint32_t> data = {11, 22, 33};
    DescriptorHeap& heap = h.device.createDescriptorHeap(2, "buffers");
    heap.setBuffer(1, DescriptorRangeType::SRV, {h.device.memory().upload(data, "data"), 12, 4});
    std::vector<uint32_t> seen;
    h.library->addRayGeneration("RG", [&](ShaderContext& ctx) {
        const GpuDescriptorHandle table = heap.gpuHandle(0);
        for (uint64_t i = 0; i < 4; ++i) seen.push_back(ctx.loadFromTable<uint32_t>(table, 1, 4 * i));
        const uint64_t straddling = ctx.loadFromTable<uint64_t>(table, 1, 8);  // 4 bytes in range, 4 past
        seen.push_back(uint32_t(straddling >> 32));
    });
    h.stateObject.pipelineConfigs = {{0, 0}};
    const auto so = h.pipeline();
    h.dispatch(so, {}, {});
    EXPECT_EQ(seen, (std::vector<uint32_t>{11, 22, 33, 0, 0}));
}

TEST(ShaderApi, ReadingATextureDescriptorAsABufferIsAnError) {
    Harness h;
    Image image(1, 1);
    DescriptorHeap& heap = h.device.createDescriptorHeap(1, "textures");
    heap.setTexture2D(0, DescriptorRangeType::UAV, &image);
    h.library->addRayGeneration("RG", [&](ShaderContext& ctx) { ctx.loadFromTable<uint32_t>(heap.gpuHandle(0), 0, 0); });
    h.stateObject.pipelineConfigs = {{0, 0}};
    const auto so = h.pipeline();
    const Diagnostic d = expectDxrError("GEN-1", [&] { h.dispatch(so, {}, {}); });
    EXPECT_NE(d.message.find("is not a buffer view"), std::string::npos) << d.message;
}

}  // namespace refray::test
