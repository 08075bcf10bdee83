// Ports MyClosestHitShader_AABB_InlineShadow of refray's scenes/inline/InlineShadows.hlsl (written for refray:
// microsoft/DirectX-Graphics-Samples@357ade6e's MyClosestHitShader_AABB, Raytracing.hlsl, with its shadow ray traced
// inline, TraceShadowRayInlineAndReportIfHit in InlineShadows.glsl).
// Closest hit of the three radiance AABB hit groups of scenes/d3d12-procedural-geometry-inline.json (local root
// signature "AABB": l_materialCB at record offset 0, l_aabbCB at 48). Payload RayPayload; attributes
// ProceduralPrimitiveAttributes; traces RayPayload (location 0) with TraceRay and its shadow ray with a ray query.
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#include "d3d12-procedural-geometry/InlineShadowClosestHit_AABB.glsl"
