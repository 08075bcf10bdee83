#include "verify/golden.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/file_input.h"
#include "core/hash.h"
#include "core/json.h"
#include "core/strings.h"
#include "core/text_file.h"
#include "emulator/validation.h"
#include "scenes/scene_loader.h"
#include "verify/object_map.h"

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
    writeTextFile(manifest.string(), out.str());
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

std::vector<EnvelopePart> envelopeParts(const GoldenEntry& entry, uint32_t threads) {
    const RenderSettings base = goldenSettings(entry, threads);
    std::vector<EnvelopePart> parts;
    parts.push_back({"nominal", base});
    for (uint32_t seed = 1; seed <= entry.orders; ++seed) {
        RenderSettings s = base;
        s.order = dxr::TraversalOrder::Adversarial;
        s.adversarialSeed = seed;
        parts.push_back({"order-" + std::to_string(seed), s});
    }
    for (uint32_t seed = 1; seed <= entry.perturbedRenders; ++seed) {
        RenderSettings s = base;
        s.perturbation = goldenPerturbation(seed);
        parts.push_back({"perturbed-" + std::to_string(seed), s});
    }
    RenderSettings s = base;
    s.precision = procedural::Precision::Double;
    parts.push_back({"double", s});
    // The nominal's objects for the regional count test (verify/object_map.h).
    parts.push_back({"objects", base});
    return parts;
}

Image renderEnvelopePart(Scene& scene, const EnvelopePart& part) {
    if (part.name == "objects")
        return objectMapImage(renderObjectMap(scene, part.settings), part.settings.width, part.settings.height);
    if (!part.settings.perturbation) return scene.render(part.settings).image;
    RenderSettings s = part.settings;
    const uint32_t seed = uint32_t(s.perturbation->seed);
    std::string reached;
    for (uint32_t attempt = 0; attempt < kPerturbedSeedAttempts; ++attempt) {
        s.perturbation = goldenPerturbation(seed + attempt * kPerturbedSeedStride);
        try {
            Image image = scene.render(s).image;
            image.metadata["golden_part_seed"] = std::to_string(s.perturbation->seed);
            return image;
        } catch (const dxr::DxrError& e) {
            reached += std::string("\n  seed ") + std::to_string(s.perturbation->seed) + ": " + e.what();
        }
    }
    REFRAY_CHECK(false, "every legal GPU tried for " << part.name << " reaches undefined behaviour:" << reached);
    return {};
}

Envelope renderEnvelope(Scene& scene, GoldenEntry& entry, const EnvelopeRenderOptions& options) {
    std::map<std::string, Image> renders;
    std::map<std::string, double> seconds;
    for (const EnvelopePart& part : envelopeParts(entry, options.threads)) {
        const auto start = std::chrono::steady_clock::now();
        renders[part.name] = renderEnvelopePart(scene, part);
        seconds[part.name] = secondsSince(start);
        if (options.onRender) options.onRender(part.name, seconds[part.name]);
    }
    return assembleEnvelope(entry, renders, seconds);
}

Envelope assembleEnvelope(GoldenEntry& entry, const std::map<std::string, Image>& renders,
                          const std::map<std::string, double>& seconds) {
    const auto render = [&](const std::string& name) -> const Image& {
        const auto found = renders.find(name);
        REFRAY_CHECK(found != renders.end(), "the envelope of " << entry.name << " lacks its render '" << name << "'");
        REFRAY_CHECK(found->second.width() == entry.width && found->second.height() == entry.height,
                     "the render '" << name << "' of " << entry.name << " is " << found->second.width() << "x"
                                    << found->second.height() << ", the golden " << entry.width << "x" << entry.height);
        return found->second;
    };
    const auto total = [&](const std::string& prefix) {
        double sum = 0;
        for (const auto& [name, t] : seconds)
            if (name.rfind(prefix, 0) == 0) sum += t;
        return sum;
    };
    const Image& nominal = render("nominal");
    // The order mask: where an adversarial order changes the pixel's bits.
    Image mask(entry.width, entry.height, vec4(0.0f, 0.0f, 0.0f, 1.0f));
    std::vector<const Image*> orders, perturbed;
    for (uint32_t seed = 1; seed <= entry.orders; ++seed) {
        const Image& other = render("order-" + std::to_string(seed));
        for (size_t i = 0; i < other.pixels().size(); ++i)
            if (std::memcmp(&other.pixels()[i], &nominal.pixels()[i], sizeof(vec4)) != 0) mask.pixels()[i] = vec4(1.0f);
        orders.push_back(&other);
    }
    std::string perturbations;
    std::string seedsUsed;
    for (uint32_t seed = 1; seed <= entry.perturbedRenders; ++seed) {
        const Image& image = render("perturbed-" + std::to_string(seed));
        perturbed.push_back(&image);
        const auto used = image.metadata.find("golden_part_seed");
        const uint32_t actual = used == image.metadata.end() ? seed : uint32_t(std::stoul(used->second));
        perturbations += (perturbations.empty() ? "" : "; ") + procedural::describe(goldenPerturbation(actual));
        seedsUsed += (seedsUsed.empty() ? "" : " ") + std::to_string(actual);
    }
    // makeEnvelope counts the first `perturbedRenders` variants as the exchangeable ones; order them so.
    std::vector<const Image*> pointers = perturbed;
    pointers.insert(pointers.end(), orders.begin(), orders.end());
    pointers.push_back(&render("double"));
    const ObjectMap objects = objectMapOf(render("objects"));
    Envelope envelope = makeEnvelope(nominal, pointers, entry.perturbedRenders, &mask, &objects);
    const double nominalSeconds = total("nominal"), orderSeconds = total("order-"),
                 perturbedSeconds = total("perturbed-"), doubleSeconds = total("double");

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
    // Seed k, or k + 100, k + 200, ... where seed k's legal GPU reaches undefined behaviour (renderEnvelopePart).
    p["perturbed_seeds"] = entry.perturbedRenders ? seedsUsed : "none";
    p["perturbations"] = perturbations;
    p["order_check_orders"] = std::to_string(entry.orders);
    p["order_dependent_pixels"] = std::to_string(entry.orderDependentPixels);
    p["sensitive_pixels"] = std::to_string(entry.sensitivePixels);
    // The count tests' calibration is in refray:envelope_stable_moves_loo and refray:envelope_sensitive_outside_loo,
    // which the compare reads; what it makes of them, for a reader of the file:
    p["stable_budget"] = std::to_string(stableBudget(envelope, {}));
    p["stable_cluster_size"] = std::to_string(leaveOneOutClusterSize(envelope.stableMovesLeaveOneOut, {}));
    p["sensitive_loo_budget"] = std::to_string(leaveOneOutBudget(envelope.sensitiveOutsideLeaveOneOut, {}));
    p["sensitive_cluster_size"] = std::to_string(leaveOneOutClusterSize(envelope.sensitiveOutsideLeaveOneOut, {}));
    p["count_test_rule"] = "clusters of m = max(9, ceil(var(c_i)/mean(c_i))) pixels; m times the largest y with "
                           "P(Binomial(y + T, 1/(K+1)) >= y) > 1e-3, T = sum ceil(c_i/m); at least max(c_i); the "
                           "sensitive budget is also at least the binomial 1e-3 quantile of 2/(K+1); docs/compare.md";
    p["regional_test_rule"] =
        "per object (instance x geometry of the nominal's primary ray; misses one more) cut by tiles of W/40, W/20, "
        "W/10 at offsets 0 and half a tile, and whole; per direction (stable up/down, sensitive above/below): the "
        "candidate's flags against the K leave-one-out renders' (planes loo.*) in clusters of m (connected components, "
        "tile dispersion), P(Binomial(Y + T, q) >= Y), q = h E_c / (h E_c + sum E_i), E = whole-image counts, E_c at "
        "least mean E_i; Bonferroni over every region and direction, FAILURE below 1e-3; docs/compare.md";
    p["other_variants"] = "precision double; adversarial orders 1.." + std::to_string(entry.orders);
    p["render_seconds_nominal"] = fixed(nominalSeconds);
    p["render_seconds_perturbed"] = fixed(perturbedSeconds);
    p["render_seconds_double"] = fixed(doubleSeconds);
    p["render_seconds_orders"] = fixed(orderSeconds);
    // The nominal render's own metadata (scene, camera, ...) stays on the nominal; the envelope's keys win.
    for (const auto& [key, value] : nominal.metadata) p.try_emplace(key, value);
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

namespace {

GoldenSet existingSet(const fs::path& manifest) {
    GoldenSet set;
    if (!fs::exists(manifest)) return set;
    // The statistical entries are kept; an older manifest's are read by hand so that an update converts it.
    try {
        set = readGoldenManifest(manifest);
    } catch (const Error&) {
        set.statistical = readStatisticalEntries(manifest);
    }
    return set;
}

// Writes an entry's envelope; with `replaceAll` (update) the set's entries are this run's, otherwise (make) the
// entry replaces the one of its name.
void addEntry(GoldenSet& set, const fs::path& directory, const GoldenEntry& e, const Envelope& envelope) {
    writeEnvelope((directory / e.envelope).string(), envelope);
    // The files of the older format (a plain golden and its order mask) are replaced by the envelope.
    fs::remove(directory / (e.name + ".exr"));
    fs::remove(directory / (e.name + ".order-mask.png"));
    std::erase_if(set.entries, [&](const GoldenEntry& other) { return other.name == e.name; });
    set.entries.push_back(e);
}

const char* const kPlanMode[] = {"make", "update"};

}  // namespace

GoldenEntry makeGolden(const GoldenMakeOptions& options) {
    GoldenEntry e = planMake(options);
    Scene scene(loadSceneFile(options.sceneFile));
    if (options.onSceneBuilt) options.onSceneBuilt(scene);
    fs::create_directories(options.goldenDirectory);
    const Envelope envelope = renderEnvelope(scene, e, options.render);
    const fs::path manifest = options.goldenDirectory / "goldens.json";
    GoldenSet set = existingSet(manifest);
    addEntry(set, options.goldenDirectory, e, envelope);
    writeGoldenManifest(manifest, set);
    return e;
}

namespace {

// What a job's render must have been made for: the settings of its golden as the plan states them.
std::string planSettings(const GoldenEntry& e) {
    std::ostringstream s;
    s << "scene " << e.scene << " (SHA-256 " << e.sceneSha256 << "), camera " << e.camera << ", time " << e.time
      << ", " << e.width << "x" << e.height << ", precision " << e.precision << ", spp " << e.spp << ", orders "
      << e.orders << ", perturbed " << e.perturbedRenders;
    return s.str();
}

std::string newPlanId() {
    std::random_device device;
    std::ostringstream id;
    id << std::hex << std::setfill('0');
    for (int i = 0; i < 4; ++i) id << std::setw(8) << device();
    return id.str();
}

std::string readPlanId(const fs::path& jobs) {
    std::string text = readInputFile((jobs / "plan-id").string(), "golden plan id", 1024);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    return text;
}

}  // namespace

std::string writeGoldenPlan(const fs::path& goldenDirectory, const std::vector<GoldenEntry>& entries, bool update) {
    const fs::path jobs = goldenDirectory / "jobs";
    std::string id;
    if (fs::exists(jobs / "plan.json")) {
        // A plan is already there: the same one keeps its id (its finished renders stay valid); another one is refused
        // rather than mixed with it or thrown away.
        const GoldenSet old = readGoldenManifest(jobs / "plan.json");
        std::string oldMode = readInputFile((jobs / "mode").string(), "golden plan mode", 1024);
        const bool same = old.entries.size() == entries.size() && oldMode == std::string(kPlanMode[update]) + "\n" &&
                          std::equal(old.entries.begin(), old.entries.end(), entries.begin(),
                                     [](const GoldenEntry& a, const GoldenEntry& b) {
                                         return a.name == b.name && planSettings(a) == planSettings(b);
                                     });
        std::string names;
        for (const GoldenEntry& e : old.entries) names += (names.empty() ? "" : ", ") + e.name + " (" + planSettings(e) + ")";
        REFRAY_CHECK(same, jobs.string() << " holds another plan (" << names << ") whose renders would be mixed with "
                                         << "this one's; collect it first ('--collect') or remove " << jobs.string()
                                         << " to discard it");
        if (fs::exists(jobs / "plan-id")) id = readPlanId(jobs);
    }
    if (id.empty()) id = newPlanId();
    GoldenSet plan;
    plan.entries = entries;
    writeGoldenManifest(jobs / "plan.json", plan);
    writeTextFile((jobs / "mode").string(), std::string(kPlanMode[update]) + "\n");
    writeTextFile((jobs / "plan-id").string(), id + "\n");
    return id;
}

std::vector<std::string> goldenJobCommands(const fs::path& goldenDirectory, const fs::path& repositoryRoot,
                                           const std::string& refray) {
    const GoldenSet plan = readGoldenManifest(goldenDirectory / "jobs" / "plan.json");
    std::vector<std::string> lines;
    for (const GoldenEntry& e : plan.entries)
        for (const EnvelopePart& part : envelopeParts(e, 0))
            lines.push_back(shellQuoted(refray) + " golden job " + shellQuoted(fs::absolute(goldenDirectory).string()) +
                            " " + shellQuoted(e.name) + " " + part.name + " --root " +
                            shellQuoted(fs::absolute(repositoryRoot).string()) + " --threads 1");
    return lines;
}

fs::path goldenJobOutput(const fs::path& goldenDirectory, const std::string& name, const std::string& part) {
    return goldenDirectory / "jobs" / name / (part + ".exr");
}

void runGoldenJob(const fs::path& goldenDirectory, const fs::path& repositoryRoot, const std::string& name,
                  const std::string& part, uint32_t threads, const SceneBuiltCallback& onSceneBuilt) {
    const fs::path planFile = goldenDirectory / "jobs" / "plan.json";
    REFRAY_CHECK(fs::exists(planFile), goldenDirectory.string() << " holds no golden plan (no jobs/plan.json); write "
                                                                   "one with 'refray golden update --emit-jobs FILE'");
    const GoldenSet plan = readGoldenManifest(planFile);
    const auto entry = std::find_if(plan.entries.begin(), plan.entries.end(),
                                    [&](const GoldenEntry& e) { return e.name == name; });
    REFRAY_CHECK(entry != plan.entries.end(), "the plan " << planFile.string() << " has no golden '" << name << "'");
    const std::vector<EnvelopePart> parts = envelopeParts(*entry, threads);
    const auto p = std::find_if(parts.begin(), parts.end(), [&](const EnvelopePart& x) { return x.name == part; });
    REFRAY_CHECK(p != parts.end(), "golden '" << name << "' has no render '" << part << "' (it has nominal, order-1.."
                                              << entry->orders << ", perturbed-1.." << entry->perturbedRenders
                                              << ", double, objects)");
    Scene scene(loadSceneFile(repositoryRoot / entry->scene));
    REFRAY_CHECK(scene.desc().fileHash == entry->sceneSha256,
                 (repositoryRoot / entry->scene).string() << " changed since the plan was written (SHA-256 "
                                                          << scene.desc().fileHash << ", planned " << entry->sceneSha256
                                                          << "); write the plan again");
    if (onSceneBuilt) onSceneBuilt(scene);
    const auto start = std::chrono::steady_clock::now();
    Image image = renderEnvelopePart(scene, *p);
    image.metadata["golden_job_seconds"] = fixed(secondsSince(start));
    // Where the render comes from, for collectGoldens to verify.
    image.metadata["golden_plan_id"] = readPlanId(goldenDirectory / "jobs");
    image.metadata["golden_job"] = name + " " + part;
    image.metadata["golden_plan_settings"] = planSettings(*entry);
    // writeImage writes the file whole or not at all: a job killed half-way leaves no file that looks finished.
    writeImage(goldenJobOutput(goldenDirectory, name, part).string(), image);
}

GoldenSet collectGoldens(const fs::path& goldenDirectory, const std::function<void(const GoldenEntry&)>& onEntry) {
    const fs::path jobs = goldenDirectory / "jobs";
    REFRAY_CHECK(fs::exists(jobs / "plan.json"), goldenDirectory.string() << " holds no golden plan (no jobs/plan.json)");
    const GoldenSet plan = readGoldenManifest(jobs / "plan.json");
    std::string mode = readInputFile((jobs / "mode").string(), "golden plan mode", 1024);
    while (!mode.empty() && (mode.back() == '\n' || mode.back() == '\r')) mode.pop_back();
    REFRAY_CHECK(fs::exists(jobs / "plan-id"), (jobs / "plan-id").string()
                                                   << " is missing: the plan was written by an older refray; write it "
                                                      "again");
    const std::string planId = readPlanId(jobs);
    REFRAY_CHECK(mode == kPlanMode[0] || mode == kPlanMode[1], (jobs / "mode").string() << " says '" << mode
                                                                  << "', not 'make' or 'update'");
    // Every render first: a missing one is named with the line that makes it, before anything is written.
    std::vector<std::string> missing;
    for (const GoldenEntry& e : plan.entries)
        for (const EnvelopePart& part : envelopeParts(e, 0))
            if (!fs::exists(goldenJobOutput(goldenDirectory, e.name, part.name)))
                missing.push_back(e.name + " " + part.name);
    if (!missing.empty()) {
        std::string list;
        for (size_t i = 0; i < missing.size() && i < 10; ++i) list += "\n  refray golden job DIR " + missing[i];
        REFRAY_CHECK(false, missing.size() << " of the plan's renders are missing in " << jobs.string()
                                           << " (a job that failed or has not run); run them:" << list
                                           << (missing.size() > 10 ? "\n  ..." : ""));
    }
    const fs::path manifest = goldenDirectory / "goldens.json";
    GoldenSet set = existingSet(manifest);
    if (mode == "update") set.entries.clear();
    for (GoldenEntry e : plan.entries) {
        std::map<std::string, Image> renders;
        std::map<std::string, double> seconds;
        for (const EnvelopePart& part : envelopeParts(e, 0)) {
            const std::string file = goldenJobOutput(goldenDirectory, e.name, part.name).string();
            Image image = readImage(file);
            const auto meta = [&image](const char* key) {
                const auto it = image.metadata.find(key);
                return it == image.metadata.end() ? std::string("(none)") : it->second;
            };
            REFRAY_CHECK(meta("golden_plan_id") == planId,
                         file << " was not rendered for this plan (its plan id is " << meta("golden_plan_id")
                              << ", the plan's " << planId
                              << "): a stale render of an earlier plan or a foreign file; delete it and run its line "
                                 "again: refray golden job DIR "
                              << e.name << " " << part.name);
            REFRAY_CHECK(meta("golden_job") == e.name + " " + part.name && meta("golden_plan_settings") == planSettings(e) &&
                             image.width() == e.width && image.height() == e.height,
                         file << " is the render '" << meta("golden_job") << "' with settings '"
                              << meta("golden_plan_settings") << "' (" << image.width() << "x" << image.height()
                              << "), not '" << e.name << " " << part.name << "' with '" << planSettings(e)
                              << "'; delete it and run its line again");
            for (const char* key : {"golden_plan_id", "golden_job", "golden_plan_settings"}) image.metadata.erase(key);
            const auto t = image.metadata.find("golden_job_seconds");
            seconds[part.name] = t == image.metadata.end() ? 0.0 : std::stod(t->second);
            if (t != image.metadata.end()) image.metadata.erase(t);
            renders[part.name] = std::move(image);
        }
        const Envelope envelope = assembleEnvelope(e, renders, seconds);
        addEntry(set, goldenDirectory, e, envelope);
        if (onEntry) onEntry(e);
    }
    writeGoldenManifest(manifest, set);
    // The plan and the renders were only the way here: a golden directory holds goldens (tests/golden stays clean).
    fs::remove_all(jobs);
    return set;
}

std::vector<GoldenEntry> planUpdate(const GoldenUpdateOptions& options) {
    std::vector<fs::path> files;
    for (const auto& f : fs::directory_iterator(options.repositoryRoot / "scenes"))
        if (f.is_regular_file() && f.path().extension() == ".json") files.push_back(f.path());
    std::sort(files.begin(), files.end());
    REFRAY_CHECK(!files.empty(), "no scene files in " << (options.repositoryRoot / "scenes").string());
    std::vector<GoldenEntry> entries;
    for (const fs::path& file : files) {
        const SceneDesc desc = loadSceneFile(file);
        if (isMonteCarlo(desc)) continue;  // statistical goldens only
        for (const CameraDesc& camera : desc.cameras)
            entries.push_back(entryFor(desc, file, options.repositoryRoot, camera, "", options.width, options.height,
                                       options.orders, options.perturbedRenders, options.refrayCommit));
    }
    return entries;
}

GoldenEntry planMake(const GoldenMakeOptions& options) {
    const SceneDesc desc = loadSceneFile(options.sceneFile);
    REFRAY_CHECK(!isMonteCarlo(desc), options.sceneFile.string()
                                          << " is a Monte Carlo scene: it gets a statistical golden (docs/compare.md), "
                                             "not an envelope");
    const CameraDesc& camera = options.camera.empty() ? desc.cameras.at(0) : desc.camera(options.camera);
    return entryFor(desc, options.sceneFile, options.repositoryRoot, camera, options.time, options.width,
                    options.height, options.orders, options.perturbedRenders, options.refrayCommit);
}


GoldenSet updateGoldens(const GoldenUpdateOptions& options) {
    const std::vector<GoldenEntry> planned = planUpdate(options);
    fs::create_directories(options.goldenDirectory);
    const fs::path manifest = options.goldenDirectory / "goldens.json";
    GoldenSet set;
    set.statistical = existingSet(manifest).statistical;
    std::unique_ptr<Scene> scene;
    std::string sceneFile;  // the planned entries come file by file: each file is built once
    for (GoldenEntry e : planned) {
        const auto start = std::chrono::steady_clock::now();
        if (!scene || sceneFile != e.scene) {
            scene = std::make_unique<Scene>(loadSceneFile(options.repositoryRoot / e.scene));
            sceneFile = e.scene;
            if (options.onSceneBuilt) options.onSceneBuilt(*scene);
        }
        EnvelopeRenderOptions render;
        render.threads = options.threads;
        render.onRender = options.onRender;
        const Envelope envelope = renderEnvelope(*scene, e, render);
        addEntry(set, options.goldenDirectory, e, envelope);
        if (options.onEntry) options.onEntry(e, secondsSince(start));
    }
    for (StatisticalGoldenEntry& e : set.statistical) {
        const auto start = std::chrono::steady_clock::now();
        Scene statisticalScene(loadSceneFile(options.repositoryRoot / e.scene));
        e.sceneSha256 = statisticalScene.desc().fileHash;
        e.refrayCommit = options.refrayCommit;
        StatisticsImage stats = renderStatistics(statisticalScene, e, e.seed, e.batches, options.threads);
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
