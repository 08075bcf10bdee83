// The body of MyClosestHitShader_Triangle_InlineShadow.rchit and of its lesson variants (the .rchit files that
// include this after defining INLINE_VARIANT_*): ports MyClosestHitShader_Triangle_InlineShadow of scenes/inline/InlineShadows.hlsl.
#define DXR_STAGE_CLOSEST_HIT
#define LOCAL_ROOT_SIGNATURE_TRIANGLE
#include "d3d12-procedural-geometry/InlineShadows.glsl"

rayPayloadInEXT RayPayload rayPayload;

// BuiltInTriangleIntersectionAttributes (unused, as in the HLSL).
hitAttributeEXT vec2 barycentrics;

// MyClosestHitShader_Triangle with TraceShadowRayInlineAndReportIfHit; the rest of the body is the sample's.
// [shader("closesthit")]
// void MyClosestHitShader_Triangle_InlineShadow(inout RayPayload rayPayload, in BuiltInTriangleIntersectionAttributes attr)
void main()
{
    uint indexSizeInBytes = 2;
    uint indicesPerTriangle = 3;
    uint triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    uint baseIndex = PrimitiveIndex() * triangleIndexStride;
    const uvec3 indices = Load3x16BitIndices(baseIndex); // PORT: g_indices is global (Raytracing.glsl)
    vec3 triangleNormal = g_vertices(indices[0]).normal; // PORT: g_vertices[i] is g_vertices(i) (Raytracing.glsl)

    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = { hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition) };
    bool shadowRayHit = TraceShadowRayInlineAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    float checkers = AnalyticalCheckersTexture(HitWorldPosition(), triangleNormal, g_sceneCB.cameraPosition.xyz, g_sceneCB.projectionToWorld);

    vec4 reflectedColor = vec4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        Ray reflectionRay = { HitWorldPosition(), reflect(WorldRayDirection(), triangleNormal) };
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);
        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), triangleNormal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    vec4 phongColor = CalculatePhongLighting(l_materialCB.albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = checkers * (phongColor + reflectedColor);

    // The closest hit's own RayTCurrent() (gl_RayTmaxEXT), not the shadow query's.
    float t = RayTCurrent();
    color = lerp(color, BackgroundColor, 1.0 - exp(-0.000002*t*t*t));
    rayPayload.color = color;
}
