// The emulator's shader tables as a Vulkan shader binding table: the same records with the same bytes, except
// that each 32-byte DXR shader identifier becomes the Vulkan group handle of the same export or hit group, and
// each root descriptor (an 8-byte GPU virtual address) in a record's local root arguments becomes the buffer
// device address of the same byte. Record strides and table ranges are the DispatchRaysDesc's.
//
// A pure function of emulator state: tests/gpu/vulkan_shader_table_test.cpp checks it without a GPU.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "emulator/shader_table.h"
#include "emulator/state_object.h"

namespace refray::gpu {

// A Vulkan shader group handle (shaderGroupHandleSize: 32 on NVIDIA, the size of a DXR shader identifier).
using GroupHandle = std::array<uint8_t, 32>;

// One table inside the translated bytes (a VkStridedDeviceAddressRegionKHR relative to the SBT buffer).
struct ShaderTableRegion {
    uint64_t offset = 0;  // a multiple of the base alignment
    uint64_t stride = 0;
    uint64_t size = 0;
    uint64_t records = 0;  // records translated (their identifiers and root descriptors)
};

struct ShaderTableTranslation {
    // The group handle of StateObject::entries()[entry] (the pipeline creates one group per entry, in order).
    std::function<GroupHandle(uint32_t entry)> groupHandle;
    // The device address of the byte at a DXR GPU virtual address; `what` names the root descriptor for errors.
    std::function<uint64_t(uint64_t address, std::string_view what)> deviceAddress;
    uint32_t baseAlignment = 64;    // shaderGroupBaseAlignment
    uint32_t handleAlignment = 32;  // shaderGroupHandleAlignment
    // AOV renders: each hit-group record also carries its own index, as a uint32 at byte `stride` of the record
    // (shaderRecordEXT offset stride - 32); the Vulkan hit-group stride grows to hold it (rounded up to
    // handleAlignment). Off: the strides are the DXR strides.
    bool appendHitGroupRecordIndex = false;
};

struct TranslatedShaderTables {
    std::vector<uint8_t> bytes;  // ray generation, miss, hit-group and callable tables, in that order
    ShaderTableRegion rayGeneration, miss, hitGroup, callable;
    // Byte offset inside a hit-group record's shaderRecordEXT block of the appended record index (AOV renders).
    uint32_t recordIndexOffset = 0;
};

// Translates the four tables of `desc` read from `memory`. Throws refray::Error for an identifier that is not one
// of `stateObject`'s, a local descriptor table (Vulkan records hold no descriptor heap handles), a stride Vulkan
// refuses, or a raygen record larger than the table range.
TranslatedShaderTables translateShaderTables(const dxr::DispatchRaysDesc& desc, const dxr::StateObject& stateObject,
                                             const dxr::GpuMemory& memory, const ShaderTableTranslation& translation);

}  // namespace refray::gpu
