// Ports: D3D12 sample AnalyticPrimitives.hlsli; isphere from Proceduray SignedDistancePrimitives.hlsli.
// Quadratic solver, hollow/solid/multiple spheres, slab AABB test and hollow box, templated on T.
// PORT: written once for a scalar T and for lanes (T = Lanes<float, N>, one ray per lane; procedural/math/lanes.h):
// a test returns LaneMask<T>, a branch on a value is taken when some lane takes it and its results are selected in
// for those lanes, and an early `return` is taken when every lane returns there. For a scalar T each `if (anyLane(m))`
// is the HLSL's `if (m)` and each select the plain assignment, so the scalar code computes what the HLSL does.
#pragma once

#include <limits>

#include "procedural/math/hlsl.h"
#include "procedural/math/ray.h"

namespace refray::procedural::math {

// PORT: hit is a LaneMask<T> (bool for a scalar T, one per ray for lanes).
template <typename T>
struct AnalyticHit {
    LaneMask<T> hit = LaneMask<T>(false);
    T thit = T(0);
    vec3<T> normal{};  // local space; zero-initialised like the IS attributes (D3D12 H6)
};

// Roots of a*x^2 + b*x + c = 0 with the numerically stable q form; x0 <= x1.
// disc < 0: no roots. disc == 0: x0 = x1 = -0.5*b/a.
// PORT: x0 and x1 are written only in the lanes that have roots (the others keep what they held, as the HLSL's
// early return leaves them); the roots are formed in r0, r1 and selected in.
template <typename T>
LaneMask<T> SolveQuadraticEqn(T a, T b, T c, T& x0, T& x1) {
    const T discr = b * b - T(4) * a * c;
    const LaneMask<T> hasRoots = !(discr < T(0));
    if (!anyLane(hasRoots)) return hasRoots;  // if (discr < 0) return false;
    const LaneMask<T> doubleRoot = discr == T(0);
    T r0 = x0;
    T r1 = x1;
    if (anyLane(doubleRoot)) {
        const T x = T(-0.5) * b / a;
        r0 = select(doubleRoot, x, r0);
        r1 = select(doubleRoot, x, r1);
    }
    if (anyLane(!doubleRoot)) {
        const T q = select(b > T(0), T(-0.5) * (b + hlsl::sqrt(discr)), T(-0.5) * (b - hlsl::sqrt(discr)));
        r0 = select(doubleRoot, r0, q / a);
        r1 = select(doubleRoot, r1, c / q);
    }
    const LaneMask<T> swap = r0 > r1;  // if (x0 > x1) swap them
    x0 = select(hasRoots, select(swap, r1, r0), x0);
    x1 = select(hasRoots, select(swap, r0, r1), x1);
    return hasRoots;
}

template <typename T>
vec3<T> CalculateNormalForARaySphereHit(const Ray<T>& ray, T thit, const vec3<T>& center) {
    const vec3<T> hitPosition = ray.origin + thit * ray.direction;
    return hlsl::normalize(hitPosition - center);
}

// Unbounded ray-sphere roots; a = dot(d, d), so the direction need not be unit length.
template <typename T>
LaneMask<T> SolveRaySphereIntersectionEquation(const Ray<T>& ray, T& tmin, T& tmax, const vec3<T>& center, T radius) {
    const vec3<T> L = ray.origin - center;
    const T a = hlsl::dot(ray.direction, ray.direction);
    const T b = T(2) * hlsl::dot(ray.direction, L);
    const T c = hlsl::dot(L, L) - radius * radius;
    return SolveQuadraticEqn(a, b, c, tmin, tmax);
}

// Hollow sphere with culling: t0 first (unless t0 < TMin), then t1; each must pass IsAValidHit.
// `tmax` receives t1 whenever the equation has roots.
// PORT: the two sides of `if (t0 < TMin)` are masks (both are computed when the lanes differ); `front` and `back`
// hold the lanes in each, and a lane that returns (or whose hit is final) drops out of the later assignments.
template <typename T>
AnalyticHit<T> RaySphereIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent, T& tmax,
                                         const vec3<T>& center = vec3<T>(T(0)), T radius = T(1)) {
    AnalyticHit<T> r;
    T t0 = T(0);
    T t1 = T(0);
    const LaneMask<T> solved = SolveRaySphereIntersectionEquation(ray, t0, t1, center, radius);
    if (!anyLane(solved)) return r;
    tmax = select(solved, t1, tmax);

    // The lanes of `mask` try root t: its normal becomes the hit's normal, and where IsAValidHit accepts it, t is
    // the hit. Returns the accepted lanes.
    const auto tryRoot = [&](const LaneMask<T>& mask, const T& t) {
        const vec3<T> normal = CalculateNormalForARaySphereHit(ray, t, center);
        r.normal = select(mask, normal, r.normal);
        const LaneMask<T> valid = mask && IsAValidHit(ray, t, normal, extent);
        r.hit = r.hit || valid;
        r.thit = select(valid, t, r.thit);
        return valid;
    };
    const LaneMask<T> t0BeforeTMin = t0 < extent.tMin;
    const LaneMask<T> front = solved && t0BeforeTMin;
    if (anyLane(front)) {
        const LaneMask<T> t1Reached = front && !(t1 < extent.tMin);  // if (t1 < TMin) return
        if (anyLane(t1Reached)) tryRoot(t1Reached, t1);
    }
    const LaneMask<T> back = solved && !t0BeforeTMin;
    if (anyLane(back)) {
        const LaneMask<T> tryT1 = back && !tryRoot(back, t0);  // a valid t0 returns
        if (anyLane(tryT1)) tryRoot(tryT1, t1);
    }
    return r;
}

// Solid sphere, no flags, no normal: thit = max(t0, TMin), tmax = min(t1, TCurrent) (NaN-ignoring).
// PORT: thit and tmax are written only in the lanes with roots.
template <typename T>
LaneMask<T> RaySolidSphereIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent, T& thit, T& tmax,
                                           const vec3<T>& center = vec3<T>(T(0)), T radius = T(1)) {
    T t0 = T(0);
    T t1 = T(0);
    const LaneMask<T> solved = SolveRaySphereIntersectionEquation(ray, t0, t1, center, radius);
    if (!anyLane(solved)) return solved;
    thit = select(solved, hlsl::max(t0, extent.tMin), thit);
    tmax = select(solved, hlsl::min(t1, extent.tCurrent), tmax);
    return solved;
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
        const LaneMask<T> closer = h.hit && h.thit < best.thit;
        if (anyLane(closer)) {
            best.thit = select(closer, h.thit, best.thit);
            best.normal = select(closer, h.normal, best.normal);
            best.hit = best.hit || closer;
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
// PORT: for lanes both cases of a component are computed when its lanes differ (d == 0 selects the first), and
// aabb[sign] / aabb[1 - sign] is a select on d > 0.
template <typename T>
LaneMask<T> RayAABBIntersectionTest(const Ray<T>& ray, const vec3<T> aabb[2], const RayExtent<T>& extent, T& tmin,
                                    T& tmax) {
    const T inf = infinityOf<T>();
    vec3<T> tmin3{};  // every component is set below; {} spares GCC a false maybe-uninitialized
    vec3<T> tmax3{};
    for (glm::length_t k = 0; k < 3; ++k) {
        const T d = ray.direction[k];
        const T o = ray.origin[k];
        const LaneMask<T> parallel = d == T(0);
        if (anyLane(parallel)) {
            const LaneMask<T> inside = o >= aabb[0][k] && o <= aabb[1][k];
            tmin3[k] = select(parallel, select(inside, -inf, inf), tmin3[k]);
            tmax3[k] = select(parallel, select(inside, inf, -inf), tmax3[k]);
        }
        if (anyLane(!parallel)) {  // the scalar's `continue` skips this for d == 0
            const LaneMask<T> positive = d > T(0);  // sign = 1
            const T invRayDirection = T(1) / d;
            tmin3[k] = select(parallel, tmin3[k], (select(positive, aabb[0][k], aabb[1][k]) - o) * invRayDirection);
            tmax3[k] = select(parallel, tmax3[k], (select(positive, aabb[1][k], aabb[0][k]) - o) * invRayDirection);
        }
    }
    tmin = hlsl::max(hlsl::max(tmin3.x, tmin3.y), tmin3.z);
    tmax = hlsl::min(hlsl::min(tmax3.x, tmax3.y), tmax3.z);
    return tmax > tmin && tmax >= extent.tMin && tmin <= extent.tCurrent;
}

// Hollow box with culling: no hit unless TMin <= tmin <= TCurrent (a ray starting inside never
// hits). The normal is the first face within 1e-4 of the hit point, in the order -x, -y, -z, +x,
// +y, +z; if none is that close it stays (0,0,0) (D3D12 H6).
// PORT: the two early returns are a mask (`inBox`: the lanes that go on); the else-if chain assigns the normal of
// the first close face per lane (`found`: the lanes whose face is chosen, or that returned).
template <typename T>
AnalyticHit<T> RayAABBIntersectionTest(const Ray<T>& ray, const vec3<T> aabb[2], const RayExtent<T>& extent) {
    AnalyticHit<T> r;
    T tmin = T(0);
    T tmax = T(0);
    const LaneMask<T> slabsHit = RayAABBIntersectionTest(ray, aabb, extent, tmin, tmax);
    if (!anyLane(slabsHit)) return r;
    const LaneMask<T> inBox = slabsHit && !(tmin < extent.tMin || tmin > extent.tCurrent);
    if (!anyLane(inBox)) return r;

    const T thit = tmin;
    const vec3<T> hitPosition = ray.origin + thit * ray.direction;
    const vec3<T> distanceToBounds[2] = {hlsl::abs(aabb[0] - hitPosition), hlsl::abs(aabb[1] - hitPosition)};
    const T eps = T(0.0001);
    LaneMask<T> found = !inBox;
    const auto face = [&](const LaneMask<T>& close, const vec3<T>& normal) {  // if (!found && close) r.normal = n
        const LaneMask<T> take = !found && close;
        r.normal = select(take, normal, r.normal);
        found = found || take;
    };
    face(distanceToBounds[0].x < eps, vec3<T>(-1, 0, 0));
    face(distanceToBounds[0].y < eps, vec3<T>(0, -1, 0));
    face(distanceToBounds[0].z < eps, vec3<T>(0, 0, -1));
    face(distanceToBounds[1].x < eps, vec3<T>(1, 0, 0));
    face(distanceToBounds[1].y < eps, vec3<T>(0, 1, 0));
    face(distanceToBounds[1].z < eps, vec3<T>(0, 0, 1));

    r.thit = select(inBox, thit, r.thit);
    r.hit = inBox && IsAValidHit(ray, thit, r.normal, extent);
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
    // PORT: the early return is taken when every lane misses; otherwise the missing lanes select (-1, -1).
    const LaneMask<T> miss = h < T(0);
    if (allLanes(miss)) return vec2<T>(T(-1), T(-1));
    h = hlsl::sqrt(h);
    return select(miss, vec2<T>(T(-1), T(-1)), -b + vec2<T>(-h, h));
}

}  // namespace refray::procedural::math
