// `refray compare REFERENCE CANDIDATE`: a render against a golden image, with idiff's
// verdicts and exit codes, FLIP, a diff heat map and a self-contained HTML report.
// `refray compare --statistical REF.exr TEST.exr`: two statistics images of noisy renders
// (core/statistical_compare.h) by a per-pixel Welch t-test. docs/compare.md is the user's guide.
//
// Wiring into the main program (tools/refray.cpp):
//     refray::tools::CompareCommandOptions compareOptions;
//     CLI::App* compare = refray::tools::addCompareCommand(app, compareOptions);
//     ...after app.parse(argc, argv):
//     if (*compare) return refray::tools::runCompare(compareOptions);
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/compare.h"
#include "core/envelope.h"
#include "core/image.h"

namespace refray::tools {

// What the command line asks for. After parsing, `thresholds` holds the thresholds to
// use: --golden's profile with any explicitly given threshold option on top.
struct CompareCommandOptions {
    std::string reference, candidate;
    std::string diffPath, htmlPath, maskPath;
    std::string channels = "rgb";  // "rgb" or "rgba"
    std::string diffMode = "flip";  // "flip" or "abs"
    float diffScale = 1.0f;
    double pixelsPerDegree = kFlipDefaultPixelsPerDegree;
    bool golden = false;
    CompareThresholds thresholds;

    // --golden DIR-or-envelope.exr: an envelope golden (docs/compare.md, "Envelope goldens"); a plain image there
    // is the reference of the threshold comparison under --golden's profile (the older form).
    std::string goldenPath;
    // --golden-set DIR CANDIDATES_DIR: every golden of DIR's manifest against CANDIDATES_DIR/<name>.exr or .png.
    std::string goldenSet;
    std::string junitPath;  // --junit: JUnit XML of the --golden-set verdicts
    EnvelopeJudgeOptions envelope;

    // --statistical: REFERENCE and CANDIDATE are statistics images (mean and variance).
    bool statistical = false;
    double alpha = 0.01;                // --alpha: false-alarm probability for the whole image
    std::string correction = "sidak";   // --correction: "sidak" or "bonferroni"
    std::string mapPath;                // --map: the failure map (PNG)
};

// Adds the `compare` subcommand to `app`; app.parse() fills `options`, which must
// outlive the parse.
CLI::App* addCompareCommand(CLI::App& app, CompareCommandOptions& options);

// Runs the comparison: the report goes to stdout, errors to stderr. Returns idiff's
// exit code: 0 pass, 1 warning, 2 failure, 3 size mismatch, 4 file error (a file that
// cannot be read or written, or with --statistical one that is no statistics image; the
// message names it). Throws nothing.
int runCompare(const CompareCommandOptions& options);

// One row of an HTML report: the images shown and the comparison's result. The
// pointers must stay valid while writeCompareReport runs.
struct CompareReportRow {
    std::string referencePath, candidatePath;
    const Image* reference = nullptr;
    const Image* candidate = nullptr;
    const CompareResult* result = nullptr;
    bool matched = false;  // the row the overall verdict comes from
    // Instead of `result`: an envelope judgement (reference: the nominal image, diff: its heat map), or, with
    // neither, `missing` says why there is no candidate (a failing row).
    const EnvelopeJudgement* envelope = nullptr;
    std::string missing;
};

// Writes one self-contained HTML page (images inline as PNG data URIs): a row per
// comparison with reference, candidate (hover shows the reference in its place) and
// diff side by side, then the numbers; failing rows first. Throws refray::Error naming
// `path` when it cannot be written.
void writeCompareReport(const std::string& path, CompareVerdict overall, const std::string& summary,
                        std::vector<CompareReportRow> rows);

}  // namespace refray::tools
