// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/JuliaSets.hlsli, ClosestHit_Julia (L278-335).
#version 460
#extension GL_GOOGLE_include_directive : require
#define PROCEDURAY_RCHIT
#define PROCEDURAY_PROCEDURAL_ROOT_ARGUMENTS
#include "proceduray/helpers.glsl"
#include "proceduray/julia_sets.glsl"

layout(location = PROCEDURAY_INCOMING_RADIANCE_PAYLOAD_LOCATION) rayPayloadInEXT RayPayload rayPayload;
hitAttributeEXT ProceduralPrimitiveAttributes attr;

void main() // [shader("closesthit")] void ClosestHit_Julia(inout RayPayload rayPayload, in ProceduralPrimitiveAttributes attr)
{
    // DEBUG
    if (g_sceneCB.debugFlag != 0)
    {
        rayPayload.color = vec4(1.f, 0.f, 0.0f, 0.f);
        return;
    }

    // Shadow component.
    // Trace a shadow ray.
    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = Ray(hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition));
    bool shadowRayHit = false;//TraceShadowRayAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    vec3 pos = ObjectRayOrigin() + RayTCurrent() * ObjectRayDirection();
    vec3 dir = WorldRayDirection();

    vec4 albedo = vec4(3.5*colorSurface(pos, attr.color.xy), 1.f);

    if (rayPayload.recursionDepth == MAX_RAY_RECURSION_DEPTH - 1u)
    {
       albedo += 1.65 * step(0.0, abs(pos.y));
    }

    // Reflected component.
    vec4 reflectedColor = vec4(0, 0, 0, 0);

    float reflecCoef = 0.1;

    if (reflecCoef > 0.001)
    {
        // Trace a reflection ray.
        Ray reflectionRay = Ray(hitPosition, reflect(WorldRayDirection(), attr.normal));
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);

        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), attr.normal, albedo.xyz);
        reflectedColor = reflecCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    float diffuseCoef = 0.6;
    float specularCoef = 0.08;
    float specularPower = 0.2;
    // Calculate final color.
    vec4 phongColor = CalculatePhongLighting(albedo, attr.normal, shadowRayHit, diffuseCoef, specularCoef, specularPower);
    vec4 color = phongColor + reflectedColor;

    color += rayPayload.color;

    rayPayload.color = color;
}
