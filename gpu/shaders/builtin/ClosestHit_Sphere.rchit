// Ports the export ClosestHit_Sphere of refray's C++ procedural/builtin/builtin_shaders.cpp (no HLSL original).
// Closest hit of HitGroup_Sphere (procedural; local root signature "Material").
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_CLOSEST_HIT
#include "builtin/builtin.glsl"

rayPayloadInEXT RadiancePayload payload;
hitAttributeEXT SphereAttributes attr;

void main() {
    // Object-space normal to world: the inverse transpose of ObjectToWorld, i.e. n times the 3x3 of WorldToObject
    // (C++: component i = sum_r w2o.m[r][i] * n[r]). GLSL: row vector times mat3 of the mat4x3 (its columns 0..2).
    const vec3 n = normalize(attr.normal * mat3(WorldToObject3x4()));
    const vec3 p = hitWorldPosition();
    vec3 color = shade(m.albedo.xyz, n, p, payload.recursionDepth);
    const float reflectance = m.albedo.w;
    if (reflectance > 0.0) {
        const vec3 r = reflect(WorldRayDirection(), n);
        color += reflectance * traceRadiance(secondaryRay(p, n, r, kTMax), payload.recursionDepth).xyz;
    }
    payload.color = vec4(color, 1.0);
}
