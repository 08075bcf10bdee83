// Ports: Proceduray Raytracing.hlsl, Helpers.hlsli, RaytracingShaderHelper.hlsli (camera ray, Fresnel, index loads),
// Triangles.hlsli, Pacman.hlsli, JuliaSets.hlsli, Mandelbulb.hlsli entry points; see proceduray_shaders.h.
#include "procedural/proceduray/proceduray_shaders.h"

#include <cstring>

#include "emulator/shader_api.h"
#include "procedural/math/fractals.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/ray.h"
#include "procedural/math/sdf.h"

namespace refray::procedural::proceduray {

using namespace refray::dxr;

// ---- Scene data (§1.1) -----------------------------------------------------------------------------

const std::array<uint16_t, 36> kSlabIndices = {0, 4, 7, 0, 7, 3, 1, 5, 4, 1, 4, 0, 5, 2, 6, 5, 1, 2,
                                               3, 7, 6, 3, 6, 2, 2, 0, 3, 2, 1, 0, 4, 6, 7, 4, 5, 6};

const std::array<Vertex, 8> kSlabVertices = {{
    {{-0.5f, -0.2f, 0.2f}, {0.0f, 0.0f, -1.0f}},
    {{-0.5f, -0.2f, -0.2f}, {0.0f, 1.0f, 0.0f}},
    {{-0.5f, 0.2f, -0.2f}, {1.0f, 0.0f, 0.0f}},
    {{-0.5f, 0.2f, 0.2f}, {0.0f, -1.0f, 0.0f}},
    {{0.5f, -0.2f, 0.2f}, {-1.0f, 0.0f, 0.0f}},
    {{0.5f, -0.2f, -0.2f}, {0.0f, 0.0f, 1.0f}},
    {{0.5f, 0.2f, -0.2f}, {0.0f, 1.0f, 0.0f}},
    {{0.5f, 0.2f, 0.2f}, {0.0f, 1.0f, 0.0f}},
}};

// ---- Root signatures and hit groups ----------------------------------------------------------------

RootSignatureDesc globalRootSignatureDesc() {
    RootSignatureDesc desc;
    desc.name = "GlobalSignature";
    desc.parameters = {
        RootParameter::table({DescriptorRange{DescriptorRangeType::UAV, 1, 0, 0, 0}}),  // u0
        RootParameter::srv(0),                                                           // t0
        RootParameter::cbv(0),                                                           // b0
        RootParameter::srv(3),                                                           // t3
        RootParameter::table({DescriptorRange{DescriptorRangeType::SRV, 2, 1, 0, 0}}),  // t1, t2
    };
    return desc;
}

RootSignatureDesc triangleLocalRootSignatureDesc() {
    RootSignatureDesc desc;
    desc.name = "Triangle";
    desc.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    desc.parameters = {RootParameter::constants(sizeof(PrimitiveConstantBuffer) / 4, 1)};
    return desc;
}

RootSignatureDesc proceduralLocalRootSignatureDesc() {
    RootSignatureDesc desc;
    desc.name = "Procedural";
    desc.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    desc.parameters = {RootParameter::constants(sizeof(PrimitiveConstantBuffer) / 4, 1),
                       RootParameter::constants(sizeof(PrimitiveInstanceConstantBuffer) / 4, 2)};
    return desc;
}

std::vector<HitGroupDesc> procedurayHitGroups() {
    using enum HitGroupType;
    return {
        {"HitGroup_Triangle", Triangles, "", "ClosestHit_Triangle", ""},
        {"HitGroup_Triangle_Shadow", Triangles, "", "", ""},
        {"HitGroup_Pacman", ProceduralPrimitive, "", "ClosestHit_Pacman", "Intersection_Pacman"},
        {"HitGroup_Pacman_Shadow", ProceduralPrimitive, "", "", "Intersection_Pacman"},
        {"HitGroup_Mandelbulb", ProceduralPrimitive, "", "ClosestHit_Mandelbulb", "Intersection_Mandelbulb"},
        {"HitGroup_Mandelbulb_Shadow", ProceduralPrimitive, "", "", "Intersection_Mandelbulb"},
        {"HitGroup_Julia", ProceduralPrimitive, "", "ClosestHit_Julia", "Intersection_Julia"},
        {"HitGroup_Julia_Shadow", ProceduralPrimitive, "", "", "Intersection_Julia"},
    };
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

uvec3 Load3x16BitIndices(uint32_t offsetBytes, const uint8_t* indices, size_t sizeInBytes) {
    const uint32_t dwordAlignedOffset = offsetBytes & ~3u;
    const uvec2 four16BitIndices(loadDword(indices, sizeInBytes, dwordAlignedOffset),
                                 loadDword(indices, sizeInBytes, dwordAlignedOffset + 4));
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

vec3 FresnelReflectanceSchlick(vec3 I, vec3 N, vec3 f0) {
    const float cosi = hlsl::saturate(hlsl::dot(-I, N));
    return f0 + (1.0f - f0) * hlsl::pow(1.0f - cosi, 5.0f);
}

vec3 colorSurface(vec3 pos, vec2 tn) {
    vec3 col = 0.5f + 0.5f * hlsl::cos(hlsl::log2(tn.y) * 0.9f + 3.5f + vec3(0.0f, 0.6f, 1.0f));
    if (pos.y > 0.0f) col = hlsl::lerp(col, vec3(1.0f), 0.2f);
    const float inside = hlsl::smoothstep(14.0f, 15.0f, tn.y);
    col *= vec3(0.45f, 0.42f, 0.40f) + vec3(0.55f, 0.58f, 0.60f) * inside;
    col = hlsl::lerp(col * col * (3.0f - 2.0f * col), col, inside);
    col = hlsl::lerp(hlsl::lerp(col, vec3(hlsl::dot(col, vec3(0.3333f, 0.333f, 0.333f))), -0.4f), col, inside);
    return hlsl::clamp(col * 0.65f, 0.0f, 1.0f);
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

vec4 MandelbulbSurfaceColor(vec3 D, vec3 N, vec4 trap) {
    // Colour from the orbit trap.
    vec3 col(0.01f, 0.01f, 0.01f);
    col = hlsl::lerp(col, vec3(0.10f, 0.20f, 0.30f), hlsl::clamp(trap.y, 0.0f, 1.0f));
    col = hlsl::lerp(col, vec3(0.02f, 0.10f, 0.30f), hlsl::clamp(trap.z * trap.z, 0.0f, 1.0f));
    col = hlsl::lerp(col, vec3(0.30f, 0.10f, 0.02f), hlsl::clamp(hlsl::pow(trap.w, 6.0f), 0.0f, 1.0f));
    col *= 0.5f;

    // Lighting terms: two fixed lights, no scene light, no shadow (sha1 = 1).
    const vec3 light1(0.577f, 0.577f, -0.577f);
    const vec3 light2(-0.707f, 0.000f, 0.707f);
    const vec3 nor = N;
    const vec3 hal = hlsl::normalize(light1 - D);
    const float occ = hlsl::clamp(0.05f * hlsl::log(trap.x), 0.0f, 1.0f);
    const float fac = hlsl::clamp(1.0f + hlsl::dot(D, nor), 0.0f, 1.0f);

    const float sha1 = 1.0f;
    const float dif1 = hlsl::clamp(hlsl::dot(light1, nor), 0.0f, 1.0f) * sha1;
    const float spe1 = hlsl::pow(hlsl::clamp(hlsl::dot(nor, hal), 0.0f, 1.0f), 32.0f) * dif1 *
                       (0.04f + 0.96f * hlsl::pow(hlsl::clamp(1.0f - hlsl::dot(hal, light1), 0.0f, 1.0f), 5.0f));
    const float dif2 = hlsl::clamp(0.5f + 0.5f * hlsl::dot(light2, nor), 0.0f, 1.0f) * occ;
    const float dif3 = (0.7f + 0.3f * nor.y) * (0.2f + 0.8f * occ);

    vec3 lin(0.0f);
    lin += 7.0f * vec3(1.50f, 1.10f, 0.70f) * dif1;
    lin += 4.0f * vec3(0.25f, 0.20f, 0.15f) * dif2;
    lin += 1.5f * vec3(0.10f, 0.20f, 0.30f) * dif3;
    lin += 2.5f * vec3(0.35f, 0.30f, 0.25f) * (0.05f + 0.95f * occ);
    lin += 4.0f * fac * occ;
    col *= lin;
    col = hlsl::pow(col, vec3(0.7f, 0.9f, 1.0f));
    col += spe1 * 15.0f;
    col = hlsl::sqrt(col);
    return vec4(col, 1.0f);
}

// ---- Shader-side helpers (Helpers.hlsli, RaytracingShaderHelper.hlsli) -----------------------------

namespace {

using hlsl::ScopedFlushDenormals;

SceneConstantBuffer sceneCB(const ShaderContext& ctx) {
    return ctx.load<SceneConstantBuffer>(ctx.globalRootDescriptor(kSceneConstantBuffer));
}

PrimitiveConstantBuffer materialCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveConstantBuffer>(kMaterialConstantBuffer);
}

PrimitiveInstanceConstantBuffer aabbCB(const ShaderContext& ctx) {
    return ctx.localRootConstants<PrimitiveInstanceConstantBuffer>(kAABBConstantBuffer);
}

vec3 HitWorldPosition(const ShaderContext& ctx) {
    return ctx.WorldRayOrigin() + ctx.RayTCurrent() * ctx.WorldRayDirection();
}

// The world ray in the AABB's local space through g_instanceBuffer[l_aabbCB.instanceIndex]; the
// direction is normalised, which is where H1 comes from.
math::Ray<float> GetRayInAABBPrimitiveLocalSpace(const ShaderContext& ctx) {
    const GpuVirtualAddress element =
        ctx.globalRootDescriptor(kInstanceBuffer) + uint64_t(aabbCB(ctx).instanceIndex) * sizeof(InstanceBuffer);
    const InstanceBuffer attr = ctx.load<InstanceBuffer>(element);
    math::Ray<float> ray;
    ray.origin = vec3(mul(vec4(ctx.WorldRayOrigin(), 1.0f), attr.localSpaceToBottomLevelAS));
    ray.direction = hlsl::normalize(mul3x3(ctx.WorldRayDirection(), attr.localSpaceToBottomLevelAS));
    return ray;
}

// normalize(mul(n, (float3x3)WorldToObject3x4())): the inverse transpose of ObjectToWorld.
vec3 NormalToWorld(const ShaderContext& ctx, const vec3& n) {
    const Matrix3x4 w = ctx.WorldToObject3x4();
    vec3 r;
    for (int j = 0; j < 3; ++j) r[j] = n.x * w.m[0][j] + n.y * w.m[1][j] + n.z * w.m[2][j];
    return hlsl::normalize(r);
}

math::RayExtent<float> CurrentExtent(const ShaderContext& ctx) {
    const uint32_t flags = ctx.RayFlags();
    return {ctx.RayTMin(), ctx.RayTCurrent(), (flags & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) != 0,
            (flags & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) != 0};
}

float CalculateDiffuseCoefficient(const vec3& incidentLightRay, const vec3& normal) {
    return hlsl::saturate(hlsl::dot(-incidentLightRay, normal));
}

float CalculateSpecularCoefficient(const ShaderContext& ctx, const vec3& incidentLightRay, const vec3& normal,
                                   float specularPower) {
    const vec3 reflectedLightRay = hlsl::normalize(hlsl::reflect(incidentLightRay, normal));
    return hlsl::pow(hlsl::saturate(hlsl::dot(reflectedLightRay, hlsl::normalize(-ctx.WorldRayDirection()))),
                     specularPower);
}

// Phong = ambient (with the "fake AO" towards -y) + diffuse + specular; the light is a point light.
vec4 CalculatePhongLighting(const ShaderContext& ctx, const SceneConstantBuffer& g_sceneCB, const vec4& albedo,
                            const vec3& normal, bool isInShadow, float diffuseCoef, float specularCoef,
                            float specularPower) {
    const vec3 hitPosition = HitWorldPosition(ctx);
    const vec3 lightPosition = vec3(g_sceneCB.lightPosition);
    const float shadowFactor = isInShadow ? kInShadowRadiance : 1.0f;
    const vec3 incidentLightRay = hlsl::normalize(hitPosition - lightPosition);

    // Diffuse component.
    const vec4 lightDiffuseColor = g_sceneCB.lightDiffuseColor;
    const float Kd = CalculateDiffuseCoefficient(incidentLightRay, normal);
    const vec4 diffuseColor = shadowFactor * diffuseCoef * Kd * lightDiffuseColor * albedo;

    // Specular component.
    vec4 specularColor(0.0f);
    if (!isInShadow) {
        const vec4 lightSpecularColor(1.0f);
        const float Ks = CalculateSpecularCoefficient(ctx, incidentLightRay, normal, specularPower);
        specularColor = specularCoef * Ks * lightSpecularColor;
    }

    // Ambient component.
    const vec4 ambientColorMin = g_sceneCB.lightAmbientColor - 0.1f;
    const vec4 ambientColorMax = g_sceneCB.lightAmbientColor;
    const float a = 1.0f - hlsl::saturate(hlsl::dot(normal, vec3(0.0f, -1.0f, 0.0f)));
    const vec4 ambientColor = albedo * hlsl::lerp(ambientColorMin, ambientColorMax, a);

    return ambientColor + diffuseColor + specularColor;
}

// TraceRay wrappers: both stop at MAX_RAY_RECURSION_DEPTH (black / "not in shadow"); TMin 0, TMax 10000.
vec4 TraceRadianceRay(ShaderContext& ctx, const vec3& origin, const vec3& direction, uint32_t currentRayRecursionDepth) {
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH) return vec4(0.0f);
    const RayDesc rayDesc{origin, 0.0f, direction, 10000.0f};
    RayPayload rayPayload{vec4(0.0f), currentRayRecursionDepth + 1, 0.0f, 0, 0};
    ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure), RAY_FLAG_CULL_BACK_FACING_TRIANGLES, kInstanceMask,
                 /*RayContributionToHitGroupIndex*/ Radiance, /*MultiplierForGeometryContribution*/ RayTypeCount,
                 /*MissShaderIndex*/ Radiance, rayDesc, rayPayload);
    return rayPayload.color;
}

bool TraceShadowRayAndReportIfHit(ShaderContext& ctx, const vec3& origin, const vec3& direction,
                                  uint32_t currentRayRecursionDepth) {
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH) return false;
    const RayDesc rayDesc{origin, 0.0f, direction, 10000.0f};
    // Starts as "hit": closest-hit and any-hit shaders are skipped, only Miss_Shadow clears it.
    ShadowRayPayload shadowPayload{0.0f, 1};
    ctx.TraceRay(ctx.globalRootDescriptor(kAccelerationStructure),
                 RAY_FLAG_CULL_BACK_FACING_TRIANGLES | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE |
                     RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
                 kInstanceMask, /*RayContributionToHitGroupIndex*/ Shadow,
                 /*MultiplierForGeometryContribution*/ RayTypeCount, /*MissShaderIndex*/ Shadow, rayDesc, shadowPayload);
    return shadowPayload.hit != 0;
}

// The shadow test every lit closest hit starts with: from HitWorldPosition() towards the light.
bool TraceShadowRayTowardsLight(ShaderContext& ctx, const SceneConstantBuffer& g_sceneCB, uint32_t recursionDepth) {
    const vec3 hitPosition = HitWorldPosition(ctx);
    return TraceShadowRayAndReportIfHit(ctx, hitPosition, hlsl::normalize(vec3(g_sceneCB.lightPosition) - hitPosition),
                                        recursionDepth);
}

// reflectanceCoef·(Fresnel, 1)·(reflection ray colour), the reflection ray leaving HitWorldPosition().
vec4 ReflectedColor(ShaderContext& ctx, const vec3& normal, float reflectanceCoef, const vec3& f0,
                    uint32_t recursionDepth) {
    const vec4 reflectionColor =
        TraceRadianceRay(ctx, HitWorldPosition(ctx), hlsl::reflect(ctx.WorldRayDirection(), normal), recursionDepth);
    const vec3 fresnelR = FresnelReflectanceSchlick(ctx.WorldRayDirection(), normal, f0);
    return reflectanceCoef * vec4(fresnelR, 1.0f) * reflectionColor;
}

// ProceduralPrimitivesLibrary.hlsli GetDistanceFromSignedDistancePrimitive: only the Pac-man case is live.
// PORT: takes the mouth interpolant instead of the time (computed once per IS, see fractals.h).
float GetDistanceFromSignedDistancePrimitive(const vec3& position, SignedDistancePrimitive signedDistancePrimitive,
                                             float mouth) {
    switch (signedDistancePrimitive) {
        case SignedDistancePrimitive::IntersectedRoundCube: return math::pacman::pacMan(position, mouth);
        default: return 0.0f;
    }
}

constexpr ProceduralPrimitiveAttributes kInitialAttributes{vec3(0.0f), vec4(0.0f, 0.0f, 0.0f, 1.0f)};

// ---- Entry points ----------------------------------------------------------------------------------

void Raygen(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const uvec3 index = ctx.DispatchRaysIndex();
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    vec3 origin, direction;
    GenerateCameraRay(uvec2(index), uvec2(ctx.DispatchRaysDimensions()), vec3(g_sceneCB.cameraPosition),
                      g_sceneCB.projectionToWorld, origin, direction);
    const uint32_t currentRecursionDepth = 0;
    const vec4 color = TraceRadianceRay(ctx, origin, direction, currentRecursionDepth);
    // PORT: the texture stores floats; the R8G8B8A8_UNORM conversion happens when the image is written out.
    ctx.rwTexture2D(ctx.globalDescriptorTable(kOutputView)).at(index.x, index.y) = color;
}

void Miss(ShaderContext&, RayPayload& rayPayload) {
    rayPayload.color = kBackgroundColor;
    rayPayload.hit = 0;
}

void Miss_Shadow(ShaderContext&, ShadowRayPayload& rayPayload) {
    const float gStep = 4.0f;
    rayPayload.dist += gStep;
    rayPayload.hit = 0;
}

void ClosestHit_Triangle(ShaderContext& ctx, RayPayload& rayPayload, const BuiltInTriangleIntersectionAttributes&) {
    ScopedFlushDenormals ftz;
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    if (g_sceneCB.debugFlag) {
        rayPayload.color = vec4(0.0f, 0.0f, 1.0f, 0.0f);
        return;
    }
    const PrimitiveConstantBuffer l_materialCB = materialCB(ctx);

    // The triangle's first 16-bit index, and the negated stored normal of that vertex.
    const uint32_t indexSizeInBytes = 2;
    const uint32_t indicesPerTriangle = 3;
    const uint32_t triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    const uint32_t baseIndex = ctx.PrimitiveIndex() * triangleIndexStride;
    // PORT: g_indices / g_vertices are the built-in copies (see kSlabIndices); out-of-range reads give 0.
    const uvec3 indices = Load3x16BitIndices(baseIndex, reinterpret_cast<const uint8_t*>(kSlabIndices.data()),
                                             sizeof(kSlabIndices));
    const vec3 storedNormal = indices[0] < kSlabVertices.size() ? kSlabVertices[indices[0]].normal : vec3(0.0f);
    const vec3 triangleNormal = -storedNormal;

    const bool shadowRayHit = TraceShadowRayTowardsLight(ctx, g_sceneCB, rayPayload.recursionDepth);

    vec4 reflectedColor(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflectedColor = ReflectedColor(ctx, triangleNormal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo),
                                        rayPayload.recursionDepth);

    const vec4 phongColor =
        CalculatePhongLighting(ctx, g_sceneCB, l_materialCB.albedo, triangleNormal, shadowRayHit,
                               l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = phongColor + reflectedColor;
    color += rayPayload.color;
    rayPayload.dist += ctx.RayTCurrent();
    rayPayload.color = color;
}

void Intersection_Pacman(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const math::Ray<float> localRay = GetRayInAABBPrimitiveLocalSpace(ctx);
    const auto primitiveType = SignedDistancePrimitive(aabbCB(ctx).primitiveType);
    ProceduralPrimitiveAttributes attr = kInitialAttributes;

    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    if (g_sceneCB.debugFlag) {
        ctx.ReportHit(0.0f, 1, attr);
        return;
    }

    const float mouth = math::pacman::PacmanMouthInterpolant(g_sceneCB.elapsedTime);
    math::SphereTraceParams<float> params;
    params.stepScale = materialCB(ctx).stepScale;
    const auto sdf = [primitiveType, mouth](const vec3& p) {
        return GetDistanceFromSignedDistancePrimitive(p, primitiveType, mouth);
    };
    const math::SphereTraceResult<float> primitiveTest =
        math::RaySignedDistancePrimitiveTest(localRay, CurrentExtent(ctx), sdf, params);

    // H1: thit is in normalised local units, compared with and reported as if it were world t.
    if (primitiveTest.hit && primitiveTest.thit < ctx.RayTCurrent()) {
        attr.color = math::pacman::PacmanHitColor(primitiveTest.normal, primitiveTest.position);
        attr.normal = NormalToWorld(ctx, primitiveTest.normal);
        ctx.ReportHit(primitiveTest.thit, /*hitKind*/ 0, attr);
    }
}

void ClosestHit_Pacman(ShaderContext& ctx, RayPayload& rayPayload, const ProceduralPrimitiveAttributes& attr) {
    ScopedFlushDenormals ftz;
    if (ctx.HitKind() == 1) {
        rayPayload.color = vec4(0.0f, 0.0f, 1.0f, 0.0f);
        return;
    }
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    const PrimitiveConstantBuffer l_materialCB = materialCB(ctx);

    const bool shadowRayHit = TraceShadowRayTowardsLight(ctx, g_sceneCB, rayPayload.recursionDepth);

    vec4 reflectedColor(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflectedColor = ReflectedColor(ctx, attr.normal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo),
                                        rayPayload.recursionDepth);

    const vec4 phongColor =
        CalculatePhongLighting(ctx, g_sceneCB, l_materialCB.albedo, attr.normal, shadowRayHit, l_materialCB.diffuseCoef,
                               l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = attr.color * (phongColor + reflectedColor);
    color += rayPayload.color;
    rayPayload.dist += ctx.RayTCurrent();
    rayPayload.color = color;
}

void Intersection_Mandelbulb(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const math::Ray<float> localRay = GetRayInAABBPrimitiveLocalSpace(ctx);
    ProceduralPrimitiveAttributes attr = kInitialAttributes;

    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    if (g_sceneCB.debugFlag) {
        ctx.ReportHit(0.0f, 1, attr);
        return;
    }

    // The step count animates with time and the procedural instance ordinal (not InstanceIndex()).
    // l_materialCB.stepScale is passed by the HLSL but never used, so it is not read here.
    const int iMax =
        math::mandelbulb::MandelbulbIterationCount(g_sceneCB.elapsedTime, int(aabbCB(ctx).instanceIndex));
    const math::mandelbulb::MandelbulbHit<float> primitiveTest =
        math::mandelbulb::MandelbulbDistance(localRay.origin, localRay.direction, iMax);

    if (primitiveTest.hit && primitiveTest.thit < ctx.RayTCurrent()) {
        attr.color = primitiveTest.color;
        attr.normal = NormalToWorld(ctx, primitiveTest.normal);
        ctx.ReportHit(primitiveTest.thit, /*hitKind*/ 0, attr);
    }
}

void ClosestHit_Mandelbulb(ShaderContext& ctx, RayPayload& rayPayload, const ProceduralPrimitiveAttributes& attr) {
    ScopedFlushDenormals ftz;
    if (ctx.HitKind() == 1) {
        rayPayload.color = vec4(0.0f, 1.0f, 0.0f, 0.0f);
        return;
    }
    const PrimitiveConstantBuffer l_materialCB = materialCB(ctx);

    vec4 color = MandelbulbSurfaceColor(ctx.WorldRayDirection(), attr.normal, attr.color);

    vec4 reflectedColor(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflectedColor = ReflectedColor(ctx, attr.normal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo),
                                        rayPayload.recursionDepth);

    color = color + reflectedColor;
    color += rayPayload.color;
    rayPayload.dist += ctx.RayTCurrent();
    rayPayload.color = color;
}

void Intersection_Julia(ShaderContext& ctx) {
    ScopedFlushDenormals ftz;
    const math::Ray<float> localRay = GetRayInAABBPrimitiveLocalSpace(ctx);
    ProceduralPrimitiveAttributes attr = kInitialAttributes;

    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    if (g_sceneCB.debugFlag) {
        ctx.ReportHit(0.0f, 1, attr);
        return;
    }

    // PORT: JuliaDistance takes no time; the HLSL's cut animation is computed and then ignored (§5.5).
    const math::julia::JuliaHit<float> primitiveTest = math::julia::JuliaDistance(localRay.origin, localRay.direction);
    const vec2 thit = primitiveTest.resT;

    // H1: thit.x is in q-space units (0.4 x normalised local units).
    if (primitiveTest.hit && thit.x < ctx.RayTCurrent()) {
        attr.normal = NormalToWorld(ctx, primitiveTest.normal);
        attr.color = vec4(thit, 0.0f, 0.0f);  // (t, iteration count) for ClosestHit_Julia
        ctx.ReportHit(thit.x, /*hitKind*/ 0, attr);
    }
}

void ClosestHit_Julia(ShaderContext& ctx, RayPayload& rayPayload, const ProceduralPrimitiveAttributes& attr) {
    ScopedFlushDenormals ftz;
    const SceneConstantBuffer g_sceneCB = sceneCB(ctx);
    if (g_sceneCB.debugFlag) {
        rayPayload.color = vec4(1.0f, 0.0f, 0.0f, 0.0f);
        return;
    }

    // No shadow ray: the HLSL has it commented out.
    const bool shadowRayHit = false;

    // H1: with the local-unit t this point lies near the object-space ray origin, not on the surface.
    const vec3 pos = ctx.ObjectRayOrigin() + ctx.RayTCurrent() * ctx.ObjectRayDirection();
    vec4 albedo = vec4(3.5f * colorSurface(pos, vec2(attr.color)), 1.0f);
    if (rayPayload.recursionDepth == MAX_RAY_RECURSION_DEPTH - 1) albedo += 1.65f * hlsl::step(0.0f, hlsl::abs(pos.y));

    const float reflecCoef = 0.1f;
    vec4 reflectedColor(0.0f);
    if (reflecCoef > 0.001f)
        reflectedColor = ReflectedColor(ctx, attr.normal, reflecCoef, vec3(albedo), rayPayload.recursionDepth);

    const float diffuseCoef = 0.6f;
    const float specularCoef = 0.08f;
    const float specularPower = 0.2f;
    const vec4 phongColor =
        CalculatePhongLighting(ctx, g_sceneCB, albedo, attr.normal, shadowRayHit, diffuseCoef, specularCoef, specularPower);
    vec4 color = phongColor + reflectedColor;
    color += rayPayload.color;
    rayPayload.color = color;
}

}  // namespace

std::shared_ptr<ShaderLibrary> makeProcedurayShaderLibrary() {
    auto lib = std::make_shared<ShaderLibrary>();
    lib->addRayGeneration("Raygen", Raygen);
    lib->addMiss<RayPayload>("Miss", Miss);
    lib->addMiss<ShadowRayPayload>("Miss_Shadow", Miss_Shadow);
    lib->addClosestHit<RayPayload, BuiltInTriangleIntersectionAttributes>("ClosestHit_Triangle", ClosestHit_Triangle);
    lib->addIntersection<ProceduralPrimitiveAttributes>("Intersection_Julia", Intersection_Julia);
    lib->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>("ClosestHit_Julia", ClosestHit_Julia);
    lib->addIntersection<ProceduralPrimitiveAttributes>("Intersection_Pacman", Intersection_Pacman);
    lib->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>("ClosestHit_Pacman", ClosestHit_Pacman);
    lib->addIntersection<ProceduralPrimitiveAttributes>("Intersection_Mandelbulb", Intersection_Mandelbulb);
    lib->addClosestHit<RayPayload, ProceduralPrimitiveAttributes>("ClosestHit_Mandelbulb", ClosestHit_Mandelbulb);
    return lib;
}

}  // namespace refray::procedural::proceduray
