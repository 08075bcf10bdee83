// Shader invocation: the checks before a shader runs, the call itself, and CallShader. Internal to the emulator.
#pragma once

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"

namespace refray::dxr::detail {

// PIPE-6: the shader's global root signature must be the one bound for the dispatch.
void checkGlobalSignature(ThreadState& ts, const Site& site, const ProgramEntry& entry);

// PAY-1: the shader's payload type must be the one its TraceRay passes.
void checkPayload(ThreadState& ts, const Site& site, const ShaderExport& shader, TypeTag traced);

// Runs `inv`'s shader with `payload` and `attributes`, counting the invocation and, when observed, emitting a
// ShaderCall event. Non-local exits (IgnoreHit, end of search) propagate to the caller.
void invoke(ThreadState& ts, Invocation& inv, void* payload, const void* attributes);

// CallShader (CALL-1, CALL-3) from the shader `caller`: the callable record at `shaderIndex`, run with a copy of
// `parameters` that is copied back. A NULL record returns with the parameters unchanged (REC-8).
void callShader(Invocation& caller, uint32_t shaderIndex, void* parameters, TypeTag type);

}  // namespace refray::dxr::detail
