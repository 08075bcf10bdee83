// What the two reference scenes share: Proceduray's engine inherited the D3D12 procedural
// sample's HLSL matrix type and root-signature layout.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <type_traits>

#include "core/math.h"
#include "emulator/ray_generation_wave.h"
#include "emulator/root_signature.h"
#include "procedural/math/hlsl.h"
#include "procedural/wave_shader.h"

namespace refray::procedural {

// An HLSL float4x4 compiled with /Zpr: row-major, used with row vectors (mul(v, M) = v·M,
// translation in row 3). Same memory layout as a DirectXMath XMMATRIX.
struct Float4x4 {
    std::array<std::array<float, 4>, 4> m{};
};
static_assert(sizeof(Float4x4) == 64);

// The material, as root constants at b1 of every hit group's local root signature.
struct PrimitiveConstantBuffer {
    vec4 albedo;
    float reflectanceCoef;
    float diffuseCoef;
    float specularCoef;
    float specularPower;
    float stepScale;  // sphere-tracing step scale (which shaders read it: see each port)
    vec3 padding;
};
static_assert(sizeof(PrimitiveConstantBuffer) == 48);

// Per procedural record: 2 root constants at b2 (what the fields index differs per port).
struct PrimitiveInstanceConstantBuffer {
    uint32_t instanceIndex;
    uint32_t primitiveType;
};
static_assert(sizeof(PrimitiveInstanceConstantBuffer) == 8);

// An element of g_vertices (StructuredBuffer<Vertex>, stride 24).
struct Vertex {
    vec3 position;
    vec3 normal;
};
static_assert(sizeof(Vertex) == 24);

// Global: [0] table {UAV u0} render target, [1] root SRV t0 TLAS, [2] root CBV b0 scene
// constants, [3] root SRV t3 instance buffer, [4] table {SRV t1, t2} indices and vertices.
dxr::RootSignatureDesc sampleGlobalRootSignatureDesc(std::string name);
// Local, triangles: PrimitiveConstantBuffer as root constants at b1.
dxr::RootSignatureDesc sampleTriangleLocalRootSignatureDesc(std::string name);
// Local, procedural: PrimitiveConstantBuffer at b1, then PrimitiveInstanceConstantBuffer at b2.
dxr::RootSignatureDesc sampleProceduralLocalRootSignatureDesc(std::string name);

// ---- Host side: the matrices the samples' hosts compute for their shaders ------------------------------

// A DXR 3x4 instance transform (column vectors, translation in column 3) in the row-vector float4x4 form
// HLSL /Zpr shaders read (translation in row 3).
Float4x4 rowVectorForm(const Matrix3x4& columnForm);

// Host matrix math in double, row-vector form [row][column] (p' = p · M), rounded to float once at the end.
using DMat4 = std::array<std::array<double, 4>, 4>;
DMat4 multiply(const DMat4& a, const DMat4& b);
Float4x4 toFloat4x4(const DMat4& m);

// mul(v, M) for a row vector, summed in row order (HLSL mul with /Zpr matrices).
template <typename T>
glm::vec<4, T> mul(const glm::vec<4, T>& v, const Float4x4& M) {
    glm::vec<4, T> r;
    for (int j = 0; j < 4; ++j)
        r[j] = v.x * T(M.m[0][j]) + v.y * T(M.m[1][j]) + v.z * T(M.m[2][j]) + v.w * T(M.m[3][j]);
    return r;
}

// mul(v, (float3x3)M): the upper-left 3x3, row vector on the left.
template <typename T>
glm::vec<3, T> mul3x3(const glm::vec<3, T>& v, const Float4x4& M) {
    glm::vec<3, T> r;
    for (int j = 0; j < 3; ++j) r[j] = v.x * T(M.m[0][j]) + v.y * T(M.m[1][j]) + v.z * T(M.m[2][j]);
    return r;
}

// FresnelReflectanceSchlick(I, N, f0) = f0 + (1 - f0)·pow(1 - saturate(dot(-I, N)), 5).
template <typename T>
glm::vec<3, T> FresnelReflectanceSchlick(glm::vec<3, T> I, glm::vec<3, T> N, glm::vec<3, T> f0) {
    const T cosi = hlsl::saturate(hlsl::dot(-I, N));
    return f0 + (T(1) - f0) * hlsl::pow(T(1) - cosi, T(5));
}

// GenerateCameraRay: pixel centre, y flipped, unprojected with mul(float4(s, 0, 1),
// projectionToWorld) and divided by w; origin = cameraPosition, direction normalized.
// GenerateCameraRayFromPixel takes the pixel index and the dimensions in T, converted from their uints (as
// GenerateCameraRay does), so that the lanes of a wave, each with its own pixel, run it as one.
template <typename T>
void GenerateCameraRayFromPixel(glm::vec<2, T> index, glm::vec<2, T> dimensions, glm::vec<3, T> cameraPosition,
                                const Float4x4& projectionToWorld, glm::vec<3, T>& origin,
                                glm::vec<3, T>& direction) {
    const glm::vec<2, T> xy = index + T(0.5f);
    glm::vec<2, T> screenPos = xy / dimensions * T(2) - T(1);
    screenPos.y = -screenPos.y;
    const glm::vec<4, T> world = mul(glm::vec<4, T>(screenPos, T(0), T(1)), projectionToWorld);
    const glm::vec<3, T> worldXYZ = glm::vec<3, T>(world) / world.w;
    origin = cameraPosition;
    direction = hlsl::normalize(worldXYZ - origin);
}

// GenerateCameraRay for DispatchRaysIndex().xy and DispatchRaysDimensions().xy as the HLSL passes them.
template <typename T>
void GenerateCameraRay(uvec2 index, uvec2 dimensions, glm::vec<3, T> cameraPosition, const Float4x4& projectionToWorld,
                       glm::vec<3, T>& origin, glm::vec<3, T>& direction) {
    GenerateCameraRayFromPixel(glm::vec<2, T>(index), glm::vec<2, T>(dimensions), cameraPosition, projectionToWorld,
                               origin, direction);
}

// A radiance ray traced alone: `makeCall(payload, call)` builds the TraceRay (false: it makes none, and the result is
// black), which runs before the payload's colour is returned (the samples' TraceRadianceRay around their
// RadianceRayCall).
template <typename T, class Payload, class MakeCall>
glm::vec<4, T> TracePayloadColor(dxr::ShaderContext& ctx, MakeCall makeCall) {
    Payload payload{};
    dxr::TraceRayCall call;
    if (!makeCall(payload, call)) return glm::vec<4, T>(T(0));
    ctx.TraceRay(call);
    return glm::vec<4, T>(payload.color);
}

// The camera a ray generation shader reads: what CameraRaygen's `camera` gives (the scene's constants).
template <typename T>
struct CameraSetup {
    glm::vec<3, T> cameraPosition;
    Float4x4 projectionToWorld;
};

// The camera rays of a ray generation wave's lanes: each active lane reads its camera (`camera(ctx)`, once between
// the lanes through `shared`: a lane whose read fails leaves the wave), and origins[i], directions[i] become lane i's
// GenerateCameraRay for its DispatchRaysIndex().xy. A float wave computes them in WaveLanes<float>, kWaveLanes lanes
// at a time (a call of one lane alone in float), each lane bit for bit its one-lane ray (procedural/math/lanes.h).
template <typename T, class Camera>
void CameraRays(dxr::RayGenerationWave& wave, WaveShared<CameraSetup<T>>& shared, Camera& camera,
                std::array<glm::vec<3, T>, dxr::kMaxWaveWidth>& origins,
                std::array<glm::vec<3, T>, dxr::kMaxWaveWidth>& directions) {
    std::array<uvec2, dxr::kMaxWaveWidth> pixels{};
    uvec2 dimensions(0);
    const CameraSetup<T>* setup = nullptr;
    dxr::LaneMask lanes;
    wave.forEachLane([&](int i, dxr::ShaderContext& ctx) {
        setup = &shared.get(ctx, camera);
        pixels[size_t(i)] = uvec2(ctx.DispatchRaysIndex());
        dimensions = uvec2(ctx.DispatchRaysDimensions());
        lanes.set(i);
    });
    const auto alone = [&](int i) {
        GenerateCameraRay(pixels[size_t(i)], dimensions, setup->cameraPosition, setup->projectionToWorld,
                          origins[size_t(i)], directions[size_t(i)]);
    };
    if constexpr (!std::is_same_v<T, float>) {
        for (int i : lanes) alone(i);
    } else {
        using L = WaveLanes<float>;
        const auto group = [&](const std::array<int, kWaveLanes>& lane, int n) {
            glm::vec<2, L> pixel;
            for (int j = 0; j < kWaveLanes; ++j) math::setLane(pixel, j, vec2(pixels[size_t(lane[size_t(j)])]));
            glm::vec<3, L> origin, direction;
            GenerateCameraRayFromPixel(pixel, glm::vec<2, L>(vec2(dimensions)), glm::vec<3, L>(setup->cameraPosition),
                                       setup->projectionToWorld, origin, direction);
            for (int j = 0; j < n; ++j) {
                origins[size_t(lane[size_t(j)])] = math::lane(origin, j);
                directions[size_t(lane[size_t(j)])] = math::lane(direction, j);
            }
        };
        inGroupsOfLanes(lanes, group, alone);
    }
}

// The ray generation shader both samples share (D3D12's MyRaygenShader, Proceduray's Raygen), written for waves
// (emulator/ray_generation_wave.h): each lane reads its camera (`camera(ctx)`: the lane's scene constants), builds its
// camera ray (GenerateCameraRay, for the wave's lanes together: CameraRays) and its radiance TraceRay
// (`radianceCall(ctx, origin, direction, currentRecursionDepth, payload, call)`: false at MAX_RAY_RECURSION_DEPTH,
// which leaves the pixel black), the wave's lanes trace together, then each lane writes its colour to the output UAV
// of descriptor table `outputTable`. Lane by lane it is the HLSL's code.
// PORT: the texture stores floats; the R8G8B8A8_UNORM conversion (clamp, round, NaN -> 0) happens when the image is
// written out (H20).
// PORT: the camera (the scene's constants) and the output texture are global root arguments, read once between the
// lanes (WaveShared, procedural/wave_shader.h).
template <typename T, class Payload, class Camera, class RadianceCall>
void CameraRaygen(dxr::RayGenerationWave& wave, uint32_t outputTable, Camera camera, RadianceCall radianceCall) {
    WaveShared<CameraSetup<T>> shared;
    WaveShared<Image*> output;
    std::array<glm::vec<3, T>, dxr::kMaxWaveWidth> origins, directions;
    CameraRays(wave, shared, camera, origins, directions);
    struct Lane {
        Payload payload;
        bool traced;
    };
    wave.TraceRaysInSteps<Lane>(
        [&](int i, dxr::ShaderContext& ctx, Lane& l, dxr::TraceRayCall& call) {
            const uint32_t currentRecursionDepth = 0;
            return l.traced = radianceCall(ctx, origins[size_t(i)], directions[size_t(i)], currentRecursionDepth,
                                           l.payload, call);
        },
        [&](int, dxr::ShaderContext& ctx, Lane& l, dxr::TraceRayCall&) {
            const uvec3 index = ctx.DispatchRaysIndex();
            const glm::vec<4, T> color = l.traced ? glm::vec<4, T>(l.payload.color) : glm::vec<4, T>(T(0));
            Image* target = output.get(ctx, [outputTable](const dxr::ShaderContext& lane) {
                return &lane.rwTexture2D(lane.globalDescriptorTable(outputTable));
            });
            target->at(index.x, index.y) = vec4(color);
            return false;
        });
}

// The index triplet inside the 8 bytes a ByteAddressBuffer Load2 read at the dword-aligned
// offset below `offsetBytes`.
uvec3 unpack3x16BitIndices(uint32_t offsetBytes, uvec2 four16BitIndices);
// Both samples' triangle closest hits' normal: the stored normal of the hit triangle's first vertex. The index
// buffer is descriptor 0 (g_indices, t1) and the vertex buffer descriptor 1 (g_vertices, t2) of the global descriptor
// table `vertexBuffersTable`; the indices are 16-bit, three per triangle, read as a ByteAddressBuffer Load2 at the
// dword-aligned offset; reads past the end of a view give 0, as in D3D.
vec3 FirstVertexNormal(const dxr::ShaderContext& ctx, uint32_t vertexBuffersTable);
// Load3x16BitIndices: the three 16-bit indices at byte `offsetBytes`, read as two aligned
// dwords the way a ByteAddressBuffer Load2 does. Dwords past `sizeInBytes` read 0.
uvec3 Load3x16BitIndices(uint32_t offsetBytes, const uint8_t* indices, size_t sizeInBytes);

}  // namespace refray::procedural
