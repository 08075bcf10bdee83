// TraceRay. Internal to the emulator: shaders call ShaderContext::TraceRay.
#pragma once

#include <cstdint>
#include <optional>

#include "emulator/detail/invocation.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/trace_ray_call.h"

namespace refray::dxr::detail {

struct Site;

// TraceRay (sections 4-10) from the shader `caller`: validation, candidate gathering, the TRV-4 loop, then the
// closest-hit or miss shader. The payload is copied in and out (RAY-9).
void traceRay(Invocation& caller, const TraceRayCall& call);

// TraceRay in its two halves, around the traversal, for a wave that traces its lanes' rays together
// (detail/wave.h, traceRaysInWave). beginTraceRay checks the arguments (LIM-2, RAY-10, FLAG-2..5, RAY-5, RAY-7,
// IDX-2), fills `rs`, copies the payload in (RAY-9), emits and counts the ray and finds its TLAS. Ended: the call
// ends there (an argument error, or no TLAS: no shader runs, the payload stays as it was); Traverse: the ray's
// candidates are to be gathered and processed (TRV-4) before finishTraceRay; Invoke: straight to finishTraceRay (a
// null acceleration structure, RAY-3, or a ray outside the traversal's range, RAY-7).
enum class TraceRayStart { Ended, Traverse, Invoke };
TraceRayStart beginTraceRay(Invocation& caller, const TraceRayCall& call, RayState& rs,
                            std::optional<ValueCopy>& payload);
// The closest-hit or miss shader (TRV-5, TRV-6), the TraceRayEnd event and the payload copied back.
void finishTraceRay(Invocation& caller, const TraceRayCall& call, RayState& rs, ValueCopy& payload);
// finishTraceRay for a closest hit that a wave runs (detail/wave.h): prepareClosestHit is TRV-5 up to the shader
// call (FLAG-9, the hit group's record and its lookup rules, PIPE-6, PAY-1), true with `inv` (which points at
// `record`) when a closest-hit shader runs; endTraceRay is what follows the shader (the TraceRayEnd event, the payload
// copied back).
bool prepareClosestHit(ThreadState& ts, RayState& rs, const Site& site, RecordView& record, Invocation& inv);
void endTraceRay(Invocation& caller, const TraceRayCall& call, RayState& rs, ValueCopy& payload);


// The ray's validity (RAY-5, or `rule` for another caller such as RQ-11) and the RAY-7 warnings; sets `ok` false
// after raising an error.
void validateRay(ThreadState& ts, const Site& site, const RayDesc& ray, bool& ok, const char* rule);

// FLAG-2..5 on rayFlags | pipelineFlags; returns false (and has raised) when they are invalid. With `queryRule`
// (RQ-5) the second set is a RayQuery's template flags and every exclusion is reported under that rule.
bool validateFlags(ThreadState& ts, const Site& site, uint32_t rayFlags, uint32_t pipelineFlags,
                   const char* queryRule = nullptr);

// Embree's range for origin and direction components; a ray beyond it (or NaN/infinite) is traced as a miss.
bool inTraversalRange(const RayDesc& ray);

// The TLAS at `asAddress` (a one-entry cache per thread), or null after raising RAY-1 / INST-10 under `rule`
// naming `intrinsic`; checks INST-8 once per epoch.
const TopLevelAS* findTopLevelAS(ThreadState& ts, const Site& site, GpuVirtualAddress asAddress);

}  // namespace refray::dxr::detail
