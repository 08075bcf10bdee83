// Ports the export ClosestHit_Plane of refray's C++ procedural/builtin/builtin_shaders.cpp (no HLSL original).
// Closest hit of HitGroup_Plane (triangles; local root signature "Material").
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_CLOSEST_HIT
#include "builtin/builtin.glsl"

rayPayloadInEXT RadiancePayload payload;
hitAttributeEXT vec2 barycentrics;  // BuiltInTriangleIntersectionAttributes (unused)

void main() {
    const vec3 p = hitWorldPosition();
    payload.color = vec4(shade(checkerAlbedo(p, m.albedo.xyz), vec3(0.0, 1.0, 0.0), p, payload.recursionDepth), 1.0);
}
