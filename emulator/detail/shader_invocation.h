// Shader invocation: the checks before a shader runs, the call itself, and CallShader. Internal to the emulator.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"
#include "emulator/detail/thread_state.h"

namespace refray::dxr::detail {

// `inv` made an invocation of `shader` for `record` on this thread, at `depth`; `ray` and `hit` for the stages that
// have them. Field by field in place: an Invocation returned by value and assigned was copied with wide loads across
// the narrow stores that built it (a store-forwarding stall per invocation).
inline void setInvocation(Invocation& inv, ThreadState& ts, ShaderStage stage, const ShaderExport* shader,
                          const RecordView* record, uint32_t depth, RayState* ray = nullptr, HitInfo* hit = nullptr) {
    inv.stage = stage;
    inv.shader = shader;
    inv.record = record;
    inv.ray = ray;
    inv.hit = hit;
    inv.dispatch = ts.dispatch;
    inv.thread = &ts;
    inv.depth = depth;
    inv.candidateOpaque = true;
    inv.searchEnded = false;
}

// setInvocation's invocation, by value (for one constructed where it is declared).
inline Invocation invocation(ThreadState& ts, ShaderStage stage, const ShaderExport* shader, const RecordView* record,
                             uint32_t depth, RayState* ray = nullptr, HitInfo* hit = nullptr) {
    Invocation inv;
    setInvocation(inv, ts, stage, shader, record, depth, ray, hit);
    return inv;
}

// What a shader receives by value, a TraceRay payload (RAY-9) or CallShader parameters: a copy, on the stack up to
// 256 bytes, that copyBack returns to the caller.
class ValueCopy {
public:
    ValueCopy(const void* value, size_t size) : size_(size) {
        if (size > sizeof inline_) {
            heap_.reset(new uint8_t[size]);
            data_ = heap_.get();
        }
        std::memcpy(data_, value, size);
    }
    ValueCopy(const ValueCopy&) = delete;
    ValueCopy& operator=(const ValueCopy&) = delete;
    uint8_t* data() { return data_; }
    void copyBack(void* value) const { std::memcpy(value, data_, size_); }

private:
    alignas(16) uint8_t inline_[256];
    std::unique_ptr<uint8_t[]> heap_;
    uint8_t* data_ = inline_;
    size_t size_;
};

// PIPE-6: the shader's global root signature must be the one bound for the dispatch.
void checkGlobalSignature(ThreadState& ts, const Site& site, const ProgramEntry& entry);

// PAY-1: the shader's payload type must be the one its TraceRay passes.
void checkPayload(ThreadState& ts, const Site& site, const ShaderExport& shader, TypeTag traced);

// Runs `inv`'s shader with `payload` and `attributes`, counting the invocation and, when observed, emitting a
// ShaderCall event. Non-local exits (IgnoreHit, end of search) propagate to the caller.
void invoke(ThreadState& ts, Invocation& inv, void* payload, const void* attributes);
// invoke's bookkeeping around a shader call that runs elsewhere (a wave's intersection shader, for each of its
// lanes): beginInvocation counts and reports the call and enters its stage; endInvocation leaves it with what
// beginInvocation returned.
uint8_t beginInvocation(ThreadState& ts, const Invocation& inv);
void endInvocation(ThreadState& ts, uint8_t callerSection);

// CallShader (CALL-1, CALL-3) from the shader `caller`: the callable record at `shaderIndex`, run with a copy of
// `parameters` that is copied back. A NULL record returns with the parameters unchanged (REC-8).
void callShader(Invocation& caller, uint32_t shaderIndex, void* parameters, TypeTag type);

}  // namespace refray::dxr::detail
