// Tests procedural/math/hlsl.h and procedural/math/ray.h: the DXC intrinsic semantics.
#include "procedural/math/hlsl.h"

#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include "procedural/math/ray.h"

namespace refray::procedural {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// ---- saturate / clamp / min / max -------------------------------------------------------------
TEST(HlslSaturate, NaNGivesZero) {
    EXPECT_EQ(hlsl::saturate(kNaN), 0.0f);
    EXPECT_EQ(hlsl::saturate(std::numeric_limits<double>::quiet_NaN()), 0.0);
}

TEST(HlslSaturate, ClampsToUnitInterval) {
    EXPECT_EQ(hlsl::saturate(-2.0f), 0.0f);
    EXPECT_EQ(hlsl::saturate(0.25f), 0.25f);
    EXPECT_EQ(hlsl::saturate(7.0f), 1.0f);
    EXPECT_EQ(hlsl::saturate(kInf), 1.0f);
    EXPECT_EQ(hlsl::saturate(-kInf), 0.0f);
}

TEST(HlslMinMax, NaNOperandIsIgnored) {
    EXPECT_EQ(hlsl::min(kNaN, 3.0f), 3.0f);
    EXPECT_EQ(hlsl::min(3.0f, kNaN), 3.0f);
    EXPECT_EQ(hlsl::max(kNaN, -3.0f), -3.0f);
    EXPECT_EQ(hlsl::max(-3.0f, kNaN), -3.0f);
    EXPECT_TRUE(std::isnan(hlsl::max(kNaN, kNaN)));
}

TEST(HlslClamp, NaNGivesLowerBoundAndBoundsApply) {
    EXPECT_EQ(hlsl::clamp(kNaN, 0.2f, 0.8f), 0.2f);
    EXPECT_EQ(hlsl::clamp(0.5f, 0.2f, 0.8f), 0.5f);
    EXPECT_EQ(hlsl::clamp(-1.0f, 0.2f, 0.8f), 0.2f);
    EXPECT_EQ(hlsl::clamp(9.0f, 0.2f, 0.8f), 0.8f);
}

TEST(HlslMinMax, VectorFormsAreComponentWiseAndIgnoreNaN) {
    const glm::vec3 a(1.0f, kNaN, -2.0f);
    const glm::vec3 b(0.0f, 5.0f, kNaN);
    EXPECT_EQ(hlsl::max(a, b), glm::vec3(1.0f, 5.0f, -2.0f));
    EXPECT_EQ(hlsl::min(a, b), glm::vec3(0.0f, 5.0f, -2.0f));
    EXPECT_EQ(hlsl::max(glm::vec3(-1.0f, 2.0f, kNaN), 0.0f), glm::vec3(0.0f, 2.0f, 0.0f));
    EXPECT_EQ(hlsl::saturate(glm::vec2(kNaN, 3.0f)), glm::vec2(0.0f, 1.0f));
}

// ---- lerp / step / smoothstep / frac ------------------------------------------------------------
TEST(HlslLerp, IsAPlusSTimesBMinusA) {
    EXPECT_EQ(hlsl::lerp(2.0f, 6.0f, 0.25f), 3.0f);
    EXPECT_EQ(hlsl::lerp(2.0f, 6.0f, -0.5f), 0.0f);  // extrapolates, as colorSurface's lerp(.., -0.4)
    EXPECT_EQ(hlsl::lerp(glm::vec3(0.0f), glm::vec3(4.0f, 8.0f, -4.0f), 0.5f), glm::vec3(2.0f, 4.0f, -2.0f));
}

TEST(HlslStep, IsXGreaterOrEqualA) {
    EXPECT_EQ(hlsl::step(0.0f, 0.0f), 1.0f);
    EXPECT_EQ(hlsl::step(0.0f, -0.0f), 1.0f);
    EXPECT_EQ(hlsl::step(0.0f, -1e-30f), 0.0f);
    EXPECT_EQ(hlsl::step(0.0f, kNaN), 0.0f);
}

TEST(HlslSmoothstep, CubicOnSaturatedRamp) {
    EXPECT_EQ(hlsl::smoothstep(0.0f, 1.0f, 0.5f), 0.5f);
    EXPECT_EQ(hlsl::smoothstep(14.0f, 15.0f, 13.0f), 0.0f);
    EXPECT_EQ(hlsl::smoothstep(14.0f, 15.0f, 16.0f), 1.0f);
    EXPECT_FLOAT_EQ(hlsl::smoothstep(0.0f, 2.0f, 0.5f), 0.25f * 0.25f * (3.0f - 0.5f));
    EXPECT_EQ(hlsl::smoothstep(14.0f, 15.0f, kNaN), 0.0f);  // saturate(NaN) = 0
}

TEST(HlslFrac, IsXMinusFloorX) {
    EXPECT_EQ(hlsl::frac(1.75f), 0.75f);
    EXPECT_EQ(hlsl::frac(-0.25f), 0.75f);
    EXPECT_EQ(hlsl::frac(3.0f), 0.0f);
}

// ---- atan2 ------------------------------------------------------------------------------------
TEST(HlslAtan2, ZeroZeroIsHalfPi) {
    EXPECT_FLOAT_EQ(hlsl::atan2(0.0f, 0.0f), std::numbers::pi_v<float> / 2);
    EXPECT_DOUBLE_EQ(hlsl::atan2(0.0, 0.0), std::numbers::pi / 2);
    // libm says pi for atan2(+0, -0); DXC treats -0 as x == 0.
    EXPECT_FLOAT_EQ(hlsl::atan2(0.0f, -0.0f), std::numbers::pi_v<float> / 2);
}

TEST(HlslAtan2, AxisCorrections) {
    const float pi = std::numbers::pi_v<float>;
    EXPECT_FLOAT_EQ(hlsl::atan2(1.0f, 0.0f), pi / 2);
    EXPECT_FLOAT_EQ(hlsl::atan2(-1.0f, 0.0f), -pi / 2);
    EXPECT_FLOAT_EQ(hlsl::atan2(0.0f, -1.0f), pi);
    EXPECT_FLOAT_EQ(hlsl::atan2(1.0f, -1.0f), 3 * pi / 4);
    EXPECT_FLOAT_EQ(hlsl::atan2(-1.0f, -1.0f), -3 * pi / 4);
    EXPECT_FLOAT_EQ(hlsl::atan2(-1.0f, 1.0f), -pi / 4);
}

TEST(HlslAtan2, MatchesLibmAwayFromTheYAxis) {
    for (int i = 0; i < 64; ++i) {
        const double ang = -3.1 + 6.2 * i / 63.0;
        const double x = std::cos(ang) * 2.5;
        const double y = std::sin(ang) * 2.5;
        if (std::abs(x) < 1e-6) continue;
        EXPECT_NEAR(hlsl::atan2(y, x), std::atan2(y, x), 1e-12) << "angle " << ang;
        EXPECT_NEAR(hlsl::atan2(static_cast<float>(y), static_cast<float>(x)), std::atan2(y, x), 2e-6)
            << "angle " << ang;
    }
}

// ---- pow / log / exp --------------------------------------------------------------------------
TEST(HlslPow, IsExp2OfYLog2X) {
    EXPECT_EQ(hlsl::pow(2.0f, 10.0f), 1024.0f);
    EXPECT_EQ(hlsl::pow(0.0f, 3.0f), 0.0f);               // exp2(-inf) = 0
    EXPECT_TRUE(std::isnan(hlsl::pow(0.0f, 0.0f)));       // 0 * -inf
    EXPECT_TRUE(std::isnan(hlsl::pow(-2.0f, 2.0f)));      // log2 of a negative number
    EXPECT_NEAR(hlsl::pow(0.7, 8.0), 0.05764801, 1e-12);
}

TEST(HlslLog, IsLog2TimesLn2) {
    EXPECT_EQ(hlsl::log(1.0f), 0.0f);
    EXPECT_EQ(hlsl::log(0.0f), -kInf);
    EXPECT_TRUE(std::isnan(hlsl::log(-1.0f)));
    EXPECT_NEAR(hlsl::log(std::numbers::e), 1.0, 1e-15);
    EXPECT_NEAR(hlsl::log(256.0f), 8.0f * std::numbers::ln2_v<float>, 1e-6f);
    EXPECT_NEAR(hlsl::exp(1.0), std::numbers::e, 1e-14);
}

// ---- fmod (intrinsic) and % (operator) --------------------------------------------------------
TEST(HlslFmod, KeepsTheSignOfTheDividend) {
    EXPECT_FLOAT_EQ(hlsl::fmod(5.5f, 2.0f), 1.5f);
    EXPECT_FLOAT_EQ(hlsl::fmod(-5.5f, 2.0f), -1.5f);
    EXPECT_FLOAT_EQ(hlsl::fmod(5.5f, -2.0f), 1.5f);
    EXPECT_FLOAT_EQ(hlsl::fmod(-5.5f, -2.0f), -1.5f);
    EXPECT_FLOAT_EQ(hlsl::fmod(-0.3f, 1.0f), -0.3f);
}

TEST(HlslFmod, DxcLoweringDiffersFromFmodfAtCellBoundary) {
    // D3D12 fact sheet §2.12: 1/0.05f rounds to exactly 20, so frac gives 0.
    EXPECT_EQ(hlsl::fmod(1.0f, 0.05f), 0.0f);
    EXPECT_NEAR(hlsl::frem(1.0f, 0.05f), 0.05f, 1e-6f);
    EXPECT_NEAR(std::fmod(1.0f, 0.05f), 0.05f, 1e-6f);
}

TEST(HlslFrem, FloatPercentIntTruncatesTowardsZero) {
    EXPECT_EQ(hlsl::fremToInt(128.5f, 256), 128);
    EXPECT_EQ(hlsl::fremToInt(300.75f, 256), 44);
    EXPECT_EQ(hlsl::fremToInt(599.99f, 600), 599);
    EXPECT_EQ(hlsl::fremToInt(-3.5f, 256), -3);  // sign of the dividend, truncation
    EXPECT_EQ(hlsl::frem(-7.0f, 3.0f), -1.0f);
}

// ---- vector helpers ---------------------------------------------------------------------------
TEST(HlslNormalize, ZeroVectorGivesNaN) {
    const glm::vec3 n = hlsl::normalize(glm::vec3(0.0f));
    EXPECT_TRUE(std::isnan(n.x) && std::isnan(n.y) && std::isnan(n.z));
}

TEST(HlslNormalize, ScalesToUnitLength) {
    const glm::dvec3 n = hlsl::normalize(glm::dvec3(3.0, 4.0, 0.0));
    EXPECT_NEAR(n.x, 0.6, 1e-15);
    EXPECT_NEAR(n.y, 0.8, 1e-15);
    EXPECT_EQ(n.z, 0.0);
    EXPECT_EQ(hlsl::length(glm::vec3(3.0f, 4.0f, 12.0f)), 13.0f);
}

TEST(HlslReflect, MirrorsAboutTheNormal) {
    EXPECT_EQ(hlsl::reflect(glm::vec3(1.0f, -1.0f, 0.0f), glm::vec3(0.0f, 1.0f, 0.0f)), glm::vec3(1.0f, 1.0f, 0.0f));
    EXPECT_EQ(hlsl::reflect(glm::vec3(0.0f, 0.0f, -2.0f), glm::vec3(0.0f, 0.0f, 1.0f)), glm::vec3(0.0f, 0.0f, 2.0f));
}

TEST(HlslDot, IsSumOfProducts) {
    EXPECT_EQ(hlsl::dot(glm::vec4(1, 2, 3, 4), glm::vec4(5, 6, 7, 8)), 70.0f);
}

// ---- float vs double ---------------------------------------------------------------------------
TEST(HlslPrecision, FloatAgreesWithDoubleWithinOneE5Relative) {
    for (int i = 1; i < 50; ++i) {
        const double x = 0.037 * i;
        const float xf = static_cast<float>(x);
        EXPECT_NEAR(hlsl::pow(xf, 7.0f), hlsl::pow(static_cast<double>(xf), 7.0), 1e-5 * hlsl::pow(x, 7.0) + 1e-30);
        EXPECT_NEAR(hlsl::log(xf), hlsl::log(static_cast<double>(xf)), 1e-6);
        EXPECT_NEAR(hlsl::smoothstep(0.0f, 1.8f, xf), hlsl::smoothstep(0.0, 1.8, static_cast<double>(xf)), 1e-6);
    }
}

// ---- denormals (H18) ----------------------------------------------------------------------------
TEST(ScopedFlushDenormals, FlushesDenormalResultsAndInputsThenRestores) {
    if (!hlsl::ScopedFlushDenormals::active()) GTEST_SKIP() << "no MXCSR on this target";
    volatile float tiny = 1e-38f;
    volatile float scale = 1e-3f;
    volatile float denormal = 1e-41f;
    volatile float one = 1.0f;
    const float before = tiny * scale;
    EXPECT_NE(before, 0.0f);
    EXPECT_EQ(std::fpclassify(before), FP_SUBNORMAL);
    {
        hlsl::ScopedFlushDenormals ftz;
        const float flushed = tiny * scale;  // FTZ: a denormal result becomes 0
        EXPECT_EQ(flushed, 0.0f);
        const float dazed = denormal * one;  // DAZ: a denormal input reads as 0
        EXPECT_EQ(dazed, 0.0f);
        {
            hlsl::ScopedFlushDenormals nested;
            EXPECT_EQ(tiny * scale, 0.0f);
        }
        EXPECT_EQ(tiny * scale, 0.0f);  // the nested scope restored "on", not "off"
    }
    const float after = tiny * scale;
    EXPECT_EQ(after, before);
}

// ---- ray.h ------------------------------------------------------------------------------------
TEST(RayHelpers, IsAValidHitIsInclusiveAndRespectsCulling) {
    using namespace math;
    const Ray<float> ray{glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, 1.0f)};
    RayExtent<float> extent{0.0f, 10.0f, true, false};
    EXPECT_TRUE(IsAValidHit(ray, 0.0f, glm::vec3(0, 0, -1), extent));
    EXPECT_TRUE(IsAValidHit(ray, 10.0f, glm::vec3(0, 0, -1), extent));
    EXPECT_FALSE(IsAValidHit(ray, 10.5f, glm::vec3(0, 0, -1), extent));
    EXPECT_FALSE(IsAValidHit(ray, kNaN, glm::vec3(0, 0, -1), extent));
    EXPECT_FALSE(IsAValidHit(ray, 5.0f, glm::vec3(0, 0, 1), extent));  // back face culled
    EXPECT_TRUE(IsAValidHit(ray, 5.0f, glm::vec3(1, 0, 0), extent));   // grazing: dot = 0
    // A NaN normal is never culled (comparisons are false).
    EXPECT_TRUE(IsAValidHit(ray, 5.0f, glm::vec3(kNaN), extent));
    extent.cullBackFacing = false;
    extent.cullFrontFacing = true;
    EXPECT_FALSE(IsAValidHit(ray, 5.0f, glm::vec3(0, 0, -1), extent));
    EXPECT_TRUE(IsAValidHit(ray, 5.0f, glm::vec3(0, 0, 1), extent));
}

TEST(RayHelpers, AnimationInterpolantIsSmoothTriangleWave) {
    using math::CalculateAnimationInterpolant;
    EXPECT_EQ(CalculateAnimationInterpolant(0.0f, 12.0f), 0.0f);
    EXPECT_EQ(CalculateAnimationInterpolant(6.0f, 12.0f), 1.0f);
    EXPECT_EQ(CalculateAnimationInterpolant(3.0f, 12.0f), 0.5f);   // v = 0.5, smoothstep(0.5) = 0.5
    EXPECT_EQ(CalculateAnimationInterpolant(12.0f, 12.0f), 0.0f);  // full cycle
    EXPECT_NEAR(CalculateAnimationInterpolant(9.0, 12.0), 0.5, 1e-15);
}

}  // namespace
}  // namespace refray::procedural
