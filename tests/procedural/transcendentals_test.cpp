// procedural/math/transcendentals.h: SLEEF's float sin, cos, acos, atan, exp2 and log2, one float and eight at a time.
// Eight at a time must give each lane the one-float result whatever its neighbours hold (SLEEF's sin and cos choose
// their argument reduction for all lanes at once, and their scalar and vector builds return NaNs of either sign);
// both must stay within SLEEF's 3.5-ulp bound of the exact value, inside docs/numerical-variation.md, with the
// special values that table names.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "procedural/math/hlsl.h"
#include "procedural/math/transcendentals.h"

namespace refray::procedural::math {
namespace {

constexpr Transcendental kAll[] = {Transcendental::Sin,  Transcendental::Cos,  Transcendental::Acos,
                                   Transcendental::Atan, Transcendental::Exp2, Transcendental::Log2};
const char* nameOf(Transcendental f) {
    static const char* names[] = {"sin", "cos", "acos", "atan", "exp2", "log2"};
    return names[int(f)];
}
double exact(Transcendental f, double x) {
    switch (f) {
        case Transcendental::Sin: return std::sin(x);
        case Transcendental::Cos: return std::cos(x);
        case Transcendental::Acos: return std::acos(x);
        case Transcendental::Atan: return std::atan(x);
        case Transcendental::Exp2: return std::exp2(x);
        case Transcendental::Log2: return std::log2(x);
    }
    return 0;
}

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Neighbours that steer SLEEF's vector sin and cos onto their other reduction, and ordinary ones.
constexpr float kOddNeighbours[] = {kNaN, kInf, -kInf, 1e30f, -1e30f, 1e-40f, 0.0f, -0.0f, 99.0f, 100.0f, 124.9f,
                                    125.0f, -200.0f, 1e5f, 0x1p-126f, -1.0f, 0.5f, 2.0f};

float anyFloat(std::mt19937& rng) {
    switch (rng() % 4) {
        case 0: return std::bit_cast<float>(uint32_t(rng()));                  // any bit pattern
        case 1: return float(int(rng() % 300000) - 150000) / 1000.0f;           // [-150, 150]: both sides of 100
        case 2: return float(int(rng() % 2000001) - 1000000) / 1000000.0f;      // [-1, 1]: acos's domain
        default: return kOddNeighbours[rng() % std::size(kOddNeighbours)];
    }
}

TEST(Transcendentals, EightAtATimeIsEachLanesOneFloatResultWhateverItsNeighboursHold) {
    std::mt19937 rng(20261127);
    for (Transcendental f : kAll) {
        int checked = 0;
        for (int round = 0; round < 200000; ++round) {
            float in[8], out[8];
            for (float& x : in) x = kOddNeighbours[rng() % std::size(kOddNeighbours)];
            const uint32_t lanes = rng() & 0xFFu;
            for (int i = 0; i < 8; ++i)
                if (lanes >> i & 1u) in[i] = anyFloat(rng);
            transcendental8(f, in, out, lanes);
            for (int i = 0; i < 8; ++i) {
                if (!(lanes >> i & 1u)) continue;
                const float one = transcendental(f, in[i]);
                ASSERT_EQ(std::bit_cast<uint32_t>(out[i]), std::bit_cast<uint32_t>(one))
                    << nameOf(f) << "(" << std::hexfloat << in[i] << ") in lane " << i << " of mask " << lanes;
                ++checked;
            }
        }
        EXPECT_GT(checked, 500000) << nameOf(f);
    }
}

TEST(Transcendentals, InPlaceAndAllLanesByDefault) {
    float v[8] = {0.0f, 0.5f, -1.0f, 3.0f, 150.0f, kNaN, 1e-3f, 7.0f};
    float expected[8];
    for (int i = 0; i < 8; ++i) expected[i] = transcendental(Transcendental::Cos, v[i]);
    transcendental8(Transcendental::Cos, v, v);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(std::bit_cast<uint32_t>(v[i]), std::bit_cast<uint32_t>(expected[i])) << i;
}

// Within 3.5 ulp of libm's double result (ulps of the float result), over the ranges the ports use.
TEST(Transcendentals, WithinThreeAndAHalfUlpsOfTheExactValue) {
    std::mt19937 rng(7);
    for (Transcendental f : kAll) {
        double worst = 0;
        for (int k = 0; k < 300000; ++k) {
            float x = anyFloat(rng);
            if (!std::isfinite(x)) continue;
            if (f == Transcendental::Exp2) x = std::fmod(x, 120.0f);  // beyond, exp2 leaves float's range
            const double e = exact(f, x);
            if (!std::isfinite(e)) continue;
            const float r = transcendental(f, x);
            const float rounded = float(e);
            const double ulp = std::fabs(double(std::nextafter(rounded, kInf)) - double(rounded));
            if (ulp == 0 || !std::isfinite(ulp)) continue;
            worst = std::max(worst, std::fabs(double(r) - e) / ulp);
        }
        EXPECT_LE(worst, 3.5) << nameOf(f) << ": " << worst << " ulp";
    }
}

// The special values docs/numerical-variation.md requires of every GPU.
TEST(Transcendentals, SpecialValues) {
    const auto bits = [](float x) { return std::bit_cast<uint32_t>(x); };
    EXPECT_EQ(bits(transcendental(Transcendental::Sin, 0.0f)), bits(0.0f));
    EXPECT_EQ(bits(transcendental(Transcendental::Sin, -0.0f)), bits(-0.0f));
    EXPECT_EQ(transcendental(Transcendental::Cos, 0.0f), 1.0f);
    EXPECT_EQ(transcendental(Transcendental::Cos, -0.0f), 1.0f);
    EXPECT_EQ(transcendental(Transcendental::Exp2, 0.0f), 1.0f);
    EXPECT_EQ(transcendental(Transcendental::Exp2, -0.0f), 1.0f);
    EXPECT_EQ(transcendental(Transcendental::Exp2, 3.0f), 8.0f);
    EXPECT_EQ(transcendental(Transcendental::Log2, 8.0f), 3.0f);
    EXPECT_EQ(transcendental(Transcendental::Log2, 0.0f), -kInf);
    EXPECT_TRUE(std::isnan(transcendental(Transcendental::Log2, -1.0f)));
    EXPECT_TRUE(std::isnan(transcendental(Transcendental::Acos, 1.0000001f)));  // no clamping (Proceduray hazard H6)
    EXPECT_EQ(transcendental(Transcendental::Acos, 1.0f), 0.0f);
    EXPECT_TRUE(std::isnan(transcendental(Transcendental::Sin, kInf)));
    EXPECT_TRUE(std::isnan(transcendental(Transcendental::Cos, kNaN)));
    // Every NaN result is one NaN, whichever build of SLEEF computed it.
    float nans[8] = {1.5f, -1.5f, 1e30f, -1e30f, kNaN, -kNaN, 2.0f, -2.0f};
    transcendental8(Transcendental::Acos, nans, nans);
    for (float r : nans) {
        EXPECT_EQ(bits(r), 0x7FC00000u);
        EXPECT_EQ(bits(r), bits(transcendental(Transcendental::Acos, -1.5f)));
    }
    for (float x : {-1e6f, -3.0f, 0.3f, 99.5f, 1e4f}) {
        EXPECT_LE(std::fabs(transcendental(Transcendental::Sin, x)), 1.0f) << x;
        EXPECT_LE(std::fabs(transcendental(Transcendental::Cos, x)), 1.0f) << x;
    }
}

// transcendental() computes exp2 of an integer and log2 of a power of two itself: SLEEF's bits, for every one.
TEST(Transcendentals, TheExactCasesAreSleefsOwnResults) {
    float in[8], out[8];
    for (int k = -149; k <= 127; ++k) {
        const float x = float(k);
        EXPECT_EQ(transcendental(Transcendental::Exp2, x), std::ldexp(1.0f, k)) << k;
        EXPECT_EQ(std::bit_cast<uint32_t>(transcendental(Transcendental::Exp2, x)),
                  std::bit_cast<uint32_t>(detail::sleefTranscendental(Transcendental::Exp2, x))) << k;
        std::fill(in, in + 8, x);
        transcendental8(Transcendental::Exp2, in, out);
        EXPECT_EQ(std::bit_cast<uint32_t>(out[3]), std::bit_cast<uint32_t>(transcendental(Transcendental::Exp2, x))) << k;
    }
    for (int k = -126; k <= 127; ++k) {
        const float x = std::ldexp(1.0f, k);
        EXPECT_EQ(transcendental(Transcendental::Log2, x), float(k)) << k;
        EXPECT_EQ(std::bit_cast<uint32_t>(transcendental(Transcendental::Log2, x)),
                  std::bit_cast<uint32_t>(detail::sleefTranscendental(Transcendental::Log2, x))) << k;
        std::fill(in, in + 8, x);
        transcendental8(Transcendental::Log2, in, out);
        EXPECT_EQ(std::bit_cast<uint32_t>(out[5]), std::bit_cast<uint32_t>(transcendental(Transcendental::Log2, x))) << k;
    }
    // Not exact cases: SLEEF's.
    for (float x : {0.5f, -3.25f, 127.5f, 1e-3f})
        EXPECT_EQ(std::bit_cast<uint32_t>(transcendental(Transcendental::Exp2, x)),
                  std::bit_cast<uint32_t>(detail::sleefTranscendental(Transcendental::Exp2, x))) << x;
    for (float x : {3.0f, 0x1.000002p0f, -2.0f, 0.0f})
        EXPECT_EQ(std::bit_cast<uint32_t>(transcendental(Transcendental::Log2, x)),
                  std::bit_cast<uint32_t>(detail::sleefTranscendental(Transcendental::Log2, x))) << x;
}

// The ports' float instructions are these functions (hlsl::ScalarOps<float>); double keeps libm's.
TEST(Transcendentals, AreFloatsHlslInstructions) {
    for (float x : {0.3f, -2.5f, 42.0f, 1e5f}) {
        EXPECT_EQ(std::bit_cast<uint32_t>(hlsl::sin(x)), std::bit_cast<uint32_t>(transcendental(Transcendental::Sin, x)));
        EXPECT_EQ(std::bit_cast<uint32_t>(hlsl::exp2(x / 10)),
                  std::bit_cast<uint32_t>(transcendental(Transcendental::Exp2, x / 10)));
        EXPECT_EQ(hlsl::cos(double(x)), std::cos(double(x)));
    }
}

}  // namespace
}  // namespace refray::procedural::math
