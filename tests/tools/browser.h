// Headless Chromium for the tests of refray's HTML pages: the DOM after the page's scripts ran.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/tools/cli_run.h"

namespace refray::testing {

inline std::string findBrowser() {
    for (const char* name : {"chromium", "chromium-browser"}) {
        const CliRun r = runCommand(std::string("command -v ") + name);
        if (r.status == 0 && !r.output.empty()) return r.output.substr(0, r.output.find('\n'));
    }
    return {};
}

// The DOM of file `htmlPath` (plus `fragment`, e.g. "#pixel=3,4") after its scripts ran, or "" with the
// failure in `error`.
inline std::string dumpDom(const std::string& browser, const std::string& htmlPath, const std::string& profile,
                           std::string& error, const std::string& fragment = "") {
    const std::string command = "timeout 120 " + browser + " --headless --disable-gpu --no-sandbox --user-data-dir=" +
                                profile + " --dump-dom 'file://" + std::filesystem::absolute(htmlPath).string() +
                                fragment + "' 2>/dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) {
        error = "cannot start " + browser;
        return {};
    }
    std::string dom;
    std::array<char, 65536> buffer;
    size_t n;
    while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) dom.append(buffer.data(), n);
    const int status = pclose(pipe);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) error = "browser exited with " + std::to_string(status);
    return dom;
}

}  // namespace refray::testing

#define REQUIRE_BROWSER(browser)                                                                              \
    const std::string browser = refray::testing::findBrowser();                                               \
    if (browser.empty()) {                                                                                    \
        if (std::getenv("REFRAY_ALLOW_NO_BROWSER")) GTEST_SKIP() << "chromium not installed";                 \
        FAIL() << "chromium is not installed: run 'bash tools/setup.sh' as root (or set "                     \
                  "REFRAY_ALLOW_NO_BROWSER=1 to skip the browser checks)";                                    \
    }
