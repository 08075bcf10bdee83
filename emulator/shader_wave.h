// ShaderWave: a shader run once for the lanes of a wave, as a GPU runs one shader over the threads of a wave, on the
// worker's own stack (no lane parks on a fiber). The shader runs its code lane by lane through each lane's
// ShaderContext (forEachLane) and issues its lanes' wave calls together (CallInWave, CallsInLoop: emulator/wave_call.h),
// which run grouped by function and key as the calls of lanes parked on their fibers do. A lane leaves the wave when
// something it does stops its launch (an error under OnError::Stop); the others go on. The stages written this way
// derive from it: those that trace rays (TracingWave: ray generation and closest hit) and compute (ComputeWave).
#pragma once

#include <array>
#include <exception>
#include <functional>
#include <span>

#include "emulator/lane_mask.h"
#include "emulator/shader_api.h"
#include "emulator/wave_call.h"

namespace refray::dxr {

namespace detail {
struct Wave;
}

class ShaderWave {
public:
    // The lanes `active` of `contexts` (the others may be null); `wave` is the wave that runs them, or null for a
    // lane that runs alone.
    ShaderWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active, detail::Wave* wave);
    ShaderWave(const ShaderWave&) = delete;
    ShaderWave& operator=(const ShaderWave&) = delete;

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

    // The wave calls of the active lanes of `lanes`, lane i's calls[i], made together: they run grouped by function
    // and key, each group in calls of at most its function's lanesPerCall lanes, in lane order, as the calls of
    // lanes that wait in ShaderContext::callInWave do (a shader that runs alone makes its lane's
    // ShaderContext::callInWave). Each lane's state holds its outputs when this returns. A call that throws stops the
    // launches of its lanes. `calls` reaches at least the highest lane of `lanes`.
    void CallInWave(LaneMask lanes, std::span<const WaveCall> calls);

    // The shape of a loop whose body makes a wave call, over the wave (a RayQuery's Proceed loop whose procedural
    // candidates' tests run as wave calls): every active lane of `lanes` runs `step(lane, ctx, call)`, which returns
    // whether the lane makes a wave call (`call`) before its next step; the calls run together (CallInWave); then the
    // lanes that made one step again, and so on until no lane makes a call.
    template <class Step>
    void CallsInLoop(LaneMask lanes, Step&& step) {
        std::array<WaveCall, kMaxWaveWidth> calls{};
        LaneMask looping(lanes.bits() & active_.bits());
        while (looping.any()) {
            LaneMask calling;
            for (int i : looping) {
                try {
                    if (step(i, *contexts_[size_t(i)], calls[size_t(i)])) calling.set(i);
                } catch (...) {
                    fail(i, std::current_exception());
                }
            }
            CallInWave(calling, calls);
            looping = LaneMask(calling.bits() & active_.bits());
        }
    }

    // Whether the shader runs for one lane alone (lane 0; its export's ShaderExport::function, at a wave width of 1,
    // or where the stage's shader is called a lane at a time): a shader may then keep its lanes' state for lane 0
    // only.
    bool runsAlone() const { return wave_ == nullptr; }

    // For the emulator, after the shader: the exception that stopped lane `lane`, if any.
    std::exception_ptr failure(int lane) const { return failures_[size_t(lane)]; }

protected:
    // Takes lane `lane` out of the wave, keeping what stopped it.
    void fail(int lane, std::exception_ptr failure);
    // For a shader run for one lane alone (lane 0 of a wave without a Wave): rethrows what stopped the lane.
    void rethrowAloneFailure() const {
        if (failures_[0]) std::rethrow_exception(failures_[0]);
    }
    // `shader`, written for waves of type W, run for `ctx`'s lane alone (width 1, `explain`, `--stats`): W is made for
    // lane 0 from `lanes` (W's per-lane arrays after the contexts, lane 0's entry set); what stopped the lane is
    // rethrown. Each kind's runAlone.
    template <class W, class... Lanes>
    static void runLaneAlone(const std::function<void(W&)>& shader, ShaderContext& ctx, const Lanes&... lanes) {
        std::array<ShaderContext*, kMaxWaveWidth> contexts{};
        contexts[0] = &ctx;
        W wave(contexts, LaneMask::only(0), nullptr, lanes...);
        shader(wave);
        static_cast<const ShaderWave&>(wave).rethrowAloneFailure();
    }
    detail::Wave* wave() const { return wave_; }

private:
    std::array<ShaderContext*, kMaxWaveWidth> contexts_;
    LaneMask active_;
    detail::Wave* wave_;
    std::array<std::exception_ptr, kMaxWaveWidth> failures_{};
};

}  // namespace refray::dxr
