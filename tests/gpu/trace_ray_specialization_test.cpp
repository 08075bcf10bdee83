// The specialization constants the host gives the GLSL ports: each ray type's TraceRay arguments as the scene has
// them (docs/vulkan-backend.md, "TraceRay arguments a scene overrides become specialization constants").
#include "tools/device_trace_ray.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/vulkan_pipeline.h"
#include "scenes/scene_loader.h"

namespace refray::tools {
namespace {

namespace fs = std::filesystem;
using gpu::TraceRayConstants;
using gpu::TraceRayField;
using gpu::traceRayConstantId;

const fs::path kScenes = fs::path(REFRAY_SOURCE_DIR) / "scenes";

// What the host gives for `scene`: the specialization data of the scene's TraceRay arguments.
gpu::SpecializationData specializationOf(const scenes::SceneDesc& scene) {
    return gpu::specializationData(deviceTraceRayConstants(scene.shaderLibrary, &scene));
}

uint32_t valueOf(const gpu::SpecializationData& data, uint32_t rayType, TraceRayField field) {
    const std::optional<uint32_t> v = data.valueOf(traceRayConstantId(rayType, field));
    EXPECT_TRUE(v) << "no constant for ray type " << rayType << " field " << uint32_t(field);
    return v.value_or(0xDEADBEEFu);
}

TEST(VulkanTraceRaySpecialization, ConstantIdsLeaveTheAovOffsetAlone) {
    EXPECT_EQ(traceRayConstantId(0, TraceRayField::RayContribution), 16u);
    EXPECT_EQ(traceRayConstantId(0, TraceRayField::InstanceInclusionMask), 19u);
    EXPECT_EQ(traceRayConstantId(1, TraceRayField::RayContribution), 32u);
    EXPECT_EQ(traceRayConstantId(1, TraceRayField::InstanceInclusionMask), 35u);
    const gpu::SpecializationData data = gpu::specializationData({{0, 2, 0, 0xFF}, {1, 2, 1, 0xFF}}, 40);
    EXPECT_EQ(data.valueOf(gpu::kRecordIndexOffsetConstantId), 40u);
    ASSERT_EQ(data.entries.size(), 9u);
    std::set<uint32_t> ids, offsets;
    for (const VkSpecializationMapEntry& e : data.entries) {
        EXPECT_TRUE(ids.insert(e.constantID).second) << "constant_id " << e.constantID << " twice";
        EXPECT_TRUE(offsets.insert(e.offset).second);
        EXPECT_EQ(e.size, sizeof(uint32_t));
        EXPECT_LT(e.offset, data.values.size() * sizeof(uint32_t));
    }
    const VkSpecializationInfo info = data.info();
    EXPECT_EQ(info.mapEntryCount, 9u);
    EXPECT_EQ(info.dataSize, 9 * sizeof(uint32_t));
}

// The lesson patches both ray types with "traceRay": {"multiplier": 1}; the GPU must trace with M = 1 too.
TEST(VulkanTraceRaySpecialization, MultiplierOneLessonGivesMOne) {
    const scenes::SceneDesc lesson = scenes::loadSceneFile(kScenes / "lessons" / "multiplier-one.json");
    ASSERT_EQ(lesson.shaderLibrary, "d3d12-procedural-geometry");
    const gpu::SpecializationData data = specializationOf(lesson);
    for (uint32_t r = 0; r < 2; ++r) {
        EXPECT_EQ(valueOf(data, r, TraceRayField::Multiplier), 1u) << "ray type " << r;
        EXPECT_EQ(valueOf(data, r, TraceRayField::RayContribution), r);
        EXPECT_EQ(valueOf(data, r, TraceRayField::MissShaderIndex), r);
        EXPECT_EQ(valueOf(data, r, TraceRayField::InstanceInclusionMask) & 0xFFu, 0xFFu);
    }
}

// The reference scenes override nothing: the HLSL's arguments, R = r, M = 2, miss index r, mask ~0 (the GLSL
// defaults, so a pipeline given them means the same as one given none).
TEST(VulkanTraceRaySpecialization, ReferenceScenesGiveTheHlslArguments) {
    for (const char* file : {"d3d12-procedural-geometry.json", "proceduray-mandel-julia-pac.json"}) {
        SCOPED_TRACE(file);
        const gpu::SpecializationData data = specializationOf(scenes::loadSceneFile(kScenes / file));
        for (uint32_t r = 0; r < 2; ++r) {
            EXPECT_EQ(valueOf(data, r, TraceRayField::RayContribution), r);
            EXPECT_EQ(valueOf(data, r, TraceRayField::Multiplier), 2u);
            EXPECT_EQ(valueOf(data, r, TraceRayField::MissShaderIndex), r);
            EXPECT_EQ(valueOf(data, r, TraceRayField::InstanceInclusionMask), ~0u);
        }
    }
    // The built-in scene has no scene file: its C++ shaders' fixed arguments.
    EXPECT_EQ(deviceTraceRayConstants("builtin", nullptr),
              (std::vector<TraceRayConstants>{{0, 2, 0, 0xFF}, {1, 2, 1, 0xFF}}));
}

// The path tracer's scenes: the C++ library's fixed arguments (R = ray type, M = 2, miss = ray type, mask 0xFF), which
// are also the GLSL port's defaults (gpu/shaders/dxr-path-tracer/pathtracer.glsl).
TEST(VulkanTraceRaySpecialization, PathTracerScenesGiveTheLibrarysFixedArguments) {
    for (const char* file : {"cornell-box.json", "textured-room.json"}) {
        SCOPED_TRACE(file);
        const scenes::SceneDesc scene = scenes::loadSceneFile(kScenes / file);
        EXPECT_EQ(deviceTraceRayConstants(scene.shaderLibrary, &scene),
                  (std::vector<TraceRayConstants>{{0, 2, 0, 0xFF}, {1, 2, 1, 0xFF}}));
    }
}

TEST(VulkanTraceRaySpecialization, RefusesWhatItCannotDetermine) {
    EXPECT_THROW(deviceTraceRayConstants("d3d12-procedural-geometry", nullptr), Error);
    const scenes::SceneDesc d3d12 = scenes::loadSceneFile(kScenes / "d3d12-procedural-geometry.json");
    EXPECT_THROW(deviceTraceRayConstants("proceduray", &d3d12), Error);
    scenes::SceneDesc threeRayTypes = d3d12;
    threeRayTypes.rayTypes.push_back(threeRayTypes.rayTypes.back());
    EXPECT_THROW(deviceTraceRayConstants(threeRayTypes.shaderLibrary, &threeRayTypes), Error);
}

// Every OpTraceRayKHR of every compiled GLSL port takes its cull mask, SBT offset, SBT stride and miss index from
// specialization constants decorated SpecId traceRayConstantId(r, field), so no library hard-codes them.
TEST(VulkanTraceRaySpecialization, EveryTraceRayReadsSpecializationConstants) {
    constexpr uint32_t kOpDecorate = 71, kDecorationSpecId = 1, kOpTraceRayKHR = 4445;
    size_t traces = 0;
    for (const char* library : {"builtin", "d3d12-procedural-geometry", "proceduray", "dxr-path-tracer"}) {
        for (const fs::directory_entry& f : fs::directory_iterator(fs::path(REFRAY_SPIRV_DIR) / library)) {
            if (f.path().extension() != ".spv") continue;
            SCOPED_TRACE(f.path().string());
            std::ifstream in(f.path(), std::ios::binary);
            std::vector<uint32_t> words;
            for (uint32_t w; in.read(reinterpret_cast<char*>(&w), sizeof w);) words.push_back(w);
            ASSERT_GE(words.size(), 5u);
            std::map<uint32_t, uint32_t> specId;  // result id -> SpecId
            std::vector<std::vector<uint32_t>> traceOperands;
            for (size_t i = 5; i < words.size();) {
                const uint32_t count = words[i] >> 16, op = words[i] & 0xFFFFu;
                ASSERT_GT(count, 0u);
                if (op == kOpDecorate && count >= 4 && words[i + 2] == kDecorationSpecId)
                    specId[words[i + 1]] = words[i + 3];
                if (op == kOpTraceRayKHR) traceOperands.emplace_back(words.begin() + i + 1, words.begin() + i + count);
                i += count;
            }
            for (const std::vector<uint32_t>& t : traceOperands) {
                ++traces;
                ASSERT_GE(t.size(), 6u);
                // accel, flags, cull mask, SBT offset, SBT stride, miss index, ...
                const uint32_t mask = specId.count(t[2]) ? specId[t[2]] : 0;
                const uint32_t rayType = mask / gpu::kTraceRayConstantStride - 1;
                EXPECT_EQ(mask, traceRayConstantId(rayType, TraceRayField::InstanceInclusionMask));
                EXPECT_EQ(specId[t[3]], traceRayConstantId(rayType, TraceRayField::RayContribution));
                EXPECT_EQ(specId[t[4]], traceRayConstantId(rayType, TraceRayField::Multiplier));
                EXPECT_EQ(specId[t[5]], traceRayConstantId(rayType, TraceRayField::MissShaderIndex));
            }
        }
    }
    EXPECT_GT(traces, 0u);
}

}  // namespace
}  // namespace refray::tools
