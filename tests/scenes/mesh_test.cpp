// Tests scenes/mesh.cpp and the scene files' "mesh" geometry on a hand-counted OBJ file.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "scenes/mesh.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {
namespace {

const std::string kData = std::string(REFRAY_SOURCE_DIR) + "/tests/scenes/data";

TEST(Mesh, ObjPolygonsAreTriangulated) {
    const TriangleMesh m = loadObjMesh(kData + "/quad-and-triangle.obj");
    ASSERT_EQ(m.positions.size(), 7u);
    EXPECT_EQ(m.positions[2], vec3(1, 0, 1));
    EXPECT_EQ(m.positions[6], vec3(0, 1, 1));
    // The quad 1 2 3 4 becomes two triangles split along its 2-4 diagonal (tinyobjloader's triangulation, same
    // winding as the quad); the triangle is (4,5,6).
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 3, 1, 2, 3, 4, 5, 6}));
}

TEST(Mesh, MissingAndBrokenFilesAreNamed) {
    try {
        loadObjMesh(kData + "/no-such.obj");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot read mesh file"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("no-such.obj"), std::string::npos) << e.what();
    }
    const std::string bad = std::string(REFRAY_TEST_OUTPUT_DIR) + "/bad-face.obj";
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nf 1 2 9\n";
    EXPECT_THROW(loadObjMesh(bad), Error);
}

TEST(Mesh, SceneGeometryFromAnObjFile) {
    // The explicit D3D12 example scene of scene_loader_test.cpp, with its triangle read from the OBJ file.
    const std::string text = R"({
      "format": "refray-scene/1", "name": "mesh", "shaderLibrary": "d3d12-procedural-geometry",
      "pipeline": {"rayGeneration": "MyRaygenShader", "maxRecursionDepth": 3, "maxPayloadBytes": 20, "maxAttributeBytes": 12},
      "rayTypes": [{"name": "Radiance", "miss": "MyMissShader", "payload": "RayPayload"},
                   {"name": "Shadow", "miss": "MyMissShader_ShadowRay", "payload": "ShadowRayPayload"}],
      "hitGroups": [{"name": "HG", "type": "triangles"}],
      "rootSignatures": {"global": {"name": "G", "parameters": []}},
      "buffers": {},
      "bottomLevel": [{"name": "m", "geometries": [{"type": "triangles", "mesh": "quad-and-triangle.obj"}]}],
      "instances": [{"name": "i", "blas": "m", "records": [{"hitGroups": {"Radiance": "HG", "Shadow": null}}]}],
      "globalArguments": {},
      "cameras": [{"name": "c", "model": "directxmath-lh", "eye": [0, 5, -5], "target": [0, 0, 0], "up": [0, 1, 0], "fovYDegrees": 45, "near": 0.01, "far": 125}],
      "light": {"position": [0, 18, -20, 0], "ambientColor": [0.25, 0.25, 0.25, 1], "diffuseColor": [0.6, 0.6, 0.6, 1]}
    })";
    const SceneDesc s = parseScene(text, kData + "/mesh-scene.json");
    const GeometryDescFile& g = s.blases[0].geometries[0];
    EXPECT_EQ(g.vertexCount, 7u);
    EXPECT_EQ(g.indexCount, 9u);
    EXPECT_EQ(g.indexFormat, dxr::Format::R32_UINT);
    std::string message;
    try {
        std::string broken = text;
        broken.replace(broken.find("quad-and-triangle.obj"), 21, "missing-mesh.obj");
        parseScene(broken, kData + "/mesh-scene.json");
    } catch (const Error& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("mesh-scene.json:9:"), std::string::npos) << message;
    EXPECT_NE(message.find("cannot read mesh file"), std::string::npos) << message;
}

}  // namespace
}  // namespace refray::scenes
