// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/JuliaSets.hlsli, the helpers (L1-248):
// qSquare, qCube, qLength2, iSphere, jdist, calcNormal, raycast, colorSurface, JuliaDistance. setCamera is dead code
// and not ported.
#ifndef PROCEDURAY_JULIA_SETS_GLSL
#define PROCEDURAY_JULIA_SETS_GLSL

#include "proceduray/raytracing_shader_helper.glsl"

#define kPrecis 0.00025f
#define kc (vec4(-2.f, 6.f, 15.f, -6.f) / 22.0f)

vec3 float3_ctor(float x0)
{
    return vec3(x0, x0, x0);
}

vec4 qSquare_float4(in vec4 q)
{
    return vec4(((((q.x * q.x) - (q.y * q.y)) - (q.z * q.z)) - (q.w * q.w)), ((2.0 * q.x) * q.yzw));
}
vec4 qCube_float4(in vec4 q)
{
    vec4 q2 = (q * q);
    return vec4((q.x * (((q2.x - (3.0 * q2.y)) - (3.0 * q2.z)) - (3.0 * q2.w))), (q.yzw * ((((3.0 * q2.x) - q2.y) - q2.z) - q2.w)));
}
float qLength2_float4(in vec4 q)
{
    return dot(q, q);
}
vec2 iSphere(in vec3 ro, in vec3 rd, in float rad)
{
    float b = dot(ro, rd);
    float c = dot(ro, ro) - (rad * rad);
    float h = (b * b) - c;
    if (h < 0.0)
    {
        return vec2(-1.0, -1.0);
    }
    h = sqrt(h);
    return vec2(-b - h, -b + h);
}
vec2 jdist(in vec3 p, in vec4 c, in int iMax)
{
    vec4 z = vec4(p, 0.0);
    float dz2 = 1.0;
    float m2 = 0.0;
    float n = 0.0;

    for (int i = 0; i < iMax; i++)
    {
        dz2 *= 9.0 * qLength2_float4(qSquare_float4(z));
        z = qCube_float4(z) + c;
        m2 = qLength2_float4(z);
        if (m2 > 256.0)
        {
            break;
        }
        n += 1.0;
    }

    float d = (0.25 * log(m2)) * sqrt((m2 / dz2));
    return vec2(d, n);
}
// PORT: GLSL has no default arguments; the one-argument overload below passes the HLSL's defaults (kc, 200).
vec3 calcNormal(in vec3 pos, in vec4 c, in int iMax)
{
    // PORT: HLSL `float2(1.0f, -1.0f) * 0.5773f * kPrecis` multiplies in float (DXC): 0.5773f * 0.00025f =
    // 0.000144325008. glslang folds it in double (0.000144324993, one float ulp less), so the product is spelled out.
    const vec2 e = vec2(1.0f, -1.0f) * 0.000144325008f;

    return normalize(
        e.xyy * jdist(pos + e.xyy, c, iMax).x +
        e.yyx * jdist(pos + e.yyx, c, iMax).x +
        e.yxy * jdist(pos + e.yxy, c, iMax).x +
        e.xxx * jdist(pos + e.xxx, c, iMax).x
    );
}
vec3 calcNormal(in vec3 pos) { return calcNormal(pos, kc, 200); }

// PORT: GLSL has no default arguments; the two-argument overload below passes the HLSL's defaults (kc, 0.0, 200).
vec2 raycast(in vec3 ro, in vec3 rd, in vec4 c, in float deltaT, in int iMax)
{
    float tmax = 7000.f;
    float tmin = kPrecis;

    float upperPlane = deltaT;

    float tpS = ( upperPlane - ro.y) / rd.y;

    bool isCamAboveUpper = (ro.y > upperPlane);

    if (tpS > 0.0)
    {
        if (isCamAboveUpper)
        {
            tmin = max(tmin, tpS);
        }
        else
        {
            tmax = min(tmax, tpS);
        }
    }
    else
    {
        if (isCamAboveUpper)
        {
            return vec2(-2.0, 0.0);
        }
    }

    float lowerPlane = -1.1;
    float tpF = (lowerPlane - ro.y) / rd.y;

    bool isCamBellowLower = (ro.y < lowerPlane);

    if (tpF > 0.0)
    {
        if (isCamBellowLower)
        {
            tmin = max(tmin, tpF);
        }
        else
        {
            tmax = min(tmax, tpF);
        }
    }
    else
    {
        if (isCamBellowLower)
        {
            return vec2(-2.0, 0.0);
        }
    }

    vec2 bv = iSphere(ro, rd, 1.2);
    if (bv.y < 0.0)
    {
        return vec2(-2.0, 0.0);
    }
    tmin = max(tmin, bv.x);
    tmax = min(tmax, bv.y);
    vec2 res = vec2(-1.0, -1.0);
    float t = tmin;
    float lt = 0.0;
    float lh = 0.0;
    {
        for (int i = 0; i < 1024; i++)
        {
            res = jdist(ro + (rd * t), c, iMax);
            if (res.x < kPrecis)
            {
                break;
            }
            lt = t;
            lh = res.x;
            t += min(res.x, 0.2);
            if (t > tmax)
            {
                break;
            }
        }
    }
    if ((lt > 9.9999997e-05) && (res.x < 0.0))
    {
        t = lt - ((lh * (t - lt)) / (res.x - lh));
    }
    float s = 0 ;
    if (t < tmax)
    {
        s = t;
    }
    else
    {
        s = -1.0;
    }
    res.x = s;
    return res;
}
vec2 raycast(in vec3 ro, in vec3 rd) { return raycast(ro, rd, kc, 0.0, 200); }

vec3 colorSurface(in vec3 pos, in vec2 tn)
{
    vec3 col = 0.5 + 0.5 * cos(log2(tn.y) * 0.9 + 3.5 + vec3(0.0, 0.6, 1.0));

    if (pos.y > 0.0)
    {
        col = mix(col, vec3(1.0, 1.0, 1.0), 0.2);
    }
    float inside = smoothstep(14., 15., tn.y);

    col *= vec3(0.45, 0.42, 0.40) + vec3(0.55, 0.58, 0.60) * inside;
    col = mix(col * col * (3.0 - 2.0 * col), col, inside);
    col = mix(mix(col, float3_ctor(dot(col, vec3(0.3333, 0.333, 0.333))), -0.4), col, inside);

    // PORT: HLSL clamp is hlsl_clamp (NaN -> 0, DXIL FMax/FMin).
    vec3 surfaceColor = hlsl_clamp(col * 0.65, 0.0, 1.0);

    return surfaceColor;
}

// PORT: no default argument in GLSL (HLSL: time = 0.3f); the caller passes g_sceneCB.elapsedTime, as in the HLSL.
bool JuliaDistance(in vec3 ro, in vec3 rd, inout vec3 normal, inout vec2 resT, in float time)
{
    resT = vec2(1e20);

    ro *= 0.4;

    ro.y += -1.f;//for the scene with multiples objects

    // cut animation
    // (computed and then ignored by the HLSL: raycast below takes its defaults, not deltaT and iMax)
    int iAnimMin = 0;
    int iAnimMax = 600;

    float minCut = -0.3f;
    float maxCut = 0.6f;

    // PORT: HLSL `(10.5*time) % (iAnimMax*2)` is a float remainder truncated to int.
    int iMax = int(hlsl_fmod(10.5*time, float(iAnimMax*2)));
    if(iMax>iAnimMax)
    {
        iMax = 2*iAnimMax - iMax;
    }
    iMax += iAnimMin;

    float deltaT = minCut + maxCut*float(iMax)/float(iAnimMax);

    // julia animation
    vec4 c = kc;

    vec2 tn = raycast(ro, rd);

    bool cond = (tn.x >= 0.0);
    if (cond)
    {
        vec3 pos = (ro + (tn.x * rd));
        normal = calcNormal(pos);
        resT = tn;
    }
    return cond;
}

#endif // PROCEDURAY_JULIA_SETS_GLSL
