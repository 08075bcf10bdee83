// Ports: D3D12RaytracingProceduralGeometry Raytracing.hlsl, RaytracingShaderHelper.hlsli (camera ray, ray
// differentials, Fresnel, index loads), CheckersTextureBoxFilter and the intersection-test dispatch of
// ProceduralPrimitivesLibrary.hlsli; see d3d12_shaders.h.
#include "procedural/d3d12/d3d12_shaders.h"

#include <cstring>

#include "emulator/shader_api.h"
#include "procedural/math/analytic.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/metaballs.h"
#include "procedural/math/ray.h"
#include "procedural/math/sdf.h"

namespace refray::procedural::d3d12 {

using namespace refray::dxr;

// ---- Scene data (§1.2) -----------------------------------------------------------------------------

const std::array<uint16_t, 6> kPlaneIndices = {3, 1, 0, 2, 1, 3};

const std::array<Vertex, 4> kPlaneVertices = {{
    {{0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
    {{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
    {{1.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}},
    {{0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}},
}};

// ---- Root signatures and hit groups ----------------------------------------------------------------

RootSignatureDesc globalRootSignatureDesc() { return sampleGlobalRootSignatureDesc("GlobalRootSignature"); }

RootSignatureDesc triangleLocalRootSignatureDesc() {
    return sampleTriangleLocalRootSignatureDesc("Triangle", sizeof(PrimitiveConstantBuffer));
}

RootSignatureDesc aabbLocalRootSignatureDesc() {
    return sampleProceduralLocalRootSignatureDesc("AABB", sizeof(PrimitiveConstantBuffer),
                                                  sizeof(PrimitiveInstanceConstantBuffer));
}

std::vector<HitGroupDesc> d3d12HitGroups() {
    using enum HitGroupType;
    const char* chsAABB = "MyClosestHitShader_AABB";
    return {
        {"MyHitGroup_Triangle", Triangles, "", "MyClosestHitShader_Triangle", ""},
        {"MyHitGroup_Triangle_ShadowRay", Triangles, "", "", ""},
        {"MyHitGroup_AABB_AnalyticPrimitive", ProceduralPrimitive, "", chsAABB,
         "MyIntersectionShader_AnalyticPrimitive"},
        {"MyHitGroup_AABB_AnalyticPrimitive_ShadowRay", ProceduralPrimitive, "", "",
         "MyIntersectionShader_AnalyticPrimitive"},
        {"MyHitGroup_AABB_VolumetricPrimitive", ProceduralPrimitive, "", chsAABB,
         "MyIntersectionShader_VolumetricPrimitive"},
        {"MyHitGroup_AABB_VolumetricPrimitive_ShadowRay", ProceduralPrimitive, "", "",
         "MyIntersectionShader_VolumetricPrimitive"},
        {"MyHitGroup_AABB_SignedDistancePrimitive", ProceduralPrimitive, "", chsAABB,
         "MyIntersectionShader_SignedDistancePrimitive"},
        {"MyHitGroup_AABB_SignedDistancePrimitive_ShadowRay", ProceduralPrimitive, "", "",
         "MyIntersectionShader_SignedDistancePrimitive"},
    };
}

std::vector<std::string> triangleHitGroupNames() { return {"MyHitGroup_Triangle", "MyHitGroup_Triangle_ShadowRay"}; }

std::vector<std::string> aabbHitGroupNames() {
    std::vector<std::string> names;
    for (const HitGroupDesc& g : d3d12HitGroups())
        if (g.Type == HitGroupType::ProceduralPrimitive) names.push_back(g.HitGroupExport);
    return names;
}

// ---- Pure helpers ----------------------------------------------------------------------------------

vec4 mul(const vec4& v, const Float4x4& M) {
    vec4 r;
    for (int j = 0; j < 4; ++j) r[j] = v.x * M.m[0][j] + v.y * M.m[1][j] + v.z * M.m[2][j] + v.w * M.m[3][j];
    return r;
}

namespace {

// mul(v, (float3x3)M): the upper-left 3x3 of a row-major matrix, row vector on the left.
vec3 mul3x3(const vec3& v, const Float4x4& M) {
    vec3 r;
    for (int j = 0; j < 3; ++j) r[j] = v.x * M.m[0][j] + v.y * M.m[1][j] + v.z * M.m[2][j];
    return r;
}

// A ByteAddressBuffer dword; past the end it reads 0, as an out-of-bounds buffer load does in D3D12.
uint32_t loadDword(const uint8_t* data, size_t sizeInBytes, uint32_t offset) {
    uint32_t value = 0;
    if (uint64_t(offset) + 4 <= sizeInBytes) std::memcpy(&value, data + offset, 4);
    return value;
}

}  // namespace

namespace {

// The index triplet inside the 8 bytes Load2 read at the dword-aligned offset.
uvec3 unpack3x16BitIndices(uint32_t offsetBytes, uvec2 four16BitIndices) {
    const uint32_t dwordAlignedOffset = offsetBytes & ~3u;
    uvec3 result;
    if (dwordAlignedOffset == offsetBytes) {  // aligned: { 0 1 | 2 - }
        result.x = four16BitIndices.x & 0xffff;
        result.y = (four16BitIndices.x >> 16) & 0xffff;
        result.z = four16BitIndices.y & 0xffff;
    } else {  // not aligned: { - 0 | 1 2 }
        result.x = (four16BitIndices.x >> 16) & 0xffff;
        result.y = four16BitIndices.y & 0xffff;
        result.z = (four16BitIndices.y >> 16) & 0xffff;
    }
    return result;
}

}  // namespace

uvec3 Load3x16BitIndices(uint32_t offsetBytes, const uint8_t* indices, size_t sizeInBytes) {
    const uint32_t dwordAlignedOffset = offsetBytes & ~3u;
    return unpack3x16BitIndices(offsetBytes, uvec2(loadDword(indices, sizeInBytes, dwordAlignedOffset),
                                                   loadDword(indices, sizeInBytes, dwordAlignedOffset + 4)));
}

void GenerateCameraRay(uvec2 index, uvec2 dimensions, vec3 cameraPosition, const Float4x4& projectionToWorld,
                       vec3& origin, vec3& direction) {
    const vec2 xy = vec2(index) + 0.5f;
    vec2 screenPos = xy / vec2(dimensions) * 2.0f - 1.0f;
    screenPos.y = -screenPos.y;
    vec4 world = mul(vec4(screenPos, 0.0f, 1.0f), projectionToWorld);
    const vec3 worldXYZ = vec3(world) / world.w;
    origin = cameraPosition;
    direction = hlsl::normalize(worldXYZ - origin);
}

vec3 FresnelReflectanceSchlick(vec3 I, vec3 N, vec3 f0) {
    const float cosi = hlsl::saturate(hlsl::dot(-I, N));
    return f0 + (1.0f - f0) * hlsl::pow(1.0f - cosi, 5.0f);
}

float CheckersTextureBoxFilter(vec2 uv, vec2 dpdx, vec2 dpdy, uint32_t ratio) {
    const float fRatio = float(ratio);
    const vec2 w = hlsl::max(hlsl::abs(dpdx), hlsl::abs(dpdy));  // filter kernel
    const vec2 a = uv + 0.5f * w;
    const vec2 b = uv - 0.5f * w;

    // Analytical integral (box filter), per component.
    vec2 i;
    for (glm::length_t k = 0; k < 2; ++k)
        i[k] = (hlsl::floor(a[k]) + hlsl::min(hlsl::frac(a[k]) * fRatio, 1.0f) - hlsl::floor(b[k]) -
                hlsl::min(hlsl::frac(b[k]) * fRatio, 1.0f)) /
               (fRatio * w[k]);
    return (1.0f - i.x) * (1.0f - i.y);
}

void CalculateRayDifferentials(vec2& ddx_uv, vec2& ddy_uv, vec2 uv, vec3 hitPosition, vec3 surfaceNormal,
                               vec3 cameraPosition, const Float4x4& projectionToWorld, uvec2 dispatchRaysIndex,
                               uvec2 dispatchRaysDimensions) {
    // Intersect the neighbouring pixels' primary rays with the tangent plane of the surface.
    vec3 ddxOrigin, ddxDirection, ddyOrigin, ddyDirection;
    GenerateCameraRay(dispatchRaysIndex + uvec2(1, 0), dispatchRaysDimensions, cameraPosition, projectionToWorld,
                      ddxOrigin, ddxDirection);
    GenerateCameraRay(dispatchRaysIndex + uvec2(0, 1), dispatchRaysDimensions, cameraPosition, projectionToWorld,
                      ddyOrigin, ddyDirection);

    const vec3 ddx_pos = ddxOrigin - ddxDirection * hlsl::dot(ddxOrigin - hitPosition, surfaceNormal) /
                                         hlsl::dot(ddxDirection, surfaceNormal);
    const vec3 ddy_pos = ddyOrigin - ddyDirection * hlsl::dot(ddyOrigin - hitPosition, surfaceNormal) /
                                         hlsl::dot(ddyDirection, surfaceNormal);

    // TexCoords(position) = position.xz.
    ddx_uv = vec2(ddx_pos.x, ddx_pos.z) - uv;
    ddy_uv = vec2(ddy_pos.x, ddy_pos.z) - uv;
}

float AnalyticalCheckersTexture(vec3 hitPosition, vec3 surfaceNormal, vec3 cameraPosition,
                                const Float4x4& projectionToWorld, uvec2 dispatchRaysIndex,
                                uvec2 dispatchRaysDimensions) {
    vec2 ddx_uv, ddy_uv;
    const vec2 uv(hitPosition.x, hitPosition.z);
    CalculateRayDifferentials(ddx_uv, ddy_uv, uv, hitPosition, surfaceNormal, cameraPosition, projectionToWorld,
                              dispatchRaysIndex, dispatchRaysDimensions);
    return CheckersTextureBoxFilter(uv, ddx_uv, ddy_uv, 50);
}

vec4 CalculatePhongLighting(const SceneConstantBuffer& sceneCB, vec4 albedo, vec3 normal, bool isInShadow,
                            float diffuseCoef, float specularCoef, float specularPower, vec3 hitPosition,
                            vec3 worldRayDirection) {
    const vec3 lightPosition = vec3(sceneCB.lightPosition);
    const float shadowFactor = isInShadow ? InShadowRadiance : 1.0f;
    const vec3 incidentLightRay = hlsl::normalize(hitPosition - lightPosition);

    // Diffuse component.
    const vec4 lightDiffuseColor = sceneCB.lightDiffuseColor;
    const float Kd = hlsl::saturate(hlsl::dot(-incidentLightRay, normal));
    const vec4 diffuseColor = shadowFactor * diffuseCoef * Kd * lightDiffuseColor * albedo;

    // Specular component.
    vec4 specularColor(0.0f);
    if (!isInShadow) {
        const vec4 lightSpecularColor(1.0f);
        const vec3 reflectedLightRay = hlsl::normalize(hlsl::reflect(incidentLightRay, normal));
        const float Ks =
            hlsl::pow(hlsl::saturate(hlsl::dot(reflectedLightRay, hlsl::normalize(-worldRayDirection))), specularPower);
        specularColor = specularCoef * Ks * lightSpecularColor;
    }

    // Ambient component, with the fake AO that darkens faces turned towards -y.
    const vec4 ambientColorMin = sceneCB.lightAmbientColor - 0.1f;
    const vec4 ambientColorMax = sceneCB.lightAmbientColor;
    const float a = 1.0f - hlsl::saturate(hlsl::dot(normal, vec3(0.0f, -1.0f, 0.0f)));
    const vec4 ambientColor = albedo * hlsl::lerp(ambientColorMin, ambientColorMax, a);

    return ambientColor + diffuseColor + specularColor;
}

vec4 ApplyVisibilityFalloff(vec4 color, float t) {
    return hlsl::lerp(color, BackgroundColor, 1.0f - hlsl::exp(-0.000002f * t * t * t));
}

// ---- Shader-side helpers (Raytracing.hlsl) ---------------------------------------------------------

namespace {

using hlsl::ScopedFlushDenormals;

SceneConstantBuffer sceneCB(const ShaderContext& ctx) {
    return ctx.load<SceneConstantBuffer>(ctx.globalRootDescriptor(kSceneConstant));
}

PrimitiveConstantBuffer materialCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveConstantBuffer>(kMaterialConstant);
}

PrimitiveInstanceConstantBuffer aabbCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveInstanceConstantBuffer>(kGeometryIndex);
}

// g_AABBPrimitiveAttributes[l_aabbCB.instanceIndex].
PrimitiveInstancePerFrameBuffer primitiveAttributes(const ShaderContext& ctx) {
    const GpuVirtualAddress element = ctx.globalRootDescriptor(kAABBattributeBuffer) +
                                      uint64_t(aabbCB(ctx).instanceIndex) * sizeof(PrimitiveInstancePerFrameBuffer);
    return ctx.load<PrimitiveInstancePerFrameBuffer>(element);
}

vec3 HitWorldPosition(const ShaderContext& ctx) {
    return ctx.WorldRayOrigin() + ctx.RayTCurrent() * ctx.WorldRayDirection();
}

// The object ray in the primitive's local space. The direction is not renormalised, so t means the same in world,
// object and local space (§2.2).
math::Ray<float> GetRayInAABBPrimitiveLocalSpace(const ShaderContext& ctx, const PrimitiveInstancePerFrameBuffer& attr) {
    math::Ray<float> ray;
    ray.origin = vec3(mul(vec4(ctx.ObjectRayOrigin(), 1.0f), attr.bottomLevelASToLocalSpace));
    ray.direction = mul3x3(ctx.ObjectRayDirection(), attr.bottomLevelASToLocalSpace);
    return ray;
}

// mul(n, (float3x3)localSpaceToBottomLevelAS), then normalize(mul((float3x3)ObjectToWorld3x4(), n)): the forward
// matrix, not the inverse transpose (I1).
vec3 NormalToWorld(const ShaderContext& ctx, const PrimitiveInstancePerFrameBuffer& attr, const vec3& localNormal) {
    const vec3 n = mul3x3(localNormal, attr.localSpaceToBottomLevelAS);
    const Matrix3x4 o2w = ctx.ObjectToWorld3x4();
    vec3 r;
    for (int i = 0; i < 3; ++i) r[i] = o2w.m[i][0] * n.x + o2w.m[i][1] * n.y + o2w.m[i][2] * n.z;
    return hlsl::normalize(r);
}

// The sample applies the triangle culling flags to its procedural hits itself (I3).
math::RayExtent<float> CurrentExtent(const ShaderContext& ctx) {
    const uint32_t flags = ctx.RayFlags();
    return {ctx.RayTMin(), ctx.RayTCurrent(), (flags & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) != 0,
            (flags & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) != 0};
}

// TraceRay wrappers: both stop at MAX_RAY_RECURSION_DEPTH (black / "not in shadow"); TMin 0, TMax 10000.
vec4 TraceRadianceRay(ShaderContext& ctx, const vec3& origin, const vec3& direction, uint32_t currentRayRecursionDepth) {
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH) return vec4(0.0f);
    const RayDesc rayDesc{origin, 0.0f, direction, 10000.0f};
    RayPayload rayPayload{vec4(0.0f), currentRayRecursionDepth + 1};
    ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure), RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
                 TraceRayParameters::InstanceMask, /*HitGroup::Offset*/ RayType::Radiance,
                 TraceRayParameters::GeometryStride, /*MissShader::Offset*/ RayType::Radiance, rayDesc, rayPayload);
    return rayPayload.color;
}

bool TraceShadowRayAndReportIfHit(ShaderContext& ctx, const vec3& origin, const vec3& direction,
                                  uint32_t currentRayRecursionDepth) {
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH) return false;
    // TMax 10000, not the distance to the light (I2).
    const RayDesc rayDesc{origin, 0.0f, direction, 10000.0f};
    // Starts as "hit": closest-hit and any-hit shaders are skipped, only MyMissShader_ShadowRay clears it.
    ShadowRayPayload shadowPayload{1};
    ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure),
                 RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE |
                     RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
                 TraceRayParameters::InstanceMask, /*HitGroup::Offset*/ RayType::Shadow,
                 TraceRayParameters::GeometryStride, /*MissShader::Offset*/ RayType::Shadow, rayDesc, shadowPayload);
    return shadowPayload.hit != 0;
}

// The shadow ray both closest hits start with: from HitWorldPosition() towards the light.
bool TraceShadowRayTowardsLight(ShaderContext& ctx, const SceneConstantBuffer& g_sceneCB, uint32_t recursionDepth) {
    const vec3 hitPosition = HitWorldPosition(ctx);
    return TraceShadowRayAndReportIfHit(ctx, hitPosition, hlsl::normalize(vec3(g_sceneCB.lightPosition) - hitPosition),
                                        recursionDepth);
}

// reflectanceCoef·(Fresnel, 1)·(reflection ray colour), the reflection ray leaving HitWorldPosition().
vec4 ReflectedColor(ShaderContext& ctx, const vec3& normal, const PrimitiveConstantBuffer& l_materialCB,
                    uint32_t recursionDepth) {
    const vec4 reflectionColor =
        TraceRadianceRay(ctx, HitWorldPosition(ctx), hlsl::reflect(ctx.WorldRayDirection(), normal), recursionDepth);
    const vec3 fresnelR = FresnelReflectanceSchlick(ctx.WorldRayDirection(), normal, vec3(l_materialCB.albedo));
    return l_materialCB.reflectanceCoef * vec4(fresnelR, 1.0f) * reflectionColor;
}

// ---- Entry points ----------------------------------------------------------------------------------

void MyRaygenShader(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const uvec3 index = ctx.DispatchRaysIndex();
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    vec3 origin, direction;
    GenerateCameraRay(uvec2(index), uvec2(ctx.DispatchRaysDimensions()), vec3(g_sceneCB.cameraPosition),
                      g_sceneCB.projectionToWorld, origin, direction);
    const uint32_t currentRecursionDepth = 0;
    const vec4 color = TraceRadianceRay(ctx, origin, direction, currentRecursionDepth);
    // PORT: the texture stores floats; the R8G8B8A8_UNORM conversion (clamp, round, NaN -> 0) happens when the
    // image is written out (H20).
    ctx.rwTexture2D(ctx.globalDescriptorTable(kOutputView)).at(index.x, index.y) = color;
}

void MyClosestHitShader_Triangle(ShaderContext& ctx, RayPayload& rayPayload,
                                 const BuiltInTriangleIntersectionAttributes&) {
    ScopedFlushDenormals ftz;
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    const PrimitiveConstantBuffer l_materialCB = materialCB(ctx);

    // The normal of the triangle's first vertex, untransformed.
    const uint32_t indexSizeInBytes = 2;
    const uint32_t indicesPerTriangle = 3;
    const uint32_t triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    const uint32_t baseIndex = ctx.PrimitiveIndex() * triangleIndexStride;
    // g_indices is t1 (descriptor 0 of the table), g_vertices t2 (descriptor 1); out-of-range reads give 0.
    const GpuDescriptorHandle vertexBuffers = ctx.globalDescriptorTable(kVertexBuffers);
    const uvec3 indices = unpack3x16BitIndices(
        baseIndex, ctx.loadFromTable<uvec2>(vertexBuffers, /*g_indices*/ 0, /*Load2 at*/ baseIndex & ~3u));
    const vec3 triangleNormal =
        ctx.loadFromTable<Vertex>(vertexBuffers, /*g_vertices*/ 1, uint64_t(indices[0]) * sizeof(Vertex)).normal;

    // Shadow component.
    const bool shadowRayHit = TraceShadowRayTowardsLight(ctx, g_sceneCB, rayPayload.recursionDepth);

    // Grid lines from the primary camera rays' footprint, even for secondary hits (I7, H4).
    const float checkers = AnalyticalCheckersTexture(
        HitWorldPosition(ctx), triangleNormal, vec3(g_sceneCB.cameraPosition), g_sceneCB.projectionToWorld,
        uvec2(ctx.DispatchRaysIndex()), uvec2(ctx.DispatchRaysDimensions()));

    // Reflected component.
    vec4 reflectedColor(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflectedColor = ReflectedColor(ctx, triangleNormal, l_materialCB, rayPayload.recursionDepth);

    // Final colour, then the visibility falloff.
    const vec4 phongColor = CalculatePhongLighting(g_sceneCB, l_materialCB.albedo, triangleNormal, shadowRayHit,
                                                   l_materialCB.diffuseCoef, l_materialCB.specularCoef,
                                                   l_materialCB.specularPower, HitWorldPosition(ctx),
                                                   ctx.WorldRayDirection());
    const vec4 color = checkers * (phongColor + reflectedColor);
    rayPayload.color = ApplyVisibilityFalloff(color, ctx.RayTCurrent());
}

void MyClosestHitShader_AABB(ShaderContext& ctx, RayPayload& rayPayload, const ProceduralPrimitiveAttributes& attr) {
    ScopedFlushDenormals ftz;
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    const PrimitiveConstantBuffer l_materialCB = materialCB(ctx);

    const bool shadowRayHit = TraceShadowRayTowardsLight(ctx, g_sceneCB, rayPayload.recursionDepth);

    vec4 reflectedColor(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflectedColor = ReflectedColor(ctx, attr.normal, l_materialCB, rayPayload.recursionDepth);

    const vec4 phongColor = CalculatePhongLighting(g_sceneCB, l_materialCB.albedo, attr.normal, shadowRayHit,
                                                   l_materialCB.diffuseCoef, l_materialCB.specularCoef,
                                                   l_materialCB.specularPower, HitWorldPosition(ctx),
                                                   ctx.WorldRayDirection());
    const vec4 color = phongColor + reflectedColor;
    rayPayload.color = ApplyVisibilityFalloff(color, ctx.RayTCurrent());
}

void MyMissShader(ShaderContext&, RayPayload& rayPayload) { rayPayload.color = BackgroundColor; }

void MyMissShader_ShadowRay(ShaderContext&, ShadowRayPayload& rayPayload) { rayPayload.hit = 0; }

// Each intersection shader starts from zero-initialised attributes (H6) and reports HitKind 0 with the world normal.
void MyIntersectionShader_AnalyticPrimitive(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const PrimitiveInstancePerFrameBuffer aabbAttribute = primitiveAttributes(ctx);
    const math::Ray<float> localRay = GetRayInAABBPrimitiveLocalSpace(ctx, aabbAttribute);
    const auto primitiveType = AnalyticPrimitive::Enum(aabbCB(ctx).primitiveType);
    const math::RayExtent<float> extent = CurrentExtent(ctx);

    // RayAnalyticGeometryIntersectionTest: the local box is <-1,1>^3.
    math::AnalyticHit<float> test;
    switch (primitiveType) {
        case AnalyticPrimitive::AABB: test = math::RayUnitCubeIntersectionTest(localRay, extent); break;
        case AnalyticPrimitive::Spheres: test = math::RaySpheresIntersectionTest(localRay, extent); break;
        default: break;
    }
    if (test.hit) {
        const ProceduralPrimitiveAttributes attr{NormalToWorld(ctx, aabbAttribute, test.normal)};
        ctx.ReportHit(test.thit, /*hitKind*/ 0, attr);
    }
}

void MyIntersectionShader_VolumetricPrimitive(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const PrimitiveInstancePerFrameBuffer aabbAttribute = primitiveAttributes(ctx);
    const math::Ray<float> localRay = GetRayInAABBPrimitiveLocalSpace(ctx, aabbAttribute);
    const auto primitiveType = VolumetricPrimitive::Enum(aabbCB(ctx).primitiveType);
    const float elapsedTime = sceneCB(ctx).elapsedTime;

    // RayVolumetricGeometryIntersectionTest: metaballs animated over a 12 s cycle. The march step depends on
    // RayTCurrent() at call time (H10).
    math::MetaballsHit<float> test;
    if (primitiveType == VolumetricPrimitive::Metaballs)
        test = math::RayMetaballsIntersectionTest(localRay, CurrentExtent(ctx), elapsedTime, 12.0f);
    if (test.hit) {
        const ProceduralPrimitiveAttributes attr{NormalToWorld(ctx, aabbAttribute, test.normal)};
        ctx.ReportHit(test.thit, /*hitKind*/ 0, attr);
    }
}

void MyIntersectionShader_SignedDistancePrimitive(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const PrimitiveInstancePerFrameBuffer aabbAttribute = primitiveAttributes(ctx);
    const math::Ray<float> localRay = GetRayInAABBPrimitiveLocalSpace(ctx, aabbAttribute);
    const auto primitiveType = SignedDistancePrimitive(aabbCB(ctx).primitiveType);

    // RaySignedDistancePrimitiveTest: sphere tracing from RayTMin(), not from the box entry (I6).
    math::SphereTraceParams<float> params;
    params.stepScale = materialCB(ctx).stepScale;
    const auto sdf = [primitiveType](const vec3& position) {
        return math::d3d12::GetDistanceFromSignedDistancePrimitive(position, primitiveType);
    };
    const math::SphereTraceResult<float> test =
        math::RaySignedDistancePrimitiveTest(localRay, CurrentExtent(ctx), sdf, params);
    if (test.hit) {
        const ProceduralPrimitiveAttributes attr{NormalToWorld(ctx, aabbAttribute, test.normal)};
        ctx.ReportHit(test.thit, /*hitKind*/ 0, attr);
    }
}

}  // namespace

std::shared_ptr<ShaderLibrary> makeD3D12ShaderLibrary() {
    auto lib = std::make_shared<ShaderLibrary>();
    lib->addRayGeneration("MyRaygenShader", MyRaygenShader);
    lib->addClosestHit<RayPayload, BuiltInTriangleIntersectionAttributes>("MyClosestHitShader_Triangle",
                                                                          MyClosestHitShader_Triangle);
    lib->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>("MyClosestHitShader_AABB", MyClosestHitShader_AABB);
    lib->addMiss<RayPayload>("MyMissShader", MyMissShader);
    lib->addMiss<ShadowRayPayload>("MyMissShader_ShadowRay", MyMissShader_ShadowRay);
    lib->addIntersection<ProceduralPrimitiveAttributes>("MyIntersectionShader_AnalyticPrimitive",
                                                        MyIntersectionShader_AnalyticPrimitive);
    lib->addIntersection<ProceduralPrimitiveAttributes>("MyIntersectionShader_VolumetricPrimitive",
                                                        MyIntersectionShader_VolumetricPrimitive);
    lib->addIntersection<ProceduralPrimitiveAttributes>("MyIntersectionShader_SignedDistancePrimitive",
                                                        MyIntersectionShader_SignedDistancePrimitive);
    return lib;
}

}  // namespace refray::procedural::d3d12
