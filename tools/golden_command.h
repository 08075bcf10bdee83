// `refray golden discriminate DIR`: how well a golden set tells correct renders from buggy ones
// (verify/discrimination.h, docs/golden-discrimination.md). Prints one line per candidate and golden as it goes,
// then the summary; --markdown writes the tables of the doc.
//
// Wiring into the main program (tools/refray.cpp), under the `golden` subcommand:
//     refray::tools::DiscriminateCommandOptions discriminateOptions;
//     CLI::App* discriminate = refray::tools::addDiscriminateCommand(*golden, discriminateOptions);
//     ...after app.parse(argc, argv):
//     if (*discriminate) return refray::tools::runDiscriminate(discriminateOptions);
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace refray::tools {

struct DiscriminateCommandOptions {
    std::string goldenDirectory = "tests/golden";
    std::string repositoryRoot = ".";
    std::string fmaRefray;  // empty: refray-fma beside this binary, if there is one
    std::vector<std::string> only;
    std::string markdown;
    uint32_t threads = 0;
};

CLI::App* addDiscriminateCommand(CLI::App& golden, DiscriminateCommandOptions& options);

// Exit status: 0 when every correct candidate passes and every mutant fails, 1 when some mutant is not caught,
// 2 when a correct candidate fails (a false alarm). Errors throw refray::Error (exit 2 from the main program).
int runDiscriminate(const DiscriminateCommandOptions& options);

}  // namespace refray::tools
