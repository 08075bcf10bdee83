// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Helpers.hlsli (the RAYTRACING paths; the
// NONLINEAR_RAYTRACING branches are compiled out in the HLSL and not ported).
#ifndef PROCEDURAY_HELPERS_GLSL
#define PROCEDURAY_HELPERS_GLSL

#include "proceduray/raytracing_shader_helper.glsl"

//***************************************************************************
//****************------ Utility functions -------***************************
//***************************************************************************

#if defined(PROCEDURAY_RCHIT)
// Diffuse lighting calculation.
float CalculateDiffuseCoefficient(in vec3 hitPosition, in vec3 incidentLightRay, in vec3 normal)
{
    float fNDotL = saturate(dot(-incidentLightRay, normal));
    return fNDotL;
}

// Phong lighting specular component
// PORT: the HLSL returns float4 from a scalar pow (a broadcast); the caller multiplies by float4(1,1,1,1) anyway.
vec4 CalculateSpecularCoefficient(in vec3 hitPosition, in vec3 incidentLightRay, in vec3 normal, in float specularPower)
{
    vec3 reflectedLightRay = normalize(reflect(incidentLightRay, normal));
    // PORT: pow is hlsl_pow, DXC's exp2(y*log2(x)).
    return vec4(hlsl_pow(saturate(dot(reflectedLightRay, normalize(-WorldRayDirection()))), specularPower));
}

// Phong lighting model = ambient + diffuse + specular components.
// PORT: GLSL has no default arguments (HLSL: diffuseCoef = 1.0, specularCoef = 1.0, specularPower = 50); every
// caller passes all of them.
vec4 CalculatePhongLighting(in vec4 albedo, in vec3 normal, in bool isInShadow, in float diffuseCoef, in float specularCoef, in float specularPower)
{
    vec3 hitPosition = HitWorldPosition();
    vec3 lightPosition = g_sceneCB.lightPosition.xyz;
    float shadowFactor = isInShadow ? InShadowRadiance : 1.0;
    vec3 incidentLightRay = normalize(hitPosition - lightPosition);

    // Diffuse component.
    vec4 lightDiffuseColor = g_sceneCB.lightDiffuseColor;
    float Kd = CalculateDiffuseCoefficient(hitPosition, incidentLightRay, normal);
    vec4 diffuseColor = shadowFactor * diffuseCoef * Kd * lightDiffuseColor * albedo;

    // Specular component.
    vec4 specularColor = vec4(0, 0, 0, 0);
    if (!isInShadow)
    {
        vec4 lightSpecularColor = vec4(1, 1, 1, 1);
        vec4 Ks = CalculateSpecularCoefficient(hitPosition, incidentLightRay, normal, specularPower);
        specularColor = specularCoef * Ks * lightSpecularColor;
    }

    // Ambient component.
    // Fake AO: Darken faces with normal facing downwards/away from the sky a little bit.
    vec4 ambientColor = g_sceneCB.lightAmbientColor;
    vec4 ambientColorMin = g_sceneCB.lightAmbientColor - 0.1;
    vec4 ambientColorMax = g_sceneCB.lightAmbientColor;
    float a = 1 - saturate(dot(normal, vec3(0, -1, 0)));
    ambientColor = albedo * mix(ambientColorMin, ambientColorMax, a);

    return ambientColor + diffuseColor + specularColor;
}
#endif

//***************************************************************************
//*****------ TraceRay wrappers for radiance and shadow rays. -------********
//***************************************************************************

#if defined(PROCEDURAY_RGEN) || defined(PROCEDURAY_RCHIT)
// Trace a radiance ray into the scene and returns a shaded color.
// PORT: HLSL's optional `float4 color = 0` argument is never passed by a caller; it is the constant vec4(0) here.
// PORT: the HLSL's local payload `rayPayload` is the global `tracedRayPayload` (location 0), since GLSL cannot
// trace with a local and a closest-hit shader already names its incoming payload `rayPayload`.
vec4 TraceRadianceRay(in Ray ray, in uint currentRayRecursionDepth)
{
    const vec4 color = vec4(0.f, 0.f, 0.f, 0.f);
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH)
    {
        return vec4(0, 0, 0, 0);
    }
    // Set the ray's extents.
    vec3 rayDesc_Origin = ray.origin;
    vec3 rayDesc_Direction = ray.direction;
    // Set TMin to a zero value to avoid aliasing artifacts along contact areas.
    // Note: make sure to enable face culling so as to avoid surface face fighting.
    float rayDesc_TMin = 0;
    float rayDesc_TMax = 10000;
    tracedRayPayload = RayPayload(color, currentRayRecursionDepth + 1u, 0.f, 0, false);
    traceRayEXT(g_scene,
        RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
        TraceRayArguments_Radiance_InstanceMask,       // PORT: TraceRayParameters_InstanceMask
        TraceRayArguments_Radiance_RayContribution,    // PORT: TraceRayParameters_HitGroup_Offset[RayType_Radiance]
        TraceRayArguments_Radiance_Multiplier,         // PORT: TraceRayParameters_HitGroup_GeometryStride
        TraceRayArguments_Radiance_MissShaderIndex,    // PORT: TraceRayParameters_MissShader_Offset[RayType_Radiance]
        rayDesc_Origin, rayDesc_TMin, rayDesc_Direction, rayDesc_TMax,
        PROCEDURAY_RADIANCE_PAYLOAD_LOCATION);

    return tracedRayPayload.color;
}
#endif

#if defined(PROCEDURAY_RCHIT)
// Trace a shadow ray and return true if it hits any geometry.
bool TraceShadowRayAndReportIfHit(in Ray ray, in uint currentRayRecursionDepth)
{
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH)
    {
        return false;
    }

    // Set the ray's extents.
    vec3 rayDesc_Origin = ray.origin;
    vec3 rayDesc_Direction = ray.direction;
    // Set TMin to a zero value to avoid aliasing artifcats along contact areas.
    // Note: make sure to enable back-face culling so as to avoid surface face fighting.
    float rayDesc_TMin = 0;
    float rayDesc_TMax = 10000;

    // Initialize shadow ray payload.
    // Set the initial value to true since closest and any hit shaders are skipped.
    // Shadow miss shader, if called, will set it to false.
    shadowPayload = ShadowRayPayload(0.f, true);
    // PORT: RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH = gl_RayFlagsTerminateOnFirstHitEXT, RAY_FLAG_FORCE_OPAQUE =
    // gl_RayFlagsOpaqueEXT, RAY_FLAG_SKIP_CLOSEST_HIT_SHADER = gl_RayFlagsSkipClosestHitShaderEXT (same bits).
    traceRayEXT(g_scene,
        RAY_FLAG_CULL_BACK_FACING_TRIANGLES
        | gl_RayFlagsTerminateOnFirstHitEXT
        | gl_RayFlagsOpaqueEXT                 // ~skip any hit shaders
        | gl_RayFlagsSkipClosestHitShaderEXT,  // ~skip closest hit shaders,
        TraceRayArguments_Shadow_InstanceMask,       // PORT: TraceRayParameters_InstanceMask
        TraceRayArguments_Shadow_RayContribution,    // PORT: TraceRayParameters_HitGroup_Offset[RayType_Shadow]
        TraceRayArguments_Shadow_Multiplier,         // PORT: TraceRayParameters_HitGroup_GeometryStride
        TraceRayArguments_Shadow_MissShaderIndex,    // PORT: TraceRayParameters_MissShader_Offset[RayType_Shadow]
        rayDesc_Origin, rayDesc_TMin, rayDesc_Direction, rayDesc_TMax,
        PROCEDURAY_SHADOW_PAYLOAD_LOCATION);

    return shadowPayload.hit;
}
#endif

#if defined(PROCEDURAY_RINT)
// Get ray in AABB's local space.
Ray GetRayInAABBPrimitiveLocalSpace()
{
    InstanceBuffer attr = g_instanceBuffer[l_aabbCB.instanceIndex];

    // Retrieve a ray origin position and direction in bottom level AS space
    // and transform them into the AABB primitive's local space.
    Ray ray;
    ray.origin = (vec4(WorldRayOrigin(), 1) * attr.localSpaceToBottomLevelAS).xyz;
    ray.direction = WorldRayDirection() * mat3(attr.localSpaceToBottomLevelAS);
    ray.direction = normalize(ray.direction);
    return ray;
}
#endif

#endif // PROCEDURAY_HELPERS_GLSL
