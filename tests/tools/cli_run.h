// Runs a command line as a user would and keeps its exit status and output (stdout and stderr).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
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

}  // namespace refray::testing
