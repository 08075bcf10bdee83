// "buffers": data buffers, and the buffers generated each frame (scene constants, instance and primitive
// transforms) or from the models (models.cpp).
#include <algorithm>
#include <cstring>

#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

uint32_t addBuffer(ParseContext& ctx, BufferDesc buffer, const Value& where) {
    if (buffer.name.empty() || buffer.name[0] == '@') where.fail("buffer names must not be empty or start with '@'");
    if (ctx.scene.findBuffer(buffer.name) >= 0) where.fail("two buffers are named " + inQuotes(buffer.name));
    buffer.where = where.location();
    ctx.scene.buffers.push_back(std::move(buffer));
    return uint32_t(ctx.scene.buffers.size() - 1);
}

void parseDataBuffers(ParseContext& ctx, const Value& value) {
    for (const json::Member& m : value.asObject()) {
        if (!m.value.isObject()) m.value.fail("expected an object for buffer " + inQuotes(m.key) + ", got " +
                                              std::string(m.value.kindName()));
        if (const std::optional<BufferDesc::Kind> kind = staticModelKind(m.value)) {
            addModelBuffer(ctx, m, *kind);  // before the geometry that reads it
            continue;
        }
        if (m.value.find("generate")) continue;  // after the instances
        ObjectReader r(m.value, "buffer " + inQuotes(m.key));
        BufferDesc b;
        b.name = m.key;
        if (const Value* structName = r.optional("struct")) {  // a StructuredBuffer of one of the file's structs
            const int32_t index = int32_t(resolveName(*structName, ctx.structNames, "struct"));
            const auto& elements = r.required("elements").asArray();
            for (size_t i = 0; i < elements.size(); ++i) {
                const std::vector<uint32_t> dwords = constantValue(
                    ctx, elements[i], index, 0, "element " + std::to_string(i) + " of buffer " + inQuotes(m.key));
                b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(dwords.data()),
                               reinterpret_cast<const uint8_t*>(dwords.data() + dwords.size()));
            }
            if (b.bytes.empty()) m.value.fail("buffer " + inQuotes(m.key) + " has no elements");
            b.stride = uint32_t(ctx.scene.structs[size_t(index)].dwords * 4);
            r.finish();
            addBuffer(ctx, std::move(b), m.value);
            continue;
        }
        const uint32_t format = resolveName(r.required("format"), {"uint16", "uint32", "int32", "float32"}, "buffer format");
        for (const Value& v : r.required("data").asArray()) {
            uint32_t bits = 0;
            if (format == 0) {
                const uint32_t u = v.asUint32();
                if (u > 0xFFFF) v.fail("a uint16 buffer holds values up to 65535, got " + std::to_string(u));
                const uint16_t h = uint16_t(u);
                b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&h), reinterpret_cast<const uint8_t*>(&h) + 2);
                continue;
            }
            bits = encodeScalar(v, format == 1 ? ScalarKind::Uint : format == 2 ? ScalarKind::Int : ScalarKind::Float,
                                "an element of buffer " + inQuotes(m.key));
            b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&bits), reinterpret_cast<const uint8_t*>(&bits) + 4);
        }
        if (b.bytes.empty()) m.value.fail("buffer " + inQuotes(m.key) + " has no data");
        if (const Value* s = r.optional("stride")) {
            b.stride = s->asUint32();
            if (b.stride == 0 || b.bytes.size() % b.stride != 0)
                s->fail("buffer " + inQuotes(m.key) + " holds " + std::to_string(b.bytes.size()) +
                        " bytes, not a multiple of its stride " + std::to_string(b.stride));
        }
        r.finish();
        addBuffer(ctx, std::move(b), m.value);
    }
}

void parseGeneratedBuffers(ParseContext& ctx, const Value& value) {
    std::vector<std::string> kinds = {"sceneConstants", "instanceTransforms", "primitiveTransforms"};
    for (const auto& k : modelBufferKinds()) kinds.push_back(k.first);
    for (const json::Member& m : value.asObject()) {
        if (!m.value.find("generate") || staticModelKind(m.value)) continue;
        const uint32_t kind = resolveName(*m.value.find("generate"), kinds, "generated buffer kind");
        if (kind >= 3) {
            addModelBuffer(ctx, m, modelBufferKinds()[kind - 3].second);
            continue;
        }
        ObjectReader r(m.value, "buffer " + inQuotes(m.key));
        r.required("generate");
        BufferDesc b;
        b.name = m.key;
        if (kind == 0) {
            b.kind = BufferDesc::Kind::SceneConstants;
            const std::string flagKey = ctx.binding->hasDebugFlag ? ctx.binding->debugFlagName : "debugFlag";
            if (const Value* d = r.optional(flagKey)) {
                if (!ctx.binding->hasDebugFlag)
                    d->fail("the " + ctx.binding->name + " scene constants have no debugFlag");
                const int64_t flag = d->asInt();
                if (flag < INT32_MIN || flag > INT32_MAX) d->fail(flagKey + " does not fit in a 32-bit int");
                b.debugFlag = int32_t(flag);
            }
            if (flagKey != "debugFlag")
                if (const Value* d = r.optional("debugFlag"))
                    d->fail("the " + ctx.binding->name + " scene constants have no debugFlag; their debug switch "
                            "is '" + flagKey + "'");
            const auto takes = [&](const char* key) {
                const auto& keys = ctx.binding->constantsKeys;
                return std::find(keys.begin(), keys.end(), key) != keys.end();
            };
            if (takes("backgroundColor"))
                if (const Value* c = r.optional("backgroundColor"))
                    b.backgroundColor = floatVector<3>(*c, "backgroundColor");
            if (takes("maxBounces"))
                if (const Value* n = r.optional("maxBounces")) b.maxBounces = n->asUint32();
        } else if (kind == 1) {
            b.kind = BufferDesc::Kind::InstanceTransforms;
            for (const Value& v : r.required("instances").asArray())
                b.instances.push_back(resolveName(v, ctx.instanceNames, "instance"));
            if (b.instances.empty()) m.value.fail("an instanceTransforms buffer lists at least one instance");
        } else {
            b.kind = BufferDesc::Kind::PrimitiveTransforms;
            const Value& blasValue = r.required("blas");
            const BlasDesc& blas = ctx.scene.blases[resolveName(blasValue, ctx.blasNames, "bottom-level structure")];
            for (const Value& e : r.required("elements").asArray()) {
                ObjectReader er(e, "an element of buffer " + inQuotes(m.key));
                const Value& g = er.required("geometry");
                const uint32_t gi = g.asUint32();
                if (gi >= blas.geometries.size())
                    g.fail("BLAS " + inQuotes(blas.name) + " has " + std::to_string(blas.geometries.size()) +
                           " geometries; there is no geometry " + std::to_string(gi));
                const GeometryDescFile& geometry = blas.geometries[gi];
                if (geometry.type != dxr::GeometryType::ProceduralPrimitiveAABBs)
                    g.fail("geometry " + std::to_string(gi) + " of BLAS " + inQuotes(blas.name) + " holds triangles, not AABBs");
                dxr::RaytracingAABB box;
                std::memcpy(&box, ctx.scene.buffers[geometry.aabbBuffer].bytes.data(), sizeof box);
                PrimitiveTransformDesc p;
                p.centre = vec3(0.5f * (box.MinX + box.MaxX), 0.5f * (box.MinY + box.MaxY), 0.5f * (box.MinZ + box.MaxZ));
                if (const Value* s = er.optional("scale")) p.scale = floatVector<3>(*s, "scale");
                if (const Value* s = er.optional("spinYPerSecond")) p.spinYPerSecond = finiteNumber(*s, "spinYPerSecond");
                er.finish();
                b.primitives.push_back(p);
            }
            if (b.primitives.empty()) m.value.fail("a primitiveTransforms buffer lists at least one element");
        }
        r.finish();
        addBuffer(ctx, std::move(b), m.value);
    }
}

int32_t dataOrGeneratedBuffer(const ParseContext& ctx, const Value& nameValue) {
    std::vector<std::string> names;
    for (const BufferDesc& b : ctx.scene.buffers) names.push_back(b.name);
    return int32_t(resolveName(nameValue, names, "buffer"));
}

int32_t dataBuffer(const ParseContext& ctx, const Value& nameValue) {
    const int32_t i = dataOrGeneratedBuffer(ctx, nameValue);
    if (!ctx.scene.buffers[size_t(i)].isStatic())
        nameValue.fail("buffer " + inQuotes(nameValue.asString()) + " is generated each frame; geometry needs a data buffer");
    return i;
}

}  // namespace refray::scenes::loader
