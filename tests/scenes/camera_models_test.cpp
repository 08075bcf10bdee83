// Tests scenes/camera_models.cpp against the fact sheets' check values (Proceduray §2.2, D3D12 §6).
#include <gtest/gtest.h>

#include "core/error.h"
#include "procedural/sample_layout.h"
#include "scenes/camera_models.h"

namespace refray::scenes {
namespace {

void expectRow(const procedural::Float4x4& m, int row, std::array<double, 4> expected, double tolerance) {
    for (int j = 0; j < 4; ++j)
        EXPECT_NEAR(m.m[size_t(row)][size_t(j)], expected[size_t(j)], tolerance * std::max(1.0, std::abs(expected[size_t(j)])))
            << "row " << row << " column " << j;
}

glm::vec3 direction(const procedural::Float4x4& m, const CameraDesc& c, uint32_t x, uint32_t y) {
    glm::vec3 origin, dir;
    procedural::GenerateCameraRay<float>({x, y}, {1280, 720}, glm::vec3(c.eye), m, origin, dir);
    return dir;
}

TEST(CameraModels, MiniEngineSampleDefaultCameraMatchesTheFactSheet) {
    // Proceduray §2.3: eye (0,0,50), at 0, up = normalize(cross(normalize(at - eye), (1,0,0))) = (0,-1,0).
    CameraDesc c;
    c.model = CameraModel::MiniEngine;
    c.eye = {0, 0, 50};
    c.target = {0, 0, 0};
    c.up = {0, -1, 0};
    c.fovYRadians = 3.14159265359 / 4;
    const procedural::Float4x4 m = projectionToWorld(c, 1280, 720);
    expectRow(m, 0, {-0.7363797, 0, 0, 0}, 1e-6);
    expectRow(m, 1, {0, -0.4142136, 0, 0}, 1e-6);
    expectRow(m, 2, {0, 0, 4999.6, 99.992}, 1e-6);
    expectRow(m, 3, {0, 0, -0.6, 0.008}, 1e-5);
    const glm::vec3 d00 = direction(m, c, 0, 0), dc = direction(m, c, 640, 360);
    EXPECT_NEAR(d00.x, 0.562272f, 2e-6f);
    EXPECT_NEAR(d00.y, -0.316086f, 2e-6f);
    EXPECT_NEAR(d00.z, -0.764160f, 2e-6f);
    EXPECT_NEAR(dc.x, -0.000575f, 2e-6f);
    EXPECT_NEAR(dc.y, 0.000575f, 2e-6f);
    EXPECT_NEAR(dc.z, -0.9999997f, 2e-6f);
}

TEST(CameraModels, DirectXMathSampleCameraMatchesTheFactSheet) {
    // D3D12 §1.6 after the 45° rotation about y.
    CameraDesc c;
    c.model = CameraModel::DirectXMathLH;
    c.eye = {-12.020815, 5.3, -12.020815};
    c.target = {0, 0, 0};
    c.up = {0.210460, 0.954680, 0.210460};
    const procedural::Float4x4 m = projectionToWorld(c, 1280, 720);
    expectRow(m, 0, {0.5206991, 0, -0.5206991, 0}, 1e-4);
    expectRow(m, 1, {0.08717539, 0.3954412, 0.08717539, 0}, 1e-4);
    expectRow(m, 2, {1201.985, -529.9576, 1201.985, -99.992}, 1e-4);
    expectRow(m, 3, {-1201.406, 529.7024, -1201.406, 100}, 1e-4);
    const glm::vec3 d00 = direction(m, c, 0, 0), dc = direction(m, c, 640, 360), d11 = direction(m, c, 1279, 719);
    EXPECT_NEAR(d00.x, 0.184791f, 1e-4f);
    EXPECT_NEAR(d00.y, 0.074320f, 1e-4f);
    EXPECT_NEAR(d00.z, 0.979964f, 1e-4f);
    EXPECT_NEAR(dc.x, 0.675346f, 1e-4f);
    EXPECT_NEAR(dc.y, -0.298185f, 1e-4f);
    EXPECT_NEAR(d11.z, 0.051744f, 1e-4f);
}

TEST(CameraModels, DegenerateCamerasAreClearErrors) {
    CameraDesc c;
    c.name = "bad";
    c.eye = {0, 0, 0};
    c.target = {0, 0, 0};
    try {
        projectionToWorld(c, 64, 64);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("camera 'bad': the view direction is degenerate"), std::string::npos)
            << e.what();
    }
    c.target = {0, 1, 0};
    c.up = {0, 2, 0};
    EXPECT_THROW(projectionToWorld(c, 64, 64), Error);
    c.up = {1, 0, 0};
    c.farZ = c.nearZ;
    EXPECT_THROW(projectionToWorld(c, 64, 64), Error);
}

}  // namespace
}  // namespace refray::scenes
