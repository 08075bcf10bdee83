// A small harness for conformance tests: tiny hand-built scenes, lambda shaders, real
// shader tables and one DispatchRays. Every test still goes through Device, the state
// object and table bytes exactly as a renderer would.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "emulator/device.h"
#include "emulator/shader_api.h"

namespace refray::test {

using namespace refray::dxr;

// What the probe shaders record about a TraceRay.
struct Probe {
    float t = -1.0f;
    uint32_t hitKind = 0;
    uint32_t instanceIndex = ~0u;
    uint32_t instanceID = ~0u;
    uint32_t geometryIndex = ~0u;
    uint32_t primitiveIndex = ~0u;
    vec2 barycentrics{-1.0f};
    uint32_t closestHits = 0;
    uint32_t misses = 0;
    uint32_t anyHits = 0;
    uint32_t tag = 0;  // set by the shader that ran (e.g. its record's local constant)
};

// Attributes the probe intersection shaders report.
struct ProbeAttributes {
    float value = 0.0f;
};

class Harness {
public:
    Harness();

    Device device;
    std::shared_ptr<ShaderLibrary> library = std::make_shared<ShaderLibrary>();
    StateObjectDesc stateObject;  // configs preset: payload 64 B, attributes 32 B, recursion 2

    // Geometry descs (data uploaded to GPU memory). Triangles are non-indexed: 3 vertices each.
    GeometryDesc triangles(const std::vector<vec3>& vertices, uint32_t flags = GEOMETRY_FLAG_OPAQUE);
    GeometryDesc aabbs(const std::vector<RaytracingAABB>& boxes, uint32_t flags = GEOMETRY_FLAG_OPAQUE);
    GpuVirtualAddress blas(const std::vector<GeometryDesc>& geometries, uint32_t buildFlags = BUILD_FLAG_NONE);
    GpuVirtualAddress tlas(const std::vector<InstanceDesc>& instances, uint32_t buildFlags = BUILD_FLAG_NONE);
    static InstanceDesc instance(GpuVirtualAddress blas, uint32_t contribution = 0, const Matrix3x4& transform = Matrix3x4::identity(),
                                 uint32_t mask = 0xFF, uint32_t flags = INSTANCE_FLAG_NONE, uint32_t instanceID = 0);

    // Registers the standard probe shaders:
    //   "CH_Probe"   closest hit (Probe, built-in triangle attributes): records SV values, closestHits++
    //   "CH_ProbeAABB" closest hit (Probe, ProbeAttributes): the same for procedural hits
    //   "AH_Probe"   any hit (Probe, triangle attributes): anyHits++
    //   "Miss_Probe" miss (Probe): misses++, t = RayTCurrent()
    //   "IS_Box"     intersection (ProbeAttributes): reports the AABB entry t of the object ray
    //                against the unit box [-1,1]^3 (the boxes tests build are that box)
    // and hit groups "HG_Tri" {CH_Probe}, "HG_TriAH" {AH_Probe, CH_Probe}, "HG_Box" {IS_Box, CH_ProbeAABB}.
    void addProbeShaders();

    // Adds a ray generation shader "RG" that traces `ray` with the given arguments into a
    // Probe and stores it in `results` at the linear launch index.
    struct TraceArgs {
        uint32_t flags = RAY_FLAG_NONE;
        uint32_t mask = 0xFF;
        uint32_t rayContribution = 0;
        uint32_t multiplier = 1;
        uint32_t missIndex = 0;
    };
    void addTracingRayGen(std::function<RayDesc(uvec3 launch)> ray, TraceArgs args, std::vector<Probe>& results);

    StateObjectPtr pipeline();
    // A shader table of the named exports ("" = NULL record); `arguments[i]` if given.
    GpuVirtualAddressRangeAndStride table(const StateObjectPtr& so, const std::vector<std::string>& names,
                                          const std::vector<const LocalRootArguments*>& arguments = {},
                                          uint64_t strideOverride = ~0ull);
    // DispatchRays with ray generation record "RG" by default.
    DispatchResult dispatch(const StateObjectPtr& so, GpuVirtualAddressRangeAndStride miss,
                            GpuVirtualAddressRangeAndStride hitGroups, uvec3 dims = uvec3(1u),
                            DispatchOptions options = {}, const GlobalRootArguments* global = nullptr,
                            GpuVirtualAddressRangeAndStride callable = {}, const std::string& rayGen = "RG");

    // The TLAS the probe ray generation traces (set by tlas()).
    GpuVirtualAddress scene = 0;
};

// The value (or limit) a diagnostic gives for `name`, or "<no value 'name'>".
const DiagnosticValue* findValue(const Diagnostic& d, const std::string& name);
std::string valueOf(const Diagnostic& d, const std::string& name);
std::string limitOf(const Diagnostic& d, const std::string& name);

// What CH_Probe records: closestHits++, t, HitKind and the index system values.
void recordHitValues(ShaderContext& ctx, Probe& p);

// Runs `fn` expecting a DxrError with `ruleId`; returns its diagnostic (fails the test otherwise).
Diagnostic expectDxrError(const std::string& ruleId, const std::function<void()>& fn);

// The unit box [-1,1]^3 as an AABB.
inline RaytracingAABB unitBox() { return {-1, -1, -1, 1, 1, 1}; }

}  // namespace refray::test
