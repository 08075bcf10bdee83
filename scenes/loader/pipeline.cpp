// "pipeline", "rayTypes" and "hitGroups": the shaders and hit groups the state object holds, checked against the
// scene's shader library.
#include <algorithm>

#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

namespace {

// The TraceRay arguments the shaders pass for ray type `index`: what the library's HLSL passes, each replaced by
// the ray type's "traceRay" where it gives one. Values above DXR's bit widths are kept: the emulator masks them
// when the ray is traced (IDX-2 warns about R and M).
void setTraceRayArguments(const ParseContext& ctx, RayTypeDesc& t, uint32_t index, const Value* traceRay) {
    procedural::TraceRayArguments a{index, ctx.binding->rayTypeCount, index, ~0u};
    if (index < ctx.binding->traceRayDefaults.size()) a = ctx.binding->traceRayDefaults[index];
    if (traceRay) {
        std::string what = "traceRay of ray type ";
        what += inQuotes(t.name);
        ObjectReader r(*traceRay, std::move(what));
        if (const Value* v = r.optional("rayContribution")) a.rayContribution = v->asUint32();
        if (const Value* v = r.optional("multiplier")) a.multiplier = v->asUint32();
        if (const Value* v = r.optional("missShaderIndex")) a.missShaderIndex = v->asUint32();
        if (const Value* v = r.optional("instanceInclusionMask")) a.instanceInclusionMask = v->asUint32();
        r.finish();
    }
    t.rayContribution = a.rayContribution;
    t.multiplier = a.multiplier;
    t.missShaderIndex = a.missShaderIndex;
    t.instanceInclusionMask = a.instanceInclusionMask;
}

}  // namespace

void parsePipeline(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "pipeline");
    if (const Value* cs = r.optional("compute")) {  // a compute dispatch renders the scene (docs/ray-query.md)
        ctx.scene.computeShader = cs->asString();
        requireExport(ctx, *cs, dxr::ShaderStage::Compute);
    }
    const Value& rg = r.required("rayGeneration");
    ctx.scene.rayGeneration = rg.asString();
    requireExport(ctx, rg, dxr::ShaderStage::RayGeneration);
    const Value& depth = r.required("maxRecursionDepth");
    ctx.scene.maxRecursionDepth = depth.asUint32();
    if (ctx.scene.maxRecursionDepth > 31) depth.fail("maxRecursionDepth must be 0..31 (PIPE-2)");
    ctx.scene.maxPayloadBytes = r.required("maxPayloadBytes").asUint32();
    ctx.scene.maxAttributeBytes = r.required("maxAttributeBytes").asUint32();
    r.finish();
}

const dxr::ShaderExport& requireExport(const ParseContext& ctx, const Value& nameValue, dxr::ShaderStage stage) {
    const std::string& name = nameValue.asString();
    std::vector<std::string> names;
    for (const auto& [n, e] : ctx.library->exports())
        if (e.stage == stage) names.push_back(n);
    const dxr::ShaderExport* e = ctx.library->find(name);
    if (!e) {
        std::vector<std::string> all;
        for (const auto& kv : ctx.library->exports()) all.push_back(kv.first);
        nameValue.fail("shader library " + inQuotes(ctx.binding->name) + " has no export " + inQuotes(name) +
                       didYouMean(name, names.empty() ? all : names) + "; its " +
                       std::string(dxr::toString(stage)) + " exports: " + joined(names));
    }
    if (e->stage != stage)
        nameValue.fail("export " + inQuotes(name) + " is a " + std::string(dxr::toString(e->stage)) +
                       " shader, not a " + std::string(dxr::toString(stage)) + " shader" +
                       (names.empty() ? "" : "; " + std::string(dxr::toString(stage)) + " exports: " + joined(names)));
    return *e;
}

void parseRayTypes(ParseContext& ctx, const Value& value) {
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a ray type");
        RayTypeDesc t;
        t.name = nonEmptyName(r.required("name"), "a ray type's name");
        r.setWhat("ray type " + inQuotes(t.name));
        for (const RayTypeDesc& o : ctx.scene.rayTypes)
            if (o.name == t.name) v.fail("two ray types are named " + inQuotes(t.name));
        const Value& miss = r.required("miss");
        t.miss = miss.asString();
        const dxr::ShaderExport& e = requireExport(ctx, miss, dxr::ShaderStage::Miss);
        const Value& payload = r.required("payload");
        t.payload = payload.asString();
        const std::string declared = withoutNamespace(e.payload.name());
        if (declared != t.payload)
            payload.fail("ray type " + inQuotes(t.name) + " says its payload is " + inQuotes(t.payload) +
                         ", but its miss shader " + inQuotes(t.miss) + " takes " + inQuotes(declared));
        const Value* traceRay = r.optional("traceRay");
        if (traceRay && !ctx.binding->configurable)
            traceRay->fail("the " + ctx.binding->name + " shaders pass fixed TraceRay arguments; remove 'traceRay'");
        setTraceRayArguments(ctx, t, uint32_t(ctx.scene.rayTypes.size()), traceRay);
        r.finish();
        ctx.scene.rayTypes.push_back(t);
    }
    if (ctx.scene.rayTypes.empty()) value.fail("a scene needs at least one ray type");
    if (ctx.scene.rayTypes.size() != ctx.binding->rayTypeCount)
        value.fail("the " + ctx.binding->name + " shaders trace " + std::to_string(ctx.binding->rayTypeCount) +
                   " ray types (by default ray contribution r, multiplier " +
                   std::to_string(ctx.binding->rayTypeCount) + ", miss index r); the scene declares " +
                   std::to_string(ctx.scene.rayTypes.size()));
}

void parseHitGroups(ParseContext& ctx, const Value& value) {
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a hit group");
        dxr::HitGroupDesc g;
        g.HitGroupExport = nonEmptyName(r.required("name"), "a hit group's name");
        r.setWhat("hit group " + inQuotes(g.HitGroupExport));
        if (std::find(ctx.hitGroupNames.begin(), ctx.hitGroupNames.end(), g.HitGroupExport) != ctx.hitGroupNames.end())
            v.fail("two hit groups are named " + inQuotes(g.HitGroupExport));
        if (ctx.library->find(g.HitGroupExport))
            v.fail("hit group " + inQuotes(g.HitGroupExport) + " has the name of a shader export (PIPE-4)");
        const uint32_t type = resolveName(r.required("type"), {"triangles", "procedural"}, "hit group type");
        g.Type = type == 0 ? dxr::HitGroupType::Triangles : dxr::HitGroupType::ProceduralPrimitive;
        if (const Value* s = r.optional("closestHit"))
            g.ClosestHitShaderImport = s->asString(), requireExport(ctx, *s, dxr::ShaderStage::ClosestHit);
        if (const Value* s = r.optional("anyHit"))
            g.AnyHitShaderImport = s->asString(), requireExport(ctx, *s, dxr::ShaderStage::AnyHit);
        if (const Value* s = r.optional("intersection")) {
            if (type == 0) s->fail("a triangles hit group has no intersection shader (PIPE-4)");
            g.IntersectionShaderImport = s->asString();
            requireExport(ctx, *s, dxr::ShaderStage::Intersection);
        } else if (type == 1) {
            v.fail("procedural hit group " + inQuotes(g.HitGroupExport) + " needs an 'intersection' shader (PIPE-4)");
        }
        r.finish();
        ctx.hitGroupNames.push_back(g.HitGroupExport);
        ctx.scene.hitGroups.push_back(g);
    }
}

}  // namespace refray::scenes::loader
