// What a render is asked to do, and what it returns.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "core/image.h"
#include "core/progress.h"
#include "emulator/device.h"
#include "emulator/dispatcher.h"
#include "procedural/accuracy.h"
#include "procedural/perturbation.h"
#include "procedural/precision.h"

namespace refray::scenes {

// Where DispatchRays runs: the same arguments as dxr::Device::dispatchRays, over the DXR state the scene built on
// that device. Another back end (gpu/vulkan_dispatch.h: `refray render --device vulkan`) translates that state and
// writes the render targets bound in the global root arguments, as the emulator does.
using DispatchBackend =
    std::function<dxr::DispatchResult(dxr::Device&, const dxr::DispatchRaysDesc&, const dxr::StateObjectPtr&,
                                      const dxr::GlobalRootArguments*, const dxr::DispatchOptions&)>;

// Where a compute dispatch runs (scenes whose pipeline names "compute": Device::dispatch's arguments).
using ComputeBackend =
    std::function<dxr::DispatchResult(dxr::Device&, const dxr::DispatchDesc&, const dxr::StateObjectPtr&,
                                      const dxr::GlobalRootArguments*, const dxr::DispatchOptions&)>;

struct RenderSettings {
    uint32_t width = 640;
    uint32_t height = 360;
    uint32_t threads = 0;  // 0: all hardware threads
    dxr::TraversalOrder order = dxr::TraversalOrder::Ordered;
    uint64_t adversarialSeed = 0;
    dxr::OnError onError = dxr::OnError::Stop;
    Progress::Sink progress;  // optional
    // Scene files only (the built-in scene has one camera, no time and no precision choice).
    std::string camera;         // empty: the scene's default camera
    std::optional<float> time;  // empty: the scene's default time
    procedural::Precision precision = procedural::Precision::Float;
    // Runs the shader math as the GPU this perturbation picks from the variation model (procedural/perturbation.h,
    // docs/numerical-variation.md); float precision only. Unset: the nominal float or double arithmetic.
    std::optional<procedural::Perturbation> perturbation;
    // The shader library's accuracy knobs (scenes/knobs.h); the default is the HLSL's constants.
    procedural::Accuracy accuracy;
    // Samples per pixel: a square number n = k·k renders a k-times larger dispatch whose k x k pixel centres
    // fall on a regular grid inside each output pixel, averaged in float (the shaders' own ray generation runs
    // unchanged). 1 is the GPU's image.
    uint32_t spp = 1;
    // The render's random seed, written into the scene constants (SceneConstantsInput::seed): shaders that sample
    // at random key their per-pixel generators by it, so renders with other seeds are independent. Libraries
    // without randomness ignore it.
    uint32_t seed = 0;
    // Only these pixels of the dispatch run (refray explain); unset: all. Needs spp 1.
    std::optional<dxr::LaunchRegion> region;
    // Receives the trace events of the dispatch (emulator/trace.h); null: nothing is recorded.
    dxr::TraceObserver* observer = nullptr;
    // Time each shader stage and the traversal (DispatchStats::stageSeconds); costs a few per cent when on.
    bool profileStages = false;
    // DispatchOptions::specialise: traversal shortcuts that change no result.
    bool specialise = true;
    // DispatchOptions::waveWidth: lanes per wave (1..32); the image is the same for every width.
    uint32_t waveWidth = 32;
    // Empty: the emulator runs the dispatch (dxr::Device::dispatchRays).
    DispatchBackend backend;
    // The same for a compute dispatch (dxr::Device::dispatch). A render with `backend` set and this empty refuses
    // a compute scene rather than running it on the emulator.
    ComputeBackend computeBackend;
};

// The DispatchOptions of the settings; `progress` receives `launches` when the settings have a progress sink.
inline dxr::DispatchOptions dispatchOptions(const RenderSettings& settings, uint64_t launches,
                                           std::unique_ptr<Progress>& progress) {
    dxr::DispatchOptions options;
    options.threads = settings.threads;
    options.order = settings.order;
    options.adversarialSeed = settings.adversarialSeed;
    options.onError = settings.onError;
    options.region = settings.region;
    options.observer = settings.observer;
    options.profileStages = settings.profileStages;
    options.specialise = settings.specialise;
    options.waveWidth = settings.waveWidth;
    if (settings.progress) {
        if (settings.region) launches = uint64_t(settings.region->width) * settings.region->height;
        progress = std::make_unique<Progress>("render", launches, settings.progress);
        options.progress = progress.get();
    }
    return options;
}

// Runs DispatchRays for a width x height dispatch with the settings' threads, order, error mode and progress.
inline dxr::DispatchResult dispatchWithSettings(dxr::Device& device, const dxr::DispatchRaysDesc& desc,
                                                const dxr::StateObjectPtr& pipeline, const dxr::GlobalRootArguments* globals,
                                                const RenderSettings& settings) {
    std::unique_ptr<Progress> progress;
    const dxr::DispatchOptions options =
        dispatchOptions(settings, uint64_t(desc.Width) * desc.Height * desc.Depth, progress);
    dxr::DispatchResult result = settings.backend ? settings.backend(device, desc, pipeline, globals, options)
                                                  : device.dispatchRays(desc, pipeline, globals, options);
    if (progress) progress->finish();
    return result;
}

// Runs a compute dispatch of `threads` (the grid of SV_DispatchThreadID) the same way.
inline dxr::DispatchResult dispatchComputeWithSettings(dxr::Device& device, const dxr::DispatchDesc& desc, uvec3 threads,
                                                       const dxr::StateObjectPtr& pipeline,
                                                       const dxr::GlobalRootArguments* globals,
                                                       const RenderSettings& settings) {
    REFRAY_CHECK(!settings.backend || settings.computeBackend,
                 "this device runs DispatchRays but has no compute back end for the compute shader '"
                     << desc.ComputeShader << "'");
    std::unique_ptr<Progress> progress;
    const dxr::DispatchOptions options = dispatchOptions(settings, uint64_t(threads.x) * threads.y * threads.z, progress);
    dxr::DispatchResult result = settings.computeBackend
                                     ? settings.computeBackend(device, desc, pipeline, globals, options)
                                     : device.dispatch(desc, pipeline, globals, options);
    if (progress) progress->finish();
    return result;
}

struct RenderResult {
    Image image;  // the render target as the shaders wrote it (float RGBA)
    dxr::DispatchResult dispatch;
};

}  // namespace refray::scenes
