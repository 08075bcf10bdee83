// IntersectionWave: an intersection shader run once for the lanes of a wave whose rays reached the same procedural
// record (emulator/wave.h, "record grouping"), as a GPU runs one shader over the threads it has grouped. A shader
// written for waves (ShaderLibrary::addWaveIntersection) computes its math over all lanes at once (procedural/math/
// lanes.h) and talks to the emulator lane by lane: every intrinsic is the lane's ShaderContext, every ReportHit is
// the lane's ReportHit with all of its rules (IS-3..IS-10, the any-hit shader it runs, the commit).
//
// A lane leaves the wave when its ReportHit ends its search (IS-10: no code of the shader runs for it after that) or
// when something it does stops its launch (an error under OnError::Stop): the others go on exactly as if each lane
// ran alone, so every lane's result is the one a one-lane wave gives.
#pragma once

#include <array>
#include <exception>
#include <functional>

#include "emulator/lane_mask.h"
#include "emulator/shader_api.h"

namespace refray::dxr {

class IntersectionWave {
public:
    // The lanes `active` of `contexts` (the others may be null).
    IntersectionWave(const std::array<ShaderContext*, kMaxWaveWidth>& contexts, LaneMask active);
    IntersectionWave(const IntersectionWave&) = delete;
    IntersectionWave& operator=(const IntersectionWave&) = delete;

    // The lanes the shader still runs for.
    LaneMask active() const { return active_; }
    bool isActive(int lane) const { return active_.test(lane); }
    // Lane `lane`'s context. An inactive lane reads the first active lane's, so that math over every lane reads
    // sane values; only active lanes' results count.
    ShaderContext& lane(int lane) const { return *contexts_[active_.test(lane) ? lane : fallback_]; }

    // f(lane, ShaderContext&) for every active lane, in lane order. Anything `f` throws for a lane (a rule that
    // stops its launch) takes that lane out of the wave and is rethrown to its launch later.
    template <class F>
    void forEachLane(F&& f) {
        for (int i : active_) {
            try {
                f(i, *contexts_[i]);
            } catch (...) {
                fail(i);
            }
        }
    }

    // f() once for each active lane alone (the wave narrowed to that lane meanwhile), in lane order: for a shader
    // whose scalar type has no SIMD instructions, one lane at a time costs less than lanes kept in step.
    template <class F>
    void forEachLaneAlone(F&& f) {
        const LaneMask all = active_;
        LaneMask left;
        for (int i : all) {
            active_ = LaneMask::only(i);
            fallback_ = i;
            f();
            if (!active_.test(i)) left.set(i);
        }
        active_ = LaneMask(all.bits() & ~left.bits());
        fallback_ = active_.any() ? active_.lowest() : 0;
    }

    // ReportHit for lane `lane` (it must be active). Returns what its ReportHit returns; the lane leaves the wave when
    // the hit ends its search.
    template <class Attributes>
    bool ReportHit(int lane, float THit, uint32_t HitKind, const Attributes& attributes) {
        bool accepted = false;
        try {
            accepted = contexts_[lane]->ReportHit(THit, HitKind, attributes);
        } catch (...) {
            endOrFail(lane);
            return true;
        }
        if (searchEnded(lane)) leave(lane);
        return accepted;
    }

    // Runs a wave shader for one lane alone (the export's ShaderExport::function): the lane's ReportHit ends the
    // shader as a scalar one would (ReportHitEnd), and what stopped the lane is rethrown.
    static void runAlone(const std::function<void(IntersectionWave&)>& shader, ShaderContext& ctx);

    // For the emulator, after the shader: whether lane `lane`'s ReportHit ended its search by unwinding
    // (ReportHitEnd::Unwind), and the exception that stopped it, if any.
    bool endedByUnwinding(int lane) const { return unwound_.test(lane); }
    std::exception_ptr failure(int lane) const { return failures_[lane]; }

private:
    bool searchEnded(int lane) const;
    void leave(int lane);
    void fail(int lane);
    void endOrFail(int lane);  // in a catch block: the search-ending signal, or a failure

    std::array<ShaderContext*, kMaxWaveWidth> contexts_;
    LaneMask active_;
    LaneMask unwound_;
    int fallback_ = 0;
    std::array<std::exception_ptr, kMaxWaveWidth> failures_{};
};

}  // namespace refray::dxr
