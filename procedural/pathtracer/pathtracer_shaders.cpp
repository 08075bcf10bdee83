// refray's own DXR path tracer (not a port); see pathtracer_shaders.h for the estimator and the bindings.
#include "procedural/pathtracer/pathtracer_shaders.h"

#include <algorithm>
#include <cmath>

#include "core/ray_offset.h"
#include "emulator/shader_api.h"
#include "procedural/pathtracer/pt_math.h"

namespace refray::procedural::pathtracer {

using namespace refray::dxr;

// ---- Root signature, hit groups, pipeline -------------------------------------------------------------------

RootSignatureDesc globalRootSignatureDesc() {
    const auto srv = [](uint32_t reg, uint32_t space, uint32_t count = 1) {
        return DescriptorRange{DescriptorRangeType::SRV, count, reg, space, kDescriptorRangeOffsetAppend};
    };
    RootSignatureDesc desc;
    desc.name = "PathTracerGlobal";
    desc.parameters = {
        RootParameter::table({DescriptorRange{DescriptorRangeType::UAV, 1, 0, 0, 0}}),
        RootParameter::srv(0),
        RootParameter::cbv(0),
        RootParameter::table({srv(0, 1), srv(0, 2), srv(0, 3), srv(1, 3), srv(0, 4), srv(0, 7)}),
        RootParameter::table({srv(0, 5, kDescriptorRangeUnbounded)}),
        RootParameter::table({srv(0, 6, kDescriptorRangeUnbounded)}),
    };
    StaticSamplerDesc sampler;
    sampler.Filter = FILTER_ANISOTROPIC;
    sampler.MaxAnisotropy = 16;
    sampler.AddressU = sampler.AddressV = sampler.AddressW = TEXTURE_ADDRESS_MODE_WRAP;
    sampler.ShaderRegister = 0;
    sampler.RegisterSpace = 0;
    desc.staticSamplers = {sampler};
    return desc;
}

std::vector<HitGroupDesc> pathTracerHitGroups() {
    return {
        {"PT_HitGroup", HitGroupType::Triangles, "", "PT_ClosestHit", ""},
        {"PT_ShadowHitGroup", HitGroupType::Triangles, "", "", ""},
    };
}

ShaderConfig pathTracerShaderConfig() { return {kMaxPayloadSizeInBytes, kMaxAttributeSizeInBytes}; }

PipelineConfig pathTracerPipelineConfig() { return {kMaxTraceRecursionDepth, PIPELINE_FLAG_NONE}; }

void generateCameraRay(uvec2 index, uvec2 dimensions, vec2 jitter, const PathTracerConstants& constants, vec3& origin,
                       vec3& direction) {
    const vec2 xy = vec2(index) + jitter;
    vec2 screenPos = xy / vec2(dimensions) * 2.0f - 1.0f;
    screenPos.y = -screenPos.y;
    const vec4 world = mul(vec4(screenPos, 0.0f, 1.0f), constants.projectionToWorld);
    origin = vec3(constants.cameraPosition);
    direction = glm::normalize(vec3(world) / world.w - origin);
}

namespace {

// ---- The resources, by their HLSL declarations -----------------------------------------------------------------

// RWTexture2D<float4> g_output : register(u0);
Image& g_output(ShaderContext& ctx) { return ctx.rwTexture2D(ctx.globalDescriptorTable(kOutputTable)); }
// RaytracingAccelerationStructure g_scene : register(t0);
GpuVirtualAddress g_scene(ShaderContext& ctx) { return ctx.globalRootDescriptor(kAccelerationStructure); }
// ConstantBuffer<PathTracerConstants> g_constants : register(b0);
PathTracerConstants g_constants(ShaderContext& ctx) { return ctx.constantBuffer<PathTracerConstants>(0, 0); }
// StructuredBuffer<VertexGPU> g_vertices : register(t0, space1);
VertexGPU g_vertices(ShaderContext& ctx, uint32_t i) { return ctx.loadStructured<VertexGPU>(0, 1, 0, i); }
// StructuredBuffer<uint> g_indices : register(t0, space2);
uint32_t g_indices(ShaderContext& ctx, uint32_t i) { return ctx.loadStructured<uint32_t>(0, 2, 0, i); }
// StructuredBuffer<MaterialGPU> g_materials : register(t0, space3);
MaterialGPU g_materials(ShaderContext& ctx, uint32_t i) { return ctx.loadStructured<MaterialGPU>(0, 3, 0, i); }
// StructuredBuffer<uint> g_triangleMaterials : register(t1, space3);
uint32_t g_triangleMaterials(ShaderContext& ctx, uint32_t i) { return ctx.loadStructured<uint32_t>(1, 3, 0, i); }
// StructuredBuffer<ObjectGPU> g_objects : register(t0, space4);
ObjectGPU g_objects(ShaderContext& ctx, uint32_t i) { return ctx.loadStructured<ObjectGPU>(0, 4, 0, i); }
// StructuredBuffer<LightTriangleGPU> g_lights : register(t0, space7);
LightTriangleGPU g_lights(ShaderContext& ctx, uint32_t i) { return ctx.loadStructured<LightTriangleGPU>(0, 7, 0, i); }
// Texture2D g_diffuseTextures[] : register(t0, space5);
Texture2DRef g_diffuseTextures(ShaderContext& ctx, uint32_t i) { return ctx.Texture2D(0, 5, i); }
// Texture2D g_normalTextures[] : register(t0, space6);
Texture2DRef g_normalTextures(ShaderContext& ctx, uint32_t i) { return ctx.Texture2D(0, 6, i); }
// SamplerState g_sampler : register(s0);
SamplerRef g_sampler(ShaderContext& ctx) { return ctx.SamplerState(0, 0); }

// ---- Helpers ------------------------------------------------------------------------------------------------------

// mul(n, (float3x3)WorldToObject4x3()): an object-space normal in world space (the inverse transpose).
vec3 normalToWorld(const Matrix3x4& worldToObject, vec3 n) {
    vec3 r;
    for (int j = 0; j < 3; ++j)
        r[j] = worldToObject.m[0][j] * n.x + worldToObject.m[1][j] * n.y + worldToObject.m[2][j] * n.z;
    return r;
}

template <class V>
V interpolate(const V& a, const V& b, const V& c, vec3 barycentrics) {
    return barycentrics.x * a + barycentrics.y * b + barycentrics.z * c;
}

bool isZero(vec3 v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

// Traces a shadow ray from `from` to `to` (both already lifted off their surfaces): true when nothing lies between.
bool TraceShadowRay(ShaderContext& ctx, vec3 from, vec3 to) {
    RayDesc ray;
    ray.Origin = from;
    ray.Direction = to - from;  // TMax 1 ends the ray at `to`
    ray.TMin = 0.0f;
    ray.TMax = 1.0f;
    ShadowPayload payload{0};
    ctx.TraceRay(g_scene(ctx), kShadowRayFlags, 0xFF, RayType::Shadow, kGeometryStride, RayType::Shadow, ray, payload);
    return payload.visible != 0;
}

RadiancePayload TraceRadianceRay(ShaderContext& ctx, const RayDesc& ray) {
    RadiancePayload payload{};
    ctx.TraceRay(g_scene(ctx), kRadianceRayFlags, 0xFF, RayType::Radiance, kGeometryStride, RayType::Radiance, ray,
                 payload);
    return payload;
}

// What a debug mode shows of the first hit along the camera ray.
vec3 DebugRadiance(ShaderContext& ctx, const PathTracerConstants& g_constantsCB, vec3 origin, vec3 direction) {
    const RadiancePayload hit = TraceRadianceRay(ctx, RayDesc{origin, 0.0f, direction, kRadianceTMax});
    if (hit.hitT < 0.0f) return hit.emission;
    switch (g_constantsCB.debugMode) {
        case kDebugAlbedo: return hit.albedo;
        case kDebugEmission: return hit.emission;
        case kDebugShadingNormal: return hit.shadingNormal * 0.5f + 0.5f;
        case kDebugGeometricNormal: return hit.geometricNormal * 0.5f + 0.5f;
        case kDebugInstanceID: return vec3(float(hit.instanceID), float(hit.primitiveIndex), float(hit.materialIndex));
        default: return vec3(0.0f);
    }
}

// One path from the camera ray (origin, direction): the estimator of pathtracer_shaders.h, steps 1-5.
vec3 PathRadiance(ShaderContext& ctx, const PathTracerConstants& g_constantsCB, vec3 origin, vec3 direction,
                  PathRng& rng) {
    vec3 radiance(0.0f);
    vec3 throughput(1.0f);
    RayDesc ray{origin, 0.0f, direction, kRadianceTMax};
    vec3 previousPosition = origin;
    float previousBsdfPdf = 0.0f;
    const float lightCount = float(g_constantsCB.lightCount);

    for (uint32_t bounce = 0;; ++bounce) {
        // 1. The next vertex, or the background.
        const RadiancePayload hit = TraceRadianceRay(ctx, ray);
        if (hit.hitT < 0.0f) {
            radiance += throughput * hit.emission;
            break;
        }
        const vec3 x = hit.position;
        const vec3 wo = -ray.Direction;
        const float cosFront = glm::dot(hit.geometricNormal, wo);

        // 2. Emission, from the front side; MIS against next-event estimation after the camera ray.
        if (cosFront > 0.0f && !isZero(hit.emission)) {
            float weight = 1.0f;
            if (bounce > 0 && g_constantsCB.lightCount > 0) {
                const float lightPdf =
                    areaToSolidAnglePdf(triangleAreaPdf(hit.area), glm::length(x - previousPosition), cosFront) /
                    lightCount;
                weight = powerHeuristic(previousBsdfPdf, lightPdf);
            }
            radiance += throughput * hit.emission * weight;
        }
        if (bounce >= g_constantsCB.maxBounces) break;

        // Both sides reflect: turn the normals towards the incoming ray.
        const vec3 ng = cosFront >= 0.0f ? hit.geometricNormal : -hit.geometricNormal;
        vec3 ns = hit.shadingNormal;
        if (glm::dot(ns, ng) < 0.0f) ns = -ns;
        const SurfaceBsdf<float> bsdf = makeSurfaceBsdf(hit.albedo, hit.specular, hit.shininess);
        if (isBlack(bsdf)) break;

        // 3. Next-event estimation: a uniformly chosen light triangle, a point uniform by area on it.
        const float uLight = nextUniform(rng), u1 = nextUniform(rng), u2 = nextUniform(rng);
        if (g_constantsCB.lightCount > 0) {
            const uint32_t k = std::min(uint32_t(uLight * lightCount), g_constantsCB.lightCount - 1);
            const LightTriangleGPU light = g_lights(ctx, k);
            const vec3 v0(light.v0), v1(light.v1), v2(light.v2);
            const vec3 y = sampleTriangleUniform(v0, v1, v2, u1, u2);
            const vec3 lightNormal = glm::normalize(glm::cross(v1 - v0, v2 - v0));
            const vec3 toLight = y - x;
            const float distance = glm::length(toLight);
            if (distance > 0.0f) {
                const vec3 wi = toLight / distance;
                const float cosLight = -glm::dot(lightNormal, wi);
                const float cosSurface = glm::dot(ns, wi);
                const vec3 f = evalBsdf(bsdf, ns, wo, wi);
                if (cosLight > 0.0f && cosSurface > 0.0f && glm::dot(ng, wi) > 0.0f && !isZero(f)) {
                    const float lightPdf =
                        areaToSolidAnglePdf(triangleAreaPdf(light.emission.w), distance, cosLight) / lightCount;
                    if (lightPdf > 0.0f &&
                        TraceShadowRay(ctx, offsetRayOrigin(x, ng), offsetRayOrigin(y, lightNormal))) {
                        const float weight = powerHeuristic(lightPdf, bsdfPdf(bsdf, ns, wo, wi));
                        radiance += throughput * f * vec3(light.emission) * (cosSurface * weight / lightPdf);
                    }
                }
            }
        }

        // 4. The next direction.
        const float u0 = nextUniform(rng), u3 = nextUniform(rng), u4 = nextUniform(rng);
        const BsdfSample<float> s = sampleBsdf(bsdf, ns, wo, u0, u3, u4);
        if (isZero(s.weight) || glm::dot(ng, s.wi) <= 0.0f) break;
        throughput *= s.weight;
        previousBsdfPdf = s.pdf;
        previousPosition = x;

        // 5. Russian roulette.
        if (bounce >= kRussianRouletteStartBounce && !russianRoulette(throughput, nextUniform(rng))) break;

        ray = RayDesc{offsetRayOrigin(x, ng), 0.0f, s.wi, kRadianceTMax};
    }
    return radiance;
}

// ---- Entry points -------------------------------------------------------------------------------------------------

void PT_RayGen(ShaderContext& ctx) {
    const uvec2 index = uvec2(ctx.DispatchRaysIndex());
    const uvec2 dimensions = uvec2(ctx.DispatchRaysDimensions());
    const PathTracerConstants g_constantsCB = g_constants(ctx);
    Image& output = g_output(ctx);

    vec3 sum(0.0f);
    output.at(index.x, index.y) = vec4(0.0f, 0.0f, 0.0f, 1.0f);
    for (uint32_t sample = 0; sample < g_constantsCB.samplesPerPixel; ++sample) {
        PathRng rng = makePathRng(index.x, index.y, sample, g_constantsCB.seed);
        const bool debug = g_constantsCB.debugMode != kDebugNone;
        // Debug modes look through pixel centres; paths jitter over the pixel (box filter).
        vec2 jitter(0.5f);
        if (!debug) {
            jitter.x = nextUniform(rng);
            jitter.y = nextUniform(rng);
        }
        vec3 origin, direction;
        generateCameraRay(index, dimensions, jitter, g_constantsCB, origin, direction);
        sum += debug ? DebugRadiance(ctx, g_constantsCB, origin, direction)
                     : PathRadiance(ctx, g_constantsCB, origin, direction, rng);
        // The progressive result: the mean of the samples so far.
        output.at(index.x, index.y) = vec4(sum / float(sample + 1), 1.0f);
    }
}

void PT_ClosestHit(ShaderContext& ctx, RadiancePayload& payload, const Attributes& attr) {
    // The object, its triangle and the triangle's corners (InstanceID() is the object's index).
    const uint32_t instanceID = ctx.InstanceID();
    const uint32_t primitiveIndex = ctx.PrimitiveIndex();
    const ObjectGPU object = g_objects(ctx, instanceID);
    const uint32_t baseIndex = object.indexOffset + 3 * primitiveIndex;
    const VertexGPU vertex0 = g_vertices(ctx, object.vertexOffset + g_indices(ctx, baseIndex + 0));
    const VertexGPU vertex1 = g_vertices(ctx, object.vertexOffset + g_indices(ctx, baseIndex + 1));
    const VertexGPU vertex2 = g_vertices(ctx, object.vertexOffset + g_indices(ctx, baseIndex + 2));
    const vec3 barycentrics(1.0f - attr.barycentrics.x - attr.barycentrics.y, attr.barycentrics.x, attr.barycentrics.y);

    // Position, geometric normal and area from the world-space triangle.
    const Matrix3x4 objectToWorld = ctx.ObjectToWorld3x4();
    const vec3 p0 = objectToWorld.transformPoint(vertex0.position);
    const vec3 p1 = objectToWorld.transformPoint(vertex1.position);
    const vec3 p2 = objectToWorld.transformPoint(vertex2.position);
    const vec3 edgeCross = glm::cross(p1 - p0, p2 - p0);
    const float crossLength = glm::length(edgeCross);
    payload.position = interpolate(p0, p1, p2, barycentrics);
    payload.geometricNormal = crossLength > 0.0f ? edgeCross / crossLength : vec3(0.0f, 0.0f, 1.0f);
    payload.area = 0.5f * crossLength;
    payload.hitT = ctx.RayTCurrent();

    // Interpolated attributes.
    const vec3 objectNormal = interpolate(vertex0.normal, vertex1.normal, vertex2.normal, barycentrics);
    const vec2 uv = interpolate(vec2(vertex0.u, vertex0.v), vec2(vertex1.u, vertex1.v), vec2(vertex2.u, vertex2.v),
                                barycentrics);
    vec3 normal = glm::normalize(normalToWorld(ctx.WorldToObject3x4(), objectNormal));
    if (!std::isfinite(normal.x)) normal = payload.geometricNormal;

    // The material and its textures.
    const uint32_t materialIndex = g_triangleMaterials(ctx, object.triangleOffset + primitiveIndex);
    const MaterialGPU material = g_materials(ctx, materialIndex);
    vec3 albedo = vec3(material.albedo);
    if (material.diffuseTextureIndex >= 0) {
        const Texture2DRef diffuseTexture = g_diffuseTextures(ctx, uint32_t(material.diffuseTextureIndex));
        albedo *= vec3(diffuseTexture.SampleLevel(g_sampler(ctx), uv, 0.0f));
    }
    const vec3 objectTangent =
        interpolate(vec3(vertex0.tangent), vec3(vertex1.tangent), vec3(vertex2.tangent), barycentrics);
    if (material.normalTextureIndex >= 0 && !isZero(objectTangent)) {
        // Tangent space, DirectX convention: x along +u, y along +v (down the image), z along the normal.
        const Texture2DRef normalTexture = g_normalTextures(ctx, uint32_t(material.normalTextureIndex));
        const vec3 mapped = vec3(normalTexture.SampleLevel(g_sampler(ctx), uv, 0.0f)) * 2.0f - 1.0f;
        const float handedness = vertex0.tangent.w < 0.0f ? -1.0f : 1.0f;
        const vec3 objectBitangent = handedness * glm::cross(objectNormal, objectTangent);
        vec3 tangent = objectToWorld.transformVector(objectTangent);
        vec3 bitangent = objectToWorld.transformVector(objectBitangent);
        tangent = glm::normalize(tangent - normal * glm::dot(normal, tangent));
        bitangent =
            glm::normalize(bitangent - normal * glm::dot(normal, bitangent) - tangent * glm::dot(tangent, bitangent));
        const vec3 perturbed = glm::normalize(mapped.x * tangent + mapped.y * bitangent + mapped.z * normal);
        if (std::isfinite(perturbed.x)) normal = perturbed;
    }

    payload.shadingNormal = normal;
    payload.instanceID = instanceID;
    payload.primitiveIndex = primitiveIndex;
    payload.materialIndex = materialIndex;
    payload.albedo = albedo;
    payload.shininess = material.shininess;
    payload.specular = vec3(material.specularRoughness);
    payload.emission = vec3(material.emission);
}

void PT_Miss(ShaderContext& ctx, RadiancePayload& payload) {
    payload.hitT = -1.0f;
    payload.emission = vec3(g_constants(ctx).backgroundColor);
}

void PT_ShadowMiss(ShaderContext&, ShadowPayload& payload) { payload.visible = 1; }

}  // namespace

std::shared_ptr<ShaderLibrary> makePathTracerShaderLibrary() {
    auto lib = std::make_shared<ShaderLibrary>();
    lib->addRayGeneration("PT_RayGen", PT_RayGen);
    lib->addClosestHit<RadiancePayload, Attributes>("PT_ClosestHit", PT_ClosestHit);
    lib->addMiss<RadiancePayload>("PT_Miss", PT_Miss);
    lib->addMiss<ShadowPayload>("PT_ShadowMiss", PT_ShadowMiss);
    return lib;
}

}  // namespace refray::procedural::pathtracer
