// The golden set: one envelope golden (core/envelope.h, docs/golden-format.md) per scene file x camera at a small
// size, with the settings that made it, listed in a manifest (tests/golden/goldens.json). An envelope is made of the
// nominal render, K perturbed renders (legal GPUs of the variation model, docs/numerical-variation.md), a
// double-precision render and the adversarial traversal orders of the order check. `refray golden update` writes
// them, `refray golden make` one of them for any scene and settings; the golden CTest re-renders each entry and
// judges it against its envelope.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/envelope.h"
#include "core/statistical_compare.h"
#include "verify/order_check.h"
#include "scenes/scene.h"

namespace refray::scenes {

inline constexpr std::string_view kGoldenFormat = "refray-goldens/2";

// The perturbed renders of an envelope golden: seeds 1..K, the default.
inline constexpr uint32_t kDefaultPerturbedRenders = 8;

struct GoldenEntry {
    std::string name;         // "<scene name>.<camera>"
    std::string scene;        // scene file, relative to the repository root
    std::string sceneSha256;  // of the scene file when the golden was made
    std::string camera;
    std::string time;  // as the scene file writes its default time
    std::string precision = "float";
    uint32_t spp = 1;
    uint32_t width = 0, height = 0;
    std::string envelope;  // the envelope EXR, relative to the manifest
    uint32_t orders = 0;   // adversarial orders of the order check (seeds 1..orders)
    uint64_t orderDependentPixels = 0;
    uint32_t perturbedRenders = kDefaultPerturbedRenders;  // K: seeds 1..K, see goldenPerturbation
    uint64_t sensitivePixels = 0;
    std::string variationModel;  // procedural::kVariationModel when made
    std::string refrayCommit;
};

// The legal GPU of perturbed render `seed` (1..K): the contraction cycles mixed, split, fuse and the denormals
// alternate flush (odd seeds) and preserve (even seeds), so K >= 6 covers every combination.
procedural::Perturbation goldenPerturbation(uint32_t seed);

// A statistical golden (docs/compare.md, "The Cornell box golden"): for a scene whose shaders sample at random
// (ShaderLibraryBinding::samplesInShader), a statistics image (core/statistical_compare.h) of `batches` renders with
// seeds seed .. seed + batches - 1 at `spp`; a test re-renders it with other seeds and compares statistically.
struct StatisticalGoldenEntry {
    std::string name;         // "<scene name>.<camera>"
    std::string scene;        // scene file, relative to the repository root
    std::string sceneSha256;  // of the scene file when the golden was made
    std::string camera;
    uint32_t width = 0, height = 0;
    uint32_t spp = 1;
    uint32_t batches = 2;
    uint32_t seed = 0;   // the first batch's
    std::string image;   // statistics EXR, relative to the manifest
    std::string refrayCommit;
};

struct GoldenSet {
    std::vector<GoldenEntry> entries;  // threshold goldens: every camera of every deterministic scene file
    std::vector<StatisticalGoldenEntry> statistical;
};

// Throws refray::Error naming the file for a manifest of another format (an older refray's: "remake it with
// 'refray golden update'") or a malformed one.
GoldenSet readGoldenManifest(const std::filesystem::path& manifest);
void writeGoldenManifest(const std::filesystem::path& manifest, const GoldenSet& set);

// The settings a golden entry was made with (threads as given).
RenderSettings goldenSettings(const GoldenEntry& entry, uint32_t threads);
// The settings of batch `batch` of a statistical golden, seeded `firstSeed` + batch (entry.seed for the golden itself).
RenderSettings goldenSettings(const StatisticalGoldenEntry& entry, uint32_t firstSeed, uint32_t batch,
                              uint32_t threads);
// Whether a scene's renders are Monte Carlo estimates (its library samples at random), so that it gets statistical
// goldens, not threshold ones.
bool isMonteCarlo(const SceneDesc& scene);

// The statistics image of `batches` renders of a statistical golden's scene and camera with seeds firstSeed,
// firstSeed + 1, ... (the golden itself: entry.batches from entry.seed).
StatisticsImage renderStatistics(Scene& scene, const StatisticalGoldenEntry& entry, uint32_t firstSeed,
                                 uint32_t batches, uint32_t threads);

struct EnvelopeRenderOptions {
    uint32_t threads = 0;
    // After each render: what it was ("nominal", "perturbed seed 3", "double", "order 2") and its seconds.
    std::function<void(const std::string& what, double seconds)> onRender;
};

// Called once per scene built (makeGolden, updateGoldens, runGoldenJob) with its build warnings
// (Scene::buildWarnings), for the command line to show; may throw to stop.
using SceneBuiltCallback = std::function<void(const Scene&)>;

// Renders the envelope of a golden entry's settings: the nominal render, entry.perturbedRenders perturbed ones
// (goldenPerturbation(1..K)), one with --precision double and entry.orders adversarial orders (the order mask); fills
// entry.orderDependentPixels and entry.sensitivePixels; the provenance names the settings, seeds, commit, variation
// model, scene SHA-256 and the seconds each kind of render took.
Envelope renderEnvelope(Scene& scene, GoldenEntry& entry, const EnvelopeRenderOptions& options);

// The renders an envelope is made of, each independent of the others: "nominal", "order-1".."order-N" (adversarial
// orders), "perturbed-1".."perturbed-K", "double" and "objects" (the nominal's object map for the regional count
// test, verify/object_map.h, as an image), with their settings.
struct EnvelopePart {
    std::string name;
    RenderSettings settings;
};
std::vector<EnvelopePart> envelopeParts(const GoldenEntry& entry, uint32_t threads);
// Renders one part. A perturbed part k is the legal GPU of seed k; where that GPU's arithmetic reaches undefined
// behaviour (a dxr::DxrError: e.g. acos of a quotient 2.5 ulp above 1 gives NaN, and a ray with a NaN direction is
// UB, RAY-5) the part takes seed k + 100, then k + 200, ... (kPerturbedSeedAttempts in all; the image's metadata
// golden_part_seed names the seed used). Deterministic: the same part always gets the same seed.
inline constexpr uint32_t kPerturbedSeedStride = 100, kPerturbedSeedAttempts = 5;
Image renderEnvelopePart(Scene& scene, const EnvelopePart& part);
// The envelope of the parts' renders (by part name; seconds by part name, for the provenance): what renderEnvelope
// does after rendering. Throws refray::Error naming a missing part or one of another size.
Envelope assembleEnvelope(GoldenEntry& entry, const std::map<std::string, Image>& renders,
                          const std::map<std::string, double>& seconds);

// `refray golden make`: the envelope golden of one scene file, camera, time and size, written as
// <directory>/<scene name>.<camera>.envelope.exr and added to (or replaced in) <directory>/goldens.json.
struct GoldenMakeOptions {
    std::filesystem::path sceneFile;
    std::filesystem::path repositoryRoot = ".";  // the manifest names the scene relative to it where it lies inside
    std::filesystem::path goldenDirectory;
    std::string camera;  // empty: the scene's first camera
    std::string time;    // empty: the scene's default time
    uint32_t width = 320, height = 180;
    uint32_t orders = 4;
    uint32_t perturbedRenders = kDefaultPerturbedRenders;
    std::string refrayCommit;
    EnvelopeRenderOptions render;
    SceneBuiltCallback onSceneBuilt;
};
GoldenEntry makeGolden(const GoldenMakeOptions& options);

struct GoldenUpdateOptions {
    std::filesystem::path repositoryRoot;  // scene paths are relative to it
    std::filesystem::path goldenDirectory;
    uint32_t width = 320, height = 180;
    uint32_t orders = 4;
    uint32_t perturbedRenders = kDefaultPerturbedRenders;
    uint32_t threads = 0;
    std::string refrayCommit;
    std::function<void(const std::string& what, double seconds)> onRender;  // each render of each envelope
    std::function<void(const GoldenEntry&, double seconds)> onEntry;  // after each entry is written
    std::function<void(const StatisticalGoldenEntry&, double seconds)> onStatisticalEntry;
    SceneBuiltCallback onSceneBuilt;
};

// Renders the envelope of every top-level scenes/*.json x camera at the scene's default time, writes
// <name>.envelope.exr and goldens.json into goldenDirectory, and returns the set. Monte Carlo scenes
// (isMonteCarlo) get no threshold golden: the statistical entries of the existing manifest are kept, each
// re-rendered with its own settings (size, spp, batches, seed; `width`/`height` above do not apply).
GoldenSet updateGoldens(const GoldenUpdateOptions& options);

// The entries updateGoldens and makeGolden would make, without rendering.
std::vector<GoldenEntry> planUpdate(const GoldenUpdateOptions& options);
GoldenEntry planMake(const GoldenMakeOptions& options);

// The distributed form (--emit-jobs, --collect; README "Goldens on a cluster"). Every render of an envelope is one
// job: writeGoldenPlan stores the entries in <dir>/jobs/plan.json (and whether they are an update, which replaces
// the set's envelope entries, or a make, which adds to them); goldenJobCommands gives one command line per render
// ("REFRAY golden job DIR NAME PART"); runGoldenJob renders one into <dir>/jobs/<name>/<part>.exr; collectGoldens
// assembles the envelopes and the manifest from them, bit-identical to the in-process run but for the
// render_seconds_* provenance. Statistical goldens are not planned: an update keeps them as they are.
//
// Every plan has an id (<dir>/jobs/plan-id, random); each job's render carries it with the golden's name, the part and
// the plan's settings for that golden (scene SHA-256, camera, time, size, precision, spp, orders, K), and
// collectGoldens refuses, by name, a render that does not carry exactly those: a stale render of an earlier plan or a
// foreign file dropped into jobs/. writeGoldenPlan refuses (refray::Error naming the folder and the plan there) to
// plan into a folder whose jobs/ holds a different plan, so that two plans' renders never mix; the same plan again
// keeps its id and its finished renders. Returns the plan id.
std::string writeGoldenPlan(const std::filesystem::path& goldenDirectory, const std::vector<GoldenEntry>& entries,
                            bool update);
std::vector<std::string> goldenJobCommands(const std::filesystem::path& goldenDirectory,
                                           const std::filesystem::path& repositoryRoot, const std::string& refray);
void runGoldenJob(const std::filesystem::path& goldenDirectory, const std::filesystem::path& repositoryRoot,
                  const std::string& name, const std::string& part, uint32_t threads,
                  const SceneBuiltCallback& onSceneBuilt = {});
// Throws refray::Error listing the missing renders (and the lines that make them) before writing anything; on success
// removes <dir>/jobs.
GoldenSet collectGoldens(const std::filesystem::path& goldenDirectory,
                         const std::function<void(const GoldenEntry&)>& onEntry);

}  // namespace refray::scenes
