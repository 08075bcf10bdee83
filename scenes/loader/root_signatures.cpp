// "rootSignatures": the global root signature and the local ones, their parameters, ranges and static samplers.
#include <algorithm>
#include <string>

#include "core/error.h"
#include "core/strings.h"
#include "emulator/texture.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

namespace {

std::pair<char, uint32_t> parseRegister(const Value& v) {
    const std::string& s = v.asString();
    if (s.size() < 2 || std::string("btus").find(s[0]) == std::string::npos)
        v.fail("a register is written like b0, t3, u0 or s1, got " + inQuotes(s));
    uint32_t n = 0;
    for (size_t i = 1; i < s.size(); ++i) {
        if (s[i] < '0' || s[i] > '9' || n > 100000000) v.fail("a register is written like b0, t3, u0 or s1, got " + inQuotes(s));
        n = n * 10 + uint32_t(s[i] - '0');
    }
    return {s[0], n};
}

void expectRegisterClass(const Value& v, char actual, char expected, const std::string& what) {
    if (actual != expected)
        v.fail(what + " binds a '" + std::string(1, expected) + "' register, got " + inQuotes(v.asString()));
}

// A D3D12_STATIC_SAMPLER_DESC: {"register": "s0", "space", "filter", "address" (all three) or "addressU" /
// "addressV" / "addressW", "mipLODBias", "maxAnisotropy", "borderColor", "minLOD", "maxLOD"}.
dxr::StaticSamplerDesc parseStaticSampler(const Value& value, const std::string& signature, size_t index) {
    static const std::vector<std::pair<std::string, dxr::SamplerFilter>> filters = {
        {"point", dxr::FILTER_MIN_MAG_MIP_POINT},
        {"linear", dxr::FILTER_MIN_MAG_MIP_LINEAR},
        {"anisotropic", dxr::FILTER_ANISOTROPIC},
        {"MIN_MAG_MIP_POINT", dxr::FILTER_MIN_MAG_MIP_POINT},
        {"MIN_MAG_POINT_MIP_LINEAR", dxr::FILTER_MIN_MAG_POINT_MIP_LINEAR},
        {"MIN_POINT_MAG_LINEAR_MIP_POINT", dxr::FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT},
        {"MIN_POINT_MAG_MIP_LINEAR", dxr::FILTER_MIN_POINT_MAG_MIP_LINEAR},
        {"MIN_LINEAR_MAG_MIP_POINT", dxr::FILTER_MIN_LINEAR_MAG_MIP_POINT},
        {"MIN_LINEAR_MAG_POINT_MIP_LINEAR", dxr::FILTER_MIN_LINEAR_MAG_POINT_MIP_LINEAR},
        {"MIN_MAG_LINEAR_MIP_POINT", dxr::FILTER_MIN_MAG_LINEAR_MIP_POINT},
        {"MIN_MAG_MIP_LINEAR", dxr::FILTER_MIN_MAG_MIP_LINEAR},
        {"ANISOTROPIC", dxr::FILTER_ANISOTROPIC}};
    static const std::vector<std::string> addressModes = {"wrap", "mirror", "clamp", "border", "mirror-once"};
    static const std::vector<std::string> borderColors = {"transparent-black", "opaque-black", "opaque-white"};
    std::string what = "static sampler ";
    what += std::to_string(index);
    what += " of root signature ";
    what += inQuotes(signature);
    ObjectReader r(value, what);
    dxr::StaticSamplerDesc d;
    const Value& reg = r.required("register");
    const auto [cls, n] = parseRegister(reg);
    expectRegisterClass(reg, cls, 's', "a static sampler");
    d.ShaderRegister = n;
    if (const Value* v = r.optional("space")) d.RegisterSpace = v->asUint32();
    if (const Value* v = r.optional("filter")) {
        std::vector<std::string> names;
        for (const auto& f : filters) names.push_back(f.first);
        d.Filter = filters[resolveName(*v, names, "sampler filter")].second;
    }
    const auto address = [&](const Value& v) {
        return dxr::TextureAddressMode(resolveName(v, addressModes, "texture address mode") + 1);
    };
    const Value* all = r.optional("address");
    const Value* u = r.optional("addressU");
    const Value* v = r.optional("addressV");
    const Value* w = r.optional("addressW");
    if (all && (u || v || w))
        (u ? u : v ? v : w)->fail("give 'address' (all three) or 'addressU' / 'addressV' / 'addressW', not both");
    if (all) d.AddressU = d.AddressV = d.AddressW = address(*all);
    if (u) d.AddressU = address(*u);
    if (v) d.AddressV = address(*v);
    if (w) d.AddressW = address(*w);
    if (const Value* x = r.optional("mipLODBias")) d.MipLODBias = x->asFloat();
    if (const Value* x = r.optional("maxAnisotropy")) d.MaxAnisotropy = x->asUint32();
    if (const Value* x = r.optional("borderColor"))
        d.BorderColor = dxr::StaticBorderColor(resolveName(*x, borderColors, "static border colour"));
    if (const Value* x = r.optional("minLOD")) d.MinLOD = x->asFloat();
    if (const Value* x = r.optional("maxLOD")) d.MaxLOD = x->asFloat();
    r.finish();
    try {
        dxr::validateSamplerDesc(d.sampler(), what);
    } catch (const Error& e) {
        value.fail(e.what());
    }
    return d;
}

dxr::RootSignatureDesc parseSignature(const ParseContext& ctx, const Value& value, bool local, SignatureInfo& info) {
    ObjectReader r(value, local ? "a local root signature" : "the global root signature");
    dxr::RootSignatureDesc desc;
    desc.name = nonEmptyName(r.required("name"), "a root signature's name");
    if (local) desc.flags = dxr::ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    for (const Value& p : r.required("parameters").asArray()) {
        ObjectReader pr(p, "a parameter of root signature " + inQuotes(desc.name));
        ParameterInfo pi;
        pi.name = nonEmptyName(pr.required("name"), "a parameter's name");
        for (const ParameterInfo& o : info.parameters)
            if (o.name == pi.name) p.fail("root signature " + inQuotes(desc.name) + " has two parameters " + inQuotes(pi.name));
        const Value& kindValue = pr.required("kind");
        const uint32_t kind = resolveName(kindValue, {"constants", "cbv", "srv", "uav", "table"}, "parameter kind");
        const Value* spaceValue = pr.optional("space");
        const uint32_t space = spaceValue ? spaceValue->asUint32() : 0;
        const std::string what = "parameter " + inQuotes(pi.name);
        if (kind == 4) {
            std::vector<dxr::DescriptorRange> ranges;
            for (const Value& rv : pr.required("ranges").asArray()) {
                ObjectReader rr(rv, "a range of " + what);
                dxr::DescriptorRange range;
                const uint32_t t = resolveName(rr.required("type"), {"SRV", "UAV", "CBV", "Sampler"}, "range type");
                range.rangeType = dxr::DescriptorRangeType(t);
                const Value& reg = rr.required("register");
                const auto [cls, n] = parseRegister(reg);
                expectRegisterClass(reg, cls, "tubs"[t], "a " + std::string(dxr::toString(range.rangeType)) + " range");
                range.baseShaderRegister = n;
                if (const Value* c = rr.optional("count")) {
                    if (c->isString()) {
                        // HLSL `Texture2D t[] : register(t0, space5)`: a range of UINT_MAX descriptors.
                        if (c->asString() != "unbounded")
                            c->fail("a range's count is a number or \"unbounded\", got " + inQuotes(c->asString()));
                        range.numDescriptors = dxr::kDescriptorRangeUnbounded;
                    } else {
                        range.numDescriptors = c->asUint32();
                        if (range.numDescriptors == dxr::kDescriptorRangeUnbounded)
                            c->fail("write an unbounded range as \"count\": \"unbounded\"");
                    }
                }
                if (range.numDescriptors == 0) rv.fail("a range needs at least one descriptor");
                if (!ranges.empty() && ranges.back().numDescriptors == dxr::kDescriptorRangeUnbounded)
                    rv.fail("a range follows the unbounded range of " + what +
                            "; scene files append ranges (OFFSET_APPEND), so an unbounded range must be the "
                            "last of its table (BIND-9)");
                if (const Value* s = rr.optional("space")) range.registerSpace = s->asUint32();
                rr.finish();
                ranges.push_back(range);
            }
            desc.parameters.push_back(dxr::RootParameter::table(ranges));
        } else {
            const Value& reg = pr.required("register");
            const auto [cls, n] = parseRegister(reg);
            if (kind == 0) {
                expectRegisterClass(reg, cls, 'b', what);
                uint32_t count = 0;
                if (const Value* s = pr.optional("struct")) {
                    pi.structIndex = int32_t(resolveName(*s, ctx.structNames, "struct"));
                    count = ctx.scene.structs[size_t(pi.structIndex)].dwords;
                }
                if (const Value* c = pr.optional("count")) {
                    if (pi.structIndex >= 0 && c->asUint32() != count)
                        c->fail(what + " declares " + std::to_string(c->asUint32()) + " values but its struct has " +
                                std::to_string(count));
                    count = c->asUint32();
                }
                if (count == 0) p.fail(what + " needs a 'struct' or a 'count' of 32-bit values");
                desc.parameters.push_back(dxr::RootParameter::constants(count, n, space));
            } else if (kind == 1) {
                expectRegisterClass(reg, cls, 'b', what);
                desc.parameters.push_back(dxr::RootParameter::cbv(n, space));
            } else if (kind == 2) {
                expectRegisterClass(reg, cls, 't', what);
                desc.parameters.push_back(dxr::RootParameter::srv(n, space));
            } else {
                expectRegisterClass(reg, cls, 'u', what);
                desc.parameters.push_back(dxr::RootParameter::uav(n, space));
            }
        }
        pr.finish();
        info.parameters.push_back(pi);
    }
    if (const Value* samplers = r.optional("staticSamplers")) {
        const auto& list = samplers->asArray();
        for (size_t i = 0; i < list.size(); ++i)
            desc.staticSamplers.push_back(parseStaticSampler(list[i], desc.name, i));
    }
    r.finish();
    return desc;
}

}  // namespace

void parseRootSignatures(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "rootSignatures");
    ctx.scene.globalSignature = parseSignature(ctx, r.required("global"), false, ctx.globalInfo);
    if (const Value* locals = r.optional("local"))
        for (const Value& l : locals->asArray()) {
            SignatureInfo info;
            dxr::RootSignatureDesc desc = parseSignature(ctx, l, true, info);
            if (std::find(ctx.localNames.begin(), ctx.localNames.end(), desc.name) != ctx.localNames.end())
                l.fail("two local root signatures are named " + inQuotes(desc.name));
            ctx.localNames.push_back(desc.name);
            ctx.localInfo.push_back(info);
            ctx.scene.localSignatures.push_back(std::move(desc));
        }
    r.finish();
    ctx.scene.localAssociations.resize(ctx.scene.localSignatures.size());
}

}  // namespace refray::scenes::loader
