// The path tracer's pure math (refray's own, not a port): per-pixel random numbers, frames, the material's BSDF
// (Lambert plus a normalized Phong lobe), uniform triangle sampling, the area-to-solid-angle conversion of
// next-event estimation, the power heuristic and Russian roulette. Header-only, allocation-free, templated on the
// scalar type; the shaders (pathtracer_shaders.cpp) instantiate float.
//
// The estimator these pieces make (pathtracer_shaders.h has the whole recipe): at every path vertex, light is
// gathered twice and the two are combined with the power heuristic (Veach 1997, MIS with beta = 2):
//   - next-event estimation: a light triangle chosen uniformly (1 / lightCount), a point on it uniform by area
//     (1 / area), converted to solid angle (distance^2 / cos at the light);
//   - BSDF sampling: the direction the path continues in; if it hits an emitter, that emission counts with the
//     BSDF pdf's weight. Emission seen by camera rays counts in full (no other strategy can find it), and so does
//     the background (no light strategy samples it).
// Each weight uses both pdfs of the same path, so the weights of every path sum to one and the estimator is
// unbiased; Russian roulette divides the survivors by their survival probability, which keeps the expectation.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "core/math.h"
#include "core/random.h"

namespace refray::procedural::pathtracer {

template <typename T>
using tvec2 = glm::vec<2, T>;
template <typename T>
using tvec3 = glm::vec<3, T>;

template <typename T>
inline constexpr T kPi = std::numbers::pi_v<T>;

// ---- Random numbers ------------------------------------------------------------------------------------------
//
// One stream per (pixel, sample, seed): the state starts at
//   pcgHash(x + pcgHash(y + pcgHash(sample + pcgHash(seed))))
// (core/random.h's PCG output permutation, so every key bit reaches every state bit) and each draw advances a PCG32
// LCG (state * 747796405 + 2891336453) and returns the RXS-M-XS permutation of the new state. A path draws its
// numbers in a fixed order from its own stream, so a pixel's value depends only on the scene, the constants and
// the pixel: never on threads or tile order.
struct PathRng {
    uint32_t state = 0;
};

inline PathRng makePathRng(uint32_t x, uint32_t y, uint32_t sample, uint32_t seed) {
    return PathRng{pcgHash(x + pcgHash(y + pcgHash(sample + pcgHash(seed))))};
}

inline uint32_t nextUint(PathRng& rng) {
    rng.state = rng.state * 747796405u + 2891336453u;
    const uint32_t word = ((rng.state >> ((rng.state >> 28u) + 4u)) ^ rng.state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform in [0, 1): the top 24 bits times 2^-24, exact in float, so 1 is never returned.
template <typename T = float>
T nextUniform(PathRng& rng) {
    return T(nextUint(rng) >> 8) * T(1.0 / 16777216.0);
}

// ---- Frames --------------------------------------------------------------------------------------------------

// t, b such that (t, b, n) is a right-handed orthonormal basis for the unit vector n (Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited": branchless and continuous except at the sign flip of n.z).
template <typename T>
void orthonormalBasis(tvec3<T> n, tvec3<T>& t, tvec3<T>& b) {
    const T sign = std::copysign(T(1), n.z);
    const T a = T(-1) / (sign + n.z);
    const T c = n.x * n.y * a;
    t = tvec3<T>(T(1) + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = tvec3<T>(c, sign + n.y * n.y * a, -n.y);
}

// `local` (z along n) in the frame of n.
template <typename T>
tvec3<T> fromLocal(tvec3<T> local, tvec3<T> n) {
    tvec3<T> t, b;
    orthonormalBasis(n, t, b);
    return local.x * t + local.y * b + local.z * n;
}

// ---- Cosine-weighted hemisphere ------------------------------------------------------------------------------

// A direction about +z with density cos(theta) / pi (Malley's method: a uniform disk point lifted to the
// hemisphere). u1, u2 in [0, 1).
template <typename T>
tvec3<T> sampleCosineHemisphere(T u1, T u2) {
    const T r = std::sqrt(u1);
    const T phi = T(2) * kPi<T> * u2;
    return tvec3<T>(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(T(0), T(1) - u1)));
}

// cos(theta) / pi above the surface, 0 below.
template <typename T>
T cosineHemispherePdf(T cosTheta) {
    return cosTheta > T(0) ? cosTheta / kPi<T> : T(0);
}

// ---- The glossy lobe: normalized modified Phong ----------------------------------------------------------------
//
// f_glossy(wo, wi) = Ks * (n + 2) / (2 pi) * max(0, cos alpha)^n, alpha the angle between wi and the mirror
// direction of wo, n = MaterialGPU::shininess (the MTL's Ns; MaterialGPU::specularRoughness.w = sqrt(2 / (Ns + 2))
// is the same information as a Beckmann roughness). The factor (n + 2) / (2 pi) makes the reflected fraction
// exactly 1 at normal incidence and less elsewhere (Lafortune and Willems 1994, "Using the Modified Phong
// Reflectance Model for Physically Based Rendering"), so with Kd + Ks <= 1 the material never creates energy.

// Density of samplePhongLobe: (n + 1) / (2 pi) * cos(alpha)^n on the hemisphere about the mirror direction.
template <typename T>
T phongLobePdf(T cosAlpha, T exponent) {
    return cosAlpha > T(0) ? (exponent + T(1)) / (T(2) * kPi<T>) * std::pow(cosAlpha, exponent) : T(0);
}

// (n + 2) / (2 pi) * cos(alpha)^n: the lobe's BRDF without Ks.
template <typename T>
T phongLobeBrdf(T cosAlpha, T exponent) {
    return cosAlpha > T(0) ? (exponent + T(2)) / (T(2) * kPi<T>) * std::pow(cosAlpha, exponent) : T(0);
}

// A direction about +z (the mirror direction) with density phongLobePdf: cos(alpha) = u1^(1 / (n + 1)).
template <typename T>
tvec3<T> samplePhongLobe(T u1, T u2, T exponent) {
    const T cosAlpha = std::pow(T(1) - u1, T(1) / (exponent + T(1)));  // 1 - u1 in (0, 1]: never cos = 0
    const T sinAlpha = std::sqrt(std::max(T(0), T(1) - cosAlpha * cosAlpha));
    const T phi = T(2) * kPi<T> * u2;
    return tvec3<T>(sinAlpha * std::cos(phi), sinAlpha * std::sin(phi), cosAlpha);
}

// ---- The material's BSDF: Lambert + Phong ------------------------------------------------------------------
//
// f(wo, wi) = diffuse / pi + specular * phongLobeBrdf, zero unless wo and wi both lie above the shading normal.
// Sampling picks the glossy lobe with probability specularProbability (the glossy share of the summed
// reflectances) and otherwise the cosine lobe; the pdf of a direction is the mixture of both (one-sample MIS over
// the lobes with the balance heuristic), which is what the MIS weights against light sampling use.

template <typename T>
struct SurfaceBsdf {
    tvec3<T> diffuse{T(0)};   // Kd times the diffuse texture
    tvec3<T> specular{T(0)};  // Ks
    T exponent = T(0);        // Ns
    T specularProbability = T(0);
};

// Scales Kd and Ks down together where a channel of Kd + Ks exceeds 1 (the MTL allows it; energy conservation
// does not), then sets the lobe probability.
template <typename T>
SurfaceBsdf<T> makeSurfaceBsdf(tvec3<T> diffuse, tvec3<T> specular, T exponent) {
    SurfaceBsdf<T> bsdf;
    const tvec3<T> sum = diffuse + specular;
    const T largest = std::max({sum.x, sum.y, sum.z});
    const T scale = largest > T(1) ? T(1) / largest : T(1);
    bsdf.diffuse = diffuse * scale;
    bsdf.specular = specular * scale;
    bsdf.exponent = std::max(T(0), exponent);
    const T d = bsdf.diffuse.x + bsdf.diffuse.y + bsdf.diffuse.z;
    const T s = bsdf.specular.x + bsdf.specular.y + bsdf.specular.z;
    bsdf.specularProbability = s > T(0) ? s / (d + s) : T(0);
    return bsdf;
}

// True when the BSDF reflects nothing (black Kd and Ks): the path ends there.
template <typename T>
bool isBlack(const SurfaceBsdf<T>& bsdf) {
    return bsdf.diffuse == tvec3<T>(T(0)) && bsdf.specular == tvec3<T>(T(0));
}

// The mirror direction of wo (pointing away from the surface) about the unit normal n.
template <typename T>
tvec3<T> mirror(tvec3<T> wo, tvec3<T> n) {
    return T(2) * glm::dot(n, wo) * n - wo;
}

// f(wo, wi), without the cosine. n: the unit shading normal; wo, wi: unit, pointing away from the surface.
template <typename T>
tvec3<T> evalBsdf(const SurfaceBsdf<T>& bsdf, tvec3<T> n, tvec3<T> wo, tvec3<T> wi) {
    if (glm::dot(n, wo) <= T(0) || glm::dot(n, wi) <= T(0)) return tvec3<T>(T(0));
    tvec3<T> f = bsdf.diffuse / kPi<T>;
    if (bsdf.specularProbability > T(0))
        f += bsdf.specular * phongLobeBrdf(glm::dot(mirror(wo, n), wi), bsdf.exponent);
    return f;
}

// The density of sampleBsdf's direction wi (solid angle), including directions below the surface (which the
// glossy lobe may produce and evalBsdf makes worthless).
template <typename T>
T bsdfPdf(const SurfaceBsdf<T>& bsdf, tvec3<T> n, tvec3<T> wo, tvec3<T> wi) {
    const T ps = bsdf.specularProbability;
    T pdf = (T(1) - ps) * cosineHemispherePdf(glm::dot(n, wi));
    if (ps > T(0)) pdf += ps * phongLobePdf(glm::dot(mirror(wo, n), wi), bsdf.exponent);
    return pdf;
}

template <typename T>
struct BsdfSample {
    tvec3<T> wi{T(0)};
    T pdf = T(0);               // bsdfPdf(wi)
    tvec3<T> weight{T(0)};      // f(wo, wi) * cos(theta_i) / pdf: what the throughput is multiplied by
};

// u0 picks the lobe, (u1, u2) the direction in it. A sample with weight 0 (below the surface) ends the path.
template <typename T>
BsdfSample<T> sampleBsdf(const SurfaceBsdf<T>& bsdf, tvec3<T> n, tvec3<T> wo, T u0, T u1, T u2) {
    BsdfSample<T> s;
    if (u0 < bsdf.specularProbability)
        s.wi = fromLocal(samplePhongLobe(u1, u2, bsdf.exponent), mirror(wo, n));
    else
        s.wi = fromLocal(sampleCosineHemisphere(u1, u2), n);
    s.pdf = bsdfPdf(bsdf, n, wo, s.wi);
    const T cosTheta = glm::dot(n, s.wi);
    if (s.pdf > T(0) && cosTheta > T(0)) s.weight = evalBsdf(bsdf, n, wo, s.wi) * (cosTheta / s.pdf);
    return s;
}

// ---- Triangles -----------------------------------------------------------------------------------------------

template <typename T>
T triangleArea(tvec3<T> v0, tvec3<T> v1, tvec3<T> v2) {
    return T(0.5) * glm::length(glm::cross(v1 - v0, v2 - v0));
}

// A point uniform by area on the triangle (density 1 / area): barycentrics (1 - sqrt(u1), u2 sqrt(u1)) for
// (v0, v1), the rest for v2 (Osada et al. 2002, "Shape Distributions", section 4.2).
template <typename T>
tvec3<T> sampleTriangleUniform(tvec3<T> v0, tvec3<T> v1, tvec3<T> v2, T u1, T u2) {
    const T su = std::sqrt(u1);
    const T b0 = T(1) - su, b1 = u2 * su;
    return b0 * v0 + b1 * v1 + (T(1) - b0 - b1) * v2;
}

template <typename T>
T triangleAreaPdf(T area) {
    return area > T(0) ? T(1) / area : T(0);
}

// ---- Next-event estimation and MIS --------------------------------------------------------------------------

// A density over area at a point `distance` away, seen at `cosLight` to the light's normal, as a density over
// the solid angle at the shading point: pdfArea * distance^2 / |cosLight| (0 at grazing incidence).
template <typename T>
T areaToSolidAnglePdf(T pdfArea, T distance, T cosLight) {
    const T c = std::fabs(cosLight);
    return c > T(0) ? pdfArea * distance * distance / c : T(0);
}

// The power heuristic with beta = 2 for one sample from each strategy: f^2 / (f^2 + g^2); 0 when both are 0.
template <typename T>
T powerHeuristic(T pdfThis, T pdfOther) {
    const T a = pdfThis * pdfThis, b = pdfOther * pdfOther;
    return a > T(0) ? a / (a + b) : T(0);
}

// ---- Russian roulette ----------------------------------------------------------------------------------------
//
// Once a path has bounced three times (at vertex kRussianRouletteStartBounce and later, vertices counted from 0 at
// the camera ray's hit, after the next direction is sampled), it survives with probability
// q = min(max throughput component, 0.95) and survivors divide their throughput by q: the expectation
// q * (throughput / q) + (1 - q) * 0 is the throughput, so the estimator stays unbiased.
inline constexpr uint32_t kRussianRouletteStartBounce = 3;
inline constexpr float kRussianRouletteMaxSurvival = 0.95f;

template <typename T>
T russianRouletteSurvival(tvec3<T> throughput) {
    return std::min(std::max({throughput.x, throughput.y, throughput.z}), T(kRussianRouletteMaxSurvival));
}

// Applies the roulette with the uniform number u: false ends the path, true divides throughput by the survival
// probability.
template <typename T>
bool russianRoulette(tvec3<T>& throughput, T u) {
    const T q = russianRouletteSurvival(throughput);
    if (!(q > T(0)) || u >= q) return false;
    throughput /= q;
    return true;
}

}  // namespace refray::procedural::pathtracer
