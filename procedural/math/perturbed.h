// PerturbedFloat: float32 shader arithmetic as one GPU of the variation model computes it (issue 17; the model and
// its sources are in docs/numerical-variation.md). Every instruction D3D11.3 lets a GPU compute inexactly (divide,
// sqrt, rsqrt, exp2, log2, sin, cos, and the acos/atan the D3D spec leaves unbounded) returns a float within the
// model's bound of the exact result; add, subtract and multiply stay correctly rounded, as D3D requires, but a
// multiply followed by an add may be fused, and a dot product may sum its terms in any order. The shader ports run in
// it unchanged: they are templates on the scalar type, and hlsl::ScalarOps<PerturbedFloat> supplies the instructions.
//
// Determinism: an operation's error is a hash of (seed, operation, the bits of its operands), so for one seed each
// instruction is a fixed function, as on a GPU: the same operands give the same result wherever and whenever they
// are computed. A render therefore depends on no thread count, schedule, traversal order or per-ray counter. The
// seed and options reach the operators through a thread-local pointer that perturbed::Scope installs for one shader
// call and puts back when it returns, as PrecisionScope does with MXCSR; nothing of it outlives the call. Without a
// Scope the type computes exactly what float does.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <compare>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <type_traits>
#include <utility>

#include "core/error.h"
#include "core/fiber_local.h"
#include "procedural/math/hlsl.h"
#include "procedural/perturbation.h"
#include "procedural/precision.h"

namespace refray::procedural {

// ---- The bounds of variation model v1 (docs/numerical-variation.md gives the source of each) --------------------
namespace variation {
inline constexpr double kDivisionUlps = 2.5;              // x / y, for 2^-126 <= |y| <= 2^126
inline constexpr double kDivisionMinDivisor = 0x1p-126;
inline constexpr double kDivisionMaxDivisor = 0x1p126;
inline constexpr double kSqrtUlps = 1.0;
inline constexpr double kRsqrtRelative = 0x1p-21;
inline constexpr double kExp2Relative = 0x1p-21;
inline constexpr double kLog2Absolute = 0x1p-21;          // log2(x) for x in [0.5, 2]
inline constexpr double kLog2Relative = 0x1p-21;          // log2(x) elsewhere
inline constexpr double kSinCosAbsolute = 0.0008;
inline constexpr double kAtanUlps = 4096.0;
inline constexpr double kAcosUlps = 4096.0;
}  // namespace variation

namespace perturbed {

// The perturbed instructions, and the two choices the model makes per operation (fuse an add with a product; the
// order of a dot product's terms). Each has its own salt, so their errors are independent.
enum class Op : uint8_t { Division, Sqrt, Rsqrt, Exp2, Log2, Sin, Cos, Acos, Atan, Contraction, DotOrder, Count };

// splitmix64's finaliser: a bijection on 64-bit words in which every output bit depends on every input bit.
constexpr uint64_t mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// One perturbed library's options, with a salt per operation derived from the seed.
class Context {
public:
    explicit Context(const Perturbation& options) : options_(options) {
        for (size_t op = 0; op < salts_.size(); ++op)
            salts_[op] = mix(mix(options.seed) + (op + 1) * 0x9E3779B97F4A7C15ull);
    }
    const Perturbation& options() const { return options_; }
    // Whether an add may fuse with a product at all.
    bool contracts() const { return options_.contraction != Contraction::Split; }
    // The hash of (seed, op, operand bits) that decides one operation's error.
    uint64_t hash(Op op, uint64_t operandBits) const { return mix(salts_[size_t(op)] ^ operandBits); }
    // A cheaper hash for the one-bit choices made at every add (contraction): a multiply by an odd constant, whose
    // top bits depend on every operand bit.
    uint64_t quickHash(Op op, uint64_t operandBits) const {
        return (salts_[size_t(op)] ^ operandBits) * 0x9E3779B97F4A7C15ull;
    }

private:
    Perturbation options_;
    std::array<uint64_t, size_t(Op::Count)> salts_{};
};

// The context of the perturbed shader call running on this thread (perturbed::Scope); null outside one.
inline constinit thread_local const Context* tCurrentContext = nullptr;
inline const Context* current() { return tCurrentContext; }
// The context belongs to the shader call that installed it, so it follows that call's fiber when the wave executor
// switches lanes on a thread (core/fiber_local.h).
inline const bool kContextFollowsFibers = registerFiberLocal(
    {[]() -> void* { return const_cast<Context*>(tCurrentContext); },
     [](void* context) { tCurrentContext = static_cast<const Context*>(context); }});

inline uint64_t bits(float x) { return std::bit_cast<uint32_t>(x); }
inline uint64_t bits(float a, float b) { return bits(a) | bits(b) << 32; }

// A number in [-1, 1) from the high 53 bits of a hash.
inline double symmetricUnit(uint64_t h) { return double(h >> 11) * 0x1p-52 - 1.0; }

// ulp(x) of float32 at a real x as the Vulkan spec defines it ("ULP" in spirvenv): the gap between the two floats
// around x, the smaller of the two gaps when x is a power of two; 2^-149 below the normal range.
inline double floatUlp(double x) {
    const uint64_t b = std::bit_cast<uint64_t>(std::fabs(x));
    const int e = int(b >> 52) - 1023;  // |x| in [2^e, 2^(e+1))
    if (e < -126) return 0x1p-149;
    const bool powerOfTwo = (b & ((uint64_t(1) << 52) - 1)) == 0;
    return std::ldexp(1.0, std::min(e, 127) - 23 - (powerOfTwo && e > -126 ? 1 : 0));
}

// r moved towards the float nearest `exact` until it lies within `bound` of it: rounding a perturbed value to float
// can overshoot the bound by the last step (where r crosses into a binade with wider gaps).
inline float withinBound(float r, double exact, double bound) {
    const float nearest = float(exact);
    while (r != nearest && std::fabs(double(r) - exact) > bound) r = std::nextafter(r, nearest);
    return r;
}

// Whether a result is left exact: 0, not finite, below the normal range (flushed or not) or beyond float's range.
inline bool keptExact(double exact) {
    const double a = std::fabs(exact);
    return !(a >= 0x1p-126 && a <= double(std::numeric_limits<float>::max()));
}

// A float within maxUlps ulp (>= 0.5) of `exact`, drawn by the hash.
inline float withinUlps(double exact, double maxUlps, uint64_t h) {
    if (keptExact(exact)) return float(exact);
    const double ulp = floatUlp(exact);
    return withinBound(float(exact + (maxUlps - 0.5) * ulp * symmetricUnit(h)), exact, maxUlps * ulp);
}

// A float within relative error `relative` (>= 2^-24) of `exact`, drawn by the hash.
inline float withinRelative(double exact, double relative, uint64_t h) {
    if (keptExact(exact)) return float(exact);
    return withinBound(float(exact * (1.0 + (relative - 0x1p-24) * symmetricUnit(h))), exact,
                       relative * std::fabs(exact));
}

// A float within absolute error `absolute` of `exact`, drawn by the hash.
inline float withinAbsolute(double exact, double absolute, uint64_t h) {
    if (!std::isfinite(exact)) return float(exact);
    return withinBound(float(exact + (absolute - 0.5 * floatUlp(exact)) * symmetricUnit(h)), exact, absolute);
}

// ---- The perturbed instructions on float values (float's own results without a context) --------------------------
// float's own: hlsl::ScalarOps<float>, so SLEEF's transcendentals (procedural/math/transcendentals.h); the exact
// value a perturbation starts from is libm's in double.
// x / y: 2.5 ulp for 2^-126 <= |y| <= 2^126, x / 1 = x; correctly rounded outside that range (not modelled in v1).
inline float divide(float x, float y) {
    const Context* c = current();
    const double ay = std::fabs(double(y));
    if (!c || y == 1.0f || !(ay >= variation::kDivisionMinDivisor && ay <= variation::kDivisionMaxDivisor))
        return x / y;
    return withinUlps(double(x) / double(y), variation::kDivisionUlps, c->hash(Op::Division, bits(x, y)));
}

// An instruction with an ulp bound: `fn` (callable on float and on double) in double, perturbed; in float without a
// context.
template <class Fn>
float withinUlpsOf(Op op, double maxUlps, float x, Fn fn) {
    const Context* c = current();
    if (!c) return fn(x);
    return withinUlps(fn(double(x)), maxUlps, c->hash(op, bits(x)));
}

inline float sqrt(float x) {
    return withinUlpsOf(Op::Sqrt, variation::kSqrtUlps, x, [](auto v) { return std::sqrt(v); });
}

inline float rsqrt(float x) {
    const Context* c = current();
    if (!c) return 1.0f / std::sqrt(x);
    return withinRelative(1.0 / std::sqrt(double(x)), variation::kRsqrtRelative, c->hash(Op::Rsqrt, bits(x)));
}

// exp2(+-0) = 1 exactly (the exp table of D3D11.3 §22.10.6).
inline float exp2(float x) {
    const Context* c = current();
    if (!c || x == 0.0f) return hlsl::ScalarOps<float>::exp2(x);
    return withinRelative(std::exp2(double(x)), variation::kExp2Relative, c->hash(Op::Exp2, bits(x)));
}

inline float log2(float x) {
    const Context* c = current();
    const double exact = std::log2(double(x));
    if (!c || !std::isfinite(exact)) return hlsl::ScalarOps<float>::log2(x);
    const uint64_t h = c->hash(Op::Log2, bits(x));
    if (x >= 0.5f && x <= 2.0f) return withinAbsolute(exact, variation::kLog2Absolute, h);
    return withinRelative(exact, variation::kLog2Relative, h);
}

// sin or cos (`fn`, callable on float and on double): sin(+-0) = +-0 and cos(+-0) = 1 exactly (the sincos table of
// D3D11.3 §22.10.20), and results stay in [-1, 1].
template <class Fn>
float sinusoid(Op op, float x, Fn fn) {
    const Context* c = current();
    if (!c || x == 0.0f || !std::isfinite(x)) return fn(x);
    const float r = withinAbsolute(fn(double(x)), variation::kSinCosAbsolute, c->hash(op, bits(x)));
    return std::fmin(std::fmax(r, -1.0f), 1.0f);
}

inline float sin(float x) { return sinusoid(Op::Sin, x, [](auto v) { return hlsl::ScalarOps<decltype(v)>::sin(v); }); }
inline float cos(float x) { return sinusoid(Op::Cos, x, [](auto v) { return hlsl::ScalarOps<decltype(v)>::cos(v); }); }

inline float acos(float x) {
    return withinUlpsOf(Op::Acos, variation::kAcosUlps, x, [](auto v) { return hlsl::ScalarOps<decltype(v)>::acos(v); });
}

inline float atan(float x) {
    return withinUlpsOf(Op::Atan, variation::kAtanUlps, x, [](auto v) { return hlsl::ScalarOps<decltype(v)>::atan(v); });
}

// `condition ? x : y` without a branch: the perturbation's coin flips are unpredictable by design.
inline float select(bool condition, float x, float y) {
    const uint32_t mask = 0u - uint32_t(condition);
    return std::bit_cast<float>((std::bit_cast<uint32_t>(x) & mask) | (std::bit_cast<uint32_t>(y) & ~mask));
}

// Whether an add a + b, one or both of whose operands a multiply rounded, is computed fused with one of those products
// (D3D11.3 §3.1.3.2: a fused result is at least as accurate as the unfused one), and with which: a's unless only b
// is a product or the hash picks b.
struct Fusion {
    bool fuse;
    bool withA;
};
inline Fusion fusion(const Context& c, float a, bool aIsProduct, float b, bool bIsProduct) {
    if (c.options().contraction != Contraction::Mixed) return {c.contracts(), aIsProduct};
    const uint64_t h = c.quickHash(Op::Contraction, bits(a, b));
    return {(h >> 63) != 0, aIsProduct && (!bIsProduct || ((h >> 62) & 1) != 0)};
}

}  // namespace perturbed

// ---- The scalar type --------------------------------------------------------------------------------------------
class PerturbedFloat {
public:
    // Trivial, as float's: GLM's vectors keep their components in unions.
    PerturbedFloat() = default;
    template <class U>
        requires std::is_arithmetic_v<U>
    constexpr explicit PerturbedFloat(U x) : v_(static_cast<float>(x)), lo_(0.0f) {}
    template <class U>
        requires std::is_arithmetic_v<U>
    constexpr explicit operator U() const { return static_cast<U>(v_); }

    constexpr float value() const { return v_; }
    // For a value that a multiply rounded: the exact product minus value() (exact in float, 0 when the product was
    // representable); 0 for any other value. An add may fuse with it.
    constexpr float productError() const { return lo_; }

    friend constexpr PerturbedFloat operator+(PerturbedFloat a) { return a; }
    friend constexpr PerturbedFloat operator-(PerturbedFloat a) { return PerturbedFloat(-a.v_, -a.lo_); }

    // Add and multiply are forced inline: the marches are mostly these two, and a call costs more than either.
    [[gnu::always_inline]] friend PerturbedFloat operator+(PerturbedFloat a, PerturbedFloat b) {
        const float sum = a.v_ + b.v_;
        if (a.lo_ != 0.0f || b.lo_ != 0.0f)
            if (const perturbed::Context* c = perturbed::current(); c && c->contracts()) {
                // A fused p*q + r: the rounded product plus r plus the product's rounding error, summed in double
                // and rounded to float. Both results are computed and one selected, sparing a branch on a coin flip.
                const perturbed::Fusion f = perturbed::fusion(*c, a.v_, a.lo_ != 0.0f, b.v_, b.lo_ != 0.0f);
                const float lo = perturbed::select(f.withA, a.lo_, b.lo_);
                const float fused = float((double(a.v_) + double(b.v_)) + double(lo));
                return PerturbedFloat(perturbed::select(f.fuse, fused, sum));
            }
        return PerturbedFloat(sum);
    }
    friend PerturbedFloat operator-(PerturbedFloat a, PerturbedFloat b) { return a + -b; }
    [[gnu::always_inline]] friend PerturbedFloat operator*(PerturbedFloat a, PerturbedFloat b) {
        PerturbedFloat r(a.v_ * b.v_);
        if (std::isfinite(r.v_)) r.lo_ = float(double(a.v_) * double(b.v_) - double(r.v_));
        return r;
    }
    friend PerturbedFloat operator/(PerturbedFloat a, PerturbedFloat b) {
        return PerturbedFloat(perturbed::divide(a.v_, b.v_));
    }
    PerturbedFloat& operator+=(PerturbedFloat b) { return *this = *this + b; }
    PerturbedFloat& operator-=(PerturbedFloat b) { return *this = *this - b; }
    PerturbedFloat& operator*=(PerturbedFloat b) { return *this = *this * b; }
    PerturbedFloat& operator/=(PerturbedFloat b) { return *this = *this / b; }

    // IEEE comparisons of the values (a NaN compares unordered).
    friend constexpr bool operator==(PerturbedFloat a, PerturbedFloat b) { return a.v_ == b.v_; }
    friend constexpr std::partial_ordering operator<=>(PerturbedFloat a, PerturbedFloat b) { return a.v_ <=> b.v_; }

private:
    constexpr PerturbedFloat(float v, float lo) : v_(v), lo_(lo) {}
    float v_;
    float lo_;
};

// ---- Installing a perturbation ----------------------------------------------------------------------------------
namespace perturbed {

// Installs `context` on the calling thread for one shader call, with MXCSR's denormal bits as its options say, and
// puts both back when it ends (nested calls, e.g. an intersection shader run by a closest-hit shader's TraceRay,
// install their own and restore this one).
class Scope {
public:
    explicit Scope(const Context& context)
        : previous_(tCurrentContext), denormals_(context.options().denormals == Denormals::Flush) {
        tCurrentContext = &context;
    }
    ~Scope() { tCurrentContext = previous_; }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

private:
    const Context* previous_;
    hlsl::ScopedFlushDenormals denormals_;
};

}  // namespace perturbed

// A shader export's callable as a library with scalar type T registers it: for PerturbedFloat inside a Scope of the
// library's perturbation, for float and double unchanged.
template <typename T, class Entry>
auto withArithmetic(const std::optional<Perturbation>& perturbation, Entry entry) {
    if constexpr (std::is_same_v<T, PerturbedFloat>) {
        REFRAY_ASSERT(perturbation, "a PerturbedFloat library needs its perturbation");
        return [context = perturbed::Context(*perturbation), entry](auto&... args) {
            const perturbed::Scope scope(context);
            entry(args...);
        };
    } else {
        return entry;
    }
}

// Calls add.template operator()<T>() with the scalar type a library's math runs in: PerturbedFloat when it is
// perturbed (float only; refray::Error with double), otherwise double or float.
template <class Add>
void forScalarType(Precision precision, const std::optional<Perturbation>& perturbation, Add&& add) {
    if (perturbation) {
        REFRAY_CHECK(precision == Precision::Float,
                     "a perturbed render perturbs the GPU's float arithmetic; --perturb cannot be combined with "
                     "--precision double");
        add.template operator()<PerturbedFloat>();
    } else if (precision == Precision::Double) {
        add.template operator()<double>();
    } else {
        add.template operator()<float>();
    }
}

}  // namespace refray::procedural

// ---- The instructions of PerturbedFloat for the ports (procedural/math/hlsl.h) ----------------------------------
template <>
struct refray::procedural::hlsl::ScalarOps<refray::procedural::PerturbedFloat> {
    using T = PerturbedFloat;
    using Storage = float;
    // Exact on a GPU too: abs, floor (round_ni), min, max and the remainder the ports take of the frame time.
    static T abs(T x) { return T(std::fabs(x.value())); }
    static T floor(T x) { return T(std::floor(x.value())); }
    static T min(T a, T b) { return T(std::fmin(a.value(), b.value())); }
    static T max(T a, T b) { return T(std::fmax(a.value(), b.value())); }
    static T frem(T x, T y) { return T(std::fmod(x.value(), y.value())); }
    static T sqrt(T x) { return T(perturbed::sqrt(x.value())); }
    static T rsqrt(T x) { return T(perturbed::rsqrt(x.value())); }
    static T sin(T x) { return T(perturbed::sin(x.value())); }
    static T cos(T x) { return T(perturbed::cos(x.value())); }
    static T acos(T x) { return T(perturbed::acos(x.value())); }
    static T atan(T x) { return T(perturbed::atan(x.value())); }
    static T exp2(T x) { return T(perturbed::exp2(x.value())); }
    static T log2(T x) { return T(perturbed::log2(x.value())); }
    // DXIL's Dot2/3/4 is a fused operation (D3D11.3 §3.1.3.2): at least as accurate as the worst order of its unfused
    // multiplies and adds. The hash of all operands picks the order of the terms; each add may fuse as usual.
    template <glm::length_t N, glm::qualifier Q>
    static T dot(const glm::vec<N, T, Q>& a, const glm::vec<N, T, Q>& b) {
        std::array<glm::length_t, size_t(N)> order;
        std::iota(order.begin(), order.end(), glm::length_t(0));
        if (const perturbed::Context* c = perturbed::current()) {
            uint64_t words = 0;
            for (glm::length_t i = 0; i < N; ++i)
                words = std::rotl((words ^ perturbed::bits(a[i].value(), b[i].value())) * 0x9E3779B97F4A7C15ull, 29);
            uint64_t h = c->hash(perturbed::Op::DotOrder, words);
            // Fisher-Yates, a 16-bit slice of the hash per step scaled to [0, i] (a multiply, not a division).
            for (glm::length_t i = N - 1; i > 0; --i, h >>= 16)
                std::swap(order[size_t(i)], order[size_t(((h & 0xFFFF) * uint64_t(i + 1)) >> 16)]);
        }
        T s = a[order[0]] * b[order[0]];
        for (size_t i = 1; i < order.size(); ++i) s = s + a[order[i]] * b[order[i]];
        return s;
    }
};

// Limits of the float values the type holds.
template <>
class std::numeric_limits<refray::procedural::PerturbedFloat> : public std::numeric_limits<float> {
    using T = refray::procedural::PerturbedFloat;
    using F = std::numeric_limits<float>;

public:
    static constexpr T min() noexcept { return T(F::min()); }
    static constexpr T max() noexcept { return T(F::max()); }
    static constexpr T lowest() noexcept { return T(F::lowest()); }
    static constexpr T epsilon() noexcept { return T(F::epsilon()); }
    static constexpr T infinity() noexcept { return T(F::infinity()); }
    static constexpr T quiet_NaN() noexcept { return T(F::quiet_NaN()); }
    static constexpr T denorm_min() noexcept { return T(F::denorm_min()); }
};
