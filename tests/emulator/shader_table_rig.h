// The tagged-record rig of the shader table tests (shader_table_test.cpp, shader_table_indexing_test.cpp):
// shaders whose record is identified by a local root constant (the "tag"), the tables and scenes they use.
#pragma once

#include <string>
#include <vector>

#include "harness.h"

// Its own namespace: other test files of this binary have a CallParams, a triangleAt and a hitRay of their own.
namespace refray::test::shader_table_rig {

inline RootSignaturePtr tagSignature(const std::string& name = "Tag") {
    return RootSignature::create({name, {RootParameter::constants(1, 0)}, ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE});
}

struct CallParams {
    uint32_t tag = 0;
    uint32_t calls = 0;
};

// "CH_Tag" / "HG_Tag" (triangles), "CH_TagBox" / "HG_TagBox" (IS_Box), "Miss_Tag", "CL_Tag":
// each writes its record's local constant into Probe::tag (CallParams::tag for the callable).
inline void addTagShaders(Harness& h, const RootSignaturePtr& sig) {
    h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
        "CH_Tag", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
            p.closestHits++;
            p.tag = ctx.localRootConstants<uint32_t>(0);
            p.t = ctx.RayTCurrent();
            p.instanceIndex = ctx.InstanceIndex();
            p.geometryIndex = ctx.GeometryIndex();
            p.primitiveIndex = ctx.PrimitiveIndex();
        });
    h.library->addClosestHit<Probe, ProbeAttributes>("CH_TagBox", [](ShaderContext& ctx, Probe& p, const ProbeAttributes&) {
        p.closestHits++;
        p.tag = ctx.localRootConstants<uint32_t>(0);
        p.geometryIndex = ctx.GeometryIndex();
    });
    h.library->addMiss<Probe>("Miss_Tag", [](ShaderContext& ctx, Probe& p) {
        p.misses++;
        p.tag = ctx.localRootConstants<uint32_t>(0);
    });
    h.library->addCallable<CallParams>("CL_Tag", [](ShaderContext& ctx, CallParams& c) {
        c.calls++;
        c.tag = ctx.localRootConstants<uint32_t>(0);
    });
    h.stateObject.hitGroups.push_back({"HG_Tag", HitGroupType::Triangles, "", "CH_Tag", ""});
    h.stateObject.hitGroups.push_back({"HG_TagBox", HitGroupType::ProceduralPrimitive, "", "CH_TagBox", "IS_Box"});
    h.stateObject.localRootSignatures.push_back({sig, {"HG_Tag", "HG_TagBox", "Miss_Tag", "CL_Tag"}});
}

// `count` records of `name`, record i tagged firstTag + i.
inline GpuVirtualAddressRangeAndStride tagTable(Harness& h, const StateObjectPtr& so, const RootSignaturePtr& sig,
                                         const std::string& name, uint32_t count, uint32_t firstTag = 100,
                                         uint64_t strideOverride = ~0ull) {
    ShaderTableBuilder builder("tag table " + name);
    for (uint32_t i = 0; i < count; ++i) {
        LocalRootArguments args(sig);
        args.setConstants(0, firstTag + i);
        builder.addRecord(so->shaderIdentifier(name), args);
    }
    return builder.upload(h.device.memory(), strideOverride);
}

inline std::vector<vec3> triangleAt(vec3 o) {
    return {o + vec3(-1, -1, 0), o + vec3(0, 1, 0), o + vec3(1, -1, 0)};
}

// The standard hitting ray: hits a triangleAt(0) at t = 5.
inline RayDesc hitRay(uvec3 = uvec3(0u)) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f}; }
inline RayDesc missRay(uvec3 = uvec3(0u)) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, -1), 100.0f}; }

// A TLAS of two instances: instance 0 far away (C = 0), instance 1 at the origin with
// contribution C over a BLAS of three geometries of which G = 2 lies at the origin.
inline void buildThreeGeometryScene(Harness& h, uint32_t c, uint32_t geometryFlags = GEOMETRY_FLAG_OPAQUE) {
    const auto blas = h.blas({h.triangles(triangleAt({10, 0, 0}), geometryFlags),
                              h.triangles(triangleAt({20, 0, 0}), geometryFlags),
                              h.triangles(triangleAt({0, 0, 0}), geometryFlags)});
    h.tlas({Harness::instance(blas, 0, Matrix3x4::translation({0, 100, 0})), Harness::instance(blas, c)});
}

// One triangle at the origin, instance contribution c.
inline void buildOneTriangleScene(Harness& h, uint32_t c = 0, uint32_t geometryFlags = GEOMETRY_FLAG_OPAQUE) {
    const auto blas = h.blas({h.triangles(triangleAt({0, 0, 0}), geometryFlags)});
    h.tlas({Harness::instance(blas, c)});
}

// A ray generation record built by hand (for NULL, misaligned or argument-carrying records).
inline DispatchRaysDesc descWithRayGen(GpuVirtualAddressRangeAndStride rg, uvec3 dims = uvec3(1u)) {
    DispatchRaysDesc desc;
    desc.RayGenerationShaderRecord = {rg.StartAddress, rg.SizeInBytes};
    desc.Width = dims.x;
    desc.Height = dims.y;
    desc.Depth = dims.z;
    return desc;
}

}  // namespace refray::test::shader_table_rig
