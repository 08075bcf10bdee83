#include "tools/sweep_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/progress.h"
#include "core/strings.h"
#include "scenes/knobs.h"
#include "study/sweep.h"
#include "study/sweep_report.h"
#include "tools/cli_common.h"

namespace refray::tools {

namespace fs = std::filesystem;

namespace {

constexpr const char* kFooter = R"(Each setting changes one knob from the defaults (the HLSL's constants, float, 1 sample per pixel).
Knobs:
%s
Examples:
  refray sweep scenes/proceduray-mandel-julia-pac.json --knob steps=0.25,0.5,2 --knob spp=4,16 -o sweep-out
  refray sweep SCENE --knob steps=0.5,2 -o DIR --emit-jobs jobs.txt && parallel < jobs.txt && refray sweep --collect DIR
The report: DIR/sweep.md, DIR/sweep.csv, DIR/plots/*.png; docs/accuracy-vs-time.md explains them.)";

std::string knobList() {
    std::string text;
    for (const scenes::KnobInfo& k : scenes::knobs()) {
        char line[256];
        std::snprintf(line, sizeof line, "  %-22s %s (default %s)\n", k.name.c_str(), k.description.c_str(),
                      scenes::knobValue(scenes::RenderSettings{}, k.name).c_str());
        text += line;
    }
    return text;
}

scenes::SweepKnob parseKnobOption(const std::string& text) {
    const size_t eq = text.find('=');
    REFRAY_CHECK(eq != std::string::npos && eq > 0 && eq + 1 < text.size(),
                 "--knob expects NAME=v1,v2,... (e.g. --knob steps=0.5,1,2), got " << inQuotes(text));
    scenes::SweepKnob knob;
    knob.name = text.substr(0, eq);
    std::string_view values(text);
    values.remove_prefix(eq + 1);
    while (true) {
        const size_t comma = values.find(',');
        knob.values.emplace_back(values.substr(0, comma));
        REFRAY_CHECK(!knob.values.back().empty(), "--knob " << knob.name << " has an empty value in " << inQuotes(text));
        if (comma == std::string_view::npos) break;
        values.remove_prefix(comma + 1);
    }
    return knob;
}

void printSummary(const scenes::SweepReport& report, const fs::path& dir) {
    std::printf("%-36s %9s %9s %11s %9s %-9s %11s\n", "setting", "median s", "x default", "num. RMSE", "> 0.005 %",
                "--golden", "total RMSE");
    double base = 0.0;
    for (const scenes::SweepRow& r : report.rows)
        if (r.run.id == "defaults") base = r.timing.medianSeconds;
    for (const scenes::SweepRow& r : report.rows)
        std::printf("%-36s %9.3f %9.2f %11.4g %9.3g %-9s %11.4g%s\n", r.run.id.c_str(), r.timing.medianSeconds,
                    base > 0 ? r.timing.medianSeconds / base : 0.0, r.numerical.idiff.rmse,
                    r.numerical.golden.failingPercent(), std::string(toString(r.numerical.golden.verdict)).c_str(),
                    r.total.idiff.rmse, r.onGlobalFront ? "  (front)" : "");
    if (!report.goldenSearchResult.empty())
        std::printf("golden settings (golden search): %s\n", report.goldenSearchResult.c_str());
    else if (report.goldenSettings)
        std::printf("golden settings (cheapest one-sample setting passing --golden): %s\n",
                    report.rows[*report.goldenSettings].run.settings.c_str());
    else
        std::printf("no one-sample setting passes --golden against the one-sample reference\n");
    if (!report.missing.empty()) std::printf("missing runs: %s\n", joined(report.missing).c_str());
    std::printf("wrote %s, %s and %zu plots in %s\n", (dir / "sweep.md").string().c_str(),
                (dir / "sweep.csv").string().c_str(), report.plots.size(), (dir / "plots").string().c_str());
}

void goldenSearch(const std::string& dir) {
    Progress progress("golden search", scenes::goldenSearchUnits(scenes::readSweepPlan(dir)), terminalProgress(),
                      std::chrono::milliseconds(250));
    const std::vector<scenes::GoldenSearchStep> steps = scenes::runGoldenSearch(dir, &progress);
    progress.finish();
    for (const scenes::GoldenSearchStep& s : steps)
        std::printf("golden search: %-22s %-36s %8.3f s  %-8s %s\n",
                    s.knob.empty() ? "start" : (s.knob + "=" + s.value).c_str(), s.settings.c_str(),
                    s.timing.medianSeconds, std::string(toString(s.error.golden.verdict)).c_str(),
                    s.knob.empty() ? "" : (s.passes ? "kept" : "rejected"));
}

}  // namespace

CLI::App* addSweepCommand(CLI::App& app, SweepCommandOptions& o) {
    CLI::App* sweep = app.add_subcommand("sweep", "What accuracy costs in time: render every knob value, time it and "
                                                  "measure its error against a high-accuracy reference");
    sweep->add_option("scene", o.scene, "Scene file (not with --collect or --job: the plan names it)");
    sweep->add_option("--knob", o.knobs, "A knob and its values, NAME=v1,v2,... (repeatable)");
    sweep->add_option("--reference", o.reference, "The reference's knob settings, NAME=V,NAME=V,...")
        ->default_str(scenes::kDefaultSweepReference);
    sweep->add_option("--camera", o.camera, "Camera name (default: the scene's defaultCamera)");
    sweep->add_option("--size", o.size, "Image size WIDTHxHEIGHT")->capture_default_str();
    sweep->add_option("--time", o.time, "Animation time in seconds (default: the scene's)")->check(seconds());
    sweep->add_option("--threads", o.threads, "Worker threads of every render (0: all, fixed when planned)")
        ->check(threadCount())
        ->capture_default_str();
    sweep->add_option("--repeats", o.repeats, "Timed renders per setting (the median counts)")
        ->check(wholeNumber("a number of timed renders, at least 1", 1))
        ->capture_default_str();
    sweep->add_option("-o,--output", o.output, "The sweep directory")->capture_default_str();
    sweep->add_option("--emit-jobs", o.emitJobs, "Plan only: write one command line per setting to this file");
    sweep->add_option("--collect", o.collect, "Report only: merge the runs in this sweep directory");
    sweep->add_option("--job", o.job, "Render one setting (a run id of the plan in --output); what --emit-jobs writes");
    sweep->add_flag("--golden-search", o.goldenSearch,
                    "Also search for the cheapest one-sample settings that pass --golden: relax the reference's knobs "
                    "one at a time towards their defaults (sequential; with --collect, after merging)");
    char footer[4096];
    std::snprintf(footer, sizeof footer, kFooter, knobList().c_str());
    sweep->footer(footer);
    return sweep;
}

int runSweep(const SweepCommandOptions& o) {
    REFRAY_CHECK(int(!o.collect.empty()) + int(!o.job.empty()) + int(!o.emitJobs.empty()) <= 1,
                 "--collect, --job and --emit-jobs are separate steps; give one of them");
    REFRAY_CHECK(!o.goldenSearch || (o.job.empty() && o.emitJobs.empty()),
                 "--golden-search renders one setting after another; give it to the sweep itself or to --collect");
    if (!o.collect.empty()) {
        REFRAY_CHECK(o.scene.empty() && o.knobs.empty(), "--collect reads the plan in " << o.collect
                                                                                          << "; give no scene or knobs");
        if (o.goldenSearch) goldenSearch(o.collect);
        printSummary(scenes::collectSweep(o.collect), o.collect);
        return 0;
    }
    if (!o.job.empty()) {
        REFRAY_CHECK(o.scene.empty() && o.knobs.empty(), "--job renders a setting of the plan in " << o.output
                                                                                                     << "; give no scene or knobs");
        const scenes::SweepTiming t = scenes::runSweepJob(o.output, o.job);
        std::printf("%s: median %.3f s of %zu renders (%u threads)\n", o.job.c_str(), t.medianSeconds, t.seconds.size(),
                    t.threads);
        return 0;
    }

    REFRAY_CHECK(!o.scene.empty(), "refray sweep needs a scene file (or --collect DIR / --job ID)");
    REFRAY_CHECK(!o.knobs.empty(), "refray sweep needs at least one --knob NAME=v1,v2,...; knobs:\n" << knobList());
    checkOutputs({{"scene file", o.scene}},
                 {{"--emit-jobs", o.emitJobs}, {"plan.json (in -o)", (fs::path(o.output) / "plan.json").string()}});
    scenes::SweepPlan plan;
    plan.scene = o.scene;
    plan.camera = o.camera;
    plan.time = o.time;
    const Size size = parseSize(o.size);
    plan.width = size.width;
    plan.height = size.height;
    plan.threads = o.threads;
    plan.repeats = o.repeats;
    if (!o.reference.empty()) plan.reference = o.reference;
    for (const std::string& k : o.knobs) plan.knobs.push_back(parseKnobOption(k));
    scenes::writeSweepPlan(o.output, plan);

    if (!o.emitJobs.empty()) {
        const std::vector<std::string> lines = scenes::sweepJobCommands(o.output, fs::read_symlink("/proc/self/exe").string());
        std::string text;
        for (const std::string& l : lines) text += l + "\n";
        writeTextFile(o.emitJobs, text);
        std::printf("planned %zu runs in %s; wrote their command lines to %s\n"
                    "run them (e.g. 'parallel < %s'), then: refray sweep --collect %s\n",
                    lines.size(), o.output.c_str(), o.emitJobs.c_str(), o.emitJobs.c_str(), o.output.c_str());
        return 0;
    }

    const scenes::SweepPlan written = scenes::readSweepPlan(o.output);
    const std::vector<scenes::SweepRun> runs = scenes::planRuns(written);
    uint64_t units = 0;
    for (const scenes::SweepRun& r : runs) units += scenes::sweepJobUnits(written, r);
    Progress progress("sweep", units, terminalProgress(), std::chrono::milliseconds(250));
    for (const scenes::SweepRun& r : runs) scenes::runSweepJob(o.output, r.id, &progress);
    progress.finish();
    if (o.goldenSearch) goldenSearch(o.output);
    printSummary(scenes::collectSweep(o.output), o.output);
    return 0;
}

}  // namespace refray::tools
