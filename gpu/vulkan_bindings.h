// Global root arguments -> Vulkan descriptor sets, by register (gpu/shaders/CONTRACT.md): set = register space,
// binding = register + a shift by register type, as DXC's -fvk-{b,t,u,s}-shift: b (CBV) +0, t (SRV) +100,
// u (UAV) +200, s (sampler) +300. The resource decides the descriptor type: the render target UAV (an Image in
// the descriptor heap) is a storage image (rgba32f), an SRV holding a TLAS an acceleration structure, a CBV a
// uniform buffer, every other SRV or UAV buffer a storage buffer, a Texture2D SRV a sampled image, a static sampler
// an immutable sampler of the set layout and a sampler descriptor a sampler.
//
// An unbounded range of Texture2D SRVs (HLSL `Texture2D t[] : register(t0, space5)`) is one arrayed binding,
// GLSL `texture2D t[]` at binding 100 + its first register, as DXC maps an unbounded array: element i is
// descriptor i of the range. D3D12 leaves the range's end to the shader; the binding holds the run of Texture2D
// descriptors from the range's start up to the first descriptor of another kind or the heap's end (null ones
// included: they read zeros, as in D3D12). An index past that run reads what the device's robustness gives,
// where the emulator reports the descriptor (BIND-4) or the heap's end.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "emulator/device.h"
#include "emulator/texture.h"
#include "gpu/vulkan_api.h"

namespace refray::gpu {

inline constexpr uint32_t kBindingShiftCBV = 0;
inline constexpr uint32_t kBindingShiftSRV = 100;
inline constexpr uint32_t kBindingShiftUAV = 200;
inline constexpr uint32_t kBindingShiftSampler = 300;
uint32_t bindingShift(dxr::DescriptorRangeType type);

// One descriptor of the global root arguments, resolved to what it names.
struct DescriptorBinding {
    enum class Resource : uint8_t {
        Buffer,                 // [address, address + size) of the emulator's GPU memory
        NullBuffer,             // a null buffer view (D3D12 reads zeros): a zero-filled buffer
        StorageImage,           // `image`, the render target
        AccelerationStructure,  // the TLAS at `address`
        SampledImages,          // `textures` (count = textures.size()); nullptr: a null descriptor (reads zeros)
        Sampler,                // `sampler`; `staticSampler`: an immutable sampler of the set layout
    };
    uint32_t set = 0;
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    Resource resource = Resource::Buffer;
    dxr::GpuVirtualAddress address = 0;
    uint64_t size = 0;  // Buffer: bytes of the view; 0: from the address to the end of its buffer (root descriptors)
    Image* image = nullptr;
    std::vector<const dxr::Texture2D*> textures;
    bool runtimeArray = false;  // SampledImages of an unbounded range: GLSL `texture2D t[]`, a runtime array
    dxr::SamplerDesc sampler;
    bool staticSampler = false;
    std::string what;  // "t3, space0 (root SRV, parameter [3])", for errors and the trace
};

// Resolves every register the global root signature binds. Throws refray::Error naming the register for what the
// Vulkan back end does not translate (global root constants, unbounded ranges of anything but Texture2D SRVs, image
// SRVs, samplers vulkan_sampler.h refuses) and for a descriptor that was never written (BIND-4).
std::vector<DescriptorBinding> translateGlobalBindings(const dxr::RootArguments& globals, const dxr::Device& device);

}  // namespace refray::gpu
