// Tests the recorded GPU round (tests/gpu-renders/, written by tools/gpu_crosscheck.sh --import) against refray:
// its index maps equal refray's outside order-dependent pixels, its images pass their goldens within the interim
// per-scene bounds of docs/gpu-crosscheck.md. No GPU needed.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/compare.h"
#include "core/image.h"
#include "core/json.h"
#include "inspect/index_map.h"
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

// The bound column of docs/gpu-crosscheck.md's table: "| `NAME` | 3.5 % | ...".
std::map<std::string, double> documentedBounds() {
    std::ifstream doc(kRoot / "docs/gpu-crosscheck.md");
    std::map<std::string, double> bounds;
    for (std::string line; std::getline(doc, line);) {
        if (line.rfind("| `", 0) != 0) continue;
        const size_t end = line.find('`', 3);
        const size_t bar = line.find('|', end);
        const std::string cell = line.substr(bar + 1, line.find('|', bar + 1) - bar - 1);
        if (cell.find('%') == std::string::npos) continue;
        bounds[line.substr(3, end - 3)] = std::stod(cell);
    }
    return bounds;
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

std::string pixelName(size_t i, uint32_t width) {
    std::ostringstream name;
    name << '(' << i % width << ',' << i / width << ')';
    return name.str();
}

TEST(GpuRenders, EveryMapEqualsRefraysOutsideOrderDependentPixels) {
    std::map<std::string, std::vector<const Recorded*>> bySetting;  // one CPU render per setting gives every map
    for (const Recorded& r : round().renders)
        if (r.what == "map") bySetting[r.name].push_back(&r);
    if (bySetting.empty())
        GTEST_SKIP() << "this GPU round (" << member(round().provenance, "date")
                     << ") recorded no index maps; import a round of tools/gpu_crosscheck.sh";
    const std::vector<GoldenEntry> goldens = readGoldenManifest(kGoldens / "goldens.json").entries;
    for (const auto& [name, maps] : bySetting) {
        SCOPED_TRACE(name);
        auto scene = loadScene((kRoot / maps.front()->scene).string());
        const RenderSettings settings = settingsOf(*maps.front());
        const std::vector<PrimaryHit> hits = renderPrimaryHits(*scene, settings);
        // Order-dependent pixels: where the maps change under adversarial orders, and the golden's mask.
        std::vector<std::vector<PrimaryHit>> adversarial;
        for (uint64_t seed : {1, 2}) {
            RenderSettings s = settings;
            s.order = dxr::TraversalOrder::Adversarial;
            s.adversarialSeed = seed;
            adversarial.push_back(renderPrimaryHits(*scene, s));
        }
        const auto golden = std::find_if(goldens.begin(), goldens.end(), [&](const GoldenEntry& g) { return g.name == name; });
        const Image goldenMask = golden != goldens.end() && golden->width == settings.width && golden->height == settings.height
                                     ? readImage((kGoldens / golden->mask).string())
                                     : Image();
        for (const Recorded* r : maps) {
            const IndexMapKind kind = *parseIndexMapKind(r->aov);
            const std::vector<int64_t> cpu = indexMapOf(scene->desc(), settings.width, settings.height, kind, hits).values;
            std::vector<std::vector<int64_t>> others;
            for (const auto& a : adversarial)
                others.push_back(indexMapOf(scene->desc(), settings.width, settings.height, kind, a).values);
            const std::vector<int64_t> gpu = readIndexValues(readImage((kRenders / r->file).string()));
            ASSERT_EQ(gpu.size(), cpu.size()) << r->file;
            std::ostringstream differing;
            uint64_t count = 0, masked = 0;
            for (size_t i = 0; i < cpu.size(); ++i) {
                if (gpu[i] == cpu[i]) continue;
                const bool orderDependent =
                    std::any_of(others.begin(), others.end(), [&](const auto& o) { return o[i] != cpu[i]; }) ||
                    (goldenMask.width() > 0 && goldenMask.pixels()[i].r > 0.0f);
                if (orderDependent) { ++masked; continue; }
                if (++count <= 40) differing << "  " << pixelName(i, settings.width) << " GPU " << gpu[i] << ", refray " << cpu[i] << "\n";
            }
            EXPECT_EQ(count, 0u) << r->file << ": " << count << " pixels differ outside order-dependent pixels ("
                                 << masked << " differ inside them); the first:\n"
                                 << differing.str();
        }
    }
}

TEST(GpuRenders, EveryImagePassesItsGoldenWithinItsBound) {
    const std::map<std::string, double> bounds = documentedBounds();
    const std::vector<GoldenEntry> goldens = readGoldenManifest(kGoldens / "goldens.json").entries;
    const fs::path out = fs::path(REFRAY_TEST_OUTPUT_DIR) / "gpu-renders";
    for (const Recorded& r : round().renders) {
        if (r.what != "image") continue;
        SCOPED_TRACE(r.name);
        const auto golden = std::find_if(goldens.begin(), goldens.end(), [&](const GoldenEntry& g) { return g.name == r.name; });
        ASSERT_NE(golden, goldens.end()) << "no golden named " << r.name << " in tests/golden/goldens.json";
        const auto bound = bounds.find(r.name);
        ASSERT_NE(bound, bounds.end()) << "docs/gpu-crosscheck.md gives no bound for " << r.name;
        const Image expected = readImage((kGoldens / golden->image).string());
        const Image mask = readImage((kGoldens / golden->mask).string());
        const Image actual = readImage((kRenders / r.file).string());
        const CompareThresholds thresholds = CompareThresholds::golden();
        const CompareResult result = compareImages(expected, actual, thresholds, &mask);
        ASSERT_NE(result.verdict, CompareVerdict::Mismatch) << result.mismatch;
        if (result.failingPercent() <= bound->second) continue;
        // Which pixels fail: outside the mask, some RGB channel off by more than the threshold.
        std::ostringstream failing;
        uint64_t listed = 0;
        for (uint32_t y = 0; y < actual.height() && listed < 40; ++y)
            for (uint32_t x = 0; x < actual.width() && listed < 40; ++x) {
                if (mask.at(x, y).r > 0.0f) continue;
                const vec4 a = actual.at(x, y), e = expected.at(x, y);
                const float d = std::max({std::abs(a.r - e.r), std::abs(a.g - e.g), std::abs(a.b - e.b)});
                if (!(d <= thresholds.fail)) {
                    ++listed;
                    failing << "  (" << x << "," << y << ") GPU (" << a.r << ", " << a.g << ", " << a.b << "), golden ("
                            << e.r << ", " << e.g << ", " << e.b << ")\n";
                }
            }
        fs::create_directories(out);
        writeImage((out / (r.name + ".gpu.exr")).string(), actual);
        writeImage((out / (r.name + ".golden.exr")).string(), expected);
        writeImage((out / (r.name + ".diff.png")).string(), result.diffImage);
        ADD_FAILURE() << r.name << ": " << result.failingPercent() << " % of the pixels fail, over the bound "
                      << bound->second << " % of docs/gpu-crosscheck.md\n"
                      << result.describe() << "  the first failing pixels:\n"
                      << failing.str() << "  GPU render, golden and diff written to " << out.string();
    }
}

}  // namespace
}  // namespace refray::scenes
