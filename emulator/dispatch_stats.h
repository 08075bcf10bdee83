// What a dispatch simulated: rays per ray type and depth, shader invocations per export, and (when
// DispatchOptions::profileStages is set) where the time went, stage by stage.
//
// Counts are deterministic: they depend on the scene, the settings and the traversal order, never on the
// thread count or the order tiles finish. Times are measured on each worker and summed over workers.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "emulator/types.h"

namespace refray::dxr {

// A ray type as the indexing rule uses it: the TraceRay's RayContributionToHitGroupIndex, low 4 bits
// (IDX-2), and its MissShaderIndex, low 16 bits (IDX-7). The scene layer may name the keys it declares.
struct RayTypeKey {
    uint32_t rayContribution = 0;
    uint32_t missShaderIndex = 0;
    auto operator<=>(const RayTypeKey&) const = default;
};

// "R=0 miss=1".
std::string toString(const RayTypeKey& key);

struct RayTypeCounts {
    RayTypeKey key;
    std::vector<uint64_t> raysPerDepth;  // index = depth of the invoked shaders (1 = traced by ray generation)
    uint64_t total() const;
};

// How many times one export ran in one stage.
struct ExportInvocations {
    std::string exportName;
    ShaderStage stage = ShaderStage::RayGeneration;
    uint64_t count = 0;
};

// The sections a worker's time is split into. Each moment belongs to exactly one (exclusive times): a
// closest-hit shader's time excludes the rays it traces, which count as traversal and as the shaders they
// invoke. Traversal is TraceRay's own work: validation, Embree and candidate gathering, ordering, the
// TRV-4 loop and record lookups, without any shader time. The first six follow ShaderStage.
enum class ProfileStage : uint8_t { RayGeneration, Intersection, AnyHit, ClosestHit, Miss, Callable, Traversal, Compute };
inline constexpr size_t kProfileStageCount = 8;
constexpr ProfileStage profileStageOf(ShaderStage stage) {
    return stage == ShaderStage::Compute ? ProfileStage::Compute : ProfileStage(uint8_t(stage));
}
// "raygeneration", ..., "callable" (as ShaderStage), "traversal".
std::string_view toString(ProfileStage stage);

struct DispatchStats {
    uint64_t raysTraced = 0;
    std::vector<uint64_t> raysPerDepth;  // index = depth of the invoked shaders (1 = primary)
    std::array<uint64_t, kShaderStageCount> invocations{};  // by ShaderStage
    uint64_t candidates = 0;
    uint64_t rayQueries = 0;  // TraceRayInline calls (emulator/ray_query.h); their candidates count in `candidates`
    // Rays per traversal mode: every candidate gathered, the nearest sure commit bounding the gather, and
    // the occlusion query (DispatchOptions::specialise).
    std::array<uint64_t, 3> raysPerGatherMode{};

    // RayQuery (inline tracing), beside `rayQueries`: the candidates Proceed() handed to the shader (it returned
    // TRUE: non-opaque triangles and procedural primitives, each the shader decides on), and the commits (by Proceed
    // for opaque triangles, RQ-14, and by the shader). ACCEPT_FIRST_HIT_AND_END_SEARCH shows here (RQ-16).
    uint64_t queryCandidates = 0;
    uint64_t queryCommits = 0;

    // Rays per ray type and depth, sorted by key; a type appears once it traced a ray.
    std::vector<RayTypeCounts> raysPerType;
    // Invocations per export and stage, sorted by stage, then export name; only exports that ran.
    std::vector<ExportInvocations> invocationsPerExport;

    // Exclusive seconds per ProfileStage, summed over worker threads; all zero unless stagesProfiled.
    bool stagesProfiled = false;
    std::array<double, kProfileStageCount> stageSeconds{};

    void merge(const DispatchStats& other);
    uint64_t invocationsOf(ShaderStage s) const { return invocations[size_t(s)]; }
    // The rays of one type (nullptr if it traced none); its count at `depth` (0 if none).
    const RayTypeCounts* raysOfType(RayTypeKey key) const;
    uint64_t raysOfType(RayTypeKey key, uint32_t depth) const;
    // Invocations of an export in a stage (0 if it never ran there).
    uint64_t invocationsOf(std::string_view exportName, ShaderStage stage) const;
    double secondsIn(ProfileStage s) const { return stageSeconds[size_t(s)]; }
    double profiledSeconds() const;  // the sum of stageSeconds
};

}  // namespace refray::dxr
