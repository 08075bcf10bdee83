// Ports MyMissShader_ShadowRay of Raytracing.hlsl (microsoft/DirectX-Graphics-Samples@357ade6e, Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/Raytracing.hlsl).
// Miss shader of shadow rays (miss index 1); payload ShadowRayPayload.
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_MISS
#include "d3d12-procedural-geometry/Raytracing.glsl"

rayPayloadInEXT ShadowRayPayload rayPayload;

void main() // [shader("miss")] void MyMissShader_ShadowRay(inout ShadowRayPayload rayPayload)
{
    rayPayload.hit = 0u; // PORT: false (the payload's bool is a uint)
}
