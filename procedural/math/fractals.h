// Ports: Proceduray Mandelbulb.hlsli, JuliaSets.hlsli, pacMan; D3D12 SignedDistanceFractals.hlsli.
// Proceduray: Mandelbulb and quaternion-Julia estimators and marches, the Pac-man SDF (from
// SignedDistancePrimitives.hlsli) and its mouth animation (ProceduralPrimitivesLibrary.hlsli).
// D3D12 sample: sdFractalPyramid and its GetDistanceFromSignedDistancePrimitive switch.
#pragma once

#include <cstdint>

#include "procedural/math/analytic.h"
#include "procedural/math/hlsl.h"
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

    for (int i = 0; i < iterations; i++) {
        // The non-PERFORMANCE branch (the live one). Exponents 7 and 8 are not the literal 2, so
        // DXC lowers both pows to exp2(y*log2(x)).
        dz = T(8) * hlsl::pow(hlsl::sqrt(m), T(7)) * dz + T(1);

        const T r = hlsl::length(w);
        const T b = T(8) * hlsl::acos(w.y / r);
        const T a = T(8) * hlsl::atan2(w.x, w.z);
        w = p + hlsl::pow(r, T(8)) *
                    vec3<T>(hlsl::sin(b) * hlsl::sin(a), hlsl::cos(b), hlsl::sin(b) * hlsl::cos(a));

        trap = hlsl::min(trap, vec4<T>(hlsl::abs(w), m));

        m = hlsl::dot(w, w);
        if (m > T(256)) break;
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
    bool hit = false;
    T thit = T(0);
    vec3<T> normal{};  // local space, computed at pos
    vec4<T> color{};   // the orbit trap of the last mdist call (attr.color)
    vec3<T> pos{};     // the last sample; when the loop runs out it lags thit by one step (H14)
};

// Bounding sphere (centre 0, radius 1.25; unit rd assumed) gives [dis.x, dis.y], clipped to
// [0, 1000]. Up to iMax steps: pos = ro + rd*t; break if t > dis.y or mdist(pos) < 1e-4*t;
// t += h. Hit iff t < dis.y afterwards, converged or not. stepScale is ignored, as in the HLSL.
// PORT: takes iMax (MandelbulbIterationCount) instead of (time, instanceId), and returns the
// HLSL `out` thit/attr as a struct. PORT: `params` holds the HLSL's constants (MandelbulbParams).
template <typename T>
MandelbulbHit<T> MandelbulbDistance(const vec3<T>& ro, const vec3<T>& rd, int iMax,
                                    const MandelbulbParams<T>& params = {}) {
    MandelbulbHit<T> result;

    vec2<T> dis = isphere(vec4<T>(T(0), T(0), T(0), T(1.25)), ro, rd);
    if (dis.y < T(0)) return result;
    dis.x = hlsl::max(dis.x, T(0));
    dis.y = hlsl::min(dis.y, T(1000));

    vec4<T> trap(T(0));
    T t = dis.x;
    vec3<T> pos(T(0));

    for (int i = 0; i < iMax; i++) {
        pos = ro + rd * t;
        const T th = params.threshold * t;
        const T h = mdist(pos, trap, params.iterations);
        if (t > dis.y || h < th) break;
        t += h;
    }

    if (t < dis.y) {
        result.hit = true;
        result.thit = t;
        result.normal = calcNormal(pos, params.normalOffset, params.iterations);
        result.color = trap;
    }
    result.pos = pos;
    return result;
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
    if (h < T(0)) return vec2<T>(T(-1), T(-1));
    h = hlsl::sqrt(h);
    return vec2<T>(-b - h, -b + h);
}

// Distance estimate of z -> z^3 + c over quaternions: (d, n) with n the iterations survived.
// dz2 *= 9*|z^2|^2; z = z^3 + c; m2 = |z|^2; break if m2 > 256; n += 1.
// d = 0.25*log(m2)*sqrt(m2/dz2). At p = 0, dz2 = 0 and d = +inf with n = 22 (H8).
template <typename T>
vec2<T> jdist(const vec3<T>& p, const vec4<T>& c, int iMax) {
    vec4<T> z(p, T(0));
    T dz2 = T(1);
    T m2 = T(0);
    T n = T(0);
    for (int i = 0; i < iMax; i++) {
        dz2 *= T(9) * qLength2_float4(qSquare_float4(z));
        z = qCube_float4(z) + c;
        m2 = qLength2_float4(z);
        if (m2 > T(256)) break;
        n += T(1);
    }
    const T d = (T(0.25) * hlsl::log(m2)) * hlsl::sqrt(m2 / dz2);
    return vec2<T>(d, n);
}

// calcNormal's tetrahedral offset, 0.5773*kPrecis (a product in T, as the HLSL computes it).
template <typename T>
T calcNormalOffset() { return T(0.5773f) * kPrecis<T>; }

// Tetrahedral normal with offset 0.5773*kPrecis on jdist(...).x.
// PORT: the offset is a parameter (the normalEpsilonFactor knob).
template <typename T>
vec3<T> calcNormal(const vec3<T>& pos, const vec4<T>& c = kc<T>(), int iMax = kIterations,
                   T offset = calcNormalOffset<T>()) {
    return sdCalculateNormal(pos, [&c, iMax](const vec3<T>& q) { return jdist(q, c, iMax).x; }, offset);
}

// March in q-space between the cut planes y = deltaT and y = -1.1 inside the sphere of radius
// 1.2: up to 1024 steps of min(d, 0.2) from tmin, stopping when d < kPrecis or t > tmax; then a
// secant step when lt > 9.9999997e-5 and the last d < 0. Returns (t, n) when t < tmax (running
// out of steps counts as a hit, H15), (-1, n) when t >= tmax, and (-2, 0) when a plane or the
// sphere rules it out. IEEE comparisons decide every branch (rd.y = 0, H10).
// PORT: the step limit 1024 and the stop test's kPrecis are parameters (maxSteps, precis: the stepsFactor and
// thresholdFactor knobs); tmin starts at kPrecis and the secant gate stays 9.9999997e-5 whatever precis is.
template <typename T>
vec2<T> raycast(const vec3<T>& ro, const vec3<T>& rd, const vec4<T>& c = kc<T>(), T deltaT = T(0),
                int iMax = kIterations, int maxSteps = kMarchSteps, T precis = kPrecis<T>) {
    T tmax = T(7000);
    T tmin = kPrecis<T>;

    const T upperPlane = deltaT;
    const T tpS = (upperPlane - ro.y) / rd.y;
    const bool isCamAboveUpper = (ro.y > upperPlane);
    if (tpS > T(0)) {
        if (isCamAboveUpper) tmin = hlsl::max(tmin, tpS);
        else tmax = hlsl::min(tmax, tpS);
    } else {
        if (isCamAboveUpper) return vec2<T>(T(-2), T(0));
    }

    const T lowerPlane = T(-1.1f);
    const T tpF = (lowerPlane - ro.y) / rd.y;
    const bool isCamBellowLower = (ro.y < lowerPlane);
    if (tpF > T(0)) {
        if (isCamBellowLower) tmin = hlsl::max(tmin, tpF);
        else tmax = hlsl::min(tmax, tpF);
    } else {
        if (isCamBellowLower) return vec2<T>(T(-2), T(0));
    }

    const vec2<T> bv = iSphere(ro, rd, T(1.2f));
    if (bv.y < T(0)) return vec2<T>(T(-2), T(0));
    tmin = hlsl::max(tmin, bv.x);
    tmax = hlsl::min(tmax, bv.y);

    vec2<T> res(T(-1), T(-1));
    T t = tmin;
    T lt = T(0);
    T lh = T(0);
    for (int i = 0; i < maxSteps; i++) {
        res = jdist(ro + (rd * t), c, iMax);
        if (res.x < precis) break;
        lt = t;
        lh = res.x;
        t += hlsl::min(res.x, T(0.2));
        if (t > tmax) break;
    }
    if ((lt > T(9.9999997e-05f)) && (res.x < T(0))) {
        t = lt - ((lh * (t - lt)) / (res.x - lh));
    }
    T s = T(0);
    if (t < tmax) s = t;
    else s = T(-1);
    res.x = s;
    return res;
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
    bool hit = false;
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
    const bool cond = (tn.x >= T(0));
    if (cond) {
        const vec3<T> pos = ro + (tn.x * rd);
        result.normal = calcNormal(pos, kc<T>(), params.iterations, params.normalOffset);
        result.resT = tn;
        result.hit = true;
    }
    return result;
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
    if (hlsl::abs(hlsl::abs(hlsl::dot(hitSurfaceNormal, hlsl::normalize(position))) - T(1)) > T(0.001))
        return vec4<T>(T(0), T(0), T(0), T(1));
    return vec4<T>(T(1), T(1), T(1), T(1));
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
template <typename T>
T sdFractalPyramid(vec3<T> position, const vec3<T>& h, T Scale = T(2), int iterations = N_FRACTAL_ITERATIONS) {
    const T a = h.z * h.y / h.x;
    const vec3<T> v1(T(0), h.z, T(0));
    const vec3<T> v2(-a, T(0), a);
    const vec3<T> v3(a, T(0), -a);
    const vec3<T> v4(a, T(0), a);
    const vec3<T> v5(-a, T(0), -a);

    int n = 0;
    for (n = 0; n < iterations; n++) {
        T dist;
        T d;
        vec3<T> v;
        v = v1;
        dist = length_toPow2(position - v1);
        d = length_toPow2(position - v2);
        if (d < dist) { v = v2; dist = d; }
        d = length_toPow2(position - v3);
        if (d < dist) { v = v3; dist = d; }
        d = length_toPow2(position - v4);
        if (d < dist) { v = v4; dist = d; }
        d = length_toPow2(position - v5);
        if (d < dist) { v = v5; dist = d; }

        position = Scale * position - v * (Scale - T(1));
    }
    const T distance = sdPyramid(position, h);
    return distance * hlsl::pow(Scale, static_cast<T>(-n));
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

// Local AABB space [-1,1]^3. An unknown type gives 0 (the HLSL default case).
template <typename T>
T GetDistanceFromSignedDistancePrimitive(const vec3<T>& position, SignedDistancePrimitive signedDistancePrimitive) {
    switch (signedDistancePrimitive) {
        case SignedDistancePrimitive::MiniSpheres: return sdMiniSpheres(position);
        case SignedDistancePrimitive::IntersectedRoundCube: return sdIntersectedRoundCube(position);
        case SignedDistancePrimitive::SquareTorus: return sdSquareTorus(position);
        case SignedDistancePrimitive::TwistedTorus: return sdTwistedTorus(position);
        case SignedDistancePrimitive::Cog: return sdCog(position);
        case SignedDistancePrimitive::Cylinder: return sdCylinderColumns(position);
        case SignedDistancePrimitive::FractalPyramid:
            // Base at y == -1 of the AABB; 63.435 degrees at the base, height 2.
            return sdFractalPyramid(position + vec3<T>(T(0), T(1), T(0)), vec3<T>(T(0.894), T(0.447), T(2.0)), T(2));
    }
    return T(0);
}

}  // namespace d3d12

}  // namespace refray::procedural::math
