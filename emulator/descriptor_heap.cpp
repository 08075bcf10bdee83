#include "emulator/descriptor_heap.h"

#include <atomic>

#include "core/error.h"

namespace refray::dxr {

namespace {
std::atomic<uint64_t> nextHeapId{1};
}

DescriptorHeap::DescriptorHeap(uint32_t numDescriptors, std::string name)
    : name_(std::move(name)), base_((0xD000ull + nextHeapId.fetch_add(1)) << 32), descriptors_(numDescriptors) {
    REFRAY_CHECK(numDescriptors > 0, "descriptor heap '" << name_ << "' needs at least one descriptor");
}

GpuDescriptorHandle DescriptorHeap::gpuHandle(uint32_t index) const {
    REFRAY_CHECK(index < size(), "descriptor heap '" << name_ << "' has " << size() << " descriptors, index "
                                                     << index << " is past its end");
    return base_ + uint64_t(index) * kDescriptorSize;
}

void DescriptorHeap::setBuffer(uint32_t index, DescriptorRangeType type, BufferView view) {
    gpuHandle(index);  // range check
    REFRAY_CHECK(type != DescriptorRangeType::Sampler, "a buffer cannot be a sampler descriptor");
    descriptors_[index] = Descriptor{Descriptor::Kind::Buffer, type, view, nullptr};
}

void DescriptorHeap::setTexture2D(uint32_t index, DescriptorRangeType type, Image* texture) {
    gpuHandle(index);
    REFRAY_CHECK(texture, "descriptor " << index << " of heap '" << name_ << "': null texture");
    REFRAY_CHECK(type == DescriptorRangeType::SRV || type == DescriptorRangeType::UAV,
                 "a Texture2D descriptor must be an SRV or a UAV");
    descriptors_[index] = Descriptor{Descriptor::Kind::Texture2D, type, {}, texture};
}

bool DescriptorHeap::owns(GpuDescriptorHandle handle) const {
    return handle >= base_ && handle < base_ + uint64_t(size()) * kDescriptorSize && (handle - base_) % kDescriptorSize == 0;
}

const Descriptor& DescriptorHeap::at(GpuDescriptorHandle handle, uint32_t offset) const {
    REFRAY_CHECK(owns(handle), "descriptor handle 0x" << std::hex << handle << std::dec << " is not in heap '" << name_
                                                      << "'");
    const uint64_t index = (handle - base_) / kDescriptorSize + offset;
    REFRAY_CHECK(index < size(), "descriptor " << index << " is past the end of heap '" << name_ << "' (" << size()
                                               << " descriptors)");
    return descriptors_[index];
}

}  // namespace refray::dxr
