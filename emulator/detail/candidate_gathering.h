// Candidate gathering and order for one TraceRay. Internal to the emulator.
#pragma once

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"

namespace refray::dxr::detail {

// Gathers the candidates of rs.ray in rs.tlas (Embree broad phase + exact tests; FLAG-12 skips) into
// ts.candidates, in the order TRV-4 meets them (GEN-3). A FirstHit ray (GatherMode) has its candidates processed
// as Embree meets them and leaves ts.candidates empty.
void gatherOrderedCandidates(ThreadState& ts, RayState& rs, const Site& site);

}  // namespace refray::dxr::detail
