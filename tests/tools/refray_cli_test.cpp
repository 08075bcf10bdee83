// The refray command line as a user runs it.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/image.h"
#include "tests/tools/cli_run.h"

namespace {

using refray::testing::CliRun;

CliRun run(const std::string& arguments) { return refray::testing::runRefray(arguments); }

std::string outputPath(const std::string& name) {
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    return std::string(REFRAY_TEST_OUTPUT_DIR) + "/" + name;
}

}  // namespace

TEST(RefrayCli, RenderWritesAPngWithProvenance) {
    const std::string path = outputPath("cli.png");
    std::filesystem::remove(path);
    const CliRun r = run("render builtin -o " + path + " --size 64x36 --threads 2 --stats");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("rays at depth 1: 2304"), std::string::npos) << r.output;
    const refray::Image image = refray::readImage(path);
    EXPECT_EQ(image.width(), 64u);
    EXPECT_EQ(image.height(), 36u);
    EXPECT_EQ(image.metadata.at("scene"), "builtin");
    EXPECT_EQ(image.metadata.at("size"), "64x36");
    EXPECT_TRUE(image.metadata.count("refray_commit"));
}

TEST(RefrayCli, ExrKeepsFloats) {
    const std::string path = outputPath("cli.exr");
    ASSERT_EQ(run("render builtin -o " + path + " --size 32x18").status, 0);
    EXPECT_EQ(refray::readImage(path).width(), 32u);
}

TEST(RefrayCli, BadSizeIsAClearError) {
    const CliRun r = run("render builtin -o " + outputPath("bad.png") + " --size 64by36");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--size expects WIDTHxHEIGHT"), std::string::npos) << r.output;
}

TEST(RefrayCli, UnknownOrderIsAClearError) {
    const CliRun r = run("render builtin -o " + outputPath("bad.png") + " --size 8x8 --order random");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--order expects"), std::string::npos) << r.output;
}

TEST(RefrayCli, UnwritablePathNamesIt) {
    const CliRun r = run("render builtin -o /proc/refray-cannot-write.png --size 8x8");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("/proc/refray-cannot-write.png"), std::string::npos) << r.output;
}

TEST(RefrayCli, RendersASceneFileWithProvenance) {
    const std::string path = outputPath("proceduray.exr");
    std::filesystem::remove(path);
    const CliRun r = run("render " + std::string(REFRAY_SOURCE_DIR) +
                         "/scenes/proceduray-mandel-julia-pac.json -o " + path +
                         " --size 40x24 --camera julia --time 0 --precision double --threads 2");
    ASSERT_EQ(r.status, 0) << r.output;
    const refray::Image image = refray::readImage(path);
    EXPECT_EQ(image.width(), 40u);
    EXPECT_EQ(image.metadata.at("scene"), "proceduray-mandel-julia-pac");
    EXPECT_EQ(image.metadata.at("camera"), "julia");
    EXPECT_EQ(image.metadata.at("time"), "0");
    EXPECT_EQ(image.metadata.at("precision"), "double");
    EXPECT_EQ(image.metadata.at("scene_sha256").size(), 64u);
    EXPECT_TRUE(image.metadata.count("render_seconds"));
    EXPECT_TRUE(image.metadata.count("refray_version"));
}

TEST(RefrayCli, BrokenSceneFileNamesFileLineAndColumn) {
    const std::string scene = outputPath("broken-scene.json");
    {
        std::FILE* f = std::fopen(scene.c_str(), "w");
        ASSERT_NE(f, nullptr);
        std::fputs("{\n  \"format\": \"refray-scene/1\",\n  \"nmae\": \"x\"\n}\n", f);
        std::fclose(f);
    }
    const CliRun r = run("render " + scene + " -o " + outputPath("never.png"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("broken-scene.json:3:3: the scene has no 'name'; is 'nmae' a misspelling of it?"),
              std::string::npos)
        << r.output;
}

TEST(RefrayCli, SceneOptionsAreCheckedByName) {
    const std::string scene = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";
    CliRun r = run("render " + scene + " -o " + outputPath("never.png") + " --size 8x8 --camera front");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("has no camera 'front'"), std::string::npos) << r.output;
    r = run("render " + scene + " -o " + outputPath("never.png") + " --size 8x8 --precision half");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--precision expects 'float' or 'double'"), std::string::npos) << r.output;
    r = run("render " + scene + " -o " + outputPath("never.png") + " --size 8x8 --spp 2");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--spp must be a square number"), std::string::npos) << r.output;
    r = run("render no-such-scene.json -o " + outputPath("never.png"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("cannot read scene file 'no-such-scene.json': no such file or directory"), std::string::npos)
        << r.output;
}

// ---- Parse errors: exit status 2 and a message naming the command, the option and what it accepts ----

namespace {

void expectBadInput(const std::string& arguments, const std::string& message) {
    const CliRun r = run(arguments);
    EXPECT_EQ(r.status, 2) << "refray " << arguments << "\n" << r.output;
    EXPECT_TRUE(refray::testing::contains(r.output, message)) << "refray " << arguments << "\n" << r.output;
}

}  // namespace

TEST(RefrayCliParseErrors, RenderNamesTheOptionAndWhatItAccepts) {
    expectBadInput("render builtin --spp -4", "refray render: --spp: expects a positive integer (a square number k*k; "
                                              "for the path tracer any N), got '-4' (see 'refray render --help')");
    expectBadInput("render builtin --time soon", "refray render: --time: expects a time in seconds, got 'soon'");
}

TEST(RefrayCliParseErrors, CompareNamesTheOptionAndWhatItAccepts) {
    // 2 is also compare's FAILURE; the message tells them apart.
    expectBadInput("compare ref.png mine.png --fail -1", "refray compare: --fail: expects a number >= 0, got '-1'");
    expectBadInput("compare ref.png mine.png --channels rbg",
                   "refray compare: --channels: expects rgb or rgba, got 'rbg' (did you mean 'rgb'?)");
}

TEST(RefrayCliParseErrors, GoldenUpdateNamesTheOptionAndWhatItAccepts) {
    expectBadInput("golden update --threads many",
                   "refray golden update: --threads: expects a number of worker threads from 0 (all) to ");
}

TEST(RefrayCliParseErrors, GoldenMakeJobAndDiscriminateNameTheOptionAndWhatItAccepts) {
    expectBadInput("golden make scene.json -o dir --perturbed -2",
                   "refray golden make: --perturbed: expects a number of perturbed renders from 3 to 1000");
    expectBadInput("golden job dir name nominal --threads x",
                   "refray golden job: --threads: expects a number of worker threads from 0 (all) to ");
    expectBadInput("golden discriminate --threads x",
                   "refray golden discriminate: --threads: expects a number of worker threads from 0 (all) to ");
}

TEST(RefrayCliParseErrors, TableNamesTheOptionAndWhatItAccepts) {
    expectBadInput("table scene.json --precision doubel",
                   "refray table: --precision: expects float or double, got 'doubel' (did you mean 'double'?)");
}

TEST(RefrayCliParseErrors, ExplainNamesTheOptionAndWhatItAccepts) {
    expectBadInput("explain scene.json --pixel 1,1 --seed -1",
                   "refray explain: --seed: expects a seed from 0 to 18446744073709551615, got '-1'");
}

TEST(RefrayCliParseErrors, SweepNamesTheOptionAndWhatItAccepts) {
    expectBadInput("sweep scene.json --knob steps=2 --repeats 0",
                   "refray sweep: --repeats: expects a number of timed renders, at least 1, got '0'");
}

TEST(RefrayCliParseErrors, UnknownOptionsSuggestTheNearestOne) {
    expectBadInput("render builtin --stat", "refray render: unknown option --stat (did you mean '--stats'?)");
    expectBadInput("explain scene.json --pixle=1,1", "refray explain: unknown option --pixle (did you mean '--pixel'?)");
}

TEST(RefrayCliParseErrors, MissingAndExtraArgumentsAndSubcommands) {
    expectBadInput("table", "refray table: scene is required");
    expectBadInput("table a.json b.json", "refray table: unexpected argument 'b.json'");
    expectBadInput("render builtin --spp", "refray render: --spp");
    expectBadInput("rendr builtin", "refray: expects a subcommand (");
    expectBadInput("rendr builtin", "got 'rendr' (did you mean 'render'?)");
    expectBadInput("golden", "refray golden: expects a subcommand (update, make, job or discriminate)");
    expectBadInput("golden job", "refray golden job: dir is required");
}

TEST(RefrayCliParseErrors, HelpAndVersionStillExitZero) {
    for (const char* command : {"--help", "render --help", "compare --help", "golden update --help", "golden make --help",
                                "golden job --help", "golden discriminate --help", "table --help",
                                "explain --help", "sweep --help"}) {
        const CliRun r = run(command);
        EXPECT_EQ(r.status, 0) << command << "\n" << r.output;
        EXPECT_TRUE(refray::testing::contains(r.output, "Usage:")) << command << "\n" << r.output;
    }
    EXPECT_EQ(run("--version").status, 0);
}
