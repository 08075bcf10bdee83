// DispatchStats: merging per-thread statistics and reading them back.
#include "emulator/dispatch_stats.h"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace refray::dxr {

namespace {

void addPerDepth(std::vector<uint64_t>& into, const std::vector<uint64_t>& from) {
    if (into.size() < from.size()) into.resize(from.size());
    for (size_t i = 0; i < from.size(); ++i) into[i] += from[i];
}

auto exportOrder(const ExportInvocations& e) { return std::tuple(uint8_t(e.stage), std::string_view(e.exportName)); }

}  // namespace

std::string toString(const RayTypeKey& key) {
    return "R=" + std::to_string(key.rayContribution) + " miss=" + std::to_string(key.missShaderIndex);
}

uint64_t RayTypeCounts::total() const { return std::accumulate(raysPerDepth.begin(), raysPerDepth.end(), uint64_t(0)); }

std::string_view toString(ProfileStage stage) {
    if (stage == ProfileStage::Traversal) return "traversal";
    if (stage == ProfileStage::Compute) return "compute";
    return toString(ShaderStage(uint8_t(stage)));
}

void DispatchStats::merge(const DispatchStats& o) {
    raysTraced += o.raysTraced;
    candidates += o.candidates;
    rayQueries += o.rayQueries;
    queryCandidates += o.queryCandidates;
    queryCommits += o.queryCommits;
    for (size_t i = 0; i < raysPerGatherMode.size(); ++i) raysPerGatherMode[i] += o.raysPerGatherMode[i];
    addPerDepth(raysPerDepth, o.raysPerDepth);
    for (size_t i = 0; i < invocations.size(); ++i) invocations[i] += o.invocations[i];

    for (const RayTypeCounts& t : o.raysPerType) {
        auto at = std::lower_bound(raysPerType.begin(), raysPerType.end(), t.key,
                                   [](const RayTypeCounts& a, const RayTypeKey& k) { return a.key < k; });
        if (at == raysPerType.end() || at->key != t.key) at = raysPerType.insert(at, RayTypeCounts{t.key, {}});
        addPerDepth(at->raysPerDepth, t.raysPerDepth);
    }
    for (const ExportInvocations& e : o.invocationsPerExport) {
        auto at = std::lower_bound(invocationsPerExport.begin(), invocationsPerExport.end(), e,
                                   [](const ExportInvocations& a, const ExportInvocations& b) { return exportOrder(a) < exportOrder(b); });
        if (at == invocationsPerExport.end() || exportOrder(*at) != exportOrder(e))
            at = invocationsPerExport.insert(at, ExportInvocations{e.exportName, e.stage, 0});
        at->count += e.count;
    }

    stagesProfiled = stagesProfiled || o.stagesProfiled;
    for (size_t i = 0; i < stageSeconds.size(); ++i) stageSeconds[i] += o.stageSeconds[i];
}

const RayTypeCounts* DispatchStats::raysOfType(RayTypeKey key) const {
    for (const RayTypeCounts& t : raysPerType)
        if (t.key == key) return &t;
    return nullptr;
}

uint64_t DispatchStats::raysOfType(RayTypeKey key, uint32_t depth) const {
    const RayTypeCounts* t = raysOfType(key);
    return t && depth < t->raysPerDepth.size() ? t->raysPerDepth[depth] : 0;
}

uint64_t DispatchStats::invocationsOf(std::string_view exportName, ShaderStage stage) const {
    for (const ExportInvocations& e : invocationsPerExport)
        if (e.stage == stage && e.exportName == exportName) return e.count;
    return 0;
}

double DispatchStats::profiledSeconds() const { return std::accumulate(stageSeconds.begin(), stageSeconds.end(), 0.0); }

}  // namespace refray::dxr
