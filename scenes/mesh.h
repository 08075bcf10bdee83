// Triangle meshes from Wavefront OBJ files (tinyobjloader), for scene-file geometry.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/math.h"

namespace refray::scenes {

struct TriangleMesh {
    std::vector<vec3> positions;
    std::vector<uint32_t> indices;  // a triangle list: every shape of the file, polygons triangulated
};

// Throws refray::Error naming the file (and tinyobjloader's line-numbered message) when it cannot be read or
// parsed, when a face refers to a vertex that does not exist, or when the file holds no triangle.
TriangleMesh loadObjMesh(const std::filesystem::path& path);

}  // namespace refray::scenes
