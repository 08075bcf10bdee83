// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Triangles.hlsli, ClosestHit_Triangle (L4-87).
// SECTIONALCURVATURE is not defined in the HLSL; that block is not ported.
#version 460
#extension GL_GOOGLE_include_directive : require
#define PROCEDURAY_RCHIT
#define PROCEDURAY_TRIANGLE_ROOT_ARGUMENTS
#include "proceduray/helpers.glsl"

layout(location = PROCEDURAY_INCOMING_RADIANCE_PAYLOAD_LOCATION) rayPayloadInEXT RayPayload rayPayload;
// BuiltInTriangleIntersectionAttributes attr: the barycentrics, which the HLSL never reads.
hitAttributeEXT vec2 attr;

void main() // [shader("closesthit")] void ClosestHit_Triangle(inout RayPayload rayPayload, in BuiltInTriangleIntersectionAttributes attr)
{
    // DEBUG
    if (g_sceneCB.debugFlag != 0)
    {
        rayPayload.color = vec4(0.f, 0.f, 1.0f, 0.f);
        return;
    }

    // Get the base index of the triangle's first 16 bit index.
    uint indexSizeInBytes = 2;
    uint indicesPerTriangle = 3;
    uint triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    uint baseIndex = gl_PrimitiveID * triangleIndexStride;

    // Load up three 16 bit indices for the triangle.
    const uvec3 indices = Load3x16BitIndices(baseIndex);

    // Retrieve corresponding vertex normals for the triangle vertices.
    vec3 triangleNormal = /*normalize(grad(HitWorldPosition()));*/-g_vertices(indices[0]).normal;


    // PERFORMANCE TIP: it is recommended to avoid values carry over across TraceRay() calls.
    // Therefore, in cases like retrieving HitWorldPosition(), it is recomputed every time.

    // Shadow component.
    // Trace a shadow ray.
    vec3 hitPosition = HitWorldPosition();
    Ray shadowRay = Ray(hitPosition, normalize(g_sceneCB.lightPosition.xyz - hitPosition));
    bool shadowRayHit = TraceShadowRayAndReportIfHit(shadowRay, rayPayload.recursionDepth);

    // Reflected component.
    vec4 reflectedColor = vec4(0, 0, 0, 0);

    if (l_materialCB.reflectanceCoef > 0.001 )
    {
        // Trace a reflection ray.
        Ray reflectionRay = Ray(HitWorldPosition(), reflect(WorldRayDirection(), triangleNormal));
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);

        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), triangleNormal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    // Calculate final color.
    vec4 phongColor = CalculatePhongLighting(l_materialCB.albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef, l_materialCB.specularPower);
    vec4 color = phongColor + reflectedColor;

    color += rayPayload.color;

    // Apply visibility falloff.
    rayPayload.dist += RayTCurrent();
    float t = rayPayload.dist;

    rayPayload.color = color;
}
