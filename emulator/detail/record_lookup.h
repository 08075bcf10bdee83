// Record lookup: the shader record at an index of a shader table, checked against the bound state object.
// Internal to the emulator.
#pragma once

#include <cstdint>

#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/dispatch_state.h"
#include "emulator/detail/invocation.h"
#include "emulator/detail/thread_state.h"
#include "emulator/shader_table.h"

namespace refray::dxr::detail {

// Extra values a hit-group lookup diagnostic carries (IDX-11).
struct HitLookupContext {
    const HitGroupIndexTerms* terms = nullptr;
    const HitInfo* hit = nullptr;
    GeometryType geometryType = GeometryType::Triangles;
};

// Resolves the record at `index` of `table` (IDX-9..14, REC-7..11) into `out`, emitting a RecordLookup trace event
// when observed. Returns false when the lookup failed in OnError::Continue mode (the caller treats it as a NULL
// record); `out.entry` is null for a NULL record (REC-8). `hit` adds the hit-group terms to diagnostics (IDX-11).
bool lookupRecord(ThreadState& ts, const Site& site, ProgramEntry::Kind kind,
                  const GpuVirtualAddressRangeAndStride& table, uint64_t index, RecordView& out,
                  const HitLookupContext* hit = nullptr);

// The hit-group record of `hit` for the ray `rs`, whose geometry is of `type` (IDX-14): the record at
// I = R + M*G + C of the dispatch's HitGroupTable, with I from hitGroupRecordIndex, the indexing rule.
inline bool lookupHitGroupRecord(ThreadState& ts, const Site& site, const RayState& rs, const HitInfo& hit,
                                 GeometryType type, RecordView& out) {
    const HitGroupIndexTerms terms = hitGroupRecordIndex(rs.rayContribution, rs.multiplier, hit.geometryIndex,
                                                         hit.instance->desc.InstanceContributionToHitGroupIndex);
    const HitLookupContext lookup{&terms, &hit, type};
    return lookupRecord(ts, site, ProgramEntry::Kind::HitGroup, ts.dispatch->desc->HitGroupTable, terms.index, out,
                        &lookup);
}

}  // namespace refray::dxr::detail
