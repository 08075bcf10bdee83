// TracingWave: a shader run once for the lanes of a wave that issues their TraceRays together, as a GPU runs one
// shader over the threads of a wave (emulator/shader_wave.h). The shader runs its code lane by lane through each
// lane's ShaderContext (forEachLane) and its lanes' TraceRays as one call (TraceRay): their rays traverse as one packet
// (emulator/wave.h), their closest-hit and miss shaders run, and the shader goes on with every lane's payload filled
// in. Two stages are written this way: ray generation (emulator/ray_generation_wave.h) and closest hit
// (emulator/closest_hit_wave.h).
//
// Every lane's TraceRay is the one ShaderContext::TraceRay makes for it (its checks and diagnostics, events,
// statistics, candidates, shaders and payload), so every lane's result is the one a one-lane wave gives. A lane leaves
// the wave when something it does stops its launch (an error under OnError::Stop); the others go on.
#pragma once

#include <array>
#include <exception>
#include <span>
#include <utility>

#include "emulator/shader_wave.h"
#include "emulator/trace_ray_call.h"

namespace refray::dxr {

class TracingWave : public ShaderWave {
public:
    using ShaderWave::ShaderWave;

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
        if (runsAlone()) {
            std::array<State, 1> states{};
            inSteps(std::span<State>(states), steps...);
        } else {
            std::array<State, kMaxWaveWidth> states{};
            inSteps(std::span<State>(states), steps...);
        }
    }
    // The same with the lanes' states kept by the shader (states[i] lane i's; it reaches the highest active lane):
    // for a shader whose lanes did something together before the first step (ShaderWave::CallsInLoop).
    template <class State, class... Steps>
    void TraceRaysInSteps(std::span<State> states, Steps&&... steps) {
        inSteps(states, steps...);
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

private:
    // TraceRaysInSteps with the lanes' states `states` (a wave's, or lane 0's alone).
    template <class State, class... Steps>
    void inSteps(std::span<State> states, Steps&... steps) {
        std::array<TraceRayCall, kMaxWaveWidth> calls;
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
};

}  // namespace refray::dxr
