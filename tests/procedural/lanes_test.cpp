// Lanes<float, N>'s own instructions (procedural/math/lanes.h) against libm, bit for bit: abs, floor, sqrt, min and
// max run vectorised for float lanes and must equal fabsf, floorf, sqrtf, fminf and fmaxf in every lane, on special
// values (signed zeros, quiet NaNs, infinities, denormals, the 2^23 boundary of floor) and on random ones.
#ifndef REFRAY_LANES_TEST_WIDTH
#define REFRAY_LANES_TEST_WIDTH 16
#endif

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <random>
#include <vector>

#include "procedural/math/hlsl.h"

namespace refray::procedural {
namespace {

// tests/procedural/CMakeLists.txt builds this file for 16 lanes (kMaxLanes) and for 8 (the ports').
constexpr int W = REFRAY_LANES_TEST_WIDTH;
using L = math::Lanes<float, W>;

uint32_t bitsOf(float x) { return std::bit_cast<uint32_t>(x); }

std::vector<float> testValues() {
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<float> v = {0.f,     -0.f,    1.f,         -1.f,       0.5f,        -0.5f,      1.5f,    -1.5f,
                            2.5f,    -2.5f,   0x1p23f,     -0x1p23f,   0x1p23f + 2, -0x1p23f - 2, 8388607.5f, -8388607.5f,
                            1e30f,   -1e30f,  inf,         -inf,       NAN,         -NAN,       1e-40f,  -1e-40f,
                            0x1p-149f, 0.99999994f, -0.99999994f, 3.0f, -3.0f,      2147483648.f, -2147483648.f, 4e9f};
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> wide(-1000.0f, 1000.0f);
    for (int i = 0; i < 4000; ++i) {
        const float x = wide(rng);
        v.push_back(x);
        v.push_back(x * 1e-3f);
        float bits = std::bit_cast<float>(uint32_t(rng()));
        if (bits != bits) bits = std::bit_cast<float>(bitsOf(bits) | 0x00400000u);  // quiet: arithmetic makes no other
        v.push_back(bits);
    }
    while (v.size() % W) v.push_back(1.0f);
    return v;
}

L lanesAt(const std::vector<float>& v, size_t k, size_t step = 1) {
    L a;
    for (int i = 0; i < W; ++i) a.v[i] = v[(k + size_t(i) * step) % v.size()];
    return a;
}

TEST(Lanes, UnaryInstructionsAreLibmBitForBit) {
    const std::vector<float> v = testValues();
    for (size_t k = 0; k < v.size(); k += W) {
        const L a = lanesAt(v, k);
        const L fl = hlsl::floor(a), ab = hlsl::abs(a), sq = hlsl::sqrt(a);
        for (int i = 0; i < W; ++i) {
            const float x = a.v[i];
            if (x == x) EXPECT_EQ(bitsOf(fl.v[i]), bitsOf(std::floor(x))) << "floor(" << x << ")";
            else EXPECT_NE(fl.v[i], fl.v[i]);
            EXPECT_EQ(bitsOf(ab.v[i]), bitsOf(std::fabs(x))) << "abs(" << x << ")";
            if (x >= 0.0f) EXPECT_EQ(bitsOf(sq.v[i]), bitsOf(std::sqrt(x))) << "sqrt(" << x << ")";
            else EXPECT_NE(sq.v[i], sq.v[i]) << "sqrt(" << x << ")";
        }
    }
}

TEST(Lanes, MinAndMaxAreGlibcFminfFmaxf) {
    const std::vector<float> v = testValues();
    for (size_t k = 0; k < v.size(); k += W)
        for (size_t step : {1u, 7u, 31u}) {
            const L a = lanesAt(v, k), b = lanesAt(v, k + 3, step);
            const L mn = hlsl::min(a, b), mx = hlsl::max(a, b);
            for (int i = 0; i < W; ++i) {
                EXPECT_EQ(bitsOf(mn.v[i]), bitsOf(std::fmin(a.v[i], b.v[i]))) << "min(" << a.v[i] << ", " << b.v[i] << ")";
                EXPECT_EQ(bitsOf(mx.v[i]), bitsOf(std::fmax(a.v[i], b.v[i]))) << "max(" << a.v[i] << ", " << b.v[i] << ")";
            }
        }
}

TEST(Lanes, SelectAndMasksWorkLaneByLane) {
    const L a = L::generate([](int i) { return float(i); });
    const auto low = a < L(4.0f);
    EXPECT_TRUE(math::anyLane(low));
    EXPECT_FALSE(math::allLanes(low));
    const L s = math::select(low, a, L(-1.0f));
    for (int i = 0; i < W; ++i) EXPECT_EQ(s.v[i], i < 4 ? float(i) : -1.0f);
    EXPECT_EQ(math::select(true, 2.0f, 3.0f), 2.0f);  // the scalar form is the plain conditional
    EXPECT_FALSE(math::anyLane(a > L(100.0f)));
}

// pow over lanes that all hold one base and one exponent is computed once and kept per thread (lastPow, for the
// fractal pyramid's pow(2, -n) at every march step): whatever came before, each result is the scalar pow of its
// operands in the floating-point mode of the moment, denormal flushing included.
TEST(Lanes, UniformPowIsTheScalarPowWhateverCameBefore) {
    const auto scalarPow = [](float a, float b) {
        volatile float x = a, y = b;  // no constant folding
        return hlsl::pow(float(x), float(y));
    };
    const std::pair<float, float> operands[] = {{2.0f, -4.0f}, {2.0f, -130.0f}, {3.0f, 0.5f}, {2.0f, -4.0f},
                                                {2.0f, -130.0f}, {0.0f, 2.0f}, {-1.0f, 2.0f}, {2.0f, -130.0f}};
    bool modesDiffer = false;
    for (int pass = 0; pass < 2; ++pass) {
        for (const auto& [a, b] : operands) {
            for (const bool flush : {true, false, true, false}) {  // kept under one mode, asked under the other
                std::optional<hlsl::ScopedFlushDenormals> ftz;
                if (flush) ftz.emplace();
                const float want = scalarPow(a, b);
                const L got = hlsl::pow(L(a), L(b));
                for (int i = 0; i < W; ++i)
                    EXPECT_EQ(bitsOf(want), bitsOf(got.v[i])) << "pow(" << a << ", " << b << ") lane " << i
                                                              << (flush ? ", denormals flushed" : "");
                if (flush && hlsl::ScopedFlushDenormals::active()) {
                    ftz.reset();
                    modesDiffer = modesDiffer || bitsOf(scalarPow(a, b)) != bitsOf(want);
                }
            }
        }
    }
    if (hlsl::ScopedFlushDenormals::active()) {
        EXPECT_TRUE(modesDiffer) << "no operands whose pow the mode changes";
    }
    // Lanes that hold different operands each get their own scalar pow.
    const L mixed = hlsl::pow(L::generate([](int i) { return 1.5f + float(i); }), L(-4.0f));
    for (int i = 0; i < W; ++i) EXPECT_EQ(bitsOf(mixed.v[i]), bitsOf(scalarPow(1.5f + float(i), -4.0f)));
}

}  // namespace
}  // namespace refray::procedural
