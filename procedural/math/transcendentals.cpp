// Compiled with AVX2 and FMA whatever the target (procedural/CMakeLists.txt), so that a target without them still
// has the AVX2 path (detail::sleefAvx2), taken where the CPU has both.
#include "procedural/math/transcendentals.h"

#if !REFRAY_TRANSCENDENTALS_AVX2
#error "transcendentals.cpp must be compiled with -mavx2 -mfma"
#endif

namespace refray::procedural::math {

namespace {

// Indexed by Transcendental.
constexpr decltype(&Sleef_sinf1_u35purecfma) kOne[] = {
    Sleef_sinf1_u35purecfma,  Sleef_cosf1_u35purecfma,  Sleef_acosf1_u35purecfma,
    Sleef_atanf1_u35purecfma, Sleef_exp2f1_u35purecfma, Sleef_log2f1_u35purecfma};
static_assert(sizeof(kOne) / sizeof(kOne[0]) == int(Transcendental::Log2) + 1);

// Asked once, when the program starts. A call before that (from another file's static initialiser) takes the scalar
// path, which gives the same numbers.
const bool kHasAvx2AndFma = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");

}  // namespace

float detail::sleefTranscendental(Transcendental f, float x) {
    const float r = kOne[int(f)](x);
    return r == r ? r : std::bit_cast<float>(kNaNBits);
}

void detail::sleefTranscendental8(Transcendental f, const float* in, float* out, uint32_t lanes) {
    if (kHasAvx2AndFma) {
        _mm256_storeu_ps(out, sleefAvx2(f, _mm256_loadu_ps(in), lanes));
        return;
    }
    for (int i = 0; i < 8; ++i)
        if (lanes >> i & 1u) out[i] = transcendental(f, in[i]);
}

}  // namespace refray::procedural::math
