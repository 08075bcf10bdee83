#include "emulator/gpu_memory.h"

#include <algorithm>

#include "core/error.h"
#include "emulator/validation.h"

namespace refray::dxr {

namespace {
constexpr uint64_t kAllocationAlignment = 256;
constexpr uint64_t kGuardGap = 0x10000;

uint64_t alignUp(uint64_t v, uint64_t a) { return (v + a - 1) / a * a; }
}  // namespace

GpuVirtualAddress GpuMemory::allocate(uint64_t sizeInBytes, std::string name) {
    REFRAY_CHECK(sizeInBytes > 0, "cannot allocate an empty GPU buffer '" << name << "'");
    REFRAY_CHECK(sizeInBytes <= (1ull << 36), "GPU buffer '" << name << "' of " << sizeInBytes
                                                               << " bytes is larger than refray's 64 GiB limit");
    auto buffer = std::make_unique<GpuBuffer>();
    buffer->name = std::move(name);
    buffer->base = next_;
    buffer->bytes.assign(sizeInBytes, 0);
    buffer->written.assign(sizeInBytes, 0);
    next_ = alignUp(next_ + sizeInBytes + kGuardGap, kAllocationAlignment);
    const GpuVirtualAddress base = buffer->base;
    buffers_.emplace(base, std::move(buffer));
    return base;
}

GpuVirtualAddress GpuMemory::upload(const void* data, uint64_t sizeInBytes, std::string name) {
    const GpuVirtualAddress va = allocate(sizeInBytes, std::move(name));
    write(va, data, sizeInBytes);
    return va;
}

const GpuBuffer* GpuMemory::find(GpuVirtualAddress va, uint64_t n) const {
    auto it = buffers_.upper_bound(va);
    if (it == buffers_.begin()) return nullptr;
    --it;
    return it->second->contains(va, n) ? it->second.get() : nullptr;
}

GpuBuffer* GpuMemory::find(GpuVirtualAddress va, uint64_t n) {
    return const_cast<GpuBuffer*>(static_cast<const GpuMemory*>(this)->find(va, n));
}

void GpuMemory::write(GpuVirtualAddress va, const void* data, uint64_t n) {
    if (n == 0) return;
    GpuBuffer* buffer = find(va, n);
    REFRAY_CHECK(buffer, "GPU write of " << n << " bytes at 0x" << std::hex << va << std::dec
                                         << " is outside every buffer");
    if (buffer->locked)
        throw DxrError(diag("REC-12", "shader table '" + buffer->name +
                                          "' written while a dispatch that uses it is executing")
                           .hex("address", va)
                           .value("bytes", n));
    const uint64_t offset = va - buffer->base;
    std::memcpy(buffer->bytes.data() + offset, data, n);
    std::fill_n(buffer->written.begin() + offset, n, uint8_t(1));
}

const uint8_t* GpuMemory::read(GpuVirtualAddress va, uint64_t n, std::string_view what) const {
    const GpuBuffer* buffer = find(va, std::max<uint64_t>(n, 1));
    REFRAY_CHECK(buffer, what << ": " << n << " bytes at GPU address 0x" << std::hex << va << std::dec
                              << " are outside every buffer");
    return buffer->bytes.data() + (va - buffer->base);
}

bool GpuMemory::isWritten(GpuVirtualAddress va, uint64_t n) const {
    const GpuBuffer* buffer = find(va, std::max<uint64_t>(n, 1));
    if (!buffer) return false;
    const uint64_t offset = va - buffer->base;
    return std::all_of(buffer->written.begin() + offset, buffer->written.begin() + offset + n,
                       [](uint8_t w) { return w != 0; });
}

void GpuMemory::setLocked(GpuVirtualAddress va, bool locked) {
    if (GpuBuffer* buffer = find(va)) buffer->locked = locked;
}

}  // namespace refray::dxr
