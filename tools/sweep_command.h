// `refray sweep SCENE --knob NAME=v1,v2,... [--knob ...]`: what accuracy costs in time (study/sweep.h). Renders
// every knob value, times it, compares it with a high-accuracy reference and writes a CSV, a markdown report and
// plots into the output directory. --emit-jobs writes one command line per setting for a job runner (GNU parallel,
// a Slurm array) instead of rendering; --collect DIR merges what those jobs wrote into the same report.
//
// Wiring into the main program (tools/refray.cpp):
//     refray::tools::SweepCommandOptions sweepOptions;
//     CLI::App* sweep = refray::tools::addSweepCommand(app, sweepOptions);
//     ...after app.parse(argc, argv):
//     if (*sweep) return refray::tools::runSweep(sweepOptions);
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace refray::tools {

struct SweepCommandOptions {
    std::string scene;
    std::string camera;
    std::string size = "320x180";
    std::optional<float> time;
    uint32_t threads = 0;
    uint32_t repeats = 3;
    std::vector<std::string> knobs;  // "name=v1,v2,..."
    std::string reference;           // empty: scenes::kDefaultSweepReference
    std::string output = "sweep";
    std::string emitJobs;  // a file: plan only, write the job lines there
    std::string collect;   // a sweep directory: report only
    std::string job;       // a run id: render that one setting of the plan in --output
    bool goldenSearch = false;  // after the runs (or with --collect), search for the cheapest passing settings
};

// Adds the `sweep` subcommand to `app`; app.parse() fills `options`, which must outlive the parse.
CLI::App* addSweepCommand(CLI::App& app, SweepCommandOptions& options);

// Exit status 0; errors throw refray::Error (the main program prints them, exit 2).
int runSweep(const SweepCommandOptions& options);

}  // namespace refray::tools
