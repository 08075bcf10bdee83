// Per-invocation state behind ShaderContext. Internal to the emulator: shaders use
// ShaderContext only. Lives on the worker's stack; nothing here outlives a TraceRay.
#pragma once

#include <cstdint>

#include "emulator/acceleration_structure.h"
#include "emulator/shader_table.h"
#include "emulator/state_object.h"
#include "emulator/types.h"

namespace refray::dxr::detail {

struct DispatchState;
struct ThreadState;

// A candidate or committed hit: the values SV-7..SV-12 report in IS/AHS/CHS.
struct HitInfo {
    const BuiltInstance* instance = nullptr;
    uint32_t instanceIndex = 0;
    uint32_t geometryIndex = 0;
    uint32_t primitiveIndex = 0;
    uint32_t hitKind = 0;
    float t = 0.0f;
    vec3 objectRayOrigin{0.0f};
    vec3 objectRayDirection{0.0f};
    alignas(16) uint8_t attributes[32] = {};
    TypeTag attributeType;
};

// One TraceRay in flight (TRV-9: each nested call has its own).
struct RayState {
    const TopLevelAS* tlas = nullptr;
    RayDesc ray;
    uint32_t rayFlags = 0;        // the TraceRay argument, defined bits (RayFlags(), FLAG-13)
    uint32_t effectiveFlags = 0;  // rayFlags | pipeline SKIP_* (FLAG-5)
    uint32_t instanceInclusionMask = 0;
    uint32_t rayContribution = 0;  // raw arguments; masked by hitGroupRecordIndex
    uint32_t multiplier = 0;
    uint32_t missShaderIndex = 0;
    uint32_t depth = 0;  // depth of the shaders this ray invokes
    float tCurrent = 0.0f;
    void* payload = nullptr;
    TypeTag payloadType;
    bool committed = false;
    bool searchEnded = false;
    HitInfo committedHit;
};

// A resolved shader record.
struct RecordView {
    const ProgramEntry* entry = nullptr;   // null: NULL identifier (REC-8)
    GpuVirtualAddress address = 0;
    uint64_t index = 0;
    const uint8_t* arguments = nullptr;    // record bytes from offset 32
    const uint8_t* argumentsWritten = nullptr;
    uint64_t argumentBytesAvailable = 0;
};

// What a ShaderContext refers to.
struct Invocation {
    ShaderStage stage = ShaderStage::RayGeneration;
    const ShaderExport* shader = nullptr;
    const RecordView* record = nullptr;
    RayState* ray = nullptr;         // IS, AHS, CHS, miss
    HitInfo* hit = nullptr;          // IS: the AABB; AHS: the candidate; CHS: the committed hit
    DispatchState* dispatch = nullptr;
    ThreadState* thread = nullptr;
    uint32_t depth = 0;
    bool candidateOpaque = true;  // IS: the OPQ-1 opacity of the box, which ReportHit applies
    bool searchEnded = false;     // IS with ReportHitEnd::Return: a ReportHit ended the search; no intrinsic may follow
};

}  // namespace refray::dxr::detail
