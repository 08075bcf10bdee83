// A ray march over lanes, refilled from a queue of rays: a lane whose ray stops takes the queue's next ray at once,
// so the lanes keep marching until the queue is empty, rather than each group of N rays until its slowest one ends.
// The fractal marches' queues (julia::raycastQueue, mandelbulb::MandelbulbDistanceQueue in fractals.h) are this loop
// around their own step. Each ray takes the steps it takes alone, in its own lane, and a lane's result never depends
// on its neighbours (lanes.h), so every ray's result is bit for bit its one-ray march.
// PORT: not in the HLSL; a GPU runs a wave's marches in its lanes, each lane until its own ray ends.
#pragma once

#include <array>
#include <bit>

#include "procedural/math/lanes.h"

namespace refray::procedural::math {

// The most rays a march queue takes: a wave's (32).
inline constexpr int kMaxMarchQueue = 32;

// Marches rays 0..count-1 over the N lanes of L, each for at most maxSteps steps (none when maxSteps <= 0):
// - marches(k): whether ray k marches at all (a ray that does not keeps the state it starts with);
// - load(j, k): puts ray k's inputs and march state into lane j;
// - step(running): one march step over the lanes, which clears `running` for the lanes whose ray stops;
// - store(j, k): takes lane j's march state back to ray k, once its ray stopped or took its last step.
// The lanes with no ray hold the first ray's inputs (load of that ray again), so that their math stays sane; they
// never run and are never stored.
template <class L, class Marches, class Load, class Step, class Store>
void marchQueue(int count, int maxSteps, Marches&& marches, Load&& load, Step&& step, Store&& store) {
    constexpr int N = L::kCount;
    if (maxSteps <= 0) return;
    LaneMask<L> running(false);
    std::array<int, size_t(N)> ray{};  // the ray each lane marches
    std::array<int, size_t(N)> steps{};
    int next = 0;
    // The next ray that marches into lane j; or, when the queue is empty, the lane left out.
    const auto fill = [&](int j) {
        while (next < count && !marches(next)) ++next;
        if (next == count) {
            setLane(running, j, false);
            return;
        }
        ray[size_t(j)] = next;
        steps[size_t(j)] = 0;
        load(j, next++);
        setLane(running, j, true);
    };
    for (int j = 0; j < N; ++j) fill(j);
    const int first = std::countr_zero(laneBits(running));  // 32 when no ray marches
    if (first >= N) return;
    for (int j = 0; j < N; ++j)
        if (!lane(running, j)) load(j, ray[size_t(first)]);
    const LiveLanes queueLanes(laneBits(LaneMask<L>(true)), 0);  // the queue's lanes, whatever encloses it
    while (anyLane(running)) {
        const LaneMask<L> stepped = running;
        step(running);
        for (int j = 0; j < N; ++j) {
            if (!lane(stepped, j)) continue;
            if (lane(running, j) && ++steps[size_t(j)] < maxSteps) continue;
            store(j, ray[size_t(j)]);  // the ray stopped, or took its last step
            fill(j);
        }
    }
}

}  // namespace refray::procedural::math
