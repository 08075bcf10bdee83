// Resource binding by HLSL register and space (emulator/shader_resources.cpp, emulator/root_signature.cpp,
// emulator/descriptor_heap.cpp): the BIND rules of docs/emulator.md, through real DispatchRays calls.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include <OpenImageIO/imageio.h>

#include "core/image.h"
#include "harness.h"
#include "tests/test_output.h"

namespace refray::test {

namespace fs = std::filesystem;

namespace {

struct Vertex {  // StructuredBuffer<Vertex> vertices[] : register(t0, space1)
    vec3 position;
    float u;
};

std::string writeTexture(const std::string& name, const Image& image) {
    const std::string path = (refray::testing::testOutputDirectory("resource_binding") / name).string();
    writeImage(path, image);
    return path;
}

StaticSamplerDesc staticSampler(uint32_t shaderRegister, uint32_t space, SamplerFilter filter,
                                TextureAddressMode address,
                                StaticBorderColor border = STATIC_BORDER_COLOR_TRANSPARENT_BLACK) {
    StaticSamplerDesc s;
    s.Filter = filter;
    s.AddressU = s.AddressV = s.AddressW = address;
    s.BorderColor = border;
    s.ShaderRegister = shaderRegister;
    s.RegisterSpace = space;
    return s;
}

// The layout of a DXR path tracer's global root signature, on one CBV_SRV_UAV heap and one sampler heap:
//   [0] table: Texture2D text[] : register(t0, space5)             heap 0..  (unbounded)
//   [1] table: StructuredBuffer<Vertex> t0, ByteAddressBuffer t1,  heap 8, 9, 10 (10: a null view)
//              a third SRV t2 (space1), then ConstantBuffer b0 (space1)  heap 11
//   [2] table: SamplerState s1                                      sampler heap 0
//   [3] root constants b0 (two uints)
//   [4] root SRV t7: StructuredBuffer<vec4>
//   [5] table: RWTexture2D<float4> output : register(u0)            heap 12
//   static samplers s0 (point, clamp) and s0 space2 (linear, border opaque white)
// Heap: 0 = texture A, 1 = texture B, 2 = null Texture2D, 3 = never written, 12 = output, 13 = a buffer UAV.
struct BindingScene {
    Harness h;
    Image output{2, 2};
    Texture2DPtr textureA, textureB;
    DescriptorHeap* heap = nullptr;
    DescriptorHeap* samplerHeap = nullptr;
    RootSignaturePtr signature;
    std::unique_ptr<GlobalRootArguments> global;
    std::function<void(ShaderContext&)> body = [](ShaderContext&) {};

    BindingScene() {
        Image a(1, 1, vec4(0.5f));
        Image b(2, 2);
        b.at(0, 0) = {1, 0, 0, 1};
        b.at(1, 0) = {0, 1, 0, 1};
        b.at(0, 1) = {0, 0, 1, 1};
        b.at(1, 1) = {1, 1, 1, 1};
        textureA = Texture2D::fromFile(writeTexture("a.exr", a));
        textureB = Texture2D::fromFile(writeTexture("b.exr", b));

        GpuMemory& memory = h.device.memory();
        const std::vector<Vertex> vertices = {{{1, 2, 3}, 0.25f}, {{4, 5, 6}, 0.75f}};
        const std::vector<uint32_t> raw = {10, 20, 30};
        const std::vector<vec4> constants = {{7, 8, 9, 10}};
        const std::vector<vec4> rootBuffer = {{1, 1, 1, 1}, {2, 2, 2, 2}};
        heap = &h.device.createDescriptorHeap(16, "resources");
        heap->setTexture2D(0, textureA);
        heap->setTexture2D(1, textureB);
        heap->setTexture2D(2, nullptr);
        heap->setBuffer(8, DescriptorRangeType::SRV,
                        {memory.upload(vertices, "vertices"), 2 * sizeof(Vertex), sizeof(Vertex)});
        heap->setBuffer(9, DescriptorRangeType::SRV, {memory.upload(raw, "raw"), 12, 0});
        heap->setBuffer(10, DescriptorRangeType::SRV, {});
        heap->setBuffer(11, DescriptorRangeType::CBV, {memory.upload(constants, "constants"), 16, 0});
        heap->setTexture2D(12, DescriptorRangeType::UAV, &output);
        heap->setBuffer(13, DescriptorRangeType::UAV, {memory.upload(raw, "uav"), 12, 0});
        samplerHeap = &h.device.createDescriptorHeap(1, "samplers");
        SamplerDesc pointWrap;
        pointWrap.Filter = FILTER_MIN_MAG_MIP_POINT;
        samplerHeap->setSampler(0, pointWrap);

        RootSignatureDesc desc;
        desc.name = "Global";
        desc.parameters = {
            RootParameter::table({{DescriptorRangeType::SRV, kDescriptorRangeUnbounded, 0, 5, 0}}),
            RootParameter::table({{DescriptorRangeType::SRV, 3, 0, 1}, {DescriptorRangeType::CBV, 1, 0, 1}}),
            RootParameter::table({{DescriptorRangeType::Sampler, 1, 1, 0}}),
            RootParameter::constants(2, 0),
            RootParameter::srv(7),
            RootParameter::table({{DescriptorRangeType::UAV, 1, 0, 0}}),
        };
        desc.staticSamplers = {staticSampler(0, 0, FILTER_MIN_MAG_MIP_POINT, TEXTURE_ADDRESS_MODE_CLAMP),
                               staticSampler(0, 2, FILTER_MIN_MAG_MIP_LINEAR, TEXTURE_ADDRESS_MODE_BORDER,
                                             STATIC_BORDER_COLOR_OPAQUE_WHITE)};
        signature = RootSignature::create(desc);
        global = std::make_unique<GlobalRootArguments>(signature);
        global->setDescriptor(0, heap->gpuHandle(0));
        global->setDescriptor(1, heap->gpuHandle(8));
        global->setDescriptor(2, samplerHeap->gpuHandle(0));
        global->setConstants(3, uvec2(5, 6));
        global->setDescriptor(4, memory.upload(rootBuffer, "root SRV"));
        global->setDescriptor(5, heap->gpuHandle(12));

        h.library->addRayGeneration("RG", [this](ShaderContext& ctx) { body(ctx); });
        h.stateObject.globalRootSignatures.push_back({signature, {"RG"}});
        h.stateObject.pipelineConfigs = {{0, PIPELINE_FLAG_NONE}};
    }

    void run(uvec3 dims = uvec3(1u)) { h.dispatch(h.pipeline(), {}, {}, dims, {}, global.get()); }

    // Runs `shader` once, expecting a DxrError with `rule` whose message contains `text`.
    void expectError(const std::string& rule, const std::string& text, std::function<void(ShaderContext&)> shader) {
        body = std::move(shader);
        const Diagnostic d = expectDxrError(rule, [&] { run(); });
        EXPECT_NE(d.message.find(text), std::string::npos) << "expected '" << text << "' in\n" << d.message;
    }
};

}  // namespace

TEST(ResourceBinding, RayGenerationReadsATextureArrayAndAStructuredBufferByRegister) {
    BindingScene s;
    s.body = [](ShaderContext& ctx) {
        const uint32_t x = ctx.DispatchRaysIndex().x;
        // Texture2D text[] : register(t0, space5); StructuredBuffer<Vertex> vertices[] : register(t0, space1);
        // SamplerState pointClamp : register(s0); RWTexture2D<float4> output : register(u0).
        const Vertex v = ctx.loadStructured<Vertex>(0, 1, 0, x);
        const vec4 texel = ctx.Texture2D(0, 5, 1).SampleLevel(ctx.SamplerState(0), vec2(v.u, 0.25f), 0.0f);
        Image& out = ctx.rwTexture2D(ctx.globalDescriptorTable(5));
        out.at(x, 0) = texel;
        out.at(x, 1) = vec4(v.position, 0.0f);
    };
    s.run(uvec3(2, 1, 1));
    EXPECT_EQ(s.output.at(0, 0), vec4(1, 0, 0, 1));  // text[1] texel (0, 0)
    EXPECT_EQ(s.output.at(1, 0), vec4(0, 1, 0, 1));  // text[1] texel (1, 0)
    EXPECT_EQ(s.output.at(0, 1), vec4(1, 2, 3, 0));
    EXPECT_EQ(s.output.at(1, 1), vec4(4, 5, 6, 0));
}

TEST(ResourceBinding, EveryKindOfBindingResolves) {
    BindingScene s;
    struct Seen {
        vec4 wrapped, border, cb, rootSRV, text0, nullTexture, nullBuffer, clampedStatic;
        uvec2 rootConstants{0u};
        uint32_t raw = 0, rawPastEnd = 1, width = 0, height = 0, levels = 0, nullWidth = 1, nullLevels = 1;
        Vertex pastEnd{{1, 1, 1}, 1};
    } seen;
    s.body = [&](ShaderContext& ctx) {
        const Texture2DRef text1 = ctx.Texture2D(0, 5, 1);
        seen.wrapped = text1.SampleLevel(ctx.SamplerState(1), {1.25f, 0.25f}, 0.0f);        // sampler table s1: WRAP
        seen.clampedStatic = text1.SampleLevel(ctx.SamplerState(0), {1.25f, 0.25f}, 0.0f);  // static s0: CLAMP
        seen.border = text1.SampleLevel(ctx.SamplerState(0, 2), {-1.0f, 0.5f}, 0.0f);       // static s0 space2: white
        text1.GetDimensions(0, seen.width, seen.height, seen.levels);
        seen.text0 = ctx.Texture2D(0, 5).Load(glm::ivec3(0, 0, 0));
        const Texture2DRef null = ctx.Texture2D(0, 5, 2);
        seen.nullTexture = null.SampleLevel(ctx.SamplerState(0), {0.5f, 0.5f}, 0.0f) + null.Load(glm::ivec3(0));
        null.GetDimensions(0, seen.nullWidth, seen.height, seen.nullLevels);
        text1.GetDimensions(seen.width, seen.height);
        seen.rootConstants = ctx.constantBuffer<uvec2>(0);
        seen.cb = ctx.constantBuffer<vec4>(0, 1);
        seen.rootSRV = ctx.loadStructured<vec4>(7, 0, 0, 1);
        seen.raw = ctx.loadByteAddress<uint32_t>(0, 1, 1, 8);
        seen.rawPastEnd = ctx.loadByteAddress<uint32_t>(0, 1, 1, 12);
        seen.pastEnd = ctx.loadStructured<Vertex>(0, 1, 0, 2);
        seen.nullBuffer = ctx.loadStructured<vec4>(0, 1, 2, 0) + vec4(float(ctx.loadByteAddress<uint32_t>(0, 1, 2, 0)));
    };
    s.run();
    EXPECT_EQ(seen.wrapped, vec4(1, 0, 0, 1));        // u = 1.25 wraps to texel 0
    EXPECT_EQ(seen.clampedStatic, vec4(0, 1, 0, 1));  // ... and clamps to texel 1
    EXPECT_EQ(seen.border, vec4(1.0f));               // far outside: all border
    EXPECT_EQ(seen.width, 2u);
    EXPECT_EQ(seen.height, 2u);
    EXPECT_EQ(seen.levels, 2u);
    EXPECT_EQ(seen.text0, vec4(0.5f));
    EXPECT_EQ(seen.nullTexture, vec4(0.0f));
    EXPECT_EQ(seen.nullWidth, 0u);
    EXPECT_EQ(seen.nullLevels, 0u);
    EXPECT_EQ(seen.rootConstants, uvec2(5, 6));
    EXPECT_EQ(seen.cb, vec4(7, 8, 9, 10));
    EXPECT_EQ(seen.rootSRV, vec4(2.0f));
    EXPECT_EQ(seen.raw, 30u);
    EXPECT_EQ(seen.rawPastEnd, 0u);
    EXPECT_EQ(seen.pastEnd.position, vec3(0.0f));
    EXPECT_EQ(seen.pastEnd.u, 0.0f);
    EXPECT_EQ(seen.nullBuffer, vec4(0.0f));
}

TEST(ResourceBinding, ALocalRootSignatureBindsRegistersOfItsShaderRecord) {
    // A miss shader whose record carries a local root signature: root constants at b0 space3 and a table of
    // Texture2D at t0 space4 (the global one binds neither).
    BindingScene s;
    RootSignatureDesc localDesc;
    localDesc.name = "MissLocal";
    localDesc.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    localDesc.parameters = {RootParameter::constants(1, 0, 3),
                            RootParameter::table({{DescriptorRangeType::SRV, 2, 0, 4}})};
    const RootSignaturePtr localSignature = RootSignature::create(localDesc);
    LocalRootArguments local(localSignature);
    local.setConstants(0, 42u);
    local.setDescriptor(1, s.heap->gpuHandle(0));
    uint32_t constant = 0;
    vec4 texel(-1.0f);
    s.h.library->addMiss<Probe>("Miss_Local", [&](ShaderContext& ctx, Probe&) {
        constant = ctx.constantBuffer<uint32_t>(0, 3);
        texel = ctx.Texture2D(0, 4, 1).Load(glm::ivec3(1, 1, 0));
    });
    s.h.stateObject.localRootSignatures.push_back({localSignature, {"Miss_Local"}});
    s.h.stateObject.pipelineConfigs = {{1, PIPELINE_FLAG_NONE}};
    s.body = [](ShaderContext& ctx) {
        Probe p;
        ctx.TraceRay(0, RAY_FLAG_NONE, 0xFF, 0, 1, 0, RayDesc{vec3(0.0f), 0.0f, vec3(0, 0, 1), 1.0f},
                     p);  // RAY-3: a miss
    };
    const StateObjectPtr so = s.h.pipeline();
    s.h.dispatch(so, s.h.table(so, {"Miss_Local"}, {&local}), {}, uvec3(1u), {}, s.global.get());
    EXPECT_EQ(constant, 42u);
    EXPECT_EQ(texel, vec4(1.0f));  // text[1] texel (1, 1) of the local table
    // Neither signature binds t9 in space4: the error names both.
    s.h.library->addMiss<Probe>("Miss_Unbound", [](ShaderContext& ctx, Probe&) { ctx.Texture2D(9, 4); });
    s.h.stateObject.localRootSignatures.back().exports.push_back("Miss_Unbound");
    const StateObjectPtr so2 = s.h.pipeline();
    const Diagnostic d = expectDxrError("BIND-1", [&] {
        s.h.dispatch(so2, s.h.table(so2, {"Miss_Unbound"}, {&local}), {}, uvec3(1u), {}, s.global.get());
    });
    EXPECT_NE(d.message.find("global root signature 'Global' binds nothing at t9 in space4 (its t bindings in space4: "
                             "none), nor does local root signature 'MissLocal' (its t bindings in space4: t0..t1, "
                             "space4 (range 0 of the descriptor table in parameter [1]))"),
              std::string::npos)
        << d.message;
}

TEST(ResourceBinding, BIND_1_NothingBindsTheRegister) {
    BindingScene s;
    s.expectError("BIND-1",
                  "Texture2D t3, space4, index 0: global root signature 'Global' binds nothing at t3 in space4 (its t "
                  "bindings in space4: none)",
                  [](ShaderContext& ctx) { ctx.Texture2D(3, 4); });
    s.expectError(
        "BIND-1",
        "SamplerState s5, space0, index 0: global root signature 'Global' binds nothing at s5 in space0 (its s "
        "bindings in space0: s0, space0 (static sampler 0); s1, space0 (range 0 of the descriptor table in "
        "parameter [2]))",
        [](ShaderContext& ctx) { ctx.SamplerState(5); });
    s.expectError("BIND-1", "binds nothing at t5 in space1 (its t bindings in space1: t0..t2, space1 (range 0",
                  [](ShaderContext& ctx) { ctx.Texture2D(5, 1); });
}

TEST(ResourceBinding, BIND_1_TheDispatchHasNoGlobalRootSignature) {
    Harness h;
    h.library->addRayGeneration("RG", [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 1); });
    h.stateObject.pipelineConfigs = {{0, PIPELINE_FLAG_NONE}};
    const Diagnostic d = expectDxrError("BIND-1", [&] { h.dispatch(h.pipeline(), {}, {}); });
    EXPECT_EQ(d.message,
              "Texture2D t0, space5, index 1: the dispatch has no global root signature (no global root "
              "arguments)");
}

TEST(ResourceBinding, BIND_2_IndexOutsideTheRangeOrTheHeap) {
    BindingScene s;
    s.expectError("BIND-2",
                  "StructuredBuffer t0, space1, index 3: index 3 is past the end of t0..t2, space1 (range 0 of the "
                  "descriptor table in parameter [1]) of 'Global', which holds 3 registers",
                  [](ShaderContext& ctx) { ctx.loadStructured<Vertex>(0, 1, 3, 0); });
    s.expectError("BIND-2",
                  "index 1 is past the end of t7, space0 (root SRV, parameter [4]) of 'Global', which holds 1 register",
                  [](ShaderContext& ctx) { ctx.loadStructured<vec4>(7, 0, 1, 0); });
    s.expectError("BIND-2",
                  "Texture2D t0, space5, index 16: descriptor 16 is past the end of heap 'resources' (16 descriptors): "
                  "table start 0 + range offset 0 + element 16",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 16); });
    s.global->setDescriptor(0, s.heap->gpuHandle(15));  // the unbounded table now starts at the last descriptor
    s.expectError("BIND-2", "descriptor 17 is past the end of heap 'resources'",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 2); });
    s.global->setDescriptor(0, 0x1234);
    s.expectError("BIND-2",
                  "the descriptor table handle 0x1234 set for parameter [0] of global root signature 'Global' is in no "
                  "descriptor heap",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 0); });
}

TEST(ResourceBinding, BIND_3_DescriptorOfTheWrongKindOrType) {
    BindingScene s;
    s.expectError(
        "BIND-3",
        "Texture2D t0, space1, index 0: descriptor 8 of heap 'resources', bound by t0..t2, space1 (range 0 of "
        "the descriptor table in parameter [1]) of root signature 'Global', holds a buffer SRV (structured, "
        "stride 16), not a Texture2D SRV",
        [](ShaderContext& ctx) { ctx.Texture2D(0, 1); });
    s.expectError(
        "BIND-3",
        "descriptor 1 of heap 'resources', bound by t0.. (unbounded), space5 (range 0 of the "
        "descriptor table in parameter [0]) of root signature 'Global', holds a Texture2D SRV, not a buffer SRV",
        [](ShaderContext& ctx) { ctx.loadStructured<vec4>(0, 5, 1, 0); });
    s.expectError("BIND-3", "holds a buffer UAV (raw), not a Texture2D SRV",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 13); });
    s.expectError("BIND-3", "holds an Image (an RWTexture2D target); a Texture2D SRV is a dxr::Texture2D",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 12); });
    s.expectError("BIND-3",
                  "Texture2D t7, space0, index 0: t7, space0 (root SRV, parameter [4]) of root signature 'Global' is a "
                  "buffer address; a Texture2D needs a descriptor table range",
                  [](ShaderContext& ctx) { ctx.Texture2D(7, 0); });
    // The buffer table moved back one descriptor: its CBV range reads the null SRV of descriptor 10.
    s.global->setDescriptor(1, s.heap->gpuHandle(7));
    s.expectError("BIND-3",
                  "descriptor 10 of heap 'resources', bound by b0, space1 (range 1 of the descriptor table in "
                  "parameter [1]) of root signature 'Global', holds a buffer SRV (null), not a CBV",
                  [](ShaderContext& ctx) { ctx.constantBuffer<vec4>(0, 1); });
    // A sampler table pointing into the CBV_SRV_UAV heap.
    s.global->setDescriptor(2, s.heap->gpuHandle(1));
    s.expectError("BIND-3", "holds a Texture2D SRV, not a sampler", [](ShaderContext& ctx) { ctx.SamplerState(1); });
}

TEST(ResourceBinding, BIND_4_ANeverWrittenDescriptorIsAnErrorAndANullOneReadsZeros) {
    BindingScene s;
    s.expectError("BIND-4",
                  "Texture2D t0, space5, index 3: descriptor 3 of heap 'resources', bound by t0.. (unbounded), space5 "
                  "(range 0 of the descriptor table in parameter [0]) of root signature 'Global', was never written; "
                  "D3D12 leaves its contents undefined (write a null descriptor to read zeros)",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 3); });
    // Null descriptors (heap 2, heap 10) read zeros: EveryKindOfBindingResolves checks the values.
}

TEST(ResourceBinding, BIND_5_StrideAndLayoutMismatches) {
    BindingScene s;
    s.expectError("BIND-5",
                  "StructuredBuffer t0, space1, index 0: the shader reads 4-byte elements but descriptor 8 of heap "
                  "'resources', bound by t0..t2, space1 (range 0 of the descriptor table in parameter [1]) of root "
                  "signature 'Global', is a structured view of StructureByteStride 16",
                  [](ShaderContext& ctx) { ctx.loadStructured<uint32_t>(0, 1, 0, 0); });
    s.expectError("BIND-5", "the shader reads 16-byte elements but descriptor 9 of heap 'resources'",
                  [](ShaderContext& ctx) { ctx.loadStructured<Vertex>(0, 1, 1, 0); });
    s.expectError("BIND-5", "is a raw view (StructureByteStride 0)",
                  [](ShaderContext& ctx) { ctx.loadStructured<Vertex>(0, 1, 1, 0); });
    s.expectError("BIND-5", "is a structured view (StructureByteStride 16); a ByteAddressBuffer needs a raw view",
                  [](ShaderContext& ctx) { ctx.loadByteAddress<uint32_t>(0, 1, 0, 0); });
    s.expectError("BIND-5", "ByteAddressBuffer t1, space1, index 0: byte offset 6 is not a multiple of 4",
                  [](ShaderContext& ctx) { ctx.loadByteAddress<uint32_t>(1, 1, 0, 6); });
    s.expectError("BIND-5",
                  "ConstantBuffer b0, space0, index 0: the shader reads 12 bytes but b0, space0 (root constants, "
                  "parameter [3]) of root signature 'Global' holds 8 bytes of constants",
                  [](ShaderContext& ctx) { ctx.constantBuffer<uvec3>(0); });
}

TEST(ResourceBinding, BIND_6_ATextureFileThatCanNoLongerBeRead) {
    BindingScene s;
    // A tiled file: making the texture reads its first tile only. Then the file loses its other tiles.
    const std::string path = (refray::testing::testOutputDirectory("resource_binding") / "vanishing.exr").string();
    {
        OIIO::ImageSpec spec(64, 64, 4, OIIO::TypeDesc::FLOAT);
        spec.tile_width = spec.tile_height = 16;
        std::vector<float> texels(64 * 64 * 4);
        for (size_t i = 0; i < texels.size(); ++i) texels[i] = float(i * 7919 % 1000) / 1000.0f;  // incompressible
        auto out = OIIO::ImageOutput::create(path);
        ASSERT_TRUE(out && out->open(path, spec) && out->write_image(OIIO::TypeDesc::FLOAT, texels.data()));
        out->close();
    }
    s.heap->setTexture2D(4, Texture2D::fromFile(path));
    fs::resize_file(path, fs::file_size(path) / 2);  // the last tiles are gone
    s.expectError("BIND-6",
                  "Texture2D t0, space5, index 4: Load cannot read the texture: texture '" + path +
                      "': cannot read texels of MIP level 0: ",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 4).Load(glm::ivec3(63, 63, 0)); });
}

TEST(ResourceBinding, REC_7_AnUnsetTableArgumentIsReported) {
    BindingScene s;
    s.global = std::make_unique<GlobalRootArguments>(s.signature);
    s.expectError("REC-7", "global root parameter 0 of 'Global', whose bytes were never written",
                  [](ShaderContext& ctx) { ctx.Texture2D(0, 5, 1); });
}

// ---------------------------------------------------------------------------------------
// Root signatures: the register map and its validation.

namespace {

RootSignatureDesc descOf(std::string name, std::vector<RootParameter> parameters,
                         std::vector<StaticSamplerDesc> samplers = {}) {
    RootSignatureDesc d;
    d.name = std::move(name);
    d.parameters = std::move(parameters);
    d.staticSamplers = std::move(samplers);
    return d;
}

std::string refusal(const std::string& rule, const RootSignatureDesc& desc) {
    return expectDxrError(rule, [&] { RootSignature::create(desc); }).format();
}

}  // namespace

TEST(RootSignatureBinding, RegisterMapResolvesAppendAndExplicitOffsets) {
    const auto sig = RootSignature::create(descOf(
        "Map",
        {RootParameter::srv(9), RootParameter::table({{DescriptorRangeType::SRV, 2, 0, 0},
                                                      {DescriptorRangeType::UAV, 1, 0, 0},
                                                      {DescriptorRangeType::SRV, 3, 4, 0, 10},
                                                      {DescriptorRangeType::SRV, kDescriptorRangeUnbounded, 0, 3}})},
        {staticSampler(2, 1, FILTER_ANISOTROPIC, TEXTURE_ADDRESS_MODE_WRAP)}));
    const RegisterBinding* b = sig->findRegister(DescriptorRangeType::SRV, 0, 5);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->source, RegisterBinding::Source::DescriptorTable);
    EXPECT_EQ(b->index, 1u);
    EXPECT_EQ(b->range, 2u);
    EXPECT_EQ(b->offsetInTable, 10u);
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::UAV, 0, 0)->offsetInTable, 2u);  // APPEND after 2 descriptors
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::SRV, 3, 1000000)->offsetInTable, 13u);  // APPEND after 10 + 3
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::SRV, 0, 9)->source, RegisterBinding::Source::RootDescriptor);
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::Sampler, 1, 2)->source, RegisterBinding::Source::StaticSampler);
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::SRV, 0, 2), nullptr);
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::SRV, 0, 7), nullptr);
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::SRV, 1, 0), nullptr);
    EXPECT_EQ(sig->findRegister(DescriptorRangeType::Sampler, 0, 2), nullptr);
    EXPECT_EQ(sig->staticSampler(0).Filter, FILTER_ANISOTROPIC);
    EXPECT_EQ(sig->describe(), "Map{[0] root SRV 9, [1] table(4 ranges); static samplers s2 space1}");
}

TEST(RootSignatureBinding, BIND_7_OneRegisterBoundTwice) {
    EXPECT_NE(refusal("BIND-7", descOf("Overlap", {RootParameter::table({{DescriptorRangeType::SRV, 4, 0, 0}}),
                                                   RootParameter::srv(2)}))
                  .find("root signature 'Overlap' binds register t2, space0 twice: t0..t3, space0 (range 0 of the "
                        "descriptor table in parameter [0]) and t2, space0 (root SRV, parameter [1])"),
              std::string::npos);
    EXPECT_NE(refusal("BIND-7", descOf("Ranges", {RootParameter::table({{DescriptorRangeType::UAV, 2, 0, 3},
                                                                        {DescriptorRangeType::UAV, 2, 1, 3}})}))
                  .find("binds register u1, space3 twice"),
              std::string::npos);
    EXPECT_NE(refusal("BIND-7", descOf("Constants", {RootParameter::constants(1, 0), RootParameter::cbv(0)}))
                  .find("b0, space0 (root constants, parameter [0]) and b0, space0 (root CBV, parameter [1])"),
              std::string::npos);
    EXPECT_NE(
        refusal("BIND-7", descOf("Unbounded",
                                 {RootParameter::table({{DescriptorRangeType::SRV, kDescriptorRangeUnbounded, 0, 0}}),
                                  RootParameter::srv(100)}))
            .find("binds register t100, space0 twice"),
        std::string::npos);
    const StaticSamplerDesc s0 = staticSampler(0, 0, FILTER_MIN_MAG_MIP_POINT, TEXTURE_ADDRESS_MODE_WRAP);
    EXPECT_NE(refusal("BIND-7", descOf("Samplers", {}, {s0, s0}))
                  .find("s0, space0 (static sampler 0) and s0, space0 "
                        "(static sampler 1)"),
              std::string::npos);
    EXPECT_NE(
        refusal("BIND-7", descOf("Mixed", {RootParameter::table({{DescriptorRangeType::Sampler, 1, 0, 0}})}, {s0}))
            .find("binds register s0, space0 twice"),
        std::string::npos);
    // Other spaces and other register types never overlap.
    EXPECT_NO_THROW(RootSignature::create(
        descOf("Apart", {RootParameter::srv(0), RootParameter::srv(0, 1), RootParameter::uav(0), RootParameter::cbv(0)},
               {staticSampler(0, 0, FILTER_MIN_MAG_MIP_POINT, TEXTURE_ADDRESS_MODE_WRAP)})));
}

TEST(RootSignatureBinding, BIND_8_SamplerRangesNeedATableOfTheirOwn) {
    EXPECT_NE(refusal("BIND-8", descOf("Mixed", {RootParameter::table({{DescriptorRangeType::SRV, 1, 0, 0},
                                                                       {DescriptorRangeType::Sampler, 1, 0, 0}})}))
                  .find("root signature 'Mixed' parameter [0]: a descriptor table mixes Sampler ranges with "
                        "CBV/SRV/UAV ranges; D3D12 keeps samplers in tables (and heaps) of their own; range 0 = SRV, "
                        "range 1 = Sampler"),
              std::string::npos);
}

TEST(RootSignatureBinding, BIND_9_RangeShapes) {
    EXPECT_NE(
        refusal("BIND-9",
                descOf("Append", {RootParameter::table({{DescriptorRangeType::SRV, kDescriptorRangeUnbounded, 0, 0},
                                                        {DescriptorRangeType::SRV, 1, 0, 1}})}))
            .find("root signature 'Append' parameter [0] range 1 uses DESCRIPTOR_RANGE_OFFSET_APPEND after an "
                  "unbounded range"),
        std::string::npos);
    // After an unbounded range, an explicit offset is fine (d3d12.h, D3D12_DESCRIPTOR_RANGE::NumDescriptors).
    EXPECT_NO_THROW(RootSignature::create(
        descOf("Explicit", {RootParameter::table({{DescriptorRangeType::SRV, kDescriptorRangeUnbounded, 0, 0, 4},
                                                  {DescriptorRangeType::SRV, 4, 0, 1, 0}})})));
    EXPECT_NE(refusal("BIND-9", descOf("Empty", {RootParameter::table({{DescriptorRangeType::CBV, 0, 0, 0}})}))
                  .find("range 0 declares no descriptors; NumDescriptors = 0"),
              std::string::npos);
    EXPECT_NE(refusal("BIND-9", descOf("Far", {RootParameter::table({{DescriptorRangeType::CBV, 2, 0xFFFFFFFFu, 0}})}))
                  .find("runs past the last register"),
              std::string::npos);
}

TEST(RootSignatureBinding, BIND_10_StaticSamplersD3D12WouldRefuse) {
    StaticSamplerDesc bad = staticSampler(3, 1, FILTER_ANISOTROPIC, TEXTURE_ADDRESS_MODE_WRAP);
    bad.MaxAnisotropy = 17;
    EXPECT_NE(refusal("BIND-10", descOf("Aniso", {}, {bad}))
                  .find("root signature 'Aniso' static sampler 0 (s3, space1): MaxAnisotropy is outside the range "
                        "D3D12 accepts; MaxAnisotropy = 17 (limit 1..16)"),
              std::string::npos);
    bad = staticSampler(0, 0, FILTER_MIN_MAG_MIP_POINT, TEXTURE_ADDRESS_MODE_BORDER, StaticBorderColor(3));
    EXPECT_NE(refusal("BIND-10", descOf("Border", {}, {bad})).find("BorderColor is not a D3D12_STATIC_BORDER_COLOR"),
              std::string::npos);
}

TEST(DescriptorHeapBinding, SamplersAndResourcesLiveInHeapsOfTheirOwn) {
    DescriptorHeap resources(4, "res");
    resources.setBuffer(0, DescriptorRangeType::SRV, {});
    EXPECT_EQ(resources.type(), DescriptorHeapType::CBV_SRV_UAV);
    try {
        resources.setSampler(1, SamplerDesc{});
        ADD_FAILURE() << "a sampler went into a CBV_SRV_UAV heap";
    } catch (const Error& e) {
        EXPECT_NE(
            std::string(e.what()).find("descriptor heap 'res' is a CBV_SRV_UAV heap; a Sampler descriptor needs a "
                                       "heap of its own type"),
            std::string::npos)
            << e.what();
    }
    DescriptorHeap samplers(4000, "smp");
    samplers.setSampler(0, SamplerDesc{});
    EXPECT_THROW(samplers.setTexture2D(1, nullptr), Error);
    EXPECT_THROW(samplers.setSampler(2048, SamplerDesc{}), Error);
    SamplerDesc bad;
    bad.MaxLOD = -1.0f;
    expectDxrError("BIND-10", [&] { samplers.setSampler(1, bad); });
    EXPECT_THROW(resources.setBuffer(1, DescriptorRangeType::SRV, {0, 16, 0}), Error);  // a null view has no size
}

}  // namespace refray::test
