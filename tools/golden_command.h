// `refray golden ...`: the envelope goldens (verify/golden.h, docs/golden-format.md) and how well they discriminate
// (verify/discrimination.h, docs/golden-discrimination.md).
//   update [--size] [--dir] [--emit-jobs FILE | --collect]   every deterministic scene x camera
//   make SCENE [--camera --time --size] -o DIR [--emit-jobs FILE] | make --collect -o DIR
//   job DIR NAME PART                                        one render of a plan (what --emit-jobs lines run)
//   discriminate [DIR] [--only ...] [--golden ...] [--markdown FILE]  correct candidates and mutants against a golden set
//
// Wiring into the main program (tools/refray.cpp):
//     refray::tools::GoldenCommandOptions goldenOptions;
//     CLI::App* golden = refray::tools::addGoldenCommand(app, goldenOptions);
//     ...after app.parse(argc, argv):
//     if (*golden) return refray::tools::runGolden(goldenOptions);
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace refray::tools {

struct GoldenCommandOptions {
    std::string repositoryRoot = ".";
    bool warningsAsErrors = false;  // --warnings-as-errors (update, make, job)
    struct {
        std::string dir = "tests/golden", size = "320x180", emitJobs;
        uint32_t orders = 4, threads = 0, perturbed = 8;
        bool collect = false;
    } update;
    struct {
        std::string scene, camera, time, size = "320x180", dir, emitJobs;
        uint32_t orders = 4, threads = 0, perturbed = 8;
        bool collect = false;
    } make;
    struct {
        std::string dir, name, part;
        uint32_t threads = 0;
    } job;
    struct {
        std::string goldenDirectory = "tests/golden";
        std::string fmaRefray;  // empty: refray-fma beside this binary, if there is one
        std::vector<std::string> only;
        std::vector<std::string> goldens;  // --golden: judge only these goldens
        std::string markdown;
        uint32_t threads = 0;
    } discriminate;
    // Which subcommand the parse chose.
    CLI::App *updateCommand = nullptr, *makeCommand = nullptr, *jobCommand = nullptr, *discriminateCommand = nullptr;
};

// Adds `golden` and its subcommands to `app`; app.parse() fills `options`, which must outlive the parse.
CLI::App* addGoldenCommand(CLI::App& app, GoldenCommandOptions& options);

// Exit status 0; for discriminate 0 when every correct candidate passes and every mutant fails, 1 when some mutant
// is not caught, 2 on a false alarm. Errors throw refray::Error (exit 2 from the main program).
int runGolden(const GoldenCommandOptions& options);

}  // namespace refray::tools
