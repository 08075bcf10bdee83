// Fixed-function intersection tests the emulator applies itself: the watertight
// ray/triangle test (TRI-1..6) and the inclusive, NaN-free ray/AABB slab test (BLAS-7).
// Defined here, inline, so that the broad phase's callbacks (embree_bridge.cpp) take their results in registers: a
// result returned through memory was read back with wider loads than the stores that wrote it (a store-forwarding
// stall per tested primitive).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
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

// Up to 16 rays tested against one triangle at once (the broad phase meets a primitive with a packet of rays):
// intersectTriangleLanes, lane by lane the same float and double operations in the same order as intersectTriangle
// (no contraction: -ffp-contract=off), so each lane's result is bit for bit the one-ray test's. Lanes outside the
// tested ones hold any finite values (another lane's), and are reported in no mask.
// The boxes' slab test stays one ray at a time (in 16 lanes it measured no faster: the six divisions
// cost as much as the few rays a packet brings to a box).
struct RayLanes {
    static constexpr int kCount = 16;
    alignas(64) float ox[kCount], oy[kCount], oz[kCount];  // the rays' object-space origins
    alignas(64) float dx[kCount], dy[kCount], dz[kCount];  // and directions
    alignas(64) float t[kCount], b1[kCount], b2[kCount];   // out: each hit lane's t and barycentrics
    uint32_t hit = 0;    // out: the lanes that hit (at any t)
    uint32_t exact = 0;  // out: the lanes left to the one-ray test
};

namespace intersection_detail {
using Floats16 = float __attribute__((vector_size(64)));
using Ints16 = int32_t __attribute__((vector_size(64)));
using Floats8 = float __attribute__((vector_size(32)));
using Doubles8 = double __attribute__((vector_size(64)));

// axis(v, k) per lane.
inline Floats16 pickAxis(Ints16 k, Floats16 x, Floats16 y, Floats16 z) { return k == 0 ? x : (k == 1 ? y : z); }
inline uint32_t bitsOf(Ints16 m) {
    uint32_t bits = 0;
    for (int i = 0; i < 16; ++i) bits |= (m[i] != 0 ? 1u : 0u) << i;
    return bits;
}
inline Doubles8 lowHalf(Floats16 x) {
    return __builtin_convertvector(__builtin_shufflevector(x, x, 0, 1, 2, 3, 4, 5, 6, 7), Doubles8);
}
inline Doubles8 highHalf(Floats16 x) {
    return __builtin_convertvector(__builtin_shufflevector(x, x, 8, 9, 10, 11, 12, 13, 14, 15), Doubles8);
}
}  // namespace intersection_detail

// intersectTriangle of each lane of `lanes`: a lane whose float edge functions have an exact zero (an edge or vertex
// in the ray's path, where ownership decides, in double) is left to the one-ray test, as `exact`.
inline void intersectTriangleLanes(vec3 v0, vec3 v1, vec3 v2, uint32_t lanes, RayLanes& r) {
    using namespace intersection_detail;
    r.hit = r.exact = 0;
    // DEGEN-7 (a triangle of collinear vertices): the same for every ray, and every ray misses it.
    const glm::dvec3 area = glm::cross(glm::dvec3(v1) - glm::dvec3(v0), glm::dvec3(v2) - glm::dvec3(v0));
    const bool degenerate = area.x == 0.0 && area.y == 0.0 && area.z == 0.0;
    Floats16 ox, oy, oz, dx, dy, dz;
    std::memcpy(&ox, r.ox, sizeof ox);
    std::memcpy(&oy, r.oy, sizeof oy);
    std::memcpy(&oz, r.oz, sizeof oz);
    std::memcpy(&dx, r.dx, sizeof dx);
    std::memcpy(&dy, r.dy, sizeof dy);
    std::memcpy(&dz, r.dz, sizeof dz);
    const Ints16 absMask = Ints16{} + 0x7FFFFFFF;
    const Floats16 ax = Floats16(Ints16(dx) & absMask), ay = Floats16(Ints16(dy) & absMask),
                   az = Floats16(Ints16(dz) & absMask);
    // largestAxis, then kx = (kz + 1) % 3, ky = (kx + 1) % 3, swapped where the direction's kz is negative.
    const Ints16 zero = Ints16{}, one = zero + 1, two = zero + 2;
    const Ints16 kz = ax > ay ? (ax > az ? zero : two) : (ay > az ? one : two);
    const Ints16 kx0 = kz == 2 ? zero : kz + 1;
    const Ints16 ky0 = kx0 == 2 ? zero : kx0 + 1;
    const Floats16 dkz = pickAxis(kz, dx, dy, dz);
    const Ints16 negative = dkz < 0.0f;
    const Ints16 kx = negative ? ky0 : kx0, ky = negative ? kx0 : ky0;
    const Ints16 invalid = (dkz == 0.0f) | (dkz != dkz);
    const Floats16 Sx = pickAxis(kx, dx, dy, dz) / dkz, Sy = pickAxis(ky, dx, dy, dz) / dkz, Sz = 1.0f / dkz;

    const auto sheared = [&](vec3 v, Floats16& X, Floats16& Y, Floats16& Z) {
        const Floats16 px = v.x - ox, py = v.y - oy, pz = v.z - oz;
        Z = pickAxis(kz, px, py, pz);
        X = pickAxis(kx, px, py, pz) - Sx * Z;
        Y = pickAxis(ky, px, py, pz) - Sy * Z;
    };
    Floats16 Ax, Ay, Akz, Bx, By, Bkz, Cx, Cy, Ckz;
    sheared(v0, Ax, Ay, Akz);
    sheared(v1, Bx, By, Bkz);
    sheared(v2, Cx, Cy, Ckz);
    const Floats16 U = Cx * By - Cy * Bx;
    const Floats16 V = Ax * Cy - Ay * Cx;
    const Floats16 W = Bx * Ay - By * Ax;
    const Ints16 onEdge = (U == 0.0f) | (V == 0.0f) | (W == 0.0f);
    const Ints16 mixed = ((U < 0.0f) | (V < 0.0f) | (W < 0.0f)) & ((U > 0.0f) | (V > 0.0f) | (W > 0.0f));
    const uint32_t valid = lanes & ~bitsOf(invalid);
    r.exact = degenerate ? 0u : valid & bitsOf(onEdge);
    uint32_t candidates = degenerate ? 0u : valid & ~bitsOf(onEdge | mixed);
    if (!candidates) return;
    // det, T, t and the barycentrics in double, eight lanes at a time.
    for (int half = 0; half < 2; ++half) {
        const auto widen = [half](Floats16 x) { return half == 0 ? lowHalf(x) : highHalf(x); };
        const Doubles8 u = widen(U), v = widen(V), w = widen(W);
        const Doubles8 det = u + v + w;
        const Doubles8 sz = widen(Sz);
        const Doubles8 T = u * (sz * widen(Akz)) + v * (sz * widen(Bkz)) + w * (sz * widen(Ckz));
        const Doubles8 t = T / det, b1 = v / det, b2 = w / det;
        for (int j = 0; j < 8; ++j) {
            const int i = half * 8 + j;
            if (!(candidates >> i & 1u)) continue;
            if (det[j] == 0.0 || std::isnan(det[j])) {
                candidates &= ~(1u << i);
                continue;
            }
            r.t[i] = float(t[j]);
            r.b1[i] = float(b1[j]);
            r.b2[i] = float(b2[j]);
        }
    }
    r.hit = candidates;
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
