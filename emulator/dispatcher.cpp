// DispatchRays (RGS-1..3): the checks of the desc, the ray generation record, and the launches over oneTBB tiles.
#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <optional>
#include <span>

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "core/strings.h"
#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/dispatch_state.h"
#include "emulator/detail/record_lookup.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/wave.h"
#include "emulator/device.h"
#include "emulator/limits.h"
#include "emulator/compute_wave.h"
#include "emulator/ray_generation_wave.h"

namespace refray::dxr {

namespace {

using detail::DispatchState;
using detail::ThreadState;
using detail::Wave;
using Waves = tbb::enumerable_thread_specific<Wave>;

// Locks every table the dispatch reads for its whole duration (REC-12).
class TableLock {
public:
    TableLock(GpuMemory& memory, std::vector<GpuVirtualAddress> addresses) : memory_(memory), addresses_(std::move(addresses)) {
        for (auto a : addresses_) memory_.setLocked(a, true);
    }
    ~TableLock() {
        for (auto a : addresses_) memory_.setLocked(a, false);
    }
    TableLock(const TableLock&) = delete;
    TableLock& operator=(const TableLock&) = delete;

private:
    GpuMemory& memory_;
    std::vector<GpuVirtualAddress> addresses_;
};

void checkTableRange(const char* name, GpuVirtualAddress start, uint64_t size, uint64_t stride, bool hasStride) {
    if (start == 0 && size == 0) return;
    if (start % kShaderTableByteAlignment)
        throw DxrError(diag("REC-2", std::string(name) + " StartAddress is not a multiple of 64")
                           .hex("StartAddress", start)
                           .value("StartAddress % 64", start % kShaderTableByteAlignment, "0"));
    if (hasStride && (stride % kShaderRecordByteAlignment || stride > kMaxShaderRecordStride))
        throw DxrError(diag("REC-3", std::string(name) + " StrideInBytes must be a multiple of 32 in [0, 4096]")
                           .value("StrideInBytes", stride, "multiple of 32, <= 4096"));
}

// RGS-3, RGS-1, REC-2, REC-3, IDX-11: what DispatchRays is given, before anything runs. `launches` is
// Width*Height*Depth.
void checkDispatchDesc(const DispatchRaysDesc& desc, const StateObjectPtr& pipeline, uint64_t launches,
                       const GpuMemory& memory) {
    if (!pipeline)
        throw DxrError(diag("RGS-3", "DispatchRays without a bound ray-tracing pipeline state object"));
    if (launches > kMaxRayGenerationShaderThreads)
        throw DxrError(diag("RGS-1", "DispatchRays launches too many threads")
                           .value("Width*Height*Depth", launches, std::to_string(kMaxRayGenerationShaderThreads))
                           .value("Width", desc.Width)
                           .value("Height", desc.Height)
                           .value("Depth", desc.Depth));
    checkTableRange("RayGenerationShaderRecord", desc.RayGenerationShaderRecord.StartAddress,
                    desc.RayGenerationShaderRecord.SizeInBytes, 0, false);
    checkTableRange("MissShaderTable", desc.MissShaderTable.StartAddress, desc.MissShaderTable.SizeInBytes,
                    desc.MissShaderTable.StrideInBytes, true);
    checkTableRange("HitGroupTable", desc.HitGroupTable.StartAddress, desc.HitGroupTable.SizeInBytes,
                    desc.HitGroupTable.StrideInBytes, true);
    checkTableRange("CallableShaderTable", desc.CallableShaderTable.StartAddress, desc.CallableShaderTable.SizeInBytes,
                    desc.CallableShaderTable.StrideInBytes, true);
    for (auto [name, range] : {std::pair{"MissShaderTable", GpuVirtualAddressRange{desc.MissShaderTable.StartAddress, desc.MissShaderTable.SizeInBytes}},
                               std::pair{"HitGroupTable", GpuVirtualAddressRange{desc.HitGroupTable.StartAddress, desc.HitGroupTable.SizeInBytes}},
                               std::pair{"CallableShaderTable", GpuVirtualAddressRange{desc.CallableShaderTable.StartAddress, desc.CallableShaderTable.SizeInBytes}},
                               std::pair{"RayGenerationShaderRecord", desc.RayGenerationShaderRecord}}) {
        if (range.SizeInBytes && !memory.find(range.StartAddress, range.SizeInBytes))
            throw DxrError(diag("IDX-11", std::string(name) + " range is not inside one GPU buffer")
                               .hex("StartAddress", range.StartAddress)
                               .value("SizeInBytes", range.SizeInBytes));
    }
}

// The launch indices that run: DispatchOptions::region, which must lie inside the dispatch, or all of them.
LaunchRegion launchRegion(const DispatchRaysDesc& desc, const DispatchOptions& options) {
    LaunchRegion region{0, 0, desc.Width, desc.Height};
    if (options.region) {
        region = *options.region;
        REFRAY_CHECK(uint64_t(region.x) + region.width <= desc.Width && uint64_t(region.y) + region.height <= desc.Height,
                     "the launch region " << region.width << "x" << region.height << " at (" << region.x << ", "
                                          << region.y << ") is not inside the " << desc.Width << "x" << desc.Height
                                          << " dispatch");
    }
    return region;
}

// PIPE-7: the root signature bound for the dispatch must be a global one.
void checkGlobalArguments(const GlobalRootArguments* globalArguments) {
    if (globalArguments && globalArguments->signature()->isLocal())
        throw DxrError(diag("PIPE-7", "the root signature bound for the dispatch is a local root signature")
                           .value("signature", globalArguments->signature()->name()));
}

// The ray generation record (IDX-9, IDX-13), resolved once for every thread into ds.rayGenRecord. Its errors
// always stop the dispatch, whatever DispatchOptions::onError says.
void resolveRayGenerationRecord(DispatchState& ds) {
    ThreadState probe;
    detail::LookupCache lookups;
    probe.dispatch = &ds;
    probe.lookups = &lookups;
    const detail::Site site{ShaderStage::RayGeneration, &detail::kNoExport, 0};
    const OnError onError = ds.options.onError;
    ds.options.onError = OnError::Stop;
    const GpuVirtualAddressRangeAndStride rg{ds.desc->RayGenerationShaderRecord.StartAddress,
                                             ds.desc->RayGenerationShaderRecord.SizeInBytes, 0};
    if (rg.StartAddress == 0 || rg.SizeInBytes < kShaderIdentifierSizeInBytes)
        throw DxrError(diag("IDX-9", "RayGenerationShaderRecord must hold at least the 32-byte identifier")
                           .hex("StartAddress", rg.StartAddress)
                           .value("SizeInBytes", rg.SizeInBytes, ">= 32"));
    detail::lookupRecord(probe, site, ProgramEntry::Kind::RayGeneration, rg, 0, ds.rayGenRecord);
    ds.options.onError = onError;
}

// The launch index in Width-major, then Height, then Depth order: the order GEN-1 calls "first".
uint64_t linearIndex(const DispatchRaysDesc& desc, uvec3 launch) {
    return (uint64_t(launch.z) * desc.Height + launch.y) * desc.Width + launch.x;
}

// OnError::Stop: keeps the error that ended this launch; launches after the first failed one are skipped.
void recordStopError(ThreadState& ts, DispatchState& ds, Diagnostic d) {
    ts.stopErrors.push_back(std::move(d));
    uint64_t seen = ds.firstErrorIndex.load();
    while (ts.linearIndex < seen && !ds.firstErrorIndex.compare_exchange_weak(seen, ts.linearIndex)) {
    }
}

// A launch's start: its index, and false when an earlier launch has stopped the dispatch (the launch is skipped).
bool startLaunch(ThreadState& ts, DispatchState& ds, uvec3 launch) {
    ts.launchIndex = launch;
    ts.linearIndex = linearIndex(*ds.desc, launch);
    if (ts.linearIndex > ds.firstErrorIndex.load(std::memory_order_relaxed)) return false;
    ts.rayCounter = 0;
    ts.queriesTraced = 0;
    return true;
}

// What ended the launch of `inv` early: kept when it is a DXR error (or another refray error, under GEN-1);
// anything else is rethrown.
void recordLaunchFailure(ThreadState& ts, DispatchState& ds, const detail::Invocation& inv, std::exception_ptr failure) {
    try {
        std::rethrow_exception(std::move(failure));
    } catch (const DxrError& e) {
        recordStopError(ts, ds, e.diagnostic());
    } catch (const Error& e) {
        recordStopError(ts, ds, detail::locate(ts, diag("GEN-1", e.what()), detail::siteOf(inv)));
    }
}

// The launch's invocation: the compute shader's, or the ray generation shader's (its record's).
detail::Invocation launchInvocation(ThreadState& ts, const DispatchState& ds) {
    return ds.computeShader
               ? detail::invocation(ts, ShaderStage::Compute, ds.computeShader, nullptr, 0)
               : detail::invocation(ts, ShaderStage::RayGeneration, ds.rayGenRecord.entry->shader, &ds.rayGenRecord, 0);
}

// One launch: the ray generation shader at `launch`, unless an earlier launch has stopped the dispatch.
void runLaunch(ThreadState& ts, DispatchState& ds, uvec3 launch) {
    if (!startLaunch(ts, ds, launch)) return;
    detail::Invocation inv = launchInvocation(ts, ds);
    try {
        if (!ds.computeShader) detail::checkGlobalSignature(ts, detail::siteOf(inv), *ds.rayGenRecord.entry);
        detail::invoke(ts, inv, nullptr, nullptr);
    } catch (const Error&) {  // DxrError too
        recordLaunchFailure(ts, ds, inv, std::current_exception());
    }
}

// The launches of a wave whose ray generation or compute shader is written for waves (emulator/ray_generation_wave.h,
// emulator/compute_wave.h): each lane starts as runLaunch starts it, the shader runs once over the lanes on the
// worker's own stack, and each lane's failure is recorded as runLaunch records it.
void runLaunchWave(Wave& wave, DispatchState& ds, std::span<const uvec3> launches) {
    detail::openWave(wave, launches.size());
    std::array<std::optional<detail::Invocation>, kMaxWaveWidth> invocations;
    std::array<std::optional<ShaderContext>, kMaxWaveWidth> contexts;
    std::array<ShaderContext*, kMaxWaveWidth> lanes{};
    std::array<uint8_t, kMaxWaveWidth> callerSections{};
    LaneMask active;
    for (size_t i = 0; i < launches.size(); ++i) {
        ThreadState& ts = wave.lanes[i].ts;
        wave.lanes[i].launch = launches[i];
        if (!startLaunch(ts, ds, launches[i])) continue;
        const detail::Invocation& inv = invocations[i].emplace(launchInvocation(ts, ds));
        if (!ds.computeShader) {
            try {
                detail::checkGlobalSignature(ts, detail::siteOf(inv), *ds.rayGenRecord.entry);
            } catch (...) {
                recordLaunchFailure(ts, ds, inv, std::current_exception());
                continue;
            }
        }
        callerSections[i] = detail::beginInvocation(ts, inv);
        lanes[i] = &contexts[i].emplace(*invocations[i]);
        active.set(int(i));
    }
    if (active.empty()) return;
    std::optional<RayGenerationWave> rayGeneration;
    std::optional<ComputeWave> compute;
    ShaderWave& shaderWave = ds.computeShader ? static_cast<ShaderWave&>(compute.emplace(lanes, active, &wave))
                                              : rayGeneration.emplace(lanes, active, &wave);
    std::exception_ptr escaped;
    try {
        if (compute) ds.computeShader->waveCompute(*compute);
        else ds.rayGenRecord.entry->shader->waveRayGeneration(*rayGeneration);
    } catch (...) {
        escaped = std::current_exception();  // not one lane's: it stops every lane still running the shader
    }
    std::exception_ptr unexpected;
    for (int i : active) {
        ThreadState& ts = wave.lanes[size_t(i)].ts;
        detail::endInvocation(ts, callerSections[size_t(i)]);
        std::exception_ptr failure = shaderWave.failure(i);
        if (!failure && escaped && shaderWave.isActive(i)) failure = escaped;
        if (!failure) continue;
        try {
            recordLaunchFailure(ts, ds, *invocations[size_t(i)], failure);
        } catch (...) {
            if (!unexpected) unexpected = std::current_exception();  // not an error of refray's: the dispatch's
        }
    }
    if (unexpected) std::rethrow_exception(unexpected);
}

// The lanes per wave the dispatch runs: DispatchOptions::waveWidth, or one for an observed or profiled dispatch.
int waveWidth(const DispatchOptions& options) {
    if (options.observer || options.profileStages) return 1;
    REFRAY_CHECK(options.waveWidth >= 1 && options.waveWidth <= uint32_t(kMaxWaveWidth),
                 "wave width " << options.waveWidth << " is outside 1.." << kMaxWaveWidth);
    return int(options.waveWidth);
}

// The launches of a wave: a block of the tile as square as the width allows (8x4 for 32 lanes, 4x4 for 16), so that its rays
// start close together and meet the same records.
uvec2 waveBlock(int width) {
    uint32_t w = 1;
    while (w * w < uint32_t(width)) w *= 2;
    const uint32_t h = uint32_t(width) / w;
    return w * h == uint32_t(width) ? uvec2(w, h) : uvec2(uint32_t(width), 1u);
}

// Every launch of `region` at every depth, over oneTBB tiles of DispatchOptions::tileSize on
// DispatchOptions::threads workers; each tile in waves.
void runTiles(DispatchState& ds, const LaunchRegion& region, Waves& waves) {
    const DispatchOptions& options = ds.options;
    const uint32_t tile = std::max(1u, options.tileSize);
    const int width = waveWidth(options);
    const uvec2 block = waveBlock(width);
    const detail::LaunchFunction launch = [&ds](ThreadState& ts, uvec3 at) { runLaunch(ts, ds, at); };
    // A ray generation or compute shader written for waves runs once a wave; one lane at a time it runs alone, on its
    // fiber.
    const bool waveShader =
        width > 1 && (ds.computeShader ? bool(ds.computeShader->waveCompute)
                                       : ds.rayGenRecord.entry && ds.rayGenRecord.entry->shader->waveRayGeneration);
    const int arenaThreads = options.threads ? int(options.threads) : tbb::task_arena::automatic;
    tbb::task_arena arena(arenaThreads);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range2d<uint32_t>(region.y, region.y + region.height, tile, region.x, region.x + region.width, tile),
            [&](const tbb::blocked_range2d<uint32_t>& range) {
                Wave& wave = waves.local();
                std::array<uvec3, kMaxWaveWidth> launches;
                for (uint32_t z = 0; z < ds.desc->Depth; ++z)
                    for (uint32_t y0 = range.rows().begin(); y0 < range.rows().end(); y0 += block.y)
                        for (uint32_t x0 = range.cols().begin(); x0 < range.cols().end(); x0 += block.x) {
                            size_t count = 0;
                            for (uint32_t y = y0; y < std::min(y0 + block.y, range.rows().end()); ++y)
                                for (uint32_t x = x0; x < std::min(x0 + block.x, range.cols().end()); ++x)
                                    launches[count++] = uvec3(x, y, z);
                            const std::span<const uvec3> lanes(launches.data(), count);
                            if (waveShader) runLaunchWave(wave, ds, lanes);
                            else detail::runWave(wave, lanes, launch);
                        }
                if (options.progress) options.progress->advance(range.rows().size() * range.cols().size());
            });
    });
}

// The thread's statistics in DispatchStats form (raysPerType stays unsorted: merge sorts).
DispatchStats finishedStats(const ThreadState& ts) {
    DispatchStats st = ts.stats;
    for (const detail::ExportCount& e : ts.exportCounts) st.invocationsPerExport.push_back({e.shader->name, e.shader->stage, e.count});
    st.stagesProfiled = ts.profiling;
    if (ts.profiling)
        for (size_t i = 0; i < kProfileStageCount; ++i) st.stageSeconds[i] = std::chrono::duration<double>(ts.clock.spent[i]).count();
    return st;
}

// Every thread's diagnostics and statistics, merged into `result`. OnError::Stop: throws the error of the
// lowest launch index (GEN-1).
void collectResults(Waves& waves, const DispatchRaysDesc& desc, DispatchResult& result) {
    std::vector<Diagnostic> errors;
    for (Wave& wave : waves)
        for (detail::WaveLane& lane : wave.lanes) {
        ThreadState& ts = lane.ts;
        detail::foldNotes(ts);
        result.diagnostics.merge(ts.log);
        result.stats.merge(finishedStats(ts));
        errors.insert(errors.end(), ts.stopErrors.begin(), ts.stopErrors.end());
        }
    if (!errors.empty()) {
        auto linear = [&](const Diagnostic& d) { return linearIndex(desc, d.site ? d.site->launchIndex : uvec3(0u)); };
        auto first = std::min_element(errors.begin(), errors.end(),
                                      [&](const Diagnostic& a, const Diagnostic& b) { return linear(a) < linear(b); });
        throw DxrError(*first);
    }
}

// What DispatchRays and Dispatch share of their state: the device, the bound pipeline and arguments, the launch grid
// (`grid` outlives the dispatch) and the options.
void initDispatchState(DispatchState& ds, Device* device, const GpuMemory& memory, const StateObjectPtr& pipeline,
                       const DispatchRaysDesc& grid, const GlobalRootArguments* global, const DispatchOptions& options,
                       uint64_t epoch) {
    ds.device = device;
    ds.memory = &memory;
    ds.pipeline = pipeline.get();
    ds.desc = &grid;
    ds.global = global;
    ds.options = options;
    ds.epoch = epoch;
}

// Runs every launch of `region` on per-thread states and merges their diagnostics and statistics into `result`.
void runLaunches(DispatchState& ds, const LaunchRegion& region, DispatchResult& result) {
    Waves waves(std::ref(ds));
    runTiles(ds, region, waves);
    collectResults(waves, *ds.desc, result);
}

}  // namespace

DispatchResult Device::dispatchRays(const DispatchRaysDesc& desc, const StateObjectPtr& pipeline,
                                    const GlobalRootArguments* globalArguments, const DispatchOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const uint64_t launches = uint64_t(desc.Width) * desc.Height * desc.Depth;
    checkDispatchDesc(desc, pipeline, launches, memory_);
    const LaunchRegion region = launchRegion(desc, options);
    checkGlobalArguments(globalArguments);

    DispatchState ds;
    initDispatchState(ds, this, memory_, pipeline, desc, globalArguments, options, epoch_.load());
    for (const ProgramEntry& entry : pipeline->entries()) {
        if (entry.anyHit) ds.anyHitInPipeline = true;
        if (entry.intersection && entry.intersection->waveIntersection) ds.waveIntersectionInPipeline = true;
    }
    resolveRayGenerationRecord(ds);

    DispatchResult result;
    result.stats.stagesProfiled = options.profileStages;
    if (ds.rayGenRecord.entry && launches != 0) {  // else REC-8: NULL ray generation; RGS-1: zero size
        const TableLock lock(memory_, {desc.RayGenerationShaderRecord.StartAddress, desc.MissShaderTable.StartAddress,
                                       desc.HitGroupTable.StartAddress, desc.CallableShaderTable.StartAddress});
        runLaunches(ds, region, result);
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

DispatchResult Device::dispatch(const DispatchDesc& desc, const StateObjectPtr& pipeline,
                                const GlobalRootArguments* globalArguments, const DispatchOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    if (!pipeline) throw DxrError(diag("RGS-3", "Dispatch without a bound state object holding the compute shader"));
    const ShaderExport* shader = pipeline->findComputeShader(desc.ComputeShader);
    if (!shader) {
        std::vector<std::string> names;
        for (const auto& [n, e] : pipeline->computeShaders()) names.push_back(n);
        throw DxrError(diag("RQ-1", "Dispatch names no compute shader of state object '" + pipeline->name() + "'")
                           .value("ComputeShader", desc.ComputeShader)
                           .value("compute exports", names.empty() ? std::string("(none)") : joined(names)));
    }
    for (uint32_t groups : {desc.ThreadGroupCountX, desc.ThreadGroupCountY, desc.ThreadGroupCountZ})
        if (groups > kMaxThreadGroupsPerDimension)
            throw DxrError(diag("RQ-1", "Dispatch thread-group count above D3D12's 65535 per dimension")
                               .value("ThreadGroupCountX", desc.ThreadGroupCountX, "<= 65535")
                               .value("ThreadGroupCountY", desc.ThreadGroupCountY, "<= 65535")
                               .value("ThreadGroupCountZ", desc.ThreadGroupCountZ, "<= 65535"));
    checkGlobalArguments(globalArguments);
    // The launch grid is the grid of SV_DispatchThreadID.
    DispatchRaysDesc grid;
    grid.Width = desc.ThreadGroupCountX * shader->numThreads.x;
    grid.Height = desc.ThreadGroupCountY * shader->numThreads.y;
    grid.Depth = desc.ThreadGroupCountZ * shader->numThreads.z;
    const LaunchRegion region = launchRegion(grid, options);

    DispatchState ds;
    initDispatchState(ds, this, memory_, pipeline, grid, globalArguments, options, epoch_.load());
    ds.computeShader = shader;

    DispatchResult result;
    result.stats.stagesProfiled = options.profileStages;
    if (uint64_t(grid.Width) * grid.Height * grid.Depth != 0) runLaunches(ds, region, result);
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace refray::dxr
