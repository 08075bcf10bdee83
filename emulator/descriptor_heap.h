// Shader-visible descriptor heaps: what a descriptor table's GPU handle points at.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "emulator/root_signature.h"

namespace refray::dxr {

using GpuDescriptorHandle = uint64_t;

struct BufferView {
    GpuVirtualAddress address = 0;
    uint64_t sizeInBytes = 0;
    uint32_t structureByteStride = 0;  // 0 for raw (ByteAddressBuffer) and constant buffers
};

struct Descriptor {
    enum class Kind : uint8_t { Null, Buffer, Texture2D };
    Kind kind = Kind::Null;
    DescriptorRangeType type = DescriptorRangeType::SRV;
    BufferView buffer;
    Image* texture = nullptr;  // not owned; a float RGBA texture (UAV: RWTexture2D<float4>)
};

// A CBV_SRV_UAV heap. Handles are base + 32 * index, with a base unique to the heap.
class DescriptorHeap {
public:
    static constexpr uint32_t kDescriptorSize = 32;

    DescriptorHeap(uint32_t numDescriptors, std::string name);
    const std::string& name() const { return name_; }
    uint32_t size() const { return uint32_t(descriptors_.size()); }
    GpuDescriptorHandle gpuHandle(uint32_t index) const;

    void setBuffer(uint32_t index, DescriptorRangeType type, BufferView view);
    void setTexture2D(uint32_t index, DescriptorRangeType type, Image* texture);

    bool owns(GpuDescriptorHandle handle) const;
    // The descriptor at `handle` + `offset` descriptors; throws naming the heap when outside it.
    const Descriptor& at(GpuDescriptorHandle handle, uint32_t offset = 0) const;

private:
    std::string name_;
    GpuDescriptorHandle base_;
    std::vector<Descriptor> descriptors_;
};

}  // namespace refray::dxr
