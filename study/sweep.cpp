#include "study/sweep.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "core/error.h"
#include "core/json.h"
#include "core/json_writer.h"
#include "core/strings.h"
#include "core/text_file.h"
#include "scenes/knobs.h"
#include "scenes/scene.h"
#include "study/sweep_report.h"

namespace refray::scenes {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPlanFormat = "refray-sweep-plan/1";
constexpr const char* kRunFormat = "refray-sweep-run/1";

std::string hostName() {
    char name[256] = {};
    if (gethostname(name, sizeof name - 1) != 0) return "unknown";
    return name;
}

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The settings of a plan's render before any knob: size, camera, time, threads.
RenderSettings baseSettings(const SweepPlan& plan) {
    RenderSettings s;
    s.width = plan.width;
    s.height = plan.height;
    s.threads = plan.threads;
    s.camera = plan.camera;
    s.time = plan.time;
    return s;
}

RenderSettings runSettings(const SweepPlan& plan, const SweepRun& run) {
    RenderSettings s = baseSettings(plan);
    if (run.settings != "defaults") applyKnobList(s, run.settings);
    return s;
}

const SweepRun& findRun(const std::vector<SweepRun>& runs, const std::string& id, const fs::path& dir) {
    for (const SweepRun& r : runs)
        if (r.id == id) return r;
    std::vector<std::string> ids;
    for (const SweepRun& r : runs) ids.push_back(r.id);
    throw Error("the sweep in " + dir.string() + " has no run " + inQuotes(id) + didYouMean(id, ids) +
                "; its runs: " + joined(ids));
}

// Parses a file of the sweep and checks its "format" member (which `reader` then counts as read).
json::Value parseSweepFile(const fs::path& path, const char* format) {
    json::Value root = json::parseFile(path);
    if (const json::Value* f = root.isObject() ? root.find("format") : nullptr; f && f->isString() && f->asString() != format)
        f->fail("expected format " + inQuotes(format));
    return root;
}

fs::path runImagePath(const fs::path& dir, const std::string& id) { return dir / "runs" / (id + ".exr"); }
fs::path runJsonPath(const fs::path& dir, const std::string& id) { return dir / "runs" / (id + ".json"); }

SweepTiming readTiming(const fs::path& path) {
    const json::Value root = parseSweepFile(path, kRunFormat);
    json::ObjectReader r(root, "a sweep run");
    r.required("format").asString();
    SweepTiming t;
    t.id = r.required("id").asString();
    r.required("settings");
    for (const json::Value& s : r.required("seconds").asArray()) t.seconds.push_back(s.asNumber());
    t.medianSeconds = r.required("medianSeconds").asNumber();
    t.threads = r.required("threads").asUint32();
    t.host = r.required("host").asString();
    t.warnings = uint64_t(r.required("warnings").asInt());
    r.finish();
    return t;
}

}  // namespace

std::vector<SweepRun> planRuns(const SweepPlan& plan) {
    RenderSettings reference = baseSettings(plan);
    applyKnobList(reference, plan.reference);
    auto sameSampling = [&](uint32_t spp) {
        return spp == reference.spp ? std::string("reference") : "reference-spp" + std::to_string(spp);
    };

    std::vector<SweepRun> rows = {{"defaults", "", "", "defaults", sameSampling(1)}};
    std::set<std::string> seen = {"defaults"};
    std::set<uint32_t> samplings = {1};
    for (const SweepKnob& k : plan.knobs) {
        REFRAY_CHECK(!k.values.empty(), "knob " << k.name << " has no values to sweep (write --knob " << k.name
                                                << "=v1,v2,...)");
        for (const std::string& v : k.values) {
            RenderSettings s = baseSettings(plan);
            applyKnob(s, k.name, v);
            if (knobValue(s, k.name) == knobValue(RenderSettings{}, k.name)) continue;  // the defaults row
            const std::string settings = describeKnobs(s);
            if (!seen.insert(settings).second) continue;  // a repeat
            rows.push_back({settings, k.name, knobValue(s, k.name), settings, sameSampling(s.spp)});
            samplings.insert(s.spp);
        }
    }

    std::vector<SweepRun> runs = {{"reference", "", "", describeKnobs(reference), ""}};
    for (uint32_t spp : samplings) {
        if (spp == reference.spp) continue;
        RenderSettings s = reference;
        s.spp = spp;
        runs.push_back({sameSampling(spp), "", "", describeKnobs(s), ""});
    }
    runs.insert(runs.end(), rows.begin(), rows.end());
    return runs;
}

void writeSweepPlan(const fs::path& dir, SweepPlan plan) {
    if (plan.threads == 0) plan.threads = std::max(1u, std::thread::hardware_concurrency());
    REFRAY_CHECK(plan.repeats >= 1, "--repeats must be at least 1");
    planRuns(plan);  // validates every knob and value before anything is written
    fs::create_directories(dir / "runs");
    json::Writer w;
    w.beginObject();
    w.member("format", kPlanFormat);
    w.member("scene", plan.scene.string());
    w.member("camera", plan.camera);
    if (plan.time) w.member("time", *plan.time);
    w.member("width", plan.width).member("height", plan.height);
    w.member("threads", plan.threads).member("repeats", plan.repeats);
    w.member("reference", plan.reference);
    w.key("knobs").beginArray();
    for (const SweepKnob& k : plan.knobs) {
        w.beginObject(json::Writer::Layout::Inline).member("name", k.name).key("values");
        w.beginArray(json::Writer::Layout::Inline);
        for (const std::string& v : k.values) w.value(v);
        w.endArray().endObject();
    }
    w.endArray().endObject();
    writeTextFile((dir / "plan.json").string(), w.text() + "\n");
}

SweepPlan readSweepPlan(const fs::path& dir) {
    const fs::path path = dir / "plan.json";
    REFRAY_CHECK(fs::exists(path), dir.string() << " holds no sweep (no plan.json); write one with 'refray sweep SCENE "
                                                   "--knob ... --emit-jobs FILE -o "
                                                << dir.string() << "'");
    const json::Value root = parseSweepFile(path, kPlanFormat);
    json::ObjectReader r(root, "the sweep plan");
    r.required("format").asString();
    SweepPlan plan;
    plan.scene = r.required("scene").asString();
    plan.camera = r.required("camera").asString();
    if (const json::Value* t = r.optional("time")) plan.time = t->asFloat();
    plan.width = r.required("width").asUint32();
    plan.height = r.required("height").asUint32();
    plan.threads = r.required("threads").asUint32();
    plan.repeats = r.required("repeats").asUint32();
    plan.reference = r.required("reference").asString();
    for (const json::Value& v : r.required("knobs").asArray()) {
        json::ObjectReader k(v, "a swept knob");
        SweepKnob knob;
        knob.name = k.required("name").asString();
        for (const json::Value& value : k.required("values").asArray()) knob.values.push_back(value.asString());
        k.finish();
        plan.knobs.push_back(std::move(knob));
    }
    r.finish();
    return plan;
}

uint64_t sweepJobUnits(const SweepPlan& plan, const SweepRun& run) {
    return uint64_t(run.isReference() ? 1 : plan.repeats) * runSettings(plan, run).spp;
}

namespace {

// Renders `settings` `renders` times, timing each, and writes runs/<id>.exr and runs/<id>.json.
SweepTiming renderRun(const fs::path& dir, Scene& scene, const SweepPlan& plan, const std::string& id,
                      const std::string& settingsText, const RenderSettings& settings, uint64_t renders,
                      Progress* progress) {
    SweepTiming timing;
    timing.id = id;
    timing.threads = plan.threads;
    timing.host = hostName();
    RenderResult result;
    for (uint64_t i = 0; i < renders; ++i) {
        const auto start = std::chrono::steady_clock::now();
        result = scene.render(settings);
        timing.seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        if (progress) progress->advance(settings.spp);
    }
    timing.medianSeconds = median(timing.seconds);
    timing.warnings = result.dispatch.diagnostics.warnings().size();

    fs::create_directories(dir / "runs");
    result.image.metadata["sweep_run"] = id;
    writeImage(runImagePath(dir, id).string(), result.image);
    json::Writer w;
    w.beginObject();
    w.member("format", kRunFormat).member("id", id).member("settings", settingsText);
    w.key("seconds").beginArray(json::Writer::Layout::Inline);
    for (double sec : timing.seconds) w.value(sec);
    w.endArray();
    w.member("medianSeconds", timing.medianSeconds).member("threads", timing.threads).member("host", timing.host);
    w.member("warnings", timing.warnings);
    w.endObject();
    writeTextFile((runJsonPath(dir, id)).string(), w.text() + "\n");
    return timing;
}

// Compares run images with reference runs, reading each reference once.
class ReferenceImages {
public:
    explicit ReferenceImages(fs::path dir) : dir_(std::move(dir)) {}
    SweepError errorOf(const std::string& referenceId, const Image& image) {
        auto it = images_.find(referenceId);
        if (it == images_.end()) it = images_.emplace(referenceId, readImage(runImagePath(dir_, referenceId).string())).first;
        SweepError e{compareImages(it->second, image, CompareThresholds{}),
                     compareImages(it->second, image, CompareThresholds::golden())};
        e.idiff.diffImage = Image();  // the report keeps numbers only
        e.golden.diffImage = Image();
        return e;
    }

private:
    fs::path dir_;
    std::map<std::string, Image> images_;
};

bool passesGolden(const SweepError& e) { return e.golden.verdict <= CompareVerdict::Warn; }

// The one-sample reference run of a plan (see planRuns).
const SweepRun& oneSampleReference(const std::vector<SweepRun>& runs, const fs::path& dir) {
    return findRun(runs, findRun(runs, "defaults", dir).sameSamplingReference, dir);
}

// The knobs the golden search relaxes, in order, with the values it tries for each.
std::vector<std::pair<std::string, std::vector<std::string>>> goldenSearchCandidates(const SweepPlan& plan,
                                                                                      const RenderSettings& start) {
    std::vector<std::string> order = {"precision", "steps", "metaball-steps", "threshold"};
    for (const KnobInfo& k : knobs())
        if (std::find(order.begin(), order.end(), k.name) == order.end() && k.name != "spp") order.push_back(k.name);
    const RenderSettings defaults;
    std::vector<std::pair<std::string, std::vector<std::string>>> candidates;
    for (const std::string& name : order) {
        const std::string from = knobValue(start, name), to = knobValue(defaults, name);
        if (from == to) continue;
        std::vector<std::string> values = {to};
        if (name != "precision") {
            // The plan's swept values strictly between the default and the start, nearest the default first.
            const double a = std::stod(to), b = std::stod(from);
            std::vector<std::pair<double, std::string>> between;
            for (const SweepKnob& k : plan.knobs)
                if (k.name == name)
                    for (const std::string& v : k.values) {
                        RenderSettings s;
                        applyKnob(s, name, v);
                        const double x = std::stod(knobValue(s, name));
                        if ((x - a) * (x - b) < 0.0) between.push_back({std::fabs(x - a), knobValue(s, name)});
                    }
            std::sort(between.begin(), between.end());
            for (const auto& [distance, v] : between)
                if (std::find(values.begin(), values.end(), v) == values.end()) values.push_back(v);
        }
        candidates.push_back({name, values});
    }
    return candidates;
}

constexpr const char* kGoldenSearchFormat = "refray-golden-search/1";

}  // namespace

SweepTiming runSweepJob(const fs::path& dir, const std::string& id, Progress* progress) {
    const SweepPlan plan = readSweepPlan(dir);
    const std::vector<SweepRun> runs = planRuns(plan);
    const SweepRun& run = findRun(runs, id, dir);
    const RenderSettings settings = runSettings(plan, run);
    std::unique_ptr<Scene> scene = loadScene(plan.scene);
    return renderRun(dir, *scene, plan, id, run.settings, settings, sweepJobUnits(plan, run) / settings.spp, progress);
}

uint64_t goldenSearchUnits(const SweepPlan& plan) {
    const std::vector<SweepRun> runs = planRuns(plan);
    RenderSettings start = runSettings(plan, runs.front());
    start.spp = 1;
    uint64_t tries = 1;
    for (const auto& [knob, values] : goldenSearchCandidates(plan, start)) tries += values.size();
    return tries * plan.repeats;
}

std::vector<GoldenSearchStep> runGoldenSearch(const fs::path& dir, Progress* progress) {
    const SweepPlan plan = readSweepPlan(dir);
    const std::vector<SweepRun> runs = planRuns(plan);
    const SweepRun& reference = oneSampleReference(runs, dir);
    REFRAY_CHECK(fs::exists(runImagePath(dir, reference.id)),
                 "the golden search compares with the one-sample reference; run its job first (refray sweep --job "
                     << reference.id << " -o " << dir.string() << ")");
    std::unique_ptr<Scene> scene = loadScene(plan.scene);
    ReferenceImages references(dir);

    RenderSettings current = runSettings(plan, reference);
    std::vector<GoldenSearchStep> steps;
    auto tryRender = [&](const std::string& knob, const std::string& value, const RenderSettings& s) {
        GoldenSearchStep step;
        step.knob = knob;
        step.value = value;
        step.settings = describeKnobs(s);
        const std::string id = "golden-" + std::to_string(steps.size());
        step.timing = renderRun(dir, *scene, plan, id, step.settings, s, plan.repeats, progress);
        step.error = references.errorOf(reference.id, readImage(runImagePath(dir, id).string()));
        step.passes = passesGolden(step.error);
        steps.push_back(step);
        return step.passes;
    };
    tryRender("", "", current);  // the start, timed; passes by construction (it is the reference's image)
    for (const auto& [knob, values] : goldenSearchCandidates(plan, current)) {
        for (const std::string& value : values) {
            RenderSettings candidate = current;
            applyKnob(candidate, knob, value);
            if (tryRender(knob, value, candidate)) {
                current = candidate;
                break;
            }
        }
    }

    json::Writer w;
    w.beginObject();
    w.member("format", kGoldenSearchFormat).member("reference", reference.id).member("result", describeKnobs(current));
    w.key("steps").beginArray();
    for (size_t i = 0; i < steps.size(); ++i)
        w.beginObject(json::Writer::Layout::Inline)
            .member("id", "golden-" + std::to_string(i))
            .member("knob", steps[i].knob)
            .member("value", steps[i].value)
            .member("settings", steps[i].settings)
            .endObject();
    w.endArray().endObject();
    writeTextFile((dir / "golden-search.json").string(), w.text() + "\n");
    return steps;
}

std::vector<std::string> sweepJobCommands(const fs::path& dir, const std::string& executable) {
    std::vector<std::string> lines;
    for (const SweepRun& r : planRuns(readSweepPlan(dir)))
        lines.push_back(shellQuoted(executable) + " sweep --job " + shellQuoted(r.id) + " -o " + shellQuoted(dir.string()));
    return lines;
}

SweepReport collectSweep(const fs::path& dir) {
    SweepReport report;
    report.plan = readSweepPlan(dir);
    const std::vector<SweepRun> runs = planRuns(report.plan);
    const SweepRun& defaults = findRun(runs, "defaults", dir);
    for (const std::string& required : {std::string("reference"), defaults.sameSamplingReference, defaults.id})
        REFRAY_CHECK(fs::exists(runJsonPath(dir, required)),
                     "the sweep in " << dir.string() << " has no " << required << " run yet ("
                                     << runJsonPath(dir, required).string() << "); run its job first");
    report.referenceTiming = readTiming(runJsonPath(dir, "reference"));
    ReferenceImages references(dir);
    std::set<std::string> missing;
    for (const SweepRun& run : runs)
        if (!fs::exists(runJsonPath(dir, run.id)) || !fs::exists(runImagePath(dir, run.id))) missing.insert(run.id);
    for (const SweepRun& run : runs) {
        if (missing.count(run.id)) report.missing.push_back(run.id);
        if (run.isReference() || missing.count(run.id) || missing.count(run.sameSamplingReference)) continue;
        SweepRow row;
        row.run = run;
        row.timing = readTiming(runJsonPath(dir, run.id));
        const Image image = readImage(runImagePath(dir, run.id).string());
        row.total = references.errorOf("reference", image);
        row.numerical = references.errorOf(run.sameSamplingReference, image);
        report.rows.push_back(std::move(row));
    }

    if (!missing.count("defaults") && !missing.count("precision=double") &&
        std::any_of(runs.begin(), runs.end(), [](const SweepRun& r) { return r.id == "precision=double"; })) {
        const Image doubleImage = readImage(runImagePath(dir, "precision=double").string());
        const Image floatImage = readImage(runImagePath(dir, "defaults").string());
        report.floatAgainstDouble = SweepError{compareImages(doubleImage, floatImage, CompareThresholds{}),
                                               compareImages(doubleImage, floatImage, CompareThresholds::golden())};
        report.floatAgainstDouble->idiff.diffImage = Image();
        report.floatAgainstDouble->golden.diffImage = Image();
    }

    if (fs::exists(dir / "golden-search.json")) {
        const json::Value root = parseSweepFile(dir / "golden-search.json", kGoldenSearchFormat);
        json::ObjectReader r(root, "the golden search");
        r.required("format").asString();
        const std::string referenceId = r.required("reference").asString();
        report.goldenSearchResult = r.required("result").asString();
        for (const json::Value& v : r.required("steps").asArray()) {
            json::ObjectReader step(v, "a golden search step");
            GoldenSearchStep g;
            const std::string id = step.required("id").asString();
            g.knob = step.required("knob").asString();
            g.value = step.required("value").asString();
            g.settings = step.required("settings").asString();
            step.finish();
            g.timing = readTiming(runJsonPath(dir, id));
            g.error = references.errorOf(referenceId, readImage(runImagePath(dir, id).string()));
            g.passes = passesGolden(g.error);
            if (!report.goldenSearchStart) report.goldenSearchStart = g;
            else report.goldenSearch.push_back(std::move(g));
        }
        r.finish();
    }
    markParetoFronts(report);
    report.goldenSettings = cheapestPassing(report);
    report.plots = writeSweepPlots(dir, report);
    writeTextFile((dir / "sweep.csv").string(), sweepCsv(report));
    writeTextFile((dir / "sweep.md").string(), sweepMarkdown(report));
    return report;
}

}  // namespace refray::scenes
