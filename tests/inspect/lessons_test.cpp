// The lessons of docs/tutorial-indexing.md (scenes/lessons/*.json): each one reports exactly the diagnostics its
// file promises, changes the image (or, with nothing wrong, does not), and is quoted verbatim in the tutorial.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

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
    if (!diagnostic.empty()) return;
    auto base = loadScene(std::filesystem::path(scene->desc().file).parent_path() / lesson.base);
    const Image reference = base->render(settings).image;
    if (table.findings.empty())
        EXPECT_EQ(image.pixels(), reference.pixels()) << "a lesson with nothing wrong must not change the image";
    else
        EXPECT_NE(image.pixels(), reference.pixels()) << "the lesson's mistake does not show in the image";
}

TEST_P(Lesson, TheTutorialQuotesIt) {
    auto scene = loadScene(kLessons / (GetParam() + ".json"));
    const LessonDesc& lesson = scene->desc().lesson;
    const std::string tutorial = testing::readText(std::string(REFRAY_SOURCE_DIR) + "/docs/tutorial-indexing.md");
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
