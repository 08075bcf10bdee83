// Ports the export PT_Miss of refray's C++ procedural/pathtracer/pathtracer_shaders.cpp (no HLSL original).
// Miss shader of the radiance ray (ray type 0): the background radiance, and a negative hitT that says "missed".
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_MISS
#include "dxr-path-tracer/pathtracer.glsl"

rayPayloadInEXT RadiancePayload payload;

void main() {
    payload.hitT = -1.0;
    payload.emission = g_constants.backgroundColor.xyz;
}
