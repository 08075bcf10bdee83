// Small pieces the refray subcommands share: option parsing, parse errors and the terminal progress bar.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/image.h"
#include "core/progress.h"
#include "core/text_file.h"  // writeTextFile, which the commands use
#include "emulator/validation.h"

namespace refray::tools {

struct Size {
    uint32_t width = 640, height = 360;
};

// "WIDTHxHEIGHT" within 1x1 .. 16384x16384; throws refray::Error naming the option otherwise.
Size parseSize(const std::string& text, const char* option = "--size");
// "X,Y": two non-negative integers; throws refray::Error naming the option otherwise.
void parsePixel(const std::string& text, uint32_t& x, uint32_t& y, const char* option = "--pixel");

// CLI11 validators whose failure says what the option accepts: "--spp: expects a positive integer ..., got '-4'"
// (CLI11's own conversion errors only say "Could not convert").
// A whole number (digits only: no sign, fraction or exponent) from `min` to `max`.
CLI::Validator wholeNumber(const std::string& accepts, uint64_t min = 0,
                           uint64_t max = std::numeric_limits<uint32_t>::max());
// A number as strtod reads it ("inf" included, NaN never) for which `inRange` holds.
CLI::Validator number(const std::string& accepts, const std::function<bool(double)>& inRange);
// One of `names`, with a "did you mean" for a near miss.
CLI::Validator oneOf(const std::vector<std::string>& names);
// What --threads and --time accept in every command that has them.
CLI::Validator threadCount();
CLI::Validator seconds();

// The exit status of a CLI11 parse error, after printing it: --help and --version print to stdout and give 0; every
// other error (an unknown option, a value an option does not accept, a missing or an extra argument) prints
// "refray SUBCOMMAND: what is wrong (see 'refray SUBCOMMAND --help')" to stderr and gives 2, bad input's status.
int parseErrorStatus(const CLI::App& app, const CLI::ParseError& error);

// A file a command reads or writes, with how the user named it: {"-o", "out.png"}, {"the scene file", "a.json"}.
struct NamedPath {
    std::string role;
    std::string path;
};

// Before any work: refuses (refray::Error, exit 2) an output that is one of the inputs or another output (through
// links, "..", hard links), naming both, and an output that cannot become a file (core/file_output.h's
// checkOutputPath: a file where its folder should be, a directory or device in its place). Empty paths are skipped.
void checkOutputs(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

// Prints a scene's build warnings (scenes::Scene::buildWarnings: rule id, scene file:line) to stderr, once each, as
// "refray COMMAND: warning DEGEN-8: ..."; with `asErrors` (--warnings-as-errors) then throws refray::Error (exit 2).
void reportBuildWarnings(const std::string& command, const std::vector<dxr::Diagnostic>& warnings, bool asErrors);
// The option every command that builds a scene takes.
inline constexpr const char* kWarningsAsErrorsHelp =
    "Treat the scene's build warnings (inverted AABBs, singular instance transforms, ...) as errors: exit 2";

// The largest --threads a command takes: the hardware threads of this machine (more cannot run at once, and the
// metadata would record threads that never ran).
uint32_t maxThreads();
// What --threads 0 ("all") or N really runs.
uint32_t threadsRun(uint32_t requested);

// A progress bar on stderr when it is a terminal; an empty sink otherwise.
Progress::Sink terminalProgress();
// Writes `image`, creating the parent directory.
void writeOutput(const std::string& path, const Image& image);

// The image as a PNG data URI (the bytes an R8G8B8A8_UNORM target holds), for self-contained HTML pages.
std::string pngDataURI(const Image& image);

}  // namespace refray::tools
