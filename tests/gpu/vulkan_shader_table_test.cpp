#include "gpu/vulkan_shader_table.h"

#include <gtest/gtest.h>

#include <cstring>

#include "core/error.h"
#include "emulator/limits.h"
#include "gpu_test_support.h"

namespace refray::gpu {
namespace {

using namespace refray::gpu::testing;
using dxr::kShaderIdentifierSizeInBytes;

struct TableView {
    const char* name;
    uint64_t start, size, stride;
    const ShaderTableRegion* region;
};

// Every record of every table: the translated bytes equal the emulator's, except the 32-byte identifier (the fake
// handle of the entry it names, or zeros for a null record) and the root descriptors (the emulator's VA plus
// kFakeAddressOffset). Counts the root descriptors seen in `rootDescriptors`.
void expectSameRecords(const dxr::DispatchRaysDesc& desc, const dxr::StateObject& so, const dxr::GpuMemory& memory,
                       const TranslatedShaderTables& out, int* rootDescriptors = nullptr) {
    const TableView tables[] = {
        {"raygen", desc.RayGenerationShaderRecord.StartAddress, desc.RayGenerationShaderRecord.SizeInBytes,
         desc.RayGenerationShaderRecord.SizeInBytes, &out.rayGeneration},
        {"miss", desc.MissShaderTable.StartAddress, desc.MissShaderTable.SizeInBytes, desc.MissShaderTable.StrideInBytes,
         &out.miss},
        {"hit", desc.HitGroupTable.StartAddress, desc.HitGroupTable.SizeInBytes, desc.HitGroupTable.StrideInBytes,
         &out.hitGroup},
    };
    for (const TableView& t : tables) {
        SCOPED_TRACE(t.name);
        EXPECT_EQ(t.region->offset % 64, 0u);
        if (t.size == 0) continue;
        const uint8_t* emulator = memory.read(t.start, t.size, t.name);
        ASSERT_LE(t.region->offset + t.size, out.bytes.size());
        const uint8_t* vulkan = out.bytes.data() + t.region->offset;
        // Same stride and records at the same offsets (the raygen region is rounded up to a handle multiple).
        if (std::string(t.name) != "raygen") {
            EXPECT_EQ(t.region->stride, t.stride);
        }
        EXPECT_EQ(t.region->records, t.size / t.stride + (t.size % t.stride >= kShaderIdentifierSizeInBytes ? 1 : 0));

        std::vector<bool> expectedDifferent(t.size, false);
        for (uint64_t i = 0; i < t.region->records; ++i) {
            const uint64_t at = i * t.stride;
            bool isNull = false;
            const dxr::ProgramEntry* entry = so.resolve(emulator + at, isNull);
            ASSERT_TRUE(isNull || entry) << "record " << i;
            const GroupHandle expected = isNull ? GroupHandle{} : fakeHandle(entry->index);
            EXPECT_EQ(std::memcmp(vulkan + at, expected.data(), 32), 0) << "identifier of record " << i;
            for (uint64_t b = 0; b < 32; ++b) expectedDifferent[at + b] = true;
            if (isNull || !entry->localRootSignature) continue;
            const dxr::RootSignature& sig = *entry->localRootSignature;
            for (uint32_t p = 0; p < sig.parameterCount(); ++p) {
                const auto type = sig.parameter(p).parameterType;
                if (type != dxr::RootParameterType::CBV && type != dxr::RootParameterType::SRV &&
                    type != dxr::RootParameterType::UAV)
                    continue;
                const uint64_t off = at + sig.argumentOffset(p);
                uint64_t before = 0, after = 0;
                std::memcpy(&before, emulator + off, 8);
                std::memcpy(&after, vulkan + off, 8);
                EXPECT_EQ(after, before ? before + kFakeAddressOffset : 0) << "root descriptor [" << p << "] of record " << i;
                for (uint64_t b = 0; b < 8; ++b) expectedDifferent[off + b] = true;
                if (rootDescriptors) ++*rootDescriptors;
            }
        }
        for (uint64_t b = 0; b < t.size; ++b)
            if (!expectedDifferent[b]) {
                EXPECT_EQ(vulkan[b], emulator[b]) << "byte " << b << " of the " << t.name << " table";
            }
    }
}

class ReferenceSceneTables : public ::testing::TestWithParam<std::string> {};

TEST_P(ReferenceSceneTables, RecordsEqualTheEmulatorsExceptIdentifiersAndRootDescriptors) {
    std::unique_ptr<scenes::Scene> scene = scenes::loadScene(sceneFile(GetParam()));
    CapturedDispatch captured;
    scenes::RenderSettings settings;
    settings.width = 8, settings.height = 4;
    settings.backend = recorder(captured);
    scene->render(settings);
    ASSERT_TRUE(captured.stateObject);
    EXPECT_EQ(captured.desc.Width, 8u);

    const TranslatedShaderTables out =
        translateShaderTables(captured.desc, *captured.stateObject, captured.device->memory(), fakeTranslation());
    expectSameRecords(captured.desc, *captured.stateObject, captured.device->memory(), out);
    EXPECT_EQ(out.hitGroup.records, scene->desc().hitGroupRecords.size());
    EXPECT_EQ(out.miss.records, scene->desc().missRecords.size());
    EXPECT_EQ(out.rayGeneration.records, 1u);
    EXPECT_EQ(out.bytes.size() % 64, 0u);
}

INSTANTIATE_TEST_SUITE_P(ReferenceScenes, ReferenceSceneTables,
                         ::testing::Values("proceduray-mandel-julia-pac.json", "d3d12-procedural-geometry.json"),
                         sceneTestName);

TEST(VulkanShaderTable, BuiltinSceneRecordsEqualTheEmulators) {
    scenes::BuiltinScene scene;
    const TranslatedShaderTables out =
        translateShaderTables(scene.tables(), *scene.pipeline(), scene.device().memory(), fakeTranslation());
    expectSameRecords(scene.tables(), *scene.pipeline(), scene.device().memory(), out);
    EXPECT_EQ(out.hitGroup.records, 4u);
    EXPECT_EQ(out.miss.records, 2u);
}

// A hand-built pipeline whose hit-group records carry root constants, a root SRV and a root CBV, and a null record.
struct RootDescriptorTables {
    dxr::Device device;
    dxr::StateObjectPtr so;
    dxr::DispatchRaysDesc desc;
    dxr::GpuVirtualAddress buffer = 0;

    RootDescriptorTables() {
        struct Payload {
            float x;
        };
        auto library = std::make_shared<dxr::ShaderLibrary>();
        library->addRayGeneration("RG", [](dxr::ShaderContext&) {});
        library->addMiss<Payload>("M", [](dxr::ShaderContext&, Payload&) {});
        library->addClosestHit<Payload, dxr::BuiltInTriangleIntersectionAttributes>(
            "CH", [](dxr::ShaderContext&, Payload&, const dxr::BuiltInTriangleIntersectionAttributes&) {});
        dxr::RootSignatureDesc local;
        local.name = "Local";
        local.flags = dxr::ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
        local.parameters = {dxr::RootParameter::constants(3, 0), dxr::RootParameter::srv(0), dxr::RootParameter::cbv(1)};
        const dxr::RootSignaturePtr signature = dxr::RootSignature::create(local);
        dxr::StateObjectDesc d;
        d.libraries = {{library, {}}};
        d.hitGroups = {{"HG", dxr::HitGroupType::Triangles, "", "CH", ""}};
        d.localRootSignatures = {{signature, {"HG"}}};
        d.shaderConfigs = {{4, 8}};
        d.pipelineConfigs = {{1, 0}};
        so = dxr::StateObject::create(d);

        const std::vector<float> data(64, 1.0f);
        buffer = device.memory().upload(data, "data");
        dxr::GpuMemory& memory = device.memory();
        const auto rg = dxr::ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier("RG")).upload(memory);
        desc.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
        desc.MissShaderTable = dxr::ShaderTableBuilder("miss").addRecord(so->shaderIdentifier("M")).upload(memory);
        dxr::ShaderTableBuilder hits("hit groups");
        for (uint32_t i = 0; i < 3; ++i) {
            dxr::LocalRootArguments args(signature);
            const uint32_t constants[3] = {i, 0xDEADBEEF, 0x12345678};
            args.setConstantBytes(0, constants, sizeof constants);
            args.setDescriptor(1, buffer + 16 * i);
            args.setDescriptor(2, i == 1 ? 0 : buffer + 4);
            hits.addRecord(so->shaderIdentifier("HG"), args);
        }
        hits.addRecord(dxr::ShaderIdentifier{});  // a null record
        desc.HitGroupTable = hits.upload(memory);
    }
};

TEST(VulkanShaderTable, RootDescriptorsBecomeDeviceAddressesAndConstantsStayVerbatim) {
    RootDescriptorTables t;
    const TranslatedShaderTables out = translateShaderTables(t.desc, *t.so, t.device.memory(), fakeTranslation());
    int rootDescriptors = 0;
    expectSameRecords(t.desc, *t.so, t.device.memory(), out, &rootDescriptors);
    EXPECT_EQ(rootDescriptors, 6);  // 2 per non-null record
    EXPECT_EQ(out.hitGroup.records, 4u);
    // Record 2's root SRV: the VA of buffer + 32, moved by the fake offset.
    uint64_t srv = 0;
    std::memcpy(&srv, out.bytes.data() + out.hitGroup.offset + 2 * out.hitGroup.stride + t.so->findEntry("HG")->localRootSignature->argumentOffset(1), 8);
    EXPECT_EQ(srv, t.buffer + 32 + kFakeAddressOffset);
}

TEST(VulkanShaderTable, AppendedRecordIndexSitsAfterTheDxrStride) {
    RootDescriptorTables t;
    ShaderTableTranslation translation = fakeTranslation();
    translation.appendHitGroupRecordIndex = true;
    const TranslatedShaderTables out = translateShaderTables(t.desc, *t.so, t.device.memory(), translation);
    const uint64_t stride = t.desc.HitGroupTable.StrideInBytes;
    EXPECT_EQ(out.hitGroup.stride, (stride + 4 + 31) / 32 * 32);
    EXPECT_EQ(out.recordIndexOffset, stride - 32);
    for (uint32_t i = 0; i < 4; ++i) {
        uint32_t index = 0;
        std::memcpy(&index, out.bytes.data() + out.hitGroup.offset + i * out.hitGroup.stride + stride, 4);
        EXPECT_EQ(index, i);
    }
    // The miss table keeps its DXR stride.
    EXPECT_EQ(out.miss.stride, t.desc.MissShaderTable.StrideInBytes);
}

TEST(VulkanShaderTable, AForeignIdentifierIsAnErrorNamingTheRecord) {
    RootDescriptorTables t;
    RootDescriptorTables other;
    const dxr::ShaderIdentifier foreign = other.so->shaderIdentifier("HG");
    t.device.memory().write(t.desc.HitGroupTable.StartAddress + t.desc.HitGroupTable.StrideInBytes, foreign.data(), 32);
    try {
        translateShaderTables(t.desc, *t.so, t.device.memory(), fakeTranslation());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("record 1 of the hit-group table"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("not one of state object"), std::string::npos) << e.what();
    }
}

TEST(VulkanShaderTable, AStrideVulkanRefusesIsAnError) {
    RootDescriptorTables t;
    t.desc.MissShaderTable.StrideInBytes = 48;
    EXPECT_THROW(translateShaderTables(t.desc, *t.so, t.device.memory(), fakeTranslation()), Error);
}

}  // namespace
}  // namespace refray::gpu
