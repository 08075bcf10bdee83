// Ports MyClosestHitShader_AABB of Raytracing.hlsl (microsoft/DirectX-Graphics-Samples@357ade6e, Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/Raytracing.hlsl).
// Closest hit of the three radiance AABB hit groups (local root signature "AABB": l_materialCB at record offset 0,
// l_aabbCB at 48). Payload RayPayload; attributes ProceduralPrimitiveAttributes; traces RayPayload (location 0) and
// ShadowRayPayload (location 1).
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_CLOSEST_HIT
#define LOCAL_ROOT_SIGNATURE_AABB
#include "d3d12-procedural-geometry/Raytracing.glsl"

rayPayloadInEXT RayPayload rayPayload;
hitAttributeEXT ProceduralPrimitiveAttributes attr;

// [shader("closesthit")]
// void MyClosestHitShader_AABB(inout RayPayload rayPayload, in ProceduralPrimitiveAttributes attr)
void main()
{
    // PERFORMANCE TIP: it is recommended to minimize values carry over across TraceRay() calls.
    // Therefore, in cases like retrieving HitWorldPosition(), it is recomputed every time.

    // Shadow component.
    // Trace a shadow ray.
    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = { hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition) };
    bool shadowRayHit = TraceShadowRayAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    // Reflected component.
    vec4 reflectedColor = vec4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        // Trace a reflection ray.
        Ray reflectionRay = { HitWorldPosition(), reflect(WorldRayDirection(), attr.normal) };
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);

        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), attr.normal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    // Calculate final color.
    vec4 phongColor = CalculatePhongLighting(l_materialCB.albedo, attr.normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = phongColor + reflectedColor;

    // Apply visibility falloff.
    float t = RayTCurrent();
    color = lerp(color, BackgroundColor, 1.0 - exp(-0.000002*t*t*t));

    rayPayload.color = color;
}
