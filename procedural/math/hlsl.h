// Ports: the HLSL intrinsics used by every *.hlsli, as DXC lowers them (HLOperationLower).
// Sources: Proceduray fact sheet §3.1 and D3D12 sample fact sheet §2.12; templated on T.
//
// Every function here reproduces what the compiled shader computes, not what libm computes:
// min/max/clamp ignore a NaN operand, saturate(NaN) is 0, atan2(0,0) is pi/2, pow goes through
// exp2/log2, fmod is DXC's frac-based lowering, normalize does not guard against zero vectors.
// Callers qualify every call (`hlsl::max(a, b)`) so GLM's and the standard library's namesakes,
// which have different NaN rules, can never be picked by argument-dependent lookup.
#pragma once

#include <cmath>
#include <concepts>
#include <numbers>

#include <glm/glm.hpp>

#include "procedural/math/transcendentals.h"

#if defined(__SSE__) || defined(__x86_64__) || defined(_M_X64)
#include <xmmintrin.h>
#define REFRAY_HAS_MXCSR 1
#else
#define REFRAY_HAS_MXCSR 0
#endif

namespace refray::procedural::hlsl {

template <glm::length_t N, typename T, glm::qualifier Q = glm::defaultp>
using vec = glm::vec<N, T, Q>;

namespace detail {

template <glm::length_t N, typename T, glm::qualifier Q, class F>
vec<N, T, Q> map(const vec<N, T, Q>& a, F f) {
    vec<N, T, Q> r{};
    for (glm::length_t i = 0; i < N; ++i) r[i] = f(a[i]);
    return r;
}

template <glm::length_t N, typename T, glm::qualifier Q, class F>
vec<N, T, Q> map(const vec<N, T, Q>& a, const vec<N, T, Q>& b, F f) {
    vec<N, T, Q> r{};
    for (glm::length_t i = 0; i < N; ++i) r[i] = f(a[i], b[i]);
    return r;
}

}  // namespace detail

// ---- The scalar types ------------------------------------------------------------------------
// The operations below that a GPU computes in one instruction (DXIL's unary and binary float ops, Dot2/3/4) come
// from ScalarOps<T>; everything else is written once over them. float and double are correctly rounded where D3D
// demands it; their transcendentals are SLEEF's to 3.5 ulp for float (procedural/math/transcendentals.h) and libm's
// for double. A scalar type of another kind specialises ScalarOps
// (procedural/math/perturbed.h: float with the errors the variation model allows). A specialisation is found when a
// template is instantiated, so it may come after this header, which an overload could not.
template <class T>
struct ScalarOps;

template <std::floating_point T>
struct ScalarOps<T> {
    using Storage = T;  // the built-in type the constants are written in
    static T abs(T x) { return std::fabs(x); }
    static T floor(T x) { return std::floor(x); }
    static T sqrt(T x) { return std::sqrt(x); }
    static T rsqrt(T x) { return T(1) / std::sqrt(x); }
    static T sin(T x) { return transcendental(math::Transcendental::Sin, x, [](T a) { return std::sin(a); }); }
    static T cos(T x) { return transcendental(math::Transcendental::Cos, x, [](T a) { return std::cos(a); }); }
    static T acos(T x) { return transcendental(math::Transcendental::Acos, x, [](T a) { return std::acos(a); }); }
    static T atan(T x) { return transcendental(math::Transcendental::Atan, x, [](T a) { return std::atan(a); }); }
    static T exp2(T x) { return transcendental(math::Transcendental::Exp2, x, [](T a) { return std::exp2(a); }); }
    static T log2(T x) { return transcendental(math::Transcendental::Log2, x, [](T a) { return std::log2(a); }); }
    // float: SLEEF's (procedural/math/transcendentals.h), the functions float lanes compute eight at a time; double:
    // libm's.
    template <class Libm>
    static T transcendental(math::Transcendental f, T x, Libm libm) {
        if constexpr (std::is_same_v<T, float>) return math::transcendental(f, x);
        else return libm(x);
    }
    static T min(T a, T b) { return std::fmin(a, b); }
    static T max(T a, T b) { return std::fmax(a, b); }
    static T frem(T x, T y) { return std::fmod(x, y); }
    // A plain sum of products in component order (no fused multiply-add).
    template <glm::length_t N, glm::qualifier Q>
    static T dot(const glm::vec<N, T, Q>& a, const glm::vec<N, T, Q>& b) {
        T s = a[0] * b[0];
        for (glm::length_t i = 1; i < N; ++i) s = s + a[i] * b[i];
        return s;
    }
};

template <class T>
concept Scalar = requires { typename ScalarOps<T>::Storage; };

// ---- Constants -------------------------------------------------------------------------------
template <Scalar T>
inline constexpr T kPi = T(std::numbers::pi_v<typename ScalarOps<T>::Storage>);
template <Scalar T>
inline constexpr T kLn2 = T(std::numbers::ln2_v<typename ScalarOps<T>::Storage>);
template <Scalar T>
inline constexpr T kLog2e = T(std::numbers::log2e_v<typename ScalarOps<T>::Storage>);

// ---- abs, floor, sqrt, rsqrt, trigonometry ---------------------------------------------------
template <Scalar T>
T abs(T x) { return ScalarOps<T>::abs(x); }
template <Scalar T>
T floor(T x) { return ScalarOps<T>::floor(x); }
template <Scalar T>
T sqrt(T x) { return ScalarOps<T>::sqrt(x); }
// PORT: GPU rsqrt is an approximation (2^-21 relative error in D3D11.3 §22.10.19); the reference rounds 1/sqrt
// correctly.
template <Scalar T>
T rsqrt(T x) { return ScalarOps<T>::rsqrt(x); }
template <Scalar T>
T sin(T x) { return ScalarOps<T>::sin(x); }
template <Scalar T>
T cos(T x) { return ScalarOps<T>::cos(x); }
// No clamping of the argument: |x| > 1 gives NaN, as on the GPU (Proceduray hazard H6).
template <Scalar T>
T acos(T x) { return ScalarOps<T>::acos(x); }

// ---- min, max, clamp, saturate: IEEE minNum/maxNum (a NaN operand is ignored) ---------------
template <Scalar T>
T min(T a, T b) { return ScalarOps<T>::min(a, b); }
template <Scalar T>
T max(T a, T b) { return ScalarOps<T>::max(a, b); }
// clamp(x, lo, hi) = min(max(x, lo), hi): clamp(NaN, lo, hi) = lo.
template <Scalar T>
T clamp(T x, T lo, T hi) { return hlsl::min(hlsl::max(x, lo), hi); }
// saturate(NaN) = 0.
template <Scalar T>
T saturate(T x) { return clamp(x, T(0), T(1)); }

// ---- lerp, step, smoothstep, frac ------------------------------------------------------------
// lerp(a, b, s) = a + s*(b - a) (not the two-product form).
template <Scalar T>
T lerp(T a, T b, T s) { return a + s * (b - a); }
// step(a, x) = (x >= a) ? 1 : 0; a NaN operand gives 0.
template <Scalar T>
T step(T a, T x) { return x >= a ? T(1) : T(0); }
// smoothstep(a, b, x): t = saturate((x - a)/(b - a)), t*t*(3 - 2t).
template <Scalar T>
T smoothstep(T a, T b, T x) {
    const T t = saturate((x - a) / (b - a));
    return t * t * (T(3) - T(2) * t);
}
// frac(x) = x - floor(x).
template <Scalar T>
T frac(T x) { return x - hlsl::floor(x); }

// ---- exp2, log2, log, exp, pow as DXC lowers them --------------------------------------------
// PORT: GPU exp2/log2 are approximations (2^-21 relative or absolute, D3D11.3 §22.10.6 and §22.10.8); the reference
// uses libm.
template <Scalar T>
T exp2(T x) { return ScalarOps<T>::exp2(x); }
template <Scalar T>
T log2(T x) { return ScalarOps<T>::log2(x); }
// log(x) = log2(x) * ln2.
template <Scalar T>
T log(T x) { return hlsl::log2(x) * kLn2<T>; }
// exp(x) = exp2(x * log2(e)).
template <Scalar T>
T exp(T x) { return hlsl::exp2(x * kLog2e<T>); }
// pow(x, y) = exp2(y * log2(x)): pow(0, y>0) = 0, pow(0, 0) = NaN, pow(x<0, y) = NaN.
// A literal exponent of exactly 2 compiles to x*x instead; ports write x*x there.
// Lane types compute it once where every live lane holds one base and one exponent (ScalarOps::powOnce).
template <Scalar T>
T pow(T x, T y) {
    if constexpr (requires(T& r) { ScalarOps<T>::powOnce(x, y, r); }) {
        T r;
        if (ScalarOps<T>::powOnce(x, y, r)) return r;
    }
    return hlsl::exp2(y * hlsl::log2(x));
}

// ---- atan2 as DXC lowers it ------------------------------------------------------------------
// r = atan(y/x), then: x<0 && y>=0 -> r+pi; x<0 && y<0 -> r-pi; x==0 && y<0 -> -pi/2;
// x==0 && y>=0 -> +pi/2. So atan2(0, 0) = pi/2 (libm: 0) and atan2(0, -0) = pi/2 (libm: pi).
template <Scalar T>
T atan2(T y, T x) {
    T r = ScalarOps<T>::atan(y / x);
    const bool xLt0 = x < T(0);
    const bool xEq0 = x == T(0);
    const bool yGe0 = y >= T(0);
    const bool yLt0 = y < T(0);
    if (xLt0 && yGe0) r = r + kPi<T>;
    if (xLt0 && yLt0) r = r - kPi<T>;
    if (xEq0 && yLt0) r = -kPi<T> / T(2);
    if (xEq0 && yGe0) r = kPi<T> / T(2);
    return r;
}

// ---- fmod (intrinsic) and % (operator) -------------------------------------------------------
// The fmod() intrinsic as DXC lowers it: q = x/y, f = frac(|q|), (q >= -q ? f : -f) * y.
// It keeps the sign of x like C fmod but is not the exact remainder: fmod(1, 0.05f) = 0
// where fmodf gives ~0.05 (D3D12 fact sheet §2.12, H14).
template <Scalar T>
T fmod(T x, T y) {
    const T q = x / y;
    const T f = frac(hlsl::abs(q));
    return (q >= -q ? f : -f) * y;
}
// The HLSL `%` operator on floats (also `float % int`, the int converted to float first):
// the truncated remainder with the sign of the dividend, i.e. C fmod (LLVM frem).
template <Scalar T>
T frem(T x, T y) { return ScalarOps<T>::frem(x, y); }
// `int i = floatExpr % intConst;` -- the remainder truncated towards zero (ftoi).
// Defined for finite remainders that fit in int; negative or NaN time is outside the contract.
template <Scalar T>
int fremToInt(T x, int m) { return static_cast<int>(hlsl::frem(x, static_cast<T>(m))); }

// ---- Vector forms (component-wise) -----------------------------------------------------------
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> abs(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return hlsl::abs(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> floor(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return hlsl::floor(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> sqrt(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return hlsl::sqrt(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> sin(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return hlsl::sin(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> cos(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return hlsl::cos(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> frac(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return frac(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> log2(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return log2(x); }); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> saturate(const vec<N, T, Q>& v) { return detail::map(v, [](T x) { return saturate(x); }); }

template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> min(const vec<N, T, Q>& a, const vec<N, T, Q>& b) {
    return detail::map(a, b, [](T x, T y) { return hlsl::min(x, y); });
}
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> max(const vec<N, T, Q>& a, const vec<N, T, Q>& b) {
    return detail::map(a, b, [](T x, T y) { return hlsl::max(x, y); });
}
// HLSL promotes a scalar operand to a vector: max(v, 0.0).
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> min(const vec<N, T, Q>& a, T b) { return hlsl::min(a, vec<N, T, Q>(b)); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> max(const vec<N, T, Q>& a, T b) { return hlsl::max(a, vec<N, T, Q>(b)); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> clamp(const vec<N, T, Q>& x, T lo, T hi) {
    return detail::map(x, [lo, hi](T c) { return clamp(c, lo, hi); });
}
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> lerp(const vec<N, T, Q>& a, const vec<N, T, Q>& b, T s) { return a + s * (b - a); }
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> lerp(const vec<N, T, Q>& a, const vec<N, T, Q>& b, const vec<N, T, Q>& s) {
    return a + s * (b - a);
}
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> pow(const vec<N, T, Q>& x, const vec<N, T, Q>& y) {
    return detail::map(x, y, [](T a, T b) { return pow(a, b); });
}
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> fmod(const vec<N, T, Q>& x, const vec<N, T, Q>& y) {
    return detail::map(x, y, [](T a, T b) { return fmod(a, b); });
}

// dot is DXIL's Dot2/Dot3/Dot4: for float and double a plain sum of products in component order (no fused
// multiply-add).
template <glm::length_t N, typename T, glm::qualifier Q>
T dot(const vec<N, T, Q>& a, const vec<N, T, Q>& b) { return ScalarOps<T>::dot(a, b); }
// length(v) = sqrt(dot(v, v)).
template <glm::length_t N, typename T, glm::qualifier Q>
T length(const vec<N, T, Q>& v) { return hlsl::sqrt(hlsl::dot(v, v)); }
// normalize(v) = v * rsqrt(dot(v, v)): a zero vector gives NaN components (no guard, H16). Always inlined: a float3
// returned from a call comes back packed in registers through memory, a store-forwarding stall per call.
template <glm::length_t N, typename T, glm::qualifier Q>
[[gnu::always_inline]] inline vec<N, T, Q> normalize(const vec<N, T, Q>& v) { return v * hlsl::rsqrt(hlsl::dot(v, v)); }
// reflect(i, n) = i - 2*dot(n, i)*n.
template <glm::length_t N, typename T, glm::qualifier Q>
vec<N, T, Q> reflect(const vec<N, T, Q>& i, const vec<N, T, Q>& n) { return i - T(2) * hlsl::dot(n, i) * n; }

// ---- Denormal flushing (Proceduray hazard H18) -----------------------------------------------
// D3D float32 arithmetic flushes denormals. While an instance lives, the calling thread runs
// with FTZ (results flushed) and DAZ (inputs treated as zero) set in MXCSR; the destructor puts
// those two bits back as they were (exception flags raised meanwhile are kept). MXCSR is per
// thread: every worker thread that runs shader math needs its own instance. Without SSE this
// is a no-op and `active()` reports false. `flush` false clears both bits instead: denormals are
// kept (what DXIL's fp32-denorm-mode "any" also allows).
class ScopedFlushDenormals {
public:
    explicit ScopedFlushDenormals(bool flush = true) {
#if REFRAY_HAS_MXCSR
        saved_ = _mm_getcsr();
        _mm_setcsr(flush ? saved_ | kMask : saved_ & ~kMask);
#else
        (void)flush;
#endif
    }
    ~ScopedFlushDenormals() {
#if REFRAY_HAS_MXCSR
        _mm_setcsr((_mm_getcsr() & ~kMask) | (saved_ & kMask));
#endif
    }
    ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
    ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;

    static constexpr bool active() { return REFRAY_HAS_MXCSR != 0; }

private:
    static constexpr unsigned kFlushToZero = 0x8000u;     // MXCSR bit 15
    static constexpr unsigned kDenormalsAreZero = 0x0040u;  // MXCSR bit 6
    static constexpr unsigned kMask = kFlushToZero | kDenormalsAreZero;
    unsigned saved_ = 0;
};

}  // namespace refray::procedural::hlsl

// The lane types (Lanes<S, N>, the shader math over a wave's rays) specialise ScalarOps and the branching intrinsics.
#include "procedural/math/lanes.h"
