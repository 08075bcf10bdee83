// `refray compare` as a user runs it: idiff's exit codes, the report, the diff image and
// the HTML report as a browser (headless Chromium) shows it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/envelope.h"
#include "core/image.h"
#include "tests/tools/browser.h"
#include "tests/tools/cli_run.h"
#include "core/random.h"

namespace {

using refray::Image;
using refray::vec4;

using refray::testing::CliRun;
using refray::testing::runCommand;
using refray::testing::dumpDom;

CliRun compare(const std::string& arguments) { return runCommand(std::string(REFRAY_BINARY) + " compare " + arguments); }

std::string directory(const std::string& name) { return refray::testing::freshDirectory("compare", name); }

Image noise(uint32_t width, uint32_t height, uint32_t seed) {
    Image image(width, height);
    refray::Random random(0, 0, 0, seed);
    for (vec4& p : image.pixels()) p = vec4(random.nextFloat(), random.nextFloat(), random.nextFloat(), 1.0f);
    return image;
}

// Values a PNG holds exactly (k/255), away from 0 and 1.
Image unorm(uint32_t width, uint32_t height) {
    Image image(width, height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x)
            image.at(x, y) = vec4(float((x * 11 + y * 3) % 200 + 20) / 255.0f, float((x + y * 7) % 200 + 20) / 255.0f,
                                  float((x * y) % 200 + 20) / 255.0f, 1.0f);
    return image;
}

std::string write(const std::string& path, const Image& image) {
    refray::writeImage(path, image);
    return path;
}

using refray::testing::contains;

// The <tr class="comparison ..."> rows of a report, in document order.
std::vector<std::string> comparisonRows(const std::string& dom) {
    std::vector<std::string> rows;
    size_t at = dom.find("<tr class=\"comparison");
    while (at != std::string::npos) {
        const size_t end = dom.find("</tr>", at);
        rows.push_back(dom.substr(at, end - at));
        at = dom.find("<tr class=\"comparison", end);
    }
    return rows;
}

size_t count(const std::string& text, const std::string& part) {
    size_t n = 0;
    for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
    return n;
}

}  // namespace

TEST(CompareCli, IdenticalImagesExitZero) {
    const std::string dir = directory("identical");
    const std::string a = write(dir + "/a.exr", noise(32, 24, 1));
    const CliRun r = compare(a + " " + a);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "PASS")) << r.output;
    EXPECT_TRUE(contains(r.output, "FLIP")) << r.output;
}

TEST(CompareCli, OnePixelOffByHalfExitsTwoAndNamesThePixel) {
    const std::string dir = directory("one-pixel");
    Image candidate = noise(16, 12, 2);
    const std::string ref = write(dir + "/ref.exr", candidate);
    candidate.at(5, 7).g += 0.5f;
    const CliRun r = compare(ref + " " + write(dir + "/cand.exr", candidate));
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "at (5, 7) channel G")) << r.output;
    EXPECT_TRUE(contains(r.output, "FAILURE")) << r.output;
}

TEST(CompareCli, ErrorUnderFailButOverWarnExitsOne) {
    const std::string dir = directory("warn");
    Image candidate = noise(16, 16, 3);
    const std::string ref = write(dir + "/ref.exr", candidate);
    candidate.at(1, 2).r += 0.01f;
    const std::string cand = write(dir + "/cand.exr", candidate);
    const CliRun r = compare(ref + " " + cand + " --fail 0.1 --warn 0.001");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_TRUE(contains(r.output, "WARNING")) << r.output;
    EXPECT_EQ(compare(ref + " " + cand + " --fail 0.1 --warn 0.02").status, 0);
    EXPECT_EQ(compare(ref + " " + cand + " --failpercent 1").status, 1);  // 1 of 256 pixels is 0.39 %
}

TEST(CompareCli, NaNInTheCandidateFailsWhateverTheThresholds) {
    const std::string dir = directory("nan");
    Image candidate = noise(8, 8, 4);
    const std::string ref = write(dir + "/ref.exr", candidate);
    candidate.at(3, 4).b = std::nanf("");
    const CliRun r = compare(ref + " " + write(dir + "/cand.exr", candidate) + " --fail 1 --failpercent 100 --warn 1");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "NaN or infinity")) << r.output;
}

TEST(CompareCli, SizeMismatchExitsThreeNamingBothSizes) {
    const std::string dir = directory("size");
    const CliRun r = compare(write(dir + "/ref.png", noise(64, 36, 5)) + " " + write(dir + "/cand.png", noise(32, 18, 5)));
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, "64x36")) << r.output;
    EXPECT_TRUE(contains(r.output, "32x18")) << r.output;
}

TEST(CompareCli, UnreadableFilesExitFourNamingThem) {
    const std::string dir = directory("missing");
    const std::string ref = write(dir + "/ref.png", noise(8, 8, 6));
    CliRun r = compare(ref + " " + dir + "/no-such-candidate.png");
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, dir + "/no-such-candidate.png")) << r.output;
    r = compare(dir + "/no-such-reference.png " + ref);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, dir + "/no-such-reference.png")) << r.output;
    std::ofstream(dir + "/garbage.png") << "not an image";
    r = compare(ref + " " + dir + "/garbage.png");
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, dir + "/garbage.png")) << r.output;
}

TEST(CompareCli, ASecondReferenceVariantMatchingPassesAndIsNamed) {
    const std::string dir = directory("variants");
    const Image candidate = unorm(20, 20);
    Image other = candidate;
    other.at(10, 10).r = 1.0f;
    write(dir + "/golden.png", other);
    write(dir + "/golden-gpu.png", candidate);
    const CliRun r = compare(dir + "/golden.png " + write(dir + "/mine.png", candidate));
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "Matched \"" + dir + "/golden-gpu.png\"")) << r.output;

    // A render saved beside its golden under a variant's name does not match itself.
    EXPECT_EQ(compare(dir + "/golden.png " + write(dir + "/golden-mine.png", candidate)).status, 0);
    std::filesystem::remove(dir + "/golden-gpu.png");
    EXPECT_EQ(compare(dir + "/golden.png " + dir + "/golden-mine.png").status, 2);
}

TEST(CompareCli, MaskedPixelsDoNotFail) {
    const std::string dir = directory("mask");
    Image candidate = unorm(20, 20), mask(20, 20, vec4(0, 0, 0, 1));
    const std::string ref = write(dir + "/ref.png", candidate);
    candidate.at(4, 6).r = 1.0f;
    mask.at(4, 6) = vec4(1.0f);
    const std::string cand = write(dir + "/cand.png", candidate);
    const CliRun r = compare(ref + " " + cand + " --mask " + write(dir + "/mask.png", mask));
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "masked pixels   1")) << r.output;
    EXPECT_EQ(compare(ref + " " + cand).status, 2);
    EXPECT_EQ(compare(ref + " " + cand + " --mask " + write(dir + "/small-mask.png", Image(4, 4))).status, 3);
}

TEST(CompareCli, GoldenProfileAcceptsOneUnormStepAndExplicitOptionsWin) {
    const std::string dir = directory("golden");
    Image candidate = unorm(20, 20);
    const std::string ref = write(dir + "/ref.png", candidate);
    for (vec4& p : candidate.pixels()) p.g += 1.0f / 255.0f;
    const std::string cand = write(dir + "/cand.png", candidate);
    EXPECT_EQ(compare(ref + " " + cand).status, 2);
    const CliRun r = compare("--golden " + ref + " " + cand);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(compare("--golden --fail 0.001 " + ref + " " + cand).status, 2);
}

TEST(CompareCli, AlphaIsComparedWithChannelsRgba) {
    const std::string dir = directory("alpha");
    // EXR: OpenImageIO (un)premultiplies PNG colour by alpha, EXR keeps the values.
    Image candidate = unorm(8, 8);
    const std::string ref = write(dir + "/ref.exr", candidate);
    candidate.at(2, 2).a = 0.0f;
    const std::string cand = write(dir + "/cand.exr", candidate);
    EXPECT_EQ(compare(ref + " " + cand).status, 0);
    const CliRun r = compare(ref + " " + cand + " --channels rgba");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "channel A")) << r.output;
}

TEST(CompareCli, WritesADiffHeatMap) {
    const std::string dir = directory("diff");
    Image candidate(40, 30, vec4(0.4f, 0.4f, 0.4f, 1.0f));
    const std::string ref = write(dir + "/ref.png", candidate);
    candidate.at(30, 10) = vec4(1.0f, 0.0f, 0.0f, 1.0f);
    const std::string cand = write(dir + "/cand.png", candidate);
    const CliRun r = compare(ref + " " + cand + " -o " + dir + "/out/diff.png");
    EXPECT_EQ(r.status, 2) << r.output;
    const Image diff = refray::readImage(dir + "/out/diff.png");
    ASSERT_EQ(diff.width(), 40u);
    ASSERT_EQ(diff.height(), 30u);
    const auto brightness = [](const vec4& p) { return p.r + p.g + p.b; };
    EXPECT_GT(brightness(diff.at(30, 10)), brightness(diff.at(3, 25)) + 0.5f);
    EXPECT_EQ(compare(ref + " " + cand + " --diff /proc/refray-no-diff.png").status, 4);
}

TEST(CompareCli, HelpDocumentsTheGoldenProfileAndExitCodes) {
    const CliRun r = runCommand(std::string(REFRAY_BINARY) + " compare --help");
    EXPECT_EQ(r.status, 0) << r.output;
    for (const char* part : {"--golden", "--fail", "--failpercent", "--hardfail", "--warnpercent", "--mask", "--html",
                             "--channels", "magma", "0 pass, 1 warning, 2 failure, 3 size mismatch, 4 file error"})
        EXPECT_TRUE(contains(r.output, part)) << part << "\n" << r.output;
}

TEST(CompareCli, HtmlReportShowsFailingRowsFirstInABrowser) {
    REQUIRE_BROWSER(browser);
    const std::string dir = directory("html");
    const Image candidate = unorm(24, 16);
    Image other = candidate;
    other.at(3, 3) = vec4(1.0f);
    write(dir + "/golden.png", candidate);      // matches
    write(dir + "/golden-zfail.png", other);    // fails
    const std::string report = dir + "/report.html";
    const CliRun r = compare(dir + "/golden.png " + write(dir + "/mine.png", candidate) + " --html " + report);
    ASSERT_EQ(r.status, 0) << r.output;

    std::string error;
    const std::string dom = dumpDom(browser, report, dir + "/profile", error);
    ASSERT_TRUE(error.empty()) << error;
    EXPECT_TRUE(contains(dom, "<span id=\"verdict\" class=\"badge PASS\">PASS</span>")) << dom.substr(0, 2000);
    const std::vector<std::string> rows = comparisonRows(dom);
    ASSERT_EQ(rows.size(), 2u) << dom.substr(0, 2000);
    EXPECT_TRUE(contains(rows[0], "data-verdict=\"FAILURE\"")) << rows[0].substr(0, 300);
    EXPECT_TRUE(contains(rows[0], "golden-zfail.png"));
    EXPECT_TRUE(contains(rows[1], "data-verdict=\"PASS\"")) << rows[1].substr(0, 300);
    EXPECT_TRUE(contains(rows[1], "matched"));
    for (const std::string& row : rows) {
        EXPECT_EQ(count(row, "<img "), 3u);
        EXPECT_EQ(count(row, "src=\"data:image/png;base64,"), 3u);
        EXPECT_TRUE(contains(row, "max error"));
        EXPECT_TRUE(contains(row, "FLIP"));
    }
    EXPECT_TRUE(contains(rows[0], "at (3, 3)"));
}

TEST(CompareCli, HtmlHoveringOverTheCandidateShowsTheReference) {
    REQUIRE_BROWSER(browser);
    const std::string dir = directory("hover");
    Image candidate = unorm(16, 16);
    const std::string ref = write(dir + "/ref.png", candidate);
    candidate.at(8, 8) = vec4(0.0f, 0.0f, 0.0f, 1.0f);
    const std::string report = dir + "/report.html";
    ASSERT_EQ(compare(ref + " " + write(dir + "/cand.png", candidate) + " --html " + report).status, 2);

    // Append a probe that hovers the candidate the way a mouse would and records what it shows.
    std::ifstream in(report);
    std::stringstream page;
    page << in.rdbuf();
    const std::string probe = R"(<script>
const row = document.querySelector('tr.comparison');
const candidate = row.querySelector('img.candidate'), reference = row.querySelector('img.reference');
const before = candidate.src;
candidate.dispatchEvent(new MouseEvent('mouseenter'));
const during = candidate.src === reference.src && row.querySelector('.showing').textContent === 'showing: reference';
candidate.dispatchEvent(new MouseEvent('mouseleave'));
const after = candidate.src === before && before !== reference.src;
document.body.insertAdjacentHTML('beforeend', '<p id="probe">during=' + during + ' after=' + after + '</p>');
</script>)";
    std::ofstream(dir + "/probe.html") << page.str() << probe;

    std::string error;
    const std::string dom = dumpDom(browser, dir + "/probe.html", dir + "/profile", error);
    ASSERT_TRUE(error.empty()) << error;
    EXPECT_TRUE(contains(dom, "<p id=\"probe\">during=true after=true</p>")) << dom.substr(dom.size() > 3000 ? dom.size() - 3000 : 0);
}

// ---- Envelope goldens (docs/compare.md, "Envelope goldens") --------------------------------------------------------

namespace {

// A golden directory holding one synthetic envelope "scene.cam" of `unorm(32, 24)` from K = 8 renders that all move
// pixel (0, 0) (sensitive) and nothing else: no render moves a stable pixel alone, so the stable budget is 27 pixels
// (docs/compare.md, "The stable count test").
std::string envelopeDirectory(const std::string& name, const std::string& scenePath, const std::string& sceneSha) {
    const std::string dir = directory(name);
    const Image nominal = unorm(32, 24);
    Image moved = nominal;
    moved.at(0, 0).r += 6.0f / 255.0f;
    const std::vector<const Image*> variants(8, &moved);
    const refray::Envelope e = refray::makeEnvelope(nominal, variants, 8, nullptr);
    refray::writeEnvelope(dir + "/scene.cam.envelope.exr", e);
    std::ofstream(dir + "/goldens.json")
        << "{\"format\": \"refray-goldens/2\", \"goldens\": [{\"name\": \"scene.cam\", \"scene\": \"" << scenePath
        << "\", \"sceneSha256\": \"" << sceneSha
        << "\", \"camera\": \"cam\", \"time\": \"0\", \"precision\": \"float\", \"spp\": 1, \"width\": 32, "
           "\"height\": 24, \"envelope\": \"scene.cam.envelope.exr\", \"perturbedRenders\": 8, \"variationModel\": "
           "\"variation model v1\", \"sensitivePixels\": 1, \"orderCheckOrders\": 0, \"orderDependentPixels\": 0, "
           "\"refrayCommit\": \"test\"}]}\n";
    return dir;
}

}  // namespace

TEST(CompareCliEnvelope, NominalPassesAStablePixelTwoStepsOffWarnsAndTwentyEightFail) {
    const std::string dir = envelopeDirectory("envelope-pass", "no/such/scene.json", "0");
    const std::string good = write(dir + "/scene.cam.png", unorm(32, 24));
    CliRun r = compare("--golden " + dir + " " + good + " --html " + dir + "/report.html -o " + dir + "/heat.png");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "verdict         PASS")) << r.output;
    EXPECT_TRUE(std::filesystem::exists(dir + "/report.html"));
    EXPECT_TRUE(std::filesystem::exists(dir + "/heat.png"));
    Image bad = unorm(32, 24);
    bad.at(7, 3).g += 2.0f / 255.0f;
    std::string badPath = write(dir + "/bad.png", bad);
    r = compare("--golden " + dir + "/scene.cam.envelope.exr " + badPath);
    EXPECT_EQ(r.status, 1) << r.output;  // within the budget of 27, but more than the renders moved (0)
    EXPECT_TRUE(contains(r.output, "(7, 3) stable G: code")) << r.output;
    for (uint32_t i = 0; i < 27; ++i) bad.at(8 + i % 20, 10 + i / 20).g += 2.0f / 255.0f;
    badPath = write(dir + "/bad.png", bad);
    r = compare("--golden " + dir + "/scene.cam.envelope.exr " + badPath);
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "28 stable pixels moved, more than 27 allowed")) << r.output;
}

// The regional count test (docs/compare.md, "The regional count test"): nine stable pixels moved up in one 3x3 block
// are within the whole-image budget of 27, but no render moved a pixel there, so the block fails the regional test;
// the report, the --golden-set line and the HTML page name the region.
TEST(CompareCliEnvelope, ConcentratedMovesFailTheRegionalTestNamingTheRegion) {
    const std::string dir = envelopeDirectory("envelope-regional", "no/such/scene.json", "0");
    Image bad = unorm(32, 24);
    for (uint32_t y = 12; y < 15; ++y)
        for (uint32_t x = 20; x < 23; ++x) bad.at(x, y).g += 3.0f / 255.0f;
    const std::string badPath = write(dir + "/bad.png", bad);
    CliRun r = compare("--golden " + dir + "/scene.cam.envelope.exr " + badPath + " -o " + dir + "/heat.png");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "9 (")) << r.output;
    EXPECT_TRUE(contains(r.output, "stable pixels moved up, the image, ")) << r.output;
    EXPECT_TRUE(contains(r.output, "the 8 legal renders: 0 0 0 0 0 0 0 0")) << r.output;
    const Image heat = refray::readImage(dir + "/heat.png");
    bool cyan = false;
    for (const vec4& p : heat.pixels()) cyan = cyan || (p.r == 0.0f && p.g == 1.0f && p.b == 1.0f);
    EXPECT_TRUE(cyan) << "the failing region is outlined in cyan on the heat map";

    const std::string candidates = directory("envelope-regional-candidates");
    write(candidates + "/scene.cam.png", bad);
    r = compare("--golden-set " + dir + " " + candidates + " --html " + candidates + "/report.html");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "regional: stable pixels moved up, the image, ")) << r.output;
    std::ifstream html(candidates + "/report.html");
    std::stringstream page;
    page << html.rdbuf();
    EXPECT_TRUE(contains(page.str(), "stable pixels moved up, the image, ")) << "the HTML report names the region";
}

TEST(CompareCliEnvelope, AnOlderFormatDirectoryExits4NamingTheManifest) {
    const std::string dir = directory("envelope-old");
    std::ofstream(dir + "/goldens.json") << "{\"format\": \"refray-goldens/1\", \"goldens\": []}\n";
    const std::string c = write(dir + "/x.png", unorm(32, 24));
    const CliRun r = compare("--golden " + dir + " " + c);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, dir + "/goldens.json is a golden directory of format 'refray-goldens/1'")) << r.output;
    EXPECT_TRUE(contains(r.output, "refray golden update")) << r.output;
}

TEST(CompareCliEnvelope, ACandidateOfAnotherSizeExits3) {
    const std::string dir = envelopeDirectory("envelope-size", "no/such/scene.json", "0");
    const std::string c = write(dir + "/scene.cam.png", unorm(16, 24));
    const CliRun r = compare("--golden " + dir + " " + c);
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_TRUE(contains(r.output, c + " is 16x24, the golden " + dir + "/scene.cam.envelope.exr is 32x24")) << r.output;
}

TEST(CompareCliEnvelope, AGoldenWhoseSceneFileChangedExits4) {
    const std::string scene = directory("envelope-scene-file") + "/scene.json";
    std::ofstream(scene) << "{}\n";
    const std::string dir = envelopeDirectory("envelope-scene", scene, "0123");
    const std::string c = write(dir + "/scene.cam.png", unorm(32, 24));
    const CliRun r = compare("--golden " + dir + " " + c);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "was made from " + scene)) << r.output;
    EXPECT_TRUE(contains(r.output, "that file has changed")) << r.output;
}

TEST(CompareCliEnvelope, ACorruptedEnvelopeExits4NamingTheFile) {
    const std::string dir = envelopeDirectory("envelope-corrupt", "no/such/scene.json", "0");
    std::ofstream(dir + "/scene.cam.envelope.exr", std::ios::binary) << "garbage";
    const std::string c = write(dir + "/scene.cam.png", unorm(32, 24));
    const CliRun r = compare("--golden " + dir + " " + c);
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, dir + "/scene.cam.envelope.exr")) << r.output;
    EXPECT_TRUE(contains(r.output, "corrupted")) << r.output;
}

TEST(CompareCliEnvelope, GoldenSetReportsAMissingCandidateAsAFailureWithJUnit) {
    const std::string dir = envelopeDirectory("envelope-set", "no/such/scene.json", "0");
    const std::string candidates = directory("envelope-set-candidates");
    CliRun r = compare("--golden-set " + dir + " " + candidates + " --junit " + candidates + "/results.xml --html " +
                       candidates + "/report.html");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "scene.cam")) << r.output;
    EXPECT_TRUE(contains(r.output, "no candidate")) << r.output;
    std::ifstream junit(candidates + "/results.xml");
    std::stringstream xml;
    xml << junit.rdbuf();
    EXPECT_TRUE(contains(xml.str(), "<testcase classname=\"refray.golden\" name=\"scene.cam\"")) << xml.str();
    EXPECT_TRUE(contains(xml.str(), "<failure")) << xml.str();
    write(candidates + "/scene.cam.exr", unorm(32, 24));
    r = compare("--golden-set " + dir + " " + candidates + " --junit " + candidates + "/results.xml");
    EXPECT_EQ(r.status, 0) << r.output;
}

// In a directory of several goldens the candidate is found by the golden's name, or by its camera where one golden
// alone has it ("julia.png" for "proceduray-mandel-julia-pac.julia"); anything else names what the directory holds.
TEST(CompareCliEnvelope, ACandidateIsFoundByTheGoldensNameOrItsCamera) {
    const std::string golden = std::string(REFRAY_SOURCE_DIR) + "/tests/golden";
    const std::string dir = directory("envelope-by-camera");
    const std::string gpu = std::string(REFRAY_SOURCE_DIR) + "/tests/gpu-renders/images/proceduray-mandel-julia-pac.julia.exr";
    std::filesystem::copy_file(gpu, dir + "/julia.exr");
    CliRun r = compare("--golden " + golden + " " + dir + "/julia.exr");
    EXPECT_NE(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "proceduray-mandel-julia-pac.julia.envelope.exr")) << r.output;
    std::filesystem::copy_file(gpu, dir + "/close-up.exr");
    r = compare("--golden " + golden + " " + dir + "/close-up.exr");
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "is named 'close-up'")) << r.output;
    EXPECT_TRUE(contains(r.output, "proceduray-mandel-julia-pac.mandelbulb")) << r.output;
}
