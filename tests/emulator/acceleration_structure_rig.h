// The rig of the acceleration structure tests (acceleration_structure_test.cpp, acceleration_structure_instance_test.cpp,
// acceleration_structure_degenerate_test.cpp, acceleration_structure_update_test.cpp): a harness tracing a list of
// rays, the reference triangle and quad, and the helpers they share.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "harness.h"

// Its own namespace: other test files of this binary have a Rig and a zRay of their own.
namespace refray::test::acceleration_structure_rig {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The reference triangle: clockwise seen from -z, so front-facing for +z rays (FACE-1).
const std::vector<vec3> kTri = {{-1, -1, 0}, {0, 1, 0}, {1, -1, 0}};

inline RayDesc zRay(float x, float y, float oz = -5.0f, float tMax = 100.0f, float tMin = 0.0f) {
    return RayDesc{vec3(x, y, oz), tMin, vec3(0, 0, 1), tMax};
}

const std::vector<vec3> kQuad = {{-1, -1, 0}, {-1, 1, 0}, {1, 1, 0}, {1, -1, 0}};

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

#define EXPECT_MESSAGE_HAS(diagnostic, text) \
    EXPECT_TRUE(contains((diagnostic).format(), text)) << "missing '" << (text) << "' in: " << (diagnostic).format()

// A harness plus a 1D ray generation shader that traces `rays[i]` with `args`, and a few
// extra shaders that record what the probe shaders do not.
class Rig {
public:
    Harness h;
    std::vector<RayDesc> rays;
    std::vector<Probe> results;
    std::vector<std::vector<uint32_t>> isCalls;  // per launch: PrimitiveIndex of every IS_Record call
    std::vector<Matrix3x4> objectToWorld;        // per launch, from CH_Record
    std::vector<vec3> objectRayOrigin;           // per launch, from CH_Record
    Harness::TraceArgs args;
    StateObjectPtr so;

    Rig() {
        args.multiplier = 0;  // every geometry of a BLAS uses the same record unless a test says otherwise
        h.addProbeShaders();
        h.library->addRayGeneration("RG", [this](ShaderContext& ctx) {
            const uint32_t i = ctx.DispatchRaysIndex().x;
            Probe p;
            ctx.TraceRay(h.scene, args.flags, args.mask, args.rayContribution, args.multiplier, args.missIndex, rays[i], p);
            results[i] = p;
        });
        h.library->addClosestHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "CH_Record", [this](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes& a) {
                recordHitValues(ctx, p);
                p.barycentrics = a.barycentrics;
                p.tag = 77;
                const uint32_t i = ctx.DispatchRaysIndex().x;
                objectToWorld[i] = ctx.ObjectToWorld3x4();
                objectRayOrigin[i] = ctx.ObjectRayOrigin();
            });
        h.library->addAnyHit<Probe, BuiltInTriangleIntersectionAttributes>(
            "AH_Ignore", [](ShaderContext& ctx, Probe& p, const BuiltInTriangleIntersectionAttributes&) {
                p.anyHits++;
                ctx.IgnoreHit();
            });
        h.library->addAnyHit<Probe, ProbeAttributes>("AH_BoxIgnore", [](ShaderContext& ctx, Probe& p, const ProbeAttributes&) {
            p.anyHits++;
            ctx.IgnoreHit();
        });
        h.library->addIntersection<ProbeAttributes>("IS_Record", [this](ShaderContext& ctx) {
            isCalls[ctx.DispatchRaysIndex().x].push_back(ctx.PrimitiveIndex());
        });
        h.stateObject.hitGroups.push_back({"HG_TriRec", HitGroupType::Triangles, "", "CH_Record", ""});
        h.stateObject.hitGroups.push_back({"HG_TriIgnore", HitGroupType::Triangles, "AH_Ignore", "CH_Probe", ""});
        h.stateObject.hitGroups.push_back({"HG_BoxRec", HitGroupType::ProceduralPrimitive, "", "CH_ProbeAABB", "IS_Record"});
        h.stateObject.hitGroups.push_back(
            {"HG_BoxIgnore", HitGroupType::ProceduralPrimitive, "AH_BoxIgnore", "CH_ProbeAABB", "IS_Box"});
    }
    Rig(const Rig&) = delete;

    std::vector<Probe>& trace(const std::vector<RayDesc>& r, const std::vector<std::string>& hitGroups = {"HG_Tri"},
                              DispatchOptions options = {}) {
        if (!so) so = h.pipeline();
        rays = r;
        results.assign(r.size(), Probe{});
        isCalls.assign(r.size(), {});
        objectToWorld.assign(r.size(), Matrix3x4{});
        objectRayOrigin.assign(r.size(), vec3(NAN));
        h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, hitGroups), uvec3(uint32_t(r.size()), 1, 1), options);
        return results;
    }
    Probe traceOne(const RayDesc& r, const std::vector<std::string>& hitGroups = {"HG_Tri"}, DispatchOptions options = {}) {
        return trace({r}, hitGroups, options)[0];
    }

    // Geometry from raw vertex bytes.
    GeometryDesc rawTriangles(Format format, const std::vector<uint8_t>& bytes, uint64_t stride, uint32_t vertexCount,
                              uint32_t flags = GEOMETRY_FLAG_OPAQUE) {
        GeometryDesc g;
        g.Type = GeometryType::Triangles;
        g.Flags = flags;
        g.Triangles.VertexFormat = format;
        g.Triangles.VertexCount = vertexCount;
        g.Triangles.VertexBuffer = {h.device.memory().upload(bytes, "raw vertices"), stride};
        return g;
    }
    GeometryDesc indexed(const std::vector<vec3>& vertices, Format indexFormat, const std::vector<uint32_t>& indices,
                         uint32_t flags = GEOMETRY_FLAG_OPAQUE) {
        GeometryDesc g = h.triangles(vertices, flags);
        g.Triangles.IndexFormat = indexFormat;
        g.Triangles.IndexCount = uint32_t(indices.size());
        if (indexFormat == Format::R16_UINT) {
            std::vector<uint16_t> narrow(indices.begin(), indices.end());
            g.Triangles.IndexBuffer = h.device.memory().upload(narrow, "indices16");
        } else {
            g.Triangles.IndexBuffer = h.device.memory().upload(indices, "indices32");
        }
        return g;
    }
    GpuVirtualAddress uploadTransform(const Matrix3x4& m) { return h.device.memory().upload(&m.m, 48, "Transform3x4"); }
};

template <class T>
inline std::vector<uint8_t> bytesOf(const std::vector<T>& values) {
    std::vector<uint8_t> out(values.size() * sizeof(T));
    std::memcpy(out.data(), values.data(), out.size());
    return out;
}
inline std::vector<uint8_t> u16s(std::initializer_list<uint16_t> v) { return bytesOf(std::vector<uint16_t>(v)); }

}  // namespace refray::test::acceleration_structure_rig
