// float's transcendental functions in every shader port: SLEEF's sin, cos, acos, atan, exp2 and log2 with a 3.5-ulp
// bound (its u35 functions), for one float and for eight floats at once.
//
// One algorithm for both, so that a lane of the wave math (procedural/math/lanes.h) is bit for bit the scalar
// result: eight floats go through SLEEF's AVX2 functions in one call where the CPU has AVX2 and FMA, else through
// its scalar FMA functions one by one (the same numbers: SLEEF compiles one source for both; a NaN result is always
// the same NaN). The bound lies inside what a GPU may return (docs/numerical-variation.md: sin and cos to 0.0008
// absolute, exp2 to 2^-21 relative, log2 to 2^-21 absolute in [0.5, 2] and relative elsewhere, atan and acos to
// 4096 ulp; 3.5 ulp is at most 0.875 * 2^-21 relative), and the special values are the ones that table names:
// sin(+-0) = +-0, cos(+-0) = exp2(+-0) = 1, acos beyond [-1, 1] and log2 below 0 are NaN. The u35 functions cost
// about what glibc's float functions do for one float (4 to 5 ns here), and the same for eight; SLEEF's 1-ulp
// functions cost two to three times more.
//
// A target compiled with AVX2 and FMA (refray's default, -march=native) calls SLEEF's AVX2 functions inline from the
// lane math; any other calls transcendentals.cpp, which asks the CPU.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#include <sleef.h>
#define REFRAY_TRANSCENDENTALS_AVX2 1
#else
#define REFRAY_TRANSCENDENTALS_AVX2 0
#endif

namespace refray::procedural::math {

enum class Transcendental { Sin, Cos, Acos, Atan, Exp2, Log2 };

namespace detail {

float sleefTranscendental(Transcendental f, float x);
void sleefTranscendental8(Transcendental f, const float* in, float* out, uint32_t lanes);

// Every NaN result is this one: SLEEF's scalar and vector builds differ in the sign of some NaNs they return (acos
// beyond [-1, 1]).
inline constexpr uint32_t kNaNBits = 0x7FC00000u;

// SLEEF's sin and cos reduce their arguments one way when every lane is below 125 in magnitude and other ways (for
// every lane) when one is not, NaN and infinity included: a lane's result would depend on its neighbours. Lanes at
// or beyond this bound (below SLEEF's 125, so the vector call always takes the first way) go one by one, where each
// lane's own magnitude decides, as for one float.
inline constexpr float kSinCosVectorRange = 100.0f;

#if REFRAY_TRANSCENDENTALS_AVX2
// f of the lanes `lanes` of x through SLEEF's AVX2 functions; the other lanes compute 0 (in range for every
// function), whatever they held, and their results are unspecified.
inline __m256 sleefAvx2(Transcendental f, __m256 x, uint32_t lanes) {
    uint32_t vectorLanes = lanes & 0xFFu;
    if (f == Transcendental::Sin || f == Transcendental::Cos) {
        const __m256 magnitude = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), x);
        vectorLanes &= uint32_t(
            _mm256_movemask_ps(_mm256_cmp_ps(magnitude, _mm256_set1_ps(kSinCosVectorRange), _CMP_LT_OQ)));
    }
    const __m256i keep = _mm256_cmpgt_epi32(
        _mm256_and_si256(_mm256_set1_epi32(int(vectorLanes)), _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128)),
        _mm256_setzero_si256());
    const __m256 in = _mm256_and_ps(x, _mm256_castsi256_ps(keep));
    __m256 r;
    switch (f) {
        case Transcendental::Sin: r = Sleef_sinf8_u35avx2(in); break;
        case Transcendental::Cos: r = Sleef_cosf8_u35avx2(in); break;
        case Transcendental::Acos: r = Sleef_acosf8_u35avx2(in); break;
        case Transcendental::Atan: r = Sleef_atanf8_u35avx2(in); break;
        case Transcendental::Exp2: r = Sleef_exp2f8_u35avx2(in); break;
        default: r = Sleef_log2f8_u35avx2(in); break;
    }
    r = _mm256_blendv_ps(r, _mm256_castsi256_ps(_mm256_set1_epi32(int(kNaNBits))), _mm256_cmp_ps(r, r, _CMP_UNORD_Q));
    if (const uint32_t oneByOne = lanes & 0xFFu & ~vectorLanes) {
        alignas(32) float original[8], result[8];
        _mm256_store_ps(original, x);
        _mm256_store_ps(result, r);
        for (uint32_t rest = oneByOne; rest; rest &= rest - 1) {
            const int i = std::countr_zero(rest);
            result[i] = sleefTranscendental(f, original[i]);
        }
        r = _mm256_load_ps(result);
    }
    return r;
}
#endif

}  // namespace detail

// f(x). The results that are exact powers of two or integers (exp2 of an integer, log2 of a power of two: the fractal
// pyramid's pow(2, -n) is exp2(-n * log2(2))) are computed here, inline, so that a compiler folds them where x is a
// constant; SLEEF returns the same bits for each (tests/procedural/transcendentals_test.cpp checks every one).
inline float transcendental(Transcendental f, float x) {
    if (f == Transcendental::Exp2 && x >= -149.0f && x <= 127.0f && float(int(x)) == x)
        return std::ldexp(1.0f, int(x));
    if (f == Transcendental::Log2) {
        const uint32_t bits = std::bit_cast<uint32_t>(x);
        const uint32_t exponent = bits >> 23;  // with the sign bit: 1..254 for a positive normal float
        if ((bits & 0x7FFFFFu) == 0 && exponent >= 1 && exponent <= 254) return float(int(exponent) - 127);
    }
    return detail::sleefTranscendental(f, x);
}

// out[i] = f(in[i]) for the lanes i of the mask `lanes` (bit i: lane i of 0..7), each bit for bit
// transcendental(f, in[i]) whatever the other lanes hold; the other out[i] are unspecified. in and out may be the same.
inline void transcendental8(Transcendental f, const float* in, float* out, uint32_t lanes = 0xFFu) {
#if REFRAY_TRANSCENDENTALS_AVX2
    _mm256_storeu_ps(out, detail::sleefAvx2(f, _mm256_loadu_ps(in), lanes));
#else
    detail::sleefTranscendental8(f, in, out, lanes);
#endif
}

}  // namespace refray::procedural::math
