#include "verify/golden.h"

#include <algorithm>
#include <chrono>
#include <cstring>
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

std::vector<StatisticalGoldenEntry> parseStatistical(const json::Value& array) {
    std::vector<StatisticalGoldenEntry> entries;
    for (const json::Value& v : array.asArray()) {
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
            entries.push_back(std::move(e));
        }
    return entries;
}

// The statistical entries of a manifest of any format (an update converts an older one).
std::vector<StatisticalGoldenEntry> readStatisticalEntries(const fs::path& manifest) {
    const json::Value root = json::parseFile(manifest);
    json::ObjectReader top(root, "the golden manifest");
    const json::Value* statistical = top.optional("statistical");
    return statistical ? parseStatistical(*statistical) : std::vector<StatisticalGoldenEntry>{};
}

}  // namespace

GoldenSet readGoldenManifest(const fs::path& manifest) {
    const json::Value root = json::parseFile(manifest);
    json::ObjectReader top(root, "the golden manifest");
    const json::Value& format = top.required("format");
    REFRAY_CHECK(format.asString() == kGoldenFormat,
                 manifest.string() << " is a golden directory of format '" << format.asString() << "'; this refray reads '"
                                   << kGoldenFormat
                                   << "' (envelope goldens, docs/golden-format.md): remake it with 'refray golden "
                                      "update' (or 'refray golden make')");
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
        e.envelope = r.required("envelope").asString();
        e.orders = r.required("orderCheckOrders").asUint32();
        e.orderDependentPixels = uint64_t(r.required("orderDependentPixels").asInt());
        e.perturbedRenders = r.required("perturbedRenders").asUint32();
        e.sensitivePixels = uint64_t(r.required("sensitivePixels").asInt());
        e.variationModel = r.required("variationModel").asString();
        e.refrayCommit = r.required("refrayCommit").asString();
        r.finish();
        set.entries.push_back(std::move(e));
    }
    if (const json::Value* statistical = top.optional("statistical")) set.statistical = parseStatistical(*statistical);
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
            << ",\n     \"envelope\": " << jsonString(e.envelope) << ", \"perturbedRenders\": " << e.perturbedRenders
            << ", \"variationModel\": " << jsonString(e.variationModel)
            << ", \"sensitivePixels\": " << e.sensitivePixels << ",\n     \"orderCheckOrders\": " << e.orders
            << ", \"orderDependentPixels\": " << e.orderDependentPixels << ", \"refrayCommit\": " << jsonString(e.refrayCommit) << "}";
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

procedural::Perturbation goldenPerturbation(uint32_t seed) {
    procedural::Perturbation p;
    p.seed = seed;
    constexpr procedural::Contraction kCycle[] = {procedural::Contraction::Mixed, procedural::Contraction::Split,
                                                  procedural::Contraction::Fuse};
    p.contraction = kCycle[(seed + 2) % 3];
    p.denormals = seed % 2 == 0 ? procedural::Denormals::Preserve : procedural::Denormals::Flush;
    return p;
}

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string fixed(double seconds) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", seconds);
    return buf;
}

}  // namespace

Envelope renderEnvelope(Scene& scene, GoldenEntry& entry, const EnvelopeRenderOptions& options) {
    const RenderSettings base = goldenSettings(entry, options.threads);
    const auto report = [&](const std::string& what, double seconds) {
        if (options.onRender) options.onRender(what, seconds);
    };
    std::vector<Image> variants;
    std::string perturbations;
    double perturbedSeconds = 0.0;

    // The nominal render and the order check (its adversarial orders are variants too).
    auto start = std::chrono::steady_clock::now();
    OrderCheckResult check = checkTraversalOrder(scene, base, 0);
    const double nominalSeconds = secondsSince(start);
    report("nominal", nominalSeconds);
    start = std::chrono::steady_clock::now();
    {
        RenderSettings s = base;
        s.order = dxr::TraversalOrder::Adversarial;
        Image mask(entry.width, entry.height, vec4(0.0f, 0.0f, 0.0f, 1.0f));
        for (uint32_t seed = 1; seed <= entry.orders; ++seed) {
            s.adversarialSeed = seed;
            Image other = scene.render(s).image;
            for (size_t i = 0; i < other.pixels().size(); ++i)
                if (std::memcmp(&other.pixels()[i], &check.ordered.image.pixels()[i], sizeof(vec4)) != 0)
                    mask.pixels()[i] = vec4(1.0f);
            variants.push_back(std::move(other));
        }
        check.mask = std::move(mask);
    }
    const double orderSeconds = secondsSince(start);
    if (entry.orders) report(std::to_string(entry.orders) + " adversarial orders", orderSeconds);

    // K legal GPUs of the variation model, then double precision.
    for (uint32_t seed = 1; seed <= entry.perturbedRenders; ++seed) {
        start = std::chrono::steady_clock::now();
        RenderSettings s = base;
        s.perturbation = goldenPerturbation(seed);
        variants.push_back(scene.render(s).image);
        perturbations += (perturbations.empty() ? "" : "; ") + procedural::describe(*s.perturbation);
        const double seconds = secondsSince(start);
        perturbedSeconds += seconds;
        report("perturbed seed " + std::to_string(seed), seconds);
    }
    start = std::chrono::steady_clock::now();
    {
        RenderSettings s = base;
        s.precision = procedural::Precision::Double;
        variants.push_back(scene.render(s).image);
    }
    const double doubleSeconds = secondsSince(start);
    report("double", doubleSeconds);

    // makeEnvelope counts the first `perturbedRenders` variants as the exchangeable ones; order them so.
    std::vector<const Image*> pointers;
    for (size_t i = entry.orders; i < entry.orders + entry.perturbedRenders; ++i) pointers.push_back(&variants[i]);
    for (size_t i = 0; i < entry.orders; ++i) pointers.push_back(&variants[i]);
    pointers.push_back(&variants.back());
    Envelope envelope = makeEnvelope(check.ordered.image, pointers, entry.perturbedRenders, &check.mask);

    entry.orderDependentPixels = 0;
    for (uint8_t o : envelope.orderDependent) entry.orderDependentPixels += o;
    entry.sensitivePixels = envelope.sensitivePixels();
    entry.variationModel = std::string(procedural::kVariationModel);
    auto& p = envelope.provenance;
    p["golden_name"] = entry.name;
    p["scene"] = entry.scene;
    p["scene_sha256"] = entry.sceneSha256;
    p["camera"] = entry.camera;
    p["time"] = entry.time;
    p["precision"] = entry.precision;
    p["size"] = std::to_string(entry.width) + "x" + std::to_string(entry.height);
    p["refray_commit"] = entry.refrayCommit;
    p["variation_model"] = entry.variationModel;
    p["perturbed_seeds"] = entry.perturbedRenders ? "1.." + std::to_string(entry.perturbedRenders) : "none";
    p["perturbations"] = perturbations;
    p["order_check_orders"] = std::to_string(entry.orders);
    p["order_dependent_pixels"] = std::to_string(entry.orderDependentPixels);
    p["sensitive_pixels"] = std::to_string(entry.sensitivePixels);
    {
        std::string moves;
        for (uint64_t c : envelope.stableMovesLeaveOneOut) {
            if (!moves.empty()) moves += ' ';
            moves += std::to_string(c);
        }
        p["stable_moves_loo"] = moves;  // also refray:envelope_stable_moves_loo, which the compare reads
        p["stable_budget"] = std::to_string(stableBudget(envelope, {}));
        const uint64_t m = stableClusterSize(envelope, {});
        p["stable_cluster_size"] = std::to_string(m);
        p["stable_budget_rule"] = "clusters of m = max(9, ceil(var(c_i)/mean(c_i))) pixels; m times the largest y with "
                                  "P(Binomial(y + T, 1/(K+1)) >= y) > 1e-3, T = sum ceil(c_i/m); at least max(c_i); "
                                  "docs/compare.md";
    }
    p["other_variants"] = "precision double; adversarial orders 1.." + std::to_string(entry.orders);
    p["render_seconds_nominal"] = fixed(nominalSeconds);
    p["render_seconds_perturbed"] = fixed(perturbedSeconds);
    p["render_seconds_double"] = fixed(doubleSeconds);
    p["render_seconds_orders"] = fixed(orderSeconds);
    // The nominal render's own metadata (scene, camera, ...) stays on the nominal; the envelope's keys win.
    for (const auto& [key, value] : check.ordered.image.metadata) p.try_emplace(key, value);
    envelope.nominal.metadata.clear();
    return envelope;
}

namespace {

GoldenEntry entryFor(const SceneDesc& desc, const fs::path& file, const fs::path& root, const CameraDesc& camera,
                     const std::string& time, uint32_t width, uint32_t height, uint32_t orders, uint32_t perturbed,
                     const std::string& commit) {
    GoldenEntry e;
    e.name = desc.name + "." + camera.name;
    std::error_code ec;
    const fs::path relative = fs::relative(file, root, ec);
    e.scene = (!ec && !relative.empty() && *relative.begin() != "..") ? relative.generic_string()
                                                                        : fs::absolute(file).generic_string();
    e.sceneSha256 = desc.fileHash;
    e.camera = camera.name;
    e.time = time.empty() ? desc.defaultTimeText : time;
    e.width = width;
    e.height = height;
    e.envelope = e.name + ".envelope.exr";
    e.orders = orders;
    e.perturbedRenders = perturbed;
    e.refrayCommit = commit;
    return e;
}

}  // namespace

GoldenEntry makeGolden(const GoldenMakeOptions& options) {
    Scene scene(loadSceneFile(options.sceneFile));
    const SceneDesc& desc = scene.desc();
    REFRAY_CHECK(!isMonteCarlo(desc), options.sceneFile.string()
                                          << " is a Monte Carlo scene: it gets a statistical golden (docs/compare.md), "
                                             "not an envelope");
    const CameraDesc& camera = options.camera.empty() ? desc.cameras.at(0) : desc.camera(options.camera);
    GoldenEntry e = entryFor(desc, options.sceneFile, options.repositoryRoot, camera, options.time, options.width,
                             options.height, options.orders, options.perturbedRenders, options.refrayCommit);
    fs::create_directories(options.goldenDirectory);
    const Envelope envelope = renderEnvelope(scene, e, options.render);
    writeEnvelope((options.goldenDirectory / e.envelope).string(), envelope);

    const fs::path manifest = options.goldenDirectory / "goldens.json";
    GoldenSet set;
    if (fs::exists(manifest)) set = readGoldenManifest(manifest);
    std::erase_if(set.entries, [&](const GoldenEntry& other) { return other.name == e.name; });
    set.entries.push_back(e);
    writeGoldenManifest(manifest, set);
    return e;
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
    if (fs::exists(manifest)) {
        // The statistical entries are kept; an older manifest's are read by hand so that an update converts it.
        try {
            set.statistical = readGoldenManifest(manifest).statistical;
        } catch (const Error&) {
            set.statistical = readStatisticalEntries(manifest);
        }
    }
    for (const fs::path& file : files) {
        Scene scene(loadSceneFile(file));
        const SceneDesc& desc = scene.desc();
        if (isMonteCarlo(desc)) continue;  // statistical goldens only (below)
        for (const CameraDesc& camera : desc.cameras) {
            const auto start = std::chrono::steady_clock::now();
            GoldenEntry e = entryFor(desc, file, options.repositoryRoot, camera, "", options.width, options.height,
                                     options.orders, options.perturbedRenders, options.refrayCommit);
            EnvelopeRenderOptions render;
            render.threads = options.threads;
            render.onRender = options.onRender;
            const Envelope envelope = renderEnvelope(scene, e, render);
            writeEnvelope((options.goldenDirectory / e.envelope).string(), envelope);
            // The files of the older format (a plain golden and its order mask) are replaced by the envelope.
            fs::remove(options.goldenDirectory / (e.name + ".exr"));
            fs::remove(options.goldenDirectory / (e.name + ".order-mask.png"));
            set.entries.push_back(e);
            if (options.onEntry) options.onEntry(e, secondsSince(start));
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
