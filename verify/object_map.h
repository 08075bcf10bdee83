// The nominal's objects (issue 27): per pixel, the instance x geometry its primary ray hit, the map that the
// regional count test of an envelope golden (core/regional_count_test.h) cuts its regions from. It is one part of
// an envelope's renders ("objects"), stored as an image so that a distributed golden job can write it.
#pragma once

#include "core/image.h"
#include "core/regional_count_test.h"
#include "scenes/scene.h"

namespace refray::scenes {

// Renders the scene at `settings` and records, per pixel, the committed hit of its first primary ray (the first
// TraceRay of depth 1): objectId(InstanceIndex, GeometryIndex), -1 where it missed or none was traced. Names:
// "object 'name'" (with " geometry g" where the instance's BLAS has several geometries), "the background".
ObjectMap renderObjectMap(Scene& scene, const RenderSettings& settings);

// The map as an image (R = G = B = the id, exact in float; metadata object_names: "id=name" lines) and back. The
// inverse throws refray::Error for an image that is no object map.
Image objectMapImage(const ObjectMap& objects, uint32_t width, uint32_t height);
ObjectMap objectMapOf(const Image& image);

}  // namespace refray::scenes
