// The scriptable dispatch rig of the dispatcher tests (dispatcher_test.cpp, trace_ray_test.cpp, ray_flags_test.cpp,
// candidate_processing_test.cpp, intersection_shader_test.cpp, shader_invocation_test.cpp,
// shader_api_intrinsics_test.cpp): a Harness with lambda-scriptable shaders and the small helpers they share.
#pragma once

#include <atomic>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "emulator/intersection.h"
#include "harness.h"

// Its own namespace: other test files of this binary have a Rig, a zRay and a triAt of their own.
namespace refray::test::dispatch_rig {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// A triangle in the plane z = `z`, front-facing for rays along +z (FACE-1: dot(n, d) < 0).
inline std::vector<vec3> triAt(float z) { return {{-1, -1, z}, {0, 1, z}, {1, -1, z}}; }
// The standard probe ray: from (0, 0.2, -5) along +z, so a triangle at z hits at t = z + 5
// with barycentrics (0.6, 0.2).
inline RayDesc zRay(float tMax = 100.0f) { return RayDesc{vec3(0.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), tMax}; }

struct CallParams {
    int value = 0;
    int nesting = 0;
};

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A harness with scriptable shaders. Every script is optional; the defaults record like
// the harness probes. Hit groups:
//   HG_Tri {CH_Probe}, HG_TriAH {AH_Probe, CH_Probe}, HG_Box {IS_Box, CH_ProbeAABB} (harness)
//   HG_TriS {AH_TriS, CH_TriS}, HG_TriS_noAH {CH_TriS}, HG_TriS_noCH {AH_TriS}
//   HG_BoxS {IS_S, AH_BoxS, CH_BoxS}, HG_BoxS_noAH {IS_S, CH_BoxS}
//   HG_BoxR {IS_R, AH_BoxS, CH_BoxS}, HG_BoxR_noAH {IS_R, CH_BoxS}: IS_R runs the IS_S script but is registered
//   with ReportHitEnd::Return
// Miss shaders: Miss_Probe (harness), Miss_S. Callable: CL_S (CallParams).
struct Rig {
    Harness h;
    RayDesc ray = zRay();
    Harness::TraceArgs args;
    bool useTlasOverride = false;
    GpuVirtualAddress tlasOverride = 0;
    Probe initial;
    Probe result;
    bool traced = false;
    bool log = false;  // single-pixel tests only
    std::vector<std::string> events;

    std::function<void(ShaderContext&)> rg;  // replaces the default trace
    std::function<void(ShaderContext&)> is;  // default: report the unit-box entry t, kind `isKind`
    uint32_t isKind = 0;
    std::function<void(ShaderContext&, Probe&, const BuiltInTriangleIntersectionAttributes&)> ahTri;
    std::function<void(ShaderContext&, Probe&, const ProbeAttributes&)> ahBox;
    std::function<void(ShaderContext&, Probe&, const BuiltInTriangleIntersectionAttributes&)> chTri;
    std::function<void(ShaderContext&, Probe&, const ProbeAttributes&)> chBox;
    std::function<void(ShaderContext&, Probe&)> miss;
    std::function<void(ShaderContext&, CallParams&)> callable;
    std::atomic<int> isCalls{0};

    StateObjectPtr so;

    Rig() {
        h.addProbeShaders();
        auto& lib = *h.library;
        lib.addRayGeneration("RG", [this](ShaderContext& ctx) {
            if (log) events.push_back("RG");
            if (rg) return rg(ctx);
            Probe p = initial;
            ctx.TraceRay(useTlasOverride ? tlasOverride : h.scene, args.flags, args.mask, args.rayContribution,
                         args.multiplier, args.missIndex, ray, p);
            result = p;
            traced = true;
        });
        const auto intersection = [this](ShaderContext& ctx) {
            isCalls++;
            if (log) events.push_back("IS");
            if (is) return is(ctx);
            auto slab = intersectAABB(ctx.ObjectRayOrigin(), ctx.ObjectRayDirection(), unitBox(), ctx.RayTMin(),
                                      ctx.RayTCurrent());
            if (slab) ctx.ReportHit(slab->tEnter, isKind, ProbeAttributes{slab->tEnter});
        };
        lib.addIntersection<ProbeAttributes>("IS_S", intersection);
        lib.addIntersection<ProbeAttributes>("IS_R", intersection, ReportHitEnd::Return);
        lib.addAnyHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "AH_TriS", [this](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
                p.anyHits++;
                if (log) events.push_back("AH");
                if (ahTri) ahTri(ctx, p, a);
            });
        lib.addAnyHit<Probe, ProbeAttributes>("AH_BoxS", [this](ShaderContext& ctx, Probe& p, const ProbeAttributes& a) {
            p.anyHits++;
            if (log) events.push_back("AH");
            if (ahBox) ahBox(ctx, p, a);
        });
        lib.addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "CH_TriS", [this](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
                if (log) events.push_back("CH");
                recordHitValues(ctx, p);
                p.barycentrics = a.barycentrics;
                if (chTri) chTri(ctx, p, a);
            });
        lib.addClosestHit<Probe, ProbeAttributes>("CH_BoxS", [this](ShaderContext& ctx, Probe& p, const ProbeAttributes& a) {
            if (log) events.push_back("CH");
            recordHitValues(ctx, p);
            if (chBox) chBox(ctx, p, a);
        });
        lib.addMiss<Probe>("Miss_S", [this](ShaderContext& ctx, Probe& p) {
            if (log) events.push_back("MS");
            p.misses++;
            p.t = ctx.RayTCurrent();
            if (miss) miss(ctx, p);
        });
        lib.addCallable<CallParams>("CL_S", [this](ShaderContext& ctx, CallParams& c) {
            if (log) events.push_back("CL");
            if (callable) callable(ctx, c);
        });
        auto& hg = h.stateObject.hitGroups;
        hg.push_back({"HG_TriS", HitGroupType::Triangles, "AH_TriS", "CH_TriS", ""});
        hg.push_back({"HG_TriS_noAH", HitGroupType::Triangles, "", "CH_TriS", ""});
        hg.push_back({"HG_TriS_noCH", HitGroupType::Triangles, "AH_TriS", "", ""});
        hg.push_back({"HG_BoxS", HitGroupType::ProceduralPrimitive, "AH_BoxS", "CH_BoxS", "IS_S"});
        hg.push_back({"HG_BoxS_noAH", HitGroupType::ProceduralPrimitive, "", "CH_BoxS", "IS_S"});
        hg.push_back({"HG_BoxR", HitGroupType::ProceduralPrimitive, "AH_BoxS", "CH_BoxS", "IS_R"});
        hg.push_back({"HG_BoxR_noAH", HitGroupType::ProceduralPrimitive, "", "CH_BoxS", "IS_R"});
    }
    Rig(const Rig&) = delete;
    Rig& operator=(const Rig&) = delete;

    void recursion(uint32_t depth, uint32_t pipelineFlags = PIPELINE_FLAG_NONE) {
        h.stateObject.pipelineConfigs = {{depth, pipelineFlags}};
    }
    void build() { so = h.pipeline(); }
    // One dispatch; `hitGroups` is the hit-group table, `missTable` the miss table.
    DispatchResult run(const std::vector<std::string>& hitGroups, uvec3 dims = uvec3(1u), DispatchOptions options = {},
                       const std::vector<std::string>& missTable = {"Miss_S"},
                       const std::vector<std::string>& callables = {"CL_S"}) {
        if (!so) build();
        traced = false;
        result = Probe{};
        events.clear();
        isCalls = 0;
        return h.dispatch(so, missTable.empty() ? GpuVirtualAddressRangeAndStride{} : h.table(so, missTable),
                          hitGroups.empty() ? GpuVirtualAddressRangeAndStride{} : h.table(so, hitGroups), dims, options,
                          nullptr, callables.empty() ? GpuVirtualAddressRangeAndStride{} : h.table(so, callables));
    }
};

inline DispatchOptions continueMode() {
    DispatchOptions o;
    o.onError = OnError::Continue;
    return o;
}

}  // namespace refray::test::dispatch_rig
