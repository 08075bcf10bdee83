// Ports: DXC's lowering of the HLSL intrinsics the Proceduray shaders use where GLSL's built-in differs
// (dsilvavinicius/Proceduray@c849b6ba, shader model 6.3 library compiled by DXC). Not a file of the HLSL itself.
// Facts: /work/shared/docs/reference-scene-proceduray.md §3.1.
#ifndef PROCEDURAY_HLSL_INTRINSICS_GLSL
#define PROCEDURAY_HLSL_INTRINSICS_GLSL

// HLSL saturate(x): DXIL Saturate, which gives 0 for NaN (H7, H20). GLSL clamp(NaN, 0, 1) is undefined.
float saturate(float x) { return isnan(x) ? 0.0 : clamp(x, 0.0, 1.0); }
vec3 saturate(vec3 v) { return vec3(saturate(v.x), saturate(v.y), saturate(v.z)); }

// HLSL clamp(x, lo, hi) = FMin(FMax(x, lo), hi); DXIL FMin/FMax return the non-NaN operand, so a NaN x gives lo.
float hlsl_clamp(float x, float lo, float hi) { return isnan(x) ? lo : clamp(x, lo, hi); }
vec3 hlsl_clamp(vec3 v, float lo, float hi)
{
    return vec3(hlsl_clamp(v.x, lo, hi), hlsl_clamp(v.y, lo, hi), hlsl_clamp(v.z, lo, hi));
}

// HLSL pow(x, y) as DXC lowers it (exponent other than the literal 2): exp2(y * log2(x)). So pow(0, y > 0) = 0,
// pow(0, 0) = NaN and pow(x < 0, y) = NaN, where GLSL's pow leaves x <= 0 undefined and lets the driver choose.
float hlsl_pow(float x, float y) { return exp2(y * log2(x)); }
vec3 hlsl_pow(vec3 x, vec3 y) { return exp2(y * log2(x)); }

// HLSL `float % float` (and fmod): the remainder with the sign of x, x - y * trunc(x / y). GLSL mod() floors
// instead; for the non-negative times of the contract both agree, but this is the HLSL's definition.
float hlsl_fmod(float x, float y) { return x - y * trunc(x / y); }

// HLSL atan2(y, x) as DXC lowers it: atan(y / x), then +pi (x < 0, y >= 0), -pi (x < 0, y < 0),
// +pi/2 (x == 0, y >= 0), -pi/2 (x == 0, y < 0). So atan2(0, 0) = +pi/2 (H5); GLSL's atan(y, x) leaves it undefined.
float hlsl_atan2(float y, float x)
{
    const float pi = 3.14159265358979323846;
    float result = atan(y / x);
    if (x < 0.0 && y >= 0.0) result = result + pi;
    if (x < 0.0 && y < 0.0) result = result - pi;
    if (x == 0.0 && y >= 0.0) result = pi / 2.0;
    if (x == 0.0 && y < 0.0) result = -pi / 2.0;
    return result;
}

#endif // PROCEDURAY_HLSL_INTRINSICS_GLSL
