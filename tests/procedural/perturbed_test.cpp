// Tests procedural/math/perturbed.h: each perturbed instruction stays within variation model v1's bound and uses
// it, the perturbation is a pure function of (seed, operands), and without a Scope PerturbedFloat computes what float
// computes. Inputs come from fixed seeds.
#include "procedural/math/perturbed.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "procedural/math/fractals.h"
#include "procedural/math/metaballs.h"

namespace refray::procedural {
namespace {

using P = PerturbedFloat;
using perturbed::floatUlp;

constexpr int kSamples = 20000;
constexpr uint32_t kInputSeed = 20260817u;

// A float of random sign (if `signed_`) with a random significand and a binary exponent in [minExp, maxExp].
std::vector<float> spread(int minExp, int maxExp, bool signed_, uint32_t seed = kInputSeed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> m(1.0, 2.0);
    std::uniform_int_distribution<int> e(minExp, maxExp);
    std::bernoulli_distribution negative(signed_ ? 0.5 : 0.0);
    std::vector<float> v(kSamples);
    for (float& x : v) x = float((negative(rng) ? -1.0 : 1.0) * std::ldexp(m(rng), e(rng)));
    return v;
}

std::vector<float> uniform(double lo, double hi, uint32_t seed = kInputSeed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> d(lo, hi);
    std::vector<float> v(kSamples);
    for (float& x : v) x = float(d(rng));
    return v;
}

// The error of r against the exact result, in the unit a bound is stated in.
enum class Unit { Ulps, Relative, Absolute };
double errorOf(float r, double exact, Unit unit) {
    const double d = std::fabs(double(r) - exact);
    switch (unit) {
        case Unit::Ulps: return d / floatUlp(exact);
        case Unit::Relative: return d / std::fabs(exact);
        case Unit::Absolute: return d;
    }
    return d;
}

struct Measured {
    double worst = 0.0;
    int moved = 0;  // results other than the correctly rounded one
};

// One instruction over `inputs` under seed `seed`: the worst error against `exact` and how often the result is not
// the correctly rounded one.
Measured measure(const std::vector<float>& inputs, const std::function<float(float)>& instruction,
                 const std::function<double(float)>& exact, Unit unit, uint64_t seed = 1) {
    const perturbed::Context context(Perturbation{seed});
    const perturbed::Scope scope(context);
    Measured m;
    for (float x : inputs) {
        const double e = exact(x);
        const float r = instruction(x);
        m.worst = std::max(m.worst, errorOf(r, e, unit));
        if (r != float(e)) ++m.moved;
    }
    return m;
}

// Within the bound, and drawing from most of it: the worst error reaches 3/4 of the bound, and a fifth of the results
// move off the correctly rounded value (a 1-ulp bound leaves only the neighbours of the nearest float: about a
// quarter move).
void expectUsesTheBound(const Measured& m, double bound, const char* what) {
    EXPECT_LE(m.worst, bound) << what;
    EXPECT_GE(m.worst, 0.75 * bound) << what;
    EXPECT_GE(m.moved, kSamples / 5) << what;
    std::printf("[perturbed] %-24s worst %.4g (bound %.4g), %d of %d moved\n", what, m.worst, bound, m.moved,
                kSamples);
}

// ---- Each instruction within its bound ------------------------------------------------------------------------

TEST(PerturbedFloat, DivisionStaysWithinTwoAndAHalfUlps) {
    const std::vector<float> x = spread(-30, 30, true, 1), y = spread(-40, 40, true, 2);
    const perturbed::Context context(Perturbation{7});
    const perturbed::Scope scope(context);
    Measured m;
    for (int i = 0; i < kSamples; ++i) {
        const double exact = double(x[i]) / double(y[i]);
        const float r = (P(x[i]) / P(y[i])).value();
        m.worst = std::max(m.worst, errorOf(r, exact, Unit::Ulps));
        if (r != float(exact)) ++m.moved;
    }
    expectUsesTheBound(m, variation::kDivisionUlps, "x / y");
}

TEST(PerturbedFloat, SqrtRsqrtExp2Log2SinCosAcosAtanStayWithinTheirBounds) {
    const std::vector<float> positive = spread(-60, 60, false);
    const auto sqrtOf = [](float x) { return hlsl::sqrt(P(x)).value(); };
    const auto rsqrtOf = [](float x) { return hlsl::rsqrt(P(x)).value(); };
    expectUsesTheBound(measure(positive, sqrtOf, [](float x) { return std::sqrt(double(x)); }, Unit::Ulps),
                       variation::kSqrtUlps, "sqrt");
    expectUsesTheBound(measure(positive, rsqrtOf, [](float x) { return 1.0 / std::sqrt(double(x)); }, Unit::Relative),
                       variation::kRsqrtRelative, "rsqrt");

    const auto exp2Of = [](float x) { return hlsl::exp2(P(x)).value(); };
    const auto exp2Exact = [](float x) { return std::exp2(double(x)); };
    expectUsesTheBound(measure(uniform(-100, 100), exp2Of, exp2Exact, Unit::Relative), variation::kExp2Relative,
                       "exp2");

    const auto log2Of = [](float x) { return hlsl::log2(P(x)).value(); };
    const auto log2Exact = [](float x) { return std::log2(double(x)); };
    expectUsesTheBound(measure(uniform(0.5, 2.0), log2Of, log2Exact, Unit::Absolute), variation::kLog2Absolute,
                       "log2 on [0.5, 2]");
    std::vector<float> outside = spread(-60, 60, false);
    std::erase_if(outside, [](float x) { return x >= 0.5f && x <= 2.0f; });
    outside.resize(kSamples, 1000.0f);
    expectUsesTheBound(measure(outside, log2Of, log2Exact, Unit::Relative), variation::kLog2Relative,
                       "log2 elsewhere");

    const std::vector<float> angles = uniform(-100 * std::numbers::pi, 100 * std::numbers::pi);
    const auto sinOf = [](float x) { return hlsl::sin(P(x)).value(); };
    const auto cosOf = [](float x) { return hlsl::cos(P(x)).value(); };
    expectUsesTheBound(measure(angles, sinOf, [](float x) { return std::sin(double(x)); }, Unit::Absolute),
                       variation::kSinCosAbsolute, "sin");
    expectUsesTheBound(measure(angles, cosOf, [](float x) { return std::cos(double(x)); }, Unit::Absolute),
                       variation::kSinCosAbsolute, "cos");

    const auto acosOf = [](float x) { return hlsl::acos(P(x)).value(); };
    expectUsesTheBound(measure(uniform(-1, 1), acosOf, [](float x) { return std::acos(double(x)); }, Unit::Ulps),
                       variation::kAcosUlps, "acos");
    // atan through atan2(y, 1) = atan(y / 1): x / 1 is exact, so only atan varies.
    const auto atanOf = [](float x) { return hlsl::atan2(P(x), P(1.0f)).value(); };
    expectUsesTheBound(measure(spread(-20, 20, true), atanOf, [](float x) { return std::atan(double(x)); }, Unit::Ulps),
                       variation::kAtanUlps, "atan");
}

TEST(PerturbedFloat, SinAndCosStayInMinusOneToOne) {
    const perturbed::Context context(Perturbation{3});
    const perturbed::Scope scope(context);
    // Near the extrema, where an absolute error of 0.0008 would leave [-1, 1] without the clamp.
    for (float x : uniform(-0.05, 0.05)) {
        const float c = hlsl::cos(P(x)).value();
        const float s = hlsl::sin(P(x + std::numbers::pi_v<float> / 2)).value();
        EXPECT_LE(c, 1.0f);
        EXPECT_LE(s, 1.0f);
        EXPECT_GE(hlsl::cos(P(x + std::numbers::pi_v<float>)).value(), -1.0f);
    }
}

// The special cases the D3D11.3 instruction tables give exactly stay exact.
TEST(PerturbedFloat, SpecialValuesAreExact) {
    const perturbed::Context context(Perturbation{11});
    const perturbed::Scope scope(context);
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (float zero : {0.0f, -0.0f}) {
        EXPECT_EQ(hlsl::exp2(P(zero)).value(), 1.0f);
        EXPECT_EQ(std::bit_cast<uint32_t>(hlsl::sin(P(zero)).value()), std::bit_cast<uint32_t>(zero));
        EXPECT_EQ(hlsl::cos(P(zero)).value(), 1.0f);
        EXPECT_EQ(std::bit_cast<uint32_t>(hlsl::sqrt(P(zero)).value()), std::bit_cast<uint32_t>(zero));
        EXPECT_EQ(hlsl::log2(P(zero)).value(), -inf);
    }
    EXPECT_EQ(hlsl::rsqrt(P(0.0f)).value(), inf);
    EXPECT_EQ(hlsl::rsqrt(P(-0.0f)).value(), -inf);
    EXPECT_EQ(hlsl::rsqrt(P(inf)).value(), 0.0f);
    EXPECT_TRUE(std::isnan(hlsl::rsqrt(P(-1.0f)).value()));
    EXPECT_TRUE(std::isnan(hlsl::sqrt(P(-1.0f)).value()));
    EXPECT_TRUE(std::isnan(hlsl::acos(P(1.5f)).value()));
    EXPECT_TRUE(std::isnan(hlsl::sin(P(inf)).value()));
    EXPECT_EQ(hlsl::exp2(P(-inf)).value(), 0.0f);
    EXPECT_EQ(hlsl::exp2(P(200.0f)).value(), inf);
    EXPECT_EQ((P(1.0f) / P(0.0f)).value(), inf);
    EXPECT_TRUE(std::isnan((P(0.0f) / P(0.0f)).value()));
    for (float x : spread(-30, 30, true)) ASSERT_EQ((P(x) / P(1.0f)).value(), x);  // x / 1 = x (§3.1.3.2)
}

// ---- Determinism ------------------------------------------------------------------------------------------------

TEST(PerturbedFloat, TheErrorIsAFunctionOfSeedAndOperandsOnly) {
    const std::vector<float> x = spread(-20, 20, false);
    std::vector<float> first;
    {
        const perturbed::Context context(Perturbation{42});
        const perturbed::Scope scope(context);
        for (float v : x) first.push_back((P(1.0f) / hlsl::sqrt(P(v))).value());
    }
    // Other operations in between and the inputs in reverse order: the same results.
    const perturbed::Context context(Perturbation{42});
    const perturbed::Scope scope(context);
    for (int i = kSamples - 1; i >= 0; --i) {
        (void)hlsl::sin(P(x[size_t(i)]));
        ASSERT_EQ((P(1.0f) / hlsl::sqrt(P(x[size_t(i)]))).value(), first[size_t(i)]) << i;
    }
    // Another seed: another GPU.
    const perturbed::Context other(Perturbation{43});
    const perturbed::Scope otherScope(other);
    int differ = 0;
    for (int i = 0; i < kSamples; ++i) differ += (P(1.0f) / hlsl::sqrt(P(x[size_t(i)]))).value() != first[size_t(i)];
    EXPECT_GE(differ, kSamples / 2);
}

TEST(PerturbedFloat, ScopesNestAndRestore) {
    EXPECT_EQ(perturbed::current(), nullptr);
    const perturbed::Context outer(Perturbation{1});
    const perturbed::Context inner(Perturbation{2});
    {
        const perturbed::Scope a(outer);
        EXPECT_EQ(perturbed::current(), &outer);
        {
            const perturbed::Scope b(inner);
            EXPECT_EQ(perturbed::current(), &inner);
        }
        EXPECT_EQ(perturbed::current(), &outer);
    }
    EXPECT_EQ(perturbed::current(), nullptr);
}

// ---- Without a Scope, PerturbedFloat is float --------------------------------------------------------------------

uint32_t bitsOf(float x) { return std::bit_cast<uint32_t>(x); }

TEST(PerturbedFloat, WithoutAScopeEveryOperationIsFloatBitForBit) {
    ASSERT_EQ(perturbed::current(), nullptr);
    const std::vector<float> a = spread(-20, 20, true, 5), b = spread(-20, 20, true, 6), c = spread(-20, 20, true, 7);
    for (int i = 0; i < kSamples; ++i) {
        const P pa(a[i]), pb(b[i]), pc(c[i]);
        ASSERT_EQ(bitsOf((pa * pb + pc).value()), bitsOf(a[i] * b[i] + c[i])) << i;
        ASSERT_EQ(bitsOf((pa / pb - pc).value()), bitsOf(a[i] / b[i] - c[i])) << i;
        ASSERT_EQ(bitsOf(hlsl::pow(hlsl::abs(pa), pc * P(0.01f)).value()),
                  bitsOf(hlsl::pow(std::fabs(a[i]), c[i] * 0.01f)));
        ASSERT_EQ(bitsOf(hlsl::atan2(pa, pb).value()), bitsOf(hlsl::atan2(a[i], b[i])));
        ASSERT_EQ(bitsOf(hlsl::rsqrt(hlsl::abs(pa)).value()), bitsOf(hlsl::rsqrt(std::fabs(a[i]))));
    }
}

// The ports instantiated on PerturbedFloat compute, without a Scope, exactly what they compute in float: one source,
// two scalar types.
TEST(PerturbedFloat, WithoutAScopeThePortsMatchFloat) {
    const std::vector<float> x = uniform(-1.2, 1.2, 8), y = uniform(-1.2, 1.2, 9), z = uniform(-1.2, 1.2, 10);
    for (int i = 0; i < 500; ++i) {
        const math::vec3<float> p(x[i], y[i], z[i]);
        const math::vec3<P> q{P(x[i]), P(y[i]), P(z[i])};
        ASSERT_EQ(bitsOf(math::mandelbulb::mdist(q).value()), bitsOf(math::mandelbulb::mdist(p))) << i;
        const math::vec2<P> j = math::julia::jdist(q, math::julia::kc<P>(), 200);
        const math::vec2<float> jf = math::julia::jdist(p, math::julia::kc<float>(), 200);
        ASSERT_EQ(bitsOf(j.x.value()), bitsOf(jf.x)) << i;
        ASSERT_EQ(bitsOf(math::d3d12::sdCog(q).value()), bitsOf(math::d3d12::sdCog(p))) << i;
        const math::vec3<P> n = math::julia::calcNormal(q);
        const math::vec3<float> nf = math::julia::calcNormal(p);
        for (int k = 0; k < 3; ++k) ASSERT_EQ(bitsOf(n[k].value()), bitsOf(nf[k])) << i;
    }
}

// ---- Contraction and the order of a dot product ---------------------------------------------------------------

// a*b + c under each contraction option: split is float's two roundings, fuse one rounding of the exact a*b + c
// (within half an ulp; the fused sum is formed in double, so a tie may round either way), mixed either.
TEST(PerturbedFloat, ContractionSplitsFusesOrMixes) {
    const std::vector<float> a = spread(-10, 10, true, 11), b = spread(-10, 10, true, 12);
    const std::vector<float> c = spread(-10, 10, true, 13);
    int fusedDiffers = 0, mixedSplit = 0, mixedFused = 0;
    for (int i = 0; i < kSamples; ++i) {
        const float split = a[i] * b[i] + c[i];
        const long double exact = (long double)a[i] * (long double)b[i] + (long double)c[i];
        float fused = 0.0f, mixed = 0.0f;
        {
            const perturbed::Context context(Perturbation{5, Contraction::Split});
            const perturbed::Scope scope(context);
            ASSERT_EQ(bitsOf((P(a[i]) * P(b[i]) + P(c[i])).value()), bitsOf(split));
            ASSERT_EQ(bitsOf((P(c[i]) - P(a[i]) * P(b[i])).value()), bitsOf(c[i] - a[i] * b[i]));
        }
        {
            const perturbed::Context context(Perturbation{5, Contraction::Fuse});
            const perturbed::Scope scope(context);
            fused = (P(a[i]) * P(b[i]) + P(c[i])).value();
            ASSERT_EQ(bitsOf((P(c[i]) + P(a[i]) * P(b[i])).value()), bitsOf(fused));
            ASSERT_LE(std::fabs((long double)fused - exact), 0.5000001L * (long double)floatUlp(double(exact))) << i;
        }
        {
            const perturbed::Context context(Perturbation{5, Contraction::Mixed});
            const perturbed::Scope scope(context);
            mixed = (P(a[i]) * P(b[i]) + P(c[i])).value();
        }
        if (fused != split) {
            ++fusedDiffers;
            mixedSplit += mixed == split;
            mixedFused += mixed == fused;
            EXPECT_TRUE(mixed == split || mixed == fused) << i;
        }
    }
    EXPECT_GE(fusedDiffers, kSamples / 20);
    EXPECT_GE(mixedSplit, fusedDiffers / 3);
    EXPECT_GE(mixedFused, fusedDiffers / 3);
}

// dot(a, b) sums its products in an order the hash picks (D3D11.3 §3.1.3.2): with split contraction, every result is
// the float sum in one of the 3! orders, and more than one order occurs.
TEST(PerturbedFloat, DotSumsItsTermsInAnyOrder) {
    const std::vector<float> x = spread(-8, 8, true, 14);
    const perturbed::Context context(Perturbation{9, Contraction::Split});
    const perturbed::Scope scope(context);
    std::set<int> ordersSeen;
    for (int i = 0; i + 6 <= kSamples; i += 6) {
        const std::array<float, 3> a{x[i], x[i + 1], x[i + 2]}, b{x[i + 3], x[i + 4], x[i + 5]};
        const float r = hlsl::dot(math::vec3<P>(P(a[0]), P(a[1]), P(a[2])), math::vec3<P>(P(b[0]), P(b[1]), P(b[2])))
                            .value();
        std::array<int, 3> order{0, 1, 2};
        int match = -1;
        for (int k = 0; k < 6; ++k) {
            const float sum = a[order[0]] * b[order[0]] + a[order[1]] * b[order[1]] + a[order[2]] * b[order[2]];
            if (sum == r && match < 0) match = k;
            std::next_permutation(order.begin(), order.end());
        }
        ASSERT_GE(match, 0) << i;
        ordersSeen.insert(match);  // the first order that gives the sum (orders with equal sums look alike)
    }
    EXPECT_GE(ordersSeen.size(), 3u);
}

// ---- Denormals -------------------------------------------------------------------------------------------------

TEST(PerturbedFloat, DenormalsAreFlushedOrPreservedAsTheOptionsSay) {
    if (!hlsl::ScopedFlushDenormals::active()) GTEST_SKIP() << "no MXCSR on this target";
    // Read from a volatile at each use: the compiler does not know that a Scope changes MXCSR, and would reuse one
    // product for all three.
    volatile float small = 1e-20f;
    const auto square = [&small] { return (P(small) * P(small)).value(); };  // 1e-40: a denormal
    {
        const perturbed::Context context(Perturbation{1, Contraction::Mixed, Denormals::Flush});
        const perturbed::Scope scope(context);
        EXPECT_EQ(square(), 0.0f);
    }
    {
        const perturbed::Context context(Perturbation{1, Contraction::Mixed, Denormals::Preserve});
        const perturbed::Scope scope(context);
        EXPECT_EQ(std::fpclassify(square()), FP_SUBNORMAL);
    }
    EXPECT_EQ(std::fpclassify(square()), FP_SUBNORMAL);  // the thread's own mode is back
}

// ---- Libraries ------------------------------------------------------------------------------------------------

TEST(PerturbedFloat, WithArithmeticInstallsTheLibrarysPerturbationForEachCall) {
    const Perturbation perturbation{77, Contraction::Fuse, Denormals::Preserve};
    const auto entry = withArithmetic<P>(perturbation, [](int& seen) {
        ASSERT_NE(perturbed::current(), nullptr);
        EXPECT_EQ(perturbed::current()->options(), (Perturbation{77, Contraction::Fuse, Denormals::Preserve}));
        ++seen;
    });
    int seen = 0;
    entry(seen);
    entry(seen);
    EXPECT_EQ(seen, 2);
    EXPECT_EQ(perturbed::current(), nullptr);
    // float keeps its callable as it is.
    const auto plain = withArithmetic<float>(std::nullopt, [](int& n) { n = perturbed::current() ? -1 : 1; });
    plain(seen);
    EXPECT_EQ(seen, 1);
}

TEST(PerturbedFloat, ForScalarTypePicksTheTypeAndRefusesPerturbedDouble) {
    std::string picked;
    const auto name = [&picked]<typename T>() {
        picked = std::is_same_v<T, P> ? "perturbed" : std::is_same_v<T, double> ? "double" : "float";
    };
    forScalarType(Precision::Float, std::nullopt, name);
    EXPECT_EQ(picked, "float");
    forScalarType(Precision::Double, std::nullopt, name);
    EXPECT_EQ(picked, "double");
    forScalarType(Precision::Float, Perturbation{1}, name);
    EXPECT_EQ(picked, "perturbed");
    try {
        forScalarType(Precision::Double, Perturbation{1}, name);
        FAIL() << "a perturbed double library must be refused";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "a perturbed render perturbs the GPU's float arithmetic; --perturb cannot be combined "
                               "with --precision double");
    }
}

}  // namespace
}  // namespace refray::procedural
