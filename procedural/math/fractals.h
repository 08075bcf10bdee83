// Ports: Proceduray Mandelbulb.hlsli, JuliaSets.hlsli, pacMan; D3D12 SignedDistanceFractals.hlsli.
// Proceduray: Mandelbulb and quaternion-Julia estimators and marches, the Pac-man SDF (from
// SignedDistancePrimitives.hlsli) and its mouth animation (ProceduralPrimitivesLibrary.hlsli).
// D3D12 sample: sdFractalPyramid and its GetDistanceFromSignedDistancePrimitive switch.
// Every function here but MandelbulbIterationCount and PacmanMouthInterpolant (per primitive, not per ray) also runs
// with T = Lanes<float, N>, one ray per lane (lanes.h): a per-ray `if`, `break` or early `return` of the HLSL
// becomes a lane mask and a select (PORT comments), and lane i is bit for bit the scalar result for ray i. For a
// scalar T the masks are bools and every select picks what the HLSL's branch picks: the scalar results are unchanged.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

#include "procedural/math/analytic.h"
#include "procedural/math/hlsl.h"
#include "procedural/math/lanes.h"
#include "procedural/math/march_queue.h"
#include "procedural/math/ray.h"
#include "procedural/math/sdf.h"

namespace refray::procedural::math {

// =================================================================================================
// Mandelbulb (Proceduray fact sheet §3.4)
// =================================================================================================
namespace mandelbulb {

// The iterations of mdist's loop in the HLSL.
inline constexpr int kIterations = 4;

// Power-8 Mandelbulb DE with orbit trap; 4 iterations, bailout |w|^2 > 256.
// resColor = (final m, trap.y, trap.z, trap.w), where trap = componentwise min over the
// iterations of (|w.x|, |w.y|, |w.z|, m before the update). DE = 0.25*log(m)*sqrt(m)/dz.
// At p = 0 the result is NaN (0/0 inside acos, H4); on the y axis atan2(0,0) = pi/2 (H5).
// PORT: the loop count is the literal 4 in the HLSL; as a parameter it carries the mandelbulbIterations knob.
template <typename T>
T mdist(const vec3<T>& p, vec4<T>& resColor, int iterations = kIterations) {
    vec3<T> w = p;
    T m = hlsl::dot(w, w);

    vec4<T> trap(hlsl::abs(w), m);
    T dz = T(1);

    // PORT: the lanes that have broken out keep their values (`running`, see lanes.h); the loop ends when none runs.
    LaneMask<T> running = allLanesSet<T>();
    for (int i = 0; i < iterations && anyLane(running); i++) {
        const LiveLanes live(running);
        // The non-PERFORMANCE branch (the live one). Exponents 7 and 8 are not the literal 2, so
        // DXC lowers both pows to exp2(y*log2(x)).
        // PORT: pow(sqrt(m), 7) and pow(r, 8) share their log2, and sin(b) is computed once, as a compiler's common
        // subexpressions: r = length(w) = sqrt(dot(w, w)) is sqrt(m) bit for bit (m is dot(w, w)), and each
        // instruction is a function of its operands, so every value is the HLSL's.
        const T r = hlsl::length(w);
        const T log2r = hlsl::log2(r);
        const T dzNext = T(8) * hlsl::exp2(T(7) * log2r) * dz + T(1);  // 8*pow(sqrt(m), 7)*dz + 1

        const T b = T(8) * hlsl::acos(w.y / r);
        const T a = T(8) * hlsl::atan2(w.x, w.z);
        const T sinB = hlsl::sin(b);
        const vec3<T> wNext = p + hlsl::exp2(T(8) * log2r) *  // pow(r, 8)
                                      vec3<T>(sinB * hlsl::sin(a), hlsl::cos(b), sinB * hlsl::cos(a));

        const vec4<T> trapNext = hlsl::min(trap, vec4<T>(hlsl::abs(wNext), m));

        const T mNext = hlsl::dot(wNext, wNext);
        // PORT: all four are assigned before the break, so the lane that breaks keeps this iteration's values.
        dz = select(running, dzNext, dz);
        w = select(running, wNext, w);
        trap = select(running, trapNext, trap);
        m = select(running, mNext, m);
        running = running && !(m > T(256));  // if (m > 256) break;
    }

    resColor = vec4<T>(m, trap.y, trap.z, trap.w);
    return T(0.25) * hlsl::log(m) * hlsl::sqrt(m) / dz;
}

template <typename T>
T mdist(const vec3<T>& p, int iterations = kIterations) {
    vec4<T> unused;
    return mdist(p, unused, iterations);
}

// Tetrahedral normal with offset 0.5773e-4 (the `t` argument of the HLSL is unused).
// PORT: the offset and mdist's iterations are parameters (the normalEpsilonFactor and mandelbulbIterations knobs).
template <typename T>
vec3<T> calcNormal(const vec3<T>& pos, T offset = tetrahedralOffset<T>(), int iterations = kIterations) {
    return sdCalculateNormal(pos, [iterations](const vec3<T>& q) { return mdist(q, iterations); }, offset);
}

// Step count iMax(time, instanceId): k = int((0.5*time^2 + instanceId) % 256) (truncated
// remainder, H11); if k > 128 then k = 256 - k; iMax = k + 1, in [1, 129].
// pow(time, 2) has a literal 2, so DXC emits time*time.
template <typename T>
int MandelbulbIterationCount(T time, int instanceId) {
    const int iAnimMin = 1;
    const int iAnimMax = 128;
    int iMax = hlsl::fremToInt(T(0.5) * (time * time) + static_cast<T>(instanceId), iAnimMax * 2);
    if (iMax > iAnimMax) iMax = 2 * iAnimMax - iMax;
    iMax += iAnimMin;
    return iMax;
}

// The constants of MandelbulbDistance besides its step count; the defaults are the HLSL's.
// PORT: constants in the HLSL; as parameters they carry the thresholdFactor, mandelbulbIterations and
// normalEpsilonFactor knobs (procedural/accuracy.h).
template <typename T>
struct MandelbulbParams {
    T threshold = T(0.0001);                  // hit when mdist < threshold * t
    int iterations = kIterations;             // mdist's loop, in the march and the normal
    T normalOffset = tetrahedralOffset<T>();  // calcNormal's tetrahedral offset
};

template <typename T>
struct MandelbulbHit {
    LaneMask<T> hit = LaneMask<T>(false);
    T thit = T(0);
    vec3<T> normal{};  // local space, computed at pos
    vec4<T> color{};   // the orbit trap of the last mdist call (attr.color)
    vec3<T> pos{};     // the last sample; when the loop runs out it lags thit by one step (H14)
};

// The bounding sphere's interval: dis = isphere(centre 0, radius 1.25), clipped to [0, 1000] for the rays that meet
// the sphere (inSphere).
template <typename T>
struct MandelbulbBounds {
    LaneMask<T> inSphere = LaneMask<T>(false);
    vec2<T> dis{};
};

template <typename T>
MandelbulbBounds<T> mandelbulbBounds(const vec3<T>& ro, const vec3<T>& rd) {
    MandelbulbBounds<T> b;
    b.dis = isphere(vec4<T>(T(0), T(0), T(0), T(1.25)), ro, rd);
    b.inSphere = !(b.dis.y < T(0));
    b.dis.x = hlsl::max(b.dis.x, T(0));
    b.dis.y = hlsl::min(b.dis.y, T(1000));
    return b;
}

// What the march carries from step to step: t, the last sample and its orbit trap.
template <typename T>
struct MandelbulbMarch {
    T t = T(0);
    vec3<T> pos = vec3<T>(T(0));
    vec4<T> trap = vec4<T>(T(0));
};

// One step of the march for the `running` lanes, which it clears for the lanes that stop.
// PORT: pos and trap are assigned before the break (the lane that breaks keeps them), t after it.
template <typename T>
void mandelbulbStep(const vec3<T>& ro, const vec3<T>& rd, T disY, T threshold, int iterations, MandelbulbMarch<T>& m,
                    LaneMask<T>& running) {
    const LiveLanes live(running);
    const vec3<T> posNext = ro + rd * m.t;
    const T th = threshold * m.t;
    vec4<T> trapNext;
    const T h = mdist(posNext, trapNext, iterations);
    m.pos = select(running, posNext, m.pos);
    m.trap = select(running, trapNext, m.trap);
    running = running && !(m.t > disY || h < th);  // if (t > dis.y || h < th) break;
    m.t = select(running, m.t + h, m.t);           // t += h;
}

// Bounding sphere (centre 0, radius 1.25; unit rd assumed) gives [dis.x, dis.y], clipped to
// [0, 1000]. Up to iMax steps: pos = ro + rd*t; break if t > dis.y or mdist(pos) < 1e-4*t;
// t += h. Hit iff t < dis.y afterwards, converged or not. stepScale is ignored, as in the HLSL.
// PORT: takes iMax (MandelbulbIterationCount) instead of (time, instanceId), and returns the
// HLSL `out` thit/attr as a struct. PORT: `params` holds the HLSL's constants (MandelbulbParams).
// PORT: the HLSL's one function is mandelbulbBounds, the loop of mandelbulbStep and the hit test, so that
// MandelbulbDistanceQueue runs the same steps for a queue of rays.
template <typename T>
MandelbulbHit<T> MandelbulbDistance(const vec3<T>& ro, const vec3<T>& rd, int iMax,
                                    const MandelbulbParams<T>& params = {}) {
    MandelbulbHit<T> result;

    // PORT: `if (dis.y < 0) return result;` for the lanes whose ray misses the sphere: they stay out of the march
    // and keep result's initial values.
    const MandelbulbBounds<T> b = mandelbulbBounds(ro, rd);
    if (!anyLane(b.inSphere)) return result;

    MandelbulbMarch<T> m;
    m.t = b.dis.x;
    LaneMask<T> running = b.inSphere;
    for (int i = 0; i < iMax && anyLane(running); i++)
        mandelbulbStep(ro, rd, b.dis.y, params.threshold, params.iterations, m, running);

    // if (t < dis.y) { ... }
    const LaneMask<T> hit = b.inSphere && (m.t < b.dis.y);
    if (anyLane(hit)) {
        result.hit = hit;
        result.thit = select(hit, m.t, result.thit);
        result.normal = select(hit, calcNormal(m.pos, params.normalOffset, params.iterations), result.normal);
        result.color = select(hit, m.trap, result.color);
    }
    result.pos = select(b.inSphere, m.pos, result.pos);
    return result;
}

// MandelbulbDistance for `count` (at most kMaxMarchQueue) rays ro[k], rd[k] in S over the lanes of L = Lanes<S, N>:
// the march refilled from the queue as rays stop (march_queue.h), then calcNormal over the lanes for the rays that
// hit, N at a time. out[k] is bit for bit MandelbulbDistance(ro[k], rd[k], iMax, params) in S.
// PORT: not in the HLSL: the lanes' MandelbulbDistance, with a queue of rays instead of one ray per lane.
template <class L, class S = typename L::Scalar>
void MandelbulbDistanceQueue(const vec3<S>* ro, const vec3<S>* rd, int count, int iMax, MandelbulbHit<S>* out,
                             const MandelbulbParams<S>& params = {}) {
    constexpr int N = L::kCount;
    std::array<MandelbulbBounds<S>, kMaxMarchQueue> bounds{};
    std::array<MandelbulbMarch<S>, kMaxMarchQueue> march{};
    for (int k = 0; k < count; ++k) {
        bounds[size_t(k)] = mandelbulbBounds(ro[k], rd[k]);
        march[size_t(k)].t = bounds[size_t(k)].dis.x;  // where a ray that never marches stays
    }
    vec3<L> roL(L(S(0))), rdL(L(S(0)));
    L disY(S(0));
    MandelbulbMarch<L> m;
    marchQueue<L>(
        count, iMax, [&](int k) { return bounds[size_t(k)].inSphere; },
        [&](int j, int k) {
            setLane(roL, j, ro[k]);
            setLane(rdL, j, rd[k]);
            setLane(disY, j, bounds[size_t(k)].dis.y);
            setLane(m.t, j, march[size_t(k)].t);
            setLane(m.pos, j, march[size_t(k)].pos);
            setLane(m.trap, j, march[size_t(k)].trap);
        },
        [&](LaneMask<L>& running) {
            mandelbulbStep(roL, rdL, disY, L(params.threshold), params.iterations, m, running);
        },
        [&](int j, int k) {
            march[size_t(k)].t = lane(m.t, j);
            march[size_t(k)].pos = lane(m.pos, j);
            march[size_t(k)].trap = lane(m.trap, j);
        });
    std::array<int, kMaxMarchQueue> hits{};
    int hitCount = 0;
    for (int k = 0; k < count; ++k) {
        const MandelbulbBounds<S>& b = bounds[size_t(k)];
        const MandelbulbMarch<S>& mk = march[size_t(k)];
        out[k] = MandelbulbHit<S>();
        if (!b.inSphere) continue;
        out[k].pos = mk.pos;
        if (!(mk.t < b.dis.y)) continue;  // if (t < dis.y)
        out[k].hit = true;
        out[k].thit = mk.t;
        out[k].color = mk.trap;
        hits[size_t(hitCount++)] = k;
    }
    for (int first = 0; first < hitCount; first += N) {
        const int lanes = std::min(N, hitCount - first);
        vec3<L> pos;
        for (int j = 0; j < N; ++j)  // lanes past the rays copy the last one
            setLane(pos, j, march[size_t(hits[size_t(first + std::min(j, lanes - 1))])].pos);
        const LiveLanes batch(kLaneBits<N> >> (N - lanes), 0);
        const vec3<L> normal = calcNormal(pos, L(params.normalOffset), params.iterations);
        for (int j = 0; j < lanes; ++j) out[hits[size_t(first + j)]].normal = lane(normal, j);
    }
}

}  // namespace mandelbulb

// =================================================================================================
// Quaternion Julia set (Proceduray fact sheet §3.5)
// =================================================================================================
namespace julia {

template <typename T>
inline constexpr T kPrecis = T(0.00025f);
// jdist's iMax as raycast and calcNormal pass it, and raycast's march steps, in the HLSL.
inline constexpr int kIterations = 200;
inline constexpr int kMarchSteps = 1024;

// kc = float4(-2, 6, 15, -6) / 22.
template <typename T>
vec4<T> kc() {
    return vec4<T>(T(-2), T(6), T(15), T(-6)) / T(22);
}

template <typename T>
vec4<T> qSquare_float4(const vec4<T>& q) {
    return vec4<T>((((q.x * q.x) - (q.y * q.y)) - (q.z * q.z)) - (q.w * q.w),
                   (T(2) * q.x) * vec3<T>(q.y, q.z, q.w));
}

template <typename T>
vec4<T> qCube_float4(const vec4<T>& q) {
    const vec4<T> q2 = q * q;
    return vec4<T>(q.x * (((q2.x - (T(3) * q2.y)) - (T(3) * q2.z)) - (T(3) * q2.w)),
                   vec3<T>(q.y, q.z, q.w) * ((((T(3) * q2.x) - q2.y) - q2.z) - q2.w));
}

template <typename T>
T qLength2_float4(const vec4<T>& q) { return hlsl::dot(q, q); }

// Ray-sphere at the origin (unit rd): (-b - h, -b + h), or (-1, -1) when it misses.
template <typename T>
vec2<T> iSphere(const vec3<T>& ro, const vec3<T>& rd, T rad) {
    const T b = hlsl::dot(ro, rd);
    const T c = hlsl::dot(ro, ro) - (rad * rad);
    T h = (b * b) - c;
    // PORT: `if (h < 0) return (-1, -1);` per lane: a lane that misses takes (-1, -1) in the select below.
    const LaneMask<T> miss = h < T(0);
    if (allLanes(miss)) return vec2<T>(T(-1), T(-1));
    h = hlsl::sqrt(h);
    return select(miss, vec2<T>(T(-1), T(-1)), vec2<T>(-b - h, -b + h));
}

// Distance estimate of z -> z^3 + c over quaternions: (d, n) with n the iterations survived.
// dz2 *= 9*|z^2|^2; z = z^3 + c; m2 = |z|^2; break if m2 > 256; n += 1.
// d = 0.25*log(m2)*sqrt(m2/dz2). At p = 0, dz2 = 0 and d = +inf with n = 22 (H8).
// PORT: `lanes` (not in the HLSL) leaves out the lanes whose result the caller discards (rays that stopped
// marching), so that a point deep in the set does not keep the others iterating; their results are meaningless.
// Scalar callers leave it at its default (set), the HLSL's loop.
template <typename T>
vec2<T> jdist(const vec3<T>& p, const vec4<T>& c, int iMax, LaneMask<T> lanes = allLanesSet<T>()) {
    vec4<T> z(p, T(0));
    T dz2 = T(1);
    T m2 = T(0);
    T n = T(0);
    LaneMask<T> running = lanes;
    for (int i = 0; i < iMax && anyLane(running); i++) {
        const LiveLanes live(running);
        const T dz2Next = dz2 * (T(9) * qLength2_float4(qSquare_float4(z)));  // dz2 *= 9*|z^2|^2
        const vec4<T> zNext = qCube_float4(z) + c;
        const T m2Next = qLength2_float4(zNext);
        // PORT: dz2, z and m2 are assigned before the break (the lane that breaks keeps them), n after it.
        dz2 = select(running, dz2Next, dz2);
        z = select(running, zNext, z);
        m2 = select(running, m2Next, m2);
        running = running && !(m2 > T(256));  // if (m2 > 256) break;
        n = select(running, n + T(1), n);     // n += 1;
    }
    const T d = (T(0.25) * hlsl::log(m2)) * hlsl::sqrt(m2 / dz2);
    return vec2<T>(d, n);
}

// calcNormal's tetrahedral offset, 0.5773*kPrecis (a product in T, as the HLSL computes it).
template <typename T>
T calcNormalOffset() { return T(0.5773f) * kPrecis<T>; }

// Tetrahedral normal with offset 0.5773*kPrecis on jdist(...).x.
// PORT: the offset is a parameter (the normalEpsilonFactor knob). PORT: `lanes` as in jdist (the lanes whose normal
// the caller uses).
template <typename T>
vec3<T> calcNormal(const vec3<T>& pos, const vec4<T>& c = kc<T>(), int iMax = kIterations,
                   T offset = calcNormalOffset<T>(), LaneMask<T> lanes = allLanesSet<T>()) {
    return sdCalculateNormal(pos, [&c, iMax, lanes](const vec3<T>& q) { return jdist(q, c, iMax, lanes).x; },
                             offset);
}

// raycast's bounds: [tmin, tmax] of the march between the cut planes y = deltaT and y = -1.1 inside the sphere of
// radius 1.2, and the lanes that a plane or the sphere rules out (the HLSL's three `return (-2, 0)`).
// PORT: the three returns are per lane: `ruledOut` collects the lanes that return there; they take (-2, 0) at the
// end and stay out of the march. Each if/else on a lane's value is a select.
template <typename T>
struct RaycastBounds {
    T tmin = kPrecis<T>;
    T tmax = T(7000);
    LaneMask<T> ruledOut = LaneMask<T>(false);
};

template <typename T>
RaycastBounds<T> raycastBounds(const vec3<T>& ro, const vec3<T>& rd, T deltaT) {
    RaycastBounds<T> b;
    T& tmin = b.tmin;
    T& tmax = b.tmax;
    LaneMask<T>& ruledOut = b.ruledOut;

    const T upperPlane = deltaT;
    const T tpS = (upperPlane - ro.y) / rd.y;
    const LaneMask<T> isCamAboveUpper = (ro.y > upperPlane);
    const LaneMask<T> tpSAhead = (tpS > T(0));
    // if (tpS > 0) { if (isCamAboveUpper) tmin = max(tmin, tpS); else tmax = min(tmax, tpS); }
    tmin = select(tpSAhead && isCamAboveUpper, hlsl::max(tmin, tpS), tmin);
    tmax = select(tpSAhead && !isCamAboveUpper, hlsl::min(tmax, tpS), tmax);
    // else { if (isCamAboveUpper) return (-2, 0); }
    ruledOut = ruledOut || (!tpSAhead && isCamAboveUpper);
    if (allLanes(ruledOut)) return b;

    const T lowerPlane = T(-1.1f);
    const T tpF = (lowerPlane - ro.y) / rd.y;
    const LaneMask<T> isCamBellowLower = (ro.y < lowerPlane);
    const LaneMask<T> tpFAhead = (tpF > T(0));
    // if (tpF > 0) { if (isCamBellowLower) tmin = max(tmin, tpF); else tmax = min(tmax, tpF); }
    tmin = select(tpFAhead && isCamBellowLower, hlsl::max(tmin, tpF), tmin);
    tmax = select(tpFAhead && !isCamBellowLower, hlsl::min(tmax, tpF), tmax);
    // else { if (isCamBellowLower) return (-2, 0); }
    ruledOut = ruledOut || (!tpFAhead && isCamBellowLower);
    if (allLanes(ruledOut)) return b;

    const vec2<T> bv = iSphere(ro, rd, T(1.2f));
    ruledOut = ruledOut || (bv.y < T(0));  // if (bv.y < 0) return (-2, 0);
    if (allLanes(ruledOut)) return b;
    tmin = hlsl::max(tmin, bv.x);
    tmax = hlsl::min(tmax, bv.y);
    return b;
}

// What raycast's march carries from step to step: t, the last step's t and distance (lt, lh) and jdist's (d, n).
template <typename T>
struct RaycastMarch {
    vec2<T> res = vec2<T>(T(-1), T(-1));
    T t = T(0);
    T lt = T(0);
    T lh = T(0);
};

// One step of raycast's march for the `running` lanes, which it clears for the lanes that stop.
// PORT: res is assigned before the first break, lt, lh and t between the two: a lane that breaks keeps what the
// HLSL has at its break. jdist leaves out the lanes that no longer march.
template <typename T>
void raycastStep(const vec3<T>& ro, const vec3<T>& rd, const vec4<T>& c, int iMax, T precis, T tmax,
                 RaycastMarch<T>& m, LaneMask<T>& running) {
    const LiveLanes live(running);
    m.res = select(running, jdist(ro + (rd * m.t), c, iMax, running), m.res);
    running = running && !(m.res.x < precis);  // if (res.x < precis) break;
    m.lt = select(running, m.t, m.lt);
    m.lh = select(running, m.res.x, m.lh);
    m.t = select(running, m.t + hlsl::min(m.res.x, T(0.2)), m.t);  // t += min(res.x, 0.2);
    running = running && !(m.t > tmax);                              // if (t > tmax) break;
}

// raycast's end: a secant step when lt > 9.9999997e-5 and the last d < 0; (t, n) when t < tmax, else (-1, n);
// (-2, 0) for the lanes ruled out.
template <typename T>
vec2<T> raycastResult(const RaycastBounds<T>& b, RaycastMarch<T> m) {
    const LaneMask<T> secant = (m.lt > T(9.9999997e-05f)) && (m.res.x < T(0));
    if (anyLane(secant)) {
        m.t = select(secant, m.lt - ((m.lh * (m.t - m.lt)) / (m.res.x - m.lh)), m.t);
    }
    // if (t < tmax) s = t; else s = -1;
    const T s = select(m.t < b.tmax, m.t, T(-1));
    m.res.x = s;
    return select(b.ruledOut, vec2<T>(T(-2), T(0)), m.res);
}

// March in q-space between the cut planes y = deltaT and y = -1.1 inside the sphere of radius
// 1.2: up to 1024 steps of min(d, 0.2) from tmin, stopping when d < kPrecis or t > tmax; then a
// secant step when lt > 9.9999997e-5 and the last d < 0. Returns (t, n) when t < tmax (running
// out of steps counts as a hit, H15), (-1, n) when t >= tmax, and (-2, 0) when a plane or the
// sphere rules it out. IEEE comparisons decide every branch (rd.y = 0, H10).
// PORT: the step limit 1024 and the stop test's kPrecis are parameters (maxSteps, precis: the stepsFactor and
// thresholdFactor knobs); tmin starts at kPrecis and the secant gate stays 9.9999997e-5 whatever precis is.
// PORT: the HLSL's one function is raycastBounds, the loop of raycastStep and raycastResult, so that
// raycastQueue runs the same steps for a queue of rays.
template <typename T>
vec2<T> raycast(const vec3<T>& ro, const vec3<T>& rd, const vec4<T>& c = kc<T>(), T deltaT = T(0),
                int iMax = kIterations, int maxSteps = kMarchSteps, T precis = kPrecis<T>) {
    const RaycastBounds<T> b = raycastBounds(ro, rd, deltaT);
    if (allLanes(b.ruledOut)) return vec2<T>(T(-2), T(0));

    RaycastMarch<T> m;
    m.t = b.tmin;
    LaneMask<T> running = !b.ruledOut;
    for (int i = 0; i < maxSteps && anyLane(running); i++) raycastStep(ro, rd, c, iMax, precis, b.tmax, m, running);
    return raycastResult(b, m);
}

// The most rays raycastQueue takes: a wave's (32).
inline constexpr int kMaxRaycastQueue = kMaxMarchQueue;

// Lane i of a march over lanes, and its writing.
template <class L, class S = typename L::Scalar>
RaycastMarch<S> marchLane(const RaycastMarch<L>& m, int i) {
    RaycastMarch<S> r;
    r.res = lane(m.res, i);
    r.t = lane(m.t, i);
    r.lt = lane(m.lt, i);
    r.lh = lane(m.lh, i);
    return r;
}
template <class L, class S>
void setMarchLane(RaycastMarch<L>& m, int i, const RaycastMarch<S>& value) {
    setLane(m.res, i, value.res);
    setLane(m.t, i, value.t);
    setLane(m.lt, i, value.lt);
    setLane(m.lh, i, value.lh);
}

// raycast for `count` (at most kMaxRaycastQueue) rays ro[k], rd[k] in S over the lanes of L = Lanes<S, N>,
// refilled from the queue as rays stop (march_queue.h). Each ray takes the steps raycast takes for it alone
// (raycastStep in its own lane), so out[k] is bit for bit raycast(ro[k], rd[k], ...) in S. c, deltaT, iMax, maxSteps
// and precis are every ray's.
// PORT: not in the HLSL; a GPU would run its rays' raycast in one wave, each lane until its own ray ends.
template <class L, class S = typename L::Scalar>
void raycastQueue(const vec3<S>* ro, const vec3<S>* rd, int count, vec2<S>* out, const vec4<L>& c = kc<L>(),
                  S deltaT = S(0), int iMax = kIterations, int maxSteps = kMarchSteps, S precis = kPrecis<S>) {
    std::array<RaycastBounds<S>, kMaxRaycastQueue> bounds{};
    std::array<RaycastMarch<S>, kMaxRaycastQueue> march{};
    for (int k = 0; k < count; ++k) {
        bounds[size_t(k)] = raycastBounds(ro[k], rd[k], deltaT);
        march[size_t(k)].t = bounds[size_t(k)].tmin;  // where a ray that never marches stays
    }
    vec3<L> roL(L(S(0))), rdL(L(S(0)));
    L tmaxL(S(0));
    RaycastMarch<L> m;
    marchQueue<L>(
        count, maxSteps, [&](int k) { return !bounds[size_t(k)].ruledOut; },
        [&](int j, int k) {
            setLane(roL, j, ro[k]);
            setLane(rdL, j, rd[k]);
            setLane(tmaxL, j, bounds[size_t(k)].tmax);
            setMarchLane(m, j, march[size_t(k)]);
        },
        [&](LaneMask<L>& running) { raycastStep(roL, rdL, c, iMax, L(precis), tmaxL, m, running); },
        [&](int j, int k) { march[size_t(k)] = marchLane(m, j); });
    for (int k = 0; k < count; ++k) out[k] = raycastResult(bounds[size_t(k)], march[size_t(k)]);
}

// The constants JuliaDistance passes to raycast and calcNormal; the defaults are the HLSL's.
// PORT: constants in the HLSL; as parameters they carry the juliaIterations, stepsFactor, thresholdFactor and
// normalEpsilonFactor knobs (procedural/accuracy.h).
template <typename T>
struct JuliaParams {
    int iterations = kIterations;            // jdist's iMax, in the march and the normal
    int marchSteps = kMarchSteps;            // raycast's step limit
    T precis = kPrecis<T>;                   // raycast's stop test res.x < precis
    T normalOffset = calcNormalOffset<T>();  // calcNormal's tetrahedral offset
};

template <typename T>
struct JuliaHit {
    LaneMask<T> hit = LaneMask<T>(false);
    vec3<T> normal{};                   // q-space normal (same directions as local space)
    vec2<T> resT = vec2<T>(T(1e20f));   // (t in q-space units, n)
};

// Local ray -> q-space: ro' = 0.4*ro + (0, -1, 0), rd unchanged; raycast with the defaults
// (kc, deltaT = 0, 200 iterations). Hit iff t >= 0.
// PORT: the cut-animation variables (iMax from 10.5*time, deltaT) are computed and then ignored
// by the HLSL; they are not ported, so there is no time parameter. PORT: `params` holds the HLSL's
// constants (JuliaParams).
template <typename T>
JuliaHit<T> JuliaDistance(vec3<T> ro, const vec3<T>& rd, const JuliaParams<T>& params = {}) {
    JuliaHit<T> result;
    ro *= T(0.4);
    ro.y += T(-1);

    const vec2<T> tn = raycast(ro, rd, kc<T>(), T(0), params.iterations, params.marchSteps, params.precis);
    const LaneMask<T> cond = (tn.x >= T(0));
    // PORT: `if (cond)` per lane: the lanes that miss keep result's initial values.
    if (anyLane(cond)) {
        const vec3<T> pos = ro + (tn.x * rd);
        result.normal = select(cond, calcNormal(pos, kc<T>(), params.iterations, params.normalOffset, cond),
                               result.normal);
        result.resT = select(cond, tn, result.resT);
        result.hit = cond;
    }
    return result;
}

// JuliaDistance for `count` (at most kMaxRaycastQueue) rays ro[k], rd[k] in S over the lanes of L = Lanes<S, N>:
// the march in raycastQueue, then calcNormal over the lanes for the rays that hit, N at a time. out[k] is bit for bit
// JuliaDistance(ro[k], rd[k], params) in S.
// PORT: not in the HLSL: the lanes' JuliaDistance, with a queue of rays instead of one ray per lane.
template <class L, class S = typename L::Scalar>
void JuliaDistanceQueue(const vec3<S>* roLocal, const vec3<S>* rd, int count, JuliaHit<S>* out,
                        const JuliaParams<S>& params = {}) {
    constexpr int N = L::kCount;
    std::array<vec3<S>, kMaxRaycastQueue> ro{};
    std::array<vec2<S>, kMaxRaycastQueue> tn{};
    for (int k = 0; k < count; ++k) {
        ro[size_t(k)] = roLocal[k] * S(0.4);
        ro[size_t(k)].y += S(-1);
    }
    raycastQueue<L>(ro.data(), rd, count, tn.data(), kc<L>(), S(0), params.iterations, params.marchSteps,
                    params.precis);
    std::array<int, kMaxRaycastQueue> hits{};
    int hitCount = 0;
    for (int k = 0; k < count; ++k) {
        out[k] = JuliaHit<S>();
        if (!(tn[size_t(k)].x >= S(0))) continue;  // if (cond)
        out[k].resT = tn[size_t(k)];
        out[k].hit = true;
        hits[size_t(hitCount++)] = k;
    }
    for (int first = 0; first < hitCount; first += N) {
        const int lanes = std::min(N, hitCount - first);
        vec3<L> pos;
        LaneMask<L> cond(false);
        for (int j = 0; j < N; ++j) {
            const int k = hits[size_t(first + std::min(j, lanes - 1))];  // lanes past the rays copy the last one
            setLane(pos, j, ro[size_t(k)] + (tn[size_t(k)].x * rd[k]));
            setLane(cond, j, j < lanes);
        }
        const LiveLanes batch(laneBits(cond), 0);
        const vec3<L> normal = calcNormal(pos, kc<L>(), params.iterations, L(params.normalOffset), cond);
        for (int j = 0; j < lanes; ++j) out[hits[size_t(first + j)]].normal = lane(normal, j);
    }
}

}  // namespace julia

// =================================================================================================
// Pac-man (Proceduray fact sheet §3.3)
// =================================================================================================
namespace pacman {

// Head sphere r = 0.5, minus the mouth prism (apex moving with t in [0,1]), minus two eye dents.
template <typename T>
T pacMan(const vec3<T>& p, T t = T(0.5)) {
    const T r1 = T(0.5f);
    const vec2<T> r2(T(0.45f) * t + T(0.05f) * (T(1) - t), T(0.5f));

    vec3<T> rot_p(p.z, p.y, -p.x);
    rot_p = vec3<T>(rot_p.y, -rot_p.x + T(0.5), rot_p.z);
    const T mouth = sdTriPrism(rot_p, r2);

    const T eyes = opU(sdSphere(p + vec3<T>(T(-0.25), T(0.365), T(-0.225)), T(0.075)),
                       sdSphere(p + vec3<T>(T(0.25), T(0.365), T(-0.225)), T(0.075)));

    return opS(opS(sdSphere(p, r1), mouth), eyes);
}

// Mouth opening tau(time): i = int((200.5*time) % 600); if i > 300 then i = 600 - i; i/300.
// PORT: the HLSL recomputes this inside every distance evaluation; it depends on time only, so
// callers compute it once per intersection and pass it to pacMan.
template <typename T>
T PacmanMouthInterpolant(T time) {
    const int iAnimMin = 0;
    const int iAnimMax = 300;
    int iMax = hlsl::fremToInt(T(200.5) * time, iAnimMax * 2);
    if (iMax > iAnimMax) iMax = 2 * iAnimMax - iMax;
    iMax += iAnimMin;
    return static_cast<T>(iMax) / static_cast<T>(iAnimMax);
}

// attr.color of a Pac-man hit: white on the spherical head (| |n . normalize(P)| - 1 | <= 0.001),
// black elsewhere (mouth and eyes). A NaN normal gives white (the > test is false).
template <typename T>
vec4<T> PacmanHitColor(const vec3<T>& hitSurfaceNormal, const vec3<T>& position) {
    // PORT: the `if (...) return black; return white;` is a select per lane.
    const LaneMask<T> offHead =
        hlsl::abs(hlsl::abs(hlsl::dot(hitSurfaceNormal, hlsl::normalize(position))) - T(1)) > T(0.001);
    return select(offHead, vec4<T>(T(0), T(0), T(0), T(1)), vec4<T>(T(1), T(1), T(1), T(1)));
}

}  // namespace pacman

// =================================================================================================
// D3D12 sample: fractal pyramid and the SignedDistance primitive switch
// =================================================================================================
namespace d3d12 {

inline constexpr int N_FRACTAL_ITERATIONS = 4;

// Sierpinski-style pyramid: per iteration the nearest of the five vertices (apex, then the four
// base corners; ties keep the earlier one) is found and p = Scale*p - v*(Scale - 1); the result
// is sdPyramid(p, h) * Scale^-n (pow through exp2/log2).
// h = {sin a, cos a, height}; base half-width a = h.z*h.y/h.x.
// PORT: the position comes by reference and is copied a component at a time: a vec3 of lanes passed by value was
// copied with wider loads than the stores that made it (a store-forwarding stall per call).
// PORT: `scaleFactor`, where the caller has it, is Scale^-iterations (fractalPyramidScaleFactor) computed once for a
// whole march rather than at every sample: the same bits, since pow depends only on its arguments and the
// floating-point mode, which a march keeps.
template <typename T>
T sdFractalPyramid(const vec3<T>& at, const vec3<T>& h, T Scale = T(2), int iterations = N_FRACTAL_ITERATIONS,
                   const T* scaleFactor = nullptr) {
    vec3<T> position(at.x, at.y, at.z);
    const T a = h.z * h.y / h.x;
    const vec3<T> v1(T(0), h.z, T(0));
    const vec3<T> v2(-a, T(0), a);
    const vec3<T> v3(a, T(0), -a);
    const vec3<T> v4(a, T(0), a);
    const vec3<T> v5(-a, T(0), -a);

    int n = 0;
    for (n = 0; n < iterations; n++) {
        if constexpr (kIsLanes<T>) {
            // PORT: over lanes, the four `if (d < dist) { v = vk; dist = d; }` pick the same vertex another way: the
            // first one at the least distance. The least distance comes from a tree of minimums (lesserOf), and
            // each lane takes the first vertex whose distance equals it; where a lane's distances are NaN (a NaN
            // position reaches all five) none equals it and the lane keeps v1, as the ifs do. Bit for bit the ifs'
            // choice (tests/procedural/lanes_*_test.cpp), in a chain of dependent instructions half as long: these
            // iterations are latency-bound.
            const T d1 = length_toPow2(position - v1), d2 = length_toPow2(position - v2);
            const T d3 = length_toPow2(position - v3), d4 = length_toPow2(position - v4);
            const T d5 = length_toPow2(position - v5);
            const T least = lesserOf(lesserOf(lesserOf(d1, d2), lesserOf(d3, d4)), d5);
            const vec3<T> v =
                select(d1 == least, v1,
                       select(d2 == least, v2,
                              select(d3 == least, v3, select(d4 == least, v4, select(d5 == least, v5, v1)))));
            position = Scale * position - v * (Scale - T(1));
            continue;
        }
        T dist;
        T d;
        vec3<T> v;
        // PORT: each `if (d < dist) { v = vk; dist = d; }` is a select per lane.
        LaneMask<T> nearer;
        v = v1;
        dist = length_toPow2(position - v1);
        d = length_toPow2(position - v2);
        nearer = d < dist; v = select(nearer, v2, v); dist = select(nearer, d, dist);
        d = length_toPow2(position - v3);
        nearer = d < dist; v = select(nearer, v3, v); dist = select(nearer, d, dist);
        d = length_toPow2(position - v4);
        nearer = d < dist; v = select(nearer, v4, v); dist = select(nearer, d, dist);
        d = length_toPow2(position - v5);
        nearer = d < dist; v = select(nearer, v5, v); dist = select(nearer, d, dist);

        position = Scale * position - v * (Scale - T(1));
    }
    const T distance = sdPyramid(position, h);
    return distance * (scaleFactor ? *scaleFactor : hlsl::pow(Scale, static_cast<T>(-n)));
}

// Scale^-n of sdFractalPyramid after its `iterations` iterations (n = iterations, or 0 when there are none).
template <typename T>
T fractalPyramidScaleFactor(T Scale = T(2), int iterations = N_FRACTAL_ITERATIONS) {
    return hlsl::pow(Scale, static_cast<T>(-std::max(iterations, 0)));
}

// primitiveType values of the D3D12 sample's SignedDistance hit group (i = 3..9).
enum class SignedDistancePrimitive : std::uint32_t {
    MiniSpheres = 0,
    IntersectedRoundCube = 1,
    SquareTorus = 2,
    TwistedTorus = 3,
    Cog = 4,
    Cylinder = 5,
    FractalPyramid = 6,
};

// The fractal pyramid's Scale^-n (sdFractalPyramid's `scaleFactor`), for a march to compute once.
template <typename T>
T fractalPyramidPrimitiveScaleFactor() {
    return fractalPyramidScaleFactor(T(2));
}

// Local AABB space [-1,1]^3. An unknown type gives 0 (the HLSL default case).
// PORT: `pyramidScaleFactor`: fractalPyramidPrimitiveScaleFactor's value, where a march computed it once.
template <typename T>
T GetDistanceFromSignedDistancePrimitive(const vec3<T>& position, SignedDistancePrimitive signedDistancePrimitive,
                                         const T* pyramidScaleFactor = nullptr) {
    switch (signedDistancePrimitive) {
        case SignedDistancePrimitive::MiniSpheres: return sdMiniSpheres(position);
        case SignedDistancePrimitive::IntersectedRoundCube: return sdIntersectedRoundCube(position);
        case SignedDistancePrimitive::SquareTorus: return sdSquareTorus(position);
        case SignedDistancePrimitive::TwistedTorus: return sdTwistedTorus(position);
        case SignedDistancePrimitive::Cog: return sdCog(position);
        case SignedDistancePrimitive::Cylinder: return sdCylinderColumns(position);
        case SignedDistancePrimitive::FractalPyramid:
            // Base at y == -1 of the AABB; 63.435 degrees at the base, height 2.
            return sdFractalPyramid(position + vec3<T>(T(0), T(1), T(0)), vec3<T>(T(0.894), T(0.447), T(2.0)), T(2),
                                    N_FRACTAL_ITERATIONS, pyramidScaleFactor);
    }
    return T(0);
}

}  // namespace d3d12

}  // namespace refray::procedural::math
