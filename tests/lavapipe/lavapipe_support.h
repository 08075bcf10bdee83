// Mesa's lavapipe in the test suite: whether it can run refray's Vulkan back end here, and the arguments that pick it.
//
// lavapipe (llvmpipe) is a CPU Vulkan driver, not a GPU: Debian 12's bookworm-backports Mesa (25.x) gives it
// VK_KHR_ray_tracing_pipeline, VK_KHR_acceleration_structure and VK_KHR_ray_query, so every machine with it runs a
// second, independent implementation of traversal and of every shader (the GLSL ports). tools/setup.sh installs it.
//
// Where it is missing the Lavapipe* tests skip, naming the install command; with CI=true in the environment a
// missing lavapipe is a failure, so CI can never pass without running them.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/json.h"
#include "tests/tools/cli_run.h"

namespace refray::testing {

struct LavapipeStatus {
    bool available = false;
    std::string device;  // "llvmpipe (LLVM 15.0.6, 256 bits), Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"
    std::string why;     // why it is not available
};

// `refray devices --json`, once per process: a device whose driver or name says llvmpipe and that can ray trace.
inline const LavapipeStatus& lavapipeStatus() {
    static const LavapipeStatus status = [] {
        LavapipeStatus s;
        const CliRun run = runRefray("devices --json");
        const size_t brace = run.output.find('{');
        if (brace == std::string::npos) {
            s.why = "'refray devices --json' printed no device list (exit " + std::to_string(run.status) +
                    "): " + run.output;
            return s;
        }
        try {
            const json::Value root = json::parse(run.output.substr(brace), "refray devices --json");
            std::string seen;
            for (const json::Value& d : root.find("devices")->asArray()) {
                std::string name = d.find("name")->asString(), driver = d.find("driver")->asString();
                seen += "\n  " + name + " (" + driver + ")";
                std::string lower = name + " " + driver;
                std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
                if (lower.find("llvmpipe") == std::string::npos) continue;
                if (!d.find("rayTracing")->asBool()) {
                    s.why = "lavapipe is installed but cannot ray trace (Mesa older than 25?): " + name + ", " +
                            d.find("driverInfo")->asString();
                    return s;
                }
                s.available = true;
                s.device = name + ", " + d.find("driverInfo")->asString();
                return s;
            }
            s.why = "no lavapipe among the Vulkan devices:" + (seen.empty() ? std::string(" none") : seen);
        } catch (const Error& e) {
            s.why = std::string("'refray devices --json' printed no device list: ") + e.what() + "\n" + run.output;
        }
        return s;
    }();
    return status;
}

inline bool runningInCi() {
    const char* ci = std::getenv("CI");
    return ci && std::string(ci) == "true";
}

// A path for the command line, in single quotes. Built by appending: GCC 12 at -O3 warns (-Wrestrict, a false
// positive) on "'" + p.string() + "'".
inline std::string shellPath(const std::filesystem::path& p) {
    std::string q = "'";
    q += p.string();
    q += '\'';
    return q;
}

// The refray arguments that render on lavapipe, even where a GPU is the default device.
inline std::string onLavapipe() { return " --device vulkan --vulkan-device llvmpipe"; }

}  // namespace refray::testing

// At the top of every Lavapipe* test: skips it where lavapipe is missing, or fails it when CI=true.
#define REFRAY_REQUIRE_LAVAPIPE()                                                                                    \
    do {                                                                                                             \
        const ::refray::testing::LavapipeStatus& lavapipe_ = ::refray::testing::lavapipeStatus();                    \
        if (!lavapipe_.available) {                                                                                  \
            if (::refray::testing::runningInCi())                                                                    \
                FAIL() << "CI=true and Mesa's lavapipe is missing, so the lavapipe cross-checks cannot run: "        \
                       << lavapipe_.why << "\nInstall it with: bash tools/setup.sh (as root)";                       \
            GTEST_SKIP() << "Mesa's lavapipe is missing (" << lavapipe_.why                                          \
                         << "); install it with: bash tools/setup.sh (as root)";                                     \
        }                                                                                                            \
    } while (0)
