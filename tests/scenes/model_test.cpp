// Tests scenes/model.cpp, scenes/model_buffers.cpp and scenes/asset_generator.cpp: hand-written OBJ and MTL files
// (the tests write them) with hand-counted answers, and the generated assets of scenes/cornell-box and
// scenes/textured-room.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>

#include "core/error.h"
#include "core/image.h"
#include "scenes/asset_generator.h"
#include "scenes/model.h"
#include "scenes/model_buffers.h"
#include "tests/error_of.h"

namespace refray::scenes {
namespace {

namespace fs = std::filesystem;

const fs::path kScenes = fs::path(REFRAY_SOURCE_DIR) / "scenes";

// A fresh folder of the test output for one test's files.
fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::path(REFRAY_TEST_OUTPUT_DIR) / "model" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

fs::path writeFile(const fs::path& path, const std::string& text) {
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

std::string readBytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

using refray::testing::errorOf;

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// ---- Hand-written files ------------------------------------------------------------------------------------------

// Four corners of the unit square; the third triangle reuses v3 with another texcoord.
const char* kSharedCornersObj = R"(v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 0.5 0.25
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
f 3/5/1 4/4/1 2/2/1
)";

// Four materials in a library one folder down, three of them used, plus faces before any usemtl.
const char* kMaterialsMtl = R"(newmtl unused
Kd 0.1 0.1 0.1

newmtl plain
Kd 0.5 0.25 0.125
Ks 0.2 0.2 0.2
Ns 98

newmtl glowing
Kd 0 0 0
Ke 4 3 2

newmtl textured
Kd 1 1 1
map_Kd textures/albedo.png
norm textures/normal.png
)";

const char* kMaterialsObj = R"(mtllib materials/lib.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3
usemtl textured
f 1 3 4
usemtl plain
f 1 2 4
usemtl glowing
f 2 3 4
usemtl plain
f 2 4 3
)";

// The materials model: obj/materials.obj, obj/materials/lib.mtl and its two (dummy) texture files.
fs::path writeMaterialsModel(const fs::path& dir) {
    writeFile(dir / "materials" / "lib.mtl", kMaterialsMtl);
    writeFile(dir / "materials" / "textures" / "albedo.png", "not read by the loader");
    writeFile(dir / "materials" / "textures" / "normal.png", "not read by the loader");
    return writeFile(dir / "materials.obj", kMaterialsObj);
}

TEST(Model, SharedCornersAreDeduplicated) {
    const fs::path dir = freshDir("shared-corners");
    const Model m = loadObjModel(writeFile(dir / "square.obj", kSharedCornersObj));
    EXPECT_EQ(m.name, "square");
    // (1,1,1) (2,2,1) (3,3,1) (4,4,1) are new in the first two triangles; (3,5,1) is new, (4,4,1) and (2,2,1) are not.
    ASSERT_EQ(m.vertices.size(), 5u);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 4, 3, 1}));
    EXPECT_EQ(m.vertices[2].position, vec3(1, 1, 0));
    EXPECT_EQ(m.vertices[4].position, vec3(1, 1, 0));
    // Texcoords in the D3D convention: (u, 1 - v).
    EXPECT_EQ(m.vertices[0].texcoord, vec2(0, 1));
    EXPECT_EQ(m.vertices[2].texcoord, vec2(1, 0));
    EXPECT_EQ(m.vertices[4].texcoord, vec2(0.5f, 0.75f));
    for (const ModelVertex& v : m.vertices) {
        EXPECT_EQ(v.normal, vec3(0, 0, 1));
        EXPECT_EQ(v.tangent, vec4(0.0f));  // no normal map: no tangents
    }
    EXPECT_FALSE(m.hasTangents);
    // No usemtl: every triangle uses the default material.
    ASSERT_EQ(m.materials.size(), 1u);
    EXPECT_EQ(m.materials[0].name, "(default)");
    EXPECT_EQ(m.materials[0].albedo, vec3(0.8f));
    EXPECT_EQ(m.triangleMaterials, (std::vector<uint32_t>{0, 0, 0}));
}

TEST(Model, PolygonsAreTriangulatedAndNormalsNormalised) {
    const fs::path dir = freshDir("polygons");
    const Model m = loadObjModel(writeFile(dir / "quad.obj", "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nvn 0 0 3\n"
                                                             "f 1//1 2//1 3//1 4//1\n"));
    EXPECT_EQ(m.triangleCount(), 2u);
    EXPECT_EQ(m.vertices.size(), 4u);
    for (const ModelVertex& v : m.vertices) EXPECT_EQ(v.normal, vec3(0, 0, 1));
}

TEST(Model, CornersWithoutNormalsGetTheirTrianglesFlatNormal) {
    const fs::path dir = freshDir("flat");
    const Model m = loadObjModel(writeFile(dir / "fold.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\n"));
    // The two triangles share v1 and v2 but not their normals: nothing is shared.
    ASSERT_EQ(m.vertices.size(), 6u);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(m.vertices[k].normal, vec3(0, 0, 1));
        EXPECT_EQ(m.vertices[3 + k].normal, vec3(0, 1, 0));
        EXPECT_EQ(m.vertices[k].texcoord, vec2(0.0f));  // no vt
    }
}

TEST(Model, MaterialsAreParsedAndNumberedPerTriangle) {
    const fs::path dir = freshDir("materials");
    const Model m = loadObjModel(writeMaterialsModel(dir));
    // Used materials in library order (plain, glowing, textured), the default one last.
    ASSERT_EQ(m.materials.size(), 4u);
    EXPECT_EQ(m.materials[0].name, "plain");
    EXPECT_EQ(m.materials[1].name, "glowing");
    EXPECT_EQ(m.materials[2].name, "textured");
    EXPECT_EQ(m.materials[3].name, "(default)");
    EXPECT_EQ(m.triangleMaterials, (std::vector<uint32_t>{3, 2, 0, 1, 0}));

    const ModelMaterial& plain = m.materials[0];
    EXPECT_EQ(plain.library, (dir / "materials" / "lib.mtl").lexically_normal());
    EXPECT_EQ(plain.albedo, vec3(0.5f, 0.25f, 0.125f));
    EXPECT_EQ(plain.specular, vec3(0.2f));
    EXPECT_FLOAT_EQ(plain.shininess, 98.0f);
    EXPECT_FLOAT_EQ(plain.roughness, std::sqrt(2.0f / 100.0f));
    EXPECT_EQ(plain.type, MaterialType::Glossy);
    EXPECT_TRUE(plain.diffuseTexture.empty());
    EXPECT_TRUE(plain.normalTexture.empty());

    const ModelMaterial& glowing = m.materials[1];
    EXPECT_EQ(glowing.emission, vec3(4, 3, 2));
    EXPECT_EQ(glowing.type, MaterialType::Emissive);

    // Texture paths are resolved against the MTL file's folder.
    const ModelMaterial& textured = m.materials[2];
    EXPECT_EQ(textured.diffuseTexture, (dir / "materials" / "textures" / "albedo.png").lexically_normal());
    EXPECT_EQ(textured.normalTexture, (dir / "materials" / "textures" / "normal.png").lexically_normal());
    EXPECT_EQ(textured.type, MaterialType::Diffuse);
    EXPECT_TRUE(m.hasTangents);
}

TEST(Model, ShininessMapsToBeckmannRoughness) {
    EXPECT_FLOAT_EQ(roughnessFromShininess(0.0f), 1.0f);
    EXPECT_FLOAT_EQ(roughnessFromShininess(-5.0f), 1.0f);
    EXPECT_FLOAT_EQ(roughnessFromShininess(18.0f), std::sqrt(0.1f));
    EXPECT_LT(roughnessFromShininess(1000.0f), 0.05f);
}

TEST(Model, TangentsFollowPlusUAndCarryTheHandedness) {
    const fs::path dir = freshDir("tangents");
    writeFile(dir / "lib.mtl", "newmtl bumpy\nmap_Bump n.png\n");
    writeFile(dir / "n.png", "dummy");
    // Two unit squares facing +z: the left one mapped as seen (u along +x, OBJ v along +y), the right one mirrored
    // (u along -x).
    const Model m = loadObjModel(writeFile(dir / "squares.obj", R"(mtllib lib.mtl
usemtl bumpy
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 3 0 0
v 3 1 0
v 2 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1 4/4/1
f 5/2/1 6/1/1 7/4/1 8/3/1
)"));
    ASSERT_TRUE(m.hasTangents);
    ASSERT_EQ(m.vertices.size(), 8u);
    for (size_t i = 0; i < 8; ++i) {
        const ModelVertex& v = m.vertices[i];
        const bool mirrored = v.position.x >= 2.0f;
        EXPECT_NEAR(glm::distance(vec3(v.tangent), vec3(mirrored ? -1 : 1, 0, 0)), 0.0f, 1e-6f) << i;
        // +v of the D3D convention runs down the texture: -y here. cross(n, t) is +y unmirrored, -y mirrored.
        EXPECT_EQ(v.tangent.w, mirrored ? 1.0f : -1.0f) << i;
        const vec3 plusV = v.tangent.w * glm::cross(v.normal, vec3(v.tangent));
        EXPECT_NEAR(glm::distance(plusV, vec3(0, -1, 0)), 0.0f, 1e-6f) << i;
    }
}

TEST(Model, TangentsOfTheGeneratedTorusAreOrthonormal) {
    const std::vector<Model> models = loadObjModels(kScenes / "textured-room" / "textured-room.obj");
    const auto torus = std::find_if(models.begin(), models.end(), [](const Model& m) { return m.name == "torus"; });
    ASSERT_NE(torus, models.end());
    ASSERT_TRUE(torus->hasTangents);
    for (const ModelVertex& v : torus->vertices) {
        const vec3 t(v.tangent);
        EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(t, v.normal), 0.0f, 1e-5f);
        EXPECT_TRUE(v.tangent.w == 1.0f || v.tangent.w == -1.0f) << v.tangent.w;
    }
}

TEST(Model, ObjectsBecomeModelsByName) {
    const fs::path dir = freshDir("objects");
    const std::vector<Model> models = loadObjModels(writeFile(dir / "parts.obj", R"(v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 2 3
o first
f 1 2 4
o second
f 1 3 4
f 2 3 4
g first
f 1 2 3
)"));
    // Faces before any o/g belong to an object named after the file; "first" comes back after "second".
    ASSERT_EQ(models.size(), 3u);
    EXPECT_EQ(models[0].name, "parts");
    EXPECT_EQ(models[1].name, "first");
    EXPECT_EQ(models[2].name, "second");
    EXPECT_EQ(models[0].triangleCount(), 1u);
    EXPECT_EQ(models[1].triangleCount(), 2u);
    EXPECT_EQ(models[2].triangleCount(), 2u);
    EXPECT_EQ(models[1].indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));  // each model numbers its own vertices
    EXPECT_EQ(models[1].vertices[3].position, vec3(0, 0, 0));
    EXPECT_EQ(loadObjModel(dir / "parts.obj").triangleCount(), 5u);
}

// ---- Errors ------------------------------------------------------------------------------------------------------

TEST(Model, UnreadableAndEmptyFilesAreNamed) {
    const fs::path dir = freshDir("unreadable");
    const std::string missing = errorOf([&] { loadObjModel(dir / "no-such.obj"); });
    EXPECT_CONTAINS(missing, "cannot read model file");
    EXPECT_CONTAINS(missing, "no-such.obj");
    const std::string empty = errorOf([&] { loadObjModel(writeFile(dir / "points.obj", "v 0 0 0\nv 1 0 0\n")); });
    EXPECT_CONTAINS(empty, "points.obj holds no triangle");
}

TEST(Model, CoordinatesAndIndicesThatAreNotFiniteNumbersNameTheLine) {
    const fs::path dir = freshDir("bad-numbers");
    const auto error = [&](const std::string& lines) {
        return errorOf([&] { loadObjModel(writeFile(dir / "bad.obj", "v 0 0 0\nv 1 0 0\n" + lines + "\nf 1 2 3\n")); });
    };
    EXPECT_CONTAINS(error("v nan 1 0"), "bad.obj:3: v statement: value 1 is 'nan', which is not a finite number");
    EXPECT_CONTAINS(error("v 0 oops 0"), "bad.obj:3: v statement: value 2 is 'oops', not a number");
    EXPECT_CONTAINS(error("v 0 1 inf"), "bad.obj:3: v statement: value 3 is 'inf', which is not a finite number");
    EXPECT_CONTAINS(error("v 0 1e39 0"), "bad.obj:3: v statement: value 2 is '1e39', which is not a finite number");
    EXPECT_CONTAINS(error("v 0 1 0\nvn 0 0 1x"), "bad.obj:4: vn statement: value 3 is '1x', not a number");
    EXPECT_CONTAINS(error("v 0 1"), "bad.obj:3: v statement has 2 values; it needs at least 3");
    const std::string index = errorOf([&] {
        loadObjModel(writeFile(dir / "bad-index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n"));
    });
    EXPECT_CONTAINS(index, "bad-index.obj:4: face refers to vertex '3x', which is not a whole number");
    // What is fine stays fine: signs, exponents, a w and vertex colours.
    EXPECT_NO_THROW(loadObjModel(writeFile(dir / "good.obj", "v -0 +1 2e-3 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n")));
}

TEST(Model, FacesReferringToMissingDataNameTheLine) {
    const fs::path dir = freshDir("bad-faces");
    const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";  // 3 v, 1 vt, 1 vn; faces on line 6
    const auto error = [&](const std::string& face) {
        return errorOf([&] { loadObjModel(writeFile(dir / "bad.obj", head + face + "\n")); });
    };
    const std::string vertex = error("f 1 2 9");
    EXPECT_CONTAINS(vertex, "bad.obj:6: face refers to vertex 9, but the file has 3 vertices");
    const std::string normal = error("f 1//1 2//1 3//2");
    EXPECT_CONTAINS(normal, "bad.obj:6: face refers to normal 2, but the file has 1 normals");
    const std::string texcoord = error("f 1/1 2/1 3/4");
    EXPECT_CONTAINS(texcoord, "bad.obj:6: face refers to texcoord 4, but the file has 1 texcoords");
    const std::string relative = error("f -1 -2 -4");
    EXPECT_CONTAINS(relative, "bad.obj:6: face refers to vertex -4 (relative), but only 3 vertices precede it");
    // A relative normal index that tinyobjloader would turn into -1 ("no normal") is caught as well.
    const std::string relativeNormal = error("f 1//-2 2//1 3//1");
    EXPECT_CONTAINS(relativeNormal, "bad.obj:6: face refers to normal -2 (relative), but only 1 normals precede it");
    const std::string zero = error("f 0 1 2");
    EXPECT_CONTAINS(zero, "bad.obj:6: face refers to vertex 0; OBJ indices start at 1");
    const std::string twoCorners = error("f 1 2");
    EXPECT_CONTAINS(twoCorners, "bad.obj:6: face has 2 vertices");
    const std::string zeroNormal = errorOf([&] {
        loadObjModel(writeFile(dir / "zero-normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n"));
    });
    EXPECT_CONTAINS(zeroNormal, "zero-normal.obj:4: normal 1 has zero length");
    EXPECT_EQ(error("f 1/1/1 2/1/1 3/1/1"), "(no error)");
}

TEST(Model, UnknownMaterialsAndLibrariesNameTheLine) {
    const fs::path dir = freshDir("bad-materials");
    writeFile(dir / "lib.mtl", "newmtl a\nKd 1 0 0\n\nnewmtl b\nKd 0 1 0\n");
    const std::string faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const std::string unknown = errorOf([&] {
        loadObjModel(writeFile(dir / "unknown.obj", "mtllib lib.mtl\nusemtl a\n" + faces + "usemtl c\nf 1 2 3\n"));
    });
    EXPECT_CONTAINS(unknown, "unknown.obj:7: usemtl names material 'c', which no material library loaded before it "
                             "defines (they define: a, b)");
    const std::string noLibrary =
        errorOf([&] { loadObjModel(writeFile(dir / "no-library.obj", faces + "usemtl a\nf 1 2 3\n")); });
    EXPECT_CONTAINS(noLibrary, "no-library.obj:5: usemtl names material 'a', which no mtllib statement before it "
                               "defines");
    const std::string missingLibrary =
        errorOf([&] { loadObjModel(writeFile(dir / "missing-library.obj", faces + "mtllib gone.mtl\n")); });
    EXPECT_CONTAINS(missingLibrary, "missing-library.obj:5: cannot read material library 'gone.mtl'");
}

TEST(Model, MissingTexturesNameTheLibraryLineAndMap) {
    const fs::path dir = freshDir("bad-textures");
    const std::string obj = "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
    writeFile(dir / "lib.mtl", "newmtl other\nKd 1 1 1\nnewmtl m\nKd 1 1 1\nmap_Kd textures/gone.png\n");
    const std::string diffuse = errorOf([&] { loadObjModel(writeFile(dir / "a.obj", obj)); });
    EXPECT_CONTAINS(diffuse, "lib.mtl:5: material 'm': map_Kd texture 'textures/gone.png' not found");
    EXPECT_CONTAINS(diffuse, (dir / "textures" / "gone.png").string());
    writeFile(dir / "lib.mtl", "newmtl m\nKd 1 1 1\nmap_Bump bumps.png\n");
    const std::string bump = errorOf([&] { loadObjModel(writeFile(dir / "a.obj", obj)); });
    EXPECT_CONTAINS(bump, "lib.mtl:3: material 'm': map_Bump texture 'bumps.png' not found");
    writeFile(dir / "lib.mtl", "newmtl m\nnorm normals.png\nKd 1 1 1\n");
    const std::string norm = errorOf([&] { loadObjModel(writeFile(dir / "a.obj", obj)); });
    EXPECT_CONTAINS(norm, "lib.mtl:2: material 'm': norm texture 'normals.png' not found");
}

// ---- Global buffers ----------------------------------------------------------------------------------------------

TEST(GlobalModelBuffers, TwoModelsThreeObjectsAreConcatenatedWithOffsets) {
    const fs::path dir = freshDir("buffers");
    const std::vector<Model> models{loadObjModel(writeFile(dir / "square.obj", kSharedCornersObj)),
                                    loadObjModel(writeMaterialsModel(dir))};
    // Model 0: 5 vertices, 9 indices, 3 triangles, 1 material. Model 1: 15 vertices (no vn: nothing shared),
    // 15 indices, 5 triangles, 4 materials.
    const std::vector<ModelObjectDesc> objects{{"first", 1, Matrix3x4::identity()},
                                               {"second", 0, Matrix3x4::translation(vec3(1, 2, 3))},
                                               {"third", 1, Matrix3x4::scale(vec3(2))}};
    const GlobalModelBuffers b = buildGlobalModelBuffers(models, objects);
    EXPECT_EQ(b.vertices.size(), 20u);
    EXPECT_EQ(b.indices.size(), 24u);
    EXPECT_EQ(b.triangleMaterials.size(), 8u);
    EXPECT_EQ(b.materials.size(), 5u);
    ASSERT_EQ(b.objects.size(), 3u);

    const ObjectGPU& third = b.objects[2];
    EXPECT_EQ(third.vertexOffset, 5u);
    EXPECT_EQ(third.indexOffset, 9u);
    EXPECT_EQ(third.materialOffset, 1u);
    EXPECT_EQ(third.triangleOffset, 3u);
    EXPECT_EQ(third.vertexCount, 15u);
    EXPECT_EQ(third.indexCount, 15u);
    EXPECT_EQ(third.materialCount, 4u);
    EXPECT_EQ(third.modelIndex, 1u);
    EXPECT_EQ(std::memcmp(&b.objects[0], &third, sizeof(ObjectGPU)), 0);  // the same model: the same offsets
    const ObjectGPU& second = b.objects[1];
    EXPECT_EQ(second.vertexOffset, 0u);
    EXPECT_EQ(second.indexOffset, 0u);
    EXPECT_EQ(second.materialOffset, 0u);
    EXPECT_EQ(second.modelIndex, 0u);
    EXPECT_EQ(b.objectDescs[1].transform, Matrix3x4::translation(vec3(1, 2, 3)));
    ASSERT_EQ(b.modelRanges.size(), 2u);
    EXPECT_EQ(std::memcmp(&b.modelRanges[1], &third, sizeof(ObjectGPU)), 0);

    // Indices stay local to the model; vertices are copied in order.
    EXPECT_EQ(b.indices[9 + 3], models[1].indices[3]);
    EXPECT_EQ(b.vertices[5 + 7].position, models[1].vertices[7].position);
    EXPECT_EQ(b.vertices[4].u, 0.5f);
    EXPECT_EQ(b.vertices[4].v, 0.75f);
    // Per-triangle materials are global: model 1's local ids {3, 2, 0, 1, 0} plus its material offset 1.
    EXPECT_EQ(b.triangleMaterials, (std::vector<uint32_t>{0, 0, 0, 4, 3, 1, 2, 1}));

    const MaterialGPU& plain = b.materials[1];
    EXPECT_EQ(plain.albedo, vec4(0.5f, 0.25f, 0.125f, 0.0f));
    EXPECT_EQ(plain.specularRoughness, vec4(0.2f, 0.2f, 0.2f, std::sqrt(2.0f / 100.0f)));
    EXPECT_EQ(plain.type, uint32_t(MaterialType::Glossy));
    EXPECT_EQ(plain.shininess, 98.0f);
    EXPECT_EQ(plain.diffuseTextureIndex, -1);
    EXPECT_EQ(b.materials[2].emission, vec4(4, 3, 2, 0));
    EXPECT_EQ(b.materials[2].type, uint32_t(MaterialType::Emissive));
    const MaterialGPU& textured = b.materials[3];
    EXPECT_EQ(textured.diffuseTextureIndex, 0);
    EXPECT_EQ(textured.normalTextureIndex, 0);
    ASSERT_EQ(b.diffuseTextures.size(), 1u);
    ASSERT_EQ(b.normalTextures.size(), 1u);
    EXPECT_EQ(b.diffuseTextures[0], (dir / "materials" / "textures" / "albedo.png").lexically_normal());
    EXPECT_EQ(b.normalTextures[0], (dir / "materials" / "textures" / "normal.png").lexically_normal());
    EXPECT_EQ(b.materials[4].albedo, vec4(0.8f, 0.8f, 0.8f, 0.0f));  // model 1's default material
}

TEST(GlobalModelBuffers, TexturesAreListedOnce) {
    const fs::path dir = freshDir("buffers-textures");
    const Model model = loadObjModel(writeMaterialsModel(dir));
    const std::vector<Model> models{model, model};
    const GlobalModelBuffers b = buildGlobalModelBuffers(models, std::vector<ModelObjectDesc>{{"a", 0}, {"b", 1}});
    EXPECT_EQ(b.materials.size(), 8u);
    EXPECT_EQ(b.diffuseTextures.size(), 1u);
    EXPECT_EQ(b.normalTextures.size(), 1u);
    EXPECT_EQ(b.materials[2].diffuseTextureIndex, 0);
    EXPECT_EQ(b.materials[6].diffuseTextureIndex, 0);
    EXPECT_EQ(b.materials[6].normalTextureIndex, 0);
}

TEST(GlobalModelBuffers, BadObjectsAreNamed) {
    const fs::path dir = freshDir("buffers-errors");
    const std::vector<Model> models{loadObjModel(writeFile(dir / "square.obj", kSharedCornersObj))};
    const std::string badModel =
        errorOf([&] { buildGlobalModelBuffers(models, std::vector<ModelObjectDesc>{{"a", 0}, {"lamp", 3}}); });
    EXPECT_CONTAINS(badModel, "object 1 ('lamp') refers to model 3, but there are 1 models");
    ModelObjectDesc infinite{"far", 0};
    infinite.transform.m[0][3] = INFINITY;
    const std::string badTransform =
        errorOf([&] { buildGlobalModelBuffers(models, std::vector<ModelObjectDesc>{infinite}); });
    EXPECT_CONTAINS(badTransform, "object 0 ('far') has a transform that is not finite");
    Model broken = models[0];
    broken.triangleMaterials[1] = 7;
    const std::string badMaterial = errorOf([&] {
        buildGlobalModelBuffers(std::vector<Model>{broken}, std::vector<ModelObjectDesc>{{"a", 0}});
    });
    EXPECT_CONTAINS(badMaterial, "model 0 ('square'): triangle 1 uses material 7, but the model has 1 materials");
}

TEST(GlobalModelBuffers, GpuStructsHaveTheHlslByteLayout) {
    // What a StructuredBuffer<Material> read sees at each byte offset.
    MaterialGPU m = toMaterialGPU(ModelMaterial{}, 5, -1);
    m.emission = vec4(1, 2, 3, 0);
    unsigned char bytes[sizeof(MaterialGPU)];
    std::memcpy(bytes, &m, sizeof m);
    float f;
    int32_t i;
    std::memcpy(&f, bytes + 16 + 4, 4);
    EXPECT_EQ(f, 2.0f);
    std::memcpy(&f, bytes + 44, 4);
    EXPECT_EQ(f, 1.0f);  // specularRoughness.w: Ns 0 is fully rough
    std::memcpy(&i, bytes + 48, 4);
    EXPECT_EQ(i, 5);
    std::memcpy(&i, bytes + 52, 4);
    EXPECT_EQ(i, -1);
    EXPECT_EQ(sizeof(VertexGPU), 48u);
    EXPECT_EQ(sizeof(MaterialGPU), 64u);
    EXPECT_EQ(sizeof(ObjectGPU), 32u);
    const VertexGPU v = toVertexGPU(ModelVertex{vec3(1, 2, 3), vec3(0, 1, 0), vec2(0.25f, 0.5f), vec4(1, 0, 0, -1)});
    unsigned char vb[sizeof(VertexGPU)];
    std::memcpy(vb, &v, sizeof v);
    std::memcpy(&f, vb + 12, 4);
    EXPECT_EQ(f, 0.25f);
    std::memcpy(&f, vb + 28, 4);
    EXPECT_EQ(f, 0.5f);
    std::memcpy(&f, vb + 44, 4);
    EXPECT_EQ(f, -1.0f);
}

// ---- The generated assets ----------------------------------------------------------------------------------------

// Every triangle winds counter-clockwise around the side its corners' normals point to.
void expectWindingFollowsNormals(const Model& m) {
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        const ModelVertex &a = m.vertices[m.indices[3 * t]], &b = m.vertices[m.indices[3 * t + 1]],
                          &c = m.vertices[m.indices[3 * t + 2]];
        const vec3 g = glm::cross(b.position - a.position, c.position - a.position);
        EXPECT_GT(glm::dot(g, a.normal + b.normal + c.normal), 0.0f) << m.name << " triangle " << t;
    }
}

TEST(CornellBox, ObjectsMaterialsAndLight) {
    const std::vector<Model> models = loadObjModels(kScenes / "cornell-box" / "cornell-box.obj");
    ASSERT_EQ(models.size(), 4u);
    const std::vector<std::string> names{"walls", "short-block", "tall-block", "light"};
    const std::vector<size_t> triangles{10, 10, 10, 2}, materials{3, 1, 1, 1};
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(models[i].name, names[i]);
        EXPECT_EQ(models[i].triangleCount(), triangles[i]) << names[i];
        EXPECT_EQ(models[i].materials.size(), materials[i]) << names[i];
        expectWindingFollowsNormals(models[i]);
    }
    EXPECT_EQ(models[0].materials[0].name, "white");
    EXPECT_EQ(models[0].materials[1].name, "red");
    EXPECT_EQ(models[0].materials[2].name, "green");
    EXPECT_EQ(models[0].materials[1].albedo, vec3(0.63f, 0.065f, 0.05f));
    EXPECT_EQ(models[0].materials[0].type, MaterialType::Diffuse);
    // Walls face into the room.
    const vec3 centre(278.0f, 274.4f, 279.6f);
    for (const ModelVertex& v : models[0].vertices) EXPECT_GT(glm::dot(v.normal, centre - v.position), 0.0f);

    const Model& light = models[3];
    EXPECT_EQ(light.materials[0].type, MaterialType::Emissive);
    EXPECT_EQ(light.materials[0].emission, vec3(17, 12, 4));
    for (const ModelVertex& v : light.vertices) {
        EXPECT_EQ(v.position.y, 548.7f);
        EXPECT_EQ(v.normal, vec3(0, -1, 0));
    }

    std::vector<ModelObjectDesc> objects;
    for (uint32_t i = 0; i < 4; ++i) objects.push_back({names[i], i});
    const GlobalModelBuffers b = buildGlobalModelBuffers(models, objects);
    EXPECT_EQ(b.materials.size(), 6u);
    EXPECT_EQ(std::count_if(b.materials.begin(), b.materials.end(),
                            [](const MaterialGPU& m) { return m.type == uint32_t(MaterialType::Emissive); }),
              1);
    // The light's triangles find the emissive material through InstanceID 3.
    const ObjectGPU& o = b.objects[3];
    EXPECT_EQ(b.materials[b.triangleMaterials[o.triangleOffset + 1]].emission, vec4(17, 12, 4, 0));
}

TEST(TexturedRoom, LoadsWithTexturesTangentsAndConsistentWinding) {
    const std::vector<Model> models = loadObjModels(kScenes / "textured-room" / "textured-room.obj");
    std::vector<std::string> names;
    size_t triangles = 0;
    for (const Model& m : models) {
        names.push_back(m.name);
        triangles += m.triangleCount();
        expectWindingFollowsNormals(m);
        ASSERT_EQ(m.materials.size(), 1u) << m.name;
        EXPECT_EQ(m.hasTangents, !m.materials[0].normalTexture.empty()) << m.name;
    }
    EXPECT_EQ(names, (std::vector<std::string>{"floor", "back-wall", "sphere", "box", "torus", "light"}));
    EXPECT_LT(triangles, 5000u);
    std::vector<ModelObjectDesc> objects;
    for (uint32_t i = 0; i < models.size(); ++i) objects.push_back({names[i], i});
    const GlobalModelBuffers b = buildGlobalModelBuffers(models, objects);
    EXPECT_EQ(b.diffuseTextures.size(), 4u);
    EXPECT_EQ(b.normalTextures.size(), 2u);
    for (const auto* list : {&b.diffuseTextures, &b.normalTextures})
        for (const fs::path& texture : *list) {
            const Image image = readImage(texture.string());
            EXPECT_LE(image.width(), 256u) << texture;
            EXPECT_LE(image.height(), 256u) << texture;
        }
}

TEST(AssetGenerator, RegeneratingGivesTheCommittedBytes) {
    const fs::path out = freshDir("generated");
    const std::vector<std::string> written = writeModelAssets(out);
    std::set<std::string> committed;
    for (const char* folder : {"cornell-box", "textured-room"})
        for (const auto& entry : fs::recursive_directory_iterator(kScenes / folder))
            if (entry.is_regular_file()) committed.insert(fs::relative(entry.path(), kScenes).generic_string());
    EXPECT_EQ(committed, std::set<std::string>(written.begin(), written.end()))
        << "scenes/cornell-box and scenes/textured-room hold exactly what refray_make_assets writes";
    for (const std::string& file : written)
        EXPECT_TRUE(readBytes(out / file) == readBytes(kScenes / file))
            << "scenes/" << file << " differs from what scenes/asset_generator.cpp generates; "
            << "run refray_make_assets to regenerate it";
}

TEST(AssetGenerator, IsDeterministic) {
    const fs::path a = freshDir("generated-a"), b = freshDir("generated-b");
    const std::vector<std::string> first = writeModelAssets(a);
    EXPECT_EQ(writeModelAssets(b), first);
    for (const std::string& file : first) {
        EXPECT_FALSE(readBytes(a / file).empty()) << file;
        EXPECT_TRUE(readBytes(a / file) == readBytes(b / file)) << file;
    }
}

}  // namespace
}  // namespace refray::scenes
