// Ports: D3D12 sample VolumetricPrimitives.hlsli (N_METABALLS = 3, static loops, no
// active-ball limiting): quintic potential, central-difference normal, animated keyframes,
// bounding-sphere span and the fixed 128-sample march.
// Every function here also runs over lanes (T = Lanes<float, N>, one ray per lane; procedural/math/lanes.h), lane i
// bit for bit the scalar float result for ray i; InitializeAnimatedMetaballs with lanes of one time gives the same
// blobs in every lane.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "procedural/math/analytic.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/ray.h"

namespace refray::procedural::math {

template <typename T>
struct Metaball {
    vec3<T> center;
    T radius;
};

inline constexpr int N_METABALLS = 3;

template <typename T>
using Metaballs = std::array<Metaball<T>, N_METABALLS>;

// Potential of one ball: with d = radius - |position - center| (inside the radius),
// 6 d^5/r^5 - 15 d^4/r^4 + 10 d^3/r^3: 1 at the centre, 0 at the radius; 0 outside.
// PORT: for lanes the `if` is taken when some ray is inside, and the rays outside select 0.
template <typename T>
T CalculateMetaballPotential(const vec3<T>& position, const Metaball<T>& blob, T& distance) {
    distance = hlsl::length(position - blob.center);
    const LaneMask<T> inside = distance <= blob.radius;
    if (anyLane(inside)) {
        T d = distance;
        d = blob.radius - d;
        const T r = blob.radius;
        return select(inside,
                      T(6) * (d * d * d * d * d) / (r * r * r * r * r) - T(15) * (d * d * d * d) / (r * r * r * r) +
                          T(10) * (d * d * d) / (r * r * r),
                      T(0));
    }
    return T(0);
}

template <typename T>
T CalculateMetaballsPotential(const vec3<T>& position, const Metaballs<T>& blobs) {
    T sumFieldPotential = T(0);
    for (int j = 0; j < N_METABALLS; j++) {
        T dummy;
        sumFieldPotential += CalculateMetaballPotential(position, blobs[j], dummy);
    }
    return sumFieldPotential;
}

// The central-difference step of CalculateMetaballsNormal, e = 0.5773e-5. `0.5773 * 0.00001` is a literal-only
// product: folded at full precision, then rounded.
template <typename T>
T metaballsNormalOffset() { return static_cast<T>(0.5773 * 0.00001); }

// Minus the central-difference gradient, normalised (points outward); e = 0.5773e-5 by default.
// A zero gradient gives a NaN normal (D3D12 H11).
// PORT: e is a constant in the HLSL; as a parameter it carries the normalEpsilonFactor knob (procedural/accuracy.h).
template <typename T>
vec3<T> CalculateMetaballsNormal(const vec3<T>& position, const Metaballs<T>& blobs, T e = metaballsNormalOffset<T>()) {
    return hlsl::normalize(vec3<T>(CalculateMetaballsPotential(position + vec3<T>(-e, 0, 0), blobs) -
                                       CalculateMetaballsPotential(position + vec3<T>(e, 0, 0), blobs),
                                   CalculateMetaballsPotential(position + vec3<T>(0, -e, 0), blobs) -
                                       CalculateMetaballsPotential(position + vec3<T>(0, e, 0), blobs),
                                   CalculateMetaballsPotential(position + vec3<T>(0, 0, -e), blobs) -
                                       CalculateMetaballsPotential(position + vec3<T>(0, 0, e), blobs)));
}

// Centres lerp between two keyframes by CalculateAnimationInterpolant(elapsedTime, cycleDuration).
template <typename T>
Metaballs<T> InitializeAnimatedMetaballs(T elapsedTime, T cycleDuration) {
    const vec3<T> keyFrameCenters[N_METABALLS][2] = {
        {vec3<T>(T(-0.3), T(-0.3), T(-0.4)), vec3<T>(T(0.3), T(-0.3), T(-0.0))},
        {vec3<T>(T(0.0), T(-0.2), T(0.5)), vec3<T>(T(0.0), T(0.4), T(0.5))},
        {vec3<T>(T(0.4), T(0.4), T(0.4)), vec3<T>(T(-0.4), T(0.2), T(-0.4))},
    };
    const T radii[N_METABALLS] = {T(0.45), T(0.55), T(0.45)};

    const T tAnimate = CalculateAnimationInterpolant(elapsedTime, cycleDuration);
    Metaballs<T> blobs{};
    for (int j = 0; j < N_METABALLS; j++) {
        blobs[j].center = hlsl::lerp(keyFrameCenters[j][0], keyFrameCenters[j][1], tAnimate);
        blobs[j].radius = radii[j];
    }
    return blobs;
}

// Union of the balls' solid-sphere spans (roots in front or behind), clipped to [TMin, TCurrent].
// A ray missing every ball leaves tmin = +inf, tmax = -inf before the clip (D3D12 H8).
// PORT: the `if` on a ball's hit is a select per ray.
template <typename T>
void FindIntersectingMetaballs(const Ray<T>& ray, const RayExtent<T>& extent, T& tmin, T& tmax,
                               const Metaballs<T>& blobs) {
    tmin = infinityOf<T>();
    tmax = -infinityOf<T>();
    for (int i = 0; i < N_METABALLS; i++) {
        T _thit = T(0);
        T _tmax = T(0);
        const LaneMask<T> hit =
            RaySolidSphereIntersectionTest(ray, extent, _thit, _tmax, blobs[i].center, blobs[i].radius);
        if (anyLane(hit)) {
            tmin = select(hit, hlsl::min(_thit, tmin), tmin);
            tmax = select(hit, hlsl::max(_tmax, tmax), tmax);
        }
    }
    tmin = hlsl::max(tmin, extent.tMin);
    tmax = hlsl::min(tmax, extent.tCurrent);
}

// The constants of RayMetaballsIntersectionTest; the defaults are the HLSL's.
// PORT: constants in the HLSL; as parameters they carry the metaballSteps and normalEpsilonFactor knobs
// (procedural/accuracy.h).
template <typename T>
struct MetaballsParams {
    std::uint32_t maxSteps = 128;                 // MAX_STEPS: the samples, and the divisor of the step
    T normalOffset = metaballsNormalOffset<T>();  // CalculateMetaballsNormal's e
};

// PORT: hit is a LaneMask<T> and step a LaneUint<T>: bool and std::uint32_t for a scalar T, one per ray for lanes.
template <typename T>
struct MetaballsHit {
    LaneMask<T> hit = LaneMask<T>(false);
    T thit = T(0);
    vec3<T> normal{};
    LaneUint<T> step = LaneUint<T>(0);  // 1-based index of the sample that hit
};

// MAX_STEPS (128) samples t = tmin + k*(tmax - tmin)/MAX_STEPS; the first sample with potential >= 0.25 whose
// normal passes IsAValidHit is the hit (no refinement: up to one step inside the surface).
// The step depends on TCurrent at call time (D3D12 H10); with no ball hit the samples are
// inf/NaN and nothing is reported (H8).
// PORT: for lanes, `running` holds the rays that have not returned; each sample is computed for all lanes and the
// rays that are done keep their t. The loop ends when no ray runs (for a scalar T: at the `return`).
template <typename T>
MetaballsHit<T> RayMetaballsIntersectionTest(const Ray<T>& ray, const RayExtent<T>& extent, T elapsedTime,
                                             T cycleDuration = T(12), const MetaballsParams<T>& params = {}) {
    MetaballsHit<T> result;
    const Metaballs<T> blobs = InitializeAnimatedMetaballs(elapsedTime, cycleDuration);

    T tmin = T(0);
    T tmax = T(0);
    FindIntersectingMetaballs(ray, extent, tmin, tmax, blobs);

    const std::uint32_t MAX_STEPS = params.maxSteps;
    T t = tmin;
    const T minTStep = (tmax - tmin) / static_cast<T>(MAX_STEPS / 1);
    std::uint32_t iStep = 0;
    // PORT: a ray that misses every ball (tmin = +inf after the clip, H8; or TMin = +inf) samples only infinite and
    // NaN positions, whose potential is 0 (`distance <= radius` fails), so no sample can be a candidate: it leaves
    // the loop at once with the result it would have after MAX_STEPS samples (no hit), instead of taking them.
    LaneMask<T> running = !(tmin == infinityOf<T>());

    while (iStep++ < MAX_STEPS && anyLane(running)) {
        const LiveLanes live(running);
        const vec3<T> position = ray.origin + t * ray.direction;
        T sumFieldPotential = T(0);
        for (int j = 0; j < N_METABALLS; j++) {
            T distance;
            sumFieldPotential += CalculateMetaballPotential(position, blobs[j], distance);
        }

        const T Threshold = T(0.25);
        const LaneMask<T> candidate = running && sumFieldPotential >= Threshold;
        if (anyLane(candidate)) {
            const vec3<T> normal = CalculateMetaballsNormal(position, blobs, params.normalOffset);
            const LaneMask<T> accepted = candidate && IsAValidHit(ray, t, normal, extent);
            // if (IsAValidHit(...)) { ...; return true; }
            result.hit = result.hit || accepted;
            result.thit = select(accepted, t, result.thit);
            result.normal = select(accepted, normal, result.normal);
            result.step = select(accepted, LaneUint<T>(iStep), result.step);
            running = running && !accepted;
        }
        t = select(running, t + minTStep, t);  // t += minTStep
    }
    return result;
}

}  // namespace refray::procedural::math
