// What one worker thread of a DispatchRays keeps between the launches it runs: the launch being run, its
// diagnostics and statistics, the candidate buffer and the lookup caches. Internal to the emulator.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <vector>

#include "emulator/detail/dispatch_state.h"
#include "emulator/dispatch_stats.h"
#include "emulator/embree_bridge.h"
#include "emulator/validation.h"

namespace refray::dxr::detail {

// Exclusive stage times (DispatchOptions::profileStages): at each switch the running section is charged
// the time since the previous switch. Sections are ProfileStage values; kOutside is time in no stage
// (the launch loop, tile scheduling), which is not reported.
struct StageClock {
    using Clock = std::chrono::steady_clock;
    static constexpr uint8_t kOutside = uint8_t(kProfileStageCount);
    Clock::time_point mark = Clock::now();
    uint8_t section = kOutside;
    std::array<Clock::duration, kProfileStageCount + 1> spent{};

    // Switches to `next`; returns the section to switch back to.
    uint8_t enter(uint8_t next) {
        const Clock::time_point now = Clock::now();
        spent[section] += now - mark;
        mark = now;
        const uint8_t previous = section;
        section = next;
        return previous;
    }
};

// Invocations of one export on one thread, keyed by the export (names are attached when merging).
struct ExportCount {
    const ShaderExport* shader = nullptr;
    uint64_t count = 0;
};

// A note (Severity::Note) a dispatch may repeat millions of times (a RayQuery's SPIR-V-undefined uses): the log gets
// the occurrence with the smallest launch index this thread met, `more` counts the rest until foldNotes.
struct NoteTally {
    bool logged = false;
    uint64_t orderKey = 0;
    uint64_t more = 0;
    Diagnostic first;
};

struct WaveLane;

// The fields every TraceRay and invocation touches come first, together, and what only a diagnostic, a note or a
// profile touches last: a wave keeps 32 of these (1.2 KB each), and a TraceRay of every lane reads its lane's; spread
// over the state, the hot fields cost a wave's step several more cache lines a lane.
struct ThreadState {
    DispatchState* dispatch = nullptr;
    WaveLane* lane = nullptr;  // the wave lane this state belongs to (detail/wave.h); null for a probe
    // The worker thread's lookup cache: its wave's, which the wave's lanes share (they run one at a time on that
    // thread, and a cached lookup is a fact of the dispatch, not of a launch); a probe's own.
    LookupCache* lookups = nullptr;
    bool profiling = false;                 // DispatchOptions::profileStages
    uint32_t queriesTraced = 0;  // TraceRayInline calls on this launch: numbers RayQuery events
    uint64_t rayCounter = 0;
    GpuVirtualAddress lastTlasAddress = 0;  // one-entry cache of the TLAS lookup
    const TopLevelAS* lastTlas = nullptr;
    uvec3 launchIndex{0u};
    uint64_t linearIndex = 0;
    std::vector<Candidate> candidates;
    std::vector<const ShaderExport*> callChain;  // the shaders running on this launch, outermost first
    // Statistics beyond `stats`, in forms cheap to update; folded into `stats` when the dispatch ends.
    std::vector<ExportCount> exportCounts;  // in first-call order: a handful of exports, searched linearly
    DispatchStats stats;
    DiagnosticLog log;
    std::array<NoteTally, 3> queryNotes;  // ray_query.cpp: Proceed after FALSE, Abort, CommittedRayT with nothing
    std::vector<Diagnostic> stopErrors;  // OnError::Stop: the errors that ended a launch
    StageClock clock;
};

// Charges this thread's time to `stage` while alive, when profiling; otherwise one untaken branch each way.
class ProfileScope {
public:
    ProfileScope(ThreadState& ts, ProfileStage stage) : ts_(ts) {
        if (ts_.profiling) previous_ = ts_.clock.enter(uint8_t(stage));
    }
    ~ProfileScope() {
        if (ts_.profiling) ts_.clock.enter(previous_);
    }
    ProfileScope(const ProfileScope&) = delete;
    ProfileScope& operator=(const ProfileScope&) = delete;

private:
    ThreadState& ts_;
    uint8_t previous_ = StageClock::kOutside;
};

}  // namespace refray::dxr::detail
