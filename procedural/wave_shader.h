// What the intersection-shader ports need to run over a wave's lanes (emulator/intersection_wave.h): the lane type of
// a library's scalar type, and the gathering of per-lane values (what a lane's intrinsics and resources give) into
// lanes. The scalar parts of a port (reading a lane's record and resources, turning its hit into attributes) run
// per lane with the scalar type, exactly as the one-ray code does; the march between them runs in lanes
// (procedural/math/lanes.h), so each lane's result is bit for bit the one-ray result.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <new>
#include <optional>
#include <type_traits>

#include "emulator/intersection_wave.h"
#include "procedural/math/lanes.h"
#include "procedural/math/ray.h"

namespace refray::procedural {

// How many lanes the ports' wave math holds (ShaderLibrary::addWaveIntersection's lanesPerCall): a record group of
// more lanes runs in calls of this many. 8 floats fill a 256-bit register. On this project's AVX-512 machine (AMD
// Zen 4) a 512-bit instruction runs as two 256-bit halves, so 16-float lanes cost twice as much per instruction
// and gain nothing at full occupancy, while a march runs until its slowest lane ends: the slowest of 8 rays ends
// sooner than the slowest of 16 (docs/performance.md, "Waves with 8-lane calls").
inline constexpr int kWaveLanes = 8;

// The lane type of a wave shader whose one-ray math runs in T.
template <typename T>
using WaveLanes = math::Lanes<T, kWaveLanes>;

// A value every lane of a wave reads alike, such as a global root argument (the scene's constants, the output
// texture): the first lane whose read succeeds reads it, and the lanes after it take that copy, each at the point
// where its code reads it (a lane whose read fails leaves the wave with its error, as it would alone).
// PORT: where a wave shader holds one, the HLSL reads the value in every lane.
template <class V>
class WaveShared {
public:
    template <class Read>
    const V& get(dxr::ShaderContext& ctx, Read&& read) {
        if (!value_) value_ = read(ctx);
        return *value_;
    }
    // What a lane read, or V{} when none has.
    V valueOrDefault() const { return value_.value_or(V{}); }

private:
    std::optional<V> value_;
};

// `read(ctx)` of an intersection record group's lanes, which all read it alike (their record's constants, a global
// root argument): read by the first lane whose read succeeds, through WaveShared (a lane whose read fails leaves the
// wave with its error); V{} when every lane's fails.
template <class Read>
auto readByTheGroup(dxr::IntersectionWave& wave, Read&& read) {
    WaveShared<std::decay_t<decltype(read(wave.lane(0)))>> shared;
    wave.forEachLane([&](int, dxr::ShaderContext& ctx) { shared.get(ctx, read); });
    return shared.valueOrDefault();
}

// f(lane's ShaderContext) for every active lane of `wave`, in lane order; an inactive lane gets the first active
// lane's value, so that the math over every lane runs on sane values (a NaN ray would keep a march running). A lane
// whose `f` throws (an error that stops its launch) leaves the wave (IntersectionWave::forEachLane).
// Each value is made where it lies (placement new takes f's result without a temporary: one assigned was copied with
// wider loads than the stores that made it, a store-forwarding stall per lane).
template <class F>
auto gatherLanes(dxr::IntersectionWave& wave, F f) {
    using V = decltype(f(wave.lane(0)));
    static_assert(std::is_trivially_destructible_v<V>);
    std::array<V, dxr::kMaxWaveWidth> values{};
    wave.forEachLane([&](int i, dxr::ShaderContext& ctx) {
        ::new (static_cast<void*>(&values[size_t(i)])) V(f(ctx));
    });
    const int first = wave.active().any() ? wave.active().lowest() : 0;
    for (int i = 0; i < dxr::kMaxWaveWidth; ++i)
        if (!wave.isActive(i)) values[size_t(i)] = values[size_t(first)];
    return values;
}

// The lanes of one value of every lane's input: lane i of the result is get(in[i]), for the Count lanes of its lane
// type (for a group of one lane, whose lane type is the scalar type itself, the value of its input, which every
// entry holds; gatherLanes).
template <class Result, int Count = kWaveLanes, class Input, class Get>
Result toLanes(const std::array<Input, dxr::kMaxWaveWidth>& in, Get get) {
    static_assert(Count >= 1 && Count <= dxr::kMaxWaveWidth);
    Result lanes{};
    for (int i = 0; i < Count; ++i) math::setLane(lanes, i, get(in[size_t(i)]));
    return lanes;
}

// The lanes of `lanes` through a march queue: item k of the queue is get(in[i]) for the k-th lane i of `lanes` (in
// lane order), `queue(items, count, results)` fills results[k] for item k, and each lane's result lands at its lane
// (the other lanes' stay Result{}).
template <class Result, class Input, class Get, class Queue>
std::array<Result, dxr::kMaxWaveWidth> throughQueue(dxr::LaneMask lanes, const std::array<Input, dxr::kMaxWaveWidth>& in,
                                                    Get get, Queue&& queue) {
    using Item = decltype(get(in[0]));
    static_assert(std::is_trivially_destructible_v<Item>);
    std::array<Item, dxr::kMaxWaveWidth> items{};
    std::array<Result, dxr::kMaxWaveWidth> results{}, byLane{};
    int count = 0;
    for (int i : lanes) ::new (static_cast<void*>(&items[size_t(count++)])) Item(get(in[size_t(i)]));  // in place
    queue(items.data(), count, results.data());
    count = 0;
    for (int i : lanes) byLane[size_t(i)] = results[size_t(count++)];
    return byLane;
}

// The lanes `lanes` of a wave in lane order, kWaveLanes at a time, for math that runs in WaveLanes: `group(lane, n)`
// for a group of n > 1 lanes, where lane[j] is the group's j-th wave lane for j < n and its first one beyond (the
// padding holds a filled lane's values, so that its math stays sane; only the first n lanes are live, LiveLanes), and
// `alone(i)` for a group of one lane, which runs in the scalar type (no lanes to pay for). The last group holds the
// remainder.
template <class Group, class Alone>
void inGroupsOfLanes(dxr::LaneMask lanes, Group&& group, Alone&& alone) {
    std::array<int, dxr::kMaxWaveWidth> order{};
    int count = 0;
    for (int i : lanes) order[size_t(count++)] = i;
    for (int first = 0; first < count; first += kWaveLanes) {
        const int n = std::min(kWaveLanes, count - first);
        if (n == 1) {
            alone(order[size_t(first)]);
            continue;
        }
        std::array<int, kWaveLanes> lane{};
        for (int j = 0; j < kWaveLanes; ++j) lane[size_t(j)] = order[size_t(j < n ? first + j : first)];
        const math::LiveLanes live(uint32_t(dxr::LaneMask::first(n).bits()), 0);
        group(lane, n);
    }
}

// Calls f.template operator()<L>() with the lane type a record group's math runs in: T itself for a group of one lane
// (nothing to keep in step, and no lanes to pay for), WaveLanes<T> for up to kWaveLanes lanes, and Lanes<T, Wide>
// for more (an export that takes Wide lanes a call: a latency-bound march, whose 16 float lanes are two independent
// 8-float chains). A scalar type without SIMD
// instructions (PerturbedFloat, whose every operation is a hash and a rounding) runs each lane alone in T, and so does
// double: its lanes are twice as wide as the 32-bit lane masks, so every compare and select goes lane by lane, and
// a double Julia render at 320x180 took 26.5 s in lanes against 1.05 s one lane at a time. All give each lane the
// same bits.
template <typename T, int Wide = kWaveLanes, class F>
void withLaneType(dxr::IntersectionWave& wave, F&& f) {
    static_assert(Wide >= kWaveLanes && Wide <= dxr::kMaxWaveWidth);
    if constexpr (!std::is_same_v<T, float>) {
        wave.forEachLaneAlone([&] { f.template operator()<T>(); });
    } else {
        // The lanes of a call are numbered from 0; the lane type must reach the highest active one.
        const int span = std::bit_width(wave.active().bits());
        if (wave.active().count() == 1) f.template operator()<T>();
        else if (Wide == kWaveLanes || span <= kWaveLanes) f.template operator()<WaveLanes<T>>();
        else if constexpr (Wide > kWaveLanes) {
            REFRAY_ASSERT(span <= Wide, "a record group call reaching lane " << span - 1 << " of " << Wide << " lanes");
            f.template operator()<math::Lanes<T, Wide>>();
        }
    }
}

}  // namespace refray::procedural
