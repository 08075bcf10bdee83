// `refray explain` and `refray render --aov` as a user runs them, and the interactive page in a browser.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/image.h"
#include "core/json.h"
#include "tests/tools/browser.h"
#include "tests/tools/cli_run.h"

namespace {

using refray::testing::CliRun;

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";

CliRun run(const std::string& arguments) { return refray::testing::runRefray(arguments); }

std::string directory(const std::string& name) { return refray::testing::freshDirectory("explain", name); }

using refray::testing::contains;

}  // namespace

TEST(ExplainCli, PrintsTheRayTreeOfAPixel) {
    const CliRun r = run("explain " + kProceduray + " --size 320x180 --pixel 112,100");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "hit-group record: I = R + M×G + C = 0 + 2×0 + 4 = 4; address = StartAddress + 96×4"))
        << r.output;
    EXPECT_TRUE(contains(r.output, "TraceRay #2 (depth 2, ray type 'Shadow')")) << r.output;
}

TEST(ExplainCli, JsonToAFile) {
    const std::string dir = directory("json");
    const CliRun r = run("explain " + kProceduray + " --size 320x180 --pixel 112,100 --json -o " + dir + "/pixel.json");
    ASSERT_EQ(r.status, 0) << r.output;
    const refray::json::Value doc = refray::json::parseFile(dir + "/pixel.json");
    bool hasEvents = false;
    for (const refray::json::Member& m : doc.asObject())
        if (m.key == "events") hasEvents = !m.value.asArray().empty();
    EXPECT_TRUE(hasEvents);
}

TEST(ExplainCli, BadPixelsAreClearErrors) {
    CliRun r = run("explain " + kProceduray + " --size 320x180 --pixel 320,0");
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.output, "--pixel 320,0 is outside the 320x180 image (x in 0..319, y in 0..179)")) << r.output;
    r = run("explain " + kProceduray + " --pixel '12;4'");
    EXPECT_EQ(r.status, 2);
    r = run("explain " + kProceduray + " --pixel twelve");
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.output, "--pixel expects X,Y (e.g. 640,360), got 'twelve'")) << r.output;
    r = run("explain " + kProceduray);
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.output, "refray explain needs --pixel X,Y (or --html PAGE for every pixel)")) << r.output;
}

TEST(ExplainCli, RenderAovWritesAnIndexMapWithALegend) {
    const std::string dir = directory("aov");
    const CliRun r = run("render " + kProceduray + " --size 160x90 --aov record -o " + dir + "/record.png");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "record 4: HitGroup_Pacman (I = 0 + 2*0 + 4)")) << r.output;
    const refray::Image image = refray::readImage(dir + "/record.png");
    EXPECT_GT(image.width(), 160u);
    EXPECT_EQ(image.metadata.at("aov"), "record");

    const CliRun bad = run("render " + kProceduray + " --size 160x90 --aov records -o " + dir + "/x.png");
    EXPECT_EQ(bad.status, 2);
    EXPECT_TRUE(contains(bad.output, "--aov expects one of record, instance, geometry, primitive, hitgroup, depth, got "
                                     "'records' (did you mean 'record'?)"))
        << bad.output;
}

TEST(ExplainCli, TheHtmlPageShowsAPixelsRaysInABrowser) {
    REQUIRE_BROWSER(browser);
    const std::string dir = directory("html");
    const CliRun r = run("explain " + kProceduray + " --size 160x90 --html " + dir + "/page.html");
    ASSERT_EQ(r.status, 0) << r.output;
    std::string error;
    // The fragment selects a pixel the way hovering does (the same function runs).
    const std::string dom = refray::testing::dumpDom(browser, dir + "/page.html", dir + "/profile", error, "#pixel=56,50");
    ASSERT_TRUE(error.empty()) << error;
    EXPECT_TRUE(contains(dom, "<div id=\"pixel\">pixel (56, 50)</div>")) << dom.substr(0, 2000);
    EXPECT_TRUE(contains(dom, "TraceRay depth 1 'Radiance': R = 0, M = 2, MissShaderIndex = 0, CULL_BACK_FACING_TRIANGLES"));
    EXPECT_TRUE(contains(dom, "I = R + M×G + C = 0 + 2×0 + 4 = 4 -&gt; record 4 'HitGroup_Pacman'"));
    EXPECT_TRUE(contains(dom, "--size 160x90 --pixel 56,50</code>"));
}
