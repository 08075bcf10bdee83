// A ray march over lanes, refilled from a queue of rays: a lane whose ray stops takes the queue's next ray at once,
// so the lanes keep marching until the queue is empty, rather than each group of N rays until its slowest one ends.
// The fractal marches' queues (julia::raycastQueue, mandelbulb::MandelbulbDistanceQueue in fractals.h) are this loop
// around their own step. Each ray takes the steps it takes alone, in its own lane, and a lane's result never depends
// on its neighbours (lanes.h), so every ray's result is bit for bit its one-ray march.
// PORT: not in the HLSL; a GPU runs a wave's marches in its lanes, each lane until its own ray ends.
#pragma once

#include <algorithm>
#include <array>
#include <bit>

#include "procedural/math/lanes.h"

namespace refray::procedural::math {

// The most rays a march queue takes: a wave's (32).
inline constexpr int kMaxMarchQueue = 32;

// marchQueue that may leave early, for a narrower march to finish: once the queue is empty and at most `leaveAt`
// lanes still march, it stores their rays' state (store) and returns the rays that have not stopped, bit k for ray
// k (0 when every ray ran to its end). taken(k) is how many steps ray k took before (a resumed march): it has
// maxSteps - taken(k) left.
// Groups > 1 marches Groups independent sets of L's lanes at each step (lane j is lane j % L::kCount of set
// j / L::kCount): step gets the sets' masks (std::array<LaneMask<L>, Groups>&) and runs them one after the other, so
// that the core overlaps their chains of dependent instructions (a latency-bound march over 16-float lanes, two
// 8-float halves, has room for more).
template <class L, int Groups = 1, class Marches, class Load, class Step, class Store, class Taken>
uint32_t marchQueueUntil(int count, int maxSteps, Marches&& marches, Load&& load, Step&& step, Store&& store,
                         int leaveAt, Taken&& taken) {
    constexpr int NL = L::kCount;
    constexpr int N = NL * Groups;
    static_assert(N <= 32, "a march queue's lanes are bits of a 32-bit mask");
    if (maxSteps <= 0) return 0;
    std::array<LaneMask<L>, size_t(Groups)> running;
    running.fill(LaneMask<L>(false));
    const auto runningBits = [&running] {
        uint32_t bits = 0;
        for (int g = 0; g < Groups; ++g) bits |= laneBits(running[size_t(g)]) << (g * NL);
        return bits;
    };
    std::array<int, size_t(N)> ray{};  // the ray each lane marches
    // A lane's ray has taken its last step once the queue's step count reaches the lane's deadline: the count when
    // the ray came in, plus the steps it has left (every running lane steps at every step of the queue).
    std::array<long long, size_t(N)> deadline{};
    long long stepsTaken = 0, nearestDeadline = maxSteps;
    int next = 0;
    // The next ray that marches into lane j; or, when the queue is empty, the lane left out.
    const auto fill = [&](int j) {
        while (next < count && !marches(next)) ++next;
        if (next == count) {
            setLane(running[size_t(j / NL)], j % NL, false);
            return;
        }
        ray[size_t(j)] = next;
        deadline[size_t(j)] = stepsTaken + maxSteps - taken(next);
        nearestDeadline = std::min(nearestDeadline, deadline[size_t(j)]);
        load(j, next++);
        setLane(running[size_t(j / NL)], j % NL, true);
    };
    for (int j = 0; j < N; ++j) fill(j);
    const int first = std::countr_zero(runningBits());  // 32 when no ray marches
    if (first >= N) return 0;
    for (int j = 0; j < N; ++j)
        if (!(runningBits() >> j & 1u)) load(j, ray[size_t(first)]);
    const LiveLanes queueLanes(laneBits(LaneMask<L>(true)), 0);  // the queue's lanes, whatever encloses it
    // Per step, the lanes whose ray stopped come from the masks (a few instructions), not from a pass over the lanes.
    for (uint32_t stepped = runningBits(); stepped; stepped = runningBits()) {
        if (next == count && std::popcount(stepped) <= leaveAt) {  // a narrower march takes the rest
            uint32_t left = 0;
            for (uint32_t live = stepped; live; live &= live - 1) {
                const int j = std::countr_zero(live);
                store(j, ray[size_t(j)]);
                left |= 1u << ray[size_t(j)];
            }
            return left;
        }
        if constexpr (Groups == 1) step(running[0]);
        else step(running);
        ++stepsTaken;
        uint32_t stopped = stepped & ~runningBits();
        if (stepsTaken >= nearestDeadline) {  // some running ray may have taken its last step
            nearestDeadline = stepsTaken + maxSteps;
            for (uint32_t live = stepped & ~stopped; live; live &= live - 1) {
                const int j = std::countr_zero(live);
                if (deadline[size_t(j)] <= stepsTaken) stopped |= 1u << j;
                else nearestDeadline = std::min(nearestDeadline, deadline[size_t(j)]);
            }
        }
        for (; stopped; stopped &= stopped - 1) {
            const int j = std::countr_zero(stopped);
            store(j, ray[size_t(j)]);  // the ray stopped, or took its last step
            fill(j);
        }
    }
    return 0;
}

// Marches rays 0..count-1 over the N lanes of L, each for at most maxSteps steps (none when maxSteps <= 0):
// - marches(k): whether ray k marches at all (a ray that does not keeps the state it starts with);
// - load(j, k): puts ray k's inputs and march state into lane j;
// - step(running): one march step over the lanes, which clears `running` for the lanes whose ray stops;
// - store(j, k): takes lane j's march state back to ray k, once its ray stopped or took its last step.
// The lanes with no ray hold the first ray's inputs (load of that ray again), so that their math stays sane; they
// never run and are never stored.
template <class L, class Marches, class Load, class Step, class Store>
void marchQueue(int count, int maxSteps, Marches&& marches, Load&& load, Step&& step, Store&& store) {
    marchQueueUntil<L, 1>(count, maxSteps, marches, load, step, store, 0, [](int) { return 0; });
}

}  // namespace refray::procedural::math
