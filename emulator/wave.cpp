// The wave executor's scheduling: lanes on fibers, parked at TraceRay or a wave call, resumed after their packet's
// traversal or their call.
#include "emulator/detail/wave.h"

#include "core/error.h"

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

}  // namespace

void runWave(Wave& wave, std::span<const uvec3> launches, const LaunchFunction& launch) {
    REFRAY_ASSERT(launches.size() <= size_t(kMaxWaveWidth), "a wave of " << launches.size() << " lanes");
    wave.parked = LaneMask();
    wave.calling = LaneMask();
    wave.grouped = launches.size() > 1;
    for (size_t i = 0; i < launches.size(); ++i) {
        WaveLane& lane = wave.lanes[i];
        lane.failure = nullptr;
        // Lane i's frames start 11*i lines (mod a page) below its stack's top: the lanes' hottest frames spread over
        // the L1 cache's sets instead of sharing them (the stacks' mappings lie whole pages apart).
        if (!wave.fibers[i])
            wave.fibers[i] = std::make_unique<Fiber>(Fiber::defaultStackBytes(), unsigned(i) * 11u % Fiber::kColours);
        lane.launch = launches[i];
        wave.fibers[i]->start([&launch, &lane] { launch(lane.ts, lane.launch); });  // two pointers: no allocation
    }
    // Each lane runs until its first TraceRay, wave call or its end; then the waiting calls run grouped and their
    // lanes go on, or, when no lane waits on a call, the parked rays traverse together and their lanes go on, until
    // none is left.
    resumeLanes(wave, LaneMask::first(int(launches.size())));
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

namespace {

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
    REFRAY_ASSERT(lane && Fiber::current(), "a TraceRay outside a wave lane");
    lane->ray = &rs;
    lane->site = site;
    lane->wave->parked.set(lane->index);
    Fiber::yield();
    lane->ray = nullptr;
    rethrowFailure(*lane);
}

void awaitWaveCall(ThreadState& ts, const WaveFunction& function, const WaveCallKey& key, void* state) {
    WaveLane* lane = ts.lane;
    if (!lane || !lane->wave->grouped || Fiber::current() != lane->wave->fibers[size_t(lane->index)].get()) {
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

}  // namespace refray::dxr::detail
