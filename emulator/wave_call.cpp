// Wave calls (emulator/wave_call.h): the calls of a wave's waiting lanes, grouped by function and key as a GPU runs
// a function once for the threads of a wave that reach it, each group in calls of at most its function's
// lanesPerCall lanes, in lane order. Groups run in the order of their first lanes; no lane's outputs depend on the
// others (WaveFunction's contract), so neither grouping nor order changes a result.
#include <array>
#include <exception>

#include "emulator/detail/wave.h"

namespace refray::dxr::detail {

namespace {

bool sameCall(const WaveLane& a, const WaveLane& b) { return a.call == b.call && a.callKey == b.callKey; }

// One call over the lanes lane[0 .. count-1]: an exception stops every lane of the call (each rethrows it).
void runCall(Wave& wave, const WaveFunction& function, const std::array<int, kMaxWaveWidth>& lane, int count) {
    std::array<void*, kMaxWaveWidth> states{};
    for (int k = 0; k < count; ++k) states[size_t(k)] = wave.lanes[size_t(lane[size_t(k)])].callState;
    try {
        function.run(std::span<void* const>(states.data(), size_t(count)));
    } catch (...) {
        const std::exception_ptr failure = std::current_exception();
        for (int k = 0; k < count; ++k) wave.lanes[size_t(lane[size_t(k)])].failure = failure;
    }
}

}  // namespace

void runWaveCalls(Wave& wave, LaneMask lanes) {
    while (lanes.any()) {
        const WaveLane& lead = wave.lanes[size_t(lanes.lowest())];
        const WaveFunction& function = *lead.call;
        const int perCall = function.lanesPerCall < 1 ? 1 : function.lanesPerCall;
        std::array<int, kMaxWaveWidth> lane{};
        int count = 0;
        LaneMask rest;
        for (int i : lanes) {
            if (!sameCall(wave.lanes[size_t(i)], lead)) {
                rest.set(i);
                continue;
            }
            lane[size_t(count++)] = i;
            if (count == perCall) {
                runCall(wave, function, lane, count);
                count = 0;
            }
        }
        if (count > 0) runCall(wave, function, lane, count);
        lanes = rest;
    }
}

}  // namespace refray::dxr::detail
