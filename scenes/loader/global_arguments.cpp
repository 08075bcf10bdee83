// "globalArguments": what the global root signature's parameters are bound to: buffers, the TLAS, descriptor tables
// of buffers, the render target and the models' textures.
#include <filesystem>

#include "core/strings.h"
#include "emulator/root_signature.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

namespace {

// {"textures": "diffuse" | "normal"}: one Texture2D SRV per texture of the models' materials, in the order of
// GlobalModelBuffers (the indices MaterialGPU holds), or one null descriptor when there is none.
void appendTextures(const ParseContext& ctx, const Value& value, GlobalArgumentDesc::TableEntry entry,
                    std::vector<GlobalArgumentDesc::TableEntry>& table, const std::string& parameter) {
    ObjectReader r(value, "a textures entry of " + inQuotes(parameter));
    const Value& which = r.required("textures");
    r.finish();
    const uint32_t kind = resolveName(which, {"diffuse", "normal"}, "texture list");
    if (ctx.scene.models.empty())
        which.fail("{\"textures\": ...} binds the textures of the scene's 'models'; this scene has none");
    if (entry.type != dxr::DescriptorRangeType::SRV)
        which.fail("textures are SRVs; the unbounded range of " + inQuotes(parameter) + " holds " +
                   std::string(dxr::toString(entry.type)) + "s");
    const auto& paths = kind == 0 ? ctx.scene.modelBuffers.diffuseTextures : ctx.scene.modelBuffers.normalTextures;
    entry.isTexture = true;
    if (paths.empty()) table.push_back(entry);
    for (const std::filesystem::path& path : paths) {
        entry.texture = path;
        table.push_back(entry);
    }
}

}  // namespace

void parseGlobalArguments(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "globalArguments");
    const dxr::RootSignatureDesc& sig = ctx.scene.globalSignature;
    for (size_t p = 0; p < sig.parameters.size(); ++p) {
        const dxr::RootParameter& param = sig.parameters[p];
        const std::string& name = ctx.globalInfo.parameters[p].name;
        const Value& v = r.required(name);
        GlobalArgumentDesc a;
        a.parameter = uint32_t(p);
        switch (param.parameterType) {
            case dxr::RootParameterType::Constants32Bit:
                v.fail("global root constants are not supported in scene files yet; use a constant buffer");
            case dxr::RootParameterType::DescriptorTable: {
                a.kind = GlobalArgumentDesc::Kind::Table;
                std::vector<dxr::DescriptorRangeType> slots;
                const dxr::DescriptorRange* unbounded = nullptr;  // the last range, when it is unbounded
                for (const dxr::DescriptorRange& range : param.ranges) {
                    if (range.numDescriptors == dxr::kDescriptorRangeUnbounded) {
                        unbounded = &range;
                        break;
                    }
                    for (uint32_t k = 0; k < range.numDescriptors; ++k) slots.push_back(range.rangeType);
                }
                const auto& entries = v.asArray();
                if (unbounded && entries.size() <= slots.size()) {
                    std::string range = "(";
                    range += dxr::registerLetter(unbounded->rangeType);
                    range += std::to_string(unbounded->baseShaderRegister);
                    range += ".., space ";
                    range += std::to_string(unbounded->registerSpace);
                    range += ")";
                    v.fail("table " + inQuotes(name) + " ends in an unbounded range " + range + ", which needs " +
                           "at least one descriptor after the " + std::to_string(slots.size()) +
                           " of its other ranges; bind the models' textures with {\"textures\": \"diffuse\"} "
                           "or {\"textures\": \"normal\"}");
                }
                if (!unbounded && entries.size() != slots.size())
                    v.fail("table " + inQuotes(name) + " has " + std::to_string(slots.size()) + " descriptors; " +
                           std::to_string(entries.size()) + " given");
                for (size_t k = 0; k < entries.size(); ++k) {
                    GlobalArgumentDesc::TableEntry e;
                    e.type = k < slots.size() ? slots[k] : unbounded->rangeType;
                    if (entries[k].isObject() && entries[k].find("textures")) {
                        if (k < slots.size())
                            entries[k].fail("{\"textures\": ...} binds as many descriptors as the models have "
                                            "textures, so it belongs in an unbounded range; descriptor " +
                                            std::to_string(k) + " of " + inQuotes(name) + " is in a bounded one");
                        appendTextures(ctx, entries[k], e, a.table, name);
                        continue;
                    }
                    if (entries[k].isString()) {
                        if (entries[k].asString() != "@renderTarget")
                            entries[k].fail("a table entry is \"@renderTarget\" or {\"buffer\": NAME, \"stride\": N}");
                        if (e.type != dxr::DescriptorRangeType::UAV)
                            entries[k].fail("the render target is a UAV; descriptor " + std::to_string(k) + " of " +
                                            inQuotes(name) + " is a " + std::string(dxr::toString(e.type)));
                        e.renderTarget = true;
                    } else {
                        ObjectReader er(entries[k], "descriptor " + std::to_string(k) + " of " + inQuotes(name));
                        e.buffer = dataOrGeneratedBuffer(ctx, er.required("buffer"));
                        if (const Value* s = er.optional("stride")) e.stride = s->asUint32();
                        er.finish();
                    }
                    a.table.push_back(e);
                }
                break;
            }
            default:
                if (v.isString() && v.asString() == "@tlas") {
                    if (param.parameterType != dxr::RootParameterType::SRV)
                        v.fail("the acceleration structure binds to a root SRV; " + inQuotes(name) + " is a " +
                               std::string(dxr::toString(param.parameterType)));
                    a.kind = GlobalArgumentDesc::Kind::AccelerationStructure;
                } else {
                    a.kind = GlobalArgumentDesc::Kind::Buffer;
                    a.buffer = dataOrGeneratedBuffer(ctx, v);
                }
        }
        ctx.scene.globalArguments.push_back(std::move(a));
    }
    r.finish();
}

}  // namespace refray::scenes::loader
