#include "procedural/sample_layout.h"

#include <cstring>

namespace refray::procedural {

using namespace refray::dxr;

RootSignatureDesc sampleGlobalRootSignatureDesc(std::string name) {
    RootSignatureDesc desc;
    desc.name = std::move(name);
    desc.parameters = {
        RootParameter::table({DescriptorRange{DescriptorRangeType::UAV, 1, 0, 0, 0}}),  // u0
        RootParameter::srv(0),                                                           // t0
        RootParameter::cbv(0),                                                           // b0
        RootParameter::srv(3),                                                           // t3
        RootParameter::table({DescriptorRange{DescriptorRangeType::SRV, 2, 1, 0, 0}}),  // t1, t2
    };
    return desc;
}

RootSignatureDesc sampleTriangleLocalRootSignatureDesc(std::string name) {
    RootSignatureDesc desc;
    desc.name = std::move(name);
    desc.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    desc.parameters = {RootParameter::constants(sizeof(PrimitiveConstantBuffer) / 4, 1)};
    return desc;
}

RootSignatureDesc sampleProceduralLocalRootSignatureDesc(std::string name) {
    RootSignatureDesc desc = sampleTriangleLocalRootSignatureDesc(std::move(name));
    desc.parameters.push_back(RootParameter::constants(sizeof(PrimitiveInstanceConstantBuffer) / 4, 2));
    return desc;
}

namespace {
// A ByteAddressBuffer dword; past the end it reads 0, as an out-of-bounds buffer load does in D3D12.
uint32_t loadDword(const uint8_t* data, size_t sizeInBytes, uint32_t offset) {
    uint32_t value = 0;
    if (uint64_t(offset) + 4 <= sizeInBytes) std::memcpy(&value, data + offset, 4);
    return value;
}
}  // namespace

Float4x4 rowVectorForm(const Matrix3x4& columnForm) {
    Float4x4 r;
    for (size_t i = 0; i < 3; ++i)
        for (size_t j = 0; j < 3; ++j) r.m[i][j] = columnForm.m[j][i];
    r.m[3] = {columnForm.m[0][3], columnForm.m[1][3], columnForm.m[2][3], 1.0f};
    return r;
}

DMat4 multiply(const DMat4& a, const DMat4& b) {
    DMat4 r{};
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j)
            for (size_t k = 0; k < 4; ++k) r[i][j] += a[i][k] * b[k][j];
    return r;
}

Float4x4 toFloat4x4(const DMat4& m) {
    Float4x4 r;
    for (size_t i = 0; i < 4; ++i)
        for (size_t j = 0; j < 4; ++j) r.m[i][j] = float(m[i][j]);
    return r;
}

uvec3 unpack3x16BitIndices(uint32_t offsetBytes, uvec2 four16BitIndices) {
    const uint32_t dwordAlignedOffset = offsetBytes & ~3u;
    uvec3 result;
    if (dwordAlignedOffset == offsetBytes) {  // aligned: { 0 1 | 2 - }
        result.x = four16BitIndices.x & 0xffff;
        result.y = (four16BitIndices.x >> 16) & 0xffff;
        result.z = four16BitIndices.y & 0xffff;
    } else {  // not aligned: { - 0 | 1 2 }
        result.x = (four16BitIndices.x >> 16) & 0xffff;
        result.y = four16BitIndices.y & 0xffff;
        result.z = (four16BitIndices.y >> 16) & 0xffff;
    }
    return result;
}

vec3 FirstVertexNormal(const dxr::ShaderContext& ctx, uint32_t vertexBuffersTable) {
    const uint32_t indexSizeInBytes = 2;
    const uint32_t indicesPerTriangle = 3;
    const uint32_t triangleIndexStride = indicesPerTriangle * indexSizeInBytes;
    const uint32_t baseIndex = ctx.PrimitiveIndex() * triangleIndexStride;
    const dxr::GpuDescriptorHandle vertexBuffers = ctx.globalDescriptorTable(vertexBuffersTable);
    const uvec3 indices = unpack3x16BitIndices(
        baseIndex, ctx.loadFromTable<uvec2>(vertexBuffers, /*g_indices*/ 0, /*Load2 at*/ baseIndex & ~3u));
    return ctx.loadFromTable<Vertex>(vertexBuffers, /*g_vertices*/ 1, uint64_t(indices[0]) * sizeof(Vertex)).normal;
}

uvec3 Load3x16BitIndices(uint32_t offsetBytes, const uint8_t* indices, size_t sizeInBytes) {
    const uint32_t dwordAlignedOffset = offsetBytes & ~3u;
    return unpack3x16BitIndices(offsetBytes, uvec2(loadDword(indices, sizeInBytes, dwordAlignedOffset),
                                                   loadDword(indices, sizeInBytes, dwordAlignedOffset + 4)));
}

}  // namespace refray::procedural
