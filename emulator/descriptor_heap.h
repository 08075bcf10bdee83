// Shader-visible descriptor heaps: what a descriptor table's GPU handle points at.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "emulator/root_signature.h"
#include "emulator/texture.h"

namespace refray::dxr {

using GpuDescriptorHandle = uint64_t;

// A buffer view (the D3D12 SRV/UAV/CBV desc of a buffer). Address 0 with size 0 is a null descriptor: every read
// returns zeros, as D3D12 defines for a null view.
struct BufferView {
    GpuVirtualAddress address = 0;
    uint64_t sizeInBytes = 0;
    uint32_t structureByteStride = 0;  // 0 for raw (ByteAddressBuffer) and constant buffers
};

struct Descriptor {
    enum class Kind : uint8_t {
        Null,       // nothing was ever written here (the default); reading it is an error (BIND-4)
        Buffer,     // `buffer`: a buffer SRV, UAV or CBV
        Image,      // `image`: a float RGBA Image, written by RWTexture2D<float4> (UAV)
        Texture2D,  // `texture`: a read-only Texture2D SRV; nullptr is a null descriptor (reads return zeros)
        Sampler,    // `sampler`
    };
    Kind kind = Kind::Null;
    DescriptorRangeType type = DescriptorRangeType::SRV;  // Sampler for a sampler
    BufferView buffer;
    Image* image = nullptr;  // not owned
    Texture2DPtr texture;
    SamplerDesc sampler;
};
std::string_view toString(Descriptor::Kind kind);

// D3D12_DESCRIPTOR_HEAP_TYPE of a shader-visible heap.
enum class DescriptorHeapType : uint8_t { CBV_SRV_UAV, Sampler };
// D3D12_MAX_SHADER_VISIBLE_SAMPLER_HEAP_SIZE.
inline constexpr uint32_t kMaxShaderVisibleSamplerHeapSize = 2048;

// A shader-visible descriptor heap. Handles are base + 32 * index, with a base unique to the heap.
//
// D3D12 gives a heap its type when it is made; refray's Device::createDescriptorHeap takes no type, so a heap
// takes the type of the first descriptor written to it (a sampler: Sampler, anything else: CBV_SRV_UAV) and
// refuses descriptors of the other type after that. Writes happen on the host, between dispatches.
class DescriptorHeap {
public:
    static constexpr uint32_t kDescriptorSize = 32;

    DescriptorHeap(uint32_t numDescriptors, std::string name);
    const std::string& name() const { return name_; }
    uint32_t size() const { return uint32_t(descriptors_.size()); }
    // Empty until the first descriptor is written.
    std::optional<DescriptorHeapType> type() const { return type_; }
    GpuDescriptorHandle gpuHandle(uint32_t index) const;

    // A buffer view; BufferView{} (address 0, size 0) writes a null descriptor of `type`.
    void setBuffer(uint32_t index, DescriptorRangeType type, BufferView view);
    // An Image as an SRV or UAV (RWTexture2D<float4>, ShaderContext::rwTexture2D).
    void setTexture2D(uint32_t index, DescriptorRangeType type, Image* image);
    // A read-only Texture2D SRV (ShaderContext::Texture2D); nullptr writes a null Texture2D descriptor.
    void setTexture2D(uint32_t index, Texture2DPtr texture);
    // A sampler; throws DxrError BIND-10 for a sampler D3D12 would refuse (validateSamplerDesc), refray::Error past
    // kMaxShaderVisibleSamplerHeapSize.
    void setSampler(uint32_t index, const SamplerDesc& sampler);

    bool owns(GpuDescriptorHandle handle) const;
    // The index of the descriptor at `handle`; the handle must be owned.
    uint32_t indexOf(GpuDescriptorHandle handle) const;
    // The descriptor at `handle` + `offset` descriptors; throws naming the heap when outside it.
    const Descriptor& at(GpuDescriptorHandle handle, uint32_t offset = 0) const;
    const Descriptor& descriptor(uint32_t index) const { return descriptors_.at(index); }

private:
    void claim(uint32_t index, DescriptorHeapType type);
    std::string name_;
    GpuDescriptorHandle base_;
    std::optional<DescriptorHeapType> type_;
    std::vector<Descriptor> descriptors_;
};

}  // namespace refray::dxr
