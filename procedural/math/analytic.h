// Ports: D3D12 sample AnalyticPrimitives.hlsli; isphere from Proceduray SignedDistancePrimitives.hlsli.
// Quadratic solver, hollow/solid/multiple spheres, slab AABB test and hollow box, templated on T.
#pragma once

#include <limits>

#include "procedural/math/hlsl.h"
#include "procedural/math/ray.h"

namespace refray::procedural::math {

template <typename T>
struct AnalyticHit {
    bool hit = false;
    T thit = T(0);
    vec3<T> normal{};  // local space; zero-initialised like the IS attributes (D3D12 H6)
};

// Roots of a*x^2 + b*x + c = 0 with the numerically stable q form; x0 <= x1.
// disc < 0: no roots. disc == 0: x0 = x1 = -0.5*b/a.
template <typename T>
bool SolveQuadraticEqn(T a, T b, T c, T& x0, T& x1) {
    const T discr = b * b - T(4) * a * c;
    if (discr < T(0)) return false;
    if (discr == T(0)) {
        x0 = x1 = T(-0.5) * b / a;
    } else {
        const T q = (b > T(0)) ? T(-0.5) * (b + hlsl::sqrt(discr)) : T(-0.5) * (b - hlsl::sqrt(discr));
        x0 = q / a;
        x1 = c / q;
    }
    if (x0 > x1) {
        const T temp = x0;
        x0 = x1;
        x1 = temp;
    }
    return true;
}

template <typename T>
vec3<T> CalculateNormalForARaySphereHit(const Ray<T>& ray, T thit, const vec3<T>& center) {
    const vec3<T> hitPosition = ray.origin + thit * ray.direction;
    return hlsl::normalize(hitPosition - center);
}

// Unbounded ray-sphere roots; a = dot(d, d), so the direction need not be unit length.
template <typename T>
bool SolveRaySphereIntersectionEquation(const Ray<T>& ray, T& tmin, T& tmax, const vec3<T>& center, T radius) {
    const vec3<T> L = ray.origin - center;
    const T a = hlsl::dot(ray.direction, ray.direction);
    const T b = T(2) * hlsl::dot(ray.direction, L);
    const T c = hlsl::dot(L, L) - radius * radius;
    return SolveQuadraticEqn(a, b, c, tmin, tmax);
}

// Hollow sphere with culling: t0 first (unless t0 < TMin), then t1; each must pass IsAValidHit.
// `tmax` receives t1 whenever the equation has roots.
template <typename T>
AnalyticHit<T> RaySphereIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent, T& tmax,
                                         const vec3<T>& center = vec3<T>(T(0)), T radius = T(1)) {
    AnalyticHit<T> r;
    T t0 = T(0);
    T t1 = T(0);
    if (!SolveRaySphereIntersectionEquation(ray, t0, t1, center, radius)) return r;
    tmax = t1;

    if (t0 < extent.tMin) {
        if (t1 < extent.tMin) return r;
        r.normal = CalculateNormalForARaySphereHit(ray, t1, center);
        if (IsAValidHit(ray, t1, r.normal, extent)) {
            r.hit = true;
            r.thit = t1;
        }
    } else {
        r.normal = CalculateNormalForARaySphereHit(ray, t0, center);
        if (IsAValidHit(ray, t0, r.normal, extent)) {
            r.hit = true;
            r.thit = t0;
            return r;
        }
        r.normal = CalculateNormalForARaySphereHit(ray, t1, center);
        if (IsAValidHit(ray, t1, r.normal, extent)) {
            r.hit = true;
            r.thit = t1;
        }
    }
    return r;
}

// Solid sphere, no flags, no normal: thit = max(t0, TMin), tmax = min(t1, TCurrent) (NaN-ignoring).
template <typename T>
bool RaySolidSphereIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent, T& thit, T& tmax,
                                    const vec3<T>& center = vec3<T>(T(0)), T radius = T(1)) {
    T t0 = T(0);
    T t1 = T(0);
    if (!SolveRaySphereIntersectionEquation(ray, t0, t1, center, radius)) return false;
    thit = hlsl::max(t0, extent.tMin);
    tmax = hlsl::min(t1, extent.tCurrent);
    return true;
}

// The three local-space spheres of the D3D12 "Spheres" primitive.
template <typename T>
struct AnalyticSpheres {
    static constexpr int N = 3;
    static vec3<T> center(int i) {
        switch (i) {
            case 0: return vec3<T>(T(-0.3), T(-0.3), T(-0.3));
            case 1: return vec3<T>(T(0.1), T(0.1), T(0.4));
            default: return vec3<T>(T(0.35), T(0.35), T(0.0));
        }
    }
    static T radius(int i) { return i == 0 ? T(0.6) : (i == 1 ? T(0.3) : T(0.15)); }
};

// Closest of the three hollow spheres: a running best starting at TCurrent, replaced only by a
// strictly smaller t (so a hit exactly at TCurrent is rejected, D3D12 I4).
template <typename T>
AnalyticHit<T> RaySpheresIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent) {
    AnalyticHit<T> best;
    best.thit = extent.tCurrent;
    for (int i = 0; i < AnalyticSpheres<T>::N; i++) {
        T _tmax = T(0);
        const AnalyticHit<T> h =
            RaySphereIntersectionTest(ray, extent, _tmax, AnalyticSpheres<T>::center(i), AnalyticSpheres<T>::radius(i));
        if (h.hit && h.thit < best.thit) {
            best.thit = h.thit;
            best.normal = h.normal;
            best.hit = true;
        }
    }
    return best;
}

// Slab test against aabb[0]..aabb[1]: tmin = max of the near planes, tmax = min of the far
// planes; hit iff tmax > tmin && tmax >= TMin && tmin <= TCurrent.
// PORT: the HLSL sets 1/d = -inf for d == 0 (either sign of zero) and forms (B - o) * -inf,
// which is 0*inf = NaN when the origin lies on a slab plane; its NaN-ignoring max/min then drop
// that term. Here a zero component gives (-inf, +inf) when aabb[0] <= o <= aabb[1] and an empty
// slab otherwise, which is the same result without ever producing a NaN.
template <typename T>
bool RayAABBIntersectionTest(const Ray<T>& ray, const vec3<T> aabb[2], const RayExtent<T>& extent, T& tmin,
                             T& tmax) {
    constexpr T inf = std::numeric_limits<T>::infinity();
    vec3<T> tmin3{};  // every component is set below; {} spares GCC a false maybe-uninitialized
    vec3<T> tmax3{};
    for (glm::length_t k = 0; k < 3; ++k) {
        const T d = ray.direction[k];
        const T o = ray.origin[k];
        if (d == T(0)) {
            const bool inside = o >= aabb[0][k] && o <= aabb[1][k];
            tmin3[k] = inside ? -inf : inf;
            tmax3[k] = inside ? inf : -inf;
            continue;
        }
        const int sign = d > T(0) ? 1 : 0;
        const T invRayDirection = T(1) / d;
        tmin3[k] = (aabb[1 - sign][k] - o) * invRayDirection;
        tmax3[k] = (aabb[sign][k] - o) * invRayDirection;
    }
    tmin = hlsl::max(hlsl::max(tmin3.x, tmin3.y), tmin3.z);
    tmax = hlsl::min(hlsl::min(tmax3.x, tmax3.y), tmax3.z);
    return tmax > tmin && tmax >= extent.tMin && tmin <= extent.tCurrent;
}

// Hollow box with culling: no hit unless TMin <= tmin <= TCurrent (a ray starting inside never
// hits). The normal is the first face within 1e-4 of the hit point, in the order -x, -y, -z, +x,
// +y, +z; if none is that close it stays (0,0,0) (D3D12 H6).
template <typename T>
AnalyticHit<T> RayAABBIntersectionTest(const Ray<T>& ray, const vec3<T> aabb[2], const RayExtent<T>& extent) {
    AnalyticHit<T> r;
    T tmin = T(0);
    T tmax = T(0);
    if (!RayAABBIntersectionTest(ray, aabb, extent, tmin, tmax)) return r;
    if (tmin < extent.tMin || tmin > extent.tCurrent) return r;

    const T thit = tmin;
    const vec3<T> hitPosition = ray.origin + thit * ray.direction;
    const vec3<T> distanceToBounds[2] = {hlsl::abs(aabb[0] - hitPosition), hlsl::abs(aabb[1] - hitPosition)};
    const T eps = T(0.0001);
    if (distanceToBounds[0].x < eps) r.normal = vec3<T>(-1, 0, 0);
    else if (distanceToBounds[0].y < eps) r.normal = vec3<T>(0, -1, 0);
    else if (distanceToBounds[0].z < eps) r.normal = vec3<T>(0, 0, -1);
    else if (distanceToBounds[1].x < eps) r.normal = vec3<T>(1, 0, 0);
    else if (distanceToBounds[1].y < eps) r.normal = vec3<T>(0, 1, 0);
    else if (distanceToBounds[1].z < eps) r.normal = vec3<T>(0, 0, 1);

    r.thit = thit;
    r.hit = IsAValidHit(ray, thit, r.normal, extent);
    return r;
}

// The local cube [-1,1]^3 of the D3D12 analytic "AABB" primitive.
template <typename T>
AnalyticHit<T> RayUnitCubeIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent) {
    const vec3<T> aabb[2] = {vec3<T>(T(-1)), vec3<T>(T(1))};
    return RayAABBIntersectionTest(ray, aabb, extent);
}

// Proceduray isphere (unit direction assumed): -b +- sqrt(b^2 - c), or (-1, -1) when h < 0.
// sph = (centre, radius).
template <typename T>
vec2<T> isphere(const vec4<T>& sph, const vec3<T>& ro, const vec3<T>& rd) {
    const vec3<T> oc = ro - vec3<T>(sph);
    const T b = hlsl::dot(oc, rd);
    const T c = hlsl::dot(oc, oc) - sph.w * sph.w;
    T h = b * b - c;
    if (h < T(0)) return vec2<T>(T(-1), T(-1));
    h = hlsl::sqrt(h);
    return -b + vec2<T>(-h, h);
}

}  // namespace refray::procedural::math
