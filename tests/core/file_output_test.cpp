#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/stat.h>

#include "core/file_output.h"
#include "core/image.h"
#include "tests/error_of.h"

using namespace refray;
using refray::testing::errorOf;
namespace fs = std::filesystem;

namespace {

fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::path(REFRAY_TEST_OUTPUT_DIR) / "file-output" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

size_t entries(const fs::path& dir) {
    return size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

}  // namespace

TEST(FileOutput, ReplacesTheFileWholeAndLeavesNothingElse) {
    const fs::path dir = freshDir("replace");
    writeFileAtomically((dir / "a.txt").string(), "first");
    writeFileAtomically((dir / "a.txt").string(), "second, longer");
    EXPECT_EQ(text(dir / "a.txt"), "second, longer");
    EXPECT_EQ(entries(dir), 1u);
    writeFileAtomically((dir / "new" / "folder" / "b.txt").string(), "b");  // creates its folder
    EXPECT_EQ(text(dir / "new" / "folder" / "b.txt"), "b");
}

TEST(FileOutput, KeepsPermissionsAndWritesThroughASymbolicLink) {
    const fs::path dir = freshDir("link");
    writeFileAtomically((dir / "target.txt").string(), "old");
    ::chmod((dir / "target.txt").c_str(), 0640);
    fs::create_symlink("target.txt", dir / "link.txt");
    writeFileAtomically((dir / "link.txt").string(), "new");
    EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
    EXPECT_EQ(text(dir / "target.txt"), "new");
    EXPECT_EQ(fs::status(dir / "target.txt").permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST(FileOutput, RefusesADirectoryADeviceAndAFileInTheFolderPath) {
    const fs::path dir = freshDir("refused");
    EXPECT_CONTAINS(errorOf([&] { writeFileAtomically(dir.string(), "x"); }), "it is a directory, not a regular file");
    EXPECT_CONTAINS(errorOf([] { writeFileAtomically("/dev/null", "x"); }), "'/dev/null': it is a device");
    writeFileAtomically((dir / "plain").string(), "keep");
    const std::string error = errorOf([&] { writeFileAtomically((dir / "plain" / "sub" / "x.png").string(), "x"); });
    EXPECT_CONTAINS(error, (dir / "plain").string() + "' is a file, not a folder");
    EXPECT_EQ(text(dir / "plain"), "keep");
}

TEST(FileOutput, ImagesGoThroughIt) {
    const fs::path dir = freshDir("image");
    writeImage((dir / "a.png").string(), Image(4, 4, vec4(1.0f)));
    writeImage((dir / "a.exr").string(), Image(4, 4, vec4(0.5f)));
    EXPECT_EQ(readImage((dir / "a.png").string()).at(1, 1), vec4(1.0f));
    EXPECT_EQ(readImage((dir / "a.exr").string()).at(1, 1), vec4(0.5f));
    EXPECT_EQ(entries(dir), 2u);
    EXPECT_CONTAINS(errorOf([&] { writeImage((dir / "a.png" / "b.png").string(), Image(1, 1)); }),
                    "is a file, not a folder");
}
