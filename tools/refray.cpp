// refray: the command line. Only this layer prints and exits.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "core/file_output.h"
#include "core/image.h"
#include "core/json_writer.h"
#include "core/statistical_compare.h"
#include "core/strings.h"
#include "emulator/validation.h"
#include "procedural/perturbation.h"
#include "procedural/precision.h"
#include "scenes/builtin_scene.h"
#include "scenes/effects.h"
#include "verify/golden.h"
#include "tools/golden_command.h"
#include "inspect/index_map.h"
#include "scenes/knobs.h"
#include "verify/order_check.h"
#include "scenes/scene.h"
#include "tools/cli_common.h"
#include "tools/compare_command.h"
#include "tools/explain_command.h"
#include "tools/render_device.h"
#include "tools/sweep_command.h"
#include "tools/table_command.h"
#include "tools/version.h"

namespace {

using namespace refray;

using tools::parseSize;
using tools::Size;
using tools::terminalProgress;
using tools::writeOutput;

// --stats: the lines below "render:" are indented, one block per measure (docs/emulator.md shows an example).
void printStats(const scenes::RenderResult& r, const Size& size) {
    const dxr::DispatchStats& st = r.dispatch.stats;
    const auto u = [](uint64_t v) { return (unsigned long long)v; };
    std::printf("render: %ux%u in %.3f s, %llu rays (%.0f rays/s)", size.width, size.height, r.dispatch.seconds,
                u(st.raysTraced), r.dispatch.seconds > 0 ? double(st.raysTraced) / r.dispatch.seconds : 0.0);
    if (st.rayQueries)
        std::printf(", %llu ray queries (%.0f/s)", u(st.rayQueries),
                    r.dispatch.seconds > 0 ? double(st.rayQueries) / r.dispatch.seconds : 0.0);
    std::printf("\n");
    for (size_t d = 1; d < st.raysPerDepth.size(); ++d) std::printf("  rays at depth %zu: %llu\n", d, u(st.raysPerDepth[d]));

    // Ray types x depth.
    std::printf("  rays per type (R = RayContributionToHitGroupIndex & 0xF, miss = MissShaderIndex) and depth:\n");
    std::printf("    %-16s %12s", "type", "total");
    for (size_t d = 1; d < st.raysPerDepth.size(); ++d) std::printf(" %12s", ("depth " + std::to_string(d)).c_str());
    std::printf("\n");
    for (const dxr::RayTypeCounts& t : st.raysPerType) {
        std::printf("    %-16s %12llu", dxr::toString(t.key).c_str(), u(t.total()));
        for (size_t d = 1; d < st.raysPerDepth.size(); ++d)
            std::printf(" %12llu", u(d < t.raysPerDepth.size() ? t.raysPerDepth[d] : 0));
        std::printf("\n");
    }

    // Invocations per stage, then per export.
    for (size_t s = 0; s < st.invocations.size(); ++s)
        if (st.invocations[s])
            std::printf("  %s invocations: %llu\n", std::string(dxr::toString(dxr::ShaderStage(s))).c_str(), u(st.invocations[s]));
    std::printf("  invocations per export:\n");
    for (const dxr::ExportInvocations& e : st.invocationsPerExport)
        std::printf("    %-13s %s: %llu\n", std::string(dxr::toString(e.stage)).c_str(), e.exportName.c_str(), u(e.count));
    std::printf("  candidates gathered: %llu\n", u(st.candidates));
    if (st.rayQueries)
        std::printf("  ray queries (TraceRayInline): %llu; candidates handed to the shader (Proceed() TRUE): %llu; "
                    "commits: %llu\n",
                    u(st.rayQueries), u(st.queryCandidates), u(st.queryCommits));
    std::printf("  rays per traversal mode: %llu every candidate, %llu bounded by the nearest sure commit, %llu "
                "occlusion query\n",
                u(st.raysPerGatherMode[0]), u(st.raysPerGatherMode[1]), u(st.raysPerGatherMode[2]));

    // Exclusive time per stage.
    const double total = st.profiledSeconds();
    if (!st.stagesProfiled) {
        std::printf("  time per stage: not measured\n");
        return;
    }
    std::printf("  time per stage (exclusive, summed over worker threads): %.3f s\n", total);
    for (size_t i = 0; i < dxr::kProfileStageCount; ++i) {
        const auto stage = dxr::ProfileStage(i);
        const bool ran = stage == dxr::ProfileStage::Traversal ? st.raysTraced > 0
                         : stage == dxr::ProfileStage::Compute ? st.invocationsOf(dxr::ShaderStage::Compute) > 0
                                                               : st.invocations[i] > 0;
        if (!ran) continue;
        std::printf("    %-13s %10.3f s %6.1f%%\n", std::string(dxr::toString(stage)).c_str(), st.secondsIn(stage),
                    total > 0 ? 100.0 * st.secondsIn(stage) / total : 0.0);
    }
}

// --stats-json: the same measures as printStats, as a "refray-stats/1" document; `effects` is empty for the
// built-in scene.
std::string statsJson(const scenes::RenderResult& r, const std::string& scene, const Size& size,
                      const std::vector<scenes::Effect>& effects) {
    const dxr::DispatchStats& st = r.dispatch.stats;
    json::Writer w;
    const auto perDepth = [&w](const std::vector<uint64_t>& rays) {
        w.beginArray(json::Writer::Layout::Inline);
        for (size_t d = 1; d < rays.size(); ++d)
            w.beginObject(json::Writer::Layout::Inline).member("depth", d).member("rays", rays[d]).endObject();
        w.endArray();
    };
    w.beginObject();
    w.member("format", "refray-stats/1").member("scene", scene).member("width", size.width).member("height", size.height);
    w.member("wallSeconds", r.dispatch.seconds).member("raysTraced", st.raysTraced);
    w.member("raysPerSecond", r.dispatch.seconds > 0 ? double(st.raysTraced) / r.dispatch.seconds : 0.0);
    w.member("candidates", st.candidates).member("rayQueries", st.rayQueries);
    w.member("rayQueryCandidates", st.queryCandidates).member("rayQueryCommits", st.queryCommits);
    w.key("raysPerTraversalMode")
        .beginObject(json::Writer::Layout::Inline)
        .member("all", st.raysPerGatherMode[0])
        .member("closest", st.raysPerGatherMode[1])
        .member("firstHit", st.raysPerGatherMode[2])
        .endObject();
    w.key("raysPerDepth");
    perDepth(st.raysPerDepth);
    w.key("rayTypes").beginArray();
    for (const dxr::RayTypeCounts& t : st.raysPerType) {
        w.beginObject(json::Writer::Layout::Inline)
            .member("rayContribution", t.key.rayContribution)
            .member("missShaderIndex", t.key.missShaderIndex)
            .member("rays", t.total())
            .key("raysPerDepth");
        perDepth(t.raysPerDepth);
        w.endObject();
    }
    w.endArray();
    w.key("invocations").beginObject(json::Writer::Layout::Inline);
    for (size_t i = 0; i < st.invocations.size(); ++i) w.member(dxr::toString(dxr::ShaderStage(i)), st.invocations[i]);
    w.endObject();
    w.key("invocationsPerExport").beginArray();
    for (const dxr::ExportInvocations& e : st.invocationsPerExport)
        w.beginObject(json::Writer::Layout::Inline)
            .member("export", e.exportName)
            .member("stage", dxr::toString(e.stage))
            .member("count", e.count)
            .endObject();
    w.endArray();
    const double total = st.profiledSeconds();
    w.key("stageTimes").beginObject();
    w.member("profiled", st.stagesProfiled).member("exclusiveSecondsSummedOverThreads", total);
    w.key("stages").beginArray();
    for (size_t i = 0; i < dxr::kProfileStageCount; ++i) {
        const auto stage = dxr::ProfileStage(i);
        w.beginObject(json::Writer::Layout::Inline)
            .member("stage", dxr::toString(stage))
            .member("seconds", st.secondsIn(stage))
            .member("share", total > 0 ? st.secondsIn(stage) / total : 0.0)
            .endObject();
    }
    w.endArray().endObject();
    w.key("effects").beginArray();
    for (const scenes::Effect& e : effects)
        w.beginObject(json::Writer::Layout::Inline).member("name", e.name).member("simulated", e.on).member("reason", e.reason).endObject();
    w.endArray();
    w.endObject();
    return w.text() + "\n";
}

struct RenderOptions {
    std::string scene;
    std::string output = "refray.png";
    std::string size;  // empty: the scene's image size
    uint32_t threads = 0;
    bool stats = false;
    std::string statsJson;  // --stats-json FILE
    bool noShortcuts = false;  // --no-shortcuts: DispatchOptions::specialise off
    uint32_t waveWidth = 32;   // --wave-width: DispatchOptions::waveWidth
    bool noStageTimes = false;  // --no-stage-times: --stats without DispatchOptions::profileStages
    std::string order = "ordered";
    uint64_t seed = 0;  // RenderSettings::seed (the first batch's) and the adversarial order's seed
    std::optional<uint32_t> batches;  // --batches K: a statistics image of K renders
    std::string camera;
    std::optional<float> time;
    std::string precision = "float";
    std::optional<uint64_t> perturb;  // --perturb SEED: RenderSettings::perturbation
    std::optional<std::string> perturbContraction, perturbDenormals;
    uint32_t spp = 1;
    uint32_t orderCheck = 0;
    std::string aov;
    std::vector<std::string> knobs;  // "name=value"
    std::string device = "cpu";      // --device: where DispatchRays runs (tools/render_device.h)
    std::string spirvDir;            // --spirv-dir
    std::string vulkanDevice;        // --vulkan-device
    bool warningsAsErrors = false;   // --warnings-as-errors
};

bool endsWithExr(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".exr";
}

// --aov: the index map with its legend beside it; the legend also goes to stdout.
// -o FILE.exr: the values themselves (scenes::indexValuesImage), for exact comparison.
void renderIndexMap(scenes::Scene& scene, const scenes::RenderSettings& settings, const RenderOptions& o,
                    const tools::RenderDevice& device) {
    const std::optional<scenes::IndexMapKind> kind = scenes::parseIndexMapKind(o.aov);
    REFRAY_CHECK(kind, "--aov expects one of " << joined(scenes::indexMapKindNames()) << ", got '" << o.aov << "'"
                                               << didYouMean(o.aov, scenes::indexMapKindNames()));
    REFRAY_CHECK(o.orderCheck == 0, "--aov and --order-check are separate renders; give one of them");
    const scenes::IndexMap map = tools::renderDeviceIndexMap(device, scene, settings, *kind);
    const std::string title = scene.desc().name + ": " + o.aov + " of each pixel's primary ray";
    bool drewText = true;
    Image image = endsWithExr(o.output) ? scenes::indexValuesImage(map) : scenes::withLegend(map, title, &drewText);
    image.metadata["refray_version"] = tools::kVersion;
    image.metadata["refray_commit"] = tools::kCommit;
    writeOutput(o.output, image);
    std::printf("%s\n", title.c_str());
    for (const scenes::IndexMapEntry& e : map.legend)
        std::printf("  #%02X%02X%02X  %6.2f%%  %s\n", floatToUnorm8(e.colour.r), floatToUnorm8(e.colour.g),
                    floatToUnorm8(e.colour.b), 100.0 * double(e.pixels) / double(map.values.size()), e.label.c_str());
    if (!drewText) std::fprintf(stderr, "refray: no font found (install fonts-dejavu-core): the legend is only printed above\n");
    std::printf("wrote %s\n", o.output.c_str());
}


// --batches K: renders K times with seeds S, S+1, ..., S+K-1 (a line per batch) and returns their statistics; `last`
// receives the last batch's render (for --stats).
StatisticsImage renderBatches(const std::function<scenes::RenderResult(const scenes::RenderSettings&)>& renderOnce,
                              scenes::RenderSettings settings, uint32_t batches, scenes::RenderResult& last) {
    StatisticsAccumulator accumulator;
    const uint32_t firstSeed = settings.seed;
    double seconds = 0.0;
    for (uint32_t k = 0; k < batches; ++k) {
        settings.seed = firstSeed + k;
        last = renderOnce(settings);
        accumulator.add(last.image);
        seconds += last.dispatch.seconds;
        std::printf("batch %u/%u (seed %u): %.3f s\n", k + 1, batches, settings.seed, last.dispatch.seconds);
        std::fflush(stdout);
    }
    StatisticsImage stats = accumulator.finish();
    stats.mean.metadata["seed"] = std::to_string(firstSeed);
    stats.mean.metadata["statistics_seeds"] = std::to_string(firstSeed) + ".." + std::to_string(firstSeed + batches - 1);
    stats.mean.metadata["render_seconds"] = std::to_string(seconds);
    return stats;
}

// --perturb SEED with its --perturb-contraction and --perturb-denormals; unset without --perturb.
std::optional<procedural::Perturbation> perturbationOf(const RenderOptions& o) {
    if (!o.perturb) {
        REFRAY_CHECK(!o.perturbContraction && !o.perturbDenormals,
                     "--perturb-contraction and --perturb-denormals shape a perturbed render: give them with --perturb "
                     "SEED");
        return std::nullopt;
    }
    procedural::Perturbation p;
    p.seed = *o.perturb;
    if (o.perturbContraction) {
        const std::optional<procedural::Contraction> c = procedural::parseContraction(*o.perturbContraction);
        REFRAY_CHECK(c, "--perturb-contraction expects 'split', 'fuse' or 'mixed', got '" << *o.perturbContraction
                                                                                            << "'");
        p.contraction = *c;
    }
    if (o.perturbDenormals) {
        const std::optional<procedural::Denormals> d = procedural::parseDenormals(*o.perturbDenormals);
        REFRAY_CHECK(d, "--perturb-denormals expects 'flush' or 'preserve', got '" << *o.perturbDenormals << "'");
        p.denormals = *d;
    }
    return p;
}

// The files a render reads that are not the scene file itself: its lesson bases are read with it; models and textures.
std::vector<tools::NamedPath> sceneInputs(const scenes::SceneDesc& desc) {
    std::vector<tools::NamedPath> inputs;
    for (const scenes::ModelDesc& m : desc.models) inputs.push_back({"model file", m.file.string()});
    for (const scenes::GlobalArgumentDesc& a : desc.globalArguments)
        for (const auto& e : a.table)
            if (e.isTexture && !e.texture.empty()) inputs.push_back({"texture", e.texture.string()});
    return inputs;
}

int runRender(const RenderOptions& o) {
    // Every output checked against the inputs and each other before anything is rendered.
    std::vector<tools::NamedPath> inputs;
    if (o.scene != "builtin") inputs.push_back({"scene file", o.scene});
    std::vector<tools::NamedPath> outputs{{"-o", o.output}, {"--stats-json", o.statsJson}};
    if (o.orderCheck > 0) outputs.push_back({"order mask (from -o)", scenes::orderMaskPath(o.output)});
    tools::checkOutputs(inputs, outputs);

    scenes::RenderSettings settings;
    settings.threads = o.threads;
    settings.adversarialSeed = o.seed;
    const uint32_t batches = o.batches.value_or(1);
    REFRAY_CHECK(!o.batches || *o.batches >= 2, "--batches needs at least 2 renders to estimate a variance, got "
                                                    << *o.batches);
    REFRAY_CHECK(o.seed <= 0xFFFFFFFFull - (batches - 1),
                 "--seed takes 0 .. 4294967295" << (o.batches ? " (less the batches after the first)" : "") << ", got "
                                                << o.seed);
    settings.seed = uint32_t(o.seed);
    if (o.batches) {
        REFRAY_CHECK(endsWithExr(o.output), "--batches writes a statistics image (the mean and variance of "
                                                << *o.batches << " renders), which needs OpenEXR: give -o a name "
                                                                 "ending in .exr, got '"
                                                << o.output << "'");
        REFRAY_CHECK(o.aov.empty() && o.orderCheck == 0,
                     "--batches renders the image K times for its statistics; --aov and --order-check are separate "
                     "renders: give them without --batches");
    }
    REFRAY_CHECK(o.order == "ordered" || o.order == "adversarial",
                 "--order expects 'ordered' or 'adversarial', got '" << o.order << "'");
    settings.order = o.order == "adversarial" ? dxr::TraversalOrder::Adversarial : dxr::TraversalOrder::Ordered;
    settings.progress = terminalProgress();
    settings.camera = o.camera;
    settings.time = o.time;
    const std::optional<procedural::Precision> precision = procedural::parsePrecision(o.precision);
    REFRAY_CHECK(precision, "--precision expects 'float' or 'double', got '" << o.precision << "'");
    settings.precision = *precision;
    settings.perturbation = perturbationOf(o);
    settings.spp = o.spp;
    for (const std::string& k : o.knobs) scenes::applyKnobAssignment(settings, k);
    settings.profileStages = (o.stats || !o.statsJson.empty()) && !o.noStageTimes;
    settings.specialise = !o.noShortcuts;
    settings.waveWidth = o.waveWidth;

    REFRAY_CHECK(o.device != "vulkan" || o.orderCheck == 0,
                 "--device vulkan renders in the GPU's own traversal order; --order-check needs the emulator's orders");
    tools::RenderDevice device;  // --device: set once the scene's shader library is known
    scenes::RenderResult result;
    std::optional<StatisticsImage> statistics;  // --batches
    scenes::EffectSet effectSet;
    std::vector<scenes::Effect> effects;  // of a scene file (the built-in scene has none to report)
    if (o.scene == "builtin") {
        REFRAY_CHECK(o.camera.empty() && !o.time && o.spp == 1 && o.precision == "float" && !o.perturb &&
                         o.orderCheck == 0 && o.aov.empty() && o.knobs.empty(),
                     "the built-in scene has one camera, no time, one sample per pixel and float shaders; "
                     "--camera, --time, --spp, --precision, --perturb, --knob, --order-check and --aov are for scene "
                     "files");
        const Size size = parseSize(o.size.empty() ? "640x360" : o.size);
        settings.width = size.width, settings.height = size.height;
        device = tools::useRenderDevice(o.device, "builtin", nullptr, o.spirvDir, o.vulkanDevice, settings);
        scenes::BuiltinScene scene;
        const auto renderOnce = [&](const scenes::RenderSettings& s) {
            scenes::RenderResult r = scene.render(s);
            r.image.metadata["scene"] = "builtin";
            r.image.metadata["size"] = std::to_string(size.width) + "x" + std::to_string(size.height);
            r.image.metadata["traversal_order"] = o.order;
            return r;
        };
        if (o.batches) statistics = renderBatches(renderOnce, settings, batches, result);
        else result = renderOnce(settings);
    } else {
        std::unique_ptr<scenes::Scene> scene = scenes::loadScene(o.scene);
        const std::vector<tools::NamedPath> read = sceneInputs(scene->desc());
        inputs.insert(inputs.end(), read.begin(), read.end());
        tools::checkOutputs(inputs, outputs);
        tools::reportBuildWarnings("render", scene->buildWarnings(), o.warningsAsErrors);
        effectSet = scenes::computeEffects(scene->desc(), settings);
        effects = effectSet.list();
        const Size size = o.size.empty() ? Size{scene->desc().defaultWidth, scene->desc().defaultHeight} : parseSize(o.size);
        settings.width = size.width, settings.height = size.height;
        device = tools::useRenderDevice(o.device, scene->desc().shaderLibrary, &scene->desc(), o.spirvDir,
                                        o.vulkanDevice, settings);
        if (!o.aov.empty()) {
            renderIndexMap(*scene, settings, o, device);
            return 0;
        }
        if (o.orderCheck > 0) {
            scenes::OrderCheckResult check = scenes::checkTraversalOrder(*scene, settings, o.orderCheck);
            result = std::move(check.ordered);
            const std::string mask = scenes::orderMaskPath(o.output);
            check.mask.metadata["refray_commit"] = tools::kCommit;
            writeOutput(mask, check.mask);
            std::printf("order check: %llu of %u pixels depend on the traversal order (ordered vs %u adversarial "
                        "orders); mask: %s\n",
                        (unsigned long long)check.orderDependentPixels, size.width * size.height, o.orderCheck,
                        mask.c_str());
        } else if (o.batches) {
            statistics = renderBatches([&](const scenes::RenderSettings& s) { return scene->render(s); }, settings,
                                       batches, result);
        } else {
            result = scene->render(settings);
        }
    }
    for (const auto& w : result.dispatch.diagnostics.warnings()) std::fprintf(stderr, "%s\n", w.format().c_str());
    // Notes: uses DXR defines that SPIR-V does not (RayQuery, docs/ray-query.md); they never fail a render.
    for (const auto& n : result.dispatch.diagnostics.notes()) std::fprintf(stderr, "%s\n", n.format().c_str());
    if (statistics) {
        statistics->mean.metadata["refray_version"] = tools::kVersion;
        statistics->mean.metadata["refray_commit"] = tools::kCommit;
        statistics->mean.metadata["threads"] = std::to_string(tools::threadsRun(o.threads));
        for (const auto& [key, value] : device.provenance) statistics->mean.metadata[key] = value;
        writeStatisticsImage(o.output, *statistics);
        const bool noVariance = std::all_of(statistics->varianceOfMean.begin(), statistics->varianceOfMean.end(),
                                            [](const vec3& v) { return v == vec3(0.0f); });
        if (noVariance)
            std::printf("note: the %u batches are identical (the scene samples nothing at random), so the variance is "
                        "0 everywhere: a statistical comparison against this file is an exact one\n",
                        statistics->batches);
    } else {
        result.image.metadata["refray_version"] = tools::kVersion;
        result.image.metadata["refray_commit"] = tools::kCommit;
        result.image.metadata["threads"] = std::to_string(tools::threadsRun(o.threads));
        result.image.metadata["render_seconds"] = std::to_string(result.dispatch.seconds);
        for (const auto& [key, value] : device.provenance) result.image.metadata[key] = value;
        writeOutput(o.output, result.image);
    }
    const Size renderedSize{result.image.width(), result.image.height()};
    if (o.stats) {
        if (statistics) std::printf("stats of the last batch (seed %u):\n", settings.seed + batches - 1);
        printStats(result, renderedSize);
        if (!effects.empty()) {
            std::printf("  effects:\n");
            std::istringstream lines(scenes::describeEffects(effectSet));
            for (std::string line; std::getline(lines, line);) std::printf("    %s\n", line.c_str());
        }
    }
    if (!o.statsJson.empty()) {
        writeTextFile(o.statsJson, statsJson(result, o.scene, renderedSize, effects));
        std::printf("wrote %s\n", o.statsJson.c_str());
    }
    std::printf("wrote %s\n", o.output.c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"refray: a CPU reference ray tracer with exact DirectX Raytracing semantics"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(refray::tools::kVersion) + " (" + refray::tools::kCommit + ")");

    auto* render = app.add_subcommand("render", "Render a scene file (or 'builtin') to an image (PNG or EXR)");
    RenderOptions ro;
    render->add_option("scene", ro.scene, "Scene file (e.g. scenes/proceduray-mandel-julia-pac.json), or 'builtin'")
        ->required();
    render->add_option("-o,--output", ro.output,
                       "Output image (.png: R8G8B8A8_UNORM as the GPU stores it; .exr: the floats the shaders wrote)")
        ->capture_default_str();
    render->add_option("--size", ro.size, "Image size WIDTHxHEIGHT (default: the scene's imageSize)");
    render->add_option("--camera", ro.camera, "Camera name (default: the scene's defaultCamera)");
    render->add_option("--time", ro.time, "Animation time in seconds (default: the scene's default time)")
        ->check(tools::seconds());
    render->add_option("--precision", ro.precision, "Shader math precision: float (the GPU's) or double")
        ->capture_default_str();
    render->add_option("--perturb", ro.perturb,
                       "Render as the GPU that SEED picks from the variation model (docs/numerical-variation.md): "
                       "every inexact float operation gets an error within the specs' bound; float precision only");
    render->add_option("--perturb-contraction", ro.perturbContraction,
                       "With --perturb: a*b+c computed split, fused, or mixed (each operation as the seed decides; "
                       "the default)");
    render->add_option("--perturb-denormals", ro.perturbDenormals,
                       "With --perturb: denormal floats flushed to zero (the default, as D3D11.3 requires) or "
                       "preserved (what DXIL's default denorm mode also allows)");
    render->add_option("--spp", ro.spp, "Samples per pixel: a square number (k x k pixel centres of a k-times larger "
                                        "dispatch, averaged); for dxr-path-tracer scenes any N (random paths per "
                                        "pixel, averaged by the shader)")
        ->check(tools::wholeNumber("a positive integer (a square number k*k; for the path tracer any N)", 1))
        ->capture_default_str();
    render->add_option("--knob", ro.knobs,
                       "An accuracy knob, NAME=VALUE (repeatable): steps, threshold, mandelbulb-iterations, "
                       "julia-iterations, normal-epsilon, metaball-steps, recursion-depth, spp, precision "
                       "(see 'refray sweep --help')");
    render->add_option("--threads", ro.threads, "Worker threads (0: all)")
        ->check(tools::threadCount())
        ->capture_default_str();
    render->add_option("--order", ro.order, "Traversal order: ordered (default) or adversarial (GEN-3)");
    render->add_option("--seed", ro.seed,
                       "Random seed: RenderSettings::seed, for shaders that sample at random (the first batch's with "
                       "--batches), and the seed of the adversarial order")
        ->check(tools::wholeNumber("a seed from 0 to 4294967295"))
        ->capture_default_str();
    render->add_option("--batches", ro.batches,
                       "Render K >= 2 times with seeds S, S+1, ..., S+K-1 and write a statistics image (-o FILE.exr: "
                       "the mean and the variance of the mean) for 'refray compare --statistical'")
        ->check(tools::wholeNumber("a number of renders (2 or more)"));
    render->add_flag("--warnings-as-errors", ro.warningsAsErrors, refray::tools::kWarningsAsErrorsHelp);
    render->add_flag("--stats", ro.stats,
                     "Print rays per ray type and depth, invocations per export, and the exclusive time per stage");
    render->add_option("--stats-json", ro.statsJson, "Write the --stats measures to FILE as JSON (format refray-stats/1)");
    render->add_flag("--no-stage-times", ro.noStageTimes,
                     "With --stats or --stats-json: do not time the stages (their clocks cost a few per cent), for "
                     "timing the render itself");
    render->add_flag("--no-shortcuts", ro.noShortcuts,
                     "Gather every candidate of every ray and unwind every intersection shader whose ReportHit ends "
                     "the search: no shortcuts (for measuring them; the image is the same)");
    render->add_option("--wave-width", ro.waveWidth,
                       "Lanes per wave of the emulator (docs/emulator.md, \"Waves\"): launches run together, their rays "
                       "traverse as a packet and their intersection shaders run once per record over the lanes that "
                       "reach it. The image is the same for every width (default 32)")
        ->check(CLI::Range(1, 32));
    render->add_option("--aov", ro.aov,
                       "Write an index map instead of the render: record|instance|geometry|primitive|hitgroup|depth "
                       "of each pixel's primary ray, false-coloured, with a legend (-o FILE.exr: the values "
                       "themselves, R = G = B = the index, -1 for a miss, exact)");
    render->add_option("--device", ro.device,
                       "Where DispatchRays runs: cpu (the emulator) or vulkan (the same DXR state translated to a Vulkan "
                       "ray-tracing GPU; docs/vulkan-backend.md)")
        ->capture_default_str();
    render->add_option("--vulkan-device", ro.vulkanDevice,
                       "With --device vulkan: which Vulkan device, by index or by part of its device or driver name "
                       "('refray devices' lists them; default $REFRAY_VULKAN_DEVICE, else a hardware ray-tracing "
                       "device when there is one and Mesa's lavapipe, a CPU driver, otherwise)");
    render->add_option("--spirv-dir", ro.spirvDir,
                       "With --device vulkan: the folder of the compiled GLSL ports (<library>/<Export>.<stage>.spv); "
                       "default $REFRAY_SPIRV_DIR, else next to the refray executable");
    render->add_option("--order-check", ro.orderCheck,
                       "Also render N seeded adversarial traversal orders (GEN-3) and write OUTPUT.order-mask.png: "
                       "white where a pixel depends on the order")
        ->check(tools::wholeNumber("a number of adversarial orders (0: none)"));

    refray::tools::CompareCommandOptions compareOptions;
    CLI::App* compare = refray::tools::addCompareCommand(app, compareOptions);

    refray::tools::TableCommandOptions tableOptions;
    CLI::App* table = refray::tools::addTableCommand(app, tableOptions);

    refray::tools::SweepCommandOptions sweepOptions;
    CLI::App* sweep = refray::tools::addSweepCommand(app, sweepOptions);

    refray::tools::ExplainCommandOptions explainOptions;
    CLI::App* explain = refray::tools::addExplainCommand(app, explainOptions);

    refray::tools::GoldenCommandOptions goldenOptions;
    CLI::App* golden = refray::tools::addGoldenCommand(app, goldenOptions);

    auto* devices = app.add_subcommand("devices", "List the Vulkan devices refray sees, whether each can ray trace "
                                                  "(and what it lacks), and which one --device vulkan takes; exit 2 "
                                                  "when none can");
    bool devicesJson = false;
    devices->add_flag("--json", devicesJson, "Print the list as JSON (format refray-devices/1)");

    // An output being written when the user interrupts refray is removed, and the file it replaces stays as it was.
    refray::removeTemporaryFilesOnSignal();
    try {
        app.parse(argc, argv);
        if (*golden) return refray::tools::runGolden(goldenOptions);
        if (*render) return runRender(ro);
        if (*compare) return refray::tools::runCompare(compareOptions);
        if (*table) return refray::tools::runTable(tableOptions);
        if (*explain) return refray::tools::runExplain(explainOptions);
        if (*sweep) return refray::tools::runSweep(sweepOptions);
        if (*devices) return refray::tools::listDevices(devicesJson);
    } catch (const CLI::ParseError& e) {
        return refray::tools::parseErrorStatus(app, e);
    } catch (const refray::dxr::DxrError& e) {
        std::fprintf(stderr, "refray: %s\n", e.what());
        return 2;
    } catch (const refray::Error& e) {
        std::fprintf(stderr, "refray: %s\n", e.what());
        return 2;
    } catch (const std::filesystem::filesystem_error& e) {
        // A folder that cannot be created or removed (a full disk, a file in the way, no permission): the file's
        // problem, named, not refray's.
        std::fprintf(stderr, "refray: cannot use '%s': %s\n", e.path1().string().c_str(), e.code().message().c_str());
        return 2;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "refray: not enough memory for this command (std::bad_alloc); a smaller --size, fewer "
                             "renders or a machine with more memory may do\n");
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray: unexpected error: %s\n", e.what());
        return 3;
    }
    return 0;
}
