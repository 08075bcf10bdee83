#include "core/math.h"

namespace refray {

Matrix3x4 Matrix3x4::identity() {
    Matrix3x4 r;
    r.m[0] = {1, 0, 0, 0};
    r.m[1] = {0, 1, 0, 0};
    r.m[2] = {0, 0, 1, 0};
    return r;
}

Matrix3x4 Matrix3x4::translation(vec3 t) {
    Matrix3x4 r = identity();
    r.m[0][3] = t.x;
    r.m[1][3] = t.y;
    r.m[2][3] = t.z;
    return r;
}

Matrix3x4 Matrix3x4::scale(vec3 s) {
    Matrix3x4 r;
    r.m[0] = {s.x, 0, 0, 0};
    r.m[1] = {0, s.y, 0, 0};
    r.m[2] = {0, 0, s.z, 0};
    return r;
}

Matrix3x4 Matrix3x4::rotation(vec3 axis, float radians) {
    const double c = std::cos(double(radians)), s = std::sin(double(radians)), t = 1.0 - c;
    const double x = axis.x, y = axis.y, z = axis.z;
    Matrix3x4 r;
    r.m[0] = {float(t * x * x + c), float(t * x * y - s * z), float(t * x * z + s * y), 0};
    r.m[1] = {float(t * x * y + s * z), float(t * y * y + c), float(t * y * z - s * x), 0};
    r.m[2] = {float(t * x * z - s * y), float(t * y * z + s * x), float(t * z * z + c), 0};
    return r;
}

bool Matrix3x4::allFinite() const {
    for (const auto& row : m)
        for (float v : row)
            if (!std::isfinite(v)) return false;
    return true;
}

double Matrix3x4::determinant3x3() const {
    const auto a = [&](int r, int c) { return double(m[r][c]); };
    return a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
           a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
}

Matrix3x4 Matrix3x4::operator*(const Matrix3x4& o) const {
    Matrix3x4 r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
            double sum = j == 3 ? double(m[i][3]) : 0.0;
            for (int k = 0; k < 3; ++k) sum += double(m[i][k]) * double(o.m[k][j]);
            r.m[i][j] = float(sum);
        }
    }
    return r;
}

std::optional<Matrix3x4> affineInverse(const Matrix3x4& m) {
    if (!m.allFinite()) return std::nullopt;
    const double det = m.determinant3x3();
    if (det == 0.0 || !std::isfinite(det)) return std::nullopt;
    const auto a = [&](int r, int c) { return double(m.m[r][c]); };
    double inv[3][3];
    inv[0][0] = (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) / det;
    inv[0][1] = (a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2)) / det;
    inv[0][2] = (a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)) / det;
    inv[1][0] = (a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2)) / det;
    inv[1][1] = (a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0)) / det;
    inv[1][2] = (a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)) / det;
    inv[2][0] = (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0)) / det;
    inv[2][1] = (a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1)) / det;
    inv[2][2] = (a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)) / det;
    Matrix3x4 r;
    for (int i = 0; i < 3; ++i) {
        double t = 0.0;
        for (int k = 0; k < 3; ++k) {
            r.m[i][k] = float(inv[i][k]);
            t -= inv[i][k] * a(k, 3);
        }
        r.m[i][3] = float(t);
    }
    if (!r.allFinite()) return std::nullopt;
    return r;
}

std::array<std::array<float, 3>, 4> transposed(const Matrix3x4& m) {
    std::array<std::array<float, 3>, 4> t{};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) t[c][r] = m.m[r][c];
    return t;
}

}  // namespace refray
