// Emulation overhead on the reference scenes (issue 8): refray against raw Embree calling the same shader functions
// directly. Each reference scene file (D3D12 procedural geometry, Proceduray Mandelbulb/Julia/Pac-man) renders its
// default camera at its default time, float, 1 spp, two ways:
//
// - refray: scenes::Scene::render — DispatchRays through the shader tables, the state object, Embree and every DXR
//   rule, with the ported shaders as the scene's library builds them.
// - raw Embree: one flat Embree scene of the same geometry, built here from the same SceneDesc. Triangle meshes are
//   native RTC_GEOMETRY_TYPE_TRIANGLE (world-space vertices; back faces dropped by a filter function, which is what
//   the shaders' RAY_FLAG_CULL_BACK_FACING_TRIANGLES asks for); every AABB is an RTC_GEOMETRY_TYPE_USER primitive
//   whose callbacks test the object-space box against [tnear, tfar] (the test DXR traversal makes before it calls an
//   intersection shader), take the ray into the primitive's local space as the port does, and call the same math the
//   ports' intersection shaders call (math::RayUnitCubeIntersectionTest / RaySpheresIntersectionTest /
//   RayMetaballsIntersectionTest / RaySignedDistancePrimitiveTest, mandelbulb::MandelbulbDistance,
//   julia::JuliaDistance, with the ports' params functions). Ray generation, closest hit and miss are a plain C++
//   recursion that calls the ports' exported shading helpers (d3d12::CalculatePhongLighting,
//   AnalyticalCheckersTexture, ApplyVisibilityFalloff, FresnelReflectanceSchlick, GenerateCameraRay,
//   proceduray::CalculatePhongLighting, colorSurface, MandelbulbSurfaceColor, ...) with the same recursion depth,
//   the same shadow rays (rtcOccluded1, TMax 10000) and reflection rays. Materials, transforms, camera, light and
//   time come from the scene file through the loader.
// - Raw leaves out: shader tables and records, root signatures and resource views (the data are plain C++ values),
//   payload and attribute copies through the emulator, std::function dispatch, the candidate gather and ordered
//   processing of DXR rule TRV-2 (Embree's own traversal order decides which primitive is met first), refray's own
//   watertight triangle test (Embree's native kernel here), validation, statistics and diagnostics.
//
// Before anything is timed both images are compared: the largest difference of any channel and the fraction of
// pixels whose R8G8B8A8_UNORM value (clamp, NaN -> 0) differs by more than 1/255 in any channel are printed, with
// the ray counts of both. Over 1% of differing pixels marks the harness as wrong and every benchmark of that scene
// fails (SkipWithError) instead of timing it.
//
// Size: 320x180 by default; --size=WxH or REFRAY_BENCH_SIZE=WxH (e.g. 1280x720) changes it. REFRAY_BENCH_IMAGES=dir
// also writes both images of each scene there as EXR. BM_Ratio renders refray and raw alternately in one body (at
// least 2 s of pairs), so machine noise hits both equally; its counter "ratio" is refray time / raw time (take the
// median over --benchmark_repetitions).
//
// The raw-Embree renderer is raw_embree_renderer.h, raw_embree_renderer.cpp and raw_embree_shaders.cpp.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/benchmarks/raw_embree_renderer.h"

namespace {

using namespace refray;
using namespace refray::bench;

// ---- The benchmark harness ------------------------------------------------------------------------------

struct FrameSize {
    uint32_t width = 320, height = 180;
};
FrameSize gSize;

struct ImageComparison {
    float maxAbsDifference = 0.0f;  // any channel, as the shaders wrote it (both NaN counts as equal)
    uint64_t differingPixels = 0;   // R8G8B8A8_UNORM values more than 1/255 apart in some channel
    double differingFraction = 0.0;
    uint64_t refrayRays = 0, rawRays = 0;
};

// The value an R8G8B8A8_UNORM target holds, before the x255: NaN -> 0, clamp to [0, 1].
float unorm(float v) { return std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f); }

ImageComparison compareImages(const Image& refray, const std::vector<vec4>& raw) {
    ImageComparison c;
    for (size_t i = 0; i < raw.size(); ++i) {
        const vec4& a = refray.pixels()[i];
        const vec4& b = raw[i];
        bool differs = false;
        for (glm::length_t k = 0; k < 4; ++k) {
            if (!(std::isnan(a[k]) && std::isnan(b[k]))) {
                const float d = std::fabs(a[k] - b[k]);
                c.maxAbsDifference = std::isnan(d) ? INFINITY : std::max(c.maxAbsDifference, d);
            }
            if (std::fabs(unorm(a[k]) - unorm(b[k])) > 1.0f / 255.0f) differs = true;
        }
        if (differs) ++c.differingPixels;
    }
    c.differingFraction = raw.empty() ? 0.0 : double(c.differingPixels) / double(raw.size());
    return c;
}

// One reference scene: its refray Scene and its raw renderer, built once, compared once.
class SceneBench {
public:
    SceneBench(const std::string& name, const std::filesystem::path& file)
        : name_(name), desc_(scenes::loadSceneFile(file)), refray_(desc_), raw_(desc_, gSize.width, gSize.height) {
        settings_.width = gSize.width;
        settings_.height = gSize.height;
        compare();
    }

    uint64_t renderRefray(uint32_t threads) {
        settings_.threads = threads;
        return refray_.render(settings_).dispatch.stats.raysTraced;
    }
    uint64_t renderRaw(uint32_t threads) { return raw_.render(threads, rawImage_); }
    const ImageComparison& comparison() const { return comparison_; }

private:
    void compare() {
        settings_.threads = 2;
        const scenes::RenderResult reference = refray_.render(settings_);
        const uint64_t rawRays = raw_.render(2, rawImage_);
        comparison_ = compareImages(reference.image, rawImage_);
        comparison_.refrayRays = reference.dispatch.stats.raysTraced;
        comparison_.rawRays = rawRays;
        std::fprintf(stderr,
                     "%s %ux%u: max |refray - raw| = %.9g, pixels differing by more than 1/255: %llu (%.4f%%); "
                     "rays: refray %llu, raw %llu\n",
                     name_.c_str(), gSize.width, gSize.height, double(comparison_.maxAbsDifference),
                     static_cast<unsigned long long>(comparison_.differingPixels),
                     100.0 * comparison_.differingFraction,
                     static_cast<unsigned long long>(comparison_.refrayRays),
                     static_cast<unsigned long long>(comparison_.rawRays));
        if (const char* dir = std::getenv("REFRAY_BENCH_IMAGES")) {
            Image raw(gSize.width, gSize.height);
            raw.pixels() = rawImage_;
            const std::string base = std::string(dir) + "/" + name_ + "-" + std::to_string(gSize.width) + "x" +
                                     std::to_string(gSize.height);
            writeImage(base + "-refray.exr", reference.image);
            writeImage(base + "-raw.exr", raw);
        }
    }

    std::string name_;
    scenes::SceneDesc desc_;
    scenes::Scene refray_;
    RawRenderer raw_;
    scenes::RenderSettings settings_;
    std::vector<vec4> rawImage_;
    ImageComparison comparison_;
};

// Built on first use (outside any timing) and kept for the run; a failure is kept as its message.
SceneBench* sceneBench(benchmark::State& state, const std::string& name) {
    static std::map<std::string, std::unique_ptr<SceneBench>> benches;
    static std::map<std::string, std::string> errors;
    if (!benches.count(name) && !errors.count(name)) {
        try {
            benches[name] = std::make_unique<SceneBench>(name, std::filesystem::path(REFRAY_SOURCE_DIR) / "scenes" /
                                                                   (name + ".json"));
        } catch (const std::exception& e) {
            errors[name] = e.what();
        }
    }
    if (auto it = errors.find(name); it != errors.end()) {
        state.SkipWithError(it->second.c_str());
        return nullptr;
    }
    SceneBench* bench = benches[name].get();
    const ImageComparison& c = bench->comparison();
    if (c.differingFraction > 0.01) {
        static std::string message;
        message = "the raw renderer's image differs from refray's in " + std::to_string(100.0 * c.differingFraction) +
                  "% of the pixels (over 1%): the harness is wrong, nothing is timed";
        state.SkipWithError(message.c_str());
        return nullptr;
    }
    return bench;
}

void addImageCounters(benchmark::State& state, const ImageComparison& c) {
    state.counters["img_maxdiff"] = c.maxAbsDifference;
    state.counters["img_px>1/255"] = c.differingFraction;
}

void BM_Refray(benchmark::State& state, const std::string& name, uint32_t threads) {
    SceneBench* bench = sceneBench(state, name);
    if (!bench) return;
    uint64_t rays = 0;
    for (auto _ : state) rays += bench->renderRefray(threads);
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}

void BM_RawEmbree(benchmark::State& state, const std::string& name, uint32_t threads) {
    SceneBench* bench = sceneBench(state, name);
    if (!bench) return;
    uint64_t rays = 0;
    for (auto _ : state) rays += bench->renderRaw(threads);
    state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
    addImageCounters(state, bench->comparison());
}

// Both renders in one body, alternating which goes first, each timed on its own.
void BM_Ratio(benchmark::State& state, const std::string& name, uint32_t threads) {
    SceneBench* bench = sceneBench(state, name);
    if (!bench) return;
    using Clock = std::chrono::steady_clock;
    double refraySeconds = 0.0, rawSeconds = 0.0;
    uint64_t refrayRays = 0, rawRays = 0;
    bool refrayFirst = true;
    for (auto _ : state) {
        for (int pass = 0; pass < 2; ++pass) {
            const bool refray = (pass == 0) == refrayFirst;
            const auto start = Clock::now();
            if (refray) refrayRays += bench->renderRefray(threads);
            else rawRays += bench->renderRaw(threads);
            const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
            (refray ? refraySeconds : rawSeconds) += seconds;
        }
        refrayFirst = !refrayFirst;
    }
    const double iterations = double(state.iterations());
    state.counters["refray_ms"] = 1e3 * refraySeconds / iterations;
    state.counters["raw_ms"] = 1e3 * rawSeconds / iterations;
    state.counters["ratio"] = refraySeconds / rawSeconds;
    state.counters["refray_rays/s"] = double(refrayRays) / refraySeconds;
    state.counters["raw_rays/s"] = double(rawRays) / rawSeconds;
    addImageCounters(state, bench->comparison());
}

bool parseSize(const std::string& text, FrameSize& size) {
    unsigned w = 0, h = 0;
    char x = 0;
    if (std::sscanf(text.c_str(), "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w == 0 || h == 0) return false;
    size = {w, h};
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (const char* env = std::getenv("REFRAY_BENCH_SIZE"); env && !parseSize(env, gSize)) {
        std::fprintf(stderr, "REFRAY_BENCH_SIZE must be WxH, got '%s'\n", env);
        return 1;
    }
    // --size=WxH, taken out before Google Benchmark reads the rest.
    int kept = 1;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.rfind("--size=", 0) == 0) {
            if (!parseSize(arg.substr(7), gSize)) {
                std::fprintf(stderr, "--size must be WxH, got '%s'\n", arg.c_str());
                return 1;
            }
            continue;
        }
        argv[kept++] = argv[i];
    }
    argc = kept;

    for (const std::string name : {"d3d12-procedural-geometry", "proceduray-mandel-julia-pac"})
        for (uint32_t threads : {1u, 2u}) {
            const std::string suffix = "/" + name + "/threads:" + std::to_string(threads);
            benchmark::RegisterBenchmark(("BM_Refray" + suffix).c_str(),
                                         [name, threads](benchmark::State& s) { BM_Refray(s, name, threads); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            benchmark::RegisterBenchmark(("BM_RawEmbree" + suffix).c_str(),
                                         [name, threads](benchmark::State& s) { BM_RawEmbree(s, name, threads); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            // Several alternations per repetition, so one slow frame weighs less in the ratio.
            benchmark::RegisterBenchmark(("BM_Ratio" + suffix).c_str(),
                                         [name, threads](benchmark::State& s) { BM_Ratio(s, name, threads); })
                ->Unit(benchmark::kMillisecond)
                ->MinTime(2.0)
                ->UseRealTime();
        }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}