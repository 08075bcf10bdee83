#include "verify/golden.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/hash.h"
#include "core/json.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {

namespace fs = std::filesystem;

namespace {

std::string jsonString(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
            continue;
        }
        out += c;
    }
    return out + "\"";
}

}  // namespace

GoldenSet readGoldenManifest(const fs::path& manifest) {
    const json::Value root = json::parseFile(manifest);
    json::ObjectReader top(root, "the golden manifest");
    const json::Value& format = top.required("format");
    if (format.asString() != kGoldenFormat) format.fail("expected format '" + std::string(kGoldenFormat) + "'");
    top.optional("comment");
    GoldenSet set;
    for (const json::Value& v : top.required("goldens").asArray()) {
        json::ObjectReader r(v, "a golden entry");
        GoldenEntry e;
        e.name = r.required("name").asString();
        e.scene = r.required("scene").asString();
        e.sceneSha256 = r.required("sceneSha256").asString();
        e.camera = r.required("camera").asString();
        e.time = r.required("time").asString();
        e.precision = r.required("precision").asString();
        e.spp = r.required("spp").asUint32();
        e.width = r.required("width").asUint32();
        e.height = r.required("height").asUint32();
        e.image = r.required("image").asString();
        e.mask = r.required("mask").asString();
        e.orders = r.required("orderCheckOrders").asUint32();
        e.orderDependentPixels = uint64_t(r.required("orderDependentPixels").asInt());
        e.refrayCommit = r.required("refrayCommit").asString();
        r.finish();
        set.entries.push_back(std::move(e));
    }
    if (const json::Value* statistical = top.optional("statistical"))
        for (const json::Value& v : statistical->asArray()) {
            json::ObjectReader r(v, "a statistical golden entry");
            StatisticalGoldenEntry e;
            e.name = r.required("name").asString();
            e.scene = r.required("scene").asString();
            e.sceneSha256 = r.required("sceneSha256").asString();
            e.camera = r.required("camera").asString();
            e.width = r.required("width").asUint32();
            e.height = r.required("height").asUint32();
            e.spp = r.required("spp").asUint32();
            e.batches = r.required("batches").asUint32();
            e.seed = r.required("seed").asUint32();
            e.image = r.required("image").asString();
            e.refrayCommit = r.required("refrayCommit").asString();
            r.finish();
            if (e.batches < 2) v.fail("a statistical golden needs at least 2 batches");
            set.statistical.push_back(std::move(e));
        }
    top.finish();
    return set;
}

void writeGoldenManifest(const fs::path& manifest, const GoldenSet& set) {
    std::ostringstream out;
    out << "{\n  \"format\": " << jsonString(std::string(kGoldenFormat)) << ",\n"
        << "  \"comment\": \"Written by 'refray golden update'; do not edit by hand.\",\n  \"goldens\": [";
    for (size_t i = 0; i < set.entries.size(); ++i) {
        const GoldenEntry& e = set.entries[i];
        out << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(e.name) << ", \"scene\": " << jsonString(e.scene)
            << ", \"sceneSha256\": " << jsonString(e.sceneSha256) << ",\n     \"camera\": " << jsonString(e.camera)
            << ", \"time\": " << jsonString(e.time) << ", \"precision\": " << jsonString(e.precision)
            << ", \"spp\": " << e.spp << ", \"width\": " << e.width << ", \"height\": " << e.height
            << ",\n     \"image\": " << jsonString(e.image) << ", \"mask\": " << jsonString(e.mask)
            << ", \"orderCheckOrders\": " << e.orders << ", \"orderDependentPixels\": " << e.orderDependentPixels
            << ", \"refrayCommit\": " << jsonString(e.refrayCommit) << "}";
    }
    out << "\n  ]";
    if (!set.statistical.empty()) {
        out << ",\n  \"statistical\": [";
        for (size_t i = 0; i < set.statistical.size(); ++i) {
            const StatisticalGoldenEntry& e = set.statistical[i];
            out << (i ? ",\n" : "\n") << "    {\"name\": " << jsonString(e.name)
                << ", \"scene\": " << jsonString(e.scene)
                << ", \"sceneSha256\": " << jsonString(e.sceneSha256) << ",\n     \"camera\": " << jsonString(e.camera)
                << ", \"width\": " << e.width << ", \"height\": " << e.height << ", \"spp\": " << e.spp
                << ", \"batches\": " << e.batches << ", \"seed\": " << e.seed
                << ",\n     \"image\": " << jsonString(e.image) << ", \"refrayCommit\": " << jsonString(e.refrayCommit)
                << "}";
        }
        out << "\n  ]";
    }
    out << "\n}\n";
    // json::Value's asFloat reads the time back from its text; the manifest keeps times as strings so no digit is lost.
    std::ofstream file(manifest, std::ios::binary);
    REFRAY_CHECK(file, "cannot write " << manifest.string());
    file << out.str();
    REFRAY_CHECK(file.good(), "cannot write " << manifest.string());
}

RenderSettings goldenSettings(const GoldenEntry& entry, uint32_t threads) {
    RenderSettings s;
    s.width = entry.width;
    s.height = entry.height;
    s.threads = threads;
    s.camera = entry.camera;
    s.time = json::parse(entry.time, "the golden time of " + entry.name).asFloat();
    const auto precision = procedural::parsePrecision(entry.precision);
    REFRAY_CHECK(precision, "golden " << entry.name << ": unknown precision '" << entry.precision << "'");
    s.precision = *precision;
    s.spp = entry.spp;
    return s;
}

RenderSettings goldenSettings(const StatisticalGoldenEntry& entry, uint32_t firstSeed, uint32_t batch,
                              uint32_t threads) {
    RenderSettings s;
    s.width = entry.width;
    s.height = entry.height;
    s.threads = threads;
    s.camera = entry.camera;
    s.spp = entry.spp;
    s.seed = firstSeed + batch;
    return s;
}

bool isMonteCarlo(const SceneDesc& scene) { return findShaderLibrary(scene.shaderLibrary).samplesInShader; }

StatisticsImage renderStatistics(Scene& scene, const StatisticalGoldenEntry& entry, uint32_t firstSeed,
                                 uint32_t batches, uint32_t threads) {
    StatisticsAccumulator accumulator;
    for (uint32_t k = 0; k < batches; ++k)
        accumulator.add(scene.render(goldenSettings(entry, firstSeed, k, threads)).image);
    StatisticsImage stats = accumulator.finish();
    stats.mean.metadata["seed"] = std::to_string(firstSeed);
    std::string seeds = std::to_string(firstSeed);
    seeds += "..";
    seeds += std::to_string(firstSeed + batches - 1);
    stats.mean.metadata["statistics_seeds"] = seeds;
    return stats;
}

GoldenSet updateGoldens(const GoldenUpdateOptions& options) {
    std::vector<fs::path> files;
    for (const auto& f : fs::directory_iterator(options.repositoryRoot / "scenes"))
        if (f.is_regular_file() && f.path().extension() == ".json") files.push_back(f.path());
    std::sort(files.begin(), files.end());
    REFRAY_CHECK(!files.empty(), "no scene files in " << (options.repositoryRoot / "scenes").string());
    fs::create_directories(options.goldenDirectory);

    GoldenSet set;
    const fs::path manifest = options.goldenDirectory / "goldens.json";
    if (fs::exists(manifest)) set.statistical = readGoldenManifest(manifest).statistical;
    for (const fs::path& file : files) {
        Scene scene(loadSceneFile(file));
        const SceneDesc& desc = scene.desc();
        if (isMonteCarlo(desc)) continue;  // statistical goldens only (below)
        for (const CameraDesc& camera : desc.cameras) {
            const auto start = std::chrono::steady_clock::now();
            GoldenEntry e;
            e.name = desc.name + "." + camera.name;
            e.scene = fs::relative(file, options.repositoryRoot).generic_string();
            e.sceneSha256 = desc.fileHash;
            e.camera = camera.name;
            e.time = desc.defaultTimeText;
            e.width = options.width;
            e.height = options.height;
            e.image = e.name + ".exr";
            e.mask = orderMaskPath(e.image);
            e.orders = options.orders;
            e.refrayCommit = options.refrayCommit;
            const OrderCheckResult check = checkTraversalOrder(scene, goldenSettings(e, options.threads), options.orders);
            e.orderDependentPixels = check.orderDependentPixels;
            Image image = check.ordered.image;
            image.metadata["refray_commit"] = options.refrayCommit;
            writeImage((options.goldenDirectory / e.image).string(), image);
            writeImage((options.goldenDirectory / e.mask).string(), check.mask);
            set.entries.push_back(e);
            if (options.onEntry)
                options.onEntry(e, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
    }
    for (StatisticalGoldenEntry& e : set.statistical) {
        const auto start = std::chrono::steady_clock::now();
        Scene scene(loadSceneFile(options.repositoryRoot / e.scene));
        e.sceneSha256 = scene.desc().fileHash;
        e.refrayCommit = options.refrayCommit;
        StatisticsImage stats = renderStatistics(scene, e, e.seed, e.batches, options.threads);
        stats.mean.metadata["refray_commit"] = options.refrayCommit;
        writeStatisticsImage((options.goldenDirectory / e.image).string(), stats);
        if (options.onStatisticalEntry) {
            const auto seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            options.onStatisticalEntry(e, seconds);
        }
    }
    writeGoldenManifest(manifest, set);
    return set;
}

}  // namespace refray::scenes
