#include "scenes/camera_models.h"

#include <cmath>

#include "core/error.h"

namespace refray::scenes {

namespace {

using glm::dvec3;
using procedural::DMat4;

// General 4x4 inverse by Gauss-Jordan elimination with partial pivoting.
DMat4 inverse(DMat4 m) {
    DMat4 inv{};
    for (int i = 0; i < 4; ++i) inv[i][i] = 1.0;
    for (int c = 0; c < 4; ++c) {
        int pivot = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::abs(m[r][c]) > std::abs(m[pivot][c])) pivot = r;
        REFRAY_CHECK(m[pivot][c] != 0.0, "the camera's view-projection matrix is singular");
        std::swap(m[c], m[pivot]);
        std::swap(inv[c], inv[pivot]);
        const double s = 1.0 / m[c][c];
        for (int j = 0; j < 4; ++j) m[c][j] *= s, inv[c][j] *= s;
        for (int r = 0; r < 4; ++r) {
            if (r == c) continue;
            const double f = m[r][c];
            for (int j = 0; j < 4; ++j) m[r][j] -= f * m[c][j], inv[r][j] -= f * inv[c][j];
        }
    }
    return inv;
}

// A view matrix in row-vector form from camera axes (x right, y up, z = the view-space axis the model uses).
DMat4 viewFromAxes(dvec3 x, dvec3 y, dvec3 z, dvec3 eye) {
    return {{{x.x, y.x, z.x, 0}, {x.y, y.y, z.y, 0}, {x.z, y.z, z.z, 0},
             {-glm::dot(x, eye), -glm::dot(y, eye), -glm::dot(z, eye), 1}}};
}

dvec3 normalized(dvec3 v, const CameraDesc& camera, const char* what) {
    const double length = glm::length(v);
    REFRAY_CHECK(length > 0.0 && std::isfinite(length),
                 "camera '" << camera.name << "': " << what << " is degenerate (eye (" << camera.eye.x << ", "
                            << camera.eye.y << ", " << camera.eye.z << "), target (" << camera.target.x << ", "
                            << camera.target.y << ", " << camera.target.z << "), up (" << camera.up.x << ", "
                            << camera.up.y << ", " << camera.up.z << "))");
    return v / length;
}

}  // namespace

std::string_view toString(CameraModel model) {
    return model == CameraModel::MiniEngine ? "miniengine" : "directxmath-lh";
}

procedural::Float4x4 projectionToWorld(const CameraDesc& camera, uint32_t width, uint32_t height) {
    REFRAY_CHECK(width > 0 && height > 0, "camera '" << camera.name << "': the image size must be positive");
    REFRAY_CHECK(camera.fovYRadians > 0.0 && camera.fovYRadians < 3.14159265358979,
                 "camera '" << camera.name << "': fovY must lie in (0, 180) degrees");
    REFRAY_CHECK(camera.nearZ > 0.0 && camera.farZ > camera.nearZ,
                 "camera '" << camera.name << "': needs 0 < near < far, got near " << camera.nearZ << ", far "
                            << camera.farZ);
    const double n = camera.nearZ, f = camera.farZ;
    const double Y = 1.0 / std::tan(0.5 * camera.fovYRadians);
    DMat4 view, projection;
    if (camera.model == CameraModel::MiniEngine) {
        // Camera.cpp: basis rows (r, u, -f); Y = 1/tan(fovY/2), X = Y·(H/W); reverse-Z: Q1 = n/(f-n), Q2 = Q1·f.
        const dvec3 forward = normalized(camera.target - camera.eye, camera, "the view direction");
        const dvec3 right = normalized(glm::cross(forward, camera.up), camera, "forward x up");
        const dvec3 up = glm::cross(right, forward);
        view = viewFromAxes(right, up, -forward, camera.eye);
        const double X = Y * (double(height) / double(width));
        const double Q1 = n / (f - n), Q2 = Q1 * f;
        projection = {{{X, 0, 0, 0}, {0, Y, 0, 0}, {0, 0, Q1, -1}, {0, 0, Q2, 0}}};
    } else {
        // XMMatrixLookAtLH: z = normalize(at - eye), x = normalize(up x z), y = z x x.
        // XMMatrixPerspectiveFovLH: h = 1/tan(fovY/2), w = h / aspect, range = f/(f-n).
        const dvec3 z = normalized(camera.target - camera.eye, camera, "the view direction");
        const dvec3 x = normalized(glm::cross(camera.up, z), camera, "up x forward");
        const dvec3 y = glm::cross(z, x);
        view = viewFromAxes(x, y, z, camera.eye);
        const double w = Y / (double(width) / double(height));
        const double range = f / (f - n);
        projection = {{{w, 0, 0, 0}, {0, Y, 0, 0}, {0, 0, range, 1}, {0, 0, -range * n, 0}}};
    }
    return procedural::toFloat4x4(inverse(procedural::multiply(view, projection)));
}

}  // namespace refray::scenes
