// `refray sweep` (issue 7): what accuracy costs in time. A sweep renders one scene and camera with every value of
// each accuracy knob (scenes/knobs.h), one knob at a time from the defaults, times each setting (median of several
// renders, one thread count), and measures its error against a high-accuracy reference render with the comparator
// of `refray compare`. The results go to a directory: sweep.csv, sweep.md and PNG plots of error against time.
//
// Every setting is an independent job. A sweep is planned (plan.json), each job renders one setting into
// runs/<id>.exr + runs/<id>.json, and collecting compares every run with the reference run and writes the report.
// `refray sweep` does the three in one process; --emit-jobs writes the job command lines for a job runner and
// --collect does the last step over what the jobs wrote.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/compare.h"
#include "core/progress.h"

namespace refray::scenes {

// The reference's settings unless --reference gives others: double precision, 8x the march steps, a quarter of the
// thresholds, 8x the metaball samples and 16 samples per pixel. Fractal iterations and the recursion depth stay the
// HLSL's: they define the surface and the number of bounces the scene shows, which the approximations converge to.
inline constexpr const char* kDefaultSweepReference = "precision=double,steps=8,threshold=0.25,metaball-steps=1024,spp=16";

struct SweepKnob {
    std::string name;                 // a knob of scenes/knobs.h
    std::vector<std::string> values;  // as written on the command line
};

struct SweepPlan {
    std::filesystem::path scene;  // as given (jobs run from the same working directory)
    std::string camera;           // empty: the scene's default camera
    std::optional<float> time;    // empty: the scene's default time
    uint32_t width = 320, height = 180;
    uint32_t threads = 0;  // 0: all hardware threads (resolved when the plan is made, so every run uses the same)
    uint32_t repeats = 3;  // timed renders per setting; the median counts
    std::string reference = kDefaultSweepReference;
    std::vector<SweepKnob> knobs;
};

// One setting of a plan: the defaults with at most one knob changed, or a reference.
struct SweepRun {
    std::string id;        // file-name safe: "reference", "reference-spp1", "defaults", "steps=0.5", ...
    std::string knob;      // empty for references and "defaults"
    std::string value;     // the knob's value as text ("" for references and defaults)
    std::string settings;  // the knob list it renders with ("defaults" or "name=value,...")
    // The reference with this run's samples per pixel: "reference" itself when the spp agree, else
    // "reference-spp<N>". Comparing with it leaves out the sampling error and measures what the numerical knobs
    // change. Empty for references.
    std::string sameSamplingReference;

    bool isReference() const { return sameSamplingReference.empty(); }
};

// The runs of a plan: the reference, the reference at each other spp the rows use ("reference-spp<N>"), the
// defaults, then every knob value that is not the default, in plan order. Throws refray::Error for an unknown
// knob or a bad value (checked by applying it).
std::vector<SweepRun> planRuns(const SweepPlan& plan);

// A finished run as a job leaves it in runs/<id>.json (its image is runs/<id>.exr).
struct SweepTiming {
    std::string id;
    std::vector<double> seconds;  // wall time of each timed render, in order
    double medianSeconds = 0.0;
    uint32_t threads = 0;
    std::string host;
    uint64_t warnings = 0;  // DXR diagnostics of the render (e.g. GEN-4 non-finite pixels)
};

// Writes `dir`/plan.json (creates `dir`). Resolves plan.threads = 0 to the hardware thread count first.
void writeSweepPlan(const std::filesystem::path& dir, SweepPlan plan);
// Reads plan.json; errors name the file and line.
SweepPlan readSweepPlan(const std::filesystem::path& dir);

// The work of one run for a progress bar: its renders times its samples per pixel.
uint64_t sweepJobUnits(const SweepPlan& plan, const SweepRun& run);

// Renders run `id` of the plan in `dir` `repeats` times (the reference once) and writes runs/<id>.exr and
// runs/<id>.json. `progress` (optional) advances by the run's samples per pixel per render.
SweepTiming runSweepJob(const std::filesystem::path& dir, const std::string& id, Progress* progress = nullptr);

// The command lines that run each job of the plan in `dir`, one per line: `refray sweep --job ID DIR`, with
// `refray` replaced by `executable`.
std::vector<std::string> sweepJobCommands(const std::filesystem::path& dir, const std::string& executable);

// A run against one reference image, by the comparator of `refray compare`.
struct SweepError {
    CompareResult idiff;   // idiff's default thresholds (a pixel fails at 1e-6)
    CompareResult golden;  // the --golden profile (a pixel fails at 0.005; the image when over 0.1 % of them do)
};

// One row of the report.
struct SweepRow {
    SweepRun run;
    SweepTiming timing;
    SweepError total;      // against the reference: sampling and numerical error together
    SweepError numerical;  // against the same-sampling reference: what the numerical knobs leave
    // The error the row is judged by: total for the spp knob, numerical for every other row.
    const SweepError& judged() const { return run.knob == "spp" ? total : numerical; }
    bool onFront = false;  // on the Pareto front of (median time, judged RMSE) among its knob's rows and the defaults
    bool onGlobalFront = false;  // ... of (median time, numerical RMSE) among the rows with one sample per pixel
};

// One render of the golden search (runGoldenSearch).
struct GoldenSearchStep {
    std::string knob;      // the knob relaxed in this step
    std::string value;     // the value tried
    std::string settings;  // the whole setting rendered
    SweepTiming timing;
    SweepError error;  // against the one-sample reference
    bool passes = false;  // --golden does not fail (PASS or WARNING); a passing value is kept
};

struct SweepReport {
    SweepPlan plan;
    SweepTiming referenceTiming;
    std::vector<SweepRow> rows;  // defaults first, then planRuns order (the reference is not a row)
    std::vector<std::string> missing;  // run ids with no result in runs/
    // The defaults' render against the same settings in double precision, when "precision=double" was swept: how
    // far float rounding alone moves the HLSL's image, i.e. what a GPU's own float arithmetic may move it too.
    std::optional<SweepError> floatAgainstDouble;
    // The cheapest row (by median time) with one sample per pixel, as the GPU renders, that passes the --golden
    // profile against the one-sample reference; empty if none.
    std::optional<size_t> goldenSettings;
    std::vector<std::filesystem::path> plots;  // written PNGs, relative to the sweep directory
    // The golden search, when one was run (golden-search.json): its start (the one-sample reference's settings,
    // timed) and each step, in order.
    std::optional<GoldenSearchStep> goldenSearchStart;
    std::vector<GoldenSearchStep> goldenSearch;
    // The settings the search ended with: the cheapest it found that pass.
    std::string goldenSearchResult;
};

// A golden needs several knobs raised together, which a one-knob-at-a-time sweep cannot show. The search starts from
// the reference's settings at one sample per pixel (which pass against the one-sample reference by construction)
// and relaxes one knob at a time towards its default: precision, then steps, metaball-steps, threshold, then any
// other. For each knob it tries the default, then the plan's swept values between the default and the reference's,
// nearest the default first, and keeps the first value whose render still passes --golden. Each try is rendered and
// timed like a run (runs/golden-<n>.exr / .json). Needs the one-sample reference run of the plan; writes
// golden-search.json, which collectSweep reports. `progress` advances per render.
std::vector<GoldenSearchStep> runGoldenSearch(const std::filesystem::path& dir, Progress* progress = nullptr);
// The renders runGoldenSearch makes at most (for a progress bar): repeats per candidate value.
uint64_t goldenSearchUnits(const SweepPlan& plan);

// Compares every run in `dir` with the reference run and writes sweep.csv, sweep.md and plots/*.png. Throws
// refray::Error when the reference run or the defaults run is missing (other missing runs are listed).
SweepReport collectSweep(const std::filesystem::path& dir);

}  // namespace refray::scenes
