// HLSL intrinsics with the semantics DXC gives them when it lowers HLSL to DXIL (HLOperationLower.cpp), for GLSL
// ports of D3D12 HLSL. Not a port of one HLSL file: GLSL either lacks these names or gives them other semantics.
// Every function here is a deliberate difference from the plain GLSL built-in (// PORT: on each).
//
// Needs, in the including file before any code: #extension GL_EXT_spirv_intrinsics : require
#ifndef D3D12_HLSL_INTRINSICS_GLSL
#define D3D12_HLSL_INTRINSICS_GLSL

// PORT: HLSL min/max on floats lower to DXIL FMin/FMax, IEEE-754 minNum/maxNum: a NaN operand is ignored. GLSL
// min/max (SPIR-V FMin/FMax) leave a NaN operand undefined, so use GLSL.std.450 NMin (79) / NMax (80), which are
// minNum/maxNum. The slab test's 0*inf (AnalyticPrimitives) relies on this.
spirv_instruction(set = "GLSL.std.450", id = 79) float hlsl_min(float x, float y);
spirv_instruction(set = "GLSL.std.450", id = 79) vec2 hlsl_min(vec2 x, vec2 y);
spirv_instruction(set = "GLSL.std.450", id = 79) vec3 hlsl_min(vec3 x, vec3 y);
spirv_instruction(set = "GLSL.std.450", id = 79) vec4 hlsl_min(vec4 x, vec4 y);
spirv_instruction(set = "GLSL.std.450", id = 80) float hlsl_max(float x, float y);
spirv_instruction(set = "GLSL.std.450", id = 80) vec2 hlsl_max(vec2 x, vec2 y);
spirv_instruction(set = "GLSL.std.450", id = 80) vec3 hlsl_max(vec3 x, vec3 y);
spirv_instruction(set = "GLSL.std.450", id = 80) vec4 hlsl_max(vec4 x, vec4 y);
// GLSL.std.450 NClamp (81): NMin(NMax(x, lo), hi), so NaN -> lo.
spirv_instruction(set = "GLSL.std.450", id = 81) float hlsl_nclamp(float x, float lo, float hi);
spirv_instruction(set = "GLSL.std.450", id = 81) vec2 hlsl_nclamp(vec2 x, vec2 lo, vec2 hi);
spirv_instruction(set = "GLSL.std.450", id = 81) vec3 hlsl_nclamp(vec3 x, vec3 lo, vec3 hi);
spirv_instruction(set = "GLSL.std.450", id = 81) vec4 hlsl_nclamp(vec4 x, vec4 lo, vec4 hi);

// PORT: saturate is DXIL Saturate: clamp to [0,1], NaN -> 0 (GLSL clamp leaves NaN undefined).
float saturate(float x) { return hlsl_nclamp(x, 0.0, 1.0); }
vec2 saturate(vec2 x) { return hlsl_nclamp(x, vec2(0.0), vec2(1.0)); }
vec3 saturate(vec3 x) { return hlsl_nclamp(x, vec3(0.0), vec3(1.0)); }
vec4 saturate(vec4 x) { return hlsl_nclamp(x, vec4(0.0), vec4(1.0)); }

// frac is DXIL Frc, x - floor(x): the same as GLSL fract.
float frac(float x) { return fract(x); }
vec2 frac(vec2 x) { return fract(x); }
vec3 frac(vec3 x) { return fract(x); }

// PORT: lerp as DXC lowers it, x + s*(y - x) (GLSL mix is x*(1-a) + y*a, rounded differently).
float lerp(float x, float y, float s) { return x + s * (y - x); }
vec3 lerp(vec3 x, vec3 y, float s) { return x + s * (y - x); }
vec4 lerp(vec4 x, vec4 y, float s) { return x + s * (y - x); }
vec4 lerp(vec4 x, vec4 y, vec4 s) { return x + s * (y - x); }

// PORT: fmod as DXC lowers it: d = x/y, f = frac(|d|), (d >= -d ? f : -f) * y. It keeps the sign of x, like C fmodf,
// but is not the exact remainder (fmod(1, 0.05) is 0 here, about 0.05 in C). GLSL mod() floors instead.
float fmod(float x, float y) {
    float d = x / y;
    float f = frac(abs(d));
    return (d >= -d ? f : -f) * y;
}
vec3 fmod(vec3 x, vec3 y) {
    vec3 d = x / y;
    vec3 f = frac(abs(d));
    return mix(-f, f, greaterThanEqual(d, -d)) * y;  // mix with a bvec selects; no arithmetic
}

// PORT: atan2 as DXC lowers it: atan(y/x), then quadrant fix-ups by select. x == 0 with y >= 0 gives +pi/2 (so
// atan2(0, 0) = pi/2, where C gives 0); x == 0 with y < 0 gives -pi/2. GLSL atan(y, x) is undefined at (0, 0).
float atan2(float y, float x) {
    const float pi = 3.14159265358979323846;
    float a = atan(y / x);
    float result = a;
    result = (x < 0.0 && y >= 0.0) ? a + pi : result;
    result = (x < 0.0 && y < 0.0) ? a - pi : result;
    result = (x == 0.0 && y < 0.0) ? -pi / 2.0 : result;
    result = (x == 0.0 && y >= 0.0) ? pi / 2.0 : result;
    return result;
}

// PORT: pow as DXC lowers it: exp2(y * log2(x)) (DXIL Log and Exp are base 2), for every exponent except a literal
// 2 (x*x). GLSL pow leaves the lowering to the driver, which may expand constant integer exponents.
// pow(0, y > 0) = 0, pow(0, 0) = NaN, pow(x < 0, y) = NaN.
float hlsl_pow(float x, float y) { return exp2(y * log2(x)); }

// PORT: smoothstep as DXC lowers it: s = saturate((x - min)/(max - min)), s*s*(3 - 2*s) (saturate maps NaN to 0).
float hlsl_smoothstep(float minValue, float maxValue, float x) {
    float s = saturate((x - minValue) / (maxValue - minValue));
    return s * s * (3.0 - 2.0 * s);
}

#endif  // D3D12_HLSL_INTRINSICS_GLSL
