// Math shared by every layer: GLM vectors and DXR's row-major 3x4 affine transforms.
#pragma once

#include <array>
#include <cmath>
#include <optional>

#include <glm/glm.hpp>

namespace refray {

using glm::dvec3;
using glm::ivec2;
using glm::uvec2;
using glm::uvec3;
using glm::vec2;
using glm::vec3;
using glm::vec4;

// A DXR 3x4 transform: row-major, m[row][col], translation in column 3.
// world = M * [x y z 1]^T (INST-2). Stored as 12 floats so ObjectToWorld3x4() is bit-exact.
struct Matrix3x4 {
    std::array<std::array<float, 4>, 3> m{};

    static Matrix3x4 identity();
    static Matrix3x4 translation(vec3 t);
    static Matrix3x4 scale(vec3 s);
    // Rotation about a unit axis by `radians`, right-handed, applied to column vectors.
    static Matrix3x4 rotation(vec3 axis, float radians);

    // Inline: every candidate of every ray takes its instance's object-space ray through them.
    vec3 transformPoint(vec3 p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    vec3 transformVector(vec3 v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    bool allFinite() const;
    // Determinant of the 3x3 part, in double.
    double determinant3x3() const;
    // this * other as 4x4 affine matrices (other applied first).
    Matrix3x4 operator*(const Matrix3x4& other) const;
    bool operator==(const Matrix3x4&) const = default;
};

// Affine inverse computed in double and rounded to float once (INST-2).
// Empty when the 3x3 part is singular or any entry is not finite.
std::optional<Matrix3x4> affineInverse(const Matrix3x4& m);

// Transpose of the 3x4 as a 4x3 (ObjectToWorld4x3 and friends).
std::array<std::array<float, 3>, 4> transposed(const Matrix3x4& m);

inline bool allFinite(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool anyNaN(vec3 v) { return std::isnan(v.x) || std::isnan(v.y) || std::isnan(v.z); }

}  // namespace refray
