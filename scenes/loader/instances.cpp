// "instances": the top-level instances, their transforms, IDs, masks and flags.
#include <algorithm>

#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

namespace {

Matrix3x4 parseTransform(const Value& value) {
    ObjectReader r(value, "a transform");
    Matrix3x4 m = Matrix3x4::identity();
    if (const Value* rows = r.optional("rowVectorMatrix")) {
        // DirectXMath layout: p' = p·M, translation in row 3; DXR stores the transpose of the 3x4 part.
        const auto& a = rows->asArray();
        if (a.size() != 4) rows->fail("rowVectorMatrix has 4 rows of 4 numbers");
        for (int i = 0; i < 4; ++i) {
            const vec4 row = floatVector<4>(a[size_t(i)], "a matrix row");
            for (int j = 0; j < 3; ++j) m.m[size_t(j)][size_t(i)] = row[j];
            if (row.w != (i == 3 ? 1.0f : 0.0f))
                a[size_t(i)].fail("the last column of an affine rowVectorMatrix is (0, 0, 0, 1)");
        }
    } else if (const Value* rows3 = r.optional("matrix3x4")) {
        const auto& a = rows3->asArray();
        if (a.size() != 3) rows3->fail("matrix3x4 (the DXR Transform) has 3 rows of 4 numbers");
        for (int i = 0; i < 3; ++i) {
            const vec4 row = floatVector<4>(a[size_t(i)], "a matrix row");
            for (int j = 0; j < 4; ++j) m.m[size_t(i)][size_t(j)] = row[j];
        }
    } else {
        // M = S · R · T in row-vector terms: scale, then rotate, then translate.
        Matrix3x4 s = Matrix3x4::identity(), rot = Matrix3x4::identity(), t = Matrix3x4::identity();
        if (const Value* v = r.optional("scale")) s = Matrix3x4::scale(floatVector<3>(*v, "scale"));
        if (const Value* v = r.optional("rotate")) {
            ObjectReader rr(*v, "rotate");
            const uint32_t axis = resolveName(rr.required("axis"), {"x", "y", "z"}, "rotation axis");
            const float radians = float(finiteNumber(rr.required("radians"), "radians"));
            vec3 a(0.0f);
            a[int(axis)] = 1.0f;
            rot = Matrix3x4::rotation(a, radians);
            rr.finish();
        }
        if (const Value* v = r.optional("translate")) t = Matrix3x4::translation(floatVector<3>(*v, "translate"));
        m = t * rot * s;
    }
    r.finish();
    if (!m.allFinite()) value.fail("the transform is not finite");
    return m;
}

}  // namespace

void parseInstances(ParseContext& ctx, const Value& value) {
    static const std::vector<std::pair<std::string, uint32_t>> instanceFlags = {
        {"TRIANGLE_CULL_DISABLE", dxr::INSTANCE_FLAG_TRIANGLE_CULL_DISABLE},
        {"TRIANGLE_FRONT_COUNTERCLOCKWISE", dxr::INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE},
        {"FORCE_OPAQUE", dxr::INSTANCE_FLAG_FORCE_OPAQUE},
        {"FORCE_NON_OPAQUE", dxr::INSTANCE_FLAG_FORCE_NON_OPAQUE}};
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "an instance");
        InstanceDescFile inst;
        inst.name = nonEmptyName(r.required("name"), "an instance name");
        r.setWhat("instance " + inQuotes(inst.name));
        if (std::find(ctx.instanceNames.begin(), ctx.instanceNames.end(), inst.name) != ctx.instanceNames.end())
            v.fail("two instances are named " + inQuotes(inst.name));
        inst.where = v.location();
        inst.blas = resolveName(r.required("blas"), ctx.blasNames, "bottom-level structure");
        if (const Value* t = r.optional("transform")) inst.transform = parseTransform(*t);
        // With models, InstanceID is the object index (= the instance index) that the shaders look objects
        // up by, as a path tracer's host writes it.
        if (!ctx.scene.models.empty()) inst.instanceID = uint32_t(ctx.scene.instances.size());
        if (const Value* id = r.optional("instanceID")) {
            inst.instanceID = id->asUint32();
            if (inst.instanceID > 0xFFFFFF) id->fail("InstanceID has 24 bits (INST-1), got " + std::to_string(inst.instanceID));
        }
        if (const Value* mask = r.optional("mask")) {
            inst.mask = mask->asUint32();
            if (inst.mask > 0xFF) mask->fail("InstanceMask has 8 bits (INST-1), got " + std::to_string(inst.mask));
        }
        if (const Value* f = r.optional("flags")) inst.flags = flagSet(*f, instanceFlags, "instance flag");
        if (ctx.scene.layout == LayoutMode::Explicit) {
            const Value& c = r.required("contribution");
            inst.contribution = c.asUint32();
            if (inst.contribution > 0xFFFFFF)
                c.fail("InstanceContributionToHitGroupIndex has 24 bits (INST-1), got " + std::to_string(inst.contribution));
            if (r.optional("records"))
                v.fail("instance 'records' belong to \"layout\": \"auto\"; explicit scenes list records in 'shaderTable'");
        } else {
            if (const Value* c = r.optional("contribution"))
                c->fail("in auto layout the instance contribution is computed; use \"layout\": \"explicit\" to set it");
            ctx.recordValues.push_back(&r.required("records"));
        }
        r.finish();
        ctx.instanceNames.push_back(inst.name);
        ctx.scene.instances.push_back(std::move(inst));
    }
    if (ctx.scene.instances.empty()) value.fail("a scene needs at least one instance");
}

}  // namespace refray::scenes::loader
