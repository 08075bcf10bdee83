// TracingWave: a shader run once for the lanes of a wave that issues their TraceRays together, as a GPU runs one
// shader over the threads of a wave. The shader runs its code lane by lane through each lane's ShaderContext
// (forEachLane) and its lanes' TraceRays as one call (TraceRay): their rays traverse as one packet (emulator/wave.h),
// their closest-hit and miss shaders run, and the shader goes on with every lane's payload filled in. Two stages are
// written this way: ray generation (emulator/ray_generation_wave.h) and closest hit (emulator/closest_hit_wave.h).
//
// Every lane's TraceRay is the one ShaderContext::TraceRay makes for it (its checks and diagnostics, events,
// statistics, candidates, shaders and payload), so every lane's result is the one a one-lane wave gives. A lane leaves
// the wave when something it does stops its launch (an error under OnError::Stop); the others go on.
#pragma once

#include <array>
#include <exception>
#include <span>
#include <utility>

#include "emulator/lane_mask.h"
#include "emulator/shader_api.h"
#include "emulator/trace_ray_call.h"

namespace refray::dxr {

namespace detail {
struct Wave;
}

class TracingWave {
public:
    // The lanes `active` of `contexts` (the others may be null); `wave` is the wave that runs them, or null for a
    // lane that runs alone (each lane's TraceRay is then its ShaderContext::TraceRay).
    TracingWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active, detail::Wave* wave);
    TracingWave(const TracingWave&) = delete;
    TracingWave& operator=(const TracingWave&) = delete;

    // The lanes the shader still runs for, and lane `lane`'s context.
    LaneMask active() const { return active_; }
    bool isActive(int lane) const { return active_.test(lane); }
    ShaderContext& lane(int lane) const { return *contexts_[size_t(lane)]; }

    // f(lane, ShaderContext&) for every active lane, in lane order. Anything `f` throws for a lane (a rule that
    // stops its launch) takes that lane out of the wave and is rethrown to its launch later.
    template <class F>
    void forEachLane(F&& f) {
        for (int i : active_) {
            try {
                f(i, *contexts_[size_t(i)]);
            } catch (...) {
                fail(i, std::current_exception());
            }
        }
    }

    // TraceRay for every active lane of `lanes`, lane i's with calls[i] (its payload is lane i's variable, filled in
    // when this returns). Lanes outside `lanes` trace nothing; `calls` reaches at least the highest lane of `lanes`.
    void TraceRay(LaneMask lanes, std::span<const TraceRayCall> calls);

    // The shape of a shader whose code runs in steps with TraceRays between them, over the wave: every active lane
    // runs the first step, `step(lane, ctx, state, call)`, which returns whether the lane traces a ray before the
    // next step (`call` its TraceRay, whose payload the lane's `state` may hold); the lanes' rays go out together;
    // then every active lane runs the next step, and so on (the last step's result is ignored). `state` is the lane's
    // own State, value-initialised, kept from step to step. A shader that runs alone keeps lane 0's only.
    template <class State, class... Steps>
    void TraceRaysInSteps(Steps&&... steps) {
        if (runsAlone()) inSteps<State, 1>(steps...);
        else inSteps<State, kMaxWaveWidth>(steps...);
    }

    // The shape of a shader with one TraceRay a launch, over the wave: each active lane runs its code up to the
    // TraceRay (`before(ctx, payload, call)`: whether the lane traces, with its payload set and its call built),
    // the lanes' TraceRays run together, then each lane runs its code after it (`after(ctx, payload, traced)`).
    template <class Payload, class Before, class After>
    void TraceRayInEachLane(Before&& before, After&& after) {
        struct Lane {
            Payload payload;
            bool traced;
        };
        TraceRaysInSteps<Lane>(
            [&](int, ShaderContext& ctx, Lane& l, TraceRayCall& call) {
                return l.traced = before(ctx, l.payload, call);
            },
            [&](int, ShaderContext& ctx, Lane& l, TraceRayCall&) {
                after(ctx, std::as_const(l.payload), l.traced);
                return false;
            });
    }

    // Whether the shader runs for one lane alone (lane 0; its export's ShaderExport::function, at a wave width of 1,
    // or where the stage's shader is called a lane at a time): a shader may then keep its lanes' state for lane 0
    // only.
    bool runsAlone() const { return wave_ == nullptr; }

    // For the emulator, after the shader: the exception that stopped lane `lane`, if any.
    std::exception_ptr failure(int lane) const { return failures_[size_t(lane)]; }

protected:
    // For a shader run for one lane alone (lane 0 of a wave without a Wave): rethrows what stopped the lane.
    void rethrowAloneFailure() const {
        if (failures_[0]) std::rethrow_exception(failures_[0]);
    }

private:
    void fail(int lane, std::exception_ptr failure);

    // TraceRaysInSteps with the state of N lanes (a wave's, or lane 0's alone).
    template <class State, int N, class... Steps>
    void inSteps(Steps&... steps) {
        std::array<State, N> states{};
        std::array<TraceRayCall, N> calls;
        size_t stepsRun = 0;
        const auto run = [&](auto& step) {
            LaneMask tracing;
            forEachLane([&](int i, ShaderContext& ctx) {
                if (step(i, ctx, states[size_t(i)], calls[size_t(i)])) tracing.set(i);
            });
            if (++stepsRun < sizeof...(Steps)) TraceRay(tracing, calls);
        };
        (run(steps), ...);
    }

    std::array<ShaderContext*, kMaxWaveWidth> contexts_;
    LaneMask active_;
    detail::Wave* wave_;
    std::array<std::exception_ptr, kMaxWaveWidth> failures_{};
};

}  // namespace refray::dxr
