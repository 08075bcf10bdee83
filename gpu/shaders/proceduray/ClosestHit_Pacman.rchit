// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Pacman.hlsli, ClosestHit_Pacman (L32-76).
#version 460
#extension GL_GOOGLE_include_directive : require
#define PROCEDURAY_RCHIT
#define PROCEDURAY_PROCEDURAL_ROOT_ARGUMENTS
#include "proceduray/helpers.glsl"

layout(location = PROCEDURAY_INCOMING_RADIANCE_PAYLOAD_LOCATION) rayPayloadInEXT RayPayload rayPayload;
hitAttributeEXT ProceduralPrimitiveAttributes attr;

void main() // [shader("closesthit")] void ClosestHit_Pacman(inout RayPayload rayPayload, in ProceduralPrimitiveAttributes attr)
{
    // DEBUG
    if (gl_HitKindEXT == 1)
    {
        rayPayload.color = vec4(0.f, 0.f, 1.f, 0.f);
        return;
    }

    // PERFORMANCE TIP: it is recommended to minimize values carry over across TraceRay() calls.
    // Therefore, in cases like retrieving HitWorldPosition(), it is recomputed every time.

    // Shadow component.
    // Trace a shadow ray.
    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = Ray(hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition));
    bool shadowRayHit = TraceShadowRayAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    // Reflected component.
    vec4 reflectedColor = vec4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        // Trace a reflection ray.
        Ray reflectionRay = Ray(HitWorldPosition(), reflect(WorldRayDirection(), attr.normal));
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);

        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), attr.normal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    // Calculate final color.
    vec4 phongColor = CalculatePhongLighting(l_materialCB.albedo, attr.normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = attr.color * (phongColor + reflectedColor);

    color += rayPayload.color;

    // Apply visibility falloff.
    rayPayload.dist += RayTCurrent();
    float t = rayPayload.dist;

    rayPayload.color = color;
}
