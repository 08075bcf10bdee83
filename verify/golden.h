// The golden set: one EXR per scene file x camera at a small size, each with its order-dependence mask and the
// settings that made it, listed in a manifest (tests/golden/goldens.json). `refray golden update` writes them; the
// golden CTest re-renders each entry and compares with the shared comparator (core/compare.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/statistical_compare.h"
#include "verify/order_check.h"
#include "scenes/scene.h"

namespace refray::scenes {

inline constexpr std::string_view kGoldenFormat = "refray-goldens/1";

struct GoldenEntry {
    std::string name;         // "<scene name>.<camera>"
    std::string scene;        // scene file, relative to the repository root
    std::string sceneSha256;  // of the scene file when the golden was made
    std::string camera;
    std::string time;  // as the scene file writes its default time
    std::string precision = "float";
    uint32_t spp = 1;
    uint32_t width = 0, height = 0;
    std::string image;  // EXR, relative to the manifest
    std::string mask;   // PNG, relative to the manifest
    uint32_t orders = 0;  // adversarial orders of the order check
    uint64_t orderDependentPixels = 0;
    std::string refrayCommit;
};

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

struct GoldenUpdateOptions {
    std::filesystem::path repositoryRoot;  // scene paths are relative to it
    std::filesystem::path goldenDirectory;
    uint32_t width = 320, height = 180;
    uint32_t orders = 4;
    uint32_t threads = 0;
    std::string refrayCommit;
    std::function<void(const GoldenEntry&, double seconds)> onEntry;  // after each entry is written
    std::function<void(const StatisticalGoldenEntry&, double seconds)> onStatisticalEntry;
};

// Renders every top-level scenes/*.json x camera at the scene's default time, with an order check, writes
// <name>.exr, <name>.order-mask.png and goldens.json into goldenDirectory, and returns the set. Monte Carlo scenes
// (isMonteCarlo) get no threshold golden: the statistical entries of the existing manifest are kept, each
// re-rendered with its own settings (size, spp, batches, seed; `width`/`height` above do not apply).
GoldenSet updateGoldens(const GoldenUpdateOptions& options);

}  // namespace refray::scenes
