// Tests the recorded GPU round (tests/gpu-renders/, written by tools/gpu_crosscheck.sh --import) against refray:
// its index maps equal refray's outside order-dependent pixels, its images pass their envelope goldens
// (docs/compare.md). No GPU needed.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "core/compare.h"
#include "core/envelope.h"
#include "core/image.h"
#include "core/json.h"
#include "core/statistical_compare.h"
#include "inspect/index_map.h"
#include "inspect/map_crosscheck.h"
#include "scenes/scene.h"
#include "verify/golden.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
const fs::path kRoot = REFRAY_SOURCE_DIR;
const fs::path kRenders = kRoot / "tests/gpu-renders";
const fs::path kGoldens = kRoot / "tests/golden";

struct Recorded {
    std::string what, name, scene, camera, time, size, precision, aov, file;
};

struct Round {
    json::Value provenance;
    std::vector<Recorded> renders;  // those the round rendered
};

std::string member(const json::Value& v, std::string_view key) {
    const json::Value* m = v.find(key);
    return m ? m->asString() : "";
}

Round readRound() {
    Round round;
    const fs::path path = kRenders / "provenance.json";
    if (!fs::exists(path)) return round;
    round.provenance = json::parseFile(path);
    for (const json::Value& r : round.provenance.find("renders")->asArray()) {
        if (!r.find("rendered")->asBool()) continue;
        round.renders.push_back({member(r, "what"), member(r, "name"), member(r, "scene"), member(r, "camera"),
                                 member(r, "time"), member(r, "size"), member(r, "precision"), member(r, "aov"),
                                 member(r, "file")});
    }
    return round;
}

const Round& round() {
    static const Round r = readRound();
    return r;
}

RenderSettings settingsOf(const Recorded& r) {
    RenderSettings s;
    const size_t x = r.size.find('x');
    s.width = uint32_t(std::stoul(r.size.substr(0, x)));
    s.height = uint32_t(std::stoul(r.size.substr(x + 1)));
    s.threads = 2;
    if (r.camera != "-") s.camera = r.camera;
    if (r.time != "-") s.time = json::parse(r.time, "the time of " + r.name).asFloat();
    return s;
}

TEST(GpuRenders, TheRoundIsRecorded) {
    ASSERT_TRUE(fs::exists(kRenders / "provenance.json"))
        << "the GPU renders are missing: tests/gpu-renders/provenance.json does not exist. Run "
           "tools/gpu_crosscheck.sh on a machine with a ray-tracing GPU and import its tar with "
           "tools/gpu_crosscheck.sh --import (docs/gpu-crosscheck.md)";
    const json::Value& p = round().provenance;
    EXPECT_FALSE(member(p, "gpu").empty()) << "provenance.json names no GPU";
    EXPECT_FALSE(member(p, "gpuDriver").empty()) << "provenance.json names no driver";
    EXPECT_FALSE(member(p, "vulkanAPI").empty()) << "provenance.json names no Vulkan API version";
    EXPECT_TRUE(std::any_of(round().renders.begin(), round().renders.end(),
                            [](const Recorded& r) { return r.what == "image"; }))
        << "the GPU renders are missing: provenance.json lists no rendered image";
    for (const Recorded& r : round().renders) EXPECT_TRUE(fs::exists(kRenders / r.file)) << r.file;
}

// The indexing rule on hardware (inspect/map_crosscheck.h): where the GPU's primary ray hit the same object as
// refray's, the record must be R + M*G + C; another object is legal only on order-dependent pixels and silhouettes.
TEST(GpuRenders, EveryMapEqualsRefraysOutsideOrderDependentPixels) {
    std::map<std::string, std::vector<const Recorded*>> bySetting;  // one CPU render per setting gives every map
    for (const Recorded& r : round().renders)
        if (r.what == "map") bySetting[r.name].push_back(&r);
    ASSERT_FALSE(bySetting.empty()) << "this GPU round (" << member(round().provenance, "date")
                                    << ") recorded no index maps; import a round of tools/gpu_crosscheck.sh";
    const std::vector<GoldenEntry> goldens = readGoldenManifest(kGoldens / "goldens.json").entries;
    for (const auto& [name, maps] : bySetting) {
        SCOPED_TRACE(name);
        auto scene = loadScene((kRoot / maps.front()->scene).string());
        const RenderSettings settings = settingsOf(*maps.front());
        const auto golden = std::find_if(goldens.begin(), goldens.end(), [&](const GoldenEntry& g) { return g.name == name; });
        const std::vector<uint8_t> goldenMask = golden != goldens.end() && golden->width == settings.width &&
                                                        golden->height == settings.height
                                                    ? readEnvelope((kGoldens / golden->envelope).string()).orderDependent
                                                    : std::vector<uint8_t>();
        IndexMapsByKind gpu;
        for (const Recorded* r : maps)
            gpu[*parseIndexMapKind(r->aov)] = readIndexValues(readImage((kRenders / r->file).string()));
        for (IndexMapKind kind : {IndexMapKind::Record, IndexMapKind::Instance, IndexMapKind::Geometry, IndexMapKind::Primitive})
            ASSERT_TRUE(gpu.contains(kind)) << name << ": the round lacks its " << indexMapKindNames()[size_t(kind)] << " map";
        const MapCrosscheck check = crosscheckIndexMaps(*scene, settings, gpu, goldenMask);
        std::printf("%s\n%s", check.summary(name).c_str(), check.exceptions().c_str());
        EXPECT_TRUE(check.passed()) << name << ": " << check.failures();
    }
}

// A GPU is one correct implementation that the envelopes were not made from: each of its renders must pass its
// envelope golden (docs/compare.md, "Envelope goldens"), as a GPU team's CI would judge it.
TEST(GpuRenders, EveryImagePassesItsEnvelopeGolden) {
    const std::vector<GoldenEntry> goldens = readGoldenManifest(kGoldens / "goldens.json").entries;
    const fs::path out = fs::path(REFRAY_TEST_OUTPUT_DIR) / "gpu-renders";
    uint64_t judged = 0;
    for (const Recorded& r : round().renders) {
        if (r.what != "image") continue;
        SCOPED_TRACE(r.name);
        const auto golden = std::find_if(goldens.begin(), goldens.end(), [&](const GoldenEntry& g) { return g.name == r.name; });
        ASSERT_NE(golden, goldens.end()) << "no golden named " << r.name << " in tests/golden/goldens.json";
        const Envelope envelope = readEnvelope((kGoldens / golden->envelope).string());
        const Image actual = readImage((kRenders / r.file).string());
        const EnvelopeJudgement j = judgeEnvelope(envelope, actual, {});
        ASSERT_NE(j.verdict, CompareVerdict::Mismatch) << j.mismatch;
        ++judged;
        std::printf("%s: %llu stable pixels moved (allowed %llu), %llu sensitive outside (allowed %llu)\n",
                    r.name.c_str(), (unsigned long long)j.stableOutside, (unsigned long long)j.stableBudget,
                    (unsigned long long)j.sensitiveOutside, (unsigned long long)j.sensitiveBudget);
        if (j.verdict != CompareVerdict::Fail) continue;
        fs::create_directories(out);
        writeImage((out / (r.name + ".gpu.exr")).string(), actual);
        writeImage((out / (r.name + ".heat.png")).string(), j.heatMap);
        ADD_FAILURE() << r.name << ": the GPU render fails its envelope golden " << golden->envelope << "\n"
                      << j.describe(20) << "  GPU render and heat map written to " << out.string();
    }
    EXPECT_GT(judged, 0u) << "the round recorded no image";
}

// The path tracer on a GPU: each statistical golden's scene, re-rendered on the GPU as a statistics image with other
// seeds (tools/gpu_crosscheck.sh, `--spp S --batches K --seed 100`), must pass `refray compare --statistical` against
// the CPU emulator's golden (docs/compare.md, "Statistical comparison"). A round recorded before the GPU ran the path
// tracer has no such render: the test then says so and checks nothing else.
TEST(GpuRenders, EveryPathTracedRenderPassesItsStatisticalGolden) {
    const std::vector<StatisticalGoldenEntry> goldens = readGoldenManifest(kGoldens / "goldens.json").statistical;
    uint64_t judged = 0;
    for (const Recorded& r : round().renders) {
        if (r.what != "stats") continue;
        SCOPED_TRACE(r.name);
        const auto golden = std::find_if(goldens.begin(), goldens.end(),
                                         [&](const StatisticalGoldenEntry& g) { return g.name == r.name; });
        ASSERT_NE(golden, goldens.end()) << "no statistical golden named " << r.name << " in tests/golden/goldens.json";
        const StatisticsImage reference = readStatisticsImage((kGoldens / golden->image).string());
        const StatisticsImage candidate = readStatisticsImage((kRenders / r.file).string());
        EXPECT_EQ(candidate.mean.metadata.at("device"), "vulkan") << r.file << " is not a device render";
        const StatisticalCompareResult result = compareStatistics(reference, candidate);
        ++judged;
        std::printf("%s: %llu of %llu pixel-channel tests below the corrected threshold %.3g; smallest p %.3g\n",
                    r.name.c_str(), (unsigned long long)result.failingTests, (unsigned long long)result.tests,
                    result.threshold, result.smallest.test.p);
        EXPECT_EQ(result.verdict, CompareVerdict::Pass) << r.name << ": the GPU's path-traced render fails its "
                                                        << "statistical golden " << golden->image << "\n"
                                                        << result.describe();
    }
    if (judged == 0)
        std::printf("this GPU round (%s) recorded no path-traced render\n", member(round().provenance, "date").c_str());
}

}  // namespace
}  // namespace refray::scenes
