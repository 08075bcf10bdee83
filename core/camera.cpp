#include "core/camera.h"

#include <cmath>

namespace refray {

CameraRay PinholeCamera::primaryRay(uint32_t x, uint32_t y, uint32_t width, uint32_t height, vec2 jitter) const {
    const vec3 forward = glm::normalize(target - eye);
    const vec3 right = glm::normalize(glm::cross(forward, up));
    const vec3 screenUp = glm::cross(right, forward);
    const float tanHalf = std::tan(0.5f * fovYRadians);
    const float aspect = float(width) / float(height);
    const float sx = ((float(x) + jitter.x) / float(width)) * 2.0f - 1.0f;
    const float sy = -(((float(y) + jitter.y) / float(height)) * 2.0f - 1.0f);
    const vec3 d = forward + sx * tanHalf * aspect * right + sy * tanHalf * screenUp;
    return {eye, glm::normalize(d)};
}

}  // namespace refray
