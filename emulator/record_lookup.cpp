// Record lookup: the shader record at an index of a shader table, checked against the bound state object
// (IDX-9..14, REC-7..11) and remembered per thread (LookupCache).
#include "emulator/detail/record_lookup.h"

#include <algorithm>
#include <cstring>

#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_events.h"
#include "emulator/limits.h"

namespace refray::dxr::detail {

namespace {

const char* tableName(ProgramEntry::Kind kind) {
    switch (kind) {
        case ProgramEntry::Kind::HitGroup: return "hit-group table";
        case ProgramEntry::Kind::Miss: return "miss shader table";
        case ProgramEntry::Kind::Callable: return "callable shader table";
        case ProgramEntry::Kind::RayGeneration: return "ray generation record";
    }
    return "table";
}

void addHitValues(DiagnosticBuilder& b, const HitLookupContext* h) {
    if (!h || !h->terms) return;
    const HitGroupIndexTerms& t = *h->terms;
    b.value("I = R + M*G + C", std::to_string(t.rayContribution) + " + " + std::to_string(t.multiplier) + "*" +
                                   std::to_string(t.geometryIndex) + " + " + std::to_string(t.instanceContribution) +
                                   " = " + std::to_string(t.index));
    if (h->hit) {
        b.value("InstanceIndex", h->hit->instanceIndex)
            .value("GeometryIndex", h->hit->geometryIndex)
            .value("PrimitiveIndex", h->hit->primitiveIndex);
    }
}

// Resolves the record at `index` of `table` (IDX-9..14, REC-7..11). Returns false when
// the lookup failed in OnError::Continue mode (the caller treats it as a NULL record).
bool lookupRecordChecked(ThreadState& ts, const Site& site, ProgramEntry::Kind kind,
                         const GpuVirtualAddressRangeAndStride& table, uint64_t index, RecordView& out,
                         const HitLookupContext* hit) {
    // A record that passed these checks for this table, index and geometry type passes them again (LookupCache).
    LookupCache::Record& cached = ts.lookups->records[LookupCache::recordSlot(index, uint8_t(kind))];
    const uint8_t geometry = hit ? uint8_t(1 + uint8_t(hit->geometryType)) : uint8_t(0);
    if (cached.index == index && cached.kind == uint8_t(kind) && cached.geometry == geometry &&
        cached.table.StartAddress == table.StartAddress && cached.table.SizeInBytes == table.SizeInBytes &&
        cached.table.StrideInBytes == table.StrideInBytes) {
        out = cached.view;
        return true;
    }
    auto remember = [&] {
        cached = {table, index, uint8_t(kind), geometry, out};
        return true;
    };

    const DispatchState& ds = *ts.dispatch;
    const std::string_view name = tableName(kind);
    out = RecordView{};
    out.index = index;
    out.address = recordAddress(table, index);
    const uint64_t offset = out.address - table.StartAddress;

    if (table.StartAddress == 0 && table.SizeInBytes == 0) {
        auto b = diag("IDX-11", "the " + std::string(name) + " is missing (StartAddress 0, SizeInBytes 0) but a record is needed");
        b.value("index", index);
        addHitValues(b, hit);
        raise(ts, site, b);
        return false;
    }
    if (offset + kShaderIdentifierSizeInBytes > table.SizeInBytes) {
        auto b = diag("IDX-11", "record index past the end of the " + std::string(name));
        addHitValues(b, hit);
        b.value("index", index)
            .value("stride", table.StrideInBytes)
            .value("record offset + 32", offset + kShaderIdentifierSizeInBytes, "SizeInBytes " + std::to_string(table.SizeInBytes))
            .value("records in table", table.StrideInBytes == 0 ? 1
                                       : table.SizeInBytes < kShaderIdentifierSizeInBytes
                                           ? 0
                                           : (table.SizeInBytes - kShaderIdentifierSizeInBytes) / table.StrideInBytes + 1);
        raise(ts, site, b);
        return false;
    }
    const GpuBuffer* buffer = ds.memory->find(out.address, kShaderIdentifierSizeInBytes);
    const uint8_t* bytes = buffer ? buffer->bytes.data() + (out.address - buffer->base) : nullptr;
    const uint8_t* identifierWritten = buffer ? buffer->written.data() + (out.address - buffer->base) : nullptr;
    if (!bytes || std::memchr(identifierWritten, 0, kShaderIdentifierSizeInBytes)) {
        auto b = diag("IDX-11", "the record's shader identifier at this index was never written (uninitialized record)");
        addHitValues(b, hit);
        b.value("index", index).hex("address", out.address);
        raise(ts, site, b);
        return false;
    }
    bool isNull = false;
    const ProgramEntry* entry = ds.pipeline->resolve(bytes, isNull);
    if (isNull) return remember();  // REC-8: nothing runs for this purpose
    if (!entry) {
        auto b = diag("REC-8", "the " + std::string(name) + " record holds an identifier that is not an export of the bound state object '" +
                                   ds.pipeline->name() + "': it is " + StateObject::describeForeignIdentifier(bytes));
        addHitValues(b, hit);
        b.value("index", index).hex("address", out.address);
        raise(ts, site, b);
        return false;
    }
    if (entry->kind != kind) {
        auto b = diag("IDX-13", "the " + std::string(name) + " record holds " + std::string(toString(entry->kind)) + " '" +
                                    entry->name + "', which does not belong in this table");
        addHitValues(b, hit);
        b.value("index", index);
        raise(ts, site, b);
        return false;
    }
    if (kind == ProgramEntry::Kind::HitGroup && hit) {
        const bool procedural = hit->geometryType == GeometryType::ProceduralPrimitiveAABBs;
        if (procedural != (entry->hitGroupType == HitGroupType::ProceduralPrimitive)) {
            auto b = diag("IDX-14", "hit group '" + entry->name + "' (" +
                                        (entry->hitGroupType == HitGroupType::ProceduralPrimitive ? "procedural" : "triangle") +
                                        ") was selected for " + (procedural ? "AABB" : "triangle") + " geometry");
            addHitValues(b, hit);
            raise(ts, site, b);
            return false;
        }
    }
    const uint32_t layout = entry->localRootSignature ? entry->localRootSignature->recordSize() : kShaderIdentifierSizeInBytes;
    if (table.StrideInBytes != 0 && table.StrideInBytes < layout) {
        auto b = diag("IDX-10", "the " + std::string(name) + " stride is smaller than the record of '" + entry->name + "'");
        addHitValues(b, hit);
        b.value("stride", table.StrideInBytes).value("record bytes (REC-5)", layout, "<= stride");
        raise(ts, site, b);
        return false;
    }
    const uint64_t available = table.StrideInBytes ? table.StrideInBytes : table.SizeInBytes - offset;
    if (kind == ProgramEntry::Kind::RayGeneration && table.SizeInBytes < layout) {
        // The ray generation record has no stride: its SizeInBytes must cover it (IDX-9).
        raise(ts, site, diag("IDX-9", "RayGenerationShaderRecord.SizeInBytes does not cover the identifier and local root "
                                      "arguments of '" + entry->name + "'")
                            .value("SizeInBytes", table.SizeInBytes, ">= " + std::to_string(layout)));
        return false;
    }
    if (available < layout || offset + layout > table.SizeInBytes) {
        auto b = diag(available < layout ? "REC-11" : "IDX-11",
                      "the record of '" + entry->name + "' does not fit in the " + std::string(name));
        addHitValues(b, hit);
        b.value("record offset", offset)
            .value("record bytes (REC-5)", layout)
            .value("SizeInBytes", table.SizeInBytes);
        raise(ts, site, b);
        return false;
    }
    out.entry = entry;
    out.arguments = bytes + kShaderIdentifierSizeInBytes;
    out.argumentsWritten = buffer->written.data() + (out.address - buffer->base) + kShaderIdentifierSizeInBytes;
    out.argumentBytesAvailable = std::min<uint64_t>(available, buffer->size() - (out.address - buffer->base)) -
                                 kShaderIdentifierSizeInBytes;
    return remember();
}

}  // namespace

bool lookupRecord(ThreadState& ts, const Site& site, ProgramEntry::Kind kind,
                  const GpuVirtualAddressRangeAndStride& table, uint64_t index, RecordView& out,
                  const HitLookupContext* hit) {
    if (!observer(ts)) return lookupRecordChecked(ts, site, kind, table, index, out, hit);
    TraceEvent e = event(ts, TraceEvent::Kind::RecordLookup,
                         site.depth + (kind == ProgramEntry::Kind::HitGroup || kind == ProgramEntry::Kind::Miss ? 1 : 0));
    e.table = tableName(kind);
    e.recordIndex = index;
    e.recordAddress = recordAddress(table, index);
    e.stride = table.StrideInBytes;
    if (hit && hit->terms) {
        e.hasTerms = true;
        e.terms = *hit->terms;
    }
    if (hit && hit->hit) setHit(e, *hit->hit);
    bool ok = false;
    try {
        ok = lookupRecordChecked(ts, site, kind, table, index, out, hit);
    } catch (...) {
        e.note = "invalid";
        observer(ts)->onEvent(e);
        throw;
    }
    e.note = !ok ? "invalid" : out.entry ? "" : "NULL";
    if (out.entry) e.exportName = out.entry->name;
    observer(ts)->onEvent(e);
    return ok;
}

}  // namespace refray::dxr::detail
