// `refray golden make/update --emit-jobs` and `--collect` as a user runs them (README "Goldens"): GNU parallel runs
// the lines, the collect assembles goldens bit-identical to the in-process run; a missing or broken render is named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/envelope.h"
#include "tests/tools/cli_run.h"

namespace {

namespace fs = std::filesystem;
using refray::testing::contains;
using refray::testing::runCommand;
using refray::testing::runRefray;

const std::string kScene = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";
const std::string kMake = "golden make " + kScene + " --size 32x18 --perturbed 3 --order-check 2 --threads 1 --root " +
                          std::string(REFRAY_SOURCE_DIR);

std::string fileText(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

size_t lineCount(const fs::path& path) {
    std::ifstream in(path);
    size_t n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
}

TEST(GoldenJobsCli, ParallelLinesCollectToTheInProcessGolden) {
    const fs::path dir = refray::testing::freshDirectory("golden-jobs", "parallel");
    const fs::path jobs = dir / "jobs.txt";
    auto r = runRefray(kMake + " -o " + (dir / "distributed").string() + " --emit-jobs " + jobs.string());
    ASSERT_EQ(r.status, 0) << r.output;
    // nominal, 2 orders, 3 perturbed, double, objects
    EXPECT_TRUE(contains(r.output, "wrote 8 job lines")) << r.output;
    ASSERT_EQ(lineCount(jobs), 8u);
    r = runCommand("parallel -j 2 < " + jobs.string());
    ASSERT_EQ(r.status, 0) << r.output;
    r = runRefray("golden make --collect -o " + (dir / "distributed").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_FALSE(fs::exists(dir / "distributed/jobs")) << "the collect leaves its plan and renders behind";
    r = runRefray(kMake + " -o " + (dir / "local").string());
    ASSERT_EQ(r.status, 0) << r.output;

    EXPECT_EQ(fileText(dir / "distributed/goldens.json"), fileText(dir / "local/goldens.json"));
    const std::string name = "d3d12-procedural-geometry.default.envelope.exr";
    const refray::Envelope a = refray::readEnvelope((dir / "distributed" / name).string());
    const refray::Envelope b = refray::readEnvelope((dir / "local" / name).string());
    EXPECT_EQ(a.nominal.pixels(), b.nominal.pixels());
    EXPECT_EQ(a.lo, b.lo);
    EXPECT_EQ(a.hi, b.hi);
    EXPECT_EQ(a.pixelClass, b.pixelClass);
    EXPECT_EQ(a.orderDependent, b.orderDependent);
    EXPECT_EQ(a.stableMovesLeaveOneOut, b.stableMovesLeaveOneOut);
    EXPECT_EQ(a.sensitiveOutsideLeaveOneOut, b.sensitiveOutsideLeaveOneOut);
    for (const auto& [key, value] : b.provenance)
        if (key.rfind("render_seconds_", 0) != 0) {
            EXPECT_EQ(a.provenance.at(key), value) << key;
        }
}

TEST(GoldenJobsCli, CollectNamesTheMissingRendersAndWritesNothing) {
    const fs::path dir = refray::testing::freshDirectory("golden-jobs", "missing");
    const fs::path jobs = dir / "jobs.txt";
    ASSERT_EQ(runRefray(kMake + " -o " + dir.string() + " --emit-jobs " + jobs.string()).status, 0);
    // Only the first line runs.
    auto r = runCommand("head -n 1 " + jobs.string() + " | parallel");
    ASSERT_EQ(r.status, 0) << r.output;
    r = runRefray("golden make --collect -o " + dir.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "7 of the plan's renders are missing")) << r.output;  // 8 parts, the nominal rendered
    EXPECT_TRUE(contains(r.output, "refray golden job DIR d3d12-procedural-geometry.default order-1")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "goldens.json"));
}

TEST(GoldenJobsCli, AJobOfAnUnknownPartOrWithoutAPlanIsRefused) {
    const fs::path dir = refray::testing::freshDirectory("golden-jobs", "refused");
    auto r = runRefray("golden job " + dir.string() + " d3d12-procedural-geometry.default nominal");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "holds no golden plan")) << r.output;
    ASSERT_EQ(runRefray(kMake + " -o " + dir.string() + " --emit-jobs " + (dir / "jobs.txt").string()).status, 0);
    r = runRefray("golden job " + dir.string() + " d3d12-procedural-geometry.default perturbed-9");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "has no render 'perturbed-9' (it has nominal, order-1..2, perturbed-1..3, double, objects)"))
        << r.output;
    r = runRefray("golden job " + dir.string() + " no-such-golden nominal");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "has no golden 'no-such-golden'")) << r.output;
    r = runRefray("golden make --collect " + kScene + " -o " + dir.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "give no scene")) << r.output;
}

TEST(GoldenDiscriminateCli, RunsOneCandidateAndNamesAnUnknownOne) {
    const fs::path dir = refray::testing::freshDirectory("golden-jobs", "discriminate");
    ASSERT_EQ(runRefray(kMake + " -o " + dir.string()).status, 0);
    auto r = runRefray("golden discriminate " + dir.string() + " --root " + std::string(REFRAY_SOURCE_DIR) +
                       " --only bgr-swapped,double --markdown " + (dir / "report.md").string());
    EXPECT_EQ(r.status, 0) << r.output;  // the mutant fails, the correct candidate passes
    EXPECT_TRUE(contains(r.output, "bgr-swapped")) << r.output;
    EXPECT_TRUE(contains(fileText(dir / "report.md"), "| correct candidates | 1 | 0 false alarms |"))
        << fileText(dir / "report.md");
    r = runRefray("golden discriminate " + dir.string() + " --only no-such-bug");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "no discrimination candidate named 'no-such-bug'")) << r.output;
    // --golden: only the goldens named, and an unknown one is named.
    r = runRefray("golden discriminate " + dir.string() + " --golden no-such-golden --only double");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "no golden named 'no-such-golden'")) << r.output;
}

// The RayQuery mutants on the inline-shadow golden (tests/golden): procedural candidates ignored fails it, a commit
// outside [RayTMin, CommittedRayT] is stopped by RQ-22 before an image exists.
TEST(GoldenDiscriminateCli, RayQueryMutantsOnTheInlineShadowGolden) {
    const fs::path dir = refray::testing::freshDirectory("golden-jobs", "discriminate-rq");
    auto r = runRefray("golden discriminate " + std::string(REFRAY_SOURCE_DIR) + "/tests/golden --root " +
                       std::string(REFRAY_SOURCE_DIR) +
                       " --golden d3d12-procedural-geometry-inline.default --only rq-procedural-ignored,"
                       "rq-commit-outside-range --markdown " + (dir / "report.md").string());
    EXPECT_EQ(r.status, 0) << r.output;
    const std::string report = fileText(dir / "report.md");
    EXPECT_TRUE(contains(report, "| `rq-procedural-ignored` | mutant | FAILURE")) << report;
    EXPECT_TRUE(contains(report, "| `rq-commit-outside-range` | mutant | render error |")) << report;
    EXPECT_TRUE(contains(r.output, "error RQ-22: CommitProceduralPrimitiveHit() was given a t outside [RayTMin, "
                                   "CommittedRayT]")) << r.output;
    EXPECT_FALSE(contains(report, "inline-ambient-occlusion")) << report;
}

}  // namespace
