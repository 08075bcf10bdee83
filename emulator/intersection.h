// Fixed-function intersection tests the emulator applies itself: the watertight
// ray/triangle test (TRI-1..6) and the inclusive, NaN-free ray/AABB slab test (BLAS-7).
#pragma once

#include <optional>

#include "core/math.h"
#include "emulator/acceleration_structure.h"

namespace refray::dxr {

struct TriangleIntersection {
    float t = 0.0f;
    vec2 barycentrics{0.0f};  // x weights v1, y weights v2 (SV-12)
};

// Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection" (JCGT 2013): per-ray
// axis permutation and shear, edge functions recomputed in double when one is exactly
// zero, and an explicit edge-ownership rule so a ray through a shared edge or vertex
// hits exactly one triangle (TRI-2, TRI-4). Returns the hit for any t (the caller
// applies the ray interval); nothing for a miss, a degenerate triangle or a ray parallel
// to the plane (TRI-5, DEGEN-7). `alternateEdgeRule` swaps which side owns an edge
// (the adversarial mode of GEN-3); either rule is watertight.
std::optional<TriangleIntersection> intersectTriangle(vec3 origin, vec3 direction, vec3 v0, vec3 v1, vec3 v2,
                                                      bool alternateEdgeRule = false);

struct SlabInterval {
    float tEnter = 0.0f;
    float tExit = 0.0f;
};

// The part of [tMin, tMax] inside the box, bounds inclusive. A zero direction component
// (+0 or -0) keeps the ray inside the slab iff the origin lies within it, so 0*inf never
// happens. Empty when the ray does not touch the box within the interval.
std::optional<SlabInterval> intersectAABB(vec3 origin, vec3 direction, const RaytracingAABB& box, float tMin,
                                          float tMax);

}  // namespace refray::dxr
