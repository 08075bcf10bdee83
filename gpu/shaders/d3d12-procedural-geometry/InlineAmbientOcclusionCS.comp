// Ports InlineAmbientOcclusionCS of refray's scenes/inline/InlineAmbientOcclusion.hlsl (written for refray over
// microsoft/DirectX-Graphics-Samples@357ade6e, D3D12RaytracingProceduralGeometry); its functions are in
// InlineAmbientOcclusion.glsl. The compute shader of scenes/inline-ambient-occlusion.json: ambient occlusion traced
// inline, one thread per pixel. Dispatch: ceil(width / 8) x ceil(height / 8) x 1 groups of 8 x 8 x 1 threads;
// threads past the render target's edge return.
//
// Compiled twice (gpu/CMakeLists.txt): InlineAmbientOcclusionCS.comp.spv renders; InlineAmbientOcclusionCS.aov.comp.spv
// (REFRAY_AOV_FIRST_QUERY) also records each thread's primary query hit for refray's index maps
// (common/d3d12_ray_query.glsl).
#version 460
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_spirv_intrinsics : require
#extension GL_GOOGLE_include_directive : require

// [numthreads(8, 8, 1)]
// PORT: declared before the includes, which may read gl_WorkGroupSize (REFRAY_AOV_FIRST_QUERY).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#define DXR_STAGE_COMPUTE
#include "d3d12-procedural-geometry/InlineAmbientOcclusion.glsl"

// void InlineAmbientOcclusionCS(uint3 dispatchThreadID : SV_DispatchThreadID)
void main()
{
    const uvec3 dispatchThreadID = gl_GlobalInvocationID;
    // PORT: g_renderTarget.GetDimensions(width, height) is imageSize.
    const uint width = uint(imageSize(g_renderTarget).x);
    const uint height = uint(imageSize(g_renderTarget).y);
    if (dispatchThreadID.x >= width || dispatchThreadID.y >= height)
    {
        return;
    }

    vec3 rayDir;
    vec3 origin;
    GenerateCameraRay(dispatchThreadID.xy, uvec2(width, height), origin, rayDir);  // the sample's, with the thread's pixel

    vec3 hitPosition, normal;
    vec4 color = BackgroundColor;
    if (TracePrimaryInline(origin, rayDir, hitPosition, normal))
    {
        uint seed = Hash(dispatchThreadID.x ^ Hash(dispatchThreadID.y));
        uint escaped = 0u;
        for (uint i = 0u; i < AO_RAY_COUNT; ++i)
        {
            float u1 = UnitFloat(Hash(seed ^ (2u * i)));
            float u2 = UnitFloat(Hash(seed ^ (2u * i + 1u)));
            vec3 direction = CosineHemisphereDirection(normal, u1, u2);
            if (!TraceOcclusionInline(hitPosition + AO_ORIGIN_OFFSET * normal, direction))
            {
                escaped++;
            }
        }
        float ao = float(escaped) / float(AO_RAY_COUNT);
        color = vec4(ao, ao, ao, 1);
    }
    imageStore(g_renderTarget, ivec2(dispatchThreadID.xy), color);  // g_renderTarget[dispatchThreadID.xy] = color
}
