// Runs a command line as a user would and keeps its exit status and output (stdout and stderr).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace refray::testing {

struct CliRun {
    int status;
    std::string output;
};

inline CliRun runCommand(const std::string& command) {
    FILE* pipe = popen((command + " 2>&1").c_str(), "r");
    CliRun r{-1, {}};
    if (!pipe) return r;
    std::array<char, 4096> buffer;
    while (fgets(buffer.data(), int(buffer.size()), pipe)) r.output += buffer.data();
    const int status = pclose(pipe);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

// The refray binary under test with `arguments`.
inline CliRun runRefray(const std::string& arguments) { return runCommand(std::string(REFRAY_BINARY) + " " + arguments); }

// A fresh, empty directory `group`/`name` under the test output directory.
inline std::string freshDirectory(const std::string& group, const std::string& name) {
    const auto dir = std::filesystem::path(REFRAY_TEST_OUTPUT_DIR) / group / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace refray::testing
