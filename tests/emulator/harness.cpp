#include "harness.h"

#include <gtest/gtest.h>

#include "emulator/intersection.h"

namespace refray::test {

Harness::Harness() {
    stateObject.name = "test";
    stateObject.shaderConfigs = {{64, 32}};
    stateObject.pipelineConfigs = {{2, PIPELINE_FLAG_NONE}};
}

GeometryDesc Harness::triangles(const std::vector<vec3>& vertices, uint32_t flags) {
    GeometryDesc g;
    g.Type = GeometryType::Triangles;
    g.Flags = flags;
    g.Triangles.VertexFormat = Format::R32G32B32_FLOAT;
    g.Triangles.VertexCount = uint32_t(vertices.size());
    g.Triangles.VertexBuffer = {device.memory().upload(vertices, "test vertices"), sizeof(vec3)};
    return g;
}

GeometryDesc Harness::aabbs(const std::vector<RaytracingAABB>& boxes, uint32_t flags) {
    GeometryDesc g;
    g.Type = GeometryType::ProceduralPrimitiveAABBs;
    g.Flags = flags;
    g.AABBs.AABBCount = boxes.size();
    g.AABBs.AABBs = {device.memory().upload(boxes, "test AABBs"), sizeof(RaytracingAABB)};
    return g;
}

GpuVirtualAddress Harness::blas(const std::vector<GeometryDesc>& geometries, uint32_t buildFlags) {
    return device.buildBottomLevelAS({buildFlags, geometries});
}

GpuVirtualAddress Harness::tlas(const std::vector<InstanceDesc>& instances, uint32_t buildFlags) {
    scene = device.buildTopLevelAS({buildFlags, uint32_t(instances.size()), ElementsLayout::Array,
                                    device.memory().upload(instances, "test instances")});
    return scene;
}

InstanceDesc Harness::instance(GpuVirtualAddress blas, uint32_t contribution, const Matrix3x4& transform, uint32_t mask,
                               uint32_t flags, uint32_t instanceID) {
    return makeInstanceDesc(transform, instanceID, mask, contribution, flags, blas);
}

void recordHitValues(ShaderContext& ctx, Probe& p) {
    p.closestHits++;
    p.t = ctx.RayTCurrent();
    p.hitKind = ctx.HitKind();
    p.instanceIndex = ctx.InstanceIndex();
    p.instanceID = ctx.InstanceID();
    p.geometryIndex = ctx.GeometryIndex();
    p.primitiveIndex = ctx.PrimitiveIndex();
}

const DiagnosticValue* findValue(const Diagnostic& d, const std::string& name) {
    for (const auto& v : d.values)
        if (v.name == name) return &v;
    return nullptr;
}

std::string valueOf(const Diagnostic& d, const std::string& name) {
    const DiagnosticValue* v = findValue(d, name);
    return v ? v->value : "<no value '" + name + "'>";
}

std::string limitOf(const Diagnostic& d, const std::string& name) {
    const DiagnosticValue* v = findValue(d, name);
    return v ? v->limit : "<no value '" + name + "'>";
}

void Harness::addProbeShaders() {
    library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Probe", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
            recordHitValues(ctx, p);
            p.barycentrics = a.barycentrics;
        });
    library->addClosestHit<Probe, ProbeAttributes>("CH_ProbeAABB", [](ShaderContext& ctx, Probe& p, const ProbeAttributes&) {
        recordHitValues(ctx, p);
    });
    library->addAnyHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "AH_Probe", [](ShaderContext&, Probe& p, const BuiltInTriangleIntersectionAttributes&) { p.anyHits++; });
    library->addMiss<Probe>("Miss_Probe", [](ShaderContext& ctx, Probe& p) {
        p.misses++;
        p.t = ctx.RayTCurrent();
    });
    library->addIntersection<ProbeAttributes>("IS_Box", [](ShaderContext& ctx) {
        auto slab = intersectAABB(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(), unitBox(), ctx.RayTMin(), ctx.RayTCurrent());
        if (slab) ctx.ReportHit(slab->tEnter, 0, ProbeAttributes{slab->tEnter});
    });
    stateObject.hitGroups.push_back({"HG_Tri", HitGroupType::Triangles, "", "CH_Probe", ""});
    stateObject.hitGroups.push_back({"HG_TriAH", HitGroupType::Triangles, "AH_Probe", "CH_Probe", ""});
    stateObject.hitGroups.push_back({"HG_Box", HitGroupType::ProceduralPrimitive, "", "CH_ProbeAABB", "IS_Box"});
}

void Harness::addTracingRayGen(std::function<RayDesc(uvec3)> ray, TraceArgs args, std::vector<Probe>& results) {
    library->addRayGeneration("RG", [this, ray, args, &results](ShaderContext& ctx) {
        const uvec3 i = ctx.DispatchRaysIndex(), d = ctx.DispatchRaysDimensions();
        Probe p;
        ctx.TraceRay(scene, args.flags, args.mask, args.rayContribution, args.multiplier, args.missIndex, ray(i), p);
        results[(size_t(i.z) * d.y + i.y) * d.x + i.x] = p;
    });
}

StateObjectPtr Harness::pipeline() {
    stateObject.libraries = {{library, {}}};
    return StateObject::create(stateObject);
}

GpuVirtualAddressRangeAndStride Harness::table(const StateObjectPtr& so, const std::vector<std::string>& names,
                                               const std::vector<const LocalRootArguments*>& arguments,
                                               uint64_t strideOverride) {
    ShaderTableBuilder builder("test table");
    for (size_t i = 0; i < names.size(); ++i) {
        const ShaderIdentifier id = names[i].empty() ? ShaderIdentifier{} : so->shaderIdentifier(names[i]);
        if (i < arguments.size() && arguments[i]) builder.addRecord(id, *arguments[i]);
        else builder.addRecord(id);
    }
    return builder.upload(device.memory(), strideOverride);
}

DispatchResult Harness::dispatch(const StateObjectPtr& so, GpuVirtualAddressRangeAndStride miss,
                                 GpuVirtualAddressRangeAndStride hitGroups, uvec3 dims, DispatchOptions options,
                                 const GlobalRootArguments* global, GpuVirtualAddressRangeAndStride callable,
                                 const std::string& rayGen) {
    const auto rg = ShaderTableBuilder("raygen").addRecord(so->shaderIdentifier(rayGen)).upload(device.memory());
    DispatchRaysDesc desc;
    desc.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
    desc.MissShaderTable = miss;
    desc.HitGroupTable = hitGroups;
    desc.CallableShaderTable = callable;
    desc.Width = dims.x;
    desc.Height = dims.y;
    desc.Depth = dims.z;
    return device.dispatchRays(desc, so, global, options);
}

Diagnostic expectDxrError(const std::string& ruleId, const std::function<void()>& fn) {
    try {
        fn();
    } catch (const DxrError& e) {
        EXPECT_EQ(e.diagnostic().ruleId, ruleId) << e.what();
        return e.diagnostic();
    }
    ADD_FAILURE() << "expected a DxrError with rule " << ruleId << ", but nothing was thrown";
    return {};
}

}  // namespace refray::test
