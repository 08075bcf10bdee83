#include "inspect/table_view.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <map>

#include "core/error.h"
#include "core/strings.h"
#include "emulator/device.h"
#include "scenes/scene.h"

namespace refray::scenes {

using namespace refray::dxr;

namespace {



std::string floatText(uint32_t bits) {
    float f = 0.0f;
    std::memcpy(&f, &bits, 4);
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, f);
    std::string out(text, end.ptr);
    if (out.find_first_not_of("-0123456789") == std::string::npos) out += ".0";
    return out;
}

// The payload struct's name without namespaces, as scene files write it.
std::string payloadName(const TypeTag& tag) {
    if (!tag.valid()) return "";
    return withoutNamespace(tag.name());
}

std::string registerName(const RootParameter& p) {
    const char cls = p.parameterType == RootParameterType::SRV ? 't' : p.parameterType == RootParameterType::UAV ? 'u' : 'b';
    std::string out(1, cls);
    out += std::to_string(p.shaderRegister);
    if (p.registerSpace != 0) {
        out += " space";
        out += std::to_string(p.registerSpace);
    }
    return out;
}

// Copies [va, va+n) out of GPU memory; false when no buffer holds all of it.
bool readBytes(const GpuMemory& memory, GpuVirtualAddress va, uint64_t n, std::vector<uint8_t>& bytes, bool& written) {
    const GpuBuffer* buffer = memory.find(va, n);
    if (!buffer) return false;
    const uint64_t at = va - buffer->base;
    bytes.assign(buffer->bytes.begin() + int64_t(at), buffer->bytes.begin() + int64_t(at + n));
    written = std::all_of(buffer->written.begin() + int64_t(at), buffer->written.begin() + int64_t(at + n),
                          [](uint8_t w) { return w != 0; });
    return true;
}

uint64_t recordCountOf(uint64_t sizeInBytes, uint64_t stride) {
    if (sizeInBytes < kShaderIdentifierSizeInBytes) return 0;
    return stride == 0 ? 1 : (sizeInBytes - kShaderIdentifierSizeInBytes) / stride + 1;
}

// Which scene-file struct decodes each constants parameter of each local root signature.
using StructMap = std::map<std::pair<std::string, uint32_t>, int32_t>;  // (signature name, parameter) -> struct

StructMap structsOfParameters(const SceneDesc& desc) {
    StructMap map;
    for (const RecordDesc& r : desc.hitGroupRecords) {
        if (r.localRootSignature < 0) continue;
        const std::string& signature = desc.localSignatures[size_t(r.localRootSignature)].name;
        for (const RecordDesc::Argument& a : r.arguments)
            if (a.buffer < 0) map[{signature, a.parameter}] = a.structIndex;
    }
    return map;
}

std::vector<ConstantFieldView> decodeConstants(const std::vector<uint8_t>& bytes, const std::vector<uint8_t>& writtenMask,
                                               const StructDesc* s) {
    const uint32_t dwords = uint32_t(bytes.size() / 4);
    auto fieldOf = [&](std::string name, StructField::Kind kind, uint32_t offset, uint32_t components) {
        ConstantFieldView f;
        f.name = std::move(name);
        f.kind = kind;
        f.components = components;
        for (uint32_t c = 0; c < components && offset + c < dwords; ++c) {
            uint32_t v = 0;
            std::memcpy(&v, bytes.data() + 4 * (offset + c), 4);
            f.dwords.push_back(v);
            for (uint32_t b = 0; b < 4; ++b) f.written = f.written && writtenMask[4 * (offset + c) + b] != 0;
        }
        return f;
    };
    std::vector<ConstantFieldView> fields;
    if (s) {
        for (const StructField& field : s->fields)
            fields.push_back(fieldOf(field.name, field.kind, field.offset, field.components));
    } else {
        for (uint32_t i = 0; i < dwords; ++i) {
            std::string name = "[";
            name += std::to_string(i);
            name += ']';
            fields.push_back(fieldOf(std::move(name), StructField::Kind::Float, i, 1));
        }
    }
    return fields;
}

struct Reader {
    const SceneDesc& desc;
    const StateObject& stateObject;
    const GpuMemory& memory;
    StructMap structs;

    RecordView readRecord(const ShaderTableView& table, uint64_t index) const {
        RecordView r;
        r.index = index;
        r.offset = table.strideInBytes * index;
        r.address = table.startAddress + r.offset;
        std::vector<uint8_t> identifier;
        bool written = false;
        if (!readBytes(memory, r.address, kShaderIdentifierSizeInBytes, identifier, written)) {
            r.contents = RecordView::Contents::Unknown;
            r.unknown = "no GPU buffer at " + hexText(r.address);
            return r;
        }
        if (!written) {
            r.contents = RecordView::Contents::Unwritten;
            return r;
        }
        bool isNull = false;
        const ProgramEntry* entry = stateObject.resolve(identifier.data(), isNull);
        if (isNull) {
            r.contents = RecordView::Contents::Null;
            return r;
        }
        if (!entry) {
            r.contents = RecordView::Contents::Unknown;
            r.unknown = StateObject::describeForeignIdentifier(identifier.data());
            return r;
        }
        r.contents = RecordView::Contents::Export;
        r.kind = std::string(toString(entry->kind));
        r.exportName = entry->name;
        if (entry->kind == ProgramEntry::Kind::HitGroup) {
            r.hitGroupType = entry->hitGroupType == HitGroupType::ProceduralPrimitive ? "procedural" : "triangles";
            if (entry->intersection) r.intersection = entry->intersection->name;
            if (entry->anyHit) r.anyHit = entry->anyHit->name;
            if (entry->closestHit) r.closestHit = entry->closestHit->name;
            r.payload = payloadName(entry->payload);
        } else if (entry->shader) {
            r.payload = payloadName(entry->shader->payload);
        }
        if (const RootSignaturePtr& signature = entry->localRootSignature) {
            r.localRootSignature = signature->name();
            r.layoutSize = signature->recordSize();
            for (uint32_t p = 0; p < signature->parameterCount(); ++p)
                r.arguments.push_back(readArgument(table, r, *signature, p));
        }
        return r;
    }

    RootArgumentView readArgument(const ShaderTableView& table, const RecordView& record, const RootSignature& signature,
                                  uint32_t p) const {
        const RootParameter& parameter = signature.parameter(p);
        RootArgumentView a;
        a.parameter = p;
        a.kind = std::string(toString(parameter.parameterType));
        if (parameter.parameterType != RootParameterType::DescriptorTable) a.shaderRegister = registerName(parameter);
        a.offset = signature.argumentOffset(p);
        a.size = signature.argumentSize(p);
        std::vector<uint8_t> bytes;
        a.inTable = record.offset + a.offset + a.size <= table.sizeInBytes &&
                    readBytes(memory, record.address + a.offset, a.size, bytes, a.written);
        if (!a.inTable) return a;
        if (parameter.parameterType == RootParameterType::Constants32Bit) {
            const GpuBuffer* buffer = memory.find(record.address + a.offset, a.size);
            const uint64_t at = record.address + a.offset - buffer->base;
            const std::vector<uint8_t> writtenMask(buffer->written.begin() + int64_t(at),
                                                   buffer->written.begin() + int64_t(at + a.size));
            const auto it = structs.find({signature.name(), p});
            const StructDesc* s = it != structs.end() && it->second >= 0 ? &desc.structs[size_t(it->second)] : nullptr;
            if (s) a.structName = s->name;
            a.fields = decodeConstants(bytes, writtenMask, s);
        } else {
            std::memcpy(&a.address, bytes.data(), 8);
            if (parameter.parameterType != RootParameterType::DescriptorTable)
                if (const GpuBuffer* target = memory.find(a.address)) {
                    a.buffer = target->name;
                    a.bufferOffset = a.address - target->base;
                }
        }
        return a;
    }

    ShaderTableView readTable(std::string key, std::string name, GpuVirtualAddress start, uint64_t size,
                              uint64_t stride) const {
        ShaderTableView t;
        t.key = std::move(key);
        t.name = std::move(name);
        t.startAddress = start;
        t.sizeInBytes = size;
        t.strideInBytes = stride;
        t.recordCount = recordCountOf(size, stride);
        for (uint64_t i = 0; i < t.recordCount; ++i) t.records.push_back(readRecord(t, i));
        return t;
    }
};

// Collects findings; they are sorted by level (stable) at the end.
class Findings {
public:
    void add(TableFinding::Level level, std::string rule, std::string message) {
        list_.push_back({level, std::move(rule), std::move(message)});
    }
    std::vector<TableFinding> sorted() && {
        std::stable_sort(list_.begin(), list_.end(),
                         [](const TableFinding& a, const TableFinding& b) { return a.level < b.level; });
        return std::move(list_);
    }

private:
    std::vector<TableFinding> list_;
};

using Level = TableFinding::Level;

// "hit-group record 3", "miss record 0", "ray generation record".
std::string recordName(const ShaderTableView& table, uint64_t index) {
    if (table.key == "rayGeneration") return table.name;
    std::string out = table.key == "hitGroup" ? "hit-group" : table.key;
    out += " record ";
    out += std::to_string(index);
    return out;
}

std::string pastTheEnd(const ShaderTableView& table) {
    return "past the end of the " + table.name + " (stride " + std::to_string(table.strideInBytes) + ", SizeInBytes " +
           std::to_string(table.sizeInBytes) + ": " + std::to_string(table.recordCount) +
           (table.recordCount == 1 ? " record)" : " records)");
}

// Findings about one record that hold whichever ray reaches it: what the identifier is, and whether the
// table has room for its layout (IDX-9, IDX-10, IDX-11, IDX-13, REC-8, REC-11).
void checkRecord(const ShaderTableView& table, const RecordView& r, ProgramEntry::Kind expected, const std::string& pipeline,
                 Findings& findings) {
    const std::string what = recordName(table, r.index);
    switch (r.contents) {
        case RecordView::Contents::Null: return;
        case RecordView::Contents::Unwritten:
            findings.add(Level::Error, "IDX-11", "the identifier of " + what + " was never written (uninitialized record)");
            return;
        case RecordView::Contents::Unknown:
            findings.add(Level::Error, "REC-8", what + " holds an identifier that is not an export of state object " +
                                                    inQuotes(pipeline) + ": it is " + r.unknown);
            return;
        case RecordView::Contents::Export: break;
    }
    if (r.kind != toString(expected)) {
        findings.add(Level::Error, "IDX-13", what + " holds " + r.describe() + ", which does not belong in the " + table.name);
        return;
    }
    const std::string sizes = std::to_string(r.layoutSize) + " bytes (REC-5)";
    std::string needs = r.describe();
    if (!r.localRootSignature.empty()) needs += " with local root signature " + inQuotes(r.localRootSignature);
    if (table.strideInBytes != 0 && table.strideInBytes < r.layoutSize) {
        findings.add(Level::Error, "IDX-10", "the " + table.name + " stride (" + std::to_string(table.strideInBytes) +
                                                 ") is smaller than " + what + ": " + needs + " needs " + sizes);
        return;
    }
    if (r.offset + r.layoutSize > table.sizeInBytes) {
        const bool noStride = table.key == "rayGeneration" || table.strideInBytes == 0;
        findings.add(Level::Error, table.key == "rayGeneration" ? "IDX-9" : noStride ? "REC-11" : "IDX-11",
                     what + " does not fit in the " + table.name + ": " + needs + " needs " + sizes + " from offset " +
                         std::to_string(r.offset) + ", but SizeInBytes is " + std::to_string(table.sizeInBytes));
    }
}

}  // namespace

// ---- small members

std::string ConstantFieldView::typeName() const {
    std::string type = kind == StructField::Kind::Float ? "float" : kind == StructField::Kind::Int ? "int" : "uint";
    if (components > 1) type += std::to_string(components);
    return type;
}

std::string ConstantFieldView::text() const {
    std::string out;
    if (dwords.size() > 1) out += '(';
    for (size_t i = 0; i < dwords.size(); ++i) {
        if (i) out += ", ";
        switch (kind) {
            case StructField::Kind::Float: out += floatText(dwords[i]); break;
            case StructField::Kind::Int: out += std::to_string(int32_t(dwords[i])); break;
            case StructField::Kind::Uint: out += std::to_string(dwords[i]); break;
        }
    }
    if (dwords.size() > 1) out += ')';
    return out;
}

std::string RecordView::describe() const {
    switch (contents) {
        case Contents::Null: return "NULL";
        case Contents::Unwritten: return "never-written bytes";
        case Contents::Unknown: return "an unknown identifier";
        case Contents::Export: break;
    }
    return kind + " " + inQuotes(exportName);
}

std::string ReachView::equation() const {
    return std::to_string(terms.rayContribution) + " + " + std::to_string(terms.multiplier) + "*" +
           std::to_string(terms.geometryIndex) + " + " + std::to_string(terms.instanceContribution) + " = " +
           std::to_string(terms.index);
}

std::string_view toString(TableFinding::Level level) {
    switch (level) {
        case TableFinding::Level::Error: return "error";
        case TableFinding::Level::Warning: return "warning";
        case TableFinding::Level::Note: return "note";
    }
    return "?";
}

std::string TableFinding::format() const {
    std::string out(toString(level));
    out += ' ';
    out += rule;
    out += ": ";
    out += message;
    return out;
}

std::string rayQueryDeclaration(uint32_t templateFlags) { return "RayQuery<" + rayFlagsToString(templateFlags) + ">"; }

std::vector<std::string> RayQueryOwnerView::declarations() const {
    std::vector<std::string> out;
    for (uint32_t flags : templateFlags) out.push_back(rayQueryDeclaration(flags));
    return out;
}

const ShaderTableView& TableView::table(const std::string& key) const {
    for (const ShaderTableView& t : tables)
        if (t.key == key) return t;
    throw Error("the dispatch has no " + key + " table");
}

size_t TableView::count(TableFinding::Level level) const {
    return size_t(std::count_if(findings.begin(), findings.end(), [level](const TableFinding& f) { return f.level == level; }));
}

const ReachView& TableView::reach(const std::string& instance, uint32_t geometry, const std::string& rayType) const {
    for (const ReachView& r : reachability)
        if (instances[r.instanceIndex].name == instance && r.geometryIndex == geometry && rayTypes[r.rayType].name == rayType)
            return r;
    throw Error("no instance " + inQuotes(instance) + " geometry " + std::to_string(geometry) + " ray type " + inQuotes(rayType));
}

// ---- the view

TableView buildTableView(Scene& scene, procedural::Precision precision) {
    const SceneDesc& desc = scene.desc();
    const StateObjectPtr stateObject = scene.pipeline(precision);
    const DispatchRaysDesc dispatch = scene.tables(precision);
    Device& device = scene.device();
    Reader reader{desc, *stateObject, device.memory(), structsOfParameters(desc)};
    Findings findings;

    TableView view;
    view.scene = desc.name;
    view.shaderLibrary = desc.shaderLibrary;
    view.precision = std::string(procedural::toString(precision));
    view.stateObject = stateObject->name();

    // Tables, record by record, from GPU memory.
    view.tables.push_back(reader.readTable("rayGeneration", "ray generation record",
                                           dispatch.RayGenerationShaderRecord.StartAddress,
                                           dispatch.RayGenerationShaderRecord.SizeInBytes, 0));
    view.tables.push_back(reader.readTable("miss", "miss shader table", dispatch.MissShaderTable.StartAddress,
                                           dispatch.MissShaderTable.SizeInBytes, dispatch.MissShaderTable.StrideInBytes));
    view.tables.push_back(reader.readTable("hitGroup", "hit-group table", dispatch.HitGroupTable.StartAddress,
                                           dispatch.HitGroupTable.SizeInBytes, dispatch.HitGroupTable.StrideInBytes));
    if (dispatch.CallableShaderTable.SizeInBytes > 0)
        view.tables.push_back(reader.readTable("callable", "callable shader table", dispatch.CallableShaderTable.StartAddress,
                                               dispatch.CallableShaderTable.SizeInBytes,
                                               dispatch.CallableShaderTable.StrideInBytes));
    const ShaderTableView& missTable = view.tables[1];
    const ShaderTableView& hitTable = view.tables[2];
    for (size_t i = 0; i < hitTable.records.size() && i < desc.hitGroupRecords.size(); ++i)
        view.tables[2].records[i].origin = desc.hitGroupRecords[i].origin;

    // BLASes: the built geometries (GeometryIndex order, IDX-4).
    for (size_t b = 0; b < desc.blases.size(); ++b) {
        BlasView v;
        v.name = desc.blases[b].name;
        v.address = scene.blasAddress(b);
        const BottomLevelAS* blas = device.findBottomLevelAS(v.address);
        REFRAY_ASSERT(blas, "BLAS '" << v.name << "' is not at " << hexText(v.address));
        for (size_t g = 0; g < blas->geometries().size(); ++g) {
            const BuiltGeometry& built = blas->geometries()[g];
            v.geometries.push_back({uint32_t(g), built.type == GeometryType::Triangles ? "triangles" : "AABBs", built.flags,
                                    geometryFlagsToString(built.flags), built.primitiveCount()});
        }
        view.blases.push_back(std::move(v));
    }

    // Ray types: TraceRay arguments and the miss record each uses (IDX-2, IDX-7).
    std::vector<bool> missUsed(missTable.records.size(), false);
    for (size_t t = 0; t < desc.rayTypes.size(); ++t) {
        const RayTypeDesc& d = desc.rayTypes[t];
        RayTypeView v{uint32_t(t), d.name, d.payload, d.rayContribution, d.multiplier, d.missShaderIndex,
                      d.instanceInclusionMask, -1, ""};
        const std::string who = "ray type " + inQuotes(d.name);
        if (d.rayContribution > kRayContributionMask)
            findings.add(Level::Warning, "IDX-2", who + ": RayContributionToHitGroupIndex " + std::to_string(d.rayContribution) +
                                                      " keeps only its low 4 bits: R = " +
                                                      std::to_string(d.rayContribution & kRayContributionMask));
        if (d.multiplier > kGeometryMultiplierMask)
            findings.add(Level::Warning, "IDX-2", who + ": MultiplierForGeometryContributionToHitGroupIndex " +
                                                      std::to_string(d.multiplier) + " keeps only its low 4 bits: M = " +
                                                      std::to_string(d.multiplier & kGeometryMultiplierMask));
        if (d.missShaderIndex > kMissShaderIndexMask)
            findings.add(Level::Warning, "IDX-7", who + ": MissShaderIndex " + std::to_string(d.missShaderIndex) +
                                                      " keeps only its low 16 bits: " +
                                                      std::to_string(d.missShaderIndex & kMissShaderIndexMask));
        const uint64_t index = missRecordIndex(d.missShaderIndex);
        if (index * missTable.strideInBytes + kShaderIdentifierSizeInBytes > missTable.sizeInBytes) {
            v.missExport = "past the end of the table";
            findings.add(Level::Error, "IDX-11", who + ": miss record MissShaderIndex " + std::to_string(index) + " is " +
                                                     pastTheEnd(missTable));
        } else {
            v.missRecord = int64_t(missTable.strideInBytes ? index : 0);
            const RecordView& r = missTable.records[size_t(v.missRecord)];
            missUsed[size_t(v.missRecord)] = true;
            v.missExport = r.contents == RecordView::Contents::Export ? r.exportName : r.describe();
            if (r.contents == RecordView::Contents::Null)
                findings.add(Level::Note, "REC-8",
                             who + ": miss record " + std::to_string(index) + " is NULL: a miss runs no shader");
            else if (r.kind == toString(ProgramEntry::Kind::Miss) && r.payload != d.payload)
                findings.add(Level::Error, "PAY-1", who + ": miss record " + std::to_string(index) + " holds " + r.describe() +
                                                        ", which takes payload " + inQuotes(r.payload) + ", not the ray type's " +
                                                        inQuotes(d.payload));
        }
        view.rayTypes.push_back(std::move(v));
    }

    // Instances: the TLAS's instance descs, bit for bit (INST-1).
    const TopLevelAS* tlas = device.findTopLevelAS(scene.tlas());
    REFRAY_ASSERT(tlas, "the scene's TLAS is not at " << hexText(scene.tlas()));
    std::vector<bool> traversed;
    for (size_t i = 0; i < tlas->instances().size(); ++i) {
        const BuiltInstance& built = tlas->instances()[i];
        InstanceView v;
        v.instanceIndex = uint32_t(i);
        v.name = i < desc.instances.size() ? desc.instances[i].name : "";
        v.instanceID = built.desc.InstanceID;
        v.instanceMask = built.desc.InstanceMask;
        v.flags = built.desc.Flags;
        v.flagNames = instanceFlagsToString(v.flags);
        v.contribution = built.desc.InstanceContributionToHitGroupIndex;
        v.blasAddress = built.desc.AccelerationStructure;
        for (size_t b = 0; b < view.blases.size(); ++b)
            if (view.blases[b].address == v.blasAddress) v.blas = int32_t(b);
        traversed.push_back(built.blas != nullptr && v.blas >= 0);
        const std::string who = "instance " + inQuotes(v.name) + " (InstanceIndex " + std::to_string(i) + ")";
        if (v.blasAddress != 0 && !built.blas)
            findings.add(Level::Warning, "INST-9", who + " has a singular or non-finite transform and is never traversed");
        if (traversed.back())
            for (const RayTypeView& t : view.rayTypes) {
                const uint32_t inclusion = t.instanceInclusionMask & kInstanceInclusionMaskBits;
                if ((v.instanceMask & inclusion) == 0)
                    findings.add(Level::Warning, "INST-4",
                                 who + " is never hit by " + inQuotes(t.name) + " rays: InstanceMask " + hexText(v.instanceMask, 2) +
                                     " & InstanceInclusionMask " + hexText(inclusion, 2) + " = 0");
            }
        view.instances.push_back(std::move(v));
    }

    // Reachability: the indexing rule for every instance x geometry x ray type (IDX-1).
    std::vector<bool> hitUsed(hitTable.records.size(), false);
    for (const InstanceView& inst : view.instances) {
        if (!traversed[inst.instanceIndex]) continue;
        for (const GeometryView& g : view.blases[size_t(inst.blas)].geometries) {
            for (const RayTypeView& t : view.rayTypes) {
                ReachView reach;
                reach.instanceIndex = inst.instanceIndex;
                reach.geometryIndex = g.geometryIndex;
                reach.rayType = t.index;
                reach.terms = hitGroupRecordIndex(t.rayContribution, t.multiplier, g.geometryIndex, inst.contribution);
                reach.address = recordAddress(dispatch.HitGroupTable, reach.terms.index);
                reach.maskedOut = (inst.instanceMask & t.instanceInclusionMask & kInstanceInclusionMaskBits) == 0;
                const bool pastEnd =
                    reach.terms.index * hitTable.strideInBytes + kShaderIdentifierSizeInBytes > hitTable.sizeInBytes;
                if (!pastEnd) reach.record = int64_t(hitTable.strideInBytes ? reach.terms.index : 0);
                reach.holds = pastEnd ? "past the end of the table" : hitTable.records[size_t(reach.record)].describe();
                view.reachability.push_back(reach);
                if (reach.maskedOut) continue;  // INST-4: reported once per instance and ray type

                const std::string who = "instance " + inQuotes(inst.name) + " (InstanceIndex " +
                                        std::to_string(inst.instanceIndex) + "), geometry " +
                                        std::to_string(g.geometryIndex) + ", ray type " + inQuotes(t.name) +
                                        ": I = R + M*G + C = " + reach.equation();
                if (pastEnd) {
                    const HitGroupIndexTerms& terms = reach.terms;
                    findings.add(Level::Error, "IDX-11",
                                 who + " is past the end of the hit-group table (R = " + std::to_string(terms.rayContribution) +
                                     ", M = " + std::to_string(terms.multiplier) + ", G = " +
                                     std::to_string(terms.geometryIndex) + ", C = " +
                                     std::to_string(terms.instanceContribution) + "; stride " +
                                     std::to_string(hitTable.strideInBytes) + ", SizeInBytes " +
                                     std::to_string(hitTable.sizeInBytes) + ": " + std::to_string(hitTable.recordCount) +
                                     (hitTable.recordCount == 1 ? " record)" : " records)"));
                    continue;
                }
                hitUsed[size_t(reach.record)] = true;
                const RecordView& r = hitTable.records[size_t(reach.record)];
                const bool aabbs = g.type == "AABBs";
                if (r.contents == RecordView::Contents::Null) {
                    findings.add(Level::Note, "REC-8",
                                 who + " lands on a NULL record: " +
                                     (aabbs ? "no intersection shader runs, so these rays never hit the AABBs"
                                            : "the hit counts, but no any-hit or closest-hit shader runs"));
                    continue;
                }
                if (r.contents != RecordView::Contents::Export || r.kind != toString(ProgramEntry::Kind::HitGroup))
                    continue;  // reported once for the record below
                if (aabbs != (r.hitGroupType == "procedural")) {
                    findings.add(Level::Error, "IDX-14", who + " selects " + r.describe() + ", a " + r.hitGroupType +
                                                             " hit group, for " + (aabbs ? "AABB" : "triangle") + " geometry");
                    continue;
                }
                if (!r.payload.empty() && r.payload != t.payload) {
                    const bool closestHit = !r.closestHit.empty();
                    const std::string shader = closestHit ? "closest-hit shader " + inQuotes(r.closestHit)
                                                          : "any-hit shader " + inQuotes(r.anyHit);
                    findings.add(Level::Warning, "PAY-1",
                                 who + " selects " + r.describe() + ", whose " + shader + " takes payload " +
                                     inQuotes(r.payload) + ", not the ray type's " + inQuotes(t.payload) + " (undefined if its " +
                                     (closestHit ? "closest-hit" : "any-hit") + " shader runs)");
                }
            }
        }
    }

    // Records: what holds for any ray that reaches them, then the ones nothing reaches (IDX-12).
    for (const RecordView& r : view.tables[0].records)
        checkRecord(view.tables[0], r, ProgramEntry::Kind::RayGeneration, view.stateObject, findings);
    for (size_t i = 0; i < missTable.records.size(); ++i)
        if (missUsed[i]) checkRecord(missTable, missTable.records[i], ProgramEntry::Kind::Miss, view.stateObject, findings);
    for (size_t i = 0; i < hitTable.records.size(); ++i)
        if (hitUsed[i]) checkRecord(hitTable, hitTable.records[i], ProgramEntry::Kind::HitGroup, view.stateObject, findings);
    for (size_t i = 0; i < missTable.records.size(); ++i)
        if (!missUsed[i])
            findings.add(Level::Note, "IDX-12", recordName(missTable, i) + " (" +
                                                    missTable.records[i].describe() + ") is used by no ray type");
    for (size_t i = 0; i < hitTable.records.size(); ++i)
        if (!hitUsed[i])
            findings.add(Level::Note, "IDX-12", recordName(hitTable, i) + " (" +
                                                    hitTable.records[i].describe() +
                                                    ") is reached by no instance, geometry and ray type");

    view.findings = std::move(findings).sorted();

    // RayQuery owners (RQ-2): the exports that declare RayQuery objects and that the scene runs: imported by a hit
    // group, a ray generation, miss or callable export of the state object, or the scene's compute shader. (The
    // library may export more; nothing runs those.)
    for (const auto& [name, e] : stateObject->exports()) {
        if (e->rayQueryFlags.empty()) continue;
        bool runs = name == desc.computeShader;
        for (const ProgramEntry& entry : stateObject->entries())
            runs = runs || entry.shader == e || entry.intersection == e || entry.anyHit == e || entry.closestHit == e;
        if (!runs) continue;
        RayQueryOwnerView owner;
        owner.exportName = name;
        owner.stage = std::string(toString(e->stage));
        owner.templateFlags = e->rayQueryFlags;
        owner.numThreads[0] = e->numThreads.x;
        owner.numThreads[1] = e->numThreads.y;
        owner.numThreads[2] = e->numThreads.z;
        for (const ProgramEntry& entry : stateObject->entries())
            if (entry.kind == ProgramEntry::Kind::HitGroup &&
                (entry.intersection == e || entry.anyHit == e || entry.closestHit == e))
                owner.hitGroups.push_back(entry.name);
        view.rayQueryOwners.push_back(std::move(owner));
    }
    if (!desc.computeShader.empty()) {
        const ShaderExport* cs = stateObject->findComputeShader(desc.computeShader);
        REFRAY_CHECK(cs, "the state object has no compute shader '" << desc.computeShader << "'");
        view.compute.shader = desc.computeShader;
        view.compute.numThreads[0] = cs->numThreads.x;
        view.compute.numThreads[1] = cs->numThreads.y;
        view.compute.numThreads[2] = cs->numThreads.z;
    }
    return view;
}

}  // namespace refray::scenes
