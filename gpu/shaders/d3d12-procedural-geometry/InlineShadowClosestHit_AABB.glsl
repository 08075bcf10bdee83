// The body of MyClosestHitShader_AABB_InlineShadow.rchit and of its lesson variants (the .rchit files that
// include this after defining INLINE_VARIANT_*): ports MyClosestHitShader_AABB_InlineShadow of scenes/inline/InlineShadows.hlsl.
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
