// The wave executor's scheduling: lanes on fibers, parked at TraceRay, resumed after their packet's traversal.
#include "emulator/detail/wave.h"

#include "core/error.h"

namespace refray::dxr::detail {

Wave::Wave(DispatchState& ds) {
    for (int i = 0; i < kMaxWaveWidth; ++i) {
        WaveLane& lane = lanes[size_t(i)];
        lane.ts.dispatch = &ds;
        lane.ts.candidates.reserve(64);
        lane.ts.profiling = ds.options.profileStages;
        lane.ts.lane = &lane;
        lane.wave = this;
        lane.index = i;
    }
}

void runWave(Wave& wave, std::span<const uvec3> launches, const LaunchFunction& launch) {
    REFRAY_ASSERT(launches.size() <= size_t(kMaxWaveWidth), "a wave of " << launches.size() << " lanes");
    wave.parked = LaneMask();
    for (size_t i = 0; i < launches.size(); ++i) {
        WaveLane& lane = wave.lanes[i];
        lane.failure = nullptr;
        if (!wave.fibers[i]) wave.fibers[i] = std::make_unique<Fiber>(Fiber::defaultStackBytes());
        lane.launch = launches[i];
        wave.fibers[i]->start([&launch, &lane] { launch(lane.ts, lane.launch); });  // two pointers: no allocation
    }
    // Each lane runs until its first TraceRay or its end; then the parked rays traverse together and their lanes
    // go on, until none is left.
    for (size_t i = 0; i < launches.size(); ++i) wave.fibers[i]->resume();
    while (wave.parked.any()) {
        const LaneMask packet = wave.parked;
        wave.parked = LaneMask();
        traversePacket(wave, packet);
        for (int i : packet) wave.fibers[size_t(i)]->resume();
    }
}

void awaitTraversal(ThreadState& ts, RayState& rs, const Site& site) {
    WaveLane* lane = ts.lane;
    REFRAY_ASSERT(lane && Fiber::current(), "a TraceRay outside a wave lane");
    lane->ray = &rs;
    lane->site = site;
    lane->wave->parked.set(lane->index);
    Fiber::yield();
    lane->ray = nullptr;
    if (lane->failure) {
        std::exception_ptr failure = std::move(lane->failure);
        lane->failure = nullptr;
        std::rethrow_exception(failure);
    }
}

}  // namespace refray::dxr::detail
