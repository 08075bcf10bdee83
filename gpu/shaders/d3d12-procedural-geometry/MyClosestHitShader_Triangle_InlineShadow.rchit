// Ports MyClosestHitShader_Triangle_InlineShadow of refray's scenes/inline/InlineShadows.hlsl (written for refray:
// microsoft/DirectX-Graphics-Samples@357ade6e's MyClosestHitShader_Triangle, Raytracing.hlsl, with its shadow ray
// traced inline, TraceShadowRayInlineAndReportIfHit in InlineShadows.glsl).
// Closest hit of MyHitGroup_Triangle in scenes/d3d12-procedural-geometry-inline.json (local root signature
// "Triangle": l_materialCB at record offset 0). Payload RayPayload; traces RayPayload (location 0) with TraceRay and
// its shadow ray with a ray query.
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#include "d3d12-procedural-geometry/InlineShadowClosestHit_Triangle.glsl"
