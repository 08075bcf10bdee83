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

// What a pixel's primary ray hit, as (instance, geometry, primitive); -1 everywhere for a miss.
struct HitObject {
    int64_t instance = -1, geometry = -1, primitive = -1;
    friend bool operator==(const HitObject&, const HitObject&) = default;
};

using MapsByKind = std::map<IndexMapKind, std::vector<int64_t>>;

// Seeded adversarial orders that find refray's order-dependent pixels. With 2, the GPU's own order (its BVH
// traversal) still reached 28 pixels of the Mandelbulb close-up that no seed had flagged, next to the 423 the
// golden's 4 orders mark: where Pac-man B's and the Mandelbulb's boxes overlap, and the Proceduray intersection
// shaders report t in object units (hazard H1), so which one commits depends on the order. With 8, and the
// region's 8-neighbourhood, none is left.
constexpr uint64_t kAdversarialOrders = 8;

std::vector<HitObject> hitObjects(const MapsByKind& maps, size_t pixels) {
    std::vector<HitObject> objects(pixels);
    for (size_t i = 0; i < pixels; ++i)
        objects[i] = {maps.at(IndexMapKind::Instance)[i], maps.at(IndexMapKind::Geometry)[i],
                      maps.at(IndexMapKind::Primitive)[i]};
    return objects;
}

// A silhouette pixel: one of its 8 neighbours in refray's map shows another object. There the edge between two
// objects crosses the pixel's neighbourhood, and a one-ulp difference in a distance or a root moves the edge by a
// pixel: which object the centre ray hits is then a numerical accident, not a DXR rule.
bool anyNeighbour(size_t i, uint32_t width, uint32_t height, const std::function<bool(size_t)>& test) {
    const int64_t x = int64_t(i % width), y = int64_t(i / width);
    for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
            const int64_t nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= int64_t(width) || ny >= int64_t(height)) continue;
            if (test(size_t(ny) * width + size_t(nx))) return true;
        }
    return false;
}

bool onSilhouette(const std::vector<HitObject>& cpu, size_t i, uint32_t width, uint32_t height) {
    return anyNeighbour(i, width, height, [&](size_t n) { return !(cpu[n] == cpu[i]); });
}

// The indexing rule on hardware. Where the GPU's primary ray hit the same (instance, geometry, primitive) as
// refray's, the hit-group record it used must be the same: R + M*G + C, with no exception. Where it hit another
// object, the pixel must be order-dependent (DXR leaves the order of intersection-shader calls open) or lie on a
// silhouette of refray's map (docs/gpu-crosscheck.md, "Index maps"); a different object anywhere else fails.
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
        const uint32_t width = settings.width, height = settings.height;
        const size_t pixels = size_t(width) * height;
        const std::vector<PrimaryHit> hits = renderPrimaryHits(*scene, settings);
        // Order-dependent pixels: where refray's maps change under adversarial orders, and the golden's mask.
        std::vector<std::vector<PrimaryHit>> adversarial;
        for (uint64_t seed = 1; seed <= kAdversarialOrders; ++seed) {
            RenderSettings s = settings;
            s.order = dxr::TraversalOrder::Adversarial;
            s.adversarialSeed = seed;
            adversarial.push_back(renderPrimaryHits(*scene, s));
        }
        const auto golden = std::find_if(goldens.begin(), goldens.end(), [&](const GoldenEntry& g) { return g.name == name; });
        const std::vector<uint8_t> goldenMask = golden != goldens.end() && golden->width == width &&
                                                        golden->height == height
                                                    ? readEnvelope((kGoldens / golden->envelope).string()).orderDependent
                                                    : std::vector<uint8_t>();
        MapsByKind cpu, gpu;
        std::vector<MapsByKind> others(adversarial.size());
        for (const Recorded* r : maps) {
            const IndexMapKind kind = *parseIndexMapKind(r->aov);
            cpu[kind] = indexMapOf(scene->desc(), width, height, kind, hits).values;
            for (size_t a = 0; a < adversarial.size(); ++a)
                others[a][kind] = indexMapOf(scene->desc(), width, height, kind, adversarial[a]).values;
            gpu[kind] = readIndexValues(readImage((kRenders / r->file).string()));
            ASSERT_EQ(gpu[kind].size(), pixels) << r->file;
        }
        for (IndexMapKind kind : {IndexMapKind::Record, IndexMapKind::Instance, IndexMapKind::Geometry, IndexMapKind::Primitive})
            ASSERT_TRUE(gpu.contains(kind)) << name << ": the round lacks its " << indexMapKindNames()[size_t(kind)] << " map";
        const std::vector<HitObject> cpuObjects = hitObjects(cpu, pixels), gpuObjects = hitObjects(gpu, pixels);
        std::vector<std::vector<HitObject>> otherObjects;
        for (const MapsByKind& o : others) otherObjects.push_back(hitObjects(o, pixels));

        // Where refray's own hit depends on the order, and the edge of that region: the GPU's order is one that
        // finitely many seeds need not reach, and the region's edge moves by a pixel as a silhouette does.
        std::vector<bool> masked(pixels);
        for (size_t i = 0; i < pixels; ++i)
            masked[i] = (!goldenMask.empty() && goldenMask[i] != 0) ||
                        std::any_of(otherObjects.begin(), otherObjects.end(),
                                    [&](const auto& o) { return !(o[i] == cpuObjects[i]); });
        std::ostringstream ruleBroken, strayHits;
        uint64_t sameObject = 0, ruleMismatches = 0, orderDependent = 0, silhouette = 0, stray = 0;
        for (size_t i = 0; i < pixels; ++i) {
            const int64_t gpuRecord = gpu[IndexMapKind::Record][i], cpuRecord = cpu[IndexMapKind::Record][i];
            if (gpuObjects[i] == cpuObjects[i]) {
                ++sameObject;
                if (gpuRecord != cpuRecord && ++ruleMismatches <= 40)
                    ruleBroken << "  " << pixelName(i, width) << " instance " << cpuObjects[i].instance << ", geometry "
                               << cpuObjects[i].geometry << ": GPU record " << gpuRecord << ", refray record " << cpuRecord
                               << "\n";
                continue;
            }
            if (anyNeighbour(i, width, height, [&](size_t n) { return masked[n]; })) { ++orderDependent; continue; }
            if (onSilhouette(cpuObjects, i, width, height)) { ++silhouette; continue; }
            if (++stray <= 40)
                strayHits << "  " << pixelName(i, width) << " GPU instance " << gpuObjects[i].instance << " geometry "
                          << gpuObjects[i].geometry << " primitive " << gpuObjects[i].primitive << ", refray instance "
                          << cpuObjects[i].instance << " geometry " << cpuObjects[i].geometry << " primitive "
                          << cpuObjects[i].primitive << "\n";
        }
        std::printf("%s: %llu pixels hit the same object (records equal on all but %llu), %llu another object on an "
                    "order-dependent pixel, %llu on a silhouette, %llu elsewhere\n",
                    name.c_str(), (unsigned long long)sameObject, (unsigned long long)ruleMismatches,
                    (unsigned long long)orderDependent, (unsigned long long)silhouette, (unsigned long long)stray);
        EXPECT_EQ(ruleMismatches, 0u) << name << ": the GPU used another hit-group record than R + M*G + C on "
                                      << ruleMismatches << " pixels that hit the same object; the first:\n"
                                      << ruleBroken.str();
        EXPECT_EQ(stray, 0u) << name << ": the GPU hit another object than refray on " << stray
                             << " pixels that are neither order-dependent nor on a silhouette; the first:\n"
                             << strayHits.str();
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

}  // namespace
}  // namespace refray::scenes
