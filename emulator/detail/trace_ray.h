// TraceRay. Internal to the emulator: shaders call ShaderContext::TraceRay.
#pragma once

#include <cstdint>

#include "emulator/detail/invocation.h"

namespace refray::dxr::detail {

// TraceRay (sections 4-10) from the shader `caller`: validation, candidate gathering, the TRV-4 loop, then the
// closest-hit or miss shader. The payload is copied in and out (RAY-9).
void traceRay(Invocation& caller, GpuVirtualAddress asAddress, uint32_t rayFlags, uint32_t mask, uint32_t r,
              uint32_t m, uint32_t missIndex, const RayDesc& ray, void* payload, TypeTag payloadType);

struct Site;

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
