// The resource intrinsics of ShaderContext: memory reads, descriptor-table views and textures, each checked
// against what the dispatch bound.
#include <algorithm>
#include <cstring>

#include "core/error.h"
#include "emulator/detail/dispatch_state.h"
#include "emulator/shader_api.h"

namespace refray::dxr {

using detail::stageError;

const uint8_t* ShaderContext::readMemory(GpuVirtualAddress address, uint64_t size) const {
    try {
        return inv_.dispatch->memory->read(address, size, "shader memory read");
    } catch (const Error& e) {
        stageError(inv_, "GEN-1", e.what());
    }
}

Image& ShaderContext::rwTexture2D(GpuDescriptorHandle tableHandle, uint32_t offset) const {
    const DescriptorHeap* heap = inv_.dispatch->device->findDescriptorHeap(tableHandle);
    if (!heap) stageError(inv_, "GEN-1", "descriptor handle is not in any descriptor heap");
    const Descriptor& d = heap->at(tableHandle, offset);
    if (d.kind != Descriptor::Kind::Texture2D || d.type != DescriptorRangeType::UAV)
        stageError(inv_, "GEN-1", "descriptor " + std::to_string(offset) + " of heap '" + heap->name() +
                                      "' is not a Texture2D UAV (RWTexture2D)");
    return *d.texture;
}

void ShaderContext::readBufferView(GpuDescriptorHandle tableHandle, uint32_t offset, uint64_t byteOffset, uint64_t size,
                                   void* out) const {
    const DescriptorHeap* heap = inv_.dispatch->device->findDescriptorHeap(tableHandle);
    if (!heap) stageError(inv_, "GEN-1", "descriptor handle is not in any descriptor heap");
    const Descriptor& d = heap->at(tableHandle, offset);
    if (d.kind != Descriptor::Kind::Buffer)
        stageError(inv_, "GEN-1", "descriptor " + std::to_string(offset) + " of heap '" + heap->name() +
                                      "' is not a buffer view");
    std::memset(out, 0, size);
    if (byteOffset >= d.buffer.sizeInBytes) return;  // wholly out of range: zeros
    const uint64_t inRange = std::min(size, d.buffer.sizeInBytes - byteOffset);
    std::memcpy(out, readMemory(d.buffer.address + byteOffset, inRange), inRange);
}

}  // namespace refray::dxr
