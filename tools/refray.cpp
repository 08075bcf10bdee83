// refray: the command line. Only this layer prints and exits.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <regex>
#include <string>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "core/image.h"
#include "emulator/validation.h"
#include "scenes/builtin_scene.h"
#include "tools/version.h"

namespace {

using namespace refray;

struct Size {
    uint32_t width = 640, height = 360;
};

Size parseSize(const std::string& text) {
    static const std::regex pattern(R"((\d+)x(\d+))");
    std::smatch m;
    REFRAY_CHECK(std::regex_match(text, m, pattern), "--size expects WIDTHxHEIGHT (e.g. 640x360), got '" << text << "'");
    const unsigned long w = std::stoul(m[1]), h = std::stoul(m[2]);
    REFRAY_CHECK(w > 0 && h > 0 && w <= 16384 && h <= 16384,
                 "--size " << text << " is outside 1x1 .. 16384x16384");
    return {uint32_t(w), uint32_t(h)};
}

Progress::Sink terminalProgress() {
    if (!isatty(STDERR_FILENO)) return {};
    return [](const ProgressState& s) {
        std::fprintf(stderr, "\r%s", formatProgressBar(s).c_str());
        if (s.finished) std::fputc('\n', stderr);
        std::fflush(stderr);
    };
}

void printStats(const scenes::RenderResult& r, const Size& size) {
    const auto& st = r.dispatch.stats;
    std::printf("render: %ux%u in %.3f s, %llu rays (%.0f rays/s)\n", size.width, size.height, r.dispatch.seconds,
                (unsigned long long)st.raysTraced, r.dispatch.seconds > 0 ? double(st.raysTraced) / r.dispatch.seconds : 0.0);
    for (size_t d = 1; d < st.raysPerDepth.size(); ++d)
        std::printf("  rays at depth %zu: %llu\n", d, (unsigned long long)st.raysPerDepth[d]);
    for (size_t s = 0; s < st.invocations.size(); ++s)
        if (st.invocations[s])
            std::printf("  %s invocations: %llu\n", std::string(dxr::toString(dxr::ShaderStage(s))).c_str(),
                        (unsigned long long)st.invocations[s]);
    std::printf("  candidates gathered: %llu\n", (unsigned long long)st.candidates);
}

int runRender(const std::string& output, const std::string& sizeText, uint32_t threads, bool stats,
              const std::string& order, uint64_t seed) {
    const Size size = parseSize(sizeText);
    scenes::RenderSettings settings;
    settings.width = size.width;
    settings.height = size.height;
    settings.threads = threads;
    settings.adversarialSeed = seed;
    REFRAY_CHECK(order == "ordered" || order == "adversarial",
                 "--order expects 'ordered' or 'adversarial', got '" << order << "'");
    settings.order = order == "adversarial" ? dxr::TraversalOrder::Adversarial : dxr::TraversalOrder::Ordered;
    settings.progress = terminalProgress();

    scenes::BuiltinScene scene;
    scenes::RenderResult result = scene.render(settings);
    for (const auto& w : result.dispatch.diagnostics.warnings()) std::fprintf(stderr, "%s\n", w.format().c_str());

    result.image.metadata["scene"] = "builtin";
    result.image.metadata["refray_version"] = tools::kVersion;
    result.image.metadata["refray_commit"] = tools::kCommit;
    result.image.metadata["size"] = sizeText;
    result.image.metadata["traversal_order"] = order;
    result.image.metadata["render_seconds"] = std::to_string(result.dispatch.seconds);
    const auto parent = std::filesystem::path(output).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    writeImage(output, result.image);
    if (stats) printStats(result, size);
    std::printf("wrote %s\n", output.c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"refray: a CPU reference ray tracer with exact DirectX Raytracing semantics"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(refray::tools::kVersion) + " (" + refray::tools::kCommit + ")");

    auto* render = app.add_subcommand("render", "Render the built-in scene to an image (PNG or EXR)");
    std::string output = "refray.png", size = "640x360", order = "ordered";
    uint32_t threads = 0;
    uint64_t seed = 0;
    bool stats = false;
    render->add_option("-o,--output", output, "Output image (.png: R8G8B8A8_UNORM as the GPU stores it; .exr: float)");
    render->add_option("--size", size, "Image size WIDTHxHEIGHT")->capture_default_str();
    render->add_option("--threads", threads, "Worker threads (0: all)")->capture_default_str();
    render->add_option("--order", order, "Traversal order: ordered (default) or adversarial (GEN-3)");
    render->add_option("--seed", seed, "Seed of the adversarial order");
    render->add_flag("--stats", stats, "Print rays, invocations and timing");

    try {
        app.parse(argc, argv);
        if (*render) return runRender(output, size, threads, stats, order, seed);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const refray::dxr::DxrError& e) {
        std::fprintf(stderr, "refray: %s\n", e.what());
        return 2;
    } catch (const refray::Error& e) {
        std::fprintf(stderr, "refray: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray: unexpected error: %s\n", e.what());
        return 3;
    }
    return 0;
}
