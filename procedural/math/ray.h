// Ports: RaytracingShaderHelper.hlsli (both samples) -- Ray, IsInRange, IsCulled, IsAValidHit,
// length_toPow2, CalculateAnimationInterpolant.
// Every function here is written once for a scalar T and for lanes (T = Lanes<float, N>, one ray per lane): a
// predicate returns LaneMask<T> (bool for a scalar) and a branch on a value is a select (procedural/math/lanes.h).
#pragma once

#include <cstdint>
#include <limits>

#include "procedural/math/hlsl.h"

namespace refray::procedural::math {

template <typename T>
using vec2 = glm::vec<2, T>;
template <typename T>
using vec3 = glm::vec<3, T>;
template <typename T>
using vec4 = glm::vec<4, T>;

// A per-ray count (a march's step counter): std::uint32_t for a scalar T, one per lane for lanes.
namespace detail {
template <class T>
struct LaneUintOf {
    using type = std::uint32_t;
};
template <class S, int N>
struct LaneUintOf<Lanes<S, N>> {
    using type = Lanes<std::uint32_t, N>;
};
}  // namespace detail
template <class T>
using LaneUint = typename detail::LaneUintOf<T>::type;

// +infinity of T: std::numeric_limits<T>::infinity() for a scalar T, the scalar's infinity in every lane for lanes
// (numeric_limits knows nothing of Lanes).
template <class T>
T infinityOf() {
    if constexpr (kIsLanes<T>)
        return T(std::numeric_limits<typename T::Scalar>::infinity());
    else
        return std::numeric_limits<T>::infinity();
}

template <typename T>
struct Ray {
    vec3<T> origin;
    vec3<T> direction;
};

// The parts of the DXR ray state that the HLSL helpers read through intrinsics:
// RayTMin(), RayTCurrent() and the two culling bits of RayFlags().
// PORT: passed as a value instead of read from intrinsics, so the math stays pure.
// PORT: the culling bits are a LaneMask<T>: bool for a scalar T, one bit per ray for lanes (a wave's rays may
// carry different flags).
template <typename T>
struct RayExtent {
    T tMin = T(0);
    T tCurrent = T(0);
    LaneMask<T> cullBackFacing = LaneMask<T>(false);   // RAY_FLAG_CULL_BACK_FACING_TRIANGLES
    LaneMask<T> cullFrontFacing = LaneMask<T>(false);  // RAY_FLAG_CULL_FRONT_FACING_TRIANGLES
};

// Writes lane i of a ray or an extent over lanes from one ray's (for a scalar type, lanes.h's setLane writes the
// whole value): what a wave shader gathers from its lanes.
template <typename L, typename T>
    requires kIsLanes<L>
void setLane(Ray<L>& ray, int i, const Ray<T>& value) {
    setLane(ray.origin, i, value.origin);
    setLane(ray.direction, i, value.direction);
}
template <typename L, typename T>
    requires kIsLanes<L>
void setLane(RayExtent<L>& extent, int i, const RayExtent<T>& value) {
    setLane(extent.tMin, i, value.tMin);
    setLane(extent.tCurrent, i, value.tCurrent);
    setLane(extent.cullBackFacing, i, bool(value.cullBackFacing));
    setLane(extent.cullFrontFacing, i, bool(value.cullFrontFacing));
}

template <typename T>
T length_toPow2(const vec2<T>& p) { return hlsl::dot(p, p); }
template <typename T>
T length_toPow2(const vec3<T>& p) { return hlsl::dot(p, p); }

// min <= val <= max (NaN is out of range).
template <typename T>
LaneMask<T> IsInRange(T val, T min, T max) { return val >= min && val <= max; }

// Culled when back-face culling is on and dot(d, n) > 0, or front-face culling and dot < 0.
template <typename T>
LaneMask<T> IsCulled(const Ray<T>& ray, const vec3<T>& hitSurfaceNormal, const RayExtent<T>& extent) {
    const T rayDirectionNormalDot = hlsl::dot(ray.direction, hitSurfaceNormal);
    return (extent.cullBackFacing && rayDirectionNormalDot > T(0)) ||
           (extent.cullFrontFacing && rayDirectionNormalDot < T(0));
}

// TMin <= t <= TCurrent and not culled.
template <typename T>
LaneMask<T> IsAValidHit(const Ray<T>& ray, T thit, const vec3<T>& hitSurfaceNormal, const RayExtent<T>& extent) {
    return IsInRange(thit, extent.tMin, extent.tCurrent) && !IsCulled(ray, hitSurfaceNormal, extent);
}

// A <0 -> 1 -> 0> cycle: u = fmod(T, cycle)/cycle, v = 2u (u <= 0.5) or 1 - 2(u - 0.5),
// smoothstep(0, 1, v). Uses the fmod intrinsic (DXC lowering).
// PORT: the ?: is a select (both sides are computed; for a scalar T the value is the same).
template <typename T>
T CalculateAnimationInterpolant(T elapsedTime, T cycleDuration) {
    T curLinearCycleTime = hlsl::fmod(elapsedTime, cycleDuration) / cycleDuration;
    curLinearCycleTime = select(curLinearCycleTime <= T(0.5), T(2) * curLinearCycleTime,
                                T(1) - T(2) * (curLinearCycleTime - T(0.5)));
    return hlsl::smoothstep(T(0), T(1), curLinearCycleTime);
}

}  // namespace refray::procedural::math
