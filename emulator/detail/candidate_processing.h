// TRV-4 for one candidate, and ReportHit. Internal to the emulator.
#pragma once

#include <cstdint>

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"
#include "emulator/embree_bridge.h"

namespace refray::dxr::detail {

// Non-local exits (IS-10, AHS-4). They never carry errors and never leave the dispatcher.
struct IgnoreHitSignal {};
struct AcceptHitAndEndSearchSignal {};
struct EndSearchSignal {};

// TRV-4 for a triangle candidate: TRV-2, FLAG-10, FLAG-11, then the any-hit shader of a non-opaque one (OPQ-3),
// and the commit.
void processTriangle(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site);
// TRV-4 for an AABB candidate: FLAG-11, then the intersection shader, whose ReportHit commits (OPQ-4: none for a
// NULL hit group).
void processProcedural(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site);
// processProcedural in two steps, for the wave's record groups (emulator/detail/wave.h): the checks before the
// intersection shader (the interval, FLAG-11, the record, OPQ-4, PIPE-6), which fill `box`, `record` and `inv` (which
// points at them) and return whether the shader runs; then the call on its own.
bool prepareIntersection(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site, HitInfo& box,
                         RecordView& record, Invocation& inv);
void runIntersection(ThreadState& ts, RayState& rs, Invocation& inv);

// TRV-4 for `c`, the ray's next candidate: skips it or runs its intersection or any-hit shader, and commits what
// they accept. Sets rs.searchEnded when the search has ended (FLAG-8, AHS-4, IS-10).
inline void processCandidate(ThreadState& ts, RayState& rs, const Candidate& c, const Site& site) {
    if (c.procedural) processProcedural(ts, rs, c, site);
    else processTriangle(ts, rs, c, site);
}

// ReportHit (IS-3..IS-9): the body behind ShaderContext::ReportHit. `inv` is the intersection
// shader's invocation: its record is the hit group, its candidateOpaque the box's OPQ-1 opacity.
bool reportHit(Invocation& inv, float tHit, uint32_t hitKind, const void* attributes, TypeTag type);

}  // namespace refray::dxr::detail
