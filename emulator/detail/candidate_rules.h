// The tests TRV-4 applies to a candidate before any shader runs: opacity (OPQ-1), facing (FACE-1..5) and the
// culling ray flags (FLAG-10, FLAG-11). Shared by candidate processing and the traversal shortcut that must
// predict it. Internal to the emulator.
#pragma once

#include <cstdint>

#include "emulator/acceleration_structure.h"
#include "emulator/embree_bridge.h"
#include "emulator/types.h"

namespace refray::dxr::detail {

// OPQ-1: opacity from the geometry, instance and ray flags.
inline bool isOpaque(uint32_t geometryFlags, uint32_t instanceFlags, uint32_t rayFlags) {
    bool opaque = (geometryFlags & GEOMETRY_FLAG_OPAQUE) != 0;
    if (instanceFlags & INSTANCE_FLAG_FORCE_OPAQUE) opaque = true;
    if (instanceFlags & INSTANCE_FLAG_FORCE_NON_OPAQUE) opaque = false;
    if (rayFlags & RAY_FLAG_FORCE_OPAQUE) opaque = true;
    if (rayFlags & RAY_FLAG_FORCE_NON_OPAQUE) opaque = false;
    return opaque;
}

// FACE-1..3: facing from the object-space winding; the instance transform never flips it.
inline bool isFrontFacing(const BuiltGeometry& geom, const Candidate& c, uint32_t instanceFlags) {
    const vec3* v = &geom.triangleVertices[size_t(c.primitiveIndex) * 3];
    const dvec3 e1 = dvec3(v[1]) - dvec3(v[0]), e2 = dvec3(v[2]) - dvec3(v[0]);
    const double facing = glm::dot(glm::cross(e1, e2), dvec3(c.objectRayDirection));
    bool front = facing < 0.0;
    if (instanceFlags & INSTANCE_FLAG_TRIANGLE_FRONT_COUNTERCLOCKWISE) front = !front;
    return front;
}

// FLAG-10, FACE-5: whether the ray's facing-culling flags drop this triangle.
inline bool isFaceCulled(uint32_t rayFlags, uint32_t instanceFlags, bool front) {
    if (instanceFlags & INSTANCE_FLAG_TRIANGLE_CULL_DISABLE) return false;
    return ((rayFlags & RAY_FLAG_CULL_BACK_FACING_TRIANGLES) && !front) ||
           ((rayFlags & RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) && front);
}

// FLAG-11.
inline bool isOpacityCulled(uint32_t rayFlags, bool opaque) {
    return ((rayFlags & RAY_FLAG_CULL_OPAQUE) && opaque) || ((rayFlags & RAY_FLAG_CULL_NON_OPAQUE) && !opaque);
}

}  // namespace refray::dxr::detail
