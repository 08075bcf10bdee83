// Stability across build modes (issue 6): the optimised build must round exactly as the debug build does.
//
// GCC 12.2 at -O2 and -O3 miscompiles double(float(x)) for a pair of components that its SLP vectorizer has put in
// one vector: value numbering (FRE) folds the vector conversions (vector(2) double)(vector(2) float) v back to v,
// because the precision it compares is that of the vector types, not of their elements. The float stays
// correct; only its widened copy keeps the unrounded double. refray's tests build every float ray's exact double
// twin that way (tests/procedural/sweep_support.h: rayPair), so the release build's oracle runs saw other rays
// than the float runs. cmake/RefrayCompilerWorkarounds.cmake turns the SLP vectorizer off for GCC; this test fails
// if that protection goes (docs/numerical-stability.md, "A note on build modes").
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>

namespace refray {
namespace {

// Not a constant, so that the compiler cannot fold the conversions at compile time.
volatile double gScale = 1e-3;

struct Twin {
    glm::vec3 f;
    glm::dvec3 d;
};

// Keeps both copies alive in memory, as a RayPair does.
__attribute__((noinline)) Twin keep(const glm::vec3& f, const glm::dvec3& d) { return {f, d}; }

// True when x is a float's value: the low 29 bits of a double's significand are zero.
bool isAFloatValue(double x) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof bits);
    return (bits & ((std::uint64_t(1) << 29) - 1)) == 0;
}

TEST(BuildMode, TheDoubleTwinOfAFloatVectorIsRounded) {
    const double scale = gScale;
    const glm::vec3 f = glm::vec3(scale * glm::dvec3(0.3, 0.5, -0.8));
    const glm::dvec3 d = glm::dvec3(f);
    const Twin t = keep(f, d);
    for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(isAFloatValue(t.d[i])) << "component " << i << " = " << t.d[i]
                                           << ": double(float(x)) was folded to x (GCC's SLP conversion fold)";
        EXPECT_EQ(t.d[i], double(t.f[i])) << "component " << i;
    }
}

}  // namespace
}  // namespace refray
