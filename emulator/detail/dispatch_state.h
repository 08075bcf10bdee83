// What every invocation of one DispatchRays shares. Internal to the emulator: dispatcher.cpp sets it up and runs
// the launches; the TraceRay stages and the intrinsics (shader_api.cpp, shader_resources.cpp) read it.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>

#include "emulator/detail/invocation.h"
#include "emulator/device.h"

namespace refray::dxr::detail {

struct DispatchState {
    Device* device = nullptr;
    const GpuMemory* memory = nullptr;
    const StateObject* pipeline = nullptr;
    const DispatchRaysDesc* desc = nullptr;
    const GlobalRootArguments* global = nullptr;
    DispatchOptions options;
    uint64_t epoch = 0;
    RecordView rayGenRecord;
    const ShaderExport* computeShader = nullptr;  // Device::dispatch: the compute shader every launch runs
    bool anyHitInPipeline = false;  // a hit group of the pipeline names an any-hit shader
    bool waveIntersectionInPipeline = false;  // a hit group's intersection shader is written for waves
    std::atomic<uint64_t> firstErrorIndex{~0ull};
};

// The root argument bytes a shader reads: its record's after the identifier (local), or what the dispatch's
// SetComputeRoot* calls set (global). All null when there are none (no record, no global arguments).
struct ArgumentBytes {
    const uint8_t* bytes = nullptr;
    const uint8_t* written = nullptr;  // 1 where the host wrote the byte (REC-7)
    uint64_t available = 0;
};
inline ArgumentBytes argumentBytes(const Invocation& inv, const DispatchState& ds, bool local) {
    if (local)
        return inv.record ? ArgumentBytes{inv.record->arguments, inv.record->argumentsWritten,
                                          inv.record->argumentBytesAvailable}
                          : ArgumentBytes{};
    return ds.global ? ArgumentBytes{ds.global->bytes().data(), ds.global->setMask().data(), ds.global->bytes().size()}
                     : ArgumentBytes{};
}

// Lookups a dispatch repeats with the same answer, remembered per worker thread (one cache per wave, which its lanes
// share: ThreadState::lookups). While a dispatch runs its shader tables are locked (REC-12), its global root
// arguments are fixed and no GPU buffer comes or goes, so a lookup that succeeded once succeeds again with the same
// result. Only successes are kept: every failure still goes through the full check and its diagnostic. Each
// dispatch starts with an empty cache.
struct LookupCache {
    // The buffers read last, most recent first: shaders read a handful of buffers over and over.
    std::array<const GpuBuffer*, 4> buffers{};
    // The buffer holding [va, va + n): from the cache, else from `memory` (then cached); nullptr if none holds it.
    const GpuBuffer* findBuffer(const GpuMemory& memory, GpuVirtualAddress va, uint64_t n) {
        size_t i = 0;
        while (i < buffers.size() && !(buffers[i] && buffers[i]->contains(va, n))) ++i;
        const GpuBuffer* found = i < buffers.size() ? buffers[i] : memory.find(va, n);
        if (!found) return nullptr;
        // Move it to the front; a buffer new to the cache pushes out the last.
        for (i = std::min(i, buffers.size() - 1); i > 0; --i) buffers[i] = buffers[i - 1];
        return buffers[0] = found;
    }

    // Root arguments that passed ShaderContext::rootArgument's checks: the argument bytes they were read from (a
    // record's, or the dispatch's global ones), the parameter, size and type, and the checked pointer.
    struct RootArgument {
        const uint8_t* arguments = nullptr;
        uint64_t available = 0;  // the argument bytes the record's table leaves it
        uint32_t parameter = 0;
        uint32_t size = 0;
        const void* type = nullptr;
        const uint8_t* bytes = nullptr;
    };
    std::array<RootArgument, 64> rootArguments{};
    static size_t rootArgumentSlot(const uint8_t* arguments, uint32_t parameter) {
        return (reinterpret_cast<uintptr_t>(arguments) / 8 * 31 + parameter) % 64;
    }

    // Records that passed lookupRecordChecked: the table, kind, index and (hit groups) geometry type they were
    // checked for.
    struct Record {
        GpuVirtualAddressRangeAndStride table{};
        uint64_t index = ~0ull;
        uint8_t kind = 0;
        uint8_t geometry = 0;  // 0: no hit; 1 + GeometryType otherwise
        RecordView view;
    };
    std::array<Record, 128> records{};
    static size_t recordSlot(uint64_t index, uint8_t kind) { return (index * 4 + kind) % 128; }
};

// The calling worker thread's LookupCache.
LookupCache& lookupCache(Invocation& inv);

}  // namespace refray::dxr::detail
