// What every invocation of one DispatchRays shares, and the error path of the intrinsics. Internal to the
// emulator: dispatcher.cpp runs the dispatch, shader_resources.cpp serves the resource intrinsics from it.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

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
    bool anyHitInPipeline = false;  // a hit group of the pipeline names an any-hit shader
    std::atomic<uint64_t> firstErrorIndex{~0ull};
};

// Stops the invocation with a DxrError carrying `rule`, the stage and the launch site: misuse of the shader API
// always stops, there is no fallback.
[[noreturn]] void stageError(Invocation& inv, const char* rule, const std::string& message);

}  // namespace refray::dxr::detail
