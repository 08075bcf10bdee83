// Candidate gathering and order: the Embree broad phase with refray's exact tests, the traversal shortcuts it
// may take (GatherMode), and the order in which candidates meet the DXR rules (GEN-3).
#include "emulator/detail/candidate_gathering.h"

#include <algorithm>
#include <array>
#include <random>

#include "emulator/detail/candidate_processing.h"
#include "emulator/detail/candidate_rules.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_events.h"

namespace refray::dxr::detail {

namespace {

// Closest: an in-range triangle the ordered loop commits whenever it reaches it: not culled, and either
// opaque or in a pipeline without any-hit shaders (then nothing can ignore it).
bool commitsSurely(const void* user, const Candidate& c) {
    const auto& sc = *static_cast<const GatherRay*>(user);
    const BuiltInstance& inst = sc.rs->tlas->instances()[c.instanceIndex];
    const BuiltGeometry& geom = inst.blas->geometries()[c.geometryIndex];
    const uint32_t flags = sc.rs->effectiveFlags;
    if (isFaceCulled(flags, inst.desc.Flags, isFrontFacing(geom, c, inst.desc.Flags))) return false;
    const bool opaque = isOpaque(geom.flags, inst.desc.Flags, flags);
    if (isOpacityCulled(flags, opaque)) return false;
    return opaque || !sc.ts->dispatch->anyHitInPipeline;
}

// FirstHit: the TRV-4 step for one candidate, as Embree meets it.
bool processNow(void* user, const Candidate& c) {
    auto& sc = *static_cast<GatherRay*>(user);
    sc.ts->stats.candidates++;
    processCandidate(*sc.ts, *sc.rs, c, *sc.site);
    return sc.rs->searchEnded;
}

// The shortcut a ray may take: none when it is observed, in adversarial order or with shortcuts off;
// FirstHit when no order can change its outcome and no intersection shader of the pipeline runs in record groups
// (FirstHit runs its candidates inside Embree's traversal, one ray at a time); else Closest.
GatherMode traversalMode(const ThreadState& ts, const RayState& rs) {
    const DispatchState& ds = *ts.dispatch;
    if (!ds.options.specialise || observer(ts) || ds.options.order != TraversalOrder::Ordered) return GatherMode::All;
    const uint32_t firstHit = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;
    if ((rs.effectiveFlags & firstHit) == firstHit && !ds.anyHitInPipeline && !ds.waveIntersectionInPipeline)
        return GatherMode::FirstHit;
    return GatherMode::Closest;
}

// Orders candidates per DispatchOptions::order (GEN-3).
void orderCandidates(ThreadState& ts, RayState& rs, std::vector<Candidate>& cs) {
    const auto before = [](const Candidate& a, const Candidate& b) {
        if (a.key != b.key) return a.key < b.key;
        if (a.instanceIndex != b.instanceIndex) return a.instanceIndex < b.instanceIndex;
        if (a.geometryIndex != b.geometryIndex) return a.geometryIndex < b.geometryIndex;
        return a.primitiveIndex < b.primitiveIndex;
    };
    // One candidate per primitive: Embree may report a primitive more than once (AHS-6, IS-1).
    const auto samePrimitive = [](const Candidate& a, const Candidate& b) {
        return a.instanceIndex == b.instanceIndex && a.geometryIndex == b.geometryIndex &&
               a.primitiveIndex == b.primitiveIndex;
    };
    // Most rays meet one or two candidates (1.26 a ray on the D3D12 view): those without std::sort and std::unique.
    if (cs.size() == 2) {
        if (before(cs[1], cs[0])) std::swap(cs[0], cs[1]);
        if (samePrimitive(cs[0], cs[1])) cs.pop_back();
    } else if (cs.size() > 2) {
        std::sort(cs.begin(), cs.end(), before);
        cs.erase(std::unique(cs.begin(), cs.end(), samePrimitive), cs.end());
    }
    if (ts.dispatch->options.order != TraversalOrder::Adversarial) return;

    std::mt19937_64 rng(ts.dispatch->options.adversarialSeed * 0x9E3779B97F4A7C15ull ^ (ts.linearIndex << 20) ^
                        ts.rayCounter);
    const size_t n = cs.size();
    for (size_t i = 0; i < n; ++i) {
        const Candidate& c = cs[i];
        const BuiltGeometry& g = rs.tlas->instances()[c.instanceIndex].blas->geometries()[c.geometryIndex];
        if (!(g.flags & GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION) && (rng() & 1)) cs.push_back(c);
    }
    std::shuffle(cs.begin(), cs.end(), rng);
}

// The request of `ray` (its candidates into `out`, gathered in `mode`), counted in the statistics.
void prepare(GatherRay& ray, std::vector<Candidate>& out, GatherMode mode) {
    ThreadState& ts = *ray.ts;
    const RayState& rs = *ray.rs;
    const DispatchState& ds = *ts.dispatch;
    out.clear();
    // Every field set in place (a request assigned from a temporary was copied across its narrow stores).
    GatherRequest& gather = ray.request;
    gather.tlas = rs.tlas;
    gather.origin = rs.ray.Origin;
    gather.direction = rs.ray.Direction;
    gather.tMin = rs.ray.TMin;
    gather.tMax = rs.ray.TMax;
    gather.instanceInclusionMask = rs.instanceInclusionMask;
    gather.skipTriangles = (rs.effectiveFlags & RAY_FLAG_SKIP_TRIANGLES) != 0;  // FLAG-12
    gather.skipProcedural = (rs.effectiveFlags & RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES) != 0;
    gather.alternateEdgeRule = ds.options.order == TraversalOrder::Adversarial && (ds.options.adversarialSeed & 1);
    gather.out = &out;
    gather.user = &ray;
    gather.commitsSurely = commitsSurely;
    gather.onCandidate = processNow;
    gather.mode = mode;
    ts.stats.raysPerGatherMode[size_t(gather.mode)]++;
}

// After the traversal: the candidates counted and put in order.
void finish(GatherRay& ray) {
    std::vector<Candidate>& out = *ray.request.out;
    if (ray.request.mode != GatherMode::FirstHit) ray.ts->stats.candidates += out.size();
    else out.clear();  // processed during the traversal
    orderCandidates(*ray.ts, *ray.rs, out);
}

// One ray alone: `out` receives its candidates, gathered in `mode`.
void gatherAlone(ThreadState& ts, RayState& rs, const Site& site, std::vector<Candidate>& out, GatherMode mode) {
    GatherRay ray{&ts, &rs, &site, {}, nullptr};
    prepare(ray, out, mode);
    gatherCandidates(ray.request);
    finish(ray);
}

}  // namespace

namespace {

// The rays of `rays` marked `pending` (their requests prepared), in packets of the rays that share a TLAS, in order.
void gatherInPackets(std::span<GatherRay> rays, std::array<bool, kMaxWaveWidth>& pending) {
    for (size_t first = 0; first < rays.size(); ++first) {
        if (!pending[first]) continue;
        std::array<const GatherRequest*, kMaxGatherPacket> requests{};
        std::array<size_t, kMaxGatherPacket> index{};
        size_t count = 0;
        for (size_t i = first; i < rays.size() && count < size_t(kMaxGatherPacket); ++i)
            if (pending[i] && rays[i].request.tlas == rays[first].request.tlas) {
                pending[i] = false;
                index[count] = i;
                requests[count++] = &rays[i].request;
            }
        std::array<std::exception_ptr, kMaxGatherPacket> errors{};
        gatherCandidatesPacket(std::span(requests.data(), count), std::span(errors.data(), count));
        for (size_t k = 0; k < count; ++k) {
            GatherRay& ray = rays[index[k]];
            if (errors[k]) ray.error = errors[k];
            else finish(ray);
        }
    }
}

}  // namespace

void gatherOrderedCandidates(std::span<GatherRay> rays) {
    // Rays that take FirstHit go alone (their candidates are processed inside the traversal); the others traverse
    // in packets of the rays that share a TLAS, in the order of their lanes.
    std::array<bool, kMaxWaveWidth> pending{};
    for (size_t i = 0; i < rays.size(); ++i) {
        GatherRay& ray = rays[i];
        const GatherMode mode = traversalMode(*ray.ts, *ray.rs);
        if (mode != GatherMode::FirstHit) {
            prepare(ray, ray.ts->candidates, mode);
            pending[i] = true;
            continue;
        }
        try {
            gatherAlone(*ray.ts, *ray.rs, *ray.site, ray.ts->candidates, mode);
        } catch (...) {
            ray.error = std::current_exception();
        }
    }
    gatherInPackets(rays, pending);
}

void gatherQueryCandidates(ThreadState& ts, RayState& rs, const Site& site, std::vector<Candidate>& out) {
    gatherAlone(ts, rs, site, out, GatherMode::All);
}

void gatherQueryCandidatesPacket(std::span<GatherRay> rays, std::span<std::vector<Candidate>* const> outs) {
    std::array<bool, kMaxWaveWidth> pending{};
    for (size_t i = 0; i < rays.size(); ++i) {
        prepare(rays[i], *outs[i], GatherMode::All);
        pending[i] = true;
    }
    gatherInPackets(rays, pending);
}

}  // namespace refray::dxr::detail
