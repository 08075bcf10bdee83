// Packet traversal (docs/emulator.md, "Waves"): the parked TraceRays of a wave traverse together. Each ray gathers
// and orders its candidates exactly as alone (GEN-3), then the packet walks the rays' candidates in rounds: a lane
// handles its candidates in its ray's order until it reaches one whose intersection shader is written for waves;
// there it waits, grouped with the other lanes waiting on the same record (record_grouping.h), and each group's
// shader runs once over its lanes. A lane's candidates, shader calls, commits and diagnostics are those of the ray
// traced alone: lanes share nothing but the shader call.
#include <array>
#include <optional>

#include "emulator/detail/candidate_gathering.h"
#include "emulator/detail/candidate_processing.h"
#include "emulator/detail/record_grouping.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/detail/trace_events.h"
#include "emulator/detail/wave.h"
#include "emulator/intersection_wave.h"

namespace refray::dxr::detail {

namespace {

void emitCandidate(const ThreadState& ts, const RayState& rs, const Candidate& c) {
    TraceEvent e = event(ts, TraceEvent::Kind::Candidate, rs.depth);
    setHit(e, rs.tlas->instances()[c.instanceIndex], c.instanceIndex, c.geometryIndex, c.primitiveIndex);
    e.procedural = c.procedural;
    e.t = c.procedural ? c.key : c.t;
    observer(ts)->onEvent(e);
}

// TRV-4 for the lane's next candidates, in order, until its search ends, its candidates run out (true: the lane is
// done) or it reaches an intersection shader written for waves (false: lane.intersection is prepared).
bool advanceLane(WaveLane& lane) {
    ThreadState& ts = lane.ts;
    RayState& rs = *lane.ray;
    // Nested TraceRays (from the CHS that follows) reuse ts.candidates: they start only after this ray's search.
    while (lane.nextCandidate < ts.candidates.size() && !rs.searchEnded) {
        const Candidate c = ts.candidates[lane.nextCandidate++];
        if (observer(ts)) emitCandidate(ts, rs, c);
        if (!c.procedural) {
            processTriangle(ts, rs, c, lane.site);
            continue;
        }
        if (!prepareIntersection(ts, rs, c, lane.site, lane.box, lane.record, lane.intersection)) continue;
        if (lane.intersection.shader->waveIntersection) return false;
        runIntersection(ts, rs, lane.intersection);
    }
    return true;
}

// One call of a record group's intersection shader over `count` of its lanes: call lane k is wave lane waveLane[k].
void runIntersectionCall(Wave& wave, const ShaderExport& shader, const std::array<int, kMaxWaveWidth>& waveLane,
                         int count) {
    std::array<std::optional<ShaderContext>, kMaxWaveWidth> contexts;
    std::array<ShaderContext*, kMaxWaveWidth> lanes{};
    std::array<uint8_t, kMaxWaveWidth> callerSections{};
    for (int k = 0; k < count; ++k) {
        WaveLane& lane = wave.lanes[size_t(waveLane[size_t(k)])];
        callerSections[size_t(k)] = beginInvocation(lane.ts, lane.intersection);
        lanes[size_t(k)] = &contexts[size_t(k)].emplace(lane.intersection);
    }
    IntersectionWave shaderWave(lanes, LaneMask::first(count));
    std::exception_ptr escaped;
    try {
        shader.waveIntersection(shaderWave);
    } catch (...) {
        escaped = std::current_exception();  // not one lane's: it stops every lane still running the shader
    }
    for (int k = 0; k < count; ++k) {
        WaveLane& lane = wave.lanes[size_t(waveLane[size_t(k)])];
        endInvocation(lane.ts, callerSections[size_t(k)]);
        if (shaderWave.failure(k)) lane.failure = shaderWave.failure(k);
        else if (escaped && shaderWave.isActive(k)) lane.failure = escaped;
        else if (lane.intersection.searchEnded || shaderWave.endedByUnwinding(k)) lane.ray->searchEnded = true;
    }
}

// One record group's intersection shader, run over its lanes in calls of at most the shader's waveLanesPerCall
// lanes (the width of its SIMD math), in lane order.
void runIntersectionGroup(Wave& wave, LaneMask group) {
    const ShaderExport& shader = *wave.lanes[size_t(group.lowest())].intersection.shader;
    std::array<int, kMaxWaveWidth> waveLane{};
    int count = 0;
    for (int i : group) {
        waveLane[size_t(count++)] = i;
        if (count == shader.waveLanesPerCall) {
            runIntersectionCall(wave, shader, waveLane, count);
            count = 0;
        }
    }
    if (count > 0) runIntersectionCall(wave, shader, waveLane, count);
}

}  // namespace

void traversePacket(Wave& wave, LaneMask lanes) {
    // The rays gather their candidates in Embree packets of up to 16 (each ray's candidates, order and statistics are
    // those it gets alone).
    std::array<GatherRay, kMaxWaveWidth> gathers;
    std::array<int, kMaxWaveWidth> laneOf{};
    size_t count = 0;
    for (int i : lanes) {
        WaveLane& lane = wave.lanes[size_t(i)];
        laneOf[count] = i;
        setGatherRay(gathers[count++], lane.ts, *lane.ray, lane.site);
    }
    gatherOrderedCandidates(std::span(gathers.data(), count));
    LaneMask running;
    for (size_t k = 0; k < count; ++k) {
        WaveLane& lane = wave.lanes[size_t(laneOf[k])];
        if (gathers[k].error) {
            lane.failure = gathers[k].error;
            continue;
        }
        lane.nextCandidate = 0;
        running.set(laneOf[k]);
    }
    RecordGroups groups;
    while (running.any()) {
        groups.clear();
        for (int i : running) {
            WaveLane& lane = wave.lanes[size_t(i)];
            bool done = true;
            try {
                done = advanceLane(lane);
            } catch (...) {
                lane.failure = std::current_exception();
            }
            if (done) running.clear(i);
            else groups.add(i, lane.intersection.shader, lane.record.address);
        }
        for (const RecordGroups::Group& group : groups) {
            runIntersectionGroup(wave, group.lanes);
            for (int i : group.lanes)
                if (wave.lanes[size_t(i)].failure) running.clear(i);
        }
    }
}

}  // namespace refray::dxr::detail
