// The wave executor's scheduling: lanes on fibers, parked at TraceRay or a wave call, resumed after their packet's
// traversal or their call.
#include "emulator/detail/wave.h"

#include <xmmintrin.h>

#include <optional>
#include <utility>

#include "core/error.h"
#include "emulator/closest_hit_wave.h"
#include "emulator/detail/lane_slots.h"
#include "emulator/detail/record_grouping.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/detail/trace_ray.h"

namespace refray::dxr::detail {

Wave::Wave(DispatchState& ds) {
    for (int i = 0; i < kMaxWaveWidth; ++i) {
        WaveLane& lane = lanes[size_t(i)];
        lane.ts.dispatch = &ds;
        lane.ts.lookups = &lookups;
        lane.ts.candidates.reserve(64);
        lane.ts.profiling = ds.options.profileStages;
        lane.ts.lane = &lane;
        lane.wave = this;
        lane.index = i;
    }
}

namespace {

// Resumes the fibers of `lanes` in lane order, each after asking the cache for the stack of the lane after it: a
// resumed lane's first touches of its frames stall (docs/performance.md).
void resumeLanes(Wave& wave, LaneMask lanes) {
    for (LaneMask::Iterator it = lanes.begin(); it != lanes.end();) {
        Fiber& fiber = *wave.fibers[size_t(*it)];
        ++it;
        if (it != lanes.end()) wave.fibers[size_t(*it)]->prefetch();
        fiber.resume();
    }
}

// Lane i's fiber, made on first use. Lane i's frames start 11*i lines (mod a page) below its stack's top: the lanes'
// hottest frames spread over the L1 cache's sets instead of sharing them (the stacks' mappings lie whole pages apart).
Fiber& laneFiber(Wave& wave, int i) {
    std::unique_ptr<Fiber>& fiber = wave.fibers[size_t(i)];
    if (!fiber) fiber = std::make_unique<Fiber>(Fiber::defaultStackBytes(), unsigned(i) * 11u % Fiber::kColours);
    return *fiber;
}

// Runs the started fibers of `lanes` until every one has ended: each runs until its next TraceRay, wave call or its
// end; then the waiting calls run grouped and their lanes go on, or, when no lane waits on a call, the parked rays
// traverse together and their lanes go on, until none is left.
void runLanes(Wave& wave, LaneMask lanes) {
    resumeLanes(wave, lanes);
    while (wave.parked.any() || wave.calling.any()) {
        if (wave.calling.any()) {
            const LaneMask calls = wave.calling;
            wave.calling = LaneMask();
            runWaveCalls(wave, calls);
            resumeLanes(wave, calls);
            continue;
        }
        const LaneMask packet = wave.parked;
        wave.parked = LaneMask();
        traversePacket(wave, packet);
        resumeLanes(wave, packet);
    }
}

}  // namespace

void openWave(Wave& wave, size_t lanes) {
    REFRAY_ASSERT(lanes <= size_t(kMaxWaveWidth), "a wave of " << lanes << " lanes");
    wave.parked = LaneMask();
    wave.calling = LaneMask();
    wave.grouped = lanes > 1;
    wave.schedulerMxcsr = _mm_getcsr();
    for (size_t i = 0; i < lanes; ++i) wave.lanes[i].failure = nullptr;
}

namespace {

// The MXCSR of the code that runs while it lives, put back when it ends.
class MxcsrScope {
public:
    explicit MxcsrScope(uint32_t mxcsr) : saved_(_mm_getcsr()) { set(mxcsr); }
    ~MxcsrScope() { set(saved_); }
    MxcsrScope(const MxcsrScope&) = delete;
    MxcsrScope& operator=(const MxcsrScope&) = delete;

private:
    static void set(uint32_t mxcsr) {
        if (_mm_getcsr() != mxcsr) _mm_setcsr(mxcsr);
    }
    uint32_t saved_;
};

}  // namespace

void runWave(Wave& wave, std::span<const uvec3> launches, const LaunchFunction& launch) {
    openWave(wave, launches.size());
    for (size_t i = 0; i < launches.size(); ++i) {
        WaveLane& lane = wave.lanes[i];
        lane.launch = launches[i];
        laneFiber(wave, int(i)).start([&launch, &lane] { launch(lane.ts, lane.launch); });  // two pointers: no allocation
    }
    runLanes(wave, LaneMask::first(int(launches.size())));
}

namespace {

// One lane's TraceRay in a wave's traceRaysInWave: its call, ray and payload copy, and where its failure goes.
struct LaneTrace {
    Invocation* caller = nullptr;
    const TraceRayCall* call = nullptr;
    RayState rs;
    std::optional<ValueCopy> payload;
    std::exception_ptr* failure = nullptr;
    // The rest of the lane's TraceRay, keeping what stops the lane's launch for its wave shader: finish runs its
    // closest-hit or miss shader and ends it; closestHit runs the closest-hit shader `hit` (prepareClosestHit's) and
    // ends it; end only ends it (the TraceRayEnd event, the payload back).
    void finish() {
        try {
            finishTraceRay(*caller, *call, rs, *payload);
        } catch (...) {
            *failure = std::current_exception();
        }
    }
    void closestHit(Invocation& hit) {
        try {
            invoke(*caller->thread, hit, rs.payload, rs.committedHit.attributes);
            endTraceRay(*caller, *call, rs, *payload);
        } catch (...) {
            *failure = std::current_exception();
        }
    }
    void end() {
        try {
            endTraceRay(*caller, *call, rs, *payload);
        } catch (...) {
            *failure = std::current_exception();
        }
    }
};

// A closest-hit shader written for waves, run once over `lanes`, the lanes of the wave whose rays selected it (their
// invocations in `hits`), on the wave's stack; each lane's TraceRay then ends as it ends alone.
void runClosestHitWave(Wave& wave, const ShaderExport& shader, LaneMask lanes, LaneSlots<LaneTrace>& traces,
                       LaneSlots<Invocation>& hits) {
    std::array<std::optional<ShaderContext>, kMaxWaveWidth> contexts;
    std::array<ShaderContext*, kMaxWaveWidth> contextOf{};
    std::array<void*, kMaxWaveWidth> payloads{};
    std::array<const void*, kMaxWaveWidth> attributes{};
    std::array<uint8_t, kMaxWaveWidth> callerSections{};
    for (int i : lanes) {
        callerSections[size_t(i)] = beginInvocation(*hits[i].thread, hits[i]);
        contextOf[size_t(i)] = &contexts[size_t(i)].emplace(hits[i]);
        payloads[size_t(i)] = traces[i].rs.payload;
        attributes[size_t(i)] = traces[i].rs.committedHit.attributes;
    }
    ClosestHitWave shaderWave(contextOf, lanes, &wave, payloads, attributes);
    std::exception_ptr escaped;
    {
        // The shader's own floating-point mode ends with it, as a lane's does with its fiber.
        const MxcsrScope callers(_mm_getcsr());
        try {
            shader.waveClosestHit(shaderWave);
        } catch (...) {
            escaped = std::current_exception();  // not one lane's: it stops every lane still running the shader
        }
    }
    for (int i : lanes) {
        LaneTrace& t = traces[i];
        endInvocation(*hits[i].thread, callerSections[size_t(i)]);
        if (shaderWave.failure(i)) *t.failure = shaderWave.failure(i);
        else if (escaped && shaderWave.isActive(i)) *t.failure = escaped;
        else t.end();
    }
}

}  // namespace

void traceRaysInWave(Wave& wave, const std::array<Invocation*, kMaxWaveWidth>& callers,
                     const TraceRayCall* calls, LaneMask lanes,
                     std::array<std::exception_ptr, kMaxWaveWidth>& failures) {
    LaneSlots<LaneTrace> traces;
    LaneMask packet, invoked;
    for (int i : lanes) {
        LaneTrace& t = traces.emplace(i);
        t.caller = callers[size_t(i)];
        t.call = &calls[size_t(i)];
        t.failure = &failures[size_t(i)];
        try {
            switch (beginTraceRay(*t.caller, *t.call, t.rs, t.payload)) {
                case TraceRayStart::Ended: continue;
                case TraceRayStart::Traverse: packet.set(i); break;
                case TraceRayStart::Invoke: break;
            }
            invoked.set(i);
        } catch (...) {
            failures[size_t(i)] = std::current_exception();
        }
    }
    if (packet.any()) {
        // The packet traverses in the scheduler's floating-point mode, as the packets of parked lanes do.
        const MxcsrScope scheduling(wave.schedulerMxcsr);
        for (int i : packet) {
            WaveLane& lane = wave.lanes[size_t(i)];
            lane.ray = &traces[i].rs;
            lane.site = siteOf(*traces[i].caller);
        }
        traversePacket(wave, packet);
        for (int i : packet) {
            WaveLane& lane = wave.lanes[size_t(i)];
            lane.ray = nullptr;
            if (lane.failure) {
                failures[size_t(i)] = std::move(lane.failure);
                lane.failure = nullptr;
                invoked.clear(i);
            }
        }
    }
    // Each lane's closest-hit or miss shader, in the caller's floating-point mode:
    // - a closest-hit shader written for waves runs once over the lanes that selected it (grouped by shader, each lane
    //   with its own record), on the wave's stack: their TraceRays go out together, and their closest hits run as
    //   waves in turn (runClosestHitWave);
    // - any other closest-hit shader runs on its lane's fiber, since it may trace rays of its own (parked and
    //   traversed together as the lanes of any wave);
    // - a lane without one (a miss shader, or none: a miss, SKIP_CLOSEST_HIT_SHADER, a NULL record) finishes here, on
    //   the wave's stack: a TraceRay from its miss shader traverses at once (awaitTraversal).
    LaneSlots<RecordView> records;
    LaneSlots<Invocation> hits;
    RecordGroups waveHits;
    LaneMask onFibers;
    for (int i : invoked) {
        LaneTrace& t = traces[i];
        if (!t.rs.committed) {
            t.finish();
            continue;
        }
        bool runs = false;
        try {
            runs = prepareClosestHit(*t.caller->thread, t.rs, siteOf(*t.caller), records.emplace(i), hits.emplace(i));
        } catch (...) {
            failures[size_t(i)] = std::current_exception();
            continue;
        }
        if (!runs) {
            t.end();
        } else if (hits[i].shader->waveClosestHit) {
            waveHits.add(i, hits[i].shader, 0);
        } else {
            laneFiber(wave, i).start([&t, &hit = hits[i]] { t.closestHit(hit); });  // two pointers
            onFibers.set(i);
        }
    }
    if (onFibers.any()) {
        const MxcsrScope scheduling(wave.schedulerMxcsr);
        runLanes(wave, onFibers);
    }
    for (const RecordGroups::Group& group : waveHits) runClosestHitWave(wave, *group.shader, group.lanes, traces, hits);
}

namespace {

// Whether the caller runs on `lane`'s own fiber (and may park there), not on the wave's stack.
bool onOwnFiber(const WaveLane& lane) {
    const Fiber* own = lane.wave->fibers[size_t(lane.index)].get();
    return own && Fiber::current() == own;
}

// Rethrows, on the lane's fiber, what stopped the lane while it waited.
void rethrowFailure(WaveLane& lane) {
    if (lane.failure) {
        std::exception_ptr failure = std::move(lane.failure);
        lane.failure = nullptr;
        std::rethrow_exception(failure);
    }
}

}  // namespace

void awaitTraversal(ThreadState& ts, RayState& rs, const Site& site) {
    WaveLane* lane = ts.lane;
    REFRAY_ASSERT(lane, "a TraceRay outside a wave lane");
    Wave& wave = *lane->wave;
    lane->ray = &rs;
    lane->site = site;
    if (onOwnFiber(*lane)) {
        wave.parked.set(lane->index);
        Fiber::yield();
    } else {
        // Off its lane's fiber (a miss shader that traceRaysInWave finishes on the wave's stack): the ray traverses at
        // once, a packet of one, in the scheduler's floating-point mode.
        const MxcsrScope scheduling(wave.schedulerMxcsr);
        traversePacket(wave, LaneMask::only(lane->index));
    }
    lane->ray = nullptr;
    rethrowFailure(*lane);
}

void awaitWaveCall(ThreadState& ts, const WaveFunction& function, const WaveCallKey& key, void* state) {
    WaveLane* lane = ts.lane;
    if (!lane || !lane->wave->grouped || !onOwnFiber(*lane)) {
        void* const alone[] = {state};
        function.run(std::span<void* const>(alone, 1));
        return;
    }
    lane->call = &function;
    lane->callKey = key;
    lane->callState = state;
    lane->wave->calling.set(lane->index);
    Fiber::yield();
    lane->call = nullptr;
    lane->callState = nullptr;
    rethrowFailure(*lane);
}

void runWaveCallsOfShader(Wave& wave, LaneMask lanes, const WaveCall* calls,
                          std::array<std::exception_ptr, kMaxWaveWidth>& failures) {
    for (int i : lanes) {
        WaveLane& lane = wave.lanes[size_t(i)];
        REFRAY_ASSERT(!lane.callState && !lane.failure, "lane " << i << " of a wave shader waits on a wave call");
        lane.call = calls[size_t(i)].function;
        lane.callKey = calls[size_t(i)].key;
        lane.callState = calls[size_t(i)].state;
    }
    {
        const MxcsrScope scheduling(wave.schedulerMxcsr);
        runWaveCalls(wave, lanes);
    }
    for (int i : lanes) {
        WaveLane& lane = wave.lanes[size_t(i)];
        lane.call = nullptr;
        lane.callState = nullptr;
        failures[size_t(i)] = std::exchange(lane.failure, nullptr);
    }
}

}  // namespace refray::dxr::detail
