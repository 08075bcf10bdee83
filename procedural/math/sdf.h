// Ports: SignedDistancePrimitives.hlsli (both samples); SDF cases of D3D12 ProceduralPrimitivesLibrary.hlsli.
// Operators, primitives, sdCalculateNormal and RaySignedDistancePrimitiveTest, templated on T;
// the fractal pyramid and the D3D12 switch live in fractals.h.
// Every function here also runs over lanes (T = Lanes<float, N>, one ray per lane; procedural/math/lanes.h), lane i
// bit for bit the scalar float result for ray i.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "procedural/accuracy.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/march_queue.h"
#include "procedural/math/ray.h"

namespace refray::procedural::math {

// ---- Operators -------------------------------------------------------------------------------
// Subtract: Obj1 - Obj2 = max(d1, -d2).
template <typename T>
T opS(T d1, T d2) { return hlsl::max(d1, -d2); }
// Union = min(d1, d2).
template <typename T>
T opU(T d1, T d2) { return hlsl::min(d1, d2); }
// Intersection = max(d1, d2).
template <typename T>
T opI(T d1, T d2) { return hlsl::max(d1, d2); }

// Repetition with the HLSL fmod intrinsic: no repetition for negative p (sign of the dividend,
// D3D12 H14), and DXC's frac-based remainder at cell boundaries.
// PORT: fmod component by component: hlsl.h's vector fmod is defined before the lanes' fmod (lanes.h), so for
// T = Lanes it would reach the scalar lowering with its ?: on a lane mask. The same three remainders, in order.
template <typename T>
vec3<T> opRep(const vec3<T>& p, const vec3<T>& c) {
    return vec3<T>(hlsl::fmod(p.x, c.x), hlsl::fmod(p.y, c.y), hlsl::fmod(p.z, c.z)) - T(0.5) * c;
}

// Polynomial smooth min (union) and smooth max (intersection).
template <typename T>
T smin(T a, T b, T k) {
    const T h = hlsl::clamp(T(0.5) + T(0.5) * (b - a) / k, T(0), T(1));
    return hlsl::lerp(b, a, h) - k * h * (T(1) - h);
}
template <typename T>
T smax(T a, T b, T k) {
    const T h = hlsl::clamp(T(0.5) + T(0.5) * (b - a) / k, T(0), T(1));
    return hlsl::lerp(a, b, h) + k * h * (T(1) - h);
}
template <typename T>
T opBlendU(T d1, T d2) { return smin(d1, d2, T(0.1)); }
template <typename T>
T opBlendI(T d1, T d2) { return smax(d1, d2, T(0.1)); }

// Twist about y: (c*x - s*z, s*x + c*z, y) with c = cos 3y, s = sin 3y. Note the component
// order: the rotated xz pair goes to .xy and the old y to .z, as the HLSL writes it.
template <typename T>
vec3<T> opTwist(const vec3<T>& p) {
    const T c = hlsl::cos(T(3) * p.y);
    const T s = hlsl::sin(T(3) * p.y);
    // float2x2 m = (c, -s, s, c); mul(m, p.xz)
    return vec3<T>(c * p.x - s * p.z, s * p.x + c * p.z, p.y);
}

// ---- Primitives ------------------------------------------------------------------------------
template <typename T>
T sdPlane(const vec3<T>& p) { return p.y; }

template <typename T>
T sdSphere(const vec3<T>& p, T s) { return hlsl::length(p) - s; }

// Box extents <-b, b>.
template <typename T>
T sdBox(const vec3<T>& p, const vec3<T>& b) {
    const vec3<T> d = hlsl::abs(p) - b;
    return hlsl::min(hlsl::max(d.x, hlsl::max(d.y, d.z)), T(0)) + hlsl::length(hlsl::max(d, T(0)));
}

template <typename T>
T sdEllipsoid(const vec3<T>& p, const vec3<T>& r) {
    return (hlsl::length(p / r) - T(1)) * hlsl::min(hlsl::min(r.x, r.y), r.z);
}

// Unsigned rounded box: inner half-size b, rounding radius r.
template <typename T>
T udRoundBox(const vec3<T>& p, const vec3<T>& b, T r) {
    return hlsl::length(hlsl::max(hlsl::abs(p) - b, T(0))) - r;
}

// t = {ring radius, tube radius}; ring in the xz plane.
template <typename T>
T sdTorus(const vec3<T>& p, const vec2<T>& t) {
    const vec2<T> q(hlsl::length(vec2<T>(p.x, p.z)) - t.x, p.y);
    return hlsl::length(q) - t.y;
}

template <typename T>
T sdHexPrism(const vec3<T>& p, const vec2<T>& h) {
    const vec3<T> q = hlsl::abs(p);
    const T d1 = q.z - h.y;
    const T d2 = hlsl::max(q.x * T(0.866025) + q.y * T(0.5), q.y) - h.x;
    return hlsl::length(hlsl::max(vec2<T>(d1, d2), T(0))) + hlsl::min(hlsl::max(d1, d2), T(0));
}

// Capsule from a to b with radius r.
template <typename T>
T sdCapsule(const vec3<T>& p, const vec3<T>& a, const vec3<T>& b, T r) {
    const vec3<T> pa = p - a;
    const vec3<T> ba = b - a;
    const T h = hlsl::clamp(hlsl::dot(pa, ba) / hlsl::dot(ba, ba), T(0), T(1));
    return hlsl::length(pa - ba * h) - r;
}

// Triangular prism along z (the "distance bound" branch, #if 1 in the HLSL):
// h.x = triangle size, h.y = half length. Note p.y (not |p.y|) in d2.
template <typename T>
T sdTriPrism(const vec3<T>& p, const vec2<T>& h) {
    const vec3<T> q = hlsl::abs(p);
    const T d1 = q.z - h.y;
    const T d2 = hlsl::max(q.x * T(0.866025) + p.y * T(0.5), -p.y) - h.x * T(0.5);
    return hlsl::length(hlsl::max(vec2<T>(d1, d2), T(0))) + hlsl::min(hlsl::max(d1, d2), T(0));
}

// Capped cylinder about y: h = {radius, half height}.
template <typename T>
T sdCylinder(const vec3<T>& p, const vec2<T>& h) {
    const vec2<T> d = hlsl::abs(vec2<T>(hlsl::length(vec2<T>(p.x, p.z)), p.y)) - h;
    return hlsl::min(hlsl::max(d.x, d.y), T(0)) + hlsl::length(hlsl::max(d, T(0)));
}

// h = {sin a, cos a, height}; octahedron centred at the origin (the ground plane cuts it).
template <typename T>
T sdOctahedron(const vec3<T>& p, const vec3<T>& h) {
    const T d = hlsl::dot(vec2<T>(hlsl::max(hlsl::abs(p.x), hlsl::abs(p.z)), hlsl::abs(p.y)), vec2<T>(h.x, h.y));
    return d - h.y * h.z;
}

// Pyramid sitting on y = 0: the octahedron minus its lower half.
template <typename T>
T sdPyramid(const vec3<T>& p, const vec3<T>& h) {
    const T octa = sdOctahedron(p, h);
    return opS(octa, p.y);
}

// (x^6 + y^6)^(1/6) through pow (exp2/log2).
template <typename T>
T length_toPowNegative6(vec2<T> p) {
    p = p * p * p;
    p = p * p;
    return hlsl::pow(p.x + p.y, T(1.0) / T(6.0));
}

// The L8 norm (x^8 + y^8)^(1/8), despite the HLSL name.
template <typename T>
T length_toPowNegative8(vec2<T> p) {
    p = p * p;
    p = p * p;
    p = p * p;
    return hlsl::pow(p.x + p.y, T(1.0) / T(8.0));
}

// Torus with an L8 ("square") tube cross-section.
template <typename T>
T sdTorus82(const vec3<T>& p, const vec2<T>& t) {
    const vec2<T> q(hlsl::length(vec2<T>(p.x, p.z)) - t.x, p.y);
    return length_toPowNegative8(q) - t.y;
}

template <typename T>
T sdTorus88(const vec3<T>& p, const vec2<T>& t) {
    const vec2<T> q(length_toPowNegative8(vec2<T>(p.x, p.z)) - t.x, p.y);
    return length_toPowNegative8(q) - t.y;
}

template <typename T>
T sdCylinder6(const vec3<T>& p, const vec2<T>& h) {
    return hlsl::max(length_toPowNegative6(vec2<T>(p.x, p.z)) - h.x, hlsl::abs(p.y) - h.y);
}

// ---- D3D12 sample: the SDF cases of GetDistanceFromSignedDistancePrimitive -----------------
// (local AABB space [-1,1]^3; FractalPyramid and the switch itself are in fractals.h)
// PORT: each switch case is a named function so entry points and tests can call it directly.
namespace d3d12 {

// 4x4x4 spheres of radius 0.1625 in the unit box.
template <typename T>
T sdMiniSpheres(const vec3<T>& position) {
    return opI(sdSphere(opRep(position + T(1), vec3<T>(T(2)) / T(4)), T(0.65) / T(4)),
               sdBox(position, vec3<T>(T(1))));
}

// Round box (0.75, rounding 0.2) minus the ball of radius 1.2, intersected with the ball of 1.32.
template <typename T>
T sdIntersectedRoundCube(const vec3<T>& position) {
    return opS(opS(udRoundBox(position, vec3<T>(T(0.75)), T(0.2)), sdSphere(position, T(1.20))),
               -sdSphere(position, T(1.32)));
}

template <typename T>
T sdSquareTorus(const vec3<T>& position) { return sdTorus82(position, vec2<T>(T(0.75), T(0.15))); }

template <typename T>
T sdTwistedTorus(const vec3<T>& position) { return sdTorus(opTwist(position), vec2<T>(T(0.6), T(0.2))); }

// Square torus with 20 angular slots per turn; atan2 is DXC's (pi/2 on the axis, D3D12 H15).
template <typename T>
T sdCog(const vec3<T>& position) {
    const vec3<T> q(hlsl::atan2(position.z, position.x) / T(6.2831), T(1),
                    T(0.015) + T(0.25) * hlsl::length(position));
    return opS(sdTorus82(position, vec2<T>(T(0.60), T(0.3))),
               sdCylinder(opRep(q + T(1), vec3<T>(T(0.05), T(1), T(0.075))), vec2<T>(T(0.02), T(0.8))));
}

// Four columns of radius 0.3 at x, z = +-0.5, clipped to the box [-3, 1] in y.
template <typename T>
T sdCylinderColumns(const vec3<T>& position) {
    return opI(sdCylinder(opRep(position + vec3<T>(T(1)), vec3<T>(T(1), T(2), T(1))), vec2<T>(T(0.3), T(2))),
               sdBox(position + vec3<T>(T(1)), vec3<T>(T(2))));
}

}  // namespace d3d12

// ---- Normal estimation -----------------------------------------------------------------------
// The tetrahedral offset of sdCalculateNormal and Mandelbulb calcNormal: 0.5773 * 0.0001.
template <typename T>
T tetrahedralOffset() { return T(0.5773) * T(0.0001); }

// normalize(k1*f(p+k1) + k2*f(p+k2) + k3*f(p+k3) + k4*f(p+k4)) with k = e*(+,-,-), e*(-,-,+),
// e*(-,+,-), e*(+,+,+), summed in that order. A NaN or constant field gives a NaN normal.
// PORT: takes the distance function as a callable (and the offset as a parameter) instead of
// switching on SignedDistancePrimitive, so Mandelbulb's and Julia's calcNormal reuse it.
template <typename T, class Sdf>
vec3<T> sdCalculateNormal(const vec3<T>& pos, Sdf&& sdf, T offset = tetrahedralOffset<T>()) {
    const vec2<T> e = vec2<T>(T(1), T(-1)) * offset;
    const vec3<T> xyy(e.x, e.y, e.y);
    const vec3<T> yyx(e.y, e.y, e.x);
    const vec3<T> yxy(e.y, e.x, e.y);
    const vec3<T> xxx(e.x, e.x, e.x);
    return hlsl::normalize(xyy * T(sdf(pos + xyy)) + yyx * T(sdf(pos + yyx)) + yxy * T(sdf(pos + yxy)) +
                           xxx * T(sdf(pos + xxx)));
}

// ---- Sphere tracing (RaySignedDistancePrimitiveTest) -------------------------------------------
// The defaults are the HLSL's constants; stepScale is the material's l_materialCB.stepScale.
// PORT: threshold, maxSteps and normalOffset are constants in the HLSL; as parameters they carry the shader
// libraries' accuracy knobs (procedural/accuracy.h: thresholdFactor, stepsFactor, normalEpsilonFactor).
template <typename T>
struct SphereTraceParams {
    T threshold = T(0.0001);  // hit when distance <= threshold * t
    std::uint32_t maxSteps = 512;
    T stepScale = T(1);
    T normalOffset = tetrahedralOffset<T>();
};

// The sphere tracing of both libraries' SDF intersection shaders with the accuracy knobs applied: threshold
// 1e-4 x thresholdFactor, 512 x stepsFactor steps, tetrahedral offset 0.5773e-4 x normalEpsilonFactor; stepScale is
// the material's. Accuracy{} gives the HLSL's constants bit for bit.
template <typename T>
SphereTraceParams<T> sphereTraceParams(const Accuracy& accuracy, T stepScale) {
    SphereTraceParams<T> params;  // the HLSL's constants
    params.threshold = scaledConstant(params.threshold, accuracy.thresholdFactor);
    params.maxSteps = scaledSteps(params.maxSteps, accuracy.stepsFactor);
    params.stepScale = stepScale;
    params.normalOffset = scaledConstant(params.normalOffset, accuracy.normalEpsilonFactor);
    return params;
}

// PORT: hit is a LaneMask<T> and steps a LaneUint<T>: bool and std::uint32_t for a scalar T, one per ray for lanes.
template <typename T>
struct SphereTraceResult {
    LaneMask<T> hit = LaneMask<T>(false);
    T thit = T(0);
    vec3<T> normal{};    // local-space normal at the hit
    vec3<T> position{};  // the sample that produced the hit
    LaneUint<T> steps = LaneUint<T>(0);  // loop iterations taken
};

// A sphere tracing's state between steps: where the ray stands and what it found so far.
template <typename T>
struct SphereTraceMarch {
    T t = T(0);
    SphereTraceResult<T> result;
};

// The candidate part of RaySignedDistancePrimitiveTest's loop body, for the lanes of `candidate` (a subset of
// `running`) at `position`: the normal, IsAValidHit, and for an accepted hit the result, and the ray out of `running`.
template <typename T, class Sdf>
void sphereTraceCandidate(const Ray<T>& ray, const RayExtent<T>& extent, Sdf& sdf, const SphereTraceParams<T>& params,
                          const LaneMask<T>& candidate, const vec3<T>& position, SphereTraceMarch<T>& m,
                          LaneMask<T>& running) {
    SphereTraceResult<T>& result = m.result;
    const vec3<T> hitSurfaceNormal = sdCalculateNormal(position, sdf, params.normalOffset);
    const LaneMask<T> accepted = candidate && IsAValidHit(ray, m.t, hitSurfaceNormal, extent);
    // if (IsAValidHit(...)) { ...; return true; }
    result.hit = result.hit || accepted;
    result.thit = select(accepted, m.t, result.thit);
    result.normal = select(accepted, hitSurfaceNormal, result.normal);
    result.position = select(accepted, position, result.position);
    running = running && !accepted;
}

// One pass of RaySignedDistancePrimitiveTest's loop body for the rays of `running`, as iteration `i` (1-based; the
// loop's `i++ < maxSteps` is the caller's): a ray beyond RayTCurrent leaves `running`, as does a ray whose hit is
// accepted. Given `candidates` (a march queue's), a candidate hit is not judged here: the ray leaves `running`
// with its bit set in `candidates` and its distance in `candidateDistance`, t where it stands, for
// sphereTraceCandidate and the step's end (t += stepScale * distance if rejected) to run later with other rays'.
template <typename T, class Sdf>
void sphereTraceStep(const Ray<T>& ray, const RayExtent<T>& extent, Sdf& sdf, const SphereTraceParams<T>& params,
                     const LaneUint<T>& i, SphereTraceMarch<T>& m, LaneMask<T>& running,
                     LaneMask<T>* candidates = nullptr, T* candidateDistance = nullptr) {
    running = running && m.t <= extent.tCurrent;  // PORT: the loop's `&& t <= RayTCurrent()`, per ray
    if (!anyLane(running)) return;
    const LiveLanes live(running);
    SphereTraceResult<T>& result = m.result;
    result.steps = select(running, i, result.steps);
    const vec3<T> position = ray.origin + m.t * ray.direction;
    const T distance = sdf(position);

    const LaneMask<T> candidate = running && distance <= params.threshold * m.t;
    if (anyLane(candidate)) {
        if (candidates) {
            *candidates = *candidates || candidate;
            *candidateDistance = select(candidate, distance, *candidateDistance);
            running = running && !candidate;
        } else {
            sphereTraceCandidate(ray, extent, sdf, params, candidate, position, m, running);
        }
    }
    m.t = select(running, m.t + params.stepScale * distance, m.t);  // t += stepScale * distance
}

// PORT: RayTMin()/RayTCurrent()/RayFlags() come in as `extent` (RayTCurrent cannot change inside
// the loop, which never calls ReportHit); the HLSL `out` thit/attr become the result struct.
// t starts at extent.tMin; at most maxSteps iterations while t <= extent.tCurrent:
// dist = sdf(o + t*d); if dist <= threshold*t, the normal is estimated and the hit is returned
// if IsAValidHit accepts it; otherwise (also for a rejected candidate) t += stepScale*dist.
// Negative distances step t backwards, as in the HLSL.
// PORT: for lanes, `running` holds the rays still in the loop: the loop condition and the `return` clear a ray's
// bit, every step is computed for all lanes and kept (select) in the running ones only, and the loop ends when no
// ray runs (the step count is uniform). For a scalar T the mask is the loop's own control flow: the same operations
// in the same order. PORT: the loop body is sphereTraceStep, so that RaySignedDistancePrimitiveTestQueue runs the
// same steps for a queue of rays.
template <typename T, class Sdf>
SphereTraceResult<T> RaySignedDistancePrimitiveTest(const Ray<T>& ray, const RayExtent<T>& extent, Sdf&& sdf,
                                                    const SphereTraceParams<T>& params = {}) {
    SphereTraceMarch<T> m;
    m.t = extent.tMin;
    LaneMask<T> running = allLanesSet<T>();
    std::uint32_t i = 0;
    while (i++ < params.maxSteps) {
        sphereTraceStep(ray, extent, sdf, params, LaneUint<T>(i), m, running);
        if (!anyLane(running)) break;
    }
    return m.result;
}

// One ray of a sphere-tracing queue: its local ray, its extent and its material's stepScale.
template <typename S>
struct SphereTraceRay {
    Ray<S> ray;
    RayExtent<S> extent;
    S stepScale = S(1);
};

namespace detail {

// A queued ray's state between passes: its march, and whether it left its last pass as a candidate hit with the
// distance that made it one.
template <typename S>
struct SphereTraceQueued {
    SphereTraceMarch<S> march;
    bool candidate = false;
    S distance = S(0);
};

// A queued ray's march state into lane j of (ray, extent, stepScale, m), and back.
template <class L, class S = typename L::Scalar>
struct SphereTraceLanes {
    Ray<L> ray;
    RayExtent<L> extent;
    SphereTraceParams<L> params;
    SphereTraceMarch<L> m;
    L distance = L(S(0));

    SphereTraceLanes() = default;
    explicit SphereTraceLanes(const SphereTraceParams<S>& p) {
        params.threshold = L(p.threshold);
        params.normalOffset = L(p.normalOffset);
    }
    void load(int j, const SphereTraceRay<S>& r, const SphereTraceQueued<S>& from) {
        setLane(ray, j, r.ray);
        setLane(extent, j, r.extent);
        setLane(params.stepScale, j, r.stepScale);
        setLane(m.t, j, from.march.t);
        setLane(m.result.hit, j, bool(from.march.result.hit));
        setLane(m.result.thit, j, from.march.result.thit);
        setLane(m.result.normal, j, from.march.result.normal);
        setLane(m.result.position, j, from.march.result.position);
        setLane(m.result.steps, j, from.march.result.steps);
        setLane(distance, j, from.distance);
    }
    void store(int j, SphereTraceQueued<S>& to) const {
        to.march.t = lane(m.t, j);
        to.march.result.hit = lane(m.result.hit, j);
        to.march.result.thit = lane(m.result.thit, j);
        to.march.result.normal = lane(m.result.normal, j);
        to.march.result.position = lane(m.result.position, j);
        to.march.result.steps = lane(m.result.steps, j);
        to.distance = lane(distance, j);
    }
};

inline int sphereTraceStepLimit(std::uint32_t maxSteps) { return int(std::min<std::uint32_t>(maxSteps, 1u << 30)); }

// One pass of RaySignedDistancePrimitiveTestQueue over the lanes of L (Groups sets of them, marchQueueUntil) for the
// rays of `marching` (bit k for ray k), from and back to their state in `queued`: a ray marches until it stops, runs
// out of steps, or meets a candidate hit (then it leaves with `candidate` set, for sphereTraceCandidatesPass).
// Returns the rays left for a narrower pass (marchQueueUntil's leaveAt).
template <class L, int Groups = 1, class Sdf, class S = typename L::Scalar>
uint32_t sphereTraceQueuePass(const SphereTraceRay<S>* rays, int count, uint32_t marching, Sdf& sdf,
                              const SphereTraceParams<S>& params, SphereTraceQueued<S>* queued, int leaveAt) {
    constexpr int NL = L::kCount;
    std::array<SphereTraceLanes<L>, size_t(Groups)> lanes;
    lanes.fill(SphereTraceLanes<L>(params));
    std::array<LaneMask<L>, size_t(Groups)> candidates;
    candidates.fill(LaneMask<L>(false));
    // A running lane has taken `steps` iterations, each of which counted itself: this one is steps + 1.
    const auto stepGroup = [&](int g, LaneMask<L>& running) {
        SphereTraceLanes<L>& l = lanes[size_t(g)];
        sphereTraceStep(l.ray, l.extent, sdf, l.params, l.m.result.steps + LaneUint<L>(1u), l.m, running,
                        &candidates[size_t(g)], &l.distance);
    };
    return marchQueueUntil<L, Groups>(
        count, sphereTraceStepLimit(params.maxSteps), [marching](int k) { return (marching >> k & 1u) != 0; },
        [&](int j, int k) {
            lanes[size_t(j / NL)].load(j % NL, rays[k], queued[k]);
            setLane(candidates[size_t(j / NL)], j % NL, false);
        },
        [&](auto& running) {
            if constexpr (Groups == 1) stepGroup(0, running);
            else for (int g = 0; g < Groups; ++g) stepGroup(g, running[size_t(g)]);
        },
        [&](int j, int k) {
            lanes[size_t(j / NL)].store(j % NL, queued[k]);
            queued[k].candidate = lane(candidates[size_t(j / NL)], j % NL);
        },
        leaveAt,
        // A ray that still marches counted each of its steps (result.steps is the iteration it is at).
        [queued](int k) { return int(queued[k].march.result.steps); });
}

// The candidate hits of `rays` (bit k for ray k, at most L's lanes of them) judged together over the lanes of L: the
// rest of each one's loop iteration (sphereTraceCandidate, then t += stepScale * distance if rejected). Returns the
// rejected rays with steps left, which march on.
template <class L, class Sdf, class S = typename L::Scalar>
uint32_t sphereTraceCandidatesPass(const SphereTraceRay<S>* rays, uint32_t candidates, Sdf& sdf,
                                   const SphereTraceParams<S>& params, SphereTraceQueued<S>* queued) {
    SphereTraceLanes<L> lanes(params);
    std::array<int, size_t(L::kCount)> ray{};
    int n = 0;
    for (uint32_t c = candidates; c; c &= c - 1) ray[size_t(n++)] = std::countr_zero(c);
    for (int j = 0; j < L::kCount; ++j) {  // the lanes past n hold the first candidate again (sane math, never kept)
        const int k = ray[size_t(j < n ? j : 0)];
        lanes.load(j, rays[k], queued[k]);
    }
    LaneMask<L> running(false);
    for (int j = 0; j < n; ++j) setLane(running, j, true);
    const LiveLanes live(running);
    const LaneMask<L> candidate = running;
    const vec3<L> position = lanes.ray.origin + lanes.m.t * lanes.ray.direction;  // the candidate's, recomputed
    sphereTraceCandidate(lanes.ray, lanes.extent, sdf, lanes.params, candidate, position, lanes.m, running);
    lanes.m.t = select(running, lanes.m.t + lanes.params.stepScale * lanes.distance, lanes.m.t);
    uint32_t resume = 0;
    const int limit = sphereTraceStepLimit(params.maxSteps);
    for (int j = 0; j < n; ++j) {
        SphereTraceQueued<S>& q = queued[ray[size_t(j)]];
        lanes.store(j, q);
        q.candidate = false;
        if (lane(running, j) && int(q.march.result.steps) < limit) resume |= 1u << ray[size_t(j)];
    }
    return resume;
}

// March passes (over two sets of L's lanes while more rays march than L holds, over L otherwise; the last 8 or fewer
// rays over 8) and candidate passes (the candidates of a march pass judged over L, or 8 lanes for 8 or fewer) until
// every ray of `marching` has ended.
template <class L, class Sdf, class S = typename L::Scalar>
void sphereTraceQueue(const SphereTraceRay<S>* rays, int count, uint32_t marching, Sdf& sdf,
                      const SphereTraceParams<S>& params, SphereTraceQueued<S>* queued) {
    constexpr int kNarrow = 8;
    using Narrow = Lanes<S, kNarrow>;
    while (marching) {
        if constexpr (L::kCount > kNarrow) {
            const uint32_t left =
                std::popcount(marching) > L::kCount
                    ? sphereTraceQueuePass<L, 2>(rays, count, marching, sdf, params, queued, kNarrow)
                    : sphereTraceQueuePass<L>(rays, count, marching, sdf, params, queued, kNarrow);
            if (left) sphereTraceQueuePass<Narrow>(rays, count, left, sdf, params, queued, 0);
        } else {
            sphereTraceQueuePass<L>(rays, count, marching, sdf, params, queued, 0);
        }
        uint32_t candidates = 0;
        for (uint32_t r = marching; r; r &= r - 1)
            if (queued[std::countr_zero(r)].candidate) candidates |= 1u << std::countr_zero(r);
        marching = 0;
        while (candidates) {
            uint32_t batch = candidates;  // the first L::kCount candidates
            for (int taken = 0, k = 0; k < 32; ++k)
                if (batch >> k & 1u && ++taken > L::kCount) batch &= ~(1u << k);
            candidates &= ~batch;
            if (L::kCount > kNarrow && std::popcount(batch) <= kNarrow)
                marching |= sphereTraceCandidatesPass<Narrow>(rays, batch, sdf, params, queued);
            else
                marching |= sphereTraceCandidatesPass<L>(rays, batch, sdf, params, queued);
        }
    }
}

}  // namespace detail

// RaySignedDistancePrimitiveTest for `count` (at most kMaxMarchQueue) rays in S over the lanes of L = Lanes<S, N>,
// refilled from the queue as rays stop (march_queue.h): out[k] is bit for bit
// RaySignedDistancePrimitiveTest(rays[k].ray, rays[k].extent, sdf, params with rays[k].stepScale) in S. `sdf` runs
// over the lanes (a generic callable: over L, and over Lanes<S, 8> for the tail below); params' threshold, maxSteps
// and normalOffset are every ray's (its stepScale is not read).
// Over more than 8 lanes, a queue of more rays than L holds marches two sets of L's lanes at each step, one after
// the other (marchQueueUntil's Groups: the core overlaps their independent chains of dependent instructions), and
// the rays that still march once the queue is empty and 8 or fewer remain go on in 8 lanes (Lanes<S, 8>): an
// 8-lane step costs less than a wide one (on AVX-512 a 16-float instruction is two 8-float halves), and a resumed
// ray takes the steps it would have taken, from the state it stopped at.
// A ray whose step meets a candidate hit leaves the march there, and the candidates of a pass are judged together
// (the normal's four distance evaluations and IsAValidHit, over the lanes of as many rays as there are): judged in the
// step, each candidate cost every lane of the step those four evaluations. A rejected candidate ends its step
// (t += stepScale * distance) and marches on in the next pass.
// PORT: not in the HLSL; a GPU runs a wave's sphere tracing in its lanes, each lane until its own ray ends.
template <class L, class Sdf, class S = typename L::Scalar>
void RaySignedDistancePrimitiveTestQueue(const SphereTraceRay<S>* rays, int count, Sdf&& sdf,
                                         const SphereTraceParams<S>& params, SphereTraceResult<S>* out) {
    std::array<detail::SphereTraceQueued<S>, kMaxMarchQueue> queued{};
    for (int k = 0; k < count; ++k) queued[size_t(k)].march.t = rays[k].extent.tMin;  // where a ray that never steps stays
    detail::sphereTraceQueue<L>(rays, count, count >= 32 ? ~0u : (1u << count) - 1u, sdf, params, queued.data());
    for (int k = 0; k < count; ++k) out[k] = queued[size_t(k)].march.result;
}

}  // namespace refray::procedural::math
