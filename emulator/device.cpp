#include "emulator/device.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <embree3/rtcore.h>

#include "emulator/embree_bridge.h"
#include "emulator/limits.h"

namespace refray::dxr {

namespace {

float halfToFloat(uint16_t h) {
    const uint32_t sign = uint32_t(h >> 15) << 31, exponent = (h >> 10) & 0x1F, mantissa = h & 0x3FF;
    uint32_t bits;
    if (exponent == 0) {
        if (mantissa == 0) {
            bits = sign;
        } else {  // subnormal half: normalise
            int e = -1;
            uint32_t m = mantissa;
            do {
                ++e;
                m <<= 1;
            } while (!(m & 0x400));
            bits = sign | uint32_t(127 - 15 - e) << 23 | (m & 0x3FF) << 13;
        }
    } else if (exponent == 31) {
        bits = sign | 0x7F800000u | mantissa << 13;
    } else {
        bits = sign | (exponent + 127 - 15) << 23 | mantissa << 13;
    }
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

// D3D conversion rules: SNORM maps -max to -1 and clamps the extra negative code to -1.
float snorm(int32_t v, int bits) { return std::max(float(v) / float((1 << (bits - 1)) - 1), -1.0f); }
float unorm(uint32_t v, int bits) { return float(v) / float((1u << bits) - 1); }

struct VertexFormatInfo {
    uint32_t bytes;           // bytes read per vertex
    uint32_t componentBytes;  // alignment unit of address and stride (BLAS-4)
    bool canEncodeNaN;
};

std::optional<VertexFormatInfo> vertexFormatInfo(Format f) {
    switch (f) {
        case Format::R32G32B32_FLOAT: return VertexFormatInfo{12, 4, true};
        case Format::R32G32_FLOAT: return VertexFormatInfo{8, 4, true};
        case Format::R16G16B16A16_FLOAT: return VertexFormatInfo{8, 2, true};
        case Format::R16G16_FLOAT: return VertexFormatInfo{4, 2, true};
        case Format::R16G16B16A16_SNORM:
        case Format::R16G16B16A16_UNORM: return VertexFormatInfo{8, 2, false};
        case Format::R16G16_SNORM:
        case Format::R16G16_UNORM: return VertexFormatInfo{4, 2, false};
        case Format::R10G10B10A2_UNORM: return VertexFormatInfo{4, 4, false};
        case Format::R8G8B8A8_UNORM:
        case Format::R8G8B8A8_SNORM: return VertexFormatInfo{4, 1, false};
        case Format::R8G8_UNORM:
        case Format::R8G8_SNORM: return VertexFormatInfo{2, 1, false};
        default: return std::nullopt;
    }
}

vec3 decodeVertex(Format f, const uint8_t* p) {
    auto rd16 = [&](int i) { uint16_t v; std::memcpy(&v, p + 2 * i, 2); return v; };
    auto rdf = [&](int i) { float v; std::memcpy(&v, p + 4 * i, 4); return v; };
    switch (f) {
        case Format::R32G32B32_FLOAT: return {rdf(0), rdf(1), rdf(2)};
        case Format::R32G32_FLOAT: return {rdf(0), rdf(1), 0.0f};
        case Format::R16G16B16A16_FLOAT: return {halfToFloat(rd16(0)), halfToFloat(rd16(1)), halfToFloat(rd16(2))};
        case Format::R16G16_FLOAT: return {halfToFloat(rd16(0)), halfToFloat(rd16(1)), 0.0f};
        case Format::R16G16B16A16_SNORM:
            return {snorm(int16_t(rd16(0)), 16), snorm(int16_t(rd16(1)), 16), snorm(int16_t(rd16(2)), 16)};
        case Format::R16G16_SNORM: return {snorm(int16_t(rd16(0)), 16), snorm(int16_t(rd16(1)), 16), 0.0f};
        case Format::R16G16B16A16_UNORM: return {unorm(rd16(0), 16), unorm(rd16(1), 16), unorm(rd16(2), 16)};
        case Format::R16G16_UNORM: return {unorm(rd16(0), 16), unorm(rd16(1), 16), 0.0f};
        case Format::R10G10B10A2_UNORM: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return {unorm(v & 0x3FF, 10), unorm((v >> 10) & 0x3FF, 10), unorm((v >> 20) & 0x3FF, 10)};
        }
        case Format::R8G8B8A8_UNORM: return {unorm(p[0], 8), unorm(p[1], 8), unorm(p[2], 8)};
        case Format::R8G8_UNORM: return {unorm(p[0], 8), unorm(p[1], 8), 0.0f};
        case Format::R8G8B8A8_SNORM: return {snorm(int8_t(p[0]), 8), snorm(int8_t(p[1]), 8), snorm(int8_t(p[2]), 8)};
        case Format::R8G8_SNORM: return {snorm(int8_t(p[0]), 8), snorm(int8_t(p[1]), 8), 0.0f};
        default: return vec3(0.0f);
    }
}

std::string geometryName(uint32_t g) { return "geometry " + std::to_string(g); }

void checkBuildFlags(uint32_t flags, const char* what) {
    if ((flags & BUILD_FLAG_PREFER_FAST_TRACE) && (flags & BUILD_FLAG_PREFER_FAST_BUILD))
        throw DxrError(diag("UPD-4", std::string(what) + " build sets both PREFER_FAST_TRACE and PREFER_FAST_BUILD")
                           .hex("Flags", flags));
}

void checkUpdateSource(uint32_t sourceFlags, uint32_t flags, const char* what) {
    if (!(sourceFlags & BUILD_FLAG_ALLOW_UPDATE))
        throw DxrError(diag("UPD-1", std::string(what) + " update of a structure built without ALLOW_UPDATE")
                           .hex("source Flags", sourceFlags));
    if ((sourceFlags & ~BUILD_FLAG_PERFORM_UPDATE) != (flags & ~BUILD_FLAG_PERFORM_UPDATE))
        throw DxrError(diag("UPD-1", std::string(what) + " update with build flags other than the source's")
                           .hex("source Flags", sourceFlags)
                           .hex("update Flags", flags));
}

// Decodes one geometry desc into object-space primitives (BLAS-3..8, DEGEN-1/2/8).
BuiltGeometry buildGeometry(const GpuMemory& memory, const GeometryDesc& desc, uint32_t g, BuildLog& log) {
    BuiltGeometry out;
    out.type = desc.Type;
    out.flags = desc.Flags;
    if (desc.Flags & ~kDefinedGeometryFlags)
        throw DxrError(diag("BLAS-2", geometryName(g) + " sets undefined geometry flag bits")
                           .hex("Flags", desc.Flags)
                           .hex("undefined bits", desc.Flags & ~kDefinedGeometryFlags));

    if (desc.Type == GeometryType::ProceduralPrimitiveAABBs) {
        const auto& a = desc.AABBs;
        if (a.AABBs.StartAddress % kAABBByteAlignment || a.AABBs.StrideInBytes % kAABBByteAlignment)
            throw DxrError(diag("BLAS-6", geometryName(g) + ": AABB address and stride must be multiples of 8")
                               .hex("StartAddress", a.AABBs.StartAddress)
                               .value("StrideInBytes", a.AABBs.StrideInBytes));
        if (a.AABBCount > kMaxPrimitivesPerBottomLevelAS)
            throw DxrError(diag("BLAS-9", geometryName(g) + " has too many AABBs")
                               .value("AABBCount", a.AABBCount, std::to_string(kMaxPrimitivesPerBottomLevelAS)));
        out.aabbs.resize(a.AABBCount);
        out.active.assign(a.AABBCount, 1);
        for (uint64_t i = 0; i < a.AABBCount; ++i) {
            RaytracingAABB box;
            std::memcpy(&box, memory.read(a.AABBs.StartAddress + a.AABBs.StrideInBytes * i, sizeof box,
                                          geometryName(g) + " AABB " + std::to_string(i)),
                        sizeof box);
            if (std::isnan(box.MinX)) {  // DEGEN-1: inactive
                out.active[i] = 0;
                out.aabbs[i] = box;
                continue;
            }
            const float values[6] = {box.MinX, box.MinY, box.MinZ, box.MaxX, box.MaxY, box.MaxZ};
            static const char* names[6] = {"MinX", "MinY", "MinZ", "MaxX", "MaxY", "MaxZ"};
            for (int c = 1; c < 6; ++c)
                if (std::isnan(values[c]))
                    throw DxrError(diag("DEGEN-2", geometryName(g) + " AABB " + std::to_string(i) + " has a NaN " +
                                                       names[c] + " while MinX is a number")
                                       .value("geometry", g)
                                       .value("primitive", i)
                                       .value("component", names[c]));
            if (box.MinX > box.MaxX || box.MinY > box.MaxY || box.MinZ > box.MaxZ) {
                // DEGEN-8: an inverted box becomes the point at its centre.
                log.add(warning("DEGEN-8", geometryName(g) + " AABB " + std::to_string(i) +
                                               " is inverted; it becomes the point at its centre")
                            .value("geometry", g)
                            .value("primitive", i));
                const float cx = 0.5f * (box.MinX + box.MaxX), cy = 0.5f * (box.MinY + box.MaxY),
                            cz = 0.5f * (box.MinZ + box.MaxZ);
                box = {cx, cy, cz, cx, cy, cz};
            }
            out.aabbs[i] = box;
        }
        return out;
    }

    // Triangles.
    const auto& t = desc.Triangles;
    const auto format = vertexFormatInfo(t.VertexFormat);
    if (!format)
        throw DxrError(diag("BLAS-4", geometryName(g) + " uses a vertex format DXR does not accept")
                           .value("VertexFormat", toString(t.VertexFormat)));
    if (t.VertexBuffer.StartAddress % format->componentBytes || (t.VertexBuffer.StrideInBytes & 0xFFFFFFFF) % format->componentBytes)
        throw DxrError(diag("BLAS-4", geometryName(g) + ": vertex address and stride must be multiples of the component size")
                           .hex("StartAddress", t.VertexBuffer.StartAddress)
                           .value("StrideInBytes", t.VertexBuffer.StrideInBytes)
                           .value("component bytes", format->componentBytes));
    if (t.VertexFormat == Format::R10G10B10A2_UNORM && (t.VertexBuffer.StrideInBytes & 0xFFFFFFFF) != 4)
        throw DxrError(diag("BLAS-4", geometryName(g) + ": R10G10B10A2_UNORM vertices need a stride of 4")
                           .value("StrideInBytes", t.VertexBuffer.StrideInBytes, "4"));
    uint32_t indexBytes = 0;
    if (t.IndexFormat == Format::R16_UINT) indexBytes = 2;
    else if (t.IndexFormat == Format::R32_UINT) indexBytes = 4;
    else if (t.IndexFormat != Format::UNKNOWN)
        throw DxrError(diag("BLAS-3", geometryName(g) + " uses an index format other than R16_UINT, R32_UINT or UNKNOWN")
                           .value("IndexFormat", toString(t.IndexFormat)));
    if (t.IndexFormat == Format::UNKNOWN && (t.IndexBuffer != 0 || t.IndexCount != 0))
        throw DxrError(diag("BLAS-3", geometryName(g) + " is non-indexed (IndexFormat UNKNOWN) but has an index buffer or count")
                           .hex("IndexBuffer", t.IndexBuffer)
                           .value("IndexCount", t.IndexCount, "0"));
    if (indexBytes && t.IndexBuffer % indexBytes)
        throw DxrError(diag("BLAS-3", geometryName(g) + ": the index buffer address is not aligned to the index size")
                           .hex("IndexBuffer", t.IndexBuffer)
                           .value("index bytes", indexBytes));
    if (t.Transform3x4 % kTransform3x4ByteAlignment)
        throw DxrError(diag("BLAS-5", geometryName(g) + ": Transform3x4 must be 16-byte aligned")
                           .hex("Transform3x4", t.Transform3x4));

    const uint32_t elementCount = indexBytes ? t.IndexCount : t.VertexCount;
    if (elementCount % 3)
        log.add(warning("BLAS-3", geometryName(g) + ": the " + (indexBytes ? "index" : "vertex") +
                                      " count is not a multiple of 3; the trailing entries are ignored")
                    .value("count", elementCount));
    const uint32_t triangleCount = elementCount / 3;
    if (triangleCount > kMaxPrimitivesPerBottomLevelAS)
        throw DxrError(diag("BLAS-9", geometryName(g) + " has too many triangles")
                           .value("triangles", triangleCount, std::to_string(kMaxPrimitivesPerBottomLevelAS)));

    std::optional<Matrix3x4> transform;
    if (t.Transform3x4) {
        Matrix3x4 m;
        std::memcpy(&m.m, memory.read(t.Transform3x4, 48, geometryName(g) + " Transform3x4"), 48);
        transform = m;
        out.hasTransform = true;
    }
    const uint64_t stride = t.VertexBuffer.StrideInBytes & 0xFFFFFFFF;  // BLAS-4: low 32 bits
    auto vertex = [&](uint32_t index) -> vec3 {
        if (index >= t.VertexCount)
            throw DxrError(diag("BLAS-3", geometryName(g) + " references a vertex past VertexCount")
                               .value("index", index)
                               .value("VertexCount", t.VertexCount, "> largest index"));
        vec3 v = decodeVertex(t.VertexFormat, memory.read(t.VertexBuffer.StartAddress + stride * index, format->bytes,
                                                          geometryName(g) + " vertex " + std::to_string(index)));
        return transform ? transform->transformPoint(v) : v;
    };
    auto index = [&](uint32_t i) -> uint32_t {
        if (!indexBytes) return i;
        const uint8_t* p = memory.read(t.IndexBuffer + uint64_t(i) * indexBytes, indexBytes,
                                       geometryName(g) + " index " + std::to_string(i));
        if (indexBytes == 2) {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return v;
        }
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    };

    out.triangleVertices.resize(size_t(triangleCount) * 3);
    out.active.assign(triangleCount, 1);
    static const char* axis[3] = {"x", "y", "z"};
    for (uint32_t tri = 0; tri < triangleCount; ++tri) {
        vec3 v[3];
        for (int k = 0; k < 3; ++k) {
            const uint32_t i = index(tri * 3 + k);
            if (indexBytes) out.indices.push_back(i);
            v[k] = vertex(i);
        }
        if (std::isnan(v[0].x) || std::isnan(v[1].x) || std::isnan(v[2].x)) {
            out.active[tri] = 0;  // DEGEN-1
        } else {
            for (int k = 0; k < 3; ++k)
                for (int c = 1; c < 3; ++c)
                    if (std::isnan(v[k][c]))
                        throw DxrError(diag("DEGEN-2", geometryName(g) + " triangle " + std::to_string(tri) + " vertex " +
                                                           std::to_string(k) + " has a NaN " + axis[c] +
                                                           " while every x is a number")
                                           .value("geometry", g)
                                           .value("primitive", tri)
                                           .value("vertex", k)
                                           .value("component", axis[c]));
        }
        for (int k = 0; k < 3; ++k) out.triangleVertices[size_t(tri) * 3 + k] = v[k];
    }
    return out;
}

// UPD-2: only vertex positions, Transform3x4 contents and AABB values may change.
void checkBottomLevelUpdate(const BottomLevelInputs& before, const BottomLevelInputs& after) {
    if (before.GeometryDescs.size() != after.GeometryDescs.size())
        throw DxrError(diag("UPD-2", "BLAS update changes the number of geometries")
                           .value("before", before.GeometryDescs.size())
                           .value("after", after.GeometryDescs.size()));
    for (size_t g = 0; g < before.GeometryDescs.size(); ++g) {
        const auto &a = before.GeometryDescs[g], &b = after.GeometryDescs[g];
        const std::string where = geometryName(uint32_t(g));
        auto differ = [&](const char* field, uint64_t x, uint64_t y) {
            if (x != y)
                throw DxrError(diag("UPD-2", "BLAS update changes " + std::string(field) + " of " + where)
                                   .value("before", x)
                                   .value("after", y));
        };
        differ("the geometry type", uint64_t(a.Type), uint64_t(b.Type));
        differ("the flags", a.Flags, b.Flags);
        if (a.Type == GeometryType::Triangles) {
            differ("IndexFormat", uint64_t(a.Triangles.IndexFormat), uint64_t(b.Triangles.IndexFormat));
            differ("VertexFormat", uint64_t(a.Triangles.VertexFormat), uint64_t(b.Triangles.VertexFormat));
            differ("IndexCount", a.Triangles.IndexCount, b.Triangles.IndexCount);
            differ("VertexCount", a.Triangles.VertexCount, b.Triangles.VertexCount);
            differ("whether Transform3x4 is NULL", a.Triangles.Transform3x4 == 0, b.Triangles.Transform3x4 == 0);
        } else {
            differ("AABBCount", a.AABBs.AABBCount, b.AABBs.AABBCount);
        }
    }
}

}  // namespace

Device::Device() : embree_(std::make_unique<detail::EmbreeDevice>()) {}
Device::~Device() {
    // Scenes reference the Embree device: release them first.
    topLevel_.clear();
    bottomLevel_.clear();
}

DescriptorHeap& Device::createDescriptorHeap(uint32_t numDescriptors, std::string name) {
    heaps_.push_back(std::make_unique<DescriptorHeap>(numDescriptors, std::move(name)));
    return *heaps_.back();
}

const DescriptorHeap* Device::findDescriptorHeap(GpuDescriptorHandle handle) const {
    for (const auto& h : heaps_)
        if (h->owns(handle)) return h.get();
    return nullptr;
}

GpuVirtualAddress Device::buildBottomLevelAS(const BottomLevelInputs& inputs, GpuVirtualAddress source) {
    checkBuildFlags(inputs.Flags, "BLAS");
    if (inputs.GeometryDescs.size() > kMaxGeometriesPerBottomLevelAS)
        throw DxrError(diag("BLAS-9", "BLAS has too many geometries")
                           .value("geometries", inputs.GeometryDescs.size(), std::to_string(kMaxGeometriesPerBottomLevelAS)));
    for (size_t g = 1; g < inputs.GeometryDescs.size(); ++g)
        if (inputs.GeometryDescs[g].Type != inputs.GeometryDescs[0].Type)
            throw DxrError(diag("BLAS-1", "BLAS mixes triangle and AABB geometry; " + geometryName(uint32_t(g)) +
                                              " is the first of the other type")
                               .value("geometry 0 type", inputs.GeometryDescs[0].Type == GeometryType::Triangles ? "TRIANGLES" : "PROCEDURAL_PRIMITIVE_AABBS")
                               .value("first other", g));

    std::vector<BuiltGeometry> geometries;
    uint64_t primitives = 0;
    for (uint32_t g = 0; g < inputs.GeometryDescs.size(); ++g) {
        geometries.push_back(buildGeometry(memory_, inputs.GeometryDescs[g], g, buildLog_));
        primitives += geometries.back().primitiveCount();
    }
    if (primitives > kMaxPrimitivesPerBottomLevelAS)
        throw DxrError(diag("BLAS-9", "BLAS has too many primitives over all its geometries")
                           .value("primitives", primitives, std::to_string(kMaxPrimitivesPerBottomLevelAS)));

    if (inputs.Flags & BUILD_FLAG_PERFORM_UPDATE) {
        auto it = bottomLevel_.find(source);
        if (it == bottomLevel_.end())
            throw DxrError(diag("UPD-1", "BLAS update names a source that is not a BLAS").hex("source", source));
        BottomLevelAS& blas = *it->second;
        checkUpdateSource(blas.buildFlags_, inputs.Flags, "BLAS");
        checkBottomLevelUpdate(blas.inputs_, inputs);
        for (size_t g = 0; g < geometries.size(); ++g)
            if (geometries[g].indices != blas.geometries_[g].indices)
                throw DxrError(diag("UPD-2", "BLAS update changes the index data of " + geometryName(uint32_t(g)))
                                   .value("geometry", g));
        for (size_t g = 0; g < geometries.size(); ++g)
            for (size_t p = 0; p < geometries[g].active.size(); ++p)
                if (geometries[g].active[p] != blas.geometries_[g].active[p])
                    throw DxrError(diag("DEGEN-5", "BLAS update makes " + geometryName(uint32_t(g)) + " primitive " +
                                                       std::to_string(p) + (geometries[g].active[p] ? " active" : " inactive"))
                                       .value("geometry", g)
                                       .value("primitive", p));
        // Update in place: same vectors, so Embree's user geometries keep valid pointers.
        for (size_t g = 0; g < geometries.size(); ++g) {
            blas.geometries_[g].triangleVertices = std::move(geometries[g].triangleVertices);
            blas.geometries_[g].aabbs = std::move(geometries[g].aabbs);
        }
        blas.inputs_ = inputs;
        auto scene = static_cast<RTCScene>(blas.embree_->scene);
        for (uint32_t g = 0; g < blas.geometries_.size(); ++g) rtcCommitGeometry(rtcGetGeometry(scene, g));
        rtcCommitScene(scene);
        blas.generation_.fetch_add(1);
        epoch_.fetch_add(1);
        return source;
    }

    auto blas = std::make_unique<BottomLevelAS>();
    blas->address_ = memory_.allocate(kAccelerationStructureByteAlignment, "BLAS");
    blas->buildFlags_ = inputs.Flags;
    blas->inputs_ = inputs;
    blas->geometries_ = std::move(geometries);
    blas->embree_ = detail::buildBottomLevelScene(*embree_, *blas);
    const GpuVirtualAddress address = blas->address_;
    bottomLevel_.emplace(address, std::move(blas));
    epoch_.fetch_add(1);
    return address;
}

GpuVirtualAddress Device::buildTopLevelAS(const TopLevelInputs& inputs, GpuVirtualAddress source) {
    checkBuildFlags(inputs.Flags, "TLAS");
    if (inputs.NumDescs > kMaxInstancesPerTopLevelAS)
        throw DxrError(diag("INST-7", "TLAS has too many instances")
                           .value("NumDescs", inputs.NumDescs, std::to_string(kMaxInstancesPerTopLevelAS)));
    if (inputs.NumDescs && inputs.InstanceDescs % kInstanceDescsByteAlignment)
        throw DxrError(diag("INST-1", "instance descs must be 16-byte aligned").hex("InstanceDescs", inputs.InstanceDescs));

    std::vector<BuiltInstance> instances(inputs.NumDescs);
    for (uint32_t i = 0; i < inputs.NumDescs; ++i) {
        GpuVirtualAddress descAddress = inputs.InstanceDescs + uint64_t(i) * sizeof(InstanceDesc);
        if (inputs.DescsLayout == ElementsLayout::ArrayOfPointers) {
            std::memcpy(&descAddress, memory_.read(inputs.InstanceDescs + uint64_t(i) * 8, 8,
                                                   "instance desc pointer " + std::to_string(i)),
                        8);
            if (descAddress % kInstanceDescsByteAlignment)
                throw DxrError(diag("INST-1", "instance desc " + std::to_string(i) + " is not 16-byte aligned")
                                   .hex("address", descAddress));
        }
        BuiltInstance& inst = instances[i];
        std::memcpy(&inst.desc, memory_.read(descAddress, sizeof(InstanceDesc), "instance desc " + std::to_string(i)),
                    sizeof(InstanceDesc));
        const uint32_t flags = inst.desc.Flags;
        if (flags & ~kDefinedInstanceFlags)
            throw DxrError(diag("INST-5", "instance " + std::to_string(i) +
                                              " sets instance flags refray does not support (opacity micromaps are rejected, EXT-1)")
                               .hex("Flags", flags)
                               .hex("unsupported bits", flags & ~kDefinedInstanceFlags));
        if ((flags & INSTANCE_FLAG_FORCE_OPAQUE) && (flags & INSTANCE_FLAG_FORCE_NON_OPAQUE))
            throw DxrError(diag("INST-5", "instance " + std::to_string(i) + " sets both FORCE_OPAQUE and FORCE_NON_OPAQUE")
                               .value("InstanceIndex", i)
                               .value("Flags", instanceFlagsToString(flags)));
        const GpuVirtualAddress blasAddress = inst.desc.AccelerationStructure;
        if (blasAddress == 0) continue;  // inactive (INST-6)
        auto it = bottomLevel_.find(blasAddress);
        if (it == bottomLevel_.end()) {
            const bool isTopLevel = topLevel_.count(blasAddress) != 0;
            throw DxrError(diag("INST-6", "instance " + std::to_string(i) + " references " +
                                              (isTopLevel ? "a TLAS" : "an address that is not a BLAS"))
                               .value("InstanceIndex", i)
                               .hex("AccelerationStructure", blasAddress));
        }
        inst.objectToWorld = instanceTransform(inst.desc);
        auto inverse = affineInverse(inst.objectToWorld);
        if (!inverse) {
            buildLog_.add(warning("INST-9", "instance " + std::to_string(i) +
                                                " has a singular or non-finite transform; it is treated as inactive")
                              .value("InstanceIndex", i)
                              .value("determinant", inst.objectToWorld.determinant3x3()));
            continue;
        }
        inst.worldToObject = *inverse;
        inst.blas = it->second.get();
        inst.blasGeneration = inst.blas->generation();
    }

    if (inputs.Flags & BUILD_FLAG_PERFORM_UPDATE) {
        auto it = topLevel_.find(source);
        if (it == topLevel_.end())
            throw DxrError(diag("UPD-1", "TLAS update names a source that is not a TLAS").hex("source", source));
        TopLevelAS& tlas = *it->second;
        checkUpdateSource(tlas.buildFlags_, inputs.Flags, "TLAS");
        if (tlas.instances_.size() != instances.size())
            throw DxrError(diag("UPD-3", "TLAS update changes the number of instances")
                               .value("before", tlas.instances_.size())
                               .value("after", instances.size()));
        for (size_t i = 0; i < instances.size(); ++i)
            if ((tlas.instances_[i].desc.AccelerationStructure == 0) != (instances[i].desc.AccelerationStructure == 0))
                throw DxrError(diag("DEGEN-5", "TLAS update changes whether instance " + std::to_string(i) + " is active")
                                   .value("InstanceIndex", i));
        tlas.instances_ = std::move(instances);
        tlas.embree_ = detail::buildTopLevelScene(*embree_, tlas);
        tlas.checkedEpoch_.store(~0ull);
        return source;
    }

    auto tlas = std::make_unique<TopLevelAS>();
    tlas->address_ = memory_.allocate(kAccelerationStructureByteAlignment, "TLAS");
    tlas->buildFlags_ = inputs.Flags;
    tlas->instances_ = std::move(instances);
    tlas->embree_ = detail::buildTopLevelScene(*embree_, *tlas);
    const GpuVirtualAddress address = tlas->address_;
    topLevel_.emplace(address, std::move(tlas));
    return address;
}

const BottomLevelAS* Device::findBottomLevelAS(GpuVirtualAddress address) const {
    auto it = bottomLevel_.find(address);
    return it == bottomLevel_.end() ? nullptr : it->second.get();
}

const TopLevelAS* Device::findTopLevelAS(GpuVirtualAddress address) const {
    auto it = topLevel_.find(address);
    return it == topLevel_.end() ? nullptr : it->second.get();
}

}  // namespace refray::dxr
