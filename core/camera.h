// A pinhole camera producing primary rays through pixel centres.
#pragma once

#include <cstdint>

#include "core/math.h"

namespace refray {

struct CameraRay {
    vec3 origin;
    vec3 direction;  // unit length
};

struct PinholeCamera {
    vec3 eye{0.0f, 0.0f, 5.0f};
    vec3 target{0.0f, 0.0f, 0.0f};
    vec3 up{0.0f, 1.0f, 0.0f};
    float fovYRadians = 0.7853982f;  // 45 degrees

    // Ray through the centre of pixel (x, y) of a width x height image; row 0 is the top.
    // Screen right is normalize(forward x up), screen up is right x forward (right-handed).
    CameraRay primaryRay(uint32_t x, uint32_t y, uint32_t width, uint32_t height, vec2 jitter = vec2(0.5f)) const;
};

}  // namespace refray
