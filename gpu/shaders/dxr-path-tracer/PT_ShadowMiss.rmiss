// Ports the export PT_ShadowMiss of refray's C++ procedural/pathtracer/pathtracer_shaders.cpp (no HLSL original).
// Miss shader of the shadow ray (ray type 1): nothing lies between the two points. A hit runs no shader (the ray
// skips closest hits and PT_ShadowHitGroup has none), which leaves `visible` 0.
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_MISS
#include "dxr-path-tracer/pathtracer.glsl"

rayPayloadInEXT ShadowPayload payload;

void main() { payload.visible = 1u; }
