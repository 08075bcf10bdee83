// Where a secondary ray starts so that it cannot hit the surface it leaves (self-intersection, "acne"): the
// method of Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems,
// chapter 6). A computed hit point lies within a few float ulps of the true surface, on either side. Moving it
// along the geometric normal by a fixed number of ulps of each coordinate clears that error at any distance from
// the origin, where a fixed epsilon (TMin = 0.001) is too large near the origin and too small far from it. Near
// the origin, where ulps become tiny, a small absolute step is used instead.
//
// refray uses it where it spawns rays itself (the built-in scene's shaders). The shader ports keep the HLSL's own
// choice (TMin 0 from the hit point), which docs/numerical-stability.md measures.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "core/math.h"

namespace refray {

// The method's constants: below kOriginBand a coordinate moves by kFloatScale * n, above it by kIntScale * n ulps.
inline constexpr float kOffsetOriginBand = 1.0f / 32.0f;
inline constexpr float kOffsetFloatScale = 1.0f / 65536.0f;
inline constexpr float kOffsetIntScale = 256.0f;

// `p` moved off the surface along `n` (the geometric normal on the side the new ray leaves towards; need not be
// unit length, about unit is intended). Trace the new ray from the result with TMin = 0.
inline vec3 offsetRayOrigin(vec3 p, vec3 n) {
    vec3 out;
    for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(p[i]) || !std::isfinite(n[i])) {  // nothing to step (and no integer overflow)
            out[i] = p[i];
            continue;
        }
        if (std::fabs(p[i]) < kOffsetOriginBand) {
            out[i] = p[i] + kOffsetFloatScale * n[i];
            continue;
        }
        // Stepping the integer representation moves |p| up or down by whole ulps; towards +n either way. Unsigned
        // arithmetic wraps as the HLSL's int does, where C++'s signed overflow would be undefined; the clamp keeps
        // the conversion of a huge normal component in range.
        const float scaled = std::clamp(kOffsetIntScale * n[i], -2147483520.0f, 2147483520.0f);
        const auto ulps = uint32_t(int32_t(scaled));
        const auto bits = std::bit_cast<uint32_t>(p[i]);
        out[i] = std::bit_cast<float>(p[i] < 0.0f ? bits - ulps : bits + ulps);
    }
    return out;
}

}  // namespace refray
