#include <gtest/gtest.h>

#include "core/math.h"

using namespace refray;

TEST(Matrix3x4, TransformPointAppliesTranslationInColumnThree) {
    const Matrix3x4 m = Matrix3x4::translation({1, 2, 3}) * Matrix3x4::scale({2, 3, 4});
    EXPECT_EQ(m.transformPoint({1, 1, 1}), vec3(3, 5, 7));
    EXPECT_EQ(m.transformVector({1, 1, 1}), vec3(2, 3, 4));
}

TEST(Matrix3x4, AffineInverseUndoesARotatedScaledTranslatedTransform) {
    const Matrix3x4 m = Matrix3x4::translation({5, -3, 100}) * Matrix3x4::rotation(glm::normalize(vec3(1, 2, 3)), 0.7f) *
                        Matrix3x4::scale({100, 30, 100});
    const auto inv = affineInverse(m);
    ASSERT_TRUE(inv);
    const vec3 p{0.25f, -0.5f, 0.75f};
    const vec3 back = inv->transformPoint(m.transformPoint(p));
    EXPECT_NEAR(back.x, p.x, 1e-5);
    EXPECT_NEAR(back.y, p.y, 1e-5);
    EXPECT_NEAR(back.z, p.z, 1e-5);
}

TEST(Matrix3x4, AffineInverseRefusesSingularAndNonFiniteMatrices) {
    EXPECT_FALSE(affineInverse(Matrix3x4::scale({1, 0, 1})));
    Matrix3x4 nan = Matrix3x4::identity();
    nan.m[1][3] = std::nanf("");
    EXPECT_FALSE(affineInverse(nan));
}

TEST(Matrix3x4, TransposedIsTheFourByThreeForm) {
    Matrix3x4 m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m.m[r][c] = float(r * 10 + c);
    const auto t = transposed(m);
    EXPECT_EQ(t[3][2], 23.0f);
    EXPECT_EQ(t[0][1], 10.0f);
}
