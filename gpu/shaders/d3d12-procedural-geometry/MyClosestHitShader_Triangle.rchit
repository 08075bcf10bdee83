// Ports MyClosestHitShader_Triangle of Raytracing.hlsl (microsoft/DirectX-Graphics-Samples@357ade6e, Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/Raytracing.hlsl).
// Closest hit of MyHitGroup_Triangle (local root signature "Triangle": l_materialCB at record offset 0).
// Payload RayPayload; traces RayPayload (location 0) and ShadowRayPayload (location 1).
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_CLOSEST_HIT
#define LOCAL_ROOT_SIGNATURE_TRIANGLE
#include "d3d12-procedural-geometry/Raytracing.glsl"

rayPayloadInEXT RayPayload rayPayload;

// BuiltInTriangleIntersectionAttributes (unused, as in the HLSL).
hitAttributeEXT vec2 barycentrics;

//***************************************************************************
//******************------ Closest hit shaders -------***********************
//***************************************************************************

// [shader("closesthit")]
// void MyClosestHitShader_Triangle(inout RayPayload rayPayload, in BuiltInTriangleIntersectionAttributes attr)
void main()
{
    // Get the base index of the triangle's first 16 bit index.
    uint indexSizeInBytes = 2;
    uint indicesPerTriangle = 3;
    uint triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    uint baseIndex = PrimitiveIndex() * triangleIndexStride;

    // Load up three 16 bit indices for the triangle.
    const uvec3 indices = Load3x16BitIndices(baseIndex);

    // Retrieve corresponding vertex normals for the triangle vertices.
    vec3 triangleNormal = g_vertices(indices[0]).normal; // PORT: g_vertices[i] is g_vertices(i) (Raytracing.glsl)

    // PERFORMANCE TIP: it is recommended to avoid values carry over across TraceRay() calls.
    // Therefore, in cases like retrieving HitWorldPosition(), it is recomputed every time.

    // Shadow component.
    // Trace a shadow ray.
    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = { hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition) };
    bool shadowRayHit = TraceShadowRayAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    float checkers = AnalyticalCheckersTexture(HitWorldPosition(), triangleNormal, g_sceneCB.cameraPosition.xyz, g_sceneCB.projectionToWorld);

    // Reflected component.
    vec4 reflectedColor = vec4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001 )
    {
        // Trace a reflection ray.
        Ray reflectionRay = { HitWorldPosition(), reflect(WorldRayDirection(), triangleNormal) };
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);

        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), triangleNormal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    // Calculate final color.
    vec4 phongColor = CalculatePhongLighting(l_materialCB.albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = checkers * (phongColor + reflectedColor);

    // Apply visibility falloff.
    float t = RayTCurrent();
    color = lerp(color, BackgroundColor, 1.0 - exp(-0.000002*t*t*t));

    rayPayload.color = color;
}
