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

#define DXR_STAGE_CLOSEST_HIT
#define LOCAL_ROOT_SIGNATURE_AABB
#include "d3d12-procedural-geometry/InlineShadows.glsl"

rayPayloadInEXT RayPayload rayPayload;
hitAttributeEXT ProceduralPrimitiveAttributes attr;

// MyClosestHitShader_AABB with TraceShadowRayInlineAndReportIfHit; the rest of the body is the sample's.
// [shader("closesthit")]
// void MyClosestHitShader_AABB_InlineShadow(inout RayPayload rayPayload, in ProceduralPrimitiveAttributes attr)
void main()
{
    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = { hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition) };
    bool shadowRayHit = TraceShadowRayInlineAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    vec4 reflectedColor = vec4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        Ray reflectionRay = { HitWorldPosition(), reflect(WorldRayDirection(), attr.normal) };
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);
        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), attr.normal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    vec4 phongColor = CalculatePhongLighting(l_materialCB.albedo, attr.normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = phongColor + reflectedColor;

    // The closest hit's own RayTCurrent() (gl_RayTmaxEXT), not the shadow query's.
    float t = RayTCurrent();
    color = lerp(color, BackgroundColor, 1.0 - exp(-0.000002*t*t*t));
    rayPayload.color = color;
}
