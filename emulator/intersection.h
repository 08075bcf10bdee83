// Fixed-function intersection tests the emulator applies itself: the watertight
// ray/triangle test (TRI-1..6) and the inclusive, NaN-free ray/AABB slab test (BLAS-7).
// Defined here, inline, so that the broad phase's callbacks (embree_bridge.cpp) take their results in registers: a
// result returned through memory was read back with wider loads than the stores that wrote it (a store-forwarding
// stall per tested primitive).
#pragma once

#include <cmath>
#include <optional>
#include <utility>

#include "core/math.h"
#include "emulator/acceleration_structure.h"

namespace refray::dxr {

struct TriangleIntersection {
    float t = 0.0f;
    vec2 barycentrics{0.0f};  // x weights v1, y weights v2 (SV-12)
};

struct SlabInterval {
    float tEnter = 0.0f;
    float tExit = 0.0f;
};

namespace intersection_detail {

inline int largestAxis(vec3 d) {
    const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (ax > ay) return ax > az ? 0 : 2;
    return ay > az ? 1 : 2;
}

// Top-left style ownership of an edge whose edge function is exactly zero. (dx, dy) is
// the edge direction in the sheared 2D frame, already multiplied by the triangle's
// orientation sign, so two triangles sharing the edge see opposite directions and
// exactly one of them owns it.
inline bool ownsEdge(double dx, double dy, bool alternate) {
    if (alternate) return dy < 0.0 || (dy == 0.0 && dx > 0.0);
    return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}

// v's component k (0: x, 1: y, 2: z), chosen in registers: an index into a vec3 on the stack costs a store and a load.
inline float axis(vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

}  // namespace intersection_detail

// Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection" (JCGT 2013): per-ray
// axis permutation and shear, edge functions recomputed in double when one is exactly
// zero, and an explicit edge-ownership rule so a ray through a shared edge or vertex
// hits exactly one triangle (TRI-2, TRI-4). True, with `hit`, for a hit at any t (the
// caller applies the ray interval); false for a miss, a degenerate triangle or a ray
// parallel to the plane (TRI-5, DEGEN-7). `alternateEdgeRule` swaps which side owns an
// edge (the adversarial mode of GEN-3); either rule is watertight.
[[gnu::always_inline]] inline bool intersectTriangle(vec3 org, vec3 dir, vec3 v0, vec3 v1, vec3 v2,
                                                     bool alternateEdgeRule, TriangleIntersection& hit) {
    using intersection_detail::axis;
    using intersection_detail::largestAxis;
    using intersection_detail::ownsEdge;
    // Permute axes so z is the largest direction component; swap x/y to keep winding.
    const int kz = largestAxis(dir);
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (axis(dir, kz) == 0.0f || std::isnan(axis(dir, kz))) return false;
    if (axis(dir, kz) < 0.0f) std::swap(kx, ky);
    const float Sx = axis(dir, kx) / axis(dir, kz), Sy = axis(dir, ky) / axis(dir, kz), Sz = 1.0f / axis(dir, kz);

    const vec3 A = v0 - org, B = v1 - org, C = v2 - org;
    const float Ax = axis(A, kx) - Sx * axis(A, kz), Ay = axis(A, ky) - Sy * axis(A, kz);
    const float Bx = axis(B, kx) - Sx * axis(B, kz), By = axis(B, ky) - Sy * axis(B, kz);
    const float Cx = axis(C, kx) - Sx * axis(C, kz), Cy = axis(C, ky) - Sy * axis(C, kz);

    double U = double(Cx * By - Cy * Bx);
    double V = double(Ax * Cy - Ay * Cx);
    double W = double(Bx * Ay - By * Ax);
    if (U == 0.0 || V == 0.0 || W == 0.0) {
        // Exactly on an edge in float: decide in double, which is exact for float inputs.
        U = double(Cx) * double(By) - double(Cy) * double(Bx);
        V = double(Ax) * double(Cy) - double(Ay) * double(Cx);
        W = double(Bx) * double(Ay) - double(By) * double(Ax);
    }
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    // DEGEN-7: a triangle with collinear vertices is inactive. For oblique rays the float shear above can round
    // such a triangle into a sliver with a non-zero determinant, so zero area is decided from the vertices
    // themselves (in double; only rays that passed the edge tests pay for it).
    const glm::dvec3 area = glm::cross(glm::dvec3(v1) - glm::dvec3(v0), glm::dvec3(v2) - glm::dvec3(v0));
    if (area.x == 0.0 && area.y == 0.0 && area.z == 0.0) return false;
    const double det = U + V + W;
    if (det == 0.0 || std::isnan(det)) return false;

    // Edge ownership where the ray passes exactly through an edge or vertex.
    const double orientation = det > 0.0 ? 1.0 : -1.0;
    if (U == 0.0 && !ownsEdge(orientation * (double(Cx) - Bx), orientation * (double(Cy) - By), alternateEdgeRule))
        return false;
    if (V == 0.0 && !ownsEdge(orientation * (double(Ax) - Cx), orientation * (double(Ay) - Cy), alternateEdgeRule))
        return false;
    if (W == 0.0 && !ownsEdge(orientation * (double(Bx) - Ax), orientation * (double(By) - Ay), alternateEdgeRule))
        return false;

    const double Az = double(Sz) * axis(A, kz), Bz = double(Sz) * axis(B, kz), Cz = double(Sz) * axis(C, kz);
    const double T = U * Az + V * Bz + W * Cz;
    hit.t = float(T / det);
    hit.barycentrics = vec2(float(V / det), float(W / det));
    return true;
}

inline std::optional<TriangleIntersection> intersectTriangle(vec3 origin, vec3 direction, vec3 v0, vec3 v1, vec3 v2,
                                                             bool alternateEdgeRule = false) {
    TriangleIntersection hit;
    if (!intersectTriangle(origin, direction, v0, v1, v2, alternateEdgeRule, hit)) return std::nullopt;
    return hit;
}

// The part of [tMin, tMax] inside the box, bounds inclusive, into `interval`. A zero
// direction component (+0 or -0) keeps the ray inside the slab iff the origin lies
// within it, so 0*inf never happens. False when the ray does not touch the box within
// the interval.
[[gnu::always_inline]] inline bool intersectAABB(vec3 origin, vec3 direction, const RaytracingAABB& box, float tMin,
                                                 float tMax, SlabInterval& interval) {
    const float lo[3] = {box.MinX, box.MinY, box.MinZ};
    const float hi[3] = {box.MaxX, box.MaxY, box.MaxZ};
    float tEnter = tMin, tExit = tMax;
    for (int axis = 0; axis < 3; ++axis) {
        const float o = origin[axis], d = direction[axis];
        if (d == 0.0f) {
            // Parallel to the slab (either sign of zero): inside iff the origin is.
            if (o < lo[axis] || o > hi[axis]) return false;
            continue;
        }
        float t0 = (lo[axis] - o) / d, t1 = (hi[axis] - o) / d;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > tEnter) tEnter = t0;
        if (t1 < tExit) tExit = t1;
        if (!(tEnter <= tExit)) return false;
    }
    interval.tEnter = tEnter;
    interval.tExit = tExit;
    return true;
}

inline std::optional<SlabInterval> intersectAABB(vec3 origin, vec3 direction, const RaytracingAABB& box, float tMin,
                                                 float tMax) {
    SlabInterval interval;
    if (!intersectAABB(origin, direction, box, tMin, tMax, interval)) return std::nullopt;
    return interval;
}

}  // namespace refray::dxr
