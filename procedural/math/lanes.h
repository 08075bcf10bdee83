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
#include <cstring>
#include <cstdint>
#include <type_traits>

#include "procedural/math/hlsl.h"

#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace refray::procedural::math {

// The widest wave: 16 floats, one AVX-512 register (docs/emulator.md says why 16).
inline constexpr int kMaxLanes = 16;
// The bits of all N lanes (bit i: lane i).
template <int N>
inline constexpr uint32_t kLaneBits = N >= 32 ? ~0u : (1u << N) - 1u;

// The lanes whose results still count (LiveLanes, below); bit i is lane i.
inline thread_local uint32_t tLiveLanes = ~0u;

namespace detail {
// The storage of N lanes of S: a GCC vector (operators become SIMD instructions, kept in registers where they fit)
// for the built-in arithmetic types, an array for any other scalar type (PerturbedFloat).
template <class S, int N, bool kVector = std::is_arithmetic_v<S> && !std::is_same_v<S, bool>>
struct LaneStorage {
    using type = S[N];
    static constexpr bool kIsVector = false;
};
template <class S, int N>
struct LaneStorage<S, N, true> {
    typedef S type __attribute__((vector_size(sizeof(S) * N)));
    static constexpr bool kIsVector = true;
};
// The signed integer of S's width: what a vector comparison of S lanes gives per lane (-1 or 0).
template <class S>
using LaneCompareInt = std::conditional_t<sizeof(S) == 8, int64_t, std::conditional_t<sizeof(S) == 4, int32_t,
                                          std::conditional_t<sizeof(S) == 2, int16_t, int8_t>>>;

// Whether LaneBools<N> keeps its lanes as the bits of an AVX-512 mask register (bit i: lane i), for 16 and 8 lanes
// where AVX-512 (with VL, for 8) is there: a comparison of float lanes writes a mask register and a select blends by
// it. Kept as a vector of all-ones lanes instead, each select cost two more instructions on its chain (the mask moved
// into a vector by the comparison and tested back by the blend: GCC does not fold the round trip), a third of the
// fractal pyramid's time.
template <int N>
inline constexpr bool kMaskRegisterBools =
#if defined(__AVX512F__) && defined(__AVX512VL__)
    N == 16 || N == 8;
#else
    false;
#endif

// The storage of LaneBools<N>: a mask register's integer (kMaskRegisterBools), else a GCC vector of 32-bit lanes.
template <int N, bool kMaskRegister = kMaskRegisterBools<N>>
struct LaneBoolsStorage {
    using type = typename LaneStorage<uint32_t, N>::type;
};
#if defined(__AVX512F__) && defined(__AVX512VL__)
template <int N>
struct LaneBoolsStorage<N, true> {
    using type = std::conditional_t<N == 16, __mmask16, __mmask8>;
};
#endif

// m ? a : b over 32-bit lanes held in GCC vectors: for a mask register's m one blend by its bits; for a vector m, where
// each lane has all its bits set or clear, for 8 lanes one blend by m's sign bits (vblendvps), else a select on m != 0.
template <class Mask, class V>
[[gnu::always_inline]] inline V selectLanes(const Mask& m, const V& a, const V& b) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
    if constexpr (std::is_integral_v<Mask> && sizeof(V) == 64) {
        return V(_mm512_mask_blend_ps(m, __m512(b), __m512(a)));
    } else if constexpr (std::is_integral_v<Mask> && sizeof(V) == 32) {
        return V(_mm256_mask_blend_ps(m, __m256(b), __m256(a)));
    }
#endif
#if defined(__AVX__)
    if constexpr (!std::is_integral_v<Mask> && sizeof(V) == 32) {
        __m256 x, y, c;
        std::memcpy(&x, &a, sizeof(x));
        std::memcpy(&y, &b, sizeof(y));
        std::memcpy(&c, &m, sizeof(c));
        const __m256 r = _mm256_blendv_ps(y, x, c);
        V out;
        std::memcpy(&out, &r, sizeof(out));
        return out;
    }
#endif
    if constexpr (!std::is_integral_v<Mask>) return m != 0u ? a : b;
    else return a;  // unreachable: an integer mask exists only with AVX-512
}

// The comparison `a op b` of N 32-bit lanes of S (GCC vectors) into a mask register, with the predicate GCC gives the
// operator for floats (the same signalling of NaNs, so the same exception flags) and the signed or unsigned integer
// comparison for integers.
template <class S, int N, int kFloatPredicate, int kIntPredicate, class V>
[[gnu::always_inline]] inline auto compareToMask(const V& a, const V& b) {
#if defined(__AVX512F__) && defined(__AVX512VL__)
    static_assert(sizeof(S) == 4 && (N == 16 || N == 8));
    if constexpr (N == 16) {
        if constexpr (std::is_floating_point_v<S>) return _mm512_cmp_ps_mask(__m512(a), __m512(b), kFloatPredicate);
        else if constexpr (std::is_signed_v<S>) return _mm512_cmp_epi32_mask(__m512i(a), __m512i(b), kIntPredicate);
        else return _mm512_cmp_epu32_mask(__m512i(a), __m512i(b), kIntPredicate);
    } else {
        if constexpr (std::is_floating_point_v<S>) return _mm256_cmp_ps_mask(__m256(a), __m256(b), kFloatPredicate);
        else if constexpr (std::is_signed_v<S>) return _mm256_cmp_epi32_mask(__m256i(a), __m256i(b), kIntPredicate);
        else return _mm256_cmp_epu32_mask(__m256i(a), __m256i(b), kIntPredicate);
    }
#else
    static_assert(sizeof(V) == 0, "mask-register comparisons need AVX-512");
#endif
}

// Bit i set where lane i of the vector m (all bits set or clear per 32-bit lane) is: one instruction for 16 and 8
// lanes, a horizontal OR otherwise.
template <int N, class V>
[[gnu::always_inline]] inline uint32_t vectorLaneBits(const V& m) {
#if defined(__AVX512F__)
    if constexpr (N == 16) {
        __m512i x;
        std::memcpy(&x, &m, sizeof(x));
        return _mm512_test_epi32_mask(x, x);
    }
#endif
#if defined(__AVX2__)
    if constexpr (N == 8) {
        __m256i x;
        std::memcpy(&x, &m, sizeof(x));
        return uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(x)));
    }
#endif
    uint32_t bits = 0;
    for (int i = 0; i < N; ++i) bits |= (m[i] != 0u ? 1u : 0u) << i;
    return bits;
}
}  // namespace detail

template <int N>
struct LaneBools {
    // The lanes' bits in a mask register where AVX-512 has one for N float lanes (detail::kMaskRegisterBools), else
    // all 32 bits set or clear per lane, as wide as a float lane (what a vector comparison of float lanes gives): either
    // way a comparison is one instruction and a select on it one blend (selectLanes).
    static constexpr bool kMaskRegister = detail::kMaskRegisterBools<N>;
    using Storage = typename detail::LaneBoolsStorage<N>::type;
    Storage v;
    static constexpr uint32_t kSet = ~0u;  // a set lane of a vector Storage

    LaneBools() = default;
    constexpr explicit LaneBools(bool b) : v(filled(b)) {}
    constexpr bool operator[](int i) const {
        if constexpr (kMaskRegister) return (uint32_t(v) >> i & 1u) != 0;
        else return v[i] != 0;
    }
    // Lane i set to `value`.
    constexpr void set(int i, bool value) {
        if constexpr (kMaskRegister) v = Storage((uint32_t(v) & ~(1u << i)) | (uint32_t(value) << i));
        else v[i] = value ? kSet : 0u;
    }

    friend constexpr LaneBools operator&(LaneBools a, LaneBools b) {
        a.v &= b.v;
        return a;
    }
    friend constexpr LaneBools operator|(LaneBools a, LaneBools b) {
        a.v |= b.v;
        return a;
    }
    friend constexpr LaneBools operator!(LaneBools a) {
        a.v = Storage(~a.v);  // a mask register's integer is N bits wide: no bit above lane N - 1
        return a;
    }
    // && and || on masks are the lane-wise & and | (both sides are evaluated, as in a shader's SIMD code).
    friend constexpr LaneBools operator&&(LaneBools a, LaneBools b) { return a & b; }
    friend constexpr LaneBools operator||(LaneBools a, LaneBools b) { return a | b; }
    LaneBools& operator&=(LaneBools b) { return *this = *this & b; }
    LaneBools& operator|=(LaneBools b) { return *this = *this | b; }

private:
    static constexpr Storage filled(bool b) {
        if constexpr (kMaskRegister) return Storage(b ? kLaneBits<N> : 0u);
        else return Storage{} + (b ? kSet : 0u);
    }
};

// Bit i set where lane i of m is: one mask instruction for the vector widths (a horizontal OR of N lanes otherwise),
// which anyLane, allLanes and LiveLanes run at every step of a march.
template <int N>
[[gnu::always_inline]] inline uint32_t laneBits(const LaneBools<N>& m) {
    if constexpr (LaneBools<N>::kMaskRegister) return uint32_t(m.v);
    else return detail::vectorLaneBits<N>(m.v);
}

template <class S, int N = kMaxLanes>
struct Lanes {
    static_assert(std::is_trivially_default_constructible_v<S>, "GLM keeps components in unions");
    using Scalar = S;
    static constexpr int kCount = N;
    static constexpr bool kVector = detail::LaneStorage<S, N>::kIsVector;
    using Storage = typename detail::LaneStorage<S, N>::type;
    Storage v;

    Lanes() = default;
    // The same value in every lane: T(0.5f), T(ratio), and GLM's static_cast from float.
    template <class U>
        requires std::is_arithmetic_v<U> || std::is_same_v<U, S>
    constexpr Lanes(U x) {  // NOLINT: implicit, as a scalar literal promotes in HLSL
        const S s = S(x);
        if constexpr (kVector) {
            v = Storage{} + s;
        } else {
            for (int i = 0; i < N; ++i) v[i] = s;
        }
    }
    constexpr S operator[](int i) const { return v[i]; }

    template <class F>
    static Lanes generate(F f) {
        Lanes r;
        for (int i = 0; i < N; ++i) r.v[i] = f(i);
        return r;
    }

#define REFRAY_LANES_BINARY(op)                                                 \
    [[gnu::always_inline]] friend Lanes operator op(const Lanes& a, const Lanes& b) { \
        Lanes r;                                                                \
        if constexpr (kVector) {                                                \
            r.v = a.v op b.v;                                                   \
        } else {                                                                \
            r = a;                                                              \
            forLiveLanes([&](int i) { r.v[i] = a.v[i] op b.v[i]; });            \
        }                                                                       \
        return r;                                                               \
    }                                                                           \
    Lanes& operator op##=(const Lanes& b) { return *this = *this op b; }
    REFRAY_LANES_BINARY(+)
    REFRAY_LANES_BINARY(-)
    REFRAY_LANES_BINARY(*)
    REFRAY_LANES_BINARY(/)
#undef REFRAY_LANES_BINARY
    friend Lanes operator-(const Lanes& a) {
        Lanes r;
        if constexpr (kVector) {
            r.v = -a.v;
        } else {
            r = a;
            forLiveLanes([&](int i) { r.v[i] = -a.v[i]; });
        }
        return r;
    }
    // The live lanes of this width (tLiveLanes): a scalar type without SIMD instructions (PerturbedFloat) computes
    // these only; the others keep an operand, which no live lane reads.
    static uint32_t liveBits() { return tLiveLanes & kLaneBits<N>; }
    // f(i) for each live lane i, in lane order.
    template <class F>
    [[gnu::always_inline]] static void forLiveLanes(F f) {
        for (uint32_t l = liveBits(); l; l &= l - 1) f(std::countr_zero(l));
    }
    friend Lanes operator+(const Lanes& a) { return a; }

#define REFRAY_LANES_COMPARE(op, floatPredicate, intPredicate)                                      \
    [[gnu::always_inline]] friend LaneBools<N> operator op(const Lanes& a, const Lanes& b) {         \
        LaneBools<N> r;                                                                              \
        if constexpr (kVector && sizeof(S) == 4 && LaneBools<N>::kMaskRegister) {                    \
            r.v = detail::compareToMask<S, N, floatPredicate, intPredicate>(a.v, b.v);               \
        } else if constexpr (kVector && sizeof(S) == 4) {                                            \
            r.v = typename LaneBools<N>::Storage(a.v op b.v);                                        \
        } else {                                                                                     \
            r = LaneBools<N>(false);                                                                 \
            forLiveLanes([&](int i) { r.set(i, a.v[i] op b.v[i]); });                                \
        }                                                                                            \
        return r;                                                                                    \
    }
    // The predicates are _CMP_LT_OS, _CMP_LE_OS, _CMP_GT_OS, _CMP_GE_OS, _CMP_EQ_OQ, _CMP_NEQ_UQ (GCC's for the
    // operators) and _MM_CMPINT_LT, LE, NLE, NLT, EQ, NE, as numbers: their macros exist only with AVX.
    REFRAY_LANES_COMPARE(<, 0x01, 1)
    REFRAY_LANES_COMPARE(<=, 0x02, 2)
    REFRAY_LANES_COMPARE(>, 0x0E, 6)
    REFRAY_LANES_COMPARE(>=, 0x0D, 5)
    REFRAY_LANES_COMPARE(==, 0x00, 0)
    REFRAY_LANES_COMPARE(!=, 0x04, 4)
#undef REFRAY_LANES_COMPARE
};

template <class T>
struct IsLanes : std::false_type {};
template <class S, int N>
struct IsLanes<Lanes<S, N>> : std::true_type {};
template <class T>
inline constexpr bool kIsLanes = IsLanes<T>::value;
// How many rays a value of T holds: N for Lanes<S, N>, 1 for a scalar.
template <class T>
inline constexpr int kLaneCount = 1;
template <class S, int N>
inline constexpr int kLaneCount<Lanes<S, N>> = N;

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
[[gnu::always_inline]] inline bool anyLane(const LaneBools<N>& m) {
    return laneBits(m) != 0;
}
constexpr bool allLanes(bool m) { return m; }
template <int N>
[[gnu::always_inline]] inline bool allLanes(const LaneBools<N>& m) {
    return laneBits(m) == kLaneBits<N>;
}

// m ? a : b, lane by lane; for a scalar mask, the plain conditional.
template <class T>
    requires(!kIsLanes<T>)
T select(bool m, const T& a, const T& b) {
    return m ? a : b;
}
// (Always inlined, as the lanes' operators are: a march's selects are its inner loop, and a call per select spills
// every register of it.)
template <class S, int N>
[[gnu::always_inline]] inline Lanes<S, N> select(const LaneBools<N>& m, const Lanes<S, N>& a, const Lanes<S, N>& b) {
    Lanes<S, N> r;
    if constexpr (Lanes<S, N>::kVector && sizeof(S) == 4) {
        r.v = detail::selectLanes(m.v, a.v, b.v);
    } else {
        for (int i = 0; i < N; ++i) r.v[i] = m[i] ? a.v[i] : b.v[i];
    }
    return r;
}
template <int N>
[[gnu::always_inline]] inline LaneBools<N> select(const LaneBools<N>& m, const LaneBools<N>& a,  // NOLINT
                                                  const LaneBools<N>& b) {
    return (m & a) | (!m & b);
}
// b < a ? b : a, lane by lane: the lesser of the two, and a where they are equal or either is NaN. For float lanes
// it is one minimum instruction (x86's minps computes exactly this), where select(b < a, b, a) is a compare and a
// blend that depends on it.
template <class S, int N>
[[gnu::always_inline]] inline Lanes<S, N> lesserOf(const Lanes<S, N>& a, const Lanes<S, N>& b) {
    Lanes<S, N> r;
    if constexpr (Lanes<S, N>::kVector) {
        r.v = b.v < a.v ? b.v : a.v;
    } else {
        for (int i = 0; i < N; ++i) r.v[i] = b.v[i] < a.v[i] ? b.v[i] : a.v[i];
    }
    return r;
}
// Vectors of lanes (GLM's vec<K, Lanes>), component by component.
template <glm::length_t K, class S, int N, glm::qualifier Q>
[[gnu::always_inline]] inline glm::vec<K, Lanes<S, N>, Q> select(const LaneBools<N>& m,
                                                                 const glm::vec<K, Lanes<S, N>, Q>& a,
                                                                 const glm::vec<K, Lanes<S, N>, Q>& b) {
    glm::vec<K, Lanes<S, N>, Q> r;
    for (glm::length_t k = 0; k < K; ++k) r[k] = select(m, a[k], b[k]);
    return r;
}

// The lanes whose results still count, while a march runs (its `running` mask within the shader's active lanes):
// the instructions a compiler cannot vectorise (libm's transcendentals, called lane by lane) are computed for these
// lanes only, and the others keep their operand. Sound because a march keeps each new value only in its running
// lanes (select), so what a stopped lane computes is never read. A scope narrows the enclosing one for its
// lifetime; for a scalar mask it does nothing. Per thread: a wave's shader runs on its worker without switching.
class LiveLanes {
public:
    explicit LiveLanes(bool) {}
    template <int N>
    explicit LiveLanes(const LaneBools<N>& m) : saved_(tLiveLanes), restore_(true) {
        tLiveLanes = saved_ & laneBits(m);
    }
    // A wave shader's active lanes (bit i: lane i), for the whole shader.
    LiveLanes(uint32_t bits, int) : saved_(tLiveLanes), restore_(true) { tLiveLanes = bits; }
    ~LiveLanes() {
        if (restore_) tLiveLanes = saved_;
    }
    LiveLanes(const LiveLanes&) = delete;
    LiveLanes& operator=(const LiveLanes&) = delete;

private:
    uint32_t saved_ = 0;
    bool restore_ = false;
};

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
    return m[i];
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
template <int N>
void setLane(LaneBools<N>& m, int i, bool value) {
    m.set(i, value);
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
    // map for the live lanes only (math::LiveLanes); the others keep their operand. Where every live lane holds the
    // same bits in every operand (a constant such as pow(2, -n)'s base and exponent), f runs once and its result
    // goes to all of them: the same bits each lane's own call gives.
    template <class F, class... More>
    static L mapLive(const L& a, F f, const More&... more) {
        L r;
        if (!once(r, f, a, more...)) {
            r = a;
            L::forLiveLanes([&](int i) { r.v[i] = f(a.v[i], more.v[i]...); });
        }
        return r;
    }
    // Where there are live lanes and each holds the same bits in every operand: f once, r = a with that one result
    // in its live lanes, and true. False, with r untouched, otherwise.
    template <class F, class... More>
    static bool once(L& r, F f, const L& a, const More&... more) {
        const uint32_t live = L::liveBits();
        if (!live) return false;
        const int first = std::countr_zero(live);
        if (!(uniformBits(live, first, a) && (uniformBits(live, first, more) && ...))) return false;
        r = liveOnly(live, L(f(a.v[first], more.v[first]...)), a);
        return true;
    }
    // `result` in the lanes of `live`, `keep` in the others: one blend for float lanes.
    static L liveOnly(uint32_t live, const L& result, const L& keep) {
        if (live == math::kLaneBits<N>) return result;
        L r = keep;
        if constexpr (std::is_same_v<S, float>) {
            typename math::detail::LaneStorage<uint32_t, N>::type laneBit;
            for (int i = 0; i < N; ++i) laneBit[i] = 1u << i;
            r.v = (laneBit & live) != 0u ? result.v : keep.v;
        } else {
            for (uint32_t l = live; l; l &= l - 1) r.v[std::countr_zero(l)] = result.v[std::countr_zero(l)];
        }
        return r;
    }
    // pow where every live lane holds one base and one exponent (the fractal pyramid's pow(2, -n)): once, the bits
    // of each lane's exp2(y * log2(x)); the lanes that are not live keep x, as mapLive leaves them.
    static bool powOnce(const L& x, const L& y, L& r) {
        return once(r, [](S a, S b) { return lastPow(a, b); }, x, y);
    }
    // pow(a, b) in S; for float the last base, exponent, result and floating-point mode (MXCSR: the denormal
    // flushing PrecisionScope sets) are kept per thread, as the fractal pyramid's march asks for pow(2, -4) at
    // every step: a kept result is the bits the call gives.
    static S lastPow(S a, S b) {
#if REFRAY_HAS_MXCSR
        if constexpr (std::is_same_v<S, float>) {
            struct Last {
                uint32_t a = 0, b = 0, mode = 0;
                float result = 0.0f;
                bool valid = false;
            };
            static thread_local Last last;
            const uint32_t abits = std::bit_cast<uint32_t>(a), bbits = std::bit_cast<uint32_t>(b);
            const uint32_t mode = _mm_getcsr() & ~0x3Fu;  // the control bits, not the sticky exception flags
            if (!(last.valid && last.a == abits && last.b == bbits && last.mode == mode))
                last = {abits, bbits, mode, hlsl::pow(a, b), true};
            return last.result;
        }
#endif
        return hlsl::pow(a, b);
    }
    // Whether every lane of `live` holds lane `first`'s bits (SIMD types only: a comparison and a mask test).
    static bool uniformBits(uint32_t live, int first, const L& x) {
        if constexpr (math::detail::LaneStorage<S, N>::kIsVector) {
            using Int = math::detail::LaneCompareInt<S>;
            using Ints = typename math::detail::LaneStorage<Int, N>::type;
            const Ints bits = Ints(x.v);
            const Ints equal = bits == bits[first];
            uint32_t same = 0;
            if constexpr (sizeof(S) == 4) {
                same = math::detail::vectorLaneBits<N>(equal);
            } else {
                for (int i = 0; i < N; ++i) same |= equal[i] ? (1u << i) : 0u;
            }
            return (same & live) == live;
        } else {
            (void)live, (void)first, (void)x;
            return false;
        }
    }
    static constexpr bool kFloat = std::is_same_v<S, float>;
    // float lanes: the instructions a compiler can vectorise, each bit for bit libm's (glibc's fabsf, floorf, sqrtf,
    // fminf and fmaxf; the lanes test checks them on special values), so that the wave math runs in SIMD registers.
    using Bits = typename math::detail::LaneStorage<uint32_t, N>::type;
    static L abs(const L& x) {
        if constexpr (kFloat) {
            L r;
            r.v = typename L::Storage(Bits(x.v) & 0x7fffffffu);
            return r;
        } else {
            return mapLive(x, [](S a) { return ScalarOps<S>::abs(a); });
        }
    }
    static L floor(const L& x) {
        if constexpr (kFloat) {
            // Below 2^23 in magnitude: truncate, step down where that rounded up, keep the sign (floor(-0) = -0);
            // from 2^23 on (and NaN, infinity) every float is its own floor.
            using F = typename L::Storage;
            using I = typename math::detail::LaneStorage<int32_t, N>::type;
            const F a = x.v;
            const F magnitude = F(Bits(a) & 0x7fffffffu);
            const auto small = magnitude < 0x1p23f;
            F t = __builtin_convertvector(__builtin_convertvector(small ? a : F{}, I), F);
            t = t > a ? t - 1.0f : t;
            t = F((Bits(t) & 0x7fffffffu) | (Bits(a) & 0x80000000u));
            L r;
            r.v = small ? t : a;
            return r;
        } else {
            return mapLive(x, [](S a) { return ScalarOps<S>::floor(a); });
        }
    }
    // op over x in chunks of W floats held in a V register.
    template <int W, class V, class Op>
    static L floatChunks(const L& x, Op op) {
        L r;
        for (int i = 0; i < N; i += W) {
            V p;
            std::memcpy(&p, reinterpret_cast<const char*>(&x.v) + i * 4, sizeof(V));
            p = op(p);
            std::memcpy(reinterpret_cast<char*>(&r.v) + i * 4, &p, sizeof(V));
        }
        return r;
    }
    static L sqrt(const L& x) {
        if constexpr (kFloat && N % 4 == 0) {
            // sqrtps: correctly rounded, as sqrtf; the widest the target has.
#if defined(__AVX512F__)
            // (the unmasked form trips -Wmaybe-uninitialized in GCC 12)
            if constexpr (N % 16 == 0)
                return floatChunks<16, __m512>(x, [](__m512 p) { return _mm512_maskz_sqrt_ps(__mmask16(0xFFFF), p); });
#endif
#if defined(__AVX__)
            if constexpr (N % 8 == 0) return floatChunks<8, __m256>(x, [](__m256 p) { return _mm256_sqrt_ps(p); });
#endif
#if REFRAY_HAS_MXCSR
            return floatChunks<4, __m128>(x, [](__m128 p) { return _mm_sqrt_ps(p); });
#endif
        }
        return mapLive(x, [](S a) { return ScalarOps<S>::sqrt(a); });
    }
    static L rsqrt(const L& x) {
        if constexpr (kFloat) return L(1.0f) / sqrt(x);
        else return mapLive(x, [](S a) { return ScalarOps<S>::rsqrt(a); });
    }
    static L sin(const L& x) { return transcendental<math::Transcendental::Sin>(x, [](S a) { return ScalarOps<S>::sin(a); }); }
    static L cos(const L& x) { return transcendental<math::Transcendental::Cos>(x, [](S a) { return ScalarOps<S>::cos(a); }); }
    static L acos(const L& x) { return transcendental<math::Transcendental::Acos>(x, [](S a) { return ScalarOps<S>::acos(a); }); }
    static L atan(const L& x) { return transcendental<math::Transcendental::Atan>(x, [](S a) { return ScalarOps<S>::atan(a); }); }
    static L exp2(const L& x) { return transcendental<math::Transcendental::Exp2>(x, [](S a) { return ScalarOps<S>::exp2(a); }); }
    static L log2(const L& x) { return transcendental<math::Transcendental::Log2>(x, [](S a) { return ScalarOps<S>::log2(a); }); }
    // float lanes: eight at a time through SLEEF (procedural/math/transcendentals.h), bit for bit the scalar float's
    // function; the lanes that are not live keep their operand, as mapLive leaves them. Eight lanes in one AVX2 call
    // cost what one float does, so they go straight to it; wider lanes, and a target without AVX2, compute live
    // lanes that hold one value once (mapLive). Other lane types: mapLive.
    template <math::Transcendental F, class Scalar>
    static L transcendental(const L& x, Scalar scalar) {
        if constexpr (kFloat && N % 8 == 0) {
            const uint32_t live = L::liveBits();
            if (!live) return x;
            L r;
#if REFRAY_TRANSCENDENTALS_AVX2
            if constexpr (N == 8) {
                r.v = std::bit_cast<typename L::Storage>(
                    math::detail::sleefAvx2(F, std::bit_cast<__m256>(x.v), live));
            } else
#endif
            {
                if (uniformBits(live, std::countr_zero(live), x)) return mapLive(x, scalar);
                alignas(32) float in[N], out[N];
                std::memcpy(in, &x.v, sizeof(in));
                for (int i = 0; i < N; i += 8)
                    if ((live >> i) & 0xFFu) math::transcendental8(F, in + i, out + i, live >> i);
                std::memcpy(&r.v, out, sizeof(out));
            }
            return liveOnly(live, r, x);
        } else {
            return mapLive(x, scalar);
        }
    }
    // glibc's fminf/fmaxf: the first operand when the two compare equal (so min(+0, -0) = +0), the other operand
    // when one is a quiet NaN, the second when both are. (Signalling NaNs, which no arithmetic makes, are not
    // quietened as libm does.)
    static L min(const L& a, const L& b) {
        if constexpr (kFloat) {
            L r;
            r.v = ((a.v <= b.v) | ((b.v != b.v) & (a.v == a.v))) ? a.v : b.v;
            return r;
        } else {
            return mapLive(a, [](S x, S y) { return ScalarOps<S>::min(x, y); }, b);
        }
    }
    static L max(const L& a, const L& b) {
        if constexpr (kFloat) {
            L r;
            r.v = ((a.v >= b.v) | ((b.v != b.v) & (a.v == a.v))) ? a.v : b.v;
            return r;
        } else {
            return mapLive(a, [](S x, S y) { return ScalarOps<S>::max(x, y); }, b);
        }
    }
    static L frem(const L& a, const L& b) { return mapLive(a, [](S x, S y) { return ScalarOps<S>::frem(x, y); }, b); }
    // The scalar type's dot, lane by lane (its order of terms and its rounding): for float and double the plain sum
    // of products in component order, over all lanes at once.
    template <glm::length_t K, glm::qualifier Q>
    static L dot(const glm::vec<K, L, Q>& a, const glm::vec<K, L, Q>& b) {
        if constexpr (std::is_floating_point_v<S>) {
            L s = a[0] * b[0];
            for (glm::length_t k = 1; k < K; ++k) s = s + a[k] * b[k];
            return s;
        }
        L r = a[0];
        L::forLiveLanes([&](int i) {
            glm::vec<K, S, Q> x, y;
            for (glm::length_t k = 0; k < K; ++k) {
                x[k] = a[k].v[i];
                y[k] = b[k].v[i];
            }
            r.v[i] = ScalarOps<S>::dot(x, y);
        });
        return r;
    }
};

// The intrinsics whose HLSL lowering branches on a value: the scalar form lane by lane. More specialised than the
// scalar templates, so overload resolution picks these for lanes.
template <class S, int N>
math::Lanes<S, N> step(math::Lanes<S, N> a, math::Lanes<S, N> x) {
    return math::select(x >= a, math::Lanes<S, N>(S(1)), math::Lanes<S, N>(S(0)));
}
template <class S, int N>
math::Lanes<S, N> atan2(math::Lanes<S, N> y, math::Lanes<S, N> x) {
    using L = math::Lanes<S, N>;
    L r = ScalarOps<L>::atan(y / x);
    const L pi(kPi<S>);
    const auto xLt0 = x < L(S(0));
    const auto xEq0 = x == L(S(0));
    const auto yGe0 = y >= L(S(0));
    const auto yLt0 = y < L(S(0));
    r = math::select(xLt0 && yGe0, r + pi, r);
    r = math::select(xLt0 && yLt0, r - pi, r);
    r = math::select(xEq0 && yLt0, -pi / L(S(2)), r);
    r = math::select(xEq0 && yGe0, pi / L(S(2)), r);
    return r;
}
template <class S, int N>
math::Lanes<S, N> fmod(math::Lanes<S, N> x, math::Lanes<S, N> y) {
    const math::Lanes<S, N> q = x / y;
    const math::Lanes<S, N> f = frac(hlsl::abs(q));
    return math::select(q >= -q, f, -f) * y;
}

}  // namespace refray::procedural::hlsl

namespace refray::procedural::math {
// hlsl.h's vector forms call these unqualified (for lanes, argument-dependent lookup searches this namespace).
using hlsl::atan2;
using hlsl::fmod;
using hlsl::step;
}  // namespace refray::procedural::math
