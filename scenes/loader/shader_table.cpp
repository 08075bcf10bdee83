// The hit-group records and miss records: from each instance's "records" (auto layout) or from "shaderTable"
// (explicit layout), and the local root signature association each hit group gets from them.
#include <map>

#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

namespace {

// ⟨hit group, local root signature, arguments⟩ from a record object (the keys other than hitGroup(s)).
void parseRecordBinding(const ParseContext& ctx, ObjectReader& r, RecordDesc& record, const std::string& what) {
    const Value* lrs = r.optional("localRootSignature");
    const Value* args = r.optional("arguments");
    if (!lrs) {
        if (args) args->fail(what + " has arguments but no 'localRootSignature'");
        return;
    }
    record.localRootSignature = int32_t(resolveName(*lrs, ctx.localNames, "local root signature"));
    const SignatureInfo& info = ctx.localInfo[size_t(record.localRootSignature)];
    const dxr::RootSignatureDesc& sig = ctx.scene.localSignatures[size_t(record.localRootSignature)];
    if (!args) {
        if (!info.parameters.empty())
            r.value().fail(what + " uses local root signature " + inQuotes(sig.name) + " but gives no 'arguments'");
        return;
    }
    ObjectReader ar(*args, "the arguments of " + what);
    for (size_t p = 0; p < info.parameters.size(); ++p) {
        const ParameterInfo& pi = info.parameters[p];
        const Value& v = ar.required(pi.name);
        RecordDesc::Argument a;
        a.parameter = uint32_t(p);
        const dxr::RootParameter& param = sig.parameters[p];
        if (param.parameterType == dxr::RootParameterType::Constants32Bit) {
            a.dwords = constantValue(ctx, v, pi.structIndex, param.num32BitValues, "argument " + inQuotes(pi.name));
            a.structIndex = pi.structIndex;
        } else if (param.parameterType == dxr::RootParameterType::DescriptorTable) {
            v.fail("local descriptor tables are not supported in scene files yet; bind buffers as root descriptors");
        } else {
            a.buffer = dataOrGeneratedBuffer(ctx, v);
        }
        record.arguments.push_back(std::move(a));
    }
    ar.finish();
}

// The hit group for a record of `geometry` (checks the geometry type against the hit group type).
void checkHitGroupFits(const ParseContext& ctx, const Value& where, const std::string& hitGroup,
                       const GeometryDescFile& geometry, const std::string& geometryWhat) {
    const dxr::HitGroupDesc& g = ctx.scene.hitGroups[resolveName(where, ctx.hitGroupNames, "hit group")];
    const bool triangles = geometry.type == dxr::GeometryType::Triangles;
    if (triangles != (g.Type == dxr::HitGroupType::Triangles))
        where.fail("hit group " + inQuotes(hitGroup) + " is a " + (triangles ? "procedural" : "triangles") +
                   " hit group, but " + geometryWhat + " holds " + (triangles ? "triangles" : "AABBs") + " (PIPE-4)");
}

}  // namespace

void buildAutoLayout(ParseContext& ctx) {
    uint32_t next = 0;
    for (size_t i = 0; i < ctx.scene.instances.size(); ++i) {
        InstanceDescFile& inst = ctx.scene.instances[i];
        const BlasDesc& blas = ctx.scene.blases[inst.blas];
        const Value& records = *ctx.recordValues[i];
        const auto& list = records.asArray();
        if (list.size() != blas.geometries.size())
            records.fail("instance " + inQuotes(inst.name) + " gives " + std::to_string(list.size()) +
                         " records but BLAS " + inQuotes(blas.name) + " has " + std::to_string(blas.geometries.size()) +
                         " geometries: one record entry per geometry, in geometry order");
        inst.contribution = next;
        for (size_t g = 0; g < list.size(); ++g) {
            const std::string geometryWhat = "geometry " + std::to_string(g) + " of BLAS " + inQuotes(blas.name);
            ObjectReader r(list[g], "the record of instance " + inQuotes(inst.name) + " " + geometryWhat);
            const Value& groups = r.required("hitGroups");
            ObjectReader gr(groups, "hitGroups (one per ray type)");
            RecordDesc binding;
            parseRecordBinding(ctx, r, binding, "instance " + inQuotes(inst.name) + " " + geometryWhat);
            for (const RayTypeDesc& rayType : ctx.scene.rayTypes) {
                const Value& hg = gr.required(rayType.name);
                RecordDesc record = binding;
                record.origin = "instance " + inQuotes(inst.name) + ", " + geometryWhat + ", ray type " + inQuotes(rayType.name);
                record.where = hg.location();
                if (!hg.isNull()) {
                    record.hitGroup = hg.asString();
                    checkHitGroupFits(ctx, hg, record.hitGroup, blas.geometries[g], geometryWhat);
                }
                ctx.recordWhere.push_back(&hg);
                ctx.scene.hitGroupRecords.push_back(std::move(record));
                ++next;
            }
            gr.finish();
            r.finish();
        }
        if (next > 0xFFFFFF) records.fail("the hit-group table outgrows the 24-bit instance contribution");
    }
    for (const RayTypeDesc& t : ctx.scene.rayTypes) ctx.scene.missRecords.push_back(t.miss);
}

void parseExplicitTable(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "shaderTable");
    for (const Value& m : r.required("miss").asArray()) {
        if (m.isNull()) {
            ctx.scene.missRecords.emplace_back();
            continue;
        }
        requireExport(ctx, m, dxr::ShaderStage::Miss);
        ctx.scene.missRecords.push_back(m.asString());
    }
    const auto& records = r.required("hitGroups").asArray();
    for (size_t i = 0; i < records.size(); ++i) {
        ObjectReader rr(records[i], "hit-group record " + std::to_string(i));
        RecordDesc record;
        record.origin = "hit-group record " + std::to_string(i);
        record.where = records[i].location();
        const Value& hg = rr.required("hitGroup");
        if (!hg.isNull()) {
            record.hitGroup = hg.asString();
            resolveName(hg, ctx.hitGroupNames, "hit group");
        }
        parseRecordBinding(ctx, rr, record, record.origin);
        rr.finish();
        ctx.recordWhere.push_back(&hg);
        ctx.scene.hitGroupRecords.push_back(std::move(record));
    }
    if (const Value* s = r.optional("hitGroupStride")) {
        ctx.scene.hitGroupStride = s->asUint32();
        if (ctx.scene.hitGroupStride % 32 != 0 || ctx.scene.hitGroupStride > 4096)
            s->fail("a hit-group stride is a multiple of 32 up to 4096 (REC-3), got " + std::to_string(ctx.scene.hitGroupStride));
    }
    r.finish();
}

void deriveAssociations(ParseContext& ctx) {
    std::map<std::string, std::pair<int32_t, const Value*>> byGroup;
    for (size_t i = 0; i < ctx.scene.hitGroupRecords.size(); ++i) {
        const RecordDesc& r = ctx.scene.hitGroupRecords[i];
        if (r.hitGroup.empty()) continue;
        const auto [it, inserted] = byGroup.emplace(r.hitGroup, std::make_pair(r.localRootSignature, ctx.recordWhere[i]));
        if (!inserted && it->second.first != r.localRootSignature) {
            auto name = [&](int32_t s) { return s < 0 ? std::string("none") : inQuotes(ctx.scene.localSignatures[size_t(s)].name); };
            ctx.recordWhere[i]->fail("hit group " + inQuotes(r.hitGroup) + " is used with local root signature " +
                                     name(r.localRootSignature) + " here but with " + name(it->second.first) + " at " +
                                     json::toString(it->second.second->location()) +
                                     "; a state object associates one local root signature with each export (ASSOC-3)");
        }
    }
    for (const auto& [group, sig] : byGroup)
        if (sig.first >= 0) ctx.scene.localAssociations[size_t(sig.first)].push_back(group);
}

}  // namespace refray::scenes::loader
