// Ports MyMissShader of Raytracing.hlsl (microsoft/DirectX-Graphics-Samples@357ade6e, Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/Raytracing.hlsl).
// Miss shader of radiance rays (miss index 0); payload RayPayload.
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_MISS
#include "d3d12-procedural-geometry/Raytracing.glsl"

rayPayloadInEXT RayPayload rayPayload;

//***************************************************************************
//**********************------ Miss shaders -------**************************
//***************************************************************************

void main() // [shader("miss")] void MyMissShader(inout RayPayload rayPayload)
{
    vec4 backgroundColor = vec4(BackgroundColor);
    rayPayload.color = backgroundColor;
}
