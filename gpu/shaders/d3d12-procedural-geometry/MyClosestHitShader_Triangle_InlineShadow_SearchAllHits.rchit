// Lesson variant MyClosestHitShader_Triangle_InlineShadow_SearchAllHits of refray's d3d12 library (InlineVariant::SearchAllHits,
// procedural/d3d12/d3d12_shaders.cpp): MyClosestHitShader_Triangle_InlineShadow except that its shadow query lacks RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH and searches every hit (scenes/lessons/accept-first-hit-for-shadows.json).
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#define INLINE_VARIANT_SEARCH_ALL_HITS
#include "d3d12-procedural-geometry/InlineShadowClosestHit_Triangle.glsl"
