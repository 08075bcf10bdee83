// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Mandelbulb.hlsli, ClosestHit_Mandelbulb
// (L145-222).
#version 460
#extension GL_GOOGLE_include_directive : require
#define PROCEDURAY_RCHIT
#define PROCEDURAY_PROCEDURAL_ROOT_ARGUMENTS
#include "proceduray/helpers.glsl"

layout(location = PROCEDURAY_INCOMING_RADIANCE_PAYLOAD_LOCATION) rayPayloadInEXT RayPayload rayPayload;
hitAttributeEXT ProceduralPrimitiveAttributes attr;

// PORT: HLSL clamp(x, 0.0, 1.0) is hlsl_clamp (NaN -> 0, as DXIL's FMax/FMin give; H7); pow is hlsl_pow (DXC's exp2(y*log2(x))).
void main() // [shader("closesthit")] void ClosestHit_Mandelbulb(inout RayPayload rayPayload, in ProceduralPrimitiveAttributes attr)
{
    if (gl_HitKindEXT == 1)
    {
        rayPayload.color = vec4(0.f, 1.f, 0.f, 0.f);
        return;
    }

    // color
    vec3 col = vec3(0.01, 0.01, 0.01);
    col = mix( col, vec3(0.10,0.20,0.30), hlsl_clamp(attr.color.y,0.0,1.0) );
    col = mix( col, vec3(0.02,0.10,0.30), hlsl_clamp(attr.color.z*attr.color.z,0.0,1.0) );
    col = mix( col, vec3(0.30,0.10,0.02), hlsl_clamp(hlsl_pow(attr.color.w,6.0),0.0,1.0) );
    col *= 0.5;
    //col = float3(0.1);

    // lighting terms
    vec3 light1 = vec3(0.577, 0.577, -0.577);
    vec3 light2 = vec3(-0.707, 0.000,  0.707);

    vec3 pos = HitWorldPosition();
    vec3 nor = attr.normal;
    vec3 hal = normalize( light1-WorldRayDirection());
    vec3 ref = reflect( WorldRayDirection(), nor );
    float occ = hlsl_clamp(0.05*log(attr.color.x),0.0,1.0);
    float fac = hlsl_clamp(1.0+dot(WorldRayDirection(),nor),0.0,1.0);

    // sun
    float sha1 = 1.f;//softshadow( pos+0.001*nor, light1, 32.0 );
    float dif1 = hlsl_clamp( dot( light1, nor ), 0.0, 1.0 )*sha1;
    float spe1 = hlsl_pow( hlsl_clamp(dot(nor,hal),0.0,1.0), 32.0 )*dif1*(0.04+0.96*hlsl_pow(hlsl_clamp(1.0-dot(hal,light1),0.0,1.0),5.0));
    // bounce
    float dif2 = hlsl_clamp( 0.5 + 0.5*dot( light2, nor ), 0.0, 1.0 )*occ;
    // sky
    float dif3 = (0.7+0.3*nor.y)*(0.2+0.8*occ);

    vec3 lin = vec3(0.0, 0.0, 0.0);
         lin += 7.0*vec3(1.50,1.10,0.70)*dif1;
         lin += 4.0*vec3(0.25,0.20,0.15)*dif2;
         lin += 1.5*vec3(0.10,0.20,0.30)*dif3;
         lin += 2.5*vec3(0.35,0.30,0.25)*(0.05+0.95*occ); // ambient
         lin += 4.0*fac*occ;                          // fake SSS
    col *= lin;
    col = hlsl_pow( col, vec3(0.7,0.9,1.0) );                  // fake SSS
    col += spe1*15.0;

    // gamma
    col = sqrt( col );

    vec4 color = vec4(col, 1.f);

    // Reflected component.
    vec4 reflectedColor = vec4(0, 0, 0, 0);
    if (l_materialCB.reflectanceCoef > 0.001)
    {
        // Trace a reflection ray.
        Ray reflectionRay = Ray(pos, ref);
        vec4 reflectionColor = TraceRadianceRay(reflectionRay, rayPayload.recursionDepth);

        vec3 fresnelR = FresnelReflectanceSchlick(WorldRayDirection(), attr.normal, l_materialCB.albedo.xyz);
        reflectedColor = l_materialCB.reflectanceCoef * vec4(fresnelR, 1) * reflectionColor;
    }

    // Calculate final color.
    color = color + reflectedColor;
    color += rayPayload.color;

    // Apply visibility falloff.
    rayPayload.dist += RayTCurrent();

    rayPayload.color = color;
}
