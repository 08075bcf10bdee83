// Candidate gathering and order for one TraceRay. Internal to the emulator.
#pragma once

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"
#include "emulator/embree_bridge.h"

#include <vector>

namespace refray::dxr::detail {

// Gathers the candidates of rs.ray in rs.tlas (Embree broad phase + exact tests; FLAG-12 skips) into
// ts.candidates, in the order TRV-4 meets them (GEN-3). A FirstHit ray (GatherMode) has its candidates processed
// as Embree meets them and leaves ts.candidates empty.
void gatherOrderedCandidates(ThreadState& ts, RayState& rs, const Site& site);

// The candidates of a RayQuery (RQ-13): every candidate, in the same order, into the query's own `out` (queries
// and TraceRays may be live at once). No traversal shortcut: the owning shader decides for each candidate.
void gatherQueryCandidates(ThreadState& ts, RayState& rs, const Site& site, std::vector<Candidate>& out);

}  // namespace refray::dxr::detail
