// Faults as a user or a full disk brings them (README "What refray never does"): each test asserts the message, the
// exit status and that no file that was there before is lost or replaced by a partial one.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/tools/cli_run.h"

namespace {

namespace fs = std::filesystem;
using refray::testing::contains;
using refray::testing::runCommand;
using refray::testing::runRefray;

const std::string kRefray = REFRAY_BINARY;
const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

std::string fileText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

void writeFile(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// Files whose name says they are one of refray's temporary files, left in `dir`.
std::string leftoverTemporaries(const fs::path& dir) {
    std::string names;
    for (const auto& f : fs::directory_iterator(dir))
        if (f.path().filename().string().find(".refray-") != std::string::npos) names += f.path().string() + " ";
    return names;
}

// A small good render to stand for the work a fault must not destroy.
std::string goodRender(const fs::path& path) {
    const auto r = runRefray("render builtin --size 8x8 -o " + path.string());
    EXPECT_EQ(r.status, 0) << r.output;
    return fileText(path);
}

TEST(FaultInjection, AFullDiskLeavesTheOldImageAndNoTemporaryFile) {
    const fs::path dir = refray::testing::freshDirectory("faults", "full-disk");
    const fs::path good = dir / "good.exr";
    const std::string before = goodRender(good);
    // A 64 KiB tmpfs in a private mount namespace holds the small EXR but not a 640x360 one (about 1 MB). Where
    // namespaces are not allowed, a 64 KiB file-size limit (ulimit -f) is the same fault from the kernel.
    const fs::path mount = dir / "mnt";
    fs::create_directories(mount);
    const std::string script =
        "set -u; M=" + mount.string() + "; cp " + good.string() + " $M/out.exr; " + kRefray +
        " render builtin --size 640x360 -o $M/out.exr; echo \"status=$?\"; cmp -s " + good.string() +
        " $M/out.exr && echo SAME; ls -a $M | grep refray- || echo NO-TEMPORARY";
    auto r = runCommand("unshare -rm sh -c 'mount -t tmpfs -o size=64k tmpfs " + mount.string() + " && " + script +
                        "'");
    const bool tmpfs = contains(r.output, "status=");
    if (!tmpfs)
        r = runCommand("sh -c '(ulimit -f 64; " + script + ")'");
    EXPECT_TRUE(contains(r.output, tmpfs ? "no space left on device" : "file too large")) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot write '" + mount.string() + "/out.exr'")) << r.output;
    EXPECT_TRUE(contains(r.output, "status=2")) << r.output;
    EXPECT_TRUE(contains(r.output, "SAME")) << "the old image was replaced:\n" << r.output;
    EXPECT_TRUE(contains(r.output, "NO-TEMPORARY")) << r.output;
    EXPECT_FALSE(contains(r.output, "wrote ")) << r.output;
    EXPECT_EQ(fileText(good), before);
}

TEST(FaultInjection, ASignalDuringAWriteLeavesTheOldImageAndNoTemporaryFile) {
    const fs::path dir = refray::testing::freshDirectory("faults", "signal");
    const fs::path out = dir / "out.png";
    const std::string before = goodRender(out);
    // REFRAY_TEST_WRITE_DELAY_MS holds the finished temporary file before its rename; SIGTERM lands then.
    const std::string script = "REFRAY_TEST_WRITE_DELAY_MS=20000 " + kRefray + " render builtin --size 64x36 -o " +
                               out.string() + " & p=$!; i=0; while [ $i -lt 400 ] && ! ls -a " + dir.string() +
                               " | grep -q refray-; do sleep 0.05; i=$((i+1)); done; ls -a " + dir.string() +
                               " | grep -q refray- && echo IN-FLIGHT; kill -TERM $p; wait $p; echo \"status=$?\"";
    const auto r = runCommand("sh -c '" + script + "'");
    EXPECT_TRUE(contains(r.output, "IN-FLIGHT")) << r.output;
    EXPECT_TRUE(contains(r.output, "status=143")) << "killed by SIGTERM: 128 + 15\n" << r.output;
    EXPECT_EQ(fileText(out), before) << "the old image was replaced";
    EXPECT_EQ(leftoverTemporaries(dir), "");

    // SIGINT too, although the shell starts a background command with SIGINT ignored.
    const std::string interrupt = "REFRAY_TEST_WRITE_DELAY_MS=20000 " + kRefray + " render builtin --size 64x36 -o " +
                                  out.string() + " & p=$!; i=0; while [ $i -lt 400 ] && ! ls -a " + dir.string() +
                                  " | grep -q refray-; do sleep 0.05; i=$((i+1)); done; kill -INT $p; wait $p; "
                                  "echo \"status=$?\"";
    const auto i = runCommand("sh -c '" + interrupt + "'");
    EXPECT_TRUE(contains(i.output, "status=130")) << "killed by SIGINT: 128 + 2\n" << i.output;
    EXPECT_EQ(fileText(out), before) << "the old image was replaced";
    EXPECT_EQ(leftoverTemporaries(dir), "");
}

TEST(FaultInjection, AnOutputThatIsAnInputIsRefusedAndTheInputKept) {
    const fs::path dir = refray::testing::freshDirectory("faults", "output-is-input");
    const fs::path reference = dir / "ref.png", candidate = dir / "cand.png";
    const std::string referenceBytes = goodRender(reference);
    goodRender(candidate);
    auto r = runRefray("compare " + reference.string() + " " + candidate.string() + " -o " + reference.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "the output -o '" + reference.string() + "' is the input REFERENCE")) << r.output;
    EXPECT_EQ(fileText(reference), referenceBytes);

    // Through another spelling of the same path.
    const fs::path scene = dir / "scene.json";
    fs::copy_file(kD3D12, scene);
    const std::string sceneBytes = fileText(scene);
    r = runRefray("explain " + scene.string() + " --pixel 1,1 --size 8x8 -o " + (dir / "." / "scene.json").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "is the input scene file")) << r.output;
    EXPECT_EQ(fileText(scene), sceneBytes);

    r = runRefray("render " + scene.string() + " --size 8x8 -o " + scene.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "refray never overwrites an input")) << r.output;
    EXPECT_EQ(fileText(scene), sceneBytes);

    // Two outputs of one command.
    const fs::path image = dir / "image.png";
    const std::string imageBytes = goodRender(image);
    r = runRefray("render builtin --size 8x8 -o " + image.string() + " --stats-json " + image.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "the outputs -o '" + image.string() + "' and --stats-json")) << r.output;
    EXPECT_EQ(fileText(image), imageBytes);
}

TEST(FaultInjection, AnOutputFolderThatCannotExistIsNamed) {
    const fs::path dir = refray::testing::freshDirectory("faults", "folder-is-a-file");
    writeFile(dir / "plain", "a file\n");
    const auto r = runRefray("render builtin --size 8x8 -o " + (dir / "plain" / "out.png").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, (dir / "plain").string() + "' is a file, not a folder")) << r.output;
    EXPECT_EQ(fileText(dir / "plain"), "a file\n");
}

TEST(FaultInjection, ADirectoryOrADeviceAsAnInputIsNamedBeforeReading) {
    const fs::path dir = refray::testing::freshDirectory("faults", "unusual-inputs");
    auto r = runRefray("render " + dir.string() + " -o " + (dir / "x.png").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot read scene file '" + dir.string() + "': it is a directory")) << r.output;
    r = runRefray("render /dev/zero -o " + (dir / "x.png").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot read scene file '/dev/zero': it is a device")) << r.output;
    r = runRefray("table /dev/zero");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "'/dev/zero': it is a device")) << r.output;
    const fs::path image = dir / "image.png";
    goodRender(image);
    r = runRefray("compare " + image.string() + " /dev/zero");
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "cannot read image '/dev/zero': it is a device")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.png"));
}

// The CRC of a PNG chunk (ISO 3309, as zlib's crc32).
uint32_t crc32(const std::string& bytes) {
    uint32_t crc = 0xFFFFFFFFu;
    for (unsigned char b : bytes) {
        crc ^= b;
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

std::string bigEndian(uint32_t v) {
    return {char(v >> 24), char((v >> 16) & 255), char((v >> 8) & 255), char(v & 255)};
}

std::string chunk(const std::string& type, const std::string& data) {
    return bigEndian(uint32_t(data.size())) + type + data + bigEndian(crc32(type + data));
}

TEST(FaultInjection, ADecompressionBombIsRefusedBeforeItsPixelsAreAllocated) {
    const fs::path dir = refray::testing::freshDirectory("faults", "bomb");
    // A PNG of a few dozen bytes whose header declares 40000 x 40000 RGBA pixels (6.4 GB as floats).
    const std::string header = bigEndian(40000) + bigEndian(40000) + std::string{8, 6, 0, 0, 0};
    const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", header) +
                            chunk("IDAT", std::string("\x78\x9c\x03\x00\x00\x00\x00\x01", 8)) + chunk("IEND", "");
    writeFile(dir / "bomb.png", png);
    const fs::path image = dir / "image.png";
    goodRender(image);
    const auto r = runRefray("compare " + image.string() + " " + (dir / "bomb.png").string());
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "bomb.png': its header declares 40000x40000 pixels")) << r.output;
    EXPECT_FALSE(contains(r.output, "bad_alloc")) << r.output;
}

// A lesson patching the D3D12 sample: the instance 'primitives' gets a singular transform (INST-9) and one AABB is
// inverted (DEGEN-8).
fs::path warningScene(const fs::path& dir) {
    const fs::path lesson = dir / "warnings.json";
    writeFile(lesson, "{\"format\": \"refray-lesson/1\", \"name\": \"warnings\", \"base\": \"" + kD3D12 +
                          "\", \"title\": \"build warnings\", \"patch\": ["
                          "{\"op\": \"replace\", \"path\": \"/instances/0/transform\", \"value\": {\"scale\": [0, 0, 0]}},"
                          "{\"op\": \"replace\", \"path\": \"/bottomLevel/1/geometries/0/aabbs\", "
                          "\"value\": [[1, 1, 1, -1, -1, -1]]}]}\n");
    return lesson;
}

TEST(FaultInjection, BuildWarningsAreShownOnceWithTheirRuleAndPlaceAndCanBeErrors) {
    const fs::path dir = refray::testing::freshDirectory("faults", "warnings");
    const fs::path scene = warningScene(dir);
    for (const std::string& command : {"render " + scene.string() + " --size 8x8 -o " + (dir / "w.png").string(),
                                      "table " + scene.string(),
                                      "explain " + scene.string() + " --size 8x8 --pixel 1,1"}) {
        auto r = runRefray(command);
        EXPECT_EQ(r.status, 0) << command << "\n" << r.output;
        // Where the instance and the bottom-level structure are declared: the lesson's base.
        EXPECT_TRUE(contains(r.output, "warning INST-9: " + kD3D12 + ":107:5: instance 'ground'")) << command << "\n"
                                                                                                   << r.output;
        EXPECT_TRUE(contains(r.output, "warning DEGEN-8: " + kD3D12 + ":93:5: bottom-level 'ProceduralPrimitives': "
                                       "geometry 0 AABB 0 is inverted"))
            << command << "\n" << r.output;
        const size_t first = r.output.find("warning DEGEN-8");
        EXPECT_EQ(r.output.find("warning DEGEN-8", first + 1), std::string::npos) << "shown twice:\n" << r.output;
        r = runRefray(command + " --warnings-as-errors");
        EXPECT_EQ(r.status, 2) << command << "\n" << r.output;
        EXPECT_TRUE(contains(r.output, "--warnings-as-errors: the scene has 2 build warnings")) << r.output;
    }
}

TEST(FaultInjection, AStaleOrForeignGoldenJobFileIsRefusedByName) {
    const fs::path dir = refray::testing::freshDirectory("faults", "golden-jobs");
    const std::string make = "golden make " + kD3D12 + " --size 8x6 --perturbed 3 --order-check 1 --threads 1 --root " +
                             std::string(REFRAY_SOURCE_DIR);
    const fs::path a = dir / "a", b = dir / "b";
    ASSERT_EQ(runRefray(make + " --time 0 -o " + a.string() + " --emit-jobs " + (dir / "a.txt").string()).status, 0);
    // Planning another time into the same folder would mix two plans' renders: refused, naming the plan there.
    auto r = runRefray(make + " --time 5 -o " + a.string() + " --emit-jobs " + (dir / "a5.txt").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, (a / "jobs").string() + " holds another plan")) << r.output;
    EXPECT_TRUE(contains(r.output, "time 0")) << r.output;

    // The same scene and settings planned elsewhere: a render of that plan dropped into a's jobs is foreign.
    ASSERT_EQ(runRefray(make + " --time 0 -o " + b.string() + " --emit-jobs " + (dir / "b.txt").string()).status, 0);
    ASSERT_EQ(runCommand("sh " + (dir / "a.txt").string()).status, 0);
    ASSERT_EQ(runCommand("sh -c \"$(sed -n 1p " + (dir / "b.txt").string() + ")\"").status, 0);
    const fs::path nominal = a / "jobs" / "d3d12-procedural-geometry.default" / "nominal.exr";
    ASSERT_TRUE(fs::exists(nominal));
    fs::copy_file(b / "jobs" / "d3d12-procedural-geometry.default" / "nominal.exr", nominal,
                  fs::copy_options::overwrite_existing);
    r = runRefray("golden make --collect -o " + a.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, nominal.string() + " was not rendered for this plan")) << r.output;
    EXPECT_FALSE(fs::exists(a / "goldens.json")) << "a golden was made from a foreign render";
}

TEST(FaultInjection, TwoCandidatesForOneGoldenAreReportedNotChosenBetween) {
    const fs::path dir = refray::testing::freshDirectory("faults", "ambiguous");
    ASSERT_EQ(runRefray("golden make " + kD3D12 + " --size 8x6 --perturbed 3 --order-check 1 --threads 1 -o " +
                        (dir / "goldens").string() + " --root " + std::string(REFRAY_SOURCE_DIR))
                  .status,
              0);
    const fs::path candidates = dir / "candidates";
    const std::string render = "render " + kD3D12 + " --size 8x6 --threads 1 -o " + (candidates / "d3d12-procedural-geometry.default").string();
    ASSERT_EQ(runRefray(render + ".exr").status, 0);
    ASSERT_EQ(runRefray("compare --golden-set " + (dir / "goldens").string() + " " + candidates.string()).status, 0);
    ASSERT_EQ(runRefray(render + ".png").status, 0);
    const auto r = runRefray("compare --golden-set " + (dir / "goldens").string() + " " + candidates.string());
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(contains(r.output, "two candidates, " + (candidates / "d3d12-procedural-geometry.default.exr").string() +
                                       " and " + (candidates / "d3d12-procedural-geometry.default.png").string()))
        << r.output;
}

TEST(FaultInjection, MeaninglessOptionsAreRefusedWithTheRange) {
    auto r = runRefray("render builtin --size 8x8 --threads 100000 -o /dev/null/x.png");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "--threads: expects a number of worker threads from 0 (all) to")) << r.output;
    r = runRefray("golden make " + kD3D12 + " --perturbed 0 -o /nonexistent");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "--perturbed: expects a number of perturbed renders from 3 to 1000")) << r.output;
}

TEST(FaultInjection, ACameraLookingNowhereOrOverflowingIsNamedAtItsLine) {
    const fs::path dir = refray::testing::freshDirectory("faults", "camera");
    const auto lesson = [&](const std::string& name, const std::string& patch) {
        const fs::path file = dir / (name + ".json");
        writeFile(file, "{\"format\": \"refray-lesson/1\", \"name\": \"" + name + "\", \"base\": \"" + kD3D12 +
                            "\", \"title\": \"camera\", \"patch\": [" + patch + "]}\n");
        return file.string();
    };
    auto r = runRefray("render " + lesson("eye-on-target", "{\"op\": \"replace\", \"path\": \"/cameras/0/target\", "
                                                           "\"value\": [0, 5.3, -17]}") + " --size 8x8 -o " +
                       (dir / "x.png").string());
    // The sample's eye is (0, 5.3, -17), and its up comes from 'upFromRight', which must not be blamed.
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "eye-on-target.json")) << r.output;
    EXPECT_TRUE(contains(r.output, "eye and target are the same point (0, 5.3, -17)")) << r.output;
    EXPECT_FALSE(contains(r.output, "parallel")) << r.output;
    r = runRefray("render " + lesson("huge", "{\"op\": \"replace\", \"path\": \"/cameras/0/eye\", \"value\": [3e38, 3e38, "
                                             "3e38]}") + " --size 8x8 -o " + (dir / "y.png").string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_TRUE(contains(r.output, kD3D12 + ":147:5: camera 'default': its rays overflow float")) << r.output;
    EXPECT_FALSE(fs::exists(dir / "y.png"));
}

}  // namespace
