// How well envelope goldens discriminate (issue 17, docs/golden-discrimination.md): for every golden of a set,
// correct candidates the envelope was not made from (other perturbation seeds, double precision, other adversarial
// orders, refray built with fused multiply-add contraction) must pass, and mutants -- bugs a GPU back end makes,
// each a scene-file patch, a shader constant (knob), a render setting or an output-stage error -- should fail.
//
//     DiscriminationOptions o;
//     o.goldenDirectory = "tests/golden";
//     for (const DiscriminationRow& row : runDiscrimination(o)) ...
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/envelope.h"

namespace refray::scenes {

enum class CandidateKind { Correct, Mutant };

struct DiscriminationCandidate {
    std::string name;   // "perturbed-seed-9", "diffuse-2pc", ...
    CandidateKind kind = CandidateKind::Mutant;
    std::string what;   // one line: what it is / which bug it plays
    std::string how;    // how it is made: "knob julia-iterations=150", "scene patch: ...", "image: ..."
};

// Every candidate, correct ones first. A candidate that does not apply to a golden's scene (a Julia knob on the
// D3D12 scene still renders: it is then identical to the nominal, which the report says) is never skipped.
const std::vector<DiscriminationCandidate>& discriminationCandidates();

struct DiscriminationOptions {
    std::filesystem::path goldenDirectory;       // a golden set (goldens.json and its envelopes)
    std::filesystem::path repositoryRoot = ".";  // the manifest's scene paths are relative to it
    uint32_t threads = 0;
    // refray built with FMA contraction of the shader libraries (the refray-fma target); empty: that candidate is
    // reported as not run, with the reason.
    std::filesystem::path fusedRefray;
    // refray built with the Vulkan back end, for the 'lavapipe' candidate (Mesa's lavapipe, a CPU Vulkan driver,
    // runs its GLSL ports); empty, or no lavapipe on the machine: that candidate is reported as not run.
    std::filesystem::path vulkanRefray;
    std::vector<std::string> only;     // candidate names to run; empty: all
    std::vector<std::string> goldens;  // golden names to judge; empty: all
    std::function<void(const struct DiscriminationRow&)> onRow;  // after each judgement (progress)
};

struct DiscriminationRow {
    std::string golden;  // the golden's name
    DiscriminationCandidate candidate;
    bool ran = false;
    bool unavailable = false;  // not run: the tool the candidate needs is missing (`error` says which)
    std::string error;   // why it did not run, or the render's error (a mutant that cannot render at all)
    std::string note;    // how it ran where that differs from the candidate's recipe
    EnvelopeJudgement judgement;  // heat map and pixel list dropped
    // Against the nominal render: pixels where some channel differs by more than one UNORM8 step, by the golden's
    // class (order-dependent pixels apart). 0 everywhere: no image test can see this candidate.
    uint64_t changedStable = 0, changedSensitive = 0, changedOrder = 0;
    double seconds = 0;
};

// Renders and judges every candidate against every golden of the set (threshold goldens; the statistical ones are
// not envelopes). Throws refray::Error for an unreadable golden set.
std::vector<DiscriminationRow> runDiscrimination(const DiscriminationOptions& options);

// What a row's outcome is called in the report: "pass", "WARNING", "FAILURE" (caught), "not run", "render error".
std::string outcomeName(const DiscriminationRow& row);
// Whether the outcome is what the candidate's kind asks: a correct candidate not failing, a mutant failing or not
// rendering at all.
bool outcomeAsExpected(const DiscriminationRow& row);

// The Markdown tables of docs/golden-discrimination.md: a summary (false alarms, catches, misses) and one row per
// candidate and golden.
std::string discriminationMarkdown(const std::vector<DiscriminationRow>& rows);

}  // namespace refray::scenes
