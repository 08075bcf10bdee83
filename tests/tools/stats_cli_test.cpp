// refray render --stats and --stats-json (format refray-stats/1) on the D3D12 procedural-geometry scene.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "core/json.h"
#include "tests/tools/cli_run.h"

namespace {

using refray::testing::CliRun;

const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

CliRun run(const std::string& arguments) { return refray::testing::runRefray(arguments); }

std::string outputPath(const std::string& name) {
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    return std::string(REFRAY_TEST_OUTPUT_DIR) + "/" + name;
}

using refray::testing::contains;

const refray::json::Value& member(const refray::json::Value& object, const std::string& key) {
    const refray::json::Value* v = object.find(key);
    if (!v) object.fail("no member '" + key + "'");
    return *v;
}

// The "rays" of {"depth": d, "rays": n} in an array of them (0 if that depth is absent).
uint64_t raysAtDepth(const refray::json::Value& perDepth, int64_t depth) {
    for (const refray::json::Value& d : perDepth.asArray())
        if (member(d, "depth").asInt() == depth) return uint64_t(member(d, "rays").asInt());
    return 0;
}

}  // namespace

TEST(StatsCli, RenderStatsPrintsAndWritesRayTypesExportsAndStageTimes) {
    const std::string image = outputPath("stats.png"), json = outputPath("stats.json");
    std::filesystem::remove(json);
    const CliRun r = run("render " + kD3D12 + " -o " + image + " --size 32x18 --threads 2 --stats --stats-json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string& text = r.output;

    // Text: one primary ray per pixel, of ray type Radiance (R=0, miss 0); shadow rays (R=1, miss 1) at depth 2.
    EXPECT_TRUE(contains(text, "render: 32x18 in ")) << text;
    EXPECT_TRUE(contains(text, "rays at depth 1: 576\n")) << text;
    EXPECT_TRUE(contains(text, "rays per type (R = RayContributionToHitGroupIndex & 0xF, miss = MissShaderIndex) and depth:"))
        << text;
    EXPECT_TRUE(contains(text, "    R=0 miss=0 ")) << text;
    EXPECT_TRUE(contains(text, "    R=1 miss=1 ")) << text;
    EXPECT_TRUE(contains(text, "  invocations per export:\n")) << text;
    EXPECT_TRUE(contains(text, "    raygeneration MyRaygenShader: 576\n")) << text;
    EXPECT_TRUE(contains(text, "    intersection  MyIntersectionShader_AnalyticPrimitive: ")) << text;
    EXPECT_TRUE(contains(text, "    closesthit    MyClosestHitShader_AABB: ")) << text;
    EXPECT_TRUE(contains(text, "    miss          MyMissShader_ShadowRay: ")) << text;
    EXPECT_TRUE(contains(text, "  time per stage")) << text;
    EXPECT_TRUE(contains(text, "wrote " + json)) << text;

    // JSON.
    const refray::json::Value doc = refray::json::parseFile(json);
    EXPECT_EQ(member(doc, "format").asString(), "refray-stats/1");
    EXPECT_EQ(member(doc, "scene").asString(), kD3D12);
    EXPECT_EQ(member(doc, "width").asInt(), 32);
    EXPECT_EQ(member(doc, "height").asInt(), 18);
    EXPECT_GT(member(doc, "wallSeconds").asNumber(), 0.0);
    EXPECT_GT(member(doc, "raysPerSecond").asNumber(), 0.0);
    const uint64_t rays = uint64_t(member(doc, "raysTraced").asInt());
    EXPECT_TRUE(contains(text, " s, " + std::to_string(rays) + " rays (")) << text;
    EXPECT_EQ(raysAtDepth(member(doc, "raysPerDepth"), 1), 576u);

    // Rays per type add up to the rays per depth.
    std::map<int64_t, uint64_t> typedPerDepth;
    uint64_t typed = 0, primary = 0, shadow = 0;
    for (const refray::json::Value& t : member(doc, "rayTypes").asArray()) {
        const int64_t contribution = member(t, "rayContribution").asInt(), miss = member(t, "missShaderIndex").asInt();
        typed += uint64_t(member(t, "rays").asInt());
        for (const refray::json::Value& d : member(t, "raysPerDepth").asArray())
            typedPerDepth[member(d, "depth").asInt()] += uint64_t(member(d, "rays").asInt());
        if (contribution == 0 && miss == 0) primary = raysAtDepth(member(t, "raysPerDepth"), 1);
        if (contribution == 1 && miss == 1) shadow = uint64_t(member(t, "rays").asInt());
    }
    EXPECT_EQ(typed, rays);
    EXPECT_EQ(primary, 576u);
    EXPECT_GT(shadow, 0u);
    for (const auto& [depth, n] : typedPerDepth) EXPECT_EQ(n, raysAtDepth(member(doc, "raysPerDepth"), depth)) << depth;

    // Invocations per export add up to the invocations per stage.
    std::map<std::string, uint64_t> perStage;
    uint64_t raygen = 0, analytic = 0;
    for (const refray::json::Value& e : member(doc, "invocationsPerExport").asArray()) {
        const std::string& name = member(e, "export").asString();
        const uint64_t count = uint64_t(member(e, "count").asInt());
        perStage[member(e, "stage").asString()] += count;
        if (name == "MyRaygenShader") raygen = count;
        if (name == "MyIntersectionShader_AnalyticPrimitive") analytic = count;
        EXPECT_TRUE(contains(text, name + ": " + std::to_string(count) + "\n")) << name;
    }
    EXPECT_EQ(raygen, 576u);
    EXPECT_GT(analytic, 0u);
    for (const refray::json::Member& s : member(doc, "invocations").asObject())
        EXPECT_EQ(uint64_t(s.value.asInt()), perStage[s.key]) << s.key;
    EXPECT_GT(perStage["closesthit"], 0u);
    EXPECT_GT(perStage["miss"], 0u);

    // The effect set (scenes/effects.h): printed after the counts and listed in the JSON, simulated first.
    EXPECT_TRUE(contains(text, "  effects:\n    simulated: triangles - ")) << text;
    EXPECT_TRUE(contains(text, "    skipped: any-hit shaders - ")) << text;
    std::map<std::string, bool> effects;
    for (const refray::json::Value& e : member(doc, "effects").asArray())
        effects[member(e, "name").asString()] = member(e, "simulated").asBool();
    EXPECT_TRUE(effects.at("shadow rays"));
    EXPECT_FALSE(effects.at("any-hit shaders"));

    // Stage times: when profiled, shares of a positive total that add up to 1; otherwise all zero.
    const refray::json::Value& times = member(doc, "stageTimes");
    const bool profiled = member(times, "profiled").asBool();
    EXPECT_EQ(contains(text, "  time per stage (exclusive, summed over worker threads): "), profiled) << text;
    double seconds = 0.0, shares = 0.0;
    std::map<std::string, double> stageSeconds;
    for (const refray::json::Value& s : member(times, "stages").asArray()) {
        stageSeconds[member(s, "stage").asString()] = member(s, "seconds").asNumber();
        seconds += member(s, "seconds").asNumber();
        shares += member(s, "share").asNumber();
    }
    EXPECT_EQ(stageSeconds.size(), 8u);  // the six shader stages, traversal, compute
    EXPECT_NEAR(seconds, member(times, "exclusiveSecondsSummedOverThreads").asNumber(), 1e-6);
    if (profiled) {
        EXPECT_NEAR(shares, 1.0, 1e-6);
        EXPECT_GT(stageSeconds["traversal"], 0.0);
        EXPECT_GT(stageSeconds["intersection"], 0.0);
        EXPECT_GT(stageSeconds["closesthit"], 0.0);
        EXPECT_LE(seconds, 2.0 * member(doc, "wallSeconds").asNumber() * 1.1);  // --threads 2
        EXPECT_TRUE(contains(text, "    traversal ")) << text;
    } else {
        EXPECT_EQ(seconds, 0.0);
        EXPECT_TRUE(contains(text, "  time per stage: not measured\n")) << text;
    }
}

TEST(StatsCli, StatsJsonAloneWritesTheFileWithoutPrinting) {
    const std::string image = outputPath("stats-only-json.png"), json = outputPath("stats-only.json");
    std::filesystem::remove(json);
    const CliRun r = run("render builtin -o " + image + " --size 16x8 --stats-json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_FALSE(contains(r.output, "invocations per export")) << r.output;
    const refray::json::Value doc = refray::json::parseFile(json);
    EXPECT_EQ(member(doc, "format").asString(), "refray-stats/1");
    EXPECT_EQ(raysAtDepth(member(doc, "raysPerDepth"), 1), 128u);
}

TEST(StatsCli, UnwritableStatsJsonNamesTheFile) {
    const CliRun r = run("render builtin -o " + outputPath("stats-bad.png") + " --size 8x8 --stats-json /proc/refray-stats.json");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "/proc/refray-stats.json")) << r.output;
}
