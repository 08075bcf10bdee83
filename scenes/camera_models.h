// The two host camera models of the reference scenes, computed in double and rounded to float once
// (the fact sheets' rule): every back end receives the same 16 floats of projectionToWorld.
#pragma once

#include <cstdint>
#include <string>

#include "core/math.h"
#include "procedural/sample_layout.h"

namespace refray::scenes {

enum class CameraModel {
    // MiniEngine (Proceduray): right-handed view space, basis rows (r, u, -f) with f = normalize(target - eye),
    // r = normalize(f x up), u = r x f; reverse-Z perspective; aspect passed as height / width.
    MiniEngine,
    // DirectXMath (Microsoft sample): XMMatrixLookAtLH and XMMatrixPerspectiveFovLH with aspect width / height.
    DirectXMathLH,
};

std::string_view toString(CameraModel model);

struct CameraDesc {
    std::string name;
    CameraModel model = CameraModel::MiniEngine;
    glm::dvec3 eye{0, 0, 1};
    glm::dvec3 target{0, 0, 0};
    glm::dvec3 up{0, 1, 0};
    double fovYRadians = 0.78539816339744831;
    double nearZ = 0.01;
    double farZ = 125.0;
};

// inverse(view · projection) in row-vector form (the HLSL /Zpr layout the shaders read), for a width x height
// dispatch. Throws refray::Error when the camera is degenerate (eye on target, up parallel to the view).
procedural::Float4x4 projectionToWorld(const CameraDesc& camera, uint32_t width, uint32_t height);

}  // namespace refray::scenes
