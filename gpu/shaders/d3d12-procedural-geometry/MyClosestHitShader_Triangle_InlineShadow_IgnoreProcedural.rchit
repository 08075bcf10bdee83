// Lesson variant MyClosestHitShader_Triangle_InlineShadow_IgnoreProcedural of refray's d3d12 library (InlineVariant::IgnoreProcedural,
// procedural/d3d12/d3d12_shaders.cpp): MyClosestHitShader_Triangle_InlineShadow except that its Proceed loop never intersects a procedural candidate, so the procedural shapes cast no shadow (scenes/lessons/inline-procedural-never-intersected.json).
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#define INLINE_VARIANT_IGNORE_PROCEDURAL
#include "d3d12-procedural-geometry/InlineShadowClosestHit_Triangle.glsl"
