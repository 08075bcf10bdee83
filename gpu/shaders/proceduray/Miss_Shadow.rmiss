// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Raytracing.hlsl, Miss_Shadow (L170-175).
#version 460
#extension GL_GOOGLE_include_directive : require
#define PROCEDURAY_RMISS
#include "proceduray/shader_compat.glsl"

layout(location = PROCEDURAY_INCOMING_SHADOW_PAYLOAD_LOCATION) rayPayloadInEXT ShadowRayPayload rayPayload;

// Raytracing.hlsl L26: static float gStep = 4.;
const float gStep = 4.;

void main() // [shader("miss")] void Miss_Shadow(inout ShadowRayPayload rayPayload)
{
   rayPayload.dist += gStep;
   rayPayload.hit = false;
}
