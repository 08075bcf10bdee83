// Ports: RaytracingShaderHelper.hlsli (both samples) -- Ray, IsInRange, IsCulled, IsAValidHit,
// length_toPow2, CalculateAnimationInterpolant.
#pragma once

#include "procedural/math/hlsl.h"

namespace refray::procedural::math {

template <typename T>
using vec2 = glm::vec<2, T>;
template <typename T>
using vec3 = glm::vec<3, T>;
template <typename T>
using vec4 = glm::vec<4, T>;

template <typename T>
struct Ray {
    vec3<T> origin;
    vec3<T> direction;
};

// The parts of the DXR ray state that the HLSL helpers read through intrinsics:
// RayTMin(), RayTCurrent() and the two culling bits of RayFlags().
// PORT: passed as a value instead of read from intrinsics, so the math stays pure.
template <typename T>
struct RayExtent {
    T tMin = T(0);
    T tCurrent = T(0);
    bool cullBackFacing = false;   // RAY_FLAG_CULL_BACK_FACING_TRIANGLES
    bool cullFrontFacing = false;  // RAY_FLAG_CULL_FRONT_FACING_TRIANGLES
};

template <typename T>
T length_toPow2(const vec2<T>& p) { return hlsl::dot(p, p); }
template <typename T>
T length_toPow2(const vec3<T>& p) { return hlsl::dot(p, p); }

// min <= val <= max (NaN is out of range).
template <typename T>
bool IsInRange(T val, T min, T max) { return val >= min && val <= max; }

// Culled when back-face culling is on and dot(d, n) > 0, or front-face culling and dot < 0.
template <typename T>
bool IsCulled(const Ray<T>& ray, const vec3<T>& hitSurfaceNormal, const RayExtent<T>& extent) {
    const T rayDirectionNormalDot = hlsl::dot(ray.direction, hitSurfaceNormal);
    return (extent.cullBackFacing && rayDirectionNormalDot > T(0)) ||
           (extent.cullFrontFacing && rayDirectionNormalDot < T(0));
}

// TMin <= t <= TCurrent and not culled.
template <typename T>
bool IsAValidHit(const Ray<T>& ray, T thit, const vec3<T>& hitSurfaceNormal, const RayExtent<T>& extent) {
    return IsInRange(thit, extent.tMin, extent.tCurrent) && !IsCulled(ray, hitSurfaceNormal, extent);
}

// A <0 -> 1 -> 0> cycle: u = fmod(T, cycle)/cycle, v = 2u (u <= 0.5) or 1 - 2(u - 0.5),
// smoothstep(0, 1, v). Uses the fmod intrinsic (DXC lowering).
template <typename T>
T CalculateAnimationInterpolant(T elapsedTime, T cycleDuration) {
    T curLinearCycleTime = hlsl::fmod(elapsedTime, cycleDuration) / cycleDuration;
    curLinearCycleTime = (curLinearCycleTime <= T(0.5)) ? T(2) * curLinearCycleTime
                                                         : T(1) - T(2) * (curLinearCycleTime - T(0.5));
    return hlsl::smoothstep(T(0), T(1), curLinearCycleTime);
}

}  // namespace refray::procedural::math
