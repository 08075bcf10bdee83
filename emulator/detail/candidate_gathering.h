// Candidate gathering and order for the TraceRays of a wave (Embree packets) and for a RayQuery. Internal to the
// emulator.
#pragma once

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/invocation.h"
#include "emulator/embree_bridge.h"

#include <exception>
#include <span>
#include <vector>

namespace refray::dxr::detail {

// One ray of a packet gather: its thread, ray and call site, the request the gather builds for it (whose traversal
// shortcuts reach the ray through it), and what stopped its gather.
struct GatherRay {
    ThreadState* ts = nullptr;
    RayState* rs = nullptr;
    const Site* site = nullptr;
    GatherRequest request;
    std::exception_ptr error;
};

// `ray` made ready for `rs` (its request is prepared by the gather), field by field in place: a GatherRay put together
// on the stack and copied was read back with wide loads across its narrow stores (a store-forwarding stall per ray).
inline void setGatherRay(GatherRay& ray, ThreadState& ts, RayState& rs, const Site& site) {
    ray.ts = &ts;
    ray.rs = &rs;
    ray.site = &site;
    ray.error = nullptr;
}

// Gathers the candidates of each of up to kMaxWaveWidth rays rs.ray in rs.tlas (Embree broad phase + exact tests;
// FLAG-12 skips) into its ts->candidates, in the order TRV-4 meets them (GEN-3). The rays that share a TLAS traverse
// in Embree packets of up to kMaxGatherPacket, in lane order, and each gets the candidates, order and statistics it
// gets alone. A FirstHit ray (GatherMode)
// traverses alone, has its candidates processed as Embree meets them and leaves its ts->candidates empty. What fails
// for one ray goes to its `error`; the others go on.
void gatherOrderedCandidates(std::span<GatherRay> rays);

// The candidates of a RayQuery (RQ-13): every candidate, in the same order, into the query's own `out` (queries
// and TraceRays may be live at once). No traversal shortcut: the owning shader decides for each candidate.
void gatherQueryCandidates(ThreadState& ts, RayState& rs, const Site& site, std::vector<Candidate>& out);

// gatherQueryCandidates for several queries' rays at once (the lanes of a wave whose queries trace together), ray k's
// candidates into outs[k]: the rays that share a TLAS traverse in Embree packets of up to kMaxGatherPacket, in order,
// and each gets the candidates, order and statistics it gets alone. What fails for one ray goes to its `error`.
void gatherQueryCandidatesPacket(std::span<GatherRay> rays, std::span<std::vector<Candidate>* const> outs);

}  // namespace refray::dxr::detail
