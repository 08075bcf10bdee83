#include "scenes/model.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>

#include <tiny_obj_loader.h>

#include "core/error.h"
#include "core/file_input.h"
#include "core/random.h"

namespace refray::scenes {

namespace fs = std::filesystem;

namespace {

constexpr const char* kDefaultMaterialName = "(default)";

// ---- Text lines -------------------------------------------------------------------------------------------------

std::string readWholeFile(const fs::path& path, const char* what) {
    return readInputFile(path.string(), what);
}

// Lines without their "\n" or "\r\n"; line k of the file is lines[k - 1].
std::vector<std::string_view> splitLines(std::string_view text) {
    std::vector<std::string_view> lines;
    while (!text.empty()) {
        const size_t end = text.find('\n');
        std::string_view line = text.substr(0, end);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        lines.push_back(line);
        if (end == std::string_view::npos) break;
        text.remove_prefix(end + 1);
    }
    return lines;
}

std::vector<std::string_view> splitTokens(std::string_view line) {
    std::vector<std::string_view> tokens;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) tokens.push_back(line.substr(start, i - start));
    }
    return tokens;
}

// atoi's reading of an index (a sign and digits; anything else ends it), clamped to int.
int leadingInt(std::string_view s) {
    size_t i = 0;
    const bool negative = i < s.size() && s[i] == '-';
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
    int64_t value = 0;
    for (; i < s.size() && s[i] >= '0' && s[i] <= '9'; ++i)
        value = std::min<int64_t>(value * 10 + (s[i] - '0'), int64_t(std::numeric_limits<int>::max()) + 1);
    value = negative ? -value : value;
    return int(std::clamp<int64_t>(value, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
}

std::string at(const fs::path& file, size_t line) { return file.string() + ":" + std::to_string(line) + ": "; }

// A coordinate of a v, vn or vt statement: the whole token a finite number within float's range. tinyobjloader would
// read "nan", "oops" or "1e39" as some number (0 for a word) and change the geometry without a word.
void checkObjNumber(std::string_view token, const std::string& where, std::string_view statement, size_t k) {
    double value = 0.0;
    const char* begin = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const char* end = token.data() + token.size();
    const auto [stop, error] = std::from_chars(begin, end, value);
    const bool number = error == std::errc() && stop == end;
    REFRAY_CHECK(number || error == std::errc::result_out_of_range,
                 where << statement << " statement: value " << k << " is '" << token << "', not a number");
    REFRAY_CHECK(number && std::isfinite(value) && std::abs(value) <= double(std::numeric_limits<float>::max()),
                 where << statement << " statement: value " << k << " is '" << token
                       << "', which is not a finite number within float's range (+-3.4e38)");
}

// A face corner's index: an optional sign and digits, nothing else.
int strictIndex(std::string_view token, const std::string& where, const char* what) {
    const size_t digits = (!token.empty() && (token[0] == '-' || token[0] == '+')) ? 1 : 0;
    const bool ok = token.size() > digits && std::all_of(token.begin() + digits, token.end(),
                                                         [](char c) { return c >= '0' && c <= '9'; });
    REFRAY_CHECK(ok, where << "face refers to " << what << " '" << token << "', which is not a whole number");
    return leadingInt(token);
}

// ---- Material libraries -----------------------------------------------------------------------------------------

// Every material of the OBJ's libraries, in the order tinyobjloader numbers them.
struct MaterialSet {
    std::vector<tinyobj::material_t> parsed;
    std::map<std::string, int> ids;  // the first definition of a name wins, as in tinyobjloader
    std::vector<ModelMaterial> converted;
    std::vector<fs::path> loadedLibraries;
};

// The line of the last `keyword` statement inside material `material`'s block of an MTL file, 0 if none.
size_t mtlLine(const std::vector<std::string_view>& lines, const std::string& material,
               std::initializer_list<std::string_view> keywords, std::string_view* foundKeyword) {
    size_t found = 0;
    bool inside = false;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::vector<std::string_view> tokens = splitTokens(lines[i]);
        if (tokens.empty()) continue;
        if (tokens[0] == "newmtl") inside = tokens.size() > 1 && tokens[1] == material;
        else if (inside && std::find(keywords.begin(), keywords.end(), tokens[0]) != keywords.end()) {
            found = i + 1;
            *foundKeyword = tokens[0];
        }
    }
    return found;
}

fs::path resolveTexture(const fs::path& library, const std::string& name, const std::vector<std::string_view>& lines,
                        const std::string& material, std::initializer_list<std::string_view> keywords) {
    if (name.empty()) return {};
    const fs::path resolved = (library.parent_path() / fs::path(name)).lexically_normal();
    std::string_view keyword = *keywords.begin();
    const size_t line = mtlLine(lines, material, keywords, &keyword);
    REFRAY_CHECK(fs::is_regular_file(resolved),
                 (line ? at(library, line) : library.string() + ": ")
                     << "material '" << material << "': " << keyword << " texture '" << name
                     << "' not found (no file " << resolved.string() << ")");
    return resolved;
}

ModelMaterial convertMaterial(const tinyobj::material_t& m, const fs::path& library,
                              const std::vector<std::string_view>& lines) {
    ModelMaterial out;
    out.name = m.name;
    out.library = library;
    out.albedo = vec3(m.diffuse[0], m.diffuse[1], m.diffuse[2]);
    out.specular = vec3(m.specular[0], m.specular[1], m.specular[2]);
    out.shininess = m.shininess;
    out.roughness = roughnessFromShininess(m.shininess);
    out.emission = vec3(m.emission[0], m.emission[1], m.emission[2]);
    for (const vec3 v : {out.albedo, out.specular, out.emission})
        REFRAY_CHECK(allFinite(v) && std::isfinite(out.shininess),
                     library.string() << ": material '" << m.name << "' has a value that is not finite");
    out.diffuseTexture = resolveTexture(library, m.diffuse_texname, lines, m.name, {"map_Kd"});
    out.normalTexture = !m.normal_texname.empty()
                            ? resolveTexture(library, m.normal_texname, lines, m.name, {"norm"})
                            : resolveTexture(library, m.bump_texname, lines, m.name, {"map_Bump", "map_bump", "bump"});
    const auto positive = [](vec3 v) { return v.x > 0.0f || v.y > 0.0f || v.z > 0.0f; };
    out.type = positive(out.emission)   ? MaterialType::Emissive
               : positive(out.specular) ? MaterialType::Glossy
                                        : MaterialType::Diffuse;
    return out;
}

void loadMaterialLibrary(const fs::path& library, MaterialSet& set) {
    const std::string text = readWholeFile(library, "material library");
    std::map<std::string, int> ids;
    std::vector<tinyobj::material_t> materials;
    std::istringstream stream(text);
    std::string warning, error;
    tinyobj::LoadMtl(&ids, &materials, &stream, &warning, &error);
    REFRAY_CHECK(error.empty(), "cannot parse material library " << library.string() << ": " << error);
    const std::vector<std::string_view> lines = splitLines(text);
    // The numeric statements: tinyobjloader reads "nan" or a word as some number without a word.
    static const std::set<std::string_view> numeric = {"Ka", "Kd", "Ks", "Ke", "Kt", "Tf", "Ns", "Ni", "d", "Tr",
                                                       "illum", "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor"};
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::vector<std::string_view> tokens = splitTokens(lines[i]);
        if (tokens.empty() || !numeric.count(tokens[0])) continue;
        if (std::find(tokens.begin(), tokens.end(), "spectral") != tokens.end()) continue;  // names a curve file
        for (size_t k = 1; k < tokens.size(); ++k) {
            const bool option =
                tokens[k].size() > 1 && tokens[k][0] == '-' && std::isalpha((unsigned char)tokens[k][1]);
            if (tokens[k] != "xyz" && !option) checkObjNumber(tokens[k], at(library, i + 1), tokens[0], k);
        }
    }
    for (const tinyobj::material_t& m : materials) {
        if (m.name.empty() || set.ids.count(m.name)) continue;  // a file without newmtl; a name defined before
        set.ids.emplace(m.name, int(set.parsed.size()));
        set.parsed.push_back(m);
        set.converted.push_back(convertMaterial(m, library, lines));
    }
}

// Hands tinyobjloader the materials loaded while checking the OBJ (all of them, at its first mtllib statement), so
// that its usemtl numbering is ours and every library is read once.
class PreloadedMaterials : public tinyobj::MaterialReader {
public:
    explicit PreloadedMaterials(const MaterialSet& set) : set_(set) {}
    bool operator()(const std::string&, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* ids, std::string*, std::string*) override {
        if (!handedOver_) {
            *materials = set_.parsed;
            *ids = set_.ids;
            handedOver_ = true;
        }
        return true;
    }

private:
    const MaterialSet& set_;
    bool handedOver_ = false;
};

// ---- Checking the OBJ statements tinyobjloader does not check (or reports without the line) ----------------------

struct ObjLines {
    std::vector<size_t> vertexLines, normalLines, texcoordLines;  // the line of each v, vn, vt statement
};

void checkFaceIndex(int index, size_t before, size_t total, const char* what, const char* plural,
                    const std::string& where) {
    REFRAY_CHECK(index != 0, where << "face refers to " << what << " 0; OBJ indices start at 1");
    if (index > 0)
        REFRAY_CHECK(size_t(index) <= total,
                     where << "face refers to " << what << " " << index << ", but the file has " << total << " "
                           << plural);
    else
        REFRAY_CHECK(size_t(-int64_t(index)) <= before,
                     where << "face refers to " << what << " " << index << " (relative), but only " << before << " "
                           << plural << " precede it");
}

// Reads mtllib statements (loading the libraries into `set`) and checks usemtl and face statements, in file order.
ObjLines checkObjStatements(const fs::path& path, const std::vector<std::string_view>& lines, MaterialSet& set) {
    ObjLines out;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::vector<std::string_view> tokens = splitTokens(lines[i]);
        if (tokens.empty()) continue;
        if (tokens[0] == "v") out.vertexLines.push_back(i + 1);
        else if (tokens[0] == "vn") out.normalLines.push_back(i + 1);
        else if (tokens[0] == "vt") out.texcoordLines.push_back(i + 1);
    }
    size_t vertices = 0, normals = 0, texcoords = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::vector<std::string_view> tokens = splitTokens(lines[i]);
        if (tokens.empty()) continue;
        const std::string where = at(path, i + 1);
        if (tokens[0] == "v" || tokens[0] == "vn" || tokens[0] == "vt") {
            const size_t least = tokens[0] == "vt" ? 1 : 3;
            REFRAY_CHECK(tokens.size() > least, where << tokens[0] << " statement has " << (tokens.size() - 1)
                                                      << " values; it needs at least " << least);
            for (size_t k = 1; k < tokens.size(); ++k) checkObjNumber(tokens[k], where, tokens[0], k);
            ++(tokens[0] == "v" ? vertices : tokens[0] == "vn" ? normals : texcoords);
        } else if (tokens[0] == "mtllib") {
            for (size_t k = 1; k < tokens.size(); ++k) {
                const fs::path library = (path.parent_path() / fs::path(tokens[k])).lexically_normal();
                REFRAY_CHECK(fs::is_regular_file(library), where << "cannot read material library '" << tokens[k]
                                                                 << "' (no file " << library.string() << ")");
                if (std::find(set.loadedLibraries.begin(), set.loadedLibraries.end(), library) !=
                    set.loadedLibraries.end())
                    continue;
                set.loadedLibraries.push_back(library);
                loadMaterialLibrary(library, set);
            }
        } else if (tokens[0] == "usemtl") {
            const std::string name = tokens.size() > 1 ? std::string(tokens[1]) : std::string();
            if (set.ids.count(name)) continue;
            std::ostringstream known;
            for (const ModelMaterial& m : set.converted) known << (known.tellp() > 0 ? ", " : "") << m.name;
            REFRAY_CHECK(false, where << "usemtl names material '" << name << "', which "
                                      << (set.loadedLibraries.empty()
                                              ? std::string("no mtllib statement before it defines")
                                              : "no material library loaded before it defines (they define: " +
                                                    known.str() + ")"));
        } else if (tokens[0] == "f") {
            REFRAY_CHECK(tokens.size() >= 4, where << "face has " << (tokens.size() - 1)
                                                   << " vertices; a face needs at least 3");
            for (size_t k = 1; k < tokens.size(); ++k) {
                const std::string_view corner = tokens[k];
                const size_t slash1 = corner.find('/');
                checkFaceIndex(strictIndex(corner.substr(0, slash1), where, "vertex"), vertices,
                               out.vertexLines.size(), "vertex", "vertices", where);
                if (slash1 == std::string_view::npos) continue;
                const size_t slash2 = corner.find('/', slash1 + 1);
                const std::string_view vt = corner.substr(slash1 + 1, slash2 == std::string_view::npos
                                                                          ? std::string_view::npos
                                                                          : slash2 - slash1 - 1);
                if (!vt.empty() || slash2 == std::string_view::npos)
                    checkFaceIndex(strictIndex(vt, where, "texcoord"), texcoords, out.texcoordLines.size(),
                                   "texcoord", "texcoords", where);
                if (slash2 != std::string_view::npos)
                    checkFaceIndex(strictIndex(corner.substr(slash2 + 1), where, "normal"), normals,
                                   out.normalLines.size(), "normal", "normals", where);
            }
        }
    }
    return out;
}

// ---- Building models --------------------------------------------------------------------------------------------

struct ParsedObj {
    fs::path path;
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    MaterialSet materials;
    ObjLines lines;
};

ParsedObj parseObj(const fs::path& path) {
    ParsedObj parsed;
    parsed.path = path;
    const std::string text = readWholeFile(path, "model file");
    parsed.lines = checkObjStatements(path, splitLines(text), parsed.materials);

    std::istringstream stream(text);
    PreloadedMaterials reader(parsed.materials);
    std::vector<tinyobj::material_t> materials;
    std::string warning, error;
    const bool ok = tinyobj::LoadObj(&parsed.attrib, &parsed.shapes, &materials, &warning, &error, &stream, &reader,
                                     /*triangulate=*/true, /*default_vcols_fallback=*/false);
    while (!error.empty() && (error.back() == '\n' || error.back() == '\r')) error.pop_back();
    REFRAY_CHECK(ok && error.empty(),
                 "cannot parse model file " << path.string() << ": " << (error.empty() ? "unknown error" : error));
    return parsed;
}

// A corner's identity: the (v, vn, vt) triple; a corner without vn also carries its triangle (flat normal).
struct CornerKey {
    int v, vn, vt;
    uint32_t flatTriangle;
    bool operator==(const CornerKey&) const = default;
};

struct CornerKeyHash {
    size_t operator()(const CornerKey& k) const {
        return pcgHash(uint32_t(k.v) ^ pcgHash(uint32_t(k.vn) ^ pcgHash(uint32_t(k.vt) ^ pcgHash(k.flatTriangle))));
    }
};

// Any unit vector orthogonal to the unit vector n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
vec3 orthogonalUnit(vec3 n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    return vec3(1.0f + sign * n.x * n.x * a, sign * n.x * n.y * a, -sign * n.x);
}

// Per-vertex tangents: each triangle's dP/du and dP/dv summed at its corners (Lengyel's method), then
// Gram-Schmidt against the normal; w says whether dP/dv is along cross(normal, tangent) or against it.
void computeTangents(Model& model) {
    std::vector<vec3> du(model.vertices.size(), vec3(0.0f)), dv(model.vertices.size(), vec3(0.0f));
    for (size_t t = 0; t < model.triangleCount(); ++t) {
        const uint32_t i0 = model.indices[3 * t], i1 = model.indices[3 * t + 1], i2 = model.indices[3 * t + 2];
        const ModelVertex &a = model.vertices[i0], &b = model.vertices[i1], &c = model.vertices[i2];
        const vec3 e1 = b.position - a.position, e2 = c.position - a.position;
        const vec2 d1 = b.texcoord - a.texcoord, d2 = c.texcoord - a.texcoord;
        const float det = d1.x * d2.y - d2.x * d1.y;
        if (!(std::abs(det) > 0.0f)) continue;  // no texcoords, or a degenerate mapping: says nothing about u and v
        const vec3 tangent = (e1 * d2.y - e2 * d1.y) / det;
        const vec3 bitangent = (e2 * d1.x - e1 * d2.x) / det;
        if (!allFinite(tangent) || !allFinite(bitangent)) continue;
        for (const uint32_t i : {i0, i1, i2}) {
            du[i] += tangent;
            dv[i] += bitangent;
        }
    }
    for (size_t i = 0; i < model.vertices.size(); ++i) {
        ModelVertex& v = model.vertices[i];
        vec3 t = du[i] - v.normal * glm::dot(v.normal, du[i]);
        const float length = glm::length(t);
        t = length > 1e-20f && std::isfinite(length) ? t / length : orthogonalUnit(v.normal);
        const float handedness = glm::dot(glm::cross(v.normal, t), dv[i]) < 0.0f ? -1.0f : 1.0f;
        v.tangent = vec4(t, handedness);
    }
}

Model buildModel(const ParsedObj& obj, const std::vector<const tinyobj::shape_t*>& shapes, std::string name) {
    const tinyobj::attrib_t& attrib = obj.attrib;
    const std::string file = obj.path.string();
    const auto lineOf = [&](const std::vector<size_t>& lines, int index) {
        return size_t(index) < lines.size() ? at(obj.path, lines[size_t(index)]) : file + ": ";
    };
    const auto position = [&](int i) {
        REFRAY_CHECK(i >= 0 && size_t(3 * i + 2) < attrib.vertices.size(),
                     file << ": a face refers to vertex " << (i + 1) << " of " << attrib.vertices.size() / 3);
        const vec3 p(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
        REFRAY_CHECK(allFinite(p), lineOf(obj.lines.vertexLines, i) << "vertex " << (i + 1) << " is not finite");
        return p;
    };

    Model model;
    model.name = std::move(name);
    model.path = obj.path;

    // Corners: unique (v, vn, vt) triples in order of first use.
    std::unordered_map<CornerKey, uint32_t, CornerKeyHash> cornerIndex;
    std::vector<int> globalMaterials;  // per triangle, tinyobjloader's material id (-1: none)
    for (const tinyobj::shape_t* shape : shapes) {
        for (size_t f = 0; f < shape->mesh.num_face_vertices.size(); ++f) {
            const unsigned n = shape->mesh.num_face_vertices[f];
            REFRAY_CHECK(n == 3, file << ": face " << (f + 1) << " of object '" << shape->name << "' has " << n
                                      << " vertices after triangulation");
            const uint32_t triangle = uint32_t(globalMaterials.size());
            const tinyobj::index_t* corners = &shape->mesh.indices[3 * f];
            const vec3 p0 = position(corners[0].vertex_index), p1 = position(corners[1].vertex_index),
                       p2 = position(corners[2].vertex_index);
            vec3 flatNormal = glm::cross(p1 - p0, p2 - p0);
            const float area2 = glm::length(flatNormal);
            // A degenerate triangle is never hit; its corners without vn still get a unit normal.
            flatNormal = area2 > 0.0f && std::isfinite(area2) ? flatNormal / area2 : vec3(0.0f, 1.0f, 0.0f);
            for (int k = 0; k < 3; ++k) {
                const tinyobj::index_t& c = corners[k];
                const CornerKey key{c.vertex_index, c.normal_index, c.texcoord_index,
                                    c.normal_index < 0 ? triangle : std::numeric_limits<uint32_t>::max()};
                const auto [it, inserted] = cornerIndex.emplace(key, uint32_t(model.vertices.size()));
                model.indices.push_back(it->second);
                if (!inserted) continue;
                ModelVertex v;
                v.position = position(c.vertex_index);
                v.normal = flatNormal;
                if (c.normal_index >= 0) {
                    const int i = c.normal_index;
                    REFRAY_CHECK(size_t(3 * i + 2) < attrib.normals.size(),
                                 file << ": a face refers to normal " << (i + 1) << " of "
                                      << attrib.normals.size() / 3);
                    const vec3 normal(attrib.normals[3 * i], attrib.normals[3 * i + 1], attrib.normals[3 * i + 2]);
                    const float length = glm::length(normal);
                    REFRAY_CHECK(allFinite(normal) && std::isfinite(length),
                                 lineOf(obj.lines.normalLines, i) << "normal " << (i + 1) << " is not finite");
                    REFRAY_CHECK(length > 0.0f, lineOf(obj.lines.normalLines, i)
                                                    << "normal " << (i + 1) << " has zero length");
                    v.normal = normal / length;
                }
                if (c.texcoord_index >= 0) {
                    const int i = c.texcoord_index;
                    REFRAY_CHECK(size_t(2 * i + 1) < attrib.texcoords.size(),
                                 file << ": a face refers to texcoord " << (i + 1) << " of "
                                      << attrib.texcoords.size() / 2);
                    v.texcoord = vec2(attrib.texcoords[2 * i], 1.0f - attrib.texcoords[2 * i + 1]);
                    REFRAY_CHECK(std::isfinite(v.texcoord.x) && std::isfinite(v.texcoord.y),
                                 lineOf(obj.lines.texcoordLines, i) << "texcoord " << (i + 1) << " is not finite");
                }
                model.vertices.push_back(v);
            }
            globalMaterials.push_back(f < shape->mesh.material_ids.size() ? shape->mesh.material_ids[f] : -1);
        }
    }
    REFRAY_ASSERT(!model.indices.empty(), "object '" << model.name << "' of " << file << " has no triangle");
    REFRAY_CHECK(model.vertices.size() <= std::numeric_limits<uint32_t>::max(),
                 "model file " << file << " has more than 2^32 vertices");

    // Materials: those the triangles use, in library order, the default one last.
    std::vector<int> used(globalMaterials);
    constexpr int kLast = std::numeric_limits<int>::max();
    std::sort(used.begin(), used.end(), [](int a, int b) { return (a < 0 ? kLast : a) < (b < 0 ? kLast : b); });
    used.erase(std::unique(used.begin(), used.end()), used.end());
    std::map<int, uint32_t> localMaterial;
    for (const int id : used) {
        localMaterial[id] = uint32_t(model.materials.size());
        if (id >= 0) {
            REFRAY_ASSERT(size_t(id) < obj.materials.converted.size(),
                          "material id " << id << " of " << obj.materials.converted.size());
            model.materials.push_back(obj.materials.converted[size_t(id)]);
        } else {
            ModelMaterial fallback;
            fallback.name = kDefaultMaterialName;
            model.materials.push_back(fallback);
        }
    }
    for (const int id : globalMaterials) model.triangleMaterials.push_back(localMaterial.at(id));

    model.hasTangents = std::any_of(model.materials.begin(), model.materials.end(),
                                    [](const ModelMaterial& m) { return !m.normalTexture.empty(); });
    if (model.hasTangents) computeTangents(model);
    return model;
}

}  // namespace

const char* toString(MaterialType type) {
    switch (type) {
    case MaterialType::Diffuse: return "diffuse";
    case MaterialType::Glossy: return "glossy";
    case MaterialType::Emissive: return "emissive";
    }
    return "unknown";
}

float roughnessFromShininess(float shininess) {
    return std::sqrt(2.0f / (std::max(shininess, 0.0f) + 2.0f));
}

Model loadObjModel(const fs::path& path) {
    const ParsedObj obj = parseObj(path);
    std::vector<const tinyobj::shape_t*> shapes;
    for (const tinyobj::shape_t& shape : obj.shapes)
        if (!shape.mesh.num_face_vertices.empty()) shapes.push_back(&shape);
    REFRAY_CHECK(!shapes.empty(), "model file " << path.string() << " holds no triangle");
    return buildModel(obj, shapes, path.stem().string());
}

std::vector<Model> loadObjModels(const fs::path& path) {
    const ParsedObj obj = parseObj(path);
    std::vector<std::string> names;
    std::vector<std::vector<const tinyobj::shape_t*>> groups;
    for (const tinyobj::shape_t& shape : obj.shapes) {
        if (shape.mesh.num_face_vertices.empty()) continue;  // lines or points only
        const std::string name = shape.name.empty() ? path.stem().string() : shape.name;
        const auto it = std::find(names.begin(), names.end(), name);
        if (it == names.end()) {
            names.push_back(name);
            groups.push_back({&shape});
        } else {
            groups[size_t(it - names.begin())].push_back(&shape);
        }
    }
    REFRAY_CHECK(!groups.empty(), "model file " << path.string() << " holds no triangle");
    std::vector<Model> models;
    for (size_t g = 0; g < groups.size(); ++g) models.push_back(buildModel(obj, groups[g], names[g]));
    return models;
}

}  // namespace refray::scenes
