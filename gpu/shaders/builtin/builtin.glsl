// Ports the shared code of refray's built-in scene library "builtin" from refray's C++ (procedural/builtin/
// builtin_shaders.cpp and core/ray_offset.h; the scene: scenes/builtin_scene.cpp). There is no HLSL original: this
// port follows the C++ line by line, so it cross-checks the emulator and the GPU, not two readings of an HLSL file.
//
// The including file defines its stage (DXR_STAGE_RAYGEN, _MISS, _CLOSEST_HIT, _INTERSECTION) and enables
// GL_EXT_ray_tracing, GL_EXT_scalar_block_layout and GL_GOOGLE_include_directive.
//
// Bindings (gpu/shaders/CONTRACT.md):
//   set 0 binding 0    b0  SceneConstants  root CBV (96 bytes, offsets below)
//   set 0 binding 100  t0  the TLAS        root SRV
//   set 0 binding 200  u0  g_output        table [0]: RWTexture2D<float4> (rgba32f image)
// Local root arguments (local root signature "Material", every hit group): offset 0 MaterialConstants (b1, 4 root
// constants: albedo, .w = reflectance).
// Payloads: location 0 RadiancePayload (20 bytes: color at 0, recursionDepth at 16); location 1 ShadowPayload
// (4 bytes: hit at 0); incoming payloads carry no location. Attributes: SphereAttributes (12 bytes: object-space normal), HitKind 0.
//
// Secondary rays start as SecondaryRayOrigin says (builtin_shaders.h); define SECONDARY_RAY_ORIGIN to pick one:
// 0 WaechterBinder (refray's default), 1 FixedTMin, 2 HitPoint.
#ifndef BUILTIN_GLSL
#define BUILTIN_GLSL

#include "common/d3d12_dxr_intrinsics.glsl"

#define SECONDARY_RAY_ORIGIN_WAECHTER_BINDER 0
#define SECONDARY_RAY_ORIGIN_FIXED_TMIN 1
#define SECONDARY_RAY_ORIGIN_HIT_POINT 2
#ifndef SECONDARY_RAY_ORIGIN
#define SECONDARY_RAY_ORIGIN SECONDARY_RAY_ORIGIN_WAECHTER_BINDER
#endif

#define PAYLOAD_LOCATION_RADIANCE 0
#define PAYLOAD_LOCATION_SHADOW 1

struct RadiancePayload {
    vec4 color;
    uint recursionDepth;
};

struct ShadowPayload {
    uint hit;
};

struct SphereAttributes {
    vec3 normal;  // object space
};

struct MaterialConstants {
    vec4 albedo;  // .w = reflectance
};

const uint kRayTypeCount = 2u;  // radiance = 0, shadow = 1

// PORT: TraceRay arguments a scene overrides become specialization constants (docs/vulkan-backend.md). refray's C++
// library takes each ray type's R, M, miss index and mask from the scene (a ray type's "traceRay", e.g. the lesson
// scenes/lessons/multiplier-one.json); the host (gpu/vulkan_pipeline.h, traceRayConstantId) gives ray type r's
// field f as constant_id 16 * (r + 1) + f: 0 R, 1 M, 2 miss index, 3 mask. The defaults are the C++ shaders' own
// arguments (procedural/builtin/builtin_shaders.cpp), so with no values given this file means them. The ray flags stay constants (a scene cannot override them).
layout(constant_id = 16) const uint kTraceRayRadiance_RayContribution = 0u;
layout(constant_id = 17) const uint kTraceRayRadiance_Multiplier = 2u;
layout(constant_id = 18) const uint kTraceRayRadiance_MissShaderIndex = 0u;
layout(constant_id = 19) const uint kTraceRayRadiance_InstanceMask = 0xFFu;
layout(constant_id = 32) const uint kTraceRayShadow_RayContribution = 1u;
layout(constant_id = 33) const uint kTraceRayShadow_Multiplier = 2u;
layout(constant_id = 34) const uint kTraceRayShadow_MissShaderIndex = 1u;
layout(constant_id = 35) const uint kTraceRayShadow_InstanceMask = 0xFFu;
const uint kMaxRecursionDepth = 3u;
const float kTMax = 10000.0;
const float kFixedTMin = 0.001;

layout(set = 0, binding = 100) uniform accelerationStructureEXT g_scene;
layout(set = 0, binding = 200, rgba32f) uniform image2D g_output;
layout(set = 0, binding = 0, scalar) uniform SceneConstants {
    layout(offset = 0) vec4 cameraPosition;
    layout(offset = 16) vec4 cameraRight;    // scaled by tan(fovY/2) * aspect
    layout(offset = 32) vec4 cameraUp;       // scaled by tan(fovY/2)
    layout(offset = 48) vec4 cameraForward;  // unit
    layout(offset = 64) vec4 lightPosition;
    layout(offset = 80) vec4 sphere;         // object-space centre (xyz) and radius (w)
} sc;

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION)
layout(shaderRecordEXT, scalar) buffer LocalRootArguments {
    layout(offset = 0) MaterialConstants m;  // kMaterialParameter: 4 root constants at b1
};
#endif

#if defined(DXR_STAGE_RAYGEN) || defined(DXR_STAGE_CLOSEST_HIT)
layout(location = PAYLOAD_LOCATION_RADIANCE) rayPayloadEXT RadiancePayload g_radiancePayload;
layout(location = PAYLOAD_LOCATION_SHADOW) rayPayloadEXT ShadowPayload g_shadowPayload;
#endif

// RayDesc, as the C++ passes it to TraceRay.
struct RayDesc {
    vec3 Origin;
    float TMin;
    vec3 Direction;
    float TMax;
};

// ---- core/ray_offset.h: offsetRayOrigin ----------------------------------------------------------------
#include "common/ray_offset.glsl"

// ---- builtin_shaders.cpp -------------------------------------------------------------------------

// Where a secondary ray leaving `position` (geometric normal `normal`) in `direction` starts, and its TMin.
RayDesc secondaryRay(vec3 position, vec3 normal, vec3 direction, float tMax) {
#if SECONDARY_RAY_ORIGIN == SECONDARY_RAY_ORIGIN_WAECHTER_BINDER
    const vec3 side = dot(normal, direction) >= 0.0 ? normal : -normal;
    return RayDesc(offsetRayOrigin(position, side), 0.0, direction, tMax);
#elif SECONDARY_RAY_ORIGIN == SECONDARY_RAY_ORIGIN_FIXED_TMIN
    return RayDesc(position, kFixedTMin, direction, tMax);
#else
    return RayDesc(position, 0.0, direction, tMax);
#endif
}

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION)
vec3 hitWorldPosition() { return WorldRayOrigin() + RayTCurrent() * WorldRayDirection(); }
#endif

#if defined(DXR_STAGE_RAYGEN) || defined(DXR_STAGE_CLOSEST_HIT)
vec4 traceRadiance(RayDesc ray, uint depth) {
    if (depth >= kMaxRecursionDepth) return vec4(0.0);
    g_radiancePayload = RadiancePayload(vec4(0.0), depth + 1u);
    // PORT: the C++ passes 0xFF, 0, kRayTypeCount, 0: the specialization constants' defaults.
    traceRayEXT(g_scene, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, kTraceRayRadiance_InstanceMask,
                kTraceRayRadiance_RayContribution, kTraceRayRadiance_Multiplier, kTraceRayRadiance_MissShaderIndex,
                ray.Origin, ray.TMin, ray.Direction, ray.TMax, PAYLOAD_LOCATION_RADIANCE);
    return g_radiancePayload.color;
}

bool inShadow(RayDesc ray, uint depth) {
    if (depth >= kMaxRecursionDepth) return false;
    g_shadowPayload = ShadowPayload(1u);
    traceRayEXT(g_scene,
                RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
                kTraceRayShadow_InstanceMask, kTraceRayShadow_RayContribution, kTraceRayShadow_Multiplier,
                kTraceRayShadow_MissShaderIndex, ray.Origin, ray.TMin, ray.Direction, ray.TMax,
                PAYLOAD_LOCATION_SHADOW);
    return g_shadowPayload.hit != 0u;
}
#endif

vec4 skyColor(vec3 direction) {
    const vec4 kSkyTop = vec4(0.35, 0.55, 0.9, 1.0);
    const vec4 kSkyHorizon = vec4(0.85, 0.9, 1.0, 1.0);
    // PORT: std::clamp(y, 0, 1) spelled out, so that a NaN passes through as in the C++.
    const float y = normalize(direction).y;
    const float up = y < 0.0 ? 0.0 : (1.0 < y ? 1.0 : y);
    return kSkyHorizon + (kSkyTop - kSkyHorizon) * up;
}

vec3 checkerAlbedo(vec3 p, vec3 albedo) {
    const bool checker = ((int(floor(p.x)) + int(floor(p.z))) & 1) != 0;
    return albedo * (checker ? 1.0 : 0.55);
}

vec3 lambert(vec3 albedo, vec3 normal, vec3 toLightUnit, bool shadowed) {
    // PORT: std::max(0.0f, c) is (0 < c) ? c : 0 (NaN -> 0), spelled out.
    const float c = dot(normal, toLightUnit);
    const float cosine = 0.0 < c ? c : 0.0;
    return albedo * (0.15 + (shadowed ? 0.0 : 0.85 * cosine));
}

// Nearest root of |o + t d - centre| = radius within [tMin, tMax], if any (o relative to the centre).
bool intersectSphere(vec3 o, vec3 d, float radius, float tMin, float tMax, out float tHit) {
    const float a = dot(d, d), b = dot(o, d), c = dot(o, o) - radius * radius;
    const float disc = b * b - a * c;
    tHit = 0.0;
    if (disc < 0.0) return false;
    const float root = sqrt(disc);
    const float roots[2] = float[2]((-b - root) / a, (-b + root) / a);
    for (int k = 0; k < 2; ++k) {
        const float t = roots[k];
        if (t >= tMin && t <= tMax) {
            tHit = t;
            return true;
        }
    }
    return false;
}

// The primary ray direction of pixel `index` (pinhole, pixel centre).
vec3 primaryDirection(uvec3 index, uvec3 dims) {
    const float sx = (float(index.x) + 0.5) / float(dims.x) * 2.0 - 1.0;
    const float sy = -((float(index.y) + 0.5) / float(dims.y) * 2.0 - 1.0);
    return normalize(sc.cameraForward.xyz + sx * sc.cameraRight.xyz + sy * sc.cameraUp.xyz);
}

#if defined(DXR_STAGE_CLOSEST_HIT)
// `normal` is the geometric normal (the plane's and the sphere's are their shading normals too).
vec3 shade(vec3 albedo, vec3 normal, vec3 position, uint depth) {
    const vec3 toLight = sc.lightPosition.xyz - position;
    const float distance = length(toLight);
    const vec3 l = toLight / distance;
    const bool shadowed = dot(normal, l) > 0.0 && inShadow(secondaryRay(position, normal, l, distance), depth);
    return lambert(albedo, normal, l, shadowed);
}
#endif

#endif  // BUILTIN_GLSL
