// "bottomLevel": the bottom-level structures and their geometries: triangles (inline, from a buffer, an OBJ mesh or a
// model) and AABBs.
#include <algorithm>
#include <cstring>
#include <filesystem>

#include "core/error.h"
#include "core/strings.h"
#include "scenes/loader/parse_context.h"
#include "scenes/mesh.h"

namespace refray::scenes::loader {

namespace {

// The scene's model buffer of `kind`, or an error at `where` saying to declare it.
uint32_t modelBuffer(const ParseContext& ctx, BufferDesc::Kind kind, const Value& where) {
    for (size_t i = 0; i < ctx.scene.buffers.size(); ++i)
        if (ctx.scene.buffers[i].kind == kind) return uint32_t(i);
    where.fail("a geometry from a model reads the models' vertex and index buffers; declare them in 'buffers': "
               "\"vertices\": {\"generate\": \"modelVertices\"}, \"indices\": {\"generate\": \"modelIndices\"}");
}

GeometryDescFile parseTriangles(ParseContext& ctx, ObjectReader& r, const std::string& prefix) {
    GeometryDescFile g;
    g.type = dxr::GeometryType::Triangles;
    if (const Value* model = r.optional("model")) {
        // The model's range of the global buffers, as a DXR path tracer's host builds one BLAS per model:
        // positions at byte 0 of each 48-byte VertexGPU, 32-bit indices local to the model.
        if (r.optional("mesh") || r.optional("vertices") || r.optional("indices"))
            model->fail("a triangle geometry takes 'model', 'mesh' or 'vertices' (and 'indices'), one of them");
        g.model = int32_t(resolveName(*model, ctx.modelNames, "model"));
        const ObjectGPU& range = ctx.scene.modelBuffers.modelRanges[size_t(g.model)];
        g.vertexBuffer = modelBuffer(ctx, BufferDesc::Kind::ModelVertices, *model);
        g.vertexOffset = uint64_t(range.vertexOffset) * sizeof(VertexGPU);
        g.vertexStride = uint32_t(sizeof(VertexGPU));
        g.vertexCount = range.vertexCount;
        g.vertexFormat = dxr::Format::R32G32B32_FLOAT;
        g.indexBuffer = int32_t(modelBuffer(ctx, BufferDesc::Kind::ModelIndices, *model));
        g.indexOffset = uint64_t(range.indexOffset) * sizeof(uint32_t);
        g.indexCount = range.indexCount;
        g.indexFormat = dxr::Format::R32_UINT;
        return g;
    }
    if (const Value* mesh = r.optional("mesh")) {
        // An OBJ file, relative to the scene file: its positions and triangulated faces become two buffers.
        if (r.optional("vertices") || r.optional("indices"))
            mesh->fail("a triangle geometry takes 'mesh' or 'vertices' (and 'indices'), not both");
        // Relative to the file that wrote the value (a lesson's base keeps its own directory).
        const std::filesystem::path path = std::filesystem::path(mesh->location().file).parent_path() / mesh->asString();
        TriangleMesh data;
        try {
            data = loadObjMesh(path);
        } catch (const Error& e) {
            mesh->fail(e.what());
        }
        BufferDesc positions;
        positions.name = prefix + "/mesh positions";
        positions.stride = 12;
        positions.bytes.resize(data.positions.size() * sizeof(vec3));
        std::memcpy(positions.bytes.data(), data.positions.data(), positions.bytes.size());
        g.vertexCount = uint32_t(data.positions.size());
        g.vertexBuffer = addBuffer(ctx, std::move(positions), *mesh);
        BufferDesc indices;
        indices.name = prefix + "/mesh indices";
        indices.bytes.resize(data.indices.size() * 4);
        std::memcpy(indices.bytes.data(), data.indices.data(), indices.bytes.size());
        g.indexCount = uint32_t(data.indices.size());
        g.indexFormat = dxr::Format::R32_UINT;
        g.indexBuffer = int32_t(addBuffer(ctx, std::move(indices), *mesh));
        return g;
    }
    const Value& vertices = r.required("vertices");
    if (vertices.isArray()) {
        BufferDesc b;
        b.name = prefix + "/vertices";
        b.stride = 12;
        for (const Value& v : vertices.asArray()) {
            const vec3 p = floatVector<3>(v, "a vertex position");
            b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&p), reinterpret_cast<const uint8_t*>(&p) + 12);
        }
        if (b.bytes.empty()) vertices.fail("a triangle geometry needs vertices");
        g.vertexCount = uint32_t(b.bytes.size() / 12);
        g.vertexBuffer = addBuffer(ctx, std::move(b), vertices);
    } else {
        ObjectReader vr(vertices, "vertices");
        g.vertexBuffer = uint32_t(dataBuffer(ctx, vr.required("buffer")));
        const BufferDesc& b = ctx.scene.buffers[g.vertexBuffer];
        g.vertexStride = vr.required("stride").asUint32();
        if (const Value* o = vr.optional("offset")) g.vertexOffset = o->asUint32();
        if (const Value* f = vr.optional("format")) {
            const uint32_t fi = resolveName(*f, {"R32G32B32_FLOAT", "R32G32_FLOAT"}, "vertex format");
            g.vertexFormat = fi == 0 ? dxr::Format::R32G32B32_FLOAT : dxr::Format::R32G32_FLOAT;
        }
        if (g.vertexStride == 0) vertices.fail("the vertex stride must not be 0");
        const uint64_t available = b.bytes.size() > g.vertexOffset ? (b.bytes.size() - g.vertexOffset) / g.vertexStride : 0;
        g.vertexCount = uint32_t(available);
        if (const Value* c = vr.optional("count")) {
            g.vertexCount = c->asUint32();
            if (g.vertexCount > available)
                c->fail(std::to_string(g.vertexCount) + " vertices of stride " + std::to_string(g.vertexStride) +
                        " do not fit in buffer " + inQuotes(b.name) + " (" + std::to_string(b.bytes.size()) + " bytes)");
        }
        vr.finish();
    }
    if (const Value* indices = r.optional("indices")) {
        if (indices->isArray()) {
            BufferDesc b;
            b.name = prefix + "/indices";
            for (const Value& v : indices->asArray()) {
                const uint32_t i = v.asUint32();
                b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&i), reinterpret_cast<const uint8_t*>(&i) + 4);
            }
            g.indexCount = uint32_t(indices->asArray().size());
            g.indexFormat = dxr::Format::R32_UINT;
            g.indexBuffer = int32_t(addBuffer(ctx, std::move(b), *indices));
        } else {
            ObjectReader ir(*indices, "indices");
            g.indexBuffer = dataBuffer(ctx, ir.required("buffer"));
            const uint32_t fi = resolveName(ir.required("format"), {"R16_UINT", "R32_UINT"}, "index format");
            g.indexFormat = fi == 0 ? dxr::Format::R16_UINT : dxr::Format::R32_UINT;
            if (const Value* o = ir.optional("offset")) g.indexOffset = o->asUint32();
            const uint64_t size = fi == 0 ? 2 : 4;
            const BufferDesc& b = ctx.scene.buffers[size_t(g.indexBuffer)];
            const uint64_t available = b.bytes.size() > g.indexOffset ? (b.bytes.size() - g.indexOffset) / size : 0;
            g.indexCount = uint32_t(available);
            if (const Value* c = ir.optional("count")) {
                g.indexCount = c->asUint32();
                if (g.indexCount > available)
                    c->fail(std::to_string(g.indexCount) + " indices do not fit in buffer " + inQuotes(b.name));
            }
            ir.finish();
        }
        if (g.indexCount == 0 || g.indexCount % 3 != 0)
            indices->fail("a triangle list needs a positive multiple of 3 indices, got " + std::to_string(g.indexCount));
    } else if (g.vertexCount % 3 != 0) {
        vertices.fail("without indices, a triangle list needs a multiple of 3 vertices, got " +
                      std::to_string(g.vertexCount));
    }
    return g;
}

}  // namespace

void parseBottomLevel(ParseContext& ctx, const Value& value) {
    static const std::vector<std::pair<std::string, uint32_t>> buildFlags = {
        {"PREFER_FAST_TRACE", dxr::BUILD_FLAG_PREFER_FAST_TRACE},
        {"PREFER_FAST_BUILD", dxr::BUILD_FLAG_PREFER_FAST_BUILD},
        {"ALLOW_UPDATE", dxr::BUILD_FLAG_ALLOW_UPDATE},
        {"ALLOW_COMPACTION", dxr::BUILD_FLAG_ALLOW_COMPACTION},
        {"MINIMIZE_MEMORY", dxr::BUILD_FLAG_MINIMIZE_MEMORY}};
    static const std::vector<std::pair<std::string, uint32_t>> geometryFlags = {
        {"OPAQUE", dxr::GEOMETRY_FLAG_OPAQUE},
        {"NO_DUPLICATE_ANYHIT_INVOCATION", dxr::GEOMETRY_FLAG_NO_DUPLICATE_ANYHIT_INVOCATION}};
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a bottom-level structure");
        BlasDesc blas;
        blas.name = nonEmptyName(r.required("name"), "a BLAS name");
        r.setWhat("bottom-level structure " + inQuotes(blas.name));
        if (std::find(ctx.blasNames.begin(), ctx.blasNames.end(), blas.name) != ctx.blasNames.end())
            v.fail("two bottom-level structures are named " + inQuotes(blas.name));
        blas.where = v.location();
        if (const Value* f = r.optional("flags")) blas.buildFlags = flagSet(*f, buildFlags, "build flag");
        const Value& geometries = r.required("geometries");
        for (const Value& gv : geometries.asArray()) {
            const std::string prefix = blas.name + "/" + std::to_string(blas.geometries.size());
            ObjectReader gr(gv, "geometry " + std::to_string(blas.geometries.size()) + " of BLAS " + inQuotes(blas.name));
            const uint32_t type = resolveName(gr.required("type"), {"triangles", "aabbs"}, "geometry type");
            GeometryDescFile g;
            if (type == 0) {
                g = parseTriangles(ctx, gr, prefix);
            } else {
                g.type = dxr::GeometryType::ProceduralPrimitiveAABBs;
                const Value& boxes = gr.required("aabbs");
                BufferDesc b;
                b.name = prefix + "/aabbs";
                b.stride = sizeof(dxr::RaytracingAABB);
                for (const Value& bv : boxes.asArray()) {
                    const auto& a = bv.asArray();
                    if (a.size() != 6) bv.fail("an AABB is [minX, minY, minZ, maxX, maxY, maxZ]");
                    for (const Value& n : a) {
                        const float f = n.asFloat();
                        b.bytes.insert(b.bytes.end(), reinterpret_cast<const uint8_t*>(&f),
                                       reinterpret_cast<const uint8_t*>(&f) + 4);
                    }
                }
                g.aabbCount = uint32_t(boxes.asArray().size());
                if (g.aabbCount == 0) boxes.fail("an AABB geometry needs at least one box");
                g.aabbBuffer = addBuffer(ctx, std::move(b), boxes);
            }
            if (const Value* f = gr.optional("flags")) g.flags = flagSet(*f, geometryFlags, "geometry flag");
            gr.finish();
            blas.geometries.push_back(g);
        }
        if (blas.geometries.empty()) geometries.fail("BLAS " + inQuotes(blas.name) + " has no geometries");
        r.finish();
        ctx.blasNames.push_back(blas.name);
        ctx.scene.blases.push_back(std::move(blas));
    }
}

}  // namespace refray::scenes::loader
