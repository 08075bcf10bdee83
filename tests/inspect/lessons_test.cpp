// The lessons of docs/tutorial-indexing.md (scenes/lessons/*.json): each one reports exactly the diagnostics its
// file promises, changes the image (or, with nothing wrong, does not), and is quoted verbatim in the tutorial.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "emulator/dispatch_stats.h"
#include "emulator/validation.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "inspect/table_view.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

const std::filesystem::path kLessons = std::filesystem::path(REFRAY_SOURCE_DIR) / "scenes" / "lessons";

std::vector<std::string> lessonNames() {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(kLessons))
        if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
    std::sort(names.begin(), names.end());
    return names;
}

RenderSettings lessonSettings(const LessonDesc& lesson) {
    RenderSettings s;
    const size_t x = lesson.renderSize.find('x');
    s.width = uint32_t(std::stoul(lesson.renderSize.substr(0, x)));
    s.height = uint32_t(std::stoul(lesson.renderSize.substr(x + 1)));
    s.camera = lesson.renderCamera;
    s.threads = 2;
    return s;
}

// The render's stopping diagnostic ("" when it renders) and the image.
std::string renderLesson(Scene& scene, const RenderSettings& settings, Image& image) {
    try {
        image = scene.render(settings).image;
    } catch (const dxr::DxrError& e) {
        return e.what();
    }
    return "";
}

class Lesson : public ::testing::TestWithParam<std::string> {};

TEST_P(Lesson, ReportsExactlyWhatItPromises) {
    const std::filesystem::path file = kLessons / (GetParam() + ".json");
    auto scene = loadScene(file);
    const LessonDesc& lesson = scene->desc().lesson;
    ASSERT_FALSE(lesson.title.empty()) << file << " is not a lesson";

    // The static check of the indexing rule (refray table --check): its first finding, verbatim.
    const TableView table = buildTableView(*scene, procedural::Precision::Float);
    EXPECT_EQ(table.findings.empty() ? std::string() : table.findings.front().format(), lesson.expectTable);

    // The render: the diagnostic it stops with, verbatim (GEN-1, GEN-2: the first error by launch index).
    const RenderSettings settings = lessonSettings(lesson);
    Image image;
    const std::string diagnostic = renderLesson(*scene, settings, image);
    EXPECT_EQ(diagnostic, lesson.expectRender);

    // Against the scene it breaks: a lesson without findings renders the same pixels; one with findings must
    // show its mistake, by a diagnostic or by a different image.
    // A lesson may say which it is ("image"): a mistake no rule reports (inline rays that ignore procedural
    // candidates) changes the image without findings, and a costlier but correct choice keeps it.
    if (!diagnostic.empty()) return;
    auto base = loadScene(std::filesystem::path(scene->desc().file).parent_path() / lesson.base);
    const Image reference = base->render(settings).image;
    const bool same = lesson.expectImage.empty() ? table.findings.empty() : lesson.expectImage == "same-as-base";
    if (same)
        EXPECT_EQ(image.pixels(), reference.pixels()) << "the lesson promises the base's image";
    else
        EXPECT_NE(image.pixels(), reference.pixels()) << "the lesson's mistake does not show in the image";
}

TEST_P(Lesson, TheTutorialQuotesIt) {
    auto scene = loadScene(kLessons / (GetParam() + ".json"));
    const LessonDesc& lesson = scene->desc().lesson;
    // The indexing lessons are in the indexing tutorial, the RayQuery lessons in docs/ray-query.md.
    const std::string tutorial = testing::readText(std::string(REFRAY_SOURCE_DIR) + "/docs/tutorial-indexing.md") +
                                 testing::readText(std::string(REFRAY_SOURCE_DIR) + "/docs/ray-query.md");
    EXPECT_CONTAINS(tutorial, "scenes/lessons/" + GetParam() + ".json");
    if (!lesson.expectTable.empty()) {
        EXPECT_CONTAINS(tutorial, lesson.expectTable);
    }
    if (!lesson.expectRender.empty()) {
        EXPECT_CONTAINS(tutorial, lesson.expectRender);
    }
}

INSTANTIATE_TEST_SUITE_P(Lessons, Lesson, ::testing::ValuesIn(lessonNames()),
                         [](const ::testing::TestParamInfo<std::string>& lesson) {
                             std::string name = lesson.param;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

// RQ-16, RQ-13: the shadow query without ACCEPT_FIRST_HIT_AND_END_SEARCH renders the same image
// (ReportsExactlyWhatItPromises). In the default order (nearest first) a commit skips every farther box anyway; in
// an adversarial order, as a GPU's unsorted traversal may be, the query without the flag is handed more candidates
// and commits more hits. The same image there too.
TEST(RayQueryLessons, RQ_16_AcceptFirstHitHandsTheShaderFewerCandidates) {
    auto lesson = loadScene(kLessons / "accept-first-hit-for-shadows.json");
    auto base = loadScene(kLessons / ".." / "d3d12-procedural-geometry-inline.json");
    RenderSettings settings = lessonSettings(lesson->desc().lesson);
    {
        const dxr::DispatchStats with = base->render(settings).dispatch.stats;
        const dxr::DispatchStats without = lesson->render(settings).dispatch.stats;
        EXPECT_GT(with.rayQueries, 0u);
        EXPECT_EQ(with.rayQueries, without.rayQueries);
        EXPECT_LE(with.queryCandidates, without.queryCandidates);
        EXPECT_LE(with.queryCommits, without.queryCommits);
    }
    settings.order = dxr::TraversalOrder::Adversarial;
    settings.adversarialSeed = 1;
    const RenderResult with = base->render(settings);
    const RenderResult without = lesson->render(settings);
    EXPECT_EQ(with.image.pixels(), without.image.pixels());
    EXPECT_EQ(with.dispatch.stats.rayQueries, without.dispatch.stats.rayQueries);
    EXPECT_LT(with.dispatch.stats.queryCandidates, without.dispatch.stats.queryCandidates);
    EXPECT_LT(with.dispatch.stats.queryCommits, without.dispatch.stats.queryCommits);
    // The TraceRay part of the scene is untouched.
    EXPECT_EQ(with.dispatch.stats.raysTraced - with.dispatch.stats.rayQueries,
              without.dispatch.stats.raysTraced - without.dispatch.stats.rayQueries);
}

// RQ-22: a procedural candidate the shader does not intersect is never committed: the shadow queries of the
// lesson commit only the ground plane's opaque triangles (inside Proceed, RQ-14), so fewer commits.
TEST(RayQueryLessons, RQ_22_IgnoredProceduralCandidatesCommitNothing) {
    auto lesson = loadScene(kLessons / "inline-procedural-never-intersected.json");
    auto base = loadScene(kLessons / ".." / "d3d12-procedural-geometry-inline.json");
    const RenderSettings settings = lessonSettings(lesson->desc().lesson);
    const dxr::DispatchStats with = base->render(settings).dispatch.stats;
    const dxr::DispatchStats without = lesson->render(settings).dispatch.stats;
    EXPECT_EQ(with.rayQueries, without.rayQueries);
    EXPECT_LT(without.queryCommits, with.queryCommits);
}

TEST(LessonFormat, AnExpectedImageIsSameOrDiffers) {
    const std::string text = R"({"format": "refray-lesson/1", "name": "x", "base": "../proceduray-mandel-julia-pac.json",
 "title": "t", "patch": [], "expect": {"render": {"diagnostic": "", "image": "similar"}}})";
    try {
        parseScene(text, (kLessons / "broken.json").string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_CONTAINS(e.what(), "the lesson's expected image is \"same-as-base\" or \"differs-from-base\"");
    }
}

TEST(LessonFormat, PatchErrorsPointAtTheLesson) {
    const std::string text = R"({"format": "refray-lesson/1", "name": "x", "base": "../proceduray-mandel-julia-pac.json",
 "title": "t", "patch": [{"op": "replace", "path": "/instances/9/mask", "value": 0}]})";
    try {
        parseScene(text, (kLessons / "broken.json").string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), (kLessons / "broken.json").string() +
                                             ":2:52: path '/instances/9/mask': index 9 is past the end of an array of 5 elements");
    }
}

TEST(LessonFormat, AMissingBaseIsNamed) {
    const std::string text = R"({"format": "refray-lesson/1", "name": "x", "base": "nowhere.json", "title": "t", "patch": []})";
    const std::string error = testing::loadError(text);
    EXPECT_CONTAINS(error, "broken.json:1:52: cannot read the lesson's base 'nowhere.json': no such file or directory");
}

}  // namespace
}  // namespace refray::scenes
