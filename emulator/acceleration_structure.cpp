#include "emulator/acceleration_structure.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "emulator/embree_bridge.h"

namespace refray::dxr {

std::string_view toString(Format format) {
    switch (format) {
        case Format::UNKNOWN: return "UNKNOWN";
        case Format::R32G32B32_FLOAT: return "R32G32B32_FLOAT";
        case Format::R32G32_FLOAT: return "R32G32_FLOAT";
        case Format::R16G16B16A16_FLOAT: return "R16G16B16A16_FLOAT";
        case Format::R16G16_FLOAT: return "R16G16_FLOAT";
        case Format::R16G16B16A16_SNORM: return "R16G16B16A16_SNORM";
        case Format::R16G16_SNORM: return "R16G16_SNORM";
        case Format::R16G16B16A16_UNORM: return "R16G16B16A16_UNORM";
        case Format::R16G16_UNORM: return "R16G16_UNORM";
        case Format::R10G10B10A2_UNORM: return "R10G10B10A2_UNORM";
        case Format::R8G8B8A8_UNORM: return "R8G8B8A8_UNORM";
        case Format::R8G8_UNORM: return "R8G8_UNORM";
        case Format::R8G8B8A8_SNORM: return "R8G8B8A8_SNORM";
        case Format::R8G8_SNORM: return "R8G8_SNORM";
        case Format::R16_UINT: return "R16_UINT";
        case Format::R32_UINT: return "R32_UINT";
    }
    return "?";
}

InstanceDesc makeInstanceDesc(const Matrix3x4& transform, uint32_t instanceID, uint32_t mask, uint32_t contribution,
                              uint32_t flags, GpuVirtualAddress blas) {
    InstanceDesc d{};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) d.Transform[r][c] = transform.m[r][c];
    d.InstanceID = instanceID & 0xFFFFFF;
    d.InstanceMask = mask & 0xFF;
    d.InstanceContributionToHitGroupIndex = contribution & 0xFFFFFF;
    d.Flags = flags & 0xFF;
    d.AccelerationStructure = blas;
    return d;
}

Matrix3x4 instanceTransform(const InstanceDesc& desc) {
    Matrix3x4 m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) m.m[r][c] = desc.Transform[r][c];
    return m;
}

BottomLevelAS::~BottomLevelAS() = default;
TopLevelAS::~TopLevelAS() = default;

bool BottomLevelAS::hasActivePrimitive() const {
    for (const auto& g : geometries_)
        if (std::any_of(g.active.begin(), g.active.end(), [](uint8_t a) { return a != 0; })) return true;
    return false;
}

}  // namespace refray::dxr
