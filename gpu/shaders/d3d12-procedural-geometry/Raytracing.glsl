// Ports Raytracing.hlsl of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/Raytracing.hlsl: its resources, utility
// functions and TraceRay wrappers. Each entry point of it is its own file (<Export>.<stage>) that includes this one.
//
// The including file defines its stage (DXR_STAGE_RAYGEN, DXR_STAGE_MISS, DXR_STAGE_CLOSEST_HIT or
// DXR_STAGE_INTERSECTION) and, for hit groups, its local root signature (LOCAL_ROOT_SIGNATURE_TRIANGLE or
// LOCAL_ROOT_SIGNATURE_AABB), and enables GL_EXT_ray_tracing, GL_EXT_scalar_block_layout, GL_EXT_spirv_intrinsics
// and GL_GOOGLE_include_directive.
//
// Bindings (gpu/shaders/CONTRACT.md: set = register space, binding = register + 0 (b) / 100 (t) / 200 (u)):
//   set 0 binding 0    b0  g_sceneCB                 root CBV, SceneConstantBuffer (scalar, row_major; offsets below)
//   set 0 binding 100  t0  g_scene                   root SRV, the TLAS
//   set 0 binding 101  t1  g_indices                 table [4] range 0: ByteAddressBuffer, 16-bit indices
//   set 0 binding 102  t2  g_vertices                table [4] range 1: StructuredBuffer<Vertex>, stride 24
//   set 0 binding 103  t3  g_AABBPrimitiveAttributes root SRV, StructuredBuffer<PrimitiveInstancePerFrameBuffer>, 128
//   set 0 binding 200  u0  g_renderTarget            table [0]: RWTexture2D<float4> (rgba32f image)
// Local root arguments (shaderRecordEXT, byte 0 = first byte after the 32-byte shader identifier):
//   Triangle: offset 0  l_materialCB (b1, 12 root constants, 48 bytes)
//   AABB:     offset 0  l_materialCB (b1, 12 root constants, 48 bytes); offset 48 l_aabbCB (b2, 2 root constants)
#ifndef RAYTRACING_GLSL
#define RAYTRACING_GLSL

#include "common/d3d12_hlsl_intrinsics.glsl"
#include "common/d3d12_dxr_intrinsics.glsl"
#include "d3d12-procedural-geometry/RaytracingHlslCompat.glsl"
#include "d3d12-procedural-geometry/RaytracingShaderHelper.glsl"
#include "d3d12-procedural-geometry/ProceduralPrimitivesLibrary.glsl"

//***************************************************************************
//*****------ Shader resources bound via root signatures -------*************
//***************************************************************************

// Scene wide resources.
//  g_* - bound via a global root signature.
//  l_* - bound via a local root signature.
layout(set = 0, binding = 100) uniform accelerationStructureEXT g_scene;
layout(set = 0, binding = 200, rgba32f) uniform image2D g_renderTarget;
// PORT: ConstantBuffer<SceneConstantBuffer> as a uniform block; the bytes are refray's SceneConstantBuffer (the
// library's sceneConstants generator: 144 bytes, the last 8 padding). projectionToWorld is stored by rows.
layout(set = 0, binding = 0, scalar, row_major) uniform SceneConstantBuffer
{
    layout(offset = 0) mat4 projectionToWorld;
    layout(offset = 64) vec4 cameraPosition;
    layout(offset = 80) vec4 lightPosition;
    layout(offset = 96) vec4 lightAmbientColor;
    layout(offset = 112) vec4 lightDiffuseColor;
    layout(offset = 128) float reflectance;
    layout(offset = 132) float elapsedTime;                 // Elapsed application time.
} g_sceneCB;

// Triangle resources
// PORT: ByteAddressBuffer as an array of 32-bit words (byte offset / 4).
layout(set = 0, binding = 101, scalar) readonly buffer IndexBuffer { uint g_indices[]; };
// PORT: StructuredBuffer<Vertex> as an array of VertexStorage (float[3] members: stride 24 without the scalar
// layout, which `spirv-val --target-env vulkan1.2` rejects for a vec3 array of stride 24); g_vertices(i) reads one.
struct VertexStorage
{
    float position[3];
    float normal[3];
};
layout(set = 0, binding = 102, scalar) readonly buffer VertexBuffer { VertexStorage g_verticesData[]; };
Vertex g_vertices(uint i)
{
    VertexStorage v = g_verticesData[i];
    return Vertex(vec3(v.position[0], v.position[1], v.position[2]), vec3(v.normal[0], v.normal[1], v.normal[2]));
}

// Procedural geometry resources
layout(set = 0, binding = 103, scalar, row_major) readonly buffer AABBPrimitiveAttributeBuffer
{
    PrimitiveInstancePerFrameBuffer g_AABBPrimitiveAttributes[];
};

#if defined(LOCAL_ROOT_SIGNATURE_TRIANGLE) || defined(LOCAL_ROOT_SIGNATURE_AABB)
// PORT: the local root constants b1 (and b2) as the shader record's bytes after the identifier.
layout(shaderRecordEXT, scalar) buffer LocalRootArguments
{
    layout(offset = 0) PrimitiveConstantBuffer l_materialCB;
#if defined(LOCAL_ROOT_SIGNATURE_AABB)
    layout(offset = 48) PrimitiveInstanceConstantBuffer l_aabbCB;
#endif
};
#endif

// Payloads of the rays this shader traces (TraceRay's `inout payload` is the variable at the location it names).
#if defined(DXR_STAGE_RAYGEN) || defined(DXR_STAGE_CLOSEST_HIT)
layout(location = PAYLOAD_LOCATION_RADIANCE) rayPayloadEXT RayPayload g_radianceRayPayload;
layout(location = PAYLOAD_LOCATION_SHADOW) rayPayloadEXT ShadowRayPayload g_shadowRayPayload;
#endif

// Load three 16 bit indices (RaytracingShaderHelper.hlsli).
// PORT: reads g_indices directly (HLSL passes it as the parameter Indices).
uvec3 Load3x16BitIndices(uint offsetBytes)
{
    uvec3 indices;

    // ByteAdressBuffer loads must be aligned at a 4 byte boundary.
    // Since we need to read three 16 bit indices: { 0, 1, 2 }
    // aligned at a 4 byte boundary as: { 0 1 } { 2 0 } { 1 2 } { 0 1 } ...
    // we will load 8 bytes (~ 4 indices { a b | c d }) to handle two possible index triplet layouts,
    // based on first index's offsetBytes being aligned at the 4 byte boundary or not:
    //  Aligned:     { 0 1 | 2 - }
    //  Not aligned: { - 0 | 1 2 }
    const uint dwordAlignedOffset = offsetBytes & ~3u;
    const uvec2 four16BitIndices = uvec2(g_indices[dwordAlignedOffset / 4u], g_indices[dwordAlignedOffset / 4u + 1u]);

    // Aligned: { 0 1 | 2 - } => retrieve first three 16bit indices
    if (dwordAlignedOffset == offsetBytes)
    {
        indices.x = four16BitIndices.x & 0xffffu;
        indices.y = (four16BitIndices.x >> 16) & 0xffffu;
        indices.z = four16BitIndices.y & 0xffffu;
    }
    else // Not aligned: { - 0 | 1 2 } => retrieve last three 16bit indices
    {
        indices.x = (four16BitIndices.x >> 16) & 0xffffu;
        indices.y = four16BitIndices.y & 0xffffu;
        indices.z = (four16BitIndices.y >> 16) & 0xffffu;
    }

    return indices;
}

//***************************************************************************
//****************------ Utility functions -------***************************
//***************************************************************************

#if defined(DXR_STAGE_CLOSEST_HIT)
// Diffuse lighting calculation.
float CalculateDiffuseCoefficient(in vec3 hitPosition, in vec3 incidentLightRay, in vec3 normal)
{
    float fNDotL = saturate(dot(-incidentLightRay, normal));
    return fNDotL;
}

// Phong lighting specular component
// PORT: HLSL returns the float pow(...) as a float4 (splat); so does this.
vec4 CalculateSpecularCoefficient(in vec3 hitPosition, in vec3 incidentLightRay, in vec3 normal, in float specularPower)
{
    vec3 reflectedLightRay = normalize(reflect(incidentLightRay, normal));
    return vec4(hlsl_pow(saturate(dot(reflectedLightRay, normalize (-WorldRayDirection()))), specularPower));
}


// Phong lighting model = ambient + diffuse + specular components.
// PORT: GLSL has no default arguments (HLSL: diffuseCoef = 1.0, specularCoef = 1.0, specularPower = 50); both
// callers pass all of them.
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
    ambientColor = albedo * lerp(ambientColorMin, ambientColorMax, a);

    return ambientColor + diffuseColor + specularColor;
}
#endif

//***************************************************************************
//*****------ TraceRay wrappers for radiance and shadow rays. -------********
//***************************************************************************

#if defined(DXR_STAGE_RAYGEN) || defined(DXR_STAGE_CLOSEST_HIT)
// Trace a radiance ray into the scene and returns a shaded color.
vec4 TraceRadianceRay(in Ray ray, in uint currentRayRecursionDepth)
{
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH)
    {
        return vec4(0, 0, 0, 0);
    }

    // Set the ray's extents.
    // PORT: RayDesc's fields are traceRayEXT's arguments.
    vec3 rayDescOrigin = ray.origin;
    vec3 rayDescDirection = ray.direction;
    // Set TMin to a zero value to avoid aliasing artifacts along contact areas.
    // Note: make sure to enable face culling so as to avoid surface face fighting.
    float rayDescTMin = 0;
    float rayDescTMax = 10000;
    g_radianceRayPayload = RayPayload(vec4(0, 0, 0, 0), currentRayRecursionDepth + 1);
    traceRayEXT(g_scene,
        RAY_FLAG_CULL_BACK_FACING_TRIANGLES,
        TraceRayArguments_Radiance_InstanceMask,       // PORT: TraceRayParameters_InstanceMask
        TraceRayArguments_Radiance_RayContribution,    // PORT: TraceRayParameters_HitGroup_Offset[RayType_Radiance]
        TraceRayArguments_Radiance_Multiplier,         // PORT: TraceRayParameters_HitGroup_GeometryStride
        TraceRayArguments_Radiance_MissShaderIndex,    // PORT: TraceRayParameters_MissShader_Offset[RayType_Radiance]
        rayDescOrigin, rayDescTMin, rayDescDirection, rayDescTMax, PAYLOAD_LOCATION_RADIANCE);

    return g_radianceRayPayload.color;
}

// Trace a shadow ray and return true if it hits any geometry.
bool TraceShadowRayAndReportIfHit(in Ray ray, in uint currentRayRecursionDepth)
{
    if (currentRayRecursionDepth >= MAX_RAY_RECURSION_DEPTH)
    {
        return false;
    }

    // Set the ray's extents.
    vec3 rayDescOrigin = ray.origin;
    vec3 rayDescDirection = ray.direction;
    // Set TMin to a zero value to avoid aliasing artifcats along contact areas.
    // Note: make sure to enable back-face culling so as to avoid surface face fighting.
    float rayDescTMin = 0;
    float rayDescTMax = 10000;

    // Initialize shadow ray payload.
    // Set the initial value to true since closest and any hit shaders are skipped.
    // Shadow miss shader, if called, will set it to false.
    g_shadowRayPayload = ShadowRayPayload(1u);
    traceRayEXT(g_scene,
        RAY_FLAG_CULL_BACK_FACING_TRIANGLES
        | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH
        | RAY_FLAG_FORCE_OPAQUE             // ~skip any hit shaders
        | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, // ~skip closest hit shaders,
        TraceRayArguments_Shadow_InstanceMask,       // PORT: TraceRayParameters_InstanceMask
        TraceRayArguments_Shadow_RayContribution,    // PORT: TraceRayParameters_HitGroup_Offset[RayType_Shadow]
        TraceRayArguments_Shadow_Multiplier,         // PORT: TraceRayParameters_HitGroup_GeometryStride
        TraceRayArguments_Shadow_MissShaderIndex,    // PORT: TraceRayParameters_MissShader_Offset[RayType_Shadow]
        rayDescOrigin, rayDescTMin, rayDescDirection, rayDescTMax, PAYLOAD_LOCATION_SHADOW);

    return g_shadowRayPayload.hit != 0u;
}
#endif

//***************************************************************************
//*****************------ Intersection shaders-------************************
//***************************************************************************

#if defined(DXR_STAGE_INTERSECTION) && defined(LOCAL_ROOT_SIGNATURE_AABB)
// Get ray in AABB's local space.
Ray GetRayInAABBPrimitiveLocalSpace()
{
    PrimitiveInstancePerFrameBuffer attr = g_AABBPrimitiveAttributes[l_aabbCB.instanceIndex];

    // Retrieve a ray origin position and direction in bottom level AS space
    // and transform them into the AABB primitive's local space.
    // PORT: HLSL mul(rowVector, M) is rowVector * M; (float3x3)M is mat3(M), the upper-left 3x3.
    Ray ray;
    ray.origin = (vec4(ObjectRayOrigin(), 1) * attr.bottomLevelASToLocalSpace).xyz;
    ray.direction = ObjectRayDirection() * mat3(attr.bottomLevelASToLocalSpace);
    return ray;
}
#endif

#endif // RAYTRACING_GLSL
