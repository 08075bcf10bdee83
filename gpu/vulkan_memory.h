// Vulkan buffers and images with their memory, and the map from the emulator's GPU virtual addresses to buffer
// device addresses.
#pragma once

#include <cstdint>
#include <map>
#include <string_view>

#include "core/image.h"
#include "emulator/gpu_memory.h"
#include "gpu/vulkan_context.h"

namespace refray::gpu {

enum class MemoryLocation : uint8_t {
    Device,  // device-local; filled through a staging buffer
    Host,    // host-visible and coherent, mapped for its lifetime
};

// A VkBuffer with its own memory. Usage always includes SHADER_DEVICE_ADDRESS, so address() is valid.
class Buffer {
public:
    Buffer() = default;
    Buffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage, MemoryLocation location);
    ~Buffer();
    Buffer(Buffer&& other) noexcept;
    Buffer& operator=(Buffer&& other) noexcept;

    VkBuffer handle() const { return buffer_; }
    VkDeviceAddress address() const { return address_; }
    VkDeviceSize size() const { return size_; }
    // Host buffers only: the mapped bytes.
    uint8_t* mapped() const { return mapped_; }

private:
    void release();
    const VulkanContext* context_ = nullptr;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceAddress address_ = 0;
    VkDeviceSize size_ = 0;
    uint8_t* mapped_ = nullptr;
};

// A device-local buffer holding `size` bytes of `data`, copied through a staging buffer.
Buffer uploadBuffer(const VulkanContext& context, const void* data, VkDeviceSize size, VkBufferUsageFlags usage);

// What every buffer copied from the emulator's GPU memory may serve as: AS build input, storage or uniform buffer.
inline constexpr VkBufferUsageFlags kEmulatorBufferUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT |
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

// A layout transition of the first `levels` MIP levels of a colour image, ordered after every earlier command.
void imageBarrier(const VulkanFunctions& f, VkCommandBuffer commands, VkImage image, uint32_t levels,
                  VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess, VkAccessFlags dstAccess);

// A device-local 2D image of `format`, `levels` MIP levels and `usage`, its memory bound, and a view of every level:
// what the render target (StorageImage) and the sampled textures (gpu/vulkan_texture.h) are made of. The caller
// destroys the three handles, also when a later step throws (each is set as soon as it exists).
void createDeviceImage2D(const VulkanContext& context, VkFormat format, uint32_t width, uint32_t height, uint32_t levels,
                         VkImageUsageFlags usage, VkImage& image, VkDeviceMemory& memory, VkImageView& view);

// A 2D rgba32f storage image in layout GENERAL (the render target UAV, RWTexture2D<float4>).
class StorageImage {
public:
    StorageImage(const VulkanContext& context, uint32_t width, uint32_t height);
    ~StorageImage();
    StorageImage(const StorageImage&) = delete;
    StorageImage& operator=(const StorageImage&) = delete;

    VkImageView view() const { return view_; }
    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    // Copies the pixels of `image` (same size) in, and leaves the image in layout GENERAL.
    void upload(const Image& image);
    // Copies the image back into `image` (same size); the metadata is left alone.
    void download(Image& image) const;

private:
    const VulkanContext& context_;
    uint32_t width_, height_;
    VkImage image_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkImageView view_ = VK_NULL_HANDLE;
};

// The emulator's GPU memory as Vulkan buffers. The first address that names a byte of an emulator buffer uploads
// that whole buffer (its bytes as they are now) into a device-local VkBuffer; any address inside it then becomes
// that VkBuffer's device address plus the same offset. So root descriptors, AS build inputs and descriptor-heap
// buffer views keep pointing at the same bytes.
class AddressMap {
public:
    AddressMap(const VulkanContext& context, const dxr::GpuMemory& memory) : context_(context), memory_(memory) {}

    struct Resolved {
        VkBuffer buffer = VK_NULL_HANDLE;
        VkDeviceSize offset = 0;       // of the address inside the buffer
        VkDeviceSize bytesToEnd = 0;   // from the address to the end of the buffer
        VkDeviceAddress address = 0;   // the device address of the same byte
    };
    // Throws refray::Error naming `what` when [va, va+bytes) is not inside one emulator buffer.
    Resolved resolve(dxr::GpuVirtualAddress va, uint64_t bytes, std::string_view what);
    VkDeviceAddress translate(dxr::GpuVirtualAddress va, uint64_t bytes, std::string_view what) {
        return resolve(va, bytes, what).address;
    }

private:
    const VulkanContext& context_;
    const dxr::GpuMemory& memory_;
    std::map<dxr::GpuVirtualAddress, Buffer> buffers_;  // by the emulator buffer's base address
};

}  // namespace refray::gpu
