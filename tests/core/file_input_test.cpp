#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/file_input.h"
#include "core/file_output.h"
#include "core/image.h"
#include "tests/error_of.h"

using namespace refray;
using refray::testing::errorOf;
namespace fs = std::filesystem;

namespace {

fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::path(REFRAY_TEST_OUTPUT_DIR) / "file-input" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

}  // namespace

TEST(FileInput, RefusesWhatIsNotAFileOfADocumentedSize) {
    const fs::path dir = freshDir("input");
    EXPECT_CONTAINS(errorOf([&] { readInputFile(dir.string(), "scene file"); }),
                    "cannot read scene file '" + dir.string() + "': it is a directory, not a file");
    EXPECT_CONTAINS(errorOf([] { readInputFile("/dev/zero", "scene file"); }),
                    "cannot read scene file '/dev/zero': it is a device, not a file");
    writeFileAtomically((dir / "big.txt").string(), std::string(100, 'x'));
    EXPECT_CONTAINS(errorOf([&] { readInputFile((dir / "big.txt").string(), "model file", 64); }),
                    "it holds 100 bytes, more than the 64 bytes refray reads");
    EXPECT_EQ(readInputFile((dir / "big.txt").string(), "model file", 100), std::string(100, 'x'));
    EXPECT_CONTAINS(errorOf([&] { readImage(dir.string()); }), "it is a directory");
}
