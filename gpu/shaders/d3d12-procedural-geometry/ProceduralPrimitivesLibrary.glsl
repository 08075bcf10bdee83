// Ports ProceduralPrimitivesLibrary.hlsli of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/ProceduralPrimitivesLibrary.hlsli.
// An interface to call per geometry intersection tests based on as primitive type.
// Needs RaytracingHlslCompat.glsl, the intrinsics files and RaytracingShaderHelper.glsl first. The analytic and
// volumetric tests read RayTMin/RayTCurrent/RayFlags, so they exist in intersection (and hit) stages only, and where
// the includer traces inline and has made those three macros for the query's values (DXR_RAY_EXTENT_OF_QUERY,
// InlineShadows.glsl); the distance function exists everywhere.
#ifndef PROCEDURALPRIMITIVESLIBRARY_GLSL
#define PROCEDURALPRIMITIVESLIBRARY_GLSL

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION) || \
    defined(DXR_RAY_EXTENT_OF_QUERY)
#include "d3d12-procedural-geometry/AnalyticPrimitives.glsl"
#include "d3d12-procedural-geometry/VolumetricPrimitives.glsl"
#endif
#include "d3d12-procedural-geometry/SignedDistancePrimitives.glsl"
#include "d3d12-procedural-geometry/SignedDistanceFractals.glsl"

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION) || \
    defined(DXR_RAY_EXTENT_OF_QUERY)
// Analytic geometry intersection test.
// AABB local space dimensions: <-1,1>.
// PORT: HLSL's enum parameter AnalyticPrimitive::Enum is a uint here.
bool RayAnalyticGeometryIntersectionTest(in Ray ray, in uint analyticPrimitive, inout float thit, inout ProceduralPrimitiveAttributes attr)
{
    vec3 aabb[2] = {
        vec3(-1,-1,-1),
        vec3(1,1,1)
    };
    float tmax;

    switch (analyticPrimitive)
    {
    case AnalyticPrimitive_AABB: return RayAABBIntersectionTest(ray, aabb, thit, attr);
    case AnalyticPrimitive_Spheres: return RaySpheresIntersectionTest(ray, thit, attr);
    default: return false;
    }
}

// Analytic geometry intersection test.
// AABB local space dimensions: <-1,1>.
bool RayVolumetricGeometryIntersectionTest(in Ray ray, in uint volumetricPrimitive, inout float thit, inout ProceduralPrimitiveAttributes attr, in float elapsedTime)
{
    switch (volumetricPrimitive)
    {
    case VolumetricPrimitive_Metaballs: return RayMetaballsIntersectionTest(ray, thit, attr, elapsedTime);
    default: return false;
    }
}
#endif

// Signed distance functions use a shared ray signed distance test.
// The test, instead, calls into this function to retrieve a distance for a primitive.
// AABB local space dimensions: <-1,1>.
// Ref: http://www.iquilezles.org/www/articles/distfunctions/distfunctions.htm
float GetDistanceFromSignedDistancePrimitive(in vec3 position, in uint signedDistancePrimitive)
{
    switch (signedDistancePrimitive)
    {
    case SignedDistancePrimitive_MiniSpheres:
        return opI(sdSphere(opRep(position + 1, vec3(2)/4), 0.65 / 4), sdBox(position, vec3(1)));

    case SignedDistancePrimitive_IntersectedRoundCube:
        return opS(opS(udRoundBox(position, vec3(0.75), 0.2), sdSphere(position, 1.20)), -sdSphere(position, 1.32));

    case SignedDistancePrimitive_SquareTorus:
        return sdTorus82(position, vec2(0.75, 0.15));

    case SignedDistancePrimitive_TwistedTorus:
        return sdTorus(opTwist(position), vec2(0.6, 0.2));

    case SignedDistancePrimitive_Cog:
        return opS( sdTorus82(position, vec2(0.60, 0.3)),
                    sdCylinder(opRep(vec3(atan2(position.z, position.x) / 6.2831,
                                          1,
                                          0.015 + 0.25 * length(position)) + 1,
                                     vec3(0.05, 1, 0.075)),
                               vec2(0.02, 0.8)));

    case SignedDistancePrimitive_Cylinder:
        return opI(sdCylinder(opRep(position + vec3(1, 1, 1), vec3(1, 2, 1)), vec2(0.3, 2)),
                   sdBox(position + vec3(1, 1, 1), vec3(2, 2, 2)));

    case SignedDistancePrimitive_FractalPyramid:
         // Let pyramid have a base at y == -1 of AABB => position + float3(0,1,0)
         // Pyramid: 63.435 degrees at base, height 2
         return sdFractalPyramid(position + vec3(0, 1, 0), vec3(0.894, 0.447, 2.0), 2.0f);

    default: return 0;
    }
}

#endif // PROCEDURALPRIMITIVESLIBRARY_GLSL
