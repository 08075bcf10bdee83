// Ports the export Miss_Shadow of refray's C++ procedural/builtin/builtin_shaders.cpp (no HLSL original).
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_MISS
#include "builtin/builtin.glsl"

rayPayloadInEXT ShadowPayload payload;

void main() { payload.hit = 0u; }
