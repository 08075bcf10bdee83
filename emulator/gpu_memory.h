// Simulated GPU memory: buffers at virtual addresses, so shader tables, instance descs and
// root descriptors are real bytes at real addresses, exactly as the DXR API sees them.
#pragma once

#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "emulator/types.h"

namespace refray::dxr {

struct GpuBuffer {
    std::string name;
    GpuVirtualAddress base = 0;
    std::vector<uint8_t> bytes;
    std::vector<uint8_t> written;  // shadow map: 1 where the host ever wrote the byte (REC-7)
    bool locked = false;           // true while a dispatch reads it as a shader table (REC-12)

    uint64_t size() const { return bytes.size(); }
    bool contains(GpuVirtualAddress va, uint64_t n) const { return va >= base && va - base <= size() && n <= size() - (va - base); }
};

// Owns every buffer. Addresses are 256-byte aligned, start at 64 KiB and leave a
// 64 KiB hole after each buffer, so an address past one buffer never lands in the next.
// Host writes happen between dispatches; reads during a dispatch are concurrent.
class GpuMemory {
public:
    GpuVirtualAddress allocate(uint64_t sizeInBytes, std::string name);
    // Allocates and writes in one step.
    GpuVirtualAddress upload(const void* data, uint64_t sizeInBytes, std::string name);
    template <class T>
    GpuVirtualAddress upload(const std::vector<T>& values, std::string name) {
        return upload(values.data(), values.size() * sizeof(T), std::move(name));
    }

    // Host write; marks the bytes written. Throws if the range is not inside one buffer,
    // or (REC-12) if the buffer is locked by an executing dispatch.
    void write(GpuVirtualAddress va, const void* data, uint64_t n);

    // The buffer holding [va, va+n), or nullptr.
    const GpuBuffer* find(GpuVirtualAddress va, uint64_t n = 1) const;
    GpuBuffer* find(GpuVirtualAddress va, uint64_t n = 1);
    // Pointer to [va, va+n); throws refray::Error naming `what` when the range is not mapped.
    // `what` names the read in the error; a view, so a literal costs nothing when the read succeeds.
    const uint8_t* read(GpuVirtualAddress va, uint64_t n, std::string_view what) const;
    // True if every byte of [va, va+n) was written by the host.
    bool isWritten(GpuVirtualAddress va, uint64_t n) const;

    void setLocked(GpuVirtualAddress va, bool locked);

private:
    std::map<GpuVirtualAddress, std::unique_ptr<GpuBuffer>> buffers_;  // keyed by base
    GpuVirtualAddress next_ = 0x10000;
};

}  // namespace refray::dxr
