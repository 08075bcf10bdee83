// core/ray_offset.h in GLSL, for every port that starts a ray on a surface (builtin, dxr-path-tracer): `p` moved off
// the surface along `n` (Waechter and Binder, Ray Tracing Gems chapter 6), bit for bit as the C++ does.
#ifndef REFRAY_RAY_OFFSET_GLSL
#define REFRAY_RAY_OFFSET_GLSL

const float kOffsetOriginBand = 1.0 / 32.0;
const float kOffsetFloatScale = 1.0 / 65536.0;
const float kOffsetIntScale = 256.0;

vec3 offsetRayOrigin(vec3 p, vec3 n) {
    vec3 moved;
    for (int i = 0; i < 3; ++i) {
        if (isinf(p[i]) || isnan(p[i]) || isinf(n[i]) || isnan(n[i])) {  // nothing to step
            moved[i] = p[i];
            continue;
        }
        if (abs(p[i]) < kOffsetOriginBand) {
            moved[i] = p[i] + kOffsetFloatScale * n[i];
            continue;
        }
        // PORT: std::clamp(v, lo, hi) is v < lo ? lo : hi < v ? hi : v; v is finite here, so GLSL clamp agrees.
        const float scaled = clamp(kOffsetIntScale * n[i], -2147483520.0, 2147483520.0);
        const uint ulps = uint(int(scaled));  // truncation toward zero, then the two's-complement bits
        const uint bits = floatBitsToUint(p[i]);
        moved[i] = uintBitsToFloat(p[i] < 0.0 ? bits - ulps : bits + ulps);  // uint arithmetic wraps, as in the C++
    }
    return moved;
}

#endif  // REFRAY_RAY_OFFSET_GLSL
