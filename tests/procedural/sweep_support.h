// What the tests and benchmarks of the procedural math share: seeded random directions, float rays with their
// exact double twins, the scenes' radiance ray extent and the Proceduray sample's canonical time.
#pragma once

#include <cstdint>
#include <cstring>
#include <random>

#include "procedural/math/ray.h"

namespace refray::procedural::math::fixtures {

// A uniformly distributed unit vector.
inline glm::dvec3 randomUnit(std::mt19937& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    for (;;) {
        const glm::dvec3 v(n(rng), n(rng), n(rng));
        const double l = glm::length(v);
        if (l > 1e-6) return v / l;
    }
}

// A ray in float and the same ray promoted exactly to double, so that only the arithmetic differs.
struct RayPair {
    Ray<float> f;
    Ray<double> d;
};

// The ray from `origin` towards `aim`: float origin and unit float direction, then their double twins.
inline RayPair rayPair(const glm::dvec3& origin, const glm::dvec3& aim) {
    RayPair r;
    r.f.origin = glm::vec3(origin);
    r.f.direction = hlsl::normalize(glm::vec3(glm::normalize(aim - origin)));
    r.d.origin = glm::dvec3(r.f.origin);
    r.d.direction = glm::dvec3(r.f.direction);
    return r;
}

// The scenes' radiance rays: [0, 10000], back faces culled (both samples' radiance and shadow rays cull them).
template <typename T>
RayExtent<T> radianceExtent() {
    RayExtent<T> e;
    e.tMin = T(0);
    e.tCurrent = T(10000);
    e.cullBackFacing = true;
    return e;
}

// Proceduray fact sheet §1.9: the canonical time T1 as float bits 0x417D7CD8.
inline float canonicalT1() {
    const std::uint32_t bits = 0x417D7CD8u;
    float t = 0;
    std::memcpy(&t, &bits, sizeof t);
    return t;
}

}  // namespace refray::procedural::math::fixtures
