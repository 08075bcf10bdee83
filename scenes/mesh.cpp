#include "scenes/mesh.h"

#include <cmath>
#include <string>

#include <tiny_obj_loader.h>

#include "core/error.h"

namespace refray::scenes {

TriangleMesh loadObjMesh(const std::filesystem::path& path) {
    REFRAY_CHECK(std::filesystem::is_regular_file(path), "cannot read mesh file " << path.string() << ": no such file");
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    config.mtl_search_path = path.parent_path().string();
    tinyobj::ObjReader reader;
    const bool ok = reader.ParseFromFile(path.string(), config);
    std::string message = reader.Error();
    while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
    REFRAY_CHECK(ok && message.empty(), "cannot parse mesh file " << path.string() << ": "
                                                                  << (message.empty() ? "unknown error" : message));

    TriangleMesh mesh;
    const std::vector<tinyobj::real_t>& v = reader.GetAttrib().vertices;
    for (size_t i = 0; i + 2 < v.size(); i += 3) {
        mesh.positions.emplace_back(float(v[i]), float(v[i + 1]), float(v[i + 2]));
        REFRAY_CHECK(allFinite(mesh.positions.back()),
                     "mesh file " << path.string() << ": vertex " << (i / 3 + 1) << " is not finite");
    }
    for (const tinyobj::shape_t& shape : reader.GetShapes())
        for (size_t f = 0, offset = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
            const unsigned n = shape.mesh.num_face_vertices[f];
            REFRAY_CHECK(n == 3, "mesh file " << path.string() << ": face " << (f + 1) << " of shape '" << shape.name
                                              << "' has " << n << " vertices after triangulation");
            for (unsigned k = 0; k < 3; ++k) {
                const int index = shape.mesh.indices[offset + k].vertex_index;
                REFRAY_CHECK(index >= 0 && size_t(index) < mesh.positions.size(),
                             "mesh file " << path.string() << ": face " << (f + 1) << " of shape '" << shape.name
                                          << "' refers to vertex " << (index + 1) << " of "
                                          << mesh.positions.size());
                mesh.indices.push_back(uint32_t(index));
            }
            offset += n;
        }
    REFRAY_CHECK(!mesh.indices.empty(), "mesh file " << path.string() << " holds no triangle");
    return mesh;
}

}  // namespace refray::scenes
