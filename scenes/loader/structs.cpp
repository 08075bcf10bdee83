// "structs" (HLSL struct layouts of 32-bit fields) and the constant values laid out with them: "values" and
// the constants arguments of records.
#include <cstring>

#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

using Field = StructField;
using StructLayout = StructDesc;

namespace {

Field parseFieldType(const Value& value) {
    static const std::vector<std::string> types = {"float",  "float2", "float3", "float4", "int",  "int2",
                                                   "int3",   "int4",   "uint",   "uint2",  "uint3", "uint4"};
    const uint32_t t = resolveName(value, types, "field type");
    Field f;
    f.kind = t < 4 ? ScalarKind::Float : t < 8 ? ScalarKind::Int : ScalarKind::Uint;
    f.components = t % 4 + 1;
    return f;
}

// The dwords of `value` (an object of field values) laid out as `layout`; missing fields are 0 (padding).
std::vector<uint32_t> encodeStruct(const Value& value, const StructLayout& layout, const std::string& what) {
    ObjectReader reader(value, what);
    std::vector<uint32_t> dwords(layout.dwords, 0u);
    for (const Field& f : layout.fields) {
        const Value* v = reader.optional(f.name);
        if (!v) continue;
        const std::string fieldWhat = "field '" + f.name + "' of " + what;
        if (f.components == 1) {
            if (v->isArray()) v->fail(fieldWhat + " is a scalar; give one number");
            dwords[f.offset] = encodeScalar(*v, f.kind, fieldWhat);
        } else {
            const auto& a = v->asArray();
            if (a.size() != f.components)
                v->fail(fieldWhat + " needs " + std::to_string(f.components) + " numbers, got " +
                        std::to_string(a.size()));
            for (uint32_t i = 0; i < f.components; ++i) dwords[f.offset + i] = encodeScalar(a[i], f.kind, fieldWhat);
        }
    }
    reader.finish();
    return dwords;
}

}  // namespace

uint32_t encodeScalar(const Value& v, ScalarKind kind, const std::string& what) {
    switch (kind) {
        case ScalarKind::Float: {
            const float f = v.asFloat();
            uint32_t bits;
            std::memcpy(&bits, &f, 4);
            return bits;
        }
        case ScalarKind::Int: {
            const int64_t i = v.asInt();
            if (i < INT32_MIN || i > INT32_MAX) v.fail(what + " does not fit in a 32-bit int");
            return uint32_t(int32_t(i));
        }
        case ScalarKind::Uint: return v.asUint32();
    }
    return 0;
}

void parseStructs(ParseContext& ctx, const Value& value) {
    for (const json::Member& m : value.asObject()) {
        StructLayout layout;
        layout.name = m.key;
        for (const Value& fieldValue : m.value.asArray()) {
            const auto& pair = fieldValue.asArray();
            if (pair.size() != 2)
                fieldValue.fail("a field of struct " + inQuotes(m.key) + " is [\"type\", \"name\"]");
            Field f = parseFieldType(pair[0]);
            f.name = nonEmptyName(pair[1], "a field name");
            for (const Field& other : layout.fields)
                if (other.name == f.name) pair[1].fail("struct " + inQuotes(m.key) + " has two fields " + inQuotes(f.name));
            f.offset = layout.dwords;
            layout.dwords += f.components;
            layout.fields.push_back(f);
        }
        if (layout.dwords == 0) m.value.fail("struct " + inQuotes(m.key) + " has no fields");
        ctx.structNames.push_back(m.key);
        ctx.scene.structs.push_back(std::move(layout));
    }
}

std::vector<uint32_t> constantValue(const ParseContext& ctx, const Value& value, int32_t structIndex, uint32_t num32,
                                    const std::string& what) {
    if (structIndex < 0) {
        // No struct: a flat array of 32-bit floats (declare a struct for ints and uints).
        const auto& a = value.asArray();
        if (a.size() != num32)
            value.fail(what + " needs " + std::to_string(num32) + " 32-bit values, got " + std::to_string(a.size()));
        std::vector<uint32_t> d;
        for (const Value& v : a) d.push_back(encodeScalar(v, ScalarKind::Float, what));
        return d;
    }
    const StructLayout& layout = ctx.scene.structs[size_t(structIndex)];
    if (value.isString()) {
        std::vector<std::string> names;
        const Value* found = nullptr;
        if (ctx.values)
            for (const json::Member& m : ctx.values->asObject()) {
                names.push_back(m.key);
                if (m.key == value.asString()) found = &m.value;
            }
        if (!found) resolveName(value, names, "value");
        return encodeStruct(*found, layout, "value " + inQuotes(value.asString()) + " (a " + layout.name + ")");
    }
    return encodeStruct(value, layout, what + " (a " + layout.name + ")");
}

}  // namespace refray::scenes::loader
