// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/SignedDistancePrimitives.hlsli (opS, opU,
// sdSphere, sdTriPrism, pacMan, isphere, sdCalculateNormal, RaySignedDistancePrimitiveTest: what the MandelJuliaPac
// shaders reach) and ProceduralPrimitivesLibrary.hlsli GetDistanceFromSignedDistancePrimitive (L63-129).
#ifndef PROCEDURAY_SIGNED_DISTANCE_PRIMITIVES_GLSL
#define PROCEDURAY_SIGNED_DISTANCE_PRIMITIVES_GLSL

#include "proceduray/raytracing_shader_helper.glsl"

// Subtract: Obj1 - Obj2
float opS(float d1, float d2)
{
    return max(d1, -d2);
}

// Union: Obj1 + Obj2
float opU(float d1, float d2)
{
    return min(d1, d2);
}

float sdSphere(vec3 p, float s)
{
    return length(p) - s;
}

float sdTriPrism(vec3 p, vec2 h)
{
    vec3 q = abs(p);
    float d1 = q.z - h.y;
    // distance bound (the HLSL's `#if 1` branch)
    float d2 = max(q.x * 0.866025 + p.y * 0.5, -p.y) - h.x * 0.5;
    return length(max(vec2(d1, d2), 0.0)) + min(max(d1, d2), 0.);
}

//by tiago
// PORT: HLSL's default t = 0.5 is never used (the only caller passes the mouth interpolant).
float pacMan(vec3 p, float t /*t must be between 0 and 1*/)
{
    float r1 = float(0.5f); //head radius
    vec2 r2 = vec2(0.45f*t+0.05f*(1.f-t), 0.5f); //mouth radius

    vec3 rot_p = vec3(p.z, p.y, -p.x); //mouth orientation
    rot_p = vec3(rot_p.y, -rot_p.x + 0.5, rot_p.z); //mouth orientation
    float mouth = sdTriPrism(rot_p, r2);

    float eyes = opU(sdSphere(p + vec3(-0.25, 0.365, -0.225), 0.075), sdSphere(p + vec3(0.25, 0.365, -0.225), 0.075));

    return opS(opS(sdSphere(p, r1), mouth), eyes);
}

vec2 isphere( in vec4 sph, in vec3 ro, in vec3 rd )
{
    vec3 oc = ro - sph.xyz;

    float b = dot(oc,rd);
    float c = dot(oc,oc) - sph.w*sph.w;
    float h = b*b - c;

    if( h<0.0 ) return vec2(-1.0, -1.0);

    h = sqrt( h );

    return -b + vec2(-h,h);
}

// ProceduralPrimitivesLibrary.hlsli L63-129.
// Signed distance functions use a shared ray signed distance test.
// The test, instead, calls into this function to retrieve a distance for a primitive.
float GetDistanceFromSignedDistancePrimitive(in vec3 position, in uint signedDistancePrimitive, in float time)
{
    switch (signedDistancePrimitive)
    {
    case SignedDistancePrimitive_IntersectedRoundCube:
        //PacMans
        {

            // mouth animation
            int iAnimMin = 0;
            int iAnimMax = 300;

            // PORT: HLSL `(200.5 * time) % (iAnimMax * 2)` is a float remainder (the int converts to float),
            // truncated to int on assignment.
            int iMax = int(hlsl_fmod(200.5 * time, float(iAnimMax * 2)));
            if (iMax > iAnimMax)
            {
                iMax = 2 * iAnimMax - iMax;
            }
            iMax += iAnimMin;

            float t = float(iMax) / float(iAnimMax);

            return pacMan(position, t);
        }

    default: return 0;
    }
}

vec3 sdCalculateNormal(in vec3 pos, in uint sdPrimitive, in float time)
{
    // PORT: HLSL `float2(1.0, -1.0) * 0.5773 * 0.0001` multiplies in float (DXC): 0.5773f * 0.0001f = 5.77299979e-05.
    // glslang folds 0.5773 * 0.0001 in double (5.77300016e-05, one float ulp more), so the float product is spelled out.
    vec2 e = vec2(1.0, -1.0) * 5.77299979e-05;
    return normalize(
        e.xyy * GetDistanceFromSignedDistancePrimitive(pos + e.xyy, sdPrimitive, time) +
        e.yyx * GetDistanceFromSignedDistancePrimitive(pos + e.yyx, sdPrimitive, time) +
        e.yxy * GetDistanceFromSignedDistancePrimitive(pos + e.yxy, sdPrimitive, time) +
        e.xxx * GetDistanceFromSignedDistancePrimitive(pos + e.xxx, sdPrimitive, time));
}

#if defined(PROCEDURAY_RINT)
// Test ray against a signed distance primitive.
// Ref: https://www.scratchapixel.com/lessons/advanced-rendering/rendering-distance-fields/basic-sphere-tracer
// PORT: no default arguments in GLSL (HLSL: stepScale = 1.0f, time = 1.f); the caller passes both.
bool RaySignedDistancePrimitiveTest(in Ray ray, in uint sdPrimitive, out float thit, out ProceduralPrimitiveAttributes attr, in float stepScale, in float time)
{
    const float threshold = 0.0001;
    float t = RayTMin();
    const uint MaxSteps = 512;

    // Do sphere tracing through the AABB.
    uint i = 0;
    while (i++ < MaxSteps && t <= RayTCurrent())
    {
        vec3 position = ray.origin + t * ray.direction;
        float distance = GetDistanceFromSignedDistancePrimitive(position, sdPrimitive, time);

        // Has the ray intersected the primitive?
        if (distance <= threshold * t)
        {
            vec3 hitSurfaceNormal = sdCalculateNormal(position, sdPrimitive, time);
            if (IsAValidHit(ray, t, hitSurfaceNormal))
            {
                thit = t;
                attr.normal = hitSurfaceNormal;

                if (abs(abs(dot(hitSurfaceNormal, normalize(position))) - 1) > 0.001)
                {
                    attr.color = vec4(0.0f, 0.0f, 0.0f, 1.0f);
                }
                else
                {
                    attr.color = vec4(1.0f, 1.0f, 1.0f, 1.0f);
                }

                return true;
            }
        }

        // Since distance is the minimum distance to the primitive,
        // we can safely jump by that amount without intersecting the primitive.
        // We allow for scaling of steps per primitive type due to any pre-applied
        // transformations that don't preserve true distances.
        t += stepScale * distance;
    }
    return false;
}
#endif

#endif // PROCEDURAY_SIGNED_DISTANCE_PRIMITIVES_GLSL
