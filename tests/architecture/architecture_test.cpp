// The layers of docs/architecture.md, checked against the tree: every top-level source folder is described
// there, and no source file includes a layer above its own.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
const fs::path kRoot(REFRAY_SOURCE_DIR);

std::string readFile(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// What each layer may include besides itself (docs/architecture.md, "The layers").
const std::map<std::string, std::set<std::string>>& allowedIncludes() {
    static const std::set<std::string> belowScenes = {"core", "emulator", "procedural"};
    static const std::set<std::string> belowJobs = {"core", "emulator", "procedural", "scenes"};
    static const std::map<std::string, std::set<std::string>> allowed = {
        {"core", {}},
        {"emulator", {"core"}},
        {"procedural", {"core", "emulator"}},
        {"gpu", {"core", "emulator"}},
        {"scenes", belowScenes},
        {"inspect", belowJobs},
        {"verify", belowJobs},
        {"study", belowJobs},
        {"tools", {"core", "emulator", "gpu", "procedural", "scenes", "inspect", "verify", "study"}},
    };
    return allowed;
}

// Top-level folders that hold a CMake target of sources (tests/ mirrors them and is checked apart).
std::set<std::string> sourceFolders() {
    std::set<std::string> folders;
    for (const auto& entry : fs::directory_iterator(kRoot)) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_directory() || name.starts_with(".") || name == "build" || name == "tests") continue;
        if (fs::exists(entry.path() / "CMakeLists.txt")) folders.insert(name);
    }
    return folders;
}

}  // namespace

TEST(Architecture, EveryTopLevelSourceFolderIsDescribed) {
    const std::string doc = readFile(kRoot / "docs" / "architecture.md");
    ASSERT_FALSE(doc.empty()) << "docs/architecture.md is missing";
    const std::set<std::string> folders = sourceFolders();
    EXPECT_GE(folders.size(), 8u);
    for (const std::string& folder : folders) {
        EXPECT_NE(doc.find("| `" + folder + "/` |"), std::string::npos)
            << "docs/architecture.md has no row for the folder " << folder << "/ in its table of layers";
        EXPECT_TRUE(allowedIncludes().contains(folder))
            << folder << "/ is a source folder this test does not know: add its allowed includes here and in "
                         "docs/architecture.md";
    }
}

TEST(Architecture, NoUpwardInclude) {
    const std::regex include(R"(#include\s+"([a-z_]+)/)");
    size_t files = 0;
    for (const auto& [layer, allowed] : allowedIncludes()) {
        const fs::path dir = kRoot / layer;
        if (!fs::exists(dir)) continue;
        for (const auto& entry : fs::recursive_directory_iterator(dir)) {
            const std::string ext = entry.path().extension().string();
            if (ext != ".h" && ext != ".cpp") continue;
            ++files;
            const std::string text = readFile(entry.path());
            for (std::sregex_iterator it(text.begin(), text.end(), include), end; it != end; ++it) {
                const std::string target = (*it)[1].str();
                if (target == layer || !allowedIncludes().contains(target)) continue;  // own layer, or not a layer
                EXPECT_TRUE(allowed.contains(target))
                    << fs::relative(entry.path(), kRoot).string() << " includes \"" << target << "/...\": " << layer
                    << "/ may include only what is below it (docs/architecture.md)";
            }
        }
    }
    EXPECT_GT(files, 100u);
}
