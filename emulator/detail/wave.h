// The wave executor (docs/emulator.md, "Waves"): each worker thread runs its launches in waves of up to
// kMaxWaveWidth lanes. A lane is one launch: its ray generation (or compute) shader and everything that shader calls
// run on the lane's own fiber (emulator/fiber.h) with the lane's own ThreadState. A TraceRay parks its lane
// (awaitTraversal); when every lane of the wave is parked or done, the rays of the parked lanes traverse together as
// a packet (packet_traversal.cpp), whose intersection shaders run once per record for the lanes that reached it
// (record grouping); then each lane resumes with its ray's closest-hit or miss shader. A wave call parks its lane too;
// the calls of the waiting lanes run grouped by key (wave_call.cpp). Internal to the emulator.
#pragma once

#include <array>
#include <exception>
#include <functional>
#include <memory>
#include <span>

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"
#include "emulator/detail/thread_state.h"
#include "emulator/fiber.h"
#include "emulator/lane_mask.h"
#include "emulator/trace_ray_call.h"
#include "emulator/wave_call.h"

namespace refray::dxr::detail {

struct Wave;

// One lane: the launch it runs, and the TraceRay it waits on.
struct WaveLane {
    Wave* wave = nullptr;
    int index = 0;
    uvec3 launch{0u};  // the launch index the lane runs
    // The parked TraceRay: its ray and where it was called. Set by awaitTraversal, read by the packet.
    RayState* ray = nullptr;
    Site site{ShaderStage::RayGeneration, &kNoExport, 0};
    // An exception the packet raised for this lane (an error that stops its launch): rethrown on its fiber.
    std::exception_ptr failure;
    // The packet's place in the ray's candidates, and the intersection-shader call the lane waits for in a
    // record group (the invocation points at `box` and `record`).
    size_t nextCandidate = 0;
    HitInfo box;
    RecordView record;
    Invocation intersection;
    // The wave call the lane waits on (awaitWaveCall): its function, key and the lane's state.
    const WaveFunction* call = nullptr;
    WaveCallKey callKey;
    void* callState = nullptr;
    // Last: its hot fields (ThreadState's first ones) then follow the lane's own, and its cold ones end the lane.
    ThreadState ts;
};

// A worker thread's wave: its lanes and their fibers, kept from wave to wave.
struct Wave {
    explicit Wave(DispatchState& ds);
    Wave(const Wave&) = delete;
    Wave& operator=(const Wave&) = delete;

    LookupCache lookups;  // the lanes' (ThreadState::lookups)
    std::array<WaveLane, kMaxWaveWidth> lanes;
    std::array<std::unique_ptr<Fiber>, kMaxWaveWidth> fibers;
    LaneMask parked;   // lanes whose TraceRay waits for the packet
    LaneMask calling;  // lanes waiting on a wave call
    bool grouped = false;  // more than one lane: a wave call parks its lane
    // The MXCSR of the wave's own code (traversal, record groups), which its lanes' shaders may change for theirs:
    // what the worker thread had when the wave opened.
    uint32_t schedulerMxcsr = 0;
};

// Runs one launch on a lane's ThreadState (the dispatcher's launch: the ray generation or compute shader).
using LaunchFunction = std::function<void(ThreadState&, uvec3)>;

// Runs `launches` (at most kMaxWaveWidth) as the lanes of `wave`, until every lane is done.
void runWave(Wave& wave, std::span<const uvec3> launches, const LaunchFunction& launch);

// Opens a round of `lanes` lanes (at most kMaxWaveWidth) that the caller runs itself, as a ray generation shader
// written for waves does (the dispatcher's runLaunchWave): no lane waits, and the wave's own code will run in the
// floating-point mode of this moment.
void openWave(Wave& wave, size_t lanes);

// The TraceRays of `lanes`, one per lane, issued together by a shader written for waves that runs on the wave's own
// stack (tracing_wave.h: ray generation or closest hit): lane i's is calls[i] from the invocation callers[i]. Each
// lane's TraceRay is the one ShaderContext::TraceRay makes (the same checks, events, counts, candidates, shaders and
// payload), and their rays traverse as one packet. Closest-hit shaders written for waves run once per shader over the
// lanes that selected them, on the wave's stack (their TraceRays come back here); other closest-hit shaders on their
// lanes' fibers (their own TraceRays park as any lane's); miss shaders on the wave's stack. What stops a lane's
// launch goes to failures[i].
void traceRaysInWave(Wave& wave, const std::array<Invocation*, kMaxWaveWidth>& callers,
                     const TraceRayCall* calls, LaneMask lanes,
                     std::array<std::exception_ptr, kMaxWaveWidth>& failures);

// TraceRay's traversal for `rs` (TRV-4: its candidates gathered, ordered and processed), which the caller's wave
// runs in a packet with the other lanes' rays; returns when the ray's search is over. Rethrows what stopped the
// lane's launch meanwhile.
void awaitTraversal(ThreadState& ts, RayState& rs, const Site& site);

// A wave call (emulator/wave_call.h) of the lane that `ts` belongs to: parks the lane until the wave runs the calls
// of its waiting lanes (runWaveCalls); runs it at once for a lane alone or off its lane's fiber. Rethrows what
// stopped the lane meanwhile.
void awaitWaveCall(ThreadState& ts, const WaveFunction& function, const WaveCallKey& key, void* state);

// wave_call.cpp: the waiting calls of `lanes`, grouped by function and key, each group in calls of at most its
// function's lanesPerCall lanes, in lane order.
void runWaveCalls(Wave& wave, LaneMask lanes);

// The wave calls of `lanes` made together by a shader written for waves on the wave's own stack (ShaderWave::CallInWave):
// lane i's is calls[i]. They run as runWaveCalls runs the calls of waiting lanes, in the floating-point mode of the
// wave's own code; what stops a lane's launch goes to failures[i].
void runWaveCallsOfShader(Wave& wave, LaneMask lanes, const WaveCall* calls,
                          std::array<std::exception_ptr, kMaxWaveWidth>& failures);

// packet_traversal.cpp: the traversal of the rays of `lanes` (parked TraceRays).
void traversePacket(Wave& wave, LaneMask lanes);

}  // namespace refray::dxr::detail
