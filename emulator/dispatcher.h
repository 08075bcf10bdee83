// DispatchRays options and results (the dispatcher itself is Device::dispatchRays).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/progress.h"
#include "emulator/dispatch_stats.h"
#include "emulator/trace.h"
#include "emulator/validation.h"

namespace refray::dxr {

// GEN-3: the order in which candidates meet the DXR rules, within what the spec allows.
enum class TraversalOrder : uint8_t {
    // Default, deterministic: candidates in increasing order of their key (a triangle's t,
    // an AABB's entry t into [TMin, TCurrent]); ties by InstanceIndex, GeometryIndex,
    // PrimitiveIndex. A box whose entry lies beyond TCurrent when its turn comes is
    // skipped (it no longer overlaps the interval). One IS call per enumerated box.
    Ordered,
    // Seeded adversarial: candidates shuffled; geometry without
    // NO_DUPLICATE_ANYHIT_INVOCATION sees candidates presented twice (duplicate IS and
    // AHS calls, AHS-6, IS-1); shared edges use the alternate ownership rule (TRI-4).
    Adversarial,
};

enum class OnError : uint8_t {
    Stop,      // GEN-1 default: the first error (lowest launch index) ends the dispatch
    Continue,  // record every error and apply the fallback its rule documents
};

// A rectangle of launch indices (z = 0 .. Depth-1 all run). DispatchRaysIndex() and
// DispatchRaysDimensions() keep their full-dispatch values.
struct LaunchRegion {
    uint32_t x = 0, y = 0, width = 0, height = 0;
};

struct DispatchOptions {
    uint32_t threads = 0;  // 0: every hardware thread
    uint32_t tileSize = 8;
    OnError onError = OnError::Stop;
    TraversalOrder order = TraversalOrder::Ordered;
    uint64_t adversarialSeed = 0;
    Progress* progress = nullptr;  // advanced once per tile
    // Only these launch indices run (explain one pixel); unset: all of them. Must lie inside the dispatch.
    std::optional<LaunchRegion> region;
    // Receives every trace event (emulator/trace.h); null: nothing is recorded.
    TraceObserver* observer = nullptr;
    // Measure the exclusive time of every stage (DispatchStats::stageSeconds) with steady_clock around each
    // shader call and TraceRay. Off: the stage times stay zero and the cost is one untaken branch per site.
    bool profileStages = false;
    // Traversal shortcuts that change no result, invocation or diagnostic (docs/emulator.md, "Traversal
    // shortcuts"): Embree's interval shrinks to the nearest triangle sure to commit, and rays that accept the
    // first hit and skip the closest hit use an occlusion query when the pipeline has no any-hit shader. They
    // are off for observed rays and adversarial order. false gathers every candidate of every ray.
    bool specialise = true;
    // Lanes per wave (docs/emulator.md, "Waves"): each worker runs up to this many launches together, their rays
    // traversing as a packet and their intersection shaders running once per record over the lanes that reach it.
    // 1..kMaxWaveWidth (32); images, diagnostics and statistics are the same for every width. An observed or
    // profiled dispatch runs one lane per wave, so that each launch's events and stage times stay its own.
    uint32_t waveWidth = 32;
};

// ID3D12GraphicsCommandList::Dispatch with a compute pipeline state whose shader is `ComputeShader`, a compute
// export of the bound state object's libraries (its [numthreads] comes with the export). Threads run in the launch
// order of DispatchRays over the grid of SV_DispatchThreadID, so diagnostics name a thread by that id.
struct DispatchDesc {
    std::string ComputeShader;
    uint32_t ThreadGroupCountX = 1;
    uint32_t ThreadGroupCountY = 1;
    uint32_t ThreadGroupCountZ = 1;
};
// D3D12_CS_DISPATCH_MAX_THREAD_GROUPS_PER_DIMENSION.
inline constexpr uint32_t kMaxThreadGroupsPerDimension = 65535;

struct DispatchResult {
    DiagnosticLog diagnostics;  // warnings, plus the errors in OnError::Continue mode
    DispatchStats stats;
    double seconds = 0.0;  // wall time of the whole dispatch
};

}  // namespace refray::dxr
