// `refray sweep` as a user runs it: in one process, and as jobs run by GNU parallel (the README's example) and
// merged with --collect.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/image.h"
#include "tests/tools/cli_run.h"

namespace {

namespace fs = std::filesystem;
using refray::testing::runCommand;

const std::string kRefray = REFRAY_BINARY;
const std::string kScene = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

fs::path freshDirectory(const std::string& name) {
    const fs::path dir = fs::path(REFRAY_TEST_OUTPUT_DIR) / name;
    fs::remove_all(dir);
    return dir;
}

std::vector<std::string> lines(const fs::path& path) {
    std::ifstream in(path);
    std::vector<std::string> out;
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
}

// The first `columns` comma-separated fields of a CSV line (the settings, not the timings).
std::string leadingFields(const std::string& line, int columns) {
    size_t at = 0;
    for (int i = 0; i < columns && at != std::string::npos; ++i) at = line.find(',', at + 1);
    return line.substr(0, at);
}

const std::string kSmall = " --size 16x9 --repeats 1 --threads 1 --reference precision=double,spp=4";

TEST(SweepCli, RunsEverySettingAndWritesTheReport) {
    const fs::path dir = freshDirectory("sweep-cli");
    const auto r = runCommand(kRefray + " sweep " + kScene + " --knob steps=0.5,2 --knob spp=4" + kSmall + " -o " +
                              dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("defaults"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("wrote " + (dir / "sweep.md").string()), std::string::npos) << r.output;
    EXPECT_EQ(lines(dir / "sweep.csv").size(), 5u);  // header, defaults, steps=0.5, steps=2, spp=4
    for (const char* p : {"plots/steps.png", "plots/spp.png", "plots/all.png", "runs/reference.exr", "runs/defaults.json"})
        EXPECT_TRUE(fs::exists(dir / p)) << p;
}

// The README's example: --emit-jobs, GNU parallel runs the lines, --collect merges them. The jobs render exactly what
// the one-process sweep renders.
TEST(SweepCli, GnuParallelRunsTheEmittedJobs) {
    const fs::path local = freshDirectory("sweep-cli-local");
    const fs::path jobs = freshDirectory("sweep-cli-jobs");
    const std::string knobs = " --knob steps=0.5 --knob precision=double";
    ASSERT_EQ(runCommand(kRefray + " sweep " + kScene + knobs + kSmall + " -o " + local.string()).status, 0);

    const fs::path jobFile = jobs / "jobs.txt";
    auto r = runCommand(kRefray + " sweep " + kScene + knobs + kSmall + " -o " + jobs.string() + " --emit-jobs " +
                        jobFile.string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("planned 5 runs"), std::string::npos) << r.output;
    ASSERT_EQ(lines(jobFile).size(), 5u);  // reference, reference-spp1, defaults, steps=0.5, precision=double
    EXPECT_FALSE(fs::exists(jobs / "runs" / "defaults.json"));  // planned, not run

    r = runCommand("parallel -j 2 < " + jobFile.string());
    ASSERT_EQ(r.status, 0) << "GNU parallel is in tools/setup.sh's packages\n" << r.output;
    r = runCommand(kRefray + " sweep --collect " + jobs.string());
    ASSERT_EQ(r.status, 0) << r.output;

    const std::vector<std::string> a = lines(local / "sweep.csv"), b = lines(jobs / "sweep.csv");
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(leadingFields(a[i], 4), leadingFields(b[i], 4)) << i;
    for (const char* id : {"reference", "reference-spp1", "defaults", "steps=0.5", "precision=double"}) {
        const std::string name = std::string("runs/") + id + ".exr";
        EXPECT_EQ(refray::readImage((local / name).string()).pixels(), refray::readImage((jobs / name).string()).pixels())
            << id;
    }
}

TEST(SweepCli, MistakesGetClearErrors) {
    const fs::path dir = freshDirectory("sweep-cli-errors");
    auto r = runCommand(kRefray + " sweep " + kScene + " -o " + dir.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("needs at least one --knob NAME=v1,v2,..."), std::string::npos) << r.output;
    r = runCommand(kRefray + " sweep " + kScene + " --knob stepz=2 -o " + dir.string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("unknown knob 'stepz' (did you mean 'steps'?)"), std::string::npos) << r.output;
    r = runCommand(kRefray + " sweep " + kScene + " --knob steps -o " + dir.string());
    EXPECT_NE(r.output.find("--knob expects NAME=v1,v2,..."), std::string::npos) << r.output;
    r = runCommand(kRefray + " sweep --collect " + (dir / "none").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("holds no sweep (no plan.json)"), std::string::npos) << r.output;
    r = runCommand(kRefray + " sweep " + kScene + " --collect " + dir.string());
    EXPECT_NE(r.output.find("give no scene or knobs"), std::string::npos) << r.output;
    r = runCommand(kRefray + " render " + kScene + " --size 8x4 --knob recursion-depth=40 -o " + (dir / "x.png").string());
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("knob recursion-depth expects a whole number from 1 to 31, got '40'"), std::string::npos)
        << r.output;
}

}  // namespace
