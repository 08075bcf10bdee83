// Lanes<S, N>: N values of the scalar type S computed together, one per ray of a wave (emulator/wave.h). The shader
// ports are templates on their scalar type; with T = Lanes<float, N> the same source runs over a wave's rays at once
// (SIMD), and with T = float, double or PerturbedFloat it stays the scalar code it was. Every operation is the scalar
// operation lane by lane, so lane i of a result is bit for bit what the scalar code gives for ray i, whatever N is and
// whichever lanes are active (docs/emulator.md, "Waves").
//
// Control flow is written once for both kinds of T through the lane-mask helpers below:
//   LaneMask<T>        bool for a scalar T, LaneBools<N> for Lanes<S, N> (the result of T < T)
//   select(m, a, b)    m ? a : b, lane by lane
//   anyLane(m)         whether some lane of m is set (for a scalar: m itself)
// A loop with a per-ray exit keeps a mask of the lanes still running, computes every lane and keeps the results of
// the running ones only (select), and stops when no lane runs; for a scalar T that is the original loop and break.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "procedural/math/hlsl.h"

namespace refray::procedural::math {

// The widest wave: 16 floats, one AVX-512 register (docs/emulator.md says why 16).
inline constexpr int kMaxLanes = 16;

template <int N>
struct LaneBools {
    bool v[N];

    LaneBools() = default;
    constexpr explicit LaneBools(bool b) {
        for (int i = 0; i < N; ++i) v[i] = b;
    }
    constexpr bool operator[](int i) const { return v[i]; }
    constexpr bool& operator[](int i) { return v[i]; }

    friend constexpr LaneBools operator&(LaneBools a, LaneBools b) {
        for (int i = 0; i < N; ++i) a.v[i] = a.v[i] && b.v[i];
        return a;
    }
    friend constexpr LaneBools operator|(LaneBools a, LaneBools b) {
        for (int i = 0; i < N; ++i) a.v[i] = a.v[i] || b.v[i];
        return a;
    }
    friend constexpr LaneBools operator!(LaneBools a) {
        for (int i = 0; i < N; ++i) a.v[i] = !a.v[i];
        return a;
    }
    // && and || on masks are the lane-wise & and | (both sides are evaluated, as in a shader's SIMD code).
    friend constexpr LaneBools operator&&(LaneBools a, LaneBools b) { return a & b; }
    friend constexpr LaneBools operator||(LaneBools a, LaneBools b) { return a | b; }
    LaneBools& operator&=(LaneBools b) { return *this = *this & b; }
    LaneBools& operator|=(LaneBools b) { return *this = *this | b; }
};

template <class S, int N = kMaxLanes>
struct Lanes {
    static_assert(std::is_trivially_default_constructible_v<S>, "GLM keeps components in unions");
    using Scalar = S;
    static constexpr int kCount = N;
    S v[N];

    Lanes() = default;
    // The same value in every lane: T(0.5f), T(ratio), and GLM's static_cast from float.
    template <class U>
        requires std::is_arithmetic_v<U> || std::is_same_v<U, S>
    constexpr Lanes(U x) {  // NOLINT: implicit, as a scalar literal promotes in HLSL
        const S s = S(x);
        for (int i = 0; i < N; ++i) v[i] = s;
    }
    constexpr S operator[](int i) const { return v[i]; }
    constexpr S& operator[](int i) { return v[i]; }

    template <class F>
    static Lanes generate(F f) {
        Lanes r;
        for (int i = 0; i < N; ++i) r.v[i] = f(i);
        return r;
    }

#define REFRAY_LANES_BINARY(op)                                        \
    friend Lanes operator op(const Lanes& a, const Lanes& b) {         \
        Lanes r;                                                       \
        for (int i = 0; i < N; ++i) r.v[i] = a.v[i] op b.v[i];         \
        return r;                                                      \
    }                                                                  \
    Lanes& operator op##=(const Lanes& b) { return *this = *this op b; }
    REFRAY_LANES_BINARY(+)
    REFRAY_LANES_BINARY(-)
    REFRAY_LANES_BINARY(*)
    REFRAY_LANES_BINARY(/)
#undef REFRAY_LANES_BINARY
    friend Lanes operator-(const Lanes& a) {
        Lanes r;
        for (int i = 0; i < N; ++i) r.v[i] = -a.v[i];
        return r;
    }
    friend Lanes operator+(const Lanes& a) { return a; }

#define REFRAY_LANES_COMPARE(op)                                              \
    friend LaneBools<N> operator op(const Lanes& a, const Lanes& b) {         \
        LaneBools<N> r;                                                       \
        for (int i = 0; i < N; ++i) r.v[i] = a.v[i] op b.v[i];                \
        return r;                                                             \
    }
    REFRAY_LANES_COMPARE(<)
    REFRAY_LANES_COMPARE(<=)
    REFRAY_LANES_COMPARE(>)
    REFRAY_LANES_COMPARE(>=)
    REFRAY_LANES_COMPARE(==)
    REFRAY_LANES_COMPARE(!=)
#undef REFRAY_LANES_COMPARE
};

template <class T>
struct IsLanes : std::false_type {};
template <class S, int N>
struct IsLanes<Lanes<S, N>> : std::true_type {};
template <class T>
inline constexpr bool kIsLanes = IsLanes<T>::value;

// ---- The lane-mask helpers (written once for scalars and lanes) -------------------------------------------------
namespace detail {
template <class T>
struct LaneMaskOf {
    using type = bool;
};
template <class S, int N>
struct LaneMaskOf<Lanes<S, N>> {
    using type = LaneBools<N>;
};
}  // namespace detail
template <class T>
using LaneMask = typename detail::LaneMaskOf<T>::type;

// The mask with every lane set (`true` for a scalar).
template <class T>
constexpr LaneMask<T> allLanesSet() { return LaneMask<T>(true); }

constexpr bool anyLane(bool m) { return m; }
template <int N>
constexpr bool anyLane(const LaneBools<N>& m) {
    bool any = false;
    for (int i = 0; i < N; ++i) any = any || m.v[i];
    return any;
}
constexpr bool allLanes(bool m) { return m; }
template <int N>
constexpr bool allLanes(const LaneBools<N>& m) {
    bool all = true;
    for (int i = 0; i < N; ++i) all = all && m.v[i];
    return all;
}

// m ? a : b, lane by lane; for a scalar mask, the plain conditional.
template <class T>
    requires(!kIsLanes<T>)
T select(bool m, const T& a, const T& b) {
    return m ? a : b;
}
template <class S, int N>
Lanes<S, N> select(const LaneBools<N>& m, const Lanes<S, N>& a, const Lanes<S, N>& b) {
    Lanes<S, N> r;
    for (int i = 0; i < N; ++i) r.v[i] = m.v[i] ? a.v[i] : b.v[i];
    return r;
}
template <int N>
LaneBools<N> select(const LaneBools<N>& m, const LaneBools<N>& a, const LaneBools<N>& b) {
    return (m & a) | (!m & b);
}
// Vectors of lanes (GLM's vec<K, Lanes>), component by component.
template <glm::length_t K, class S, int N, glm::qualifier Q>
glm::vec<K, Lanes<S, N>, Q> select(const LaneBools<N>& m, const glm::vec<K, Lanes<S, N>, Q>& a,
                                   const glm::vec<K, Lanes<S, N>, Q>& b) {
    glm::vec<K, Lanes<S, N>, Q> r;
    for (glm::length_t k = 0; k < K; ++k) r[k] = select(m, a[k], b[k]);
    return r;
}

// Lane i of a scalar is the scalar; of lanes, its lane i.
template <class T>
    requires(!kIsLanes<T>)
T lane(const T& x, int) {
    return x;
}
template <class S, int N>
S lane(const Lanes<S, N>& x, int i) {
    return x.v[i];
}
template <glm::length_t K, class S, int N, glm::qualifier Q>
glm::vec<K, S, Q> lane(const glm::vec<K, Lanes<S, N>, Q>& x, int i) {
    glm::vec<K, S, Q> r;
    for (glm::length_t k = 0; k < K; ++k) r[k] = x[k].v[i];
    return r;
}
constexpr bool lane(bool m, int) { return m; }
template <int N>
constexpr bool lane(const LaneBools<N>& m, int i) {
    return m.v[i];
}

// Writes lane i (the whole value for a scalar).
template <class T>
    requires(!kIsLanes<T>)
void setLane(T& x, int, const T& value) {
    x = value;
}
template <class S, int N>
void setLane(Lanes<S, N>& x, int i, const S& value) {
    x.v[i] = value;
}
template <glm::length_t K, class S, int N, glm::qualifier Q>
void setLane(glm::vec<K, Lanes<S, N>, Q>& x, int i, const glm::vec<K, S, Q>& value) {
    for (glm::length_t k = 0; k < K; ++k) x[k].v[i] = value[k];
}

}  // namespace refray::procedural::math

namespace refray::procedural::hlsl {

// The instructions over lanes: the scalar type's instruction lane by lane, so each lane is bit for bit the scalar
// result. min and max follow the scalar type's NaN rules (libm's fmin/fmax for float and double).
template <class S, int N>
struct ScalarOps<math::Lanes<S, N>> {
    using L = math::Lanes<S, N>;
    using Storage = typename ScalarOps<S>::Storage;
    template <class F>
    static L map(const L& a, F f) {
        L r;
        for (int i = 0; i < N; ++i) r.v[i] = f(a.v[i]);
        return r;
    }
    template <class F>
    static L map(const L& a, const L& b, F f) {
        L r;
        for (int i = 0; i < N; ++i) r.v[i] = f(a.v[i], b.v[i]);
        return r;
    }
    static constexpr bool kFloat = std::is_same_v<S, float>;
    // float lanes: the instructions a compiler can vectorise, each bit for bit libm's (glibc's fabsf, floorf, sqrtf,
    // fminf and fmaxf; the lanes test checks them on special values), so that the wave math runs in SIMD registers.
    static L abs(const L& x) {
        if constexpr (kFloat) {
            L r;
            for (int i = 0; i < N; ++i) r.v[i] = std::bit_cast<float>(std::bit_cast<uint32_t>(x.v[i]) & 0x7fffffffu);
            return r;
        } else {
            return map(x, [](S a) { return ScalarOps<S>::abs(a); });
        }
    }
    static L floor(const L& x) {
        if constexpr (kFloat) {
            // Below 2^23 in magnitude: truncate, step down where that rounded up, keep the sign (floor(-0) = -0);
            // from 2^23 on (and NaN, infinity) every float is its own floor.
            L r;
            for (int i = 0; i < N; ++i) {
                const float a = x.v[i];
                float t = float(int32_t(std::bit_cast<float>(std::bit_cast<uint32_t>(a) & 0x7fffffffu) < 0x1p23f ? a : 0.0f));
                t = t > a ? t - 1.0f : t;
                t = std::bit_cast<float>((std::bit_cast<uint32_t>(t) & 0x7fffffffu) | (std::bit_cast<uint32_t>(a) & 0x80000000u));
                r.v[i] = std::bit_cast<float>(std::bit_cast<uint32_t>(a) & 0x7fffffffu) < 0x1p23f ? t : a;
            }
            return r;
        } else {
            return map(x, [](S a) { return ScalarOps<S>::floor(a); });
        }
    }
    static L sqrt(const L& x) {
#if REFRAY_HAS_MXCSR
        if constexpr (kFloat && N % 4 == 0) {
            L r;
            for (int i = 0; i < N; i += 4) _mm_storeu_ps(r.v + i, _mm_sqrt_ps(_mm_loadu_ps(x.v + i)));
            return r;
        }
#endif
        return map(x, [](S a) { return ScalarOps<S>::sqrt(a); });
    }
    static L rsqrt(const L& x) {
        if constexpr (kFloat) return L(1.0f) / sqrt(x);
        else return map(x, [](S a) { return ScalarOps<S>::rsqrt(a); });
    }
    static L sin(const L& x) { return map(x, [](S a) { return ScalarOps<S>::sin(a); }); }
    static L cos(const L& x) { return map(x, [](S a) { return ScalarOps<S>::cos(a); }); }
    static L acos(const L& x) { return map(x, [](S a) { return ScalarOps<S>::acos(a); }); }
    static L atan(const L& x) { return map(x, [](S a) { return ScalarOps<S>::atan(a); }); }
    static L exp2(const L& x) { return map(x, [](S a) { return ScalarOps<S>::exp2(a); }); }
    static L log2(const L& x) { return map(x, [](S a) { return ScalarOps<S>::log2(a); }); }
    // glibc's fminf/fmaxf: the first operand when the two compare equal (so min(+0, -0) = +0), the other operand
    // when one is a quiet NaN, the second when both are. (Signalling NaNs, which no arithmetic makes, are not
    // quietened as libm does.)
    static L min(const L& a, const L& b) {
        if constexpr (kFloat) {
            L r;
            for (int i = 0; i < N; ++i) r.v[i] = (a.v[i] <= b.v[i] || (b.v[i] != b.v[i] && a.v[i] == a.v[i])) ? a.v[i] : b.v[i];
            return r;
        } else {
            return map(a, b, [](S x, S y) { return ScalarOps<S>::min(x, y); });
        }
    }
    static L max(const L& a, const L& b) {
        if constexpr (kFloat) {
            L r;
            for (int i = 0; i < N; ++i) r.v[i] = (a.v[i] >= b.v[i] || (b.v[i] != b.v[i] && a.v[i] == a.v[i])) ? a.v[i] : b.v[i];
            return r;
        } else {
            return map(a, b, [](S x, S y) { return ScalarOps<S>::max(x, y); });
        }
    }
    static L frem(const L& a, const L& b) { return map(a, b, [](S x, S y) { return ScalarOps<S>::frem(x, y); }); }
    // The scalar type's dot, lane by lane (its order of terms and its rounding).
    template <glm::length_t K, glm::qualifier Q>
    static L dot(const glm::vec<K, L, Q>& a, const glm::vec<K, L, Q>& b) {
        L r;
        for (int i = 0; i < N; ++i) {
            glm::vec<K, S, Q> x, y;
            for (glm::length_t k = 0; k < K; ++k) {
                x[k] = a[k].v[i];
                y[k] = b[k].v[i];
            }
            r.v[i] = ScalarOps<S>::dot(x, y);
        }
        return r;
    }
};

// The intrinsics whose HLSL lowering branches on a value: the scalar form lane by lane. More specialised than the
// scalar templates, so overload resolution picks these for lanes.
template <class S, int N>
math::Lanes<S, N> step(math::Lanes<S, N> a, math::Lanes<S, N> x) {
    return math::Lanes<S, N>::generate([&](int i) { return hlsl::step(a.v[i], x.v[i]); });
}
template <class S, int N>
math::Lanes<S, N> atan2(math::Lanes<S, N> y, math::Lanes<S, N> x) {
    return math::Lanes<S, N>::generate([&](int i) { return hlsl::atan2(y.v[i], x.v[i]); });
}
template <class S, int N>
math::Lanes<S, N> fmod(math::Lanes<S, N> x, math::Lanes<S, N> y) {
    return math::Lanes<S, N>::generate([&](int i) { return hlsl::fmod(x.v[i], y.v[i]); });
}

}  // namespace refray::procedural::hlsl

namespace refray::procedural::math {
// hlsl.h's vector forms call these unqualified (for lanes, argument-dependent lookup searches this namespace).
using hlsl::atan2;
using hlsl::fmod;
using hlsl::step;
}  // namespace refray::procedural::math
