#include "emulator/descriptor_heap.h"

#include <atomic>

#include "core/error.h"

namespace refray::dxr {

namespace {
std::atomic<uint64_t> nextHeapId{1};

const char* heapTypeName(DescriptorHeapType type) {
    return type == DescriptorHeapType::Sampler ? "Sampler" : "CBV_SRV_UAV";
}
}  // namespace

std::string_view toString(Descriptor::Kind kind) {
    switch (kind) {
        case Descriptor::Kind::Null: return "never-written descriptor";
        case Descriptor::Kind::Buffer: return "buffer";
        case Descriptor::Kind::Image: return "Image (RWTexture2D)";
        case Descriptor::Kind::Texture2D: return "Texture2D";
        case Descriptor::Kind::Sampler: return "sampler";
    }
    return "?";
}

DescriptorHeap::DescriptorHeap(uint32_t numDescriptors, std::string name)
    : name_(std::move(name)), base_((0xD000ull + nextHeapId.fetch_add(1)) << 32), descriptors_(numDescriptors) {
    REFRAY_CHECK(numDescriptors > 0, "descriptor heap '" << name_ << "' needs at least one descriptor");
}

GpuDescriptorHandle DescriptorHeap::gpuHandle(uint32_t index) const {
    REFRAY_CHECK(index < size(), "descriptor heap '" << name_ << "' has " << size() << " descriptors, index " << index
                                                     << " is past its end");
    return base_ + uint64_t(index) * kDescriptorSize;
}

void DescriptorHeap::claim(uint32_t index, DescriptorHeapType type) {
    gpuHandle(index);  // range check
    REFRAY_CHECK(!type_ || *type_ == type, "descriptor heap '" << name_ << "' is a " << heapTypeName(*type_)
                                                               << " heap; a " << heapTypeName(type)
                                                               << " descriptor needs a heap of its own type");
    REFRAY_CHECK(type != DescriptorHeapType::Sampler || index < kMaxShaderVisibleSamplerHeapSize,
                 "sampler heap '" << name_ << "': index " << index << " is past the "
                                  << kMaxShaderVisibleSamplerHeapSize << " samplers a shader-visible heap may hold");
    type_ = type;
}

void DescriptorHeap::setBuffer(uint32_t index, DescriptorRangeType type, BufferView view) {
    REFRAY_CHECK(type != DescriptorRangeType::Sampler, "a buffer cannot be a sampler descriptor");
    REFRAY_CHECK(view.address != 0 || view.sizeInBytes == 0,
                 "descriptor " << index << " of heap '" << name_ << "': a view of address 0 (a null descriptor) "
                               << "must have size 0, not " << view.sizeInBytes);
    claim(index, DescriptorHeapType::CBV_SRV_UAV);
    Descriptor d;
    d.kind = Descriptor::Kind::Buffer;
    d.type = type;
    d.buffer = view;
    descriptors_[index] = std::move(d);
}

void DescriptorHeap::setTexture2D(uint32_t index, DescriptorRangeType type, Image* image) {
    REFRAY_CHECK(image, "descriptor " << index << " of heap '" << name_ << "': null texture");
    REFRAY_CHECK(type == DescriptorRangeType::SRV || type == DescriptorRangeType::UAV,
                 "a Texture2D descriptor must be an SRV or a UAV");
    claim(index, DescriptorHeapType::CBV_SRV_UAV);
    Descriptor d;
    d.kind = Descriptor::Kind::Image;
    d.type = type;
    d.image = image;
    descriptors_[index] = std::move(d);
}

void DescriptorHeap::setTexture2D(uint32_t index, Texture2DPtr texture) {
    claim(index, DescriptorHeapType::CBV_SRV_UAV);
    Descriptor d;
    d.kind = Descriptor::Kind::Texture2D;
    d.type = DescriptorRangeType::SRV;
    d.texture = std::move(texture);
    descriptors_[index] = std::move(d);
}

void DescriptorHeap::setSampler(uint32_t index, const SamplerDesc& sampler) {
    validateSamplerDesc(sampler, "sampler descriptor " + std::to_string(index) + " of heap '" + name_ + "'");
    claim(index, DescriptorHeapType::Sampler);
    Descriptor d;
    d.kind = Descriptor::Kind::Sampler;
    d.type = DescriptorRangeType::Sampler;
    d.sampler = sampler;
    descriptors_[index] = std::move(d);
}

bool DescriptorHeap::owns(GpuDescriptorHandle handle) const {
    return handle >= base_ && handle < base_ + uint64_t(size()) * kDescriptorSize &&
           (handle - base_) % kDescriptorSize == 0;
}

uint32_t DescriptorHeap::indexOf(GpuDescriptorHandle handle) const {
    REFRAY_CHECK(owns(handle),
                 "descriptor handle 0x" << std::hex << handle << std::dec << " is not in heap '" << name_ << "'");
    return uint32_t((handle - base_) / kDescriptorSize);
}

const Descriptor& DescriptorHeap::at(GpuDescriptorHandle handle, uint32_t offset) const {
    const uint64_t index = uint64_t(indexOf(handle)) + offset;
    REFRAY_CHECK(index < size(),
                 "descriptor " << index << " is past the end of heap '" << name_ << "' (" << size() << " descriptors)");
    return descriptors_[index];
}

}  // namespace refray::dxr
