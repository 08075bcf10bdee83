// TraceRay. Internal to the emulator: shaders call ShaderContext::TraceRay.
#pragma once

#include <cstdint>

#include "emulator/detail/invocation.h"

namespace refray::dxr::detail {

// TraceRay (sections 4-10) from the shader `caller`: validation, candidate gathering, the TRV-4 loop, then the
// closest-hit or miss shader. The payload is copied in and out (RAY-9).
void traceRay(Invocation& caller, GpuVirtualAddress asAddress, uint32_t rayFlags, uint32_t mask, uint32_t r,
              uint32_t m, uint32_t missIndex, const RayDesc& ray, void* payload, TypeTag payloadType);

}  // namespace refray::dxr::detail
