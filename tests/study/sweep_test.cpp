// The accuracy knobs by name (scenes/knobs.h) and `refray sweep`'s plan, jobs and report (study/sweep.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "scenes/knobs.h"
#include "scenes/scene.h"
#include "study/sweep.h"
#include "study/sweep_report.h"
#include "tests/scenes/scene_test_support.h"
#include "tests/error_of.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
using testing::readText;

const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

using refray::testing::errorOf;

fs::path freshDirectory(const std::string& name) {
    const fs::path dir = fs::path(REFRAY_TEST_OUTPUT_DIR) / name;
    fs::remove_all(dir);
    return dir;
}

TEST(Knobs, SetTheAccuracyFieldsAndSpellDefaultsOut) {
    RenderSettings s;
    EXPECT_EQ(describeKnobs(s), "defaults");
    EXPECT_EQ(knobValue(s, "julia-iterations"), "200");
    EXPECT_EQ(knobValue(s, "steps"), "1");
    applyKnobList(s, "steps=0.5,threshold=2,mandelbulb-iterations=6,julia-iterations=100,normal-epsilon=4,"
                     "metaball-steps=64,recursion-depth=5,spp=4,precision=double");
    EXPECT_EQ(s.accuracy.stepsFactor, 0.5);
    EXPECT_EQ(s.accuracy.thresholdFactor, 2.0);
    EXPECT_EQ(s.accuracy.mandelbulbIterations, 6u);
    EXPECT_EQ(s.accuracy.juliaIterations, 100u);
    EXPECT_EQ(s.accuracy.normalEpsilonFactor, 4.0);
    EXPECT_EQ(s.accuracy.metaballSteps, 64u);
    EXPECT_EQ(s.accuracy.maxRecursionDepth, 5u);
    EXPECT_EQ(s.spp, 4u);
    EXPECT_EQ(s.precision, procedural::Precision::Double);
    // The description reads back to the same settings.
    RenderSettings again;
    applyKnobList(again, describeKnobs(s));
    EXPECT_EQ(again.accuracy, s.accuracy);
    EXPECT_EQ(describeKnobs(again), describeKnobs(s));
}

TEST(Knobs, TheHlslValueIsTheDefaultHoweverItIsWritten) {
    RenderSettings s;
    applyKnobList(s, "julia-iterations=200,steps=1,spp=1,precision=float");
    EXPECT_TRUE(s.accuracy.isDefault());
    EXPECT_EQ(describeKnobs(s), "defaults");
    // recursion-depth keeps an explicit 3: it overrides a scene's effects block.
    applyKnob(s, "recursion-depth", "3");
    EXPECT_EQ(s.accuracy.maxRecursionDepth, 3u);
    EXPECT_EQ(describeKnobs(s), "recursion-depth=3");
}

TEST(Knobs, BadNamesAndValuesAreClearErrors) {
    RenderSettings s;
    EXPECT_EQ(errorOf([&] { applyKnob(s, "step", "2"); }),
              "unknown knob 'step' (did you mean 'steps'?); knobs: steps, threshold, mandelbulb-iterations, "
              "julia-iterations, normal-epsilon, metaball-steps, recursion-depth, spp, precision");
    EXPECT_EQ(errorOf([&] { applyKnob(s, "steps", "0"); }), "knob steps expects a factor between 0.001 and 1000, got '0'");
    EXPECT_EQ(errorOf([&] { applyKnob(s, "steps", "nan"); }), "knob steps expects a factor between 0.001 and 1000, got 'nan'");
    EXPECT_EQ(errorOf([&] { applyKnob(s, "recursion-depth", "32"); }),
              "knob recursion-depth expects a whole number from 1 to 31, got '32'");
    EXPECT_EQ(errorOf([&] { applyKnob(s, "spp", "8"); }), "knob spp expects a square number (1, 4, 9, 16, ...), got '8'");
    EXPECT_EQ(errorOf([&] { applyKnob(s, "precision", "half"); }), "knob precision expects float or double, got 'half'");
    EXPECT_EQ(errorOf([&] { applyKnobAssignment(s, "steps"); }), "a knob setting is name=value (e.g. steps=2), got 'steps'");
    EXPECT_TRUE(s.accuracy.isDefault());
}

// A recursion depth beyond the scene's MaxTraceRecursionDepth raises the pipeline's (it is the shaders and the host
// recompiled together), so deeper reflections render instead of stopping on REC-1.
TEST(Knobs, RecursionDepthRaisesThePipelineDepth) {
    std::unique_ptr<Scene> scene = loadScene(kD3D12);
    RenderSettings s;
    s.width = 32, s.height = 18, s.threads = 1;
    const RenderResult base = scene->render(s);
    applyKnob(s, "recursion-depth", "6");
    const RenderResult deeper = scene->render(s);
    EXPECT_TRUE(deeper.dispatch.diagnostics.errors().empty());
    EXPECT_EQ(deeper.image.metadata.at("knobs"), "recursion-depth=6");
    EXPECT_GT(deeper.dispatch.stats.raysPerDepth.size(), base.dispatch.stats.raysPerDepth.size());
}

SweepPlan smallPlan() {
    SweepPlan plan;
    plan.scene = kD3D12;
    plan.width = 24, plan.height = 14;
    plan.threads = 2;
    plan.repeats = 2;
    plan.knobs = {{"spp", {"1", "4"}}, {"precision", {"double", "float"}}, {"steps", {"0.01", "1"}}};
    return plan;
}

TEST(Sweep, PlanHasOneReferencePerSamplingAndNoDuplicateRows) {
    const std::vector<SweepRun> runs = planRuns(smallPlan());
    std::vector<std::string> ids;
    for (const SweepRun& r : runs) ids.push_back(r.id);
    EXPECT_EQ(ids, (std::vector<std::string>{"reference", "reference-spp1", "reference-spp4", "defaults", "spp=4",
                                             "precision=double", "steps=0.01"}));
    EXPECT_EQ(runs[0].settings, "steps=8,threshold=0.25,metaball-steps=1024,spp=16,precision=double");
    EXPECT_EQ(runs[1].settings, "steps=8,threshold=0.25,metaball-steps=1024,precision=double");
    EXPECT_TRUE(runs[2].isReference());
    EXPECT_EQ(runs[3].sameSamplingReference, "reference-spp1");
    EXPECT_EQ(runs[4].sameSamplingReference, "reference-spp4");
    EXPECT_EQ(runs[6].knob, "steps");
    EXPECT_EQ(runs[6].value, "0.01");

    SweepPlan bad = smallPlan();
    bad.knobs.push_back({"iterations", {"2"}});
    EXPECT_EQ(errorOf([&] { planRuns(bad); }).rfind("unknown knob 'iterations'", 0), 0u);
}

// The whole pipeline on a tiny image: plan, every job, the report. Renders are deterministic, so a row that renders
// the reference's settings has zero error, and more samples per pixel come closer to the supersampled reference.
TEST(Sweep, JobsAndCollectWriteTheReport) {
    const fs::path dir = freshDirectory("sweep-small");
    SweepPlan plan = smallPlan();
    plan.reference = "precision=double,spp=4";  // cheap: the "spp=4,precision=double" row would equal it
    writeSweepPlan(dir, plan);
    const std::vector<SweepRun> runs = planRuns(readSweepPlan(dir));
    ASSERT_EQ(runs.size(), 6u);  // reference, reference-spp1, defaults, spp=4, precision=double, steps=0.01
    for (const SweepRun& r : runs) {
        const SweepTiming t = runSweepJob(dir, r.id);
        EXPECT_EQ(t.seconds.size(), r.isReference() ? 1u : 2u) << r.id;
        EXPECT_EQ(t.threads, 2u);
    }
    const SweepReport report = collectSweep(dir);
    ASSERT_EQ(report.rows.size(), 4u);
    EXPECT_TRUE(report.missing.empty());
    const SweepRow& defaults = report.rows[0];
    const SweepRow& spp4 = report.rows[1];
    const SweepRow& doubleRow = report.rows[2];
    EXPECT_EQ(defaults.run.id, "defaults");
    // precision=double at one sample is exactly the one-sample reference.
    EXPECT_EQ(doubleRow.run.id, "precision=double");
    EXPECT_EQ(doubleRow.numerical.idiff.rmse, 0.0);
    EXPECT_EQ(doubleRow.numerical.golden.verdict, CompareVerdict::Pass);
    EXPECT_GT(doubleRow.total.idiff.rmse, 0.0);
    // Sampling: 4 samples are closer to the 4-sample reference than 1 sample is.
    EXPECT_LT(spp4.total.idiff.rmse, defaults.total.idiff.rmse);
    // The golden settings pass against the one-sample reference and use one sample.
    ASSERT_TRUE(report.goldenSettings);
    const SweepRow& golden = report.rows[*report.goldenSettings];
    EXPECT_NE(golden.run.knob, "spp");
    EXPECT_LE(golden.numerical.golden.verdict, CompareVerdict::Warn);

    // The files: CSV with a header and one line per row, the markdown, one plot per knob and one of all.
    std::istringstream csv(readText((dir / "sweep.csv").string()));
    std::string header, line;
    std::getline(csv, header);
    EXPECT_EQ(header.rfind("id,knob,value,settings,median_seconds,time_vs_defaults,seconds,threads,host,warnings,", 0), 0u);
    size_t lines = 0;
    while (std::getline(csv, line)) ++lines;
    EXPECT_EQ(lines, report.rows.size());
    const std::string md = readText((dir / "sweep.md").string());
    EXPECT_NE(md.find("## Golden settings"), std::string::npos);
    EXPECT_NE(md.find("**`" + golden.run.settings + "`**"), std::string::npos);
    EXPECT_NE(md.find("![steps: RMSE against time](plots/steps.png)"), std::string::npos);
    for (const char* p : {"plots/spp.png", "plots/precision.png", "plots/steps.png", "plots/all.png"}) {
        ASSERT_TRUE(fs::exists(dir / p)) << p;
        EXPECT_EQ(readImage((dir / p).string()).width(), 800u) << p;
    }

    // A job that has not run is listed; without the reference there is nothing to compare with.
    fs::remove(dir / "runs" / "steps=0.01.json");
    EXPECT_EQ(collectSweep(dir).missing, std::vector<std::string>{"steps=0.01"});
    fs::remove(dir / "runs" / "reference.json");
    EXPECT_NE(errorOf([&] { collectSweep(dir); }).find("has no reference run yet"), std::string::npos);
}

// The golden search starts at the reference's settings with one sample (identical to the one-sample reference), tries
// precision first, then steps at the default and at the swept value between default and reference, and keeps a value
// exactly when its render passes --golden.
TEST(Sweep, GoldenSearchRelaxesOneKnobAtATime) {
    const fs::path dir = freshDirectory("sweep-golden-search");
    SweepPlan plan = smallPlan();
    plan.repeats = 1;
    plan.reference = "precision=double,steps=2,spp=4";
    plan.knobs = {{"steps", {"1.5", "3"}}, {"precision", {"double"}}};
    writeSweepPlan(dir, plan);
    for (const SweepRun& r : planRuns(readSweepPlan(dir))) runSweepJob(dir, r.id);
    EXPECT_EQ(goldenSearchUnits(readSweepPlan(dir)), 4u);  // start, precision=float, steps=1, steps=1.5

    const std::vector<GoldenSearchStep> steps = runGoldenSearch(dir);
    ASSERT_GE(steps.size(), 3u);
    EXPECT_EQ(steps[0].settings, "steps=2,precision=double");
    EXPECT_EQ(steps[0].error.idiff.rmse, 0.0);  // the one-sample reference's own settings
    EXPECT_EQ(steps[1].knob, "precision");
    EXPECT_EQ(steps[1].value, "float");
    EXPECT_EQ(steps[2].knob, "steps");
    EXPECT_EQ(steps[2].value, "1");
    if (steps.size() == 4) {
        EXPECT_FALSE(steps[2].passes);
        EXPECT_EQ(steps[3].value, "1.5");
    }
    RenderSettings expected;
    applyKnobList(expected, "steps=2,precision=double");
    for (size_t i = 1; i < steps.size(); ++i) {
        EXPECT_EQ(steps[i].passes, steps[i].error.golden.verdict <= CompareVerdict::Warn) << i;
        if (steps[i].passes) applyKnob(expected, steps[i].knob, steps[i].value);
    }

    const SweepReport report = collectSweep(dir);
    ASSERT_TRUE(report.goldenSearchStart);
    EXPECT_EQ(report.goldenSearch.size(), steps.size() - 1);
    EXPECT_EQ(report.goldenSearchResult, describeKnobs(expected));
    ASSERT_TRUE(report.floatAgainstDouble);
    EXPECT_GT(report.floatAgainstDouble->idiff.rmse, 0.0);
    const std::string md = readText((dir / "sweep.md").string());
    EXPECT_NE(md.find("**Golden settings: `" + report.goldenSearchResult + "`**"), std::string::npos) << md;
    EXPECT_NE(md.find("Float rounding alone"), std::string::npos);
}

TEST(Sweep, JobCommandsNameEveryRunAndErrorsNameTheDirectory) {
    const fs::path dir = freshDirectory("sweep-jobs");
    writeSweepPlan(dir, smallPlan());
    const std::vector<std::string> lines = sweepJobCommands(dir, "/opt/refray bin/refray");
    ASSERT_EQ(lines.size(), planRuns(smallPlan()).size());
    EXPECT_EQ(lines[0], "'/opt/refray bin/refray' sweep --job reference -o " + dir.string());
    EXPECT_EQ(lines[4], "'/opt/refray bin/refray' sweep --job spp=4 -o " + dir.string());
    EXPECT_NE(errorOf([&] { runSweepJob(dir, "stpes=0.01"); }).find("has no run 'stpes=0.01' (did you mean 'steps=0.01'?)"),
              std::string::npos);
    EXPECT_NE(errorOf([&] { readSweepPlan(dir / "nowhere"); }).find("holds no sweep (no plan.json)"), std::string::npos);
}

}  // namespace
}  // namespace refray::scenes
