// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Raytracing.hlsl, Miss (L93-168; the
// RAYTRACING branch, NONLINEAR_RAYTRACING is not defined).
#version 460
#extension GL_GOOGLE_include_directive : require
#define PROCEDURAY_RMISS
#include "proceduray/shader_compat.glsl"

layout(location = PROCEDURAY_INCOMING_RADIANCE_PAYLOAD_LOCATION) rayPayloadInEXT RayPayload rayPayload;

//***************************************************************************
//**********************------ Miss shaders -------**************************
//***************************************************************************

void main() // [shader("miss")] void Miss(inout RayPayload rayPayload)
{
    vec4 backgroundColor = vec4(BackgroundColor);
    rayPayload.color = backgroundColor;
    rayPayload.hit = false;
}
