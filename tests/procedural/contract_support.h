// What the two shader-library contract tests (d3d12_contract_test.cpp, proceduray_contract_test.cpp) share:
// geometry that blocks a ray, and the angle between two normals.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "core/math.h"
#include "emulator/types.h"

namespace refray::procedural::fixtures {

// An opaque triangle across `ray` at world distance t, front-facing to it (DXR: dot(d, (v1-v0)x(v2-v0)) < 0).
inline std::array<vec3, 3> occluderAcross(const dxr::RayDesc& ray, float t) {
    const vec3 d = glm::normalize(ray.Direction);
    const vec3 u = glm::normalize(glm::cross(d, std::abs(d.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0)));
    const vec3 v = glm::cross(d, u);
    const vec3 c = ray.Origin + t * ray.Direction;
    std::array<vec3, 3> tri = {c - 0.5f * u - 0.5f * v, c + 0.5f * u - 0.5f * v, c + 0.5f * v};
    if (glm::dot(d, glm::cross(tri[1] - tri[0], tri[2] - tri[0])) > 0.0f) std::swap(tri[1], tri[2]);
    return tri;
}

// The angle between two directions, in radians, computed in double.
inline double angleBetween(vec3 a, vec3 b) {
    return std::acos(std::clamp(glm::dot(glm::normalize(glm::dvec3(a)), glm::normalize(glm::dvec3(b))), -1.0, 1.0));
}

}  // namespace refray::procedural::fixtures
