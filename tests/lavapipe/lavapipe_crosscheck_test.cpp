// refray against Mesa's lavapipe (a CPU Vulkan driver, not a GPU) in every CI run: the same scene files rendered by
// refray's Vulkan back end and GLSL ports on lavapipe (`refray render --device vulkan --vulkan-device llvmpipe`),
// judged against refray's envelope goldens and compared with refray's index maps (docs/gpu-crosscheck.md,
// "lavapipe in every CI run").
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "core/envelope.h"
#include "core/image.h"
#include "core/json.h"
#include "inspect/index_map.h"
#include "inspect/map_crosscheck.h"
#include "scenes/scene.h"
#include "tests/lavapipe/lavapipe_support.h"
#include "tests/test_output.h"
#include "tests/tools/cli_run.h"
#include "verify/discrimination.h"
#include "verify/golden.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;
using testing::onLavapipe;
using testing::shellPath;
using testing::runRefray;
const fs::path kRoot = REFRAY_SOURCE_DIR;
const fs::path kGoldens = kRoot / "tests/golden";


std::vector<GoldenEntry> goldens() { return readGoldenManifest(kGoldens / "goldens.json").entries; }

const GoldenEntry& goldenNamed(const std::string& name) {
    static const std::vector<GoldenEntry> all = goldens();
    const auto it = std::find_if(all.begin(), all.end(), [&](const GoldenEntry& g) { return g.name == name; });
    if (it == all.end()) throw Error("no golden named " + name);
    return *it;
}

// The refray arguments of a golden's settings (after the scene file).
std::string goldenSettingArguments(const GoldenEntry& g) {
    return " --camera " + g.camera + " --time " + g.time + " --size " + std::to_string(g.width) + "x" +
           std::to_string(g.height);
}

// The scene file and its arguments.
std::string goldenArguments(const GoldenEntry& g) {
    return shellPath(kRoot / g.scene) + goldenSettingArguments(g);
}

std::string testName(std::string name) {
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

TEST(LavapipeDevices, ListedAsACpuDriverThatRayTracesAndHasRayQueries) {
    REFRAY_REQUIRE_LAVAPIPE();
    const testing::CliRun run = runRefray("devices");
    EXPECT_TRUE(testing::contains(run.output, "llvmpipe")) << run.output;
    EXPECT_TRUE(testing::contains(run.output, "is a CPU driver, not a GPU")) << run.output;
    const testing::CliRun listed = runRefray("devices --json");
    const json::Value root = json::parse(listed.output.substr(listed.output.find('{')), "refray devices --json");
    bool found = false;
    for (const json::Value& d : root.find("devices")->asArray()) {
        if (d.find("driver")->asString().find("llvmpipe") == std::string::npos) continue;
        found = true;
        EXPECT_TRUE(d.find("rayTracing")->asBool());
        EXPECT_TRUE(d.find("rayQuery")->asBool()) << "lavapipe offers VK_KHR_ray_query (Mesa 25)";
        EXPECT_TRUE(d.find("software")->asBool()) << "lavapipe is VK_PHYSICAL_DEVICE_TYPE_CPU";
    }
    EXPECT_TRUE(found) << listed.output;
}

TEST(LavapipeDevices, ANameThatMatchesNoDeviceIsRefusedWithTheList) {
    REFRAY_REQUIRE_LAVAPIPE();
    const fs::path out = testing::testOutputDirectory("lavapipe") / "none.png";
    const testing::CliRun run = runRefray("render builtin --size 8x8 --device vulkan --vulkan-device no-such-gpu -o " +
                                          shellPath(out));
    EXPECT_EQ(run.status, 2) << run.output;
    EXPECT_TRUE(testing::contains(run.output, "no Vulkan device matches 'no-such-gpu'")) << run.output;
    EXPECT_TRUE(testing::contains(run.output, "llvmpipe")) << "the message lists the devices: " << run.output;
    EXPECT_FALSE(fs::exists(out));
}

TEST(LavapipeDevices, ARenderRecordsDeviceDriverAndMesaVersion) {
    REFRAY_REQUIRE_LAVAPIPE();
    const fs::path out = testing::testOutputDirectory("lavapipe") / "builtin.exr";
    const testing::CliRun run = runRefray("render builtin --size 32x18" + onLavapipe() + " -o " + shellPath(out));
    ASSERT_EQ(run.status, 0) << run.output;
    const Image image = readImage(out.string());
    EXPECT_EQ(image.metadata.at("device"), "vulkan");
    EXPECT_NE(image.metadata.at("gpu").find("llvmpipe"), std::string::npos) << image.metadata.at("gpu");
    EXPECT_EQ(image.metadata.at("vulkan_device_type"), "CPU");
    EXPECT_NE(image.metadata.at("gpu_driver").find("Mesa"), std::string::npos) << image.metadata.at("gpu_driver");
    ASSERT_TRUE(image.metadata.contains("mesa_version"));
    EXPECT_GE(std::stoi(image.metadata.at("mesa_version")), 25) << image.metadata.at("mesa_version");
}

// ---- Every golden setting rendered on lavapipe passes its envelope golden, as a GPU team's CI would judge it.

class LavapipeGoldens : public ::testing::TestWithParam<std::string> {};

TEST_P(LavapipeGoldens, RenderPassesItsEnvelopeGolden) {
    REFRAY_REQUIRE_LAVAPIPE();
    const GoldenEntry& g = goldenNamed(GetParam());
    const fs::path dir = testing::testOutputDirectory("lavapipe");
    const fs::path out = dir / (g.name + ".lavapipe.exr"), heat = dir / (g.name + ".heat.png");
    const testing::CliRun render = runRefray("render " + goldenArguments(g) + onLavapipe() + " -o " + shellPath(out));
    ASSERT_EQ(render.status, 0) << render.output;
    const Image image = readImage(out.string());
    EXPECT_NE(image.metadata.at("gpu").find("llvmpipe"), std::string::npos);
    // The user's command: compare --golden finds the envelope in the golden directory by the candidate's name.
    const testing::CliRun compare = runRefray("compare --golden " + shellPath(kGoldens / g.envelope) + " " +
                                              shellPath(out) + " -o " + shellPath(heat));
    std::printf("%s", compare.output.c_str());
    EXPECT_TRUE(compare.status == 0 || compare.status == 1)
        << g.name << ": lavapipe's render fails its envelope golden (exit " << compare.status << "); render "
        << out.string() << ", heat map " << heat.string() << "\n"
        << compare.output;
}

std::vector<std::string> goldenNames() {
    std::vector<std::string> names;
    for (const GoldenEntry& g : goldens()) names.push_back(g.name);
    return names;
}

INSTANTIATE_TEST_SUITE_P(EveryGolden, LavapipeGoldens, ::testing::ValuesIn(goldenNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return testName(p.param); });

// ---- lavapipe is a correct candidate of `refray golden discriminate`: no false alarm on any golden.

class LavapipeDiscrimination : public ::testing::TestWithParam<std::string> {};

TEST_P(LavapipeDiscrimination, IsACorrectCandidateWithNoFalseAlarm) {
    REFRAY_REQUIRE_LAVAPIPE();
    DiscriminationOptions o;
    o.goldenDirectory = kGoldens;
    o.repositoryRoot = kRoot;
    o.threads = 2;
    o.goldens = {GetParam()};
    o.only = {"lavapipe"};
    o.vulkanRefray = REFRAY_BINARY;
    const std::vector<DiscriminationRow> rows = runDiscrimination(o);
    ASSERT_EQ(rows.size(), 1u);
    const DiscriminationRow& r = rows.front();
    ASSERT_TRUE(r.ran) << r.golden << ": the lavapipe candidate did not run: " << r.error;
    std::printf("%s: lavapipe %s, stable %llu/%llu, sensitive %llu/%llu\n", r.golden.c_str(), outcomeName(r).c_str(),
                (unsigned long long)r.judgement.stableOutside, (unsigned long long)r.judgement.stableBudget,
                (unsigned long long)r.judgement.sensitiveOutside, (unsigned long long)r.judgement.sensitiveBudget);
    EXPECT_TRUE(outcomeAsExpected(r)) << r.golden << ": lavapipe, a correct implementation, fails: a false alarm\n"
                                      << r.judgement.describe();
}

INSTANTIATE_TEST_SUITE_P(EveryGolden, LavapipeDiscrimination, ::testing::ValuesIn(goldenNames()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return testName(p.param); });

// ---- Index maps: every golden setting and every lesson that renders.

struct MapSetting {
    std::string name;       // the golden's name, or "lesson-<file stem>"
    fs::path scene;         // absolute
    std::string arguments;  // camera, time, size
    RenderSettings settings;
    std::string goldenEnvelope;  // for a golden setting: its order mask marks order-dependent pixels
};

RenderSettings sizeAndCamera(const std::string& camera, const std::string& size) {
    RenderSettings s;
    const size_t x = size.find('x');
    s.width = uint32_t(std::stoul(size.substr(0, x)));
    s.height = uint32_t(std::stoul(size.substr(x + 1)));
    s.camera = camera;
    s.threads = 2;
    return s;
}

std::vector<MapSetting> mapSettings() {
    std::vector<MapSetting> out;
    for (const GoldenEntry& g : goldens()) {
        MapSetting m{g.name, kRoot / g.scene, goldenSettingArguments(g), goldenSettings(g, 2), g.envelope};
        out.push_back(m);
    }
    // Lessons whose render is defined (expect.render.diagnostic empty); the others stop at a DXR diagnostic, where
    // a GPU's behaviour is undefined and nothing can be compared.
    std::vector<fs::path> lessons;
    for (const auto& entry : fs::directory_iterator(kRoot / "scenes/lessons"))
        if (entry.path().extension() == ".json") lessons.push_back(entry.path());
    std::sort(lessons.begin(), lessons.end());
    for (const fs::path& lesson : lessons) {
        const json::Value root = json::parseFile(lesson);
        const json::Value* render = root.find("expect") ? root.find("expect")->find("render") : nullptr;
        if (!render || !render->find("diagnostic")->asString().empty()) continue;
        const std::string camera = render->find("camera")->asString(), size = render->find("size")->asString();
        out.push_back({"lesson-" + lesson.stem().string(), lesson, " --camera " + camera + " --size " + size,
                       sizeAndCamera(camera, size), ""});
    }
    return out;
}

// The index maps a scene has: record, instance, geometry, primitive and hit group; a compute scene's primary rays are
// ray queries, which read no shader record (RQ-31), so only instance, geometry and primitive
// (docs/vulkan-backend.md, "AOVs").
std::vector<IndexMapKind> mapKindsOf(const SceneDesc& desc) {
    if (!desc.computeShader.empty()) return {IndexMapKind::Instance, IndexMapKind::Geometry, IndexMapKind::Primitive};
    return {IndexMapKind::Record, IndexMapKind::Instance, IndexMapKind::Geometry, IndexMapKind::Primitive,
            IndexMapKind::HitGroup};
}

// What a failing test prints for its parameter.
void PrintTo(const MapSetting& m, std::ostream* os) { *os << m.name << ": " << m.scene.string() << m.arguments; }

class LavapipeMaps : public ::testing::TestWithParam<MapSetting> {};

TEST_P(LavapipeMaps, EqualRefraysOutsideOrderDependentPixelsAndSilhouettes) {
    REFRAY_REQUIRE_LAVAPIPE();
    const MapSetting& m = GetParam();
    const fs::path dir = testing::testOutputDirectory("lavapipe");
    auto scene = loadScene(m.scene);
    IndexMapsByKind device;
    for (IndexMapKind kind : mapKindsOf(scene->desc())) {
        const std::string kindName = indexMapKindNames()[size_t(kind)];
        const fs::path out = dir / (m.name + "." + kindName + ".exr");
        const testing::CliRun run = runRefray("render " + shellPath(m.scene) + m.arguments + " --aov " + kindName +
                                              onLavapipe() + " -o " + shellPath(out));
        ASSERT_EQ(run.status, 0) << m.name << " " << kindName << ": " << run.output;
        const Image map = readImage(out.string());
        EXPECT_EQ(map.metadata.at("aov_instance_id_mismatches"), "0")
            << m.name << ": lavapipe's InstanceID() differs from the scene's on some pixels";
        device[kind] = readIndexValues(map);
    }
    const std::vector<uint8_t> mask =
        m.goldenEnvelope.empty() ? std::vector<uint8_t>() : readEnvelope((kGoldens / m.goldenEnvelope).string()).orderDependent;
    const MapCrosscheck check = crosscheckIndexMaps(*scene, m.settings, device, mask);
    std::printf("%s\n", check.summary(m.name + " (lavapipe)").c_str());
    if (!check.legal.empty()) std::printf("every exception, and why it is legal:\n%s", check.exceptions().c_str());
    EXPECT_TRUE(check.passed()) << m.name << ": " << check.failures();
}

INSTANTIATE_TEST_SUITE_P(EverySettingAndLesson, LavapipeMaps, ::testing::ValuesIn(mapSettings()),
                         [](const ::testing::TestParamInfo<MapSetting>& p) { return testName(p.param.name); });

}  // namespace
}  // namespace refray::scenes
