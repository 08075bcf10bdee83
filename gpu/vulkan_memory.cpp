#include "gpu/vulkan_memory.h"

#include <cstring>
#include <utility>

namespace refray::gpu {

Buffer::Buffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage, MemoryLocation location)
    : context_(&context), size_(size) {
    const VulkanFunctions& f = context.vk();
    auto info = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = size;
    info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    REFRAY_VK(f.vkCreateBuffer(context.device(), &info, nullptr, &buffer_));
    try {
        VkMemoryRequirements requirements;
        f.vkGetBufferMemoryRequirements(context.device(), buffer_, &requirements);
        const VkMemoryPropertyFlags flags = location == MemoryLocation::Device
                                                ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT
                                                : VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        auto addressable = vkStruct<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
        addressable.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        auto allocate = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &addressable);
        allocate.allocationSize = requirements.size;
        allocate.memoryTypeIndex = context.memoryType(requirements.memoryTypeBits, flags);
        REFRAY_VK(f.vkAllocateMemory(context.device(), &allocate, nullptr, &memory_));
        REFRAY_VK(f.vkBindBufferMemory(context.device(), buffer_, memory_, 0));
        if (location == MemoryLocation::Host) {
            void* p = nullptr;
            REFRAY_VK(f.vkMapMemory(context.device(), memory_, 0, VK_WHOLE_SIZE, 0, &p));
            mapped_ = static_cast<uint8_t*>(p);
        }
        auto addressInfo = vkStruct<VkBufferDeviceAddressInfo>(VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO);
        addressInfo.buffer = buffer_;
        address_ = f.vkGetBufferDeviceAddress(context.device(), &addressInfo);
    } catch (...) {
        release();
        throw;
    }
}

Buffer::~Buffer() { release(); }

Buffer::Buffer(Buffer&& other) noexcept { *this = std::move(other); }

Buffer& Buffer::operator=(Buffer&& other) noexcept {
    if (this != &other) {
        release();
        context_ = std::exchange(other.context_, nullptr);
        buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
        address_ = std::exchange(other.address_, 0);
        size_ = std::exchange(other.size_, 0);
        mapped_ = std::exchange(other.mapped_, nullptr);
    }
    return *this;
}

void Buffer::release() {
    if (!context_) return;
    const VulkanFunctions& f = context_->vk();
    if (mapped_) f.vkUnmapMemory(context_->device(), memory_);
    if (buffer_) f.vkDestroyBuffer(context_->device(), buffer_, nullptr);
    if (memory_) f.vkFreeMemory(context_->device(), memory_, nullptr);
    context_ = nullptr;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    mapped_ = nullptr;
}

Buffer uploadBuffer(const VulkanContext& context, const void* data, VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer staging(context, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryLocation::Host);
    std::memcpy(staging.mapped(), data, size);
    Buffer buffer(context, size, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryLocation::Device);
    context.submitAndWait([&](VkCommandBuffer commands) {
        const VkBufferCopy region{0, 0, size};
        context.vk().vkCmdCopyBuffer(commands, staging.handle(), buffer.handle(), 1, &region);
    });
    return buffer;
}

// Storage image.

void imageBarrier(const VulkanFunctions& f, VkCommandBuffer commands, VkImage image, uint32_t levels,
                  VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess, VkAccessFlags dstAccess) {
    auto barrier = vkStruct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
    barrier.srcAccessMask = srcAccess;
    barrier.dstAccessMask = dstAccess;
    barrier.oldLayout = from;
    barrier.newLayout = to;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, levels, 0, 1};
    f.vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                           nullptr, 0, nullptr, 1, &barrier);
}

void createDeviceImage2D(const VulkanContext& context, VkFormat format, uint32_t width, uint32_t height, uint32_t levels,
                         VkImageUsageFlags usage, VkImage& image, VkDeviceMemory& memory, VkImageView& view) {
    const VulkanFunctions& f = context.vk();
    auto info = vkStruct<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = levels;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    REFRAY_VK(f.vkCreateImage(context.device(), &info, nullptr, &image));
    VkMemoryRequirements requirements;
    f.vkGetImageMemoryRequirements(context.device(), image, &requirements);
    auto allocate = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = context.memoryType(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    REFRAY_VK(f.vkAllocateMemory(context.device(), &allocate, nullptr, &memory));
    REFRAY_VK(f.vkBindImageMemory(context.device(), image, memory, 0));
    auto viewInfo = vkStruct<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    viewInfo.image = image;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, levels, 0, 1};
    REFRAY_VK(f.vkCreateImageView(context.device(), &viewInfo, nullptr, &view));
}

StorageImage::StorageImage(const VulkanContext& context, uint32_t width, uint32_t height)
    : context_(context), width_(width), height_(height) {
    createDeviceImage2D(context, VK_FORMAT_R32G32B32A32_SFLOAT, width, height, 1,
                        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                        image_, memory_, view_);
}

StorageImage::~StorageImage() {
    const VulkanFunctions& f = context_.vk();
    if (view_) f.vkDestroyImageView(context_.device(), view_, nullptr);
    if (image_) f.vkDestroyImage(context_.device(), image_, nullptr);
    if (memory_) f.vkFreeMemory(context_.device(), memory_, nullptr);
}

namespace {

VkBufferImageCopy wholeImage(uint32_t width, uint32_t height) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    return region;
}

}  // namespace

void StorageImage::upload(const Image& image) {
    REFRAY_ASSERT(image.width() == width_ && image.height() == height_,
                  image.width() << "x" << image.height() << " vs " << width_ << "x" << height_);
    const VkDeviceSize bytes = VkDeviceSize(width_) * height_ * sizeof(vec4);
    Buffer staging(context_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryLocation::Host);
    std::memcpy(staging.mapped(), image.pixels().data(), bytes);
    const VulkanFunctions& f = context_.vk();
    context_.submitAndWait([&](VkCommandBuffer commands) {
        imageBarrier(f, commands, image_, 1, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                     VK_ACCESS_TRANSFER_WRITE_BIT);
        const VkBufferImageCopy region = wholeImage(width_, height_);
        f.vkCmdCopyBufferToImage(commands, staging.handle(), image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        imageBarrier(f, commands, image_, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                     VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    });
}

void StorageImage::download(Image& image) const {
    REFRAY_ASSERT(image.width() == width_ && image.height() == height_,
                  image.width() << "x" << image.height() << " vs " << width_ << "x" << height_);
    const VkDeviceSize bytes = VkDeviceSize(width_) * height_ * sizeof(vec4);
    Buffer staging(context_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryLocation::Host);
    const VulkanFunctions& f = context_.vk();
    context_.submitAndWait([&](VkCommandBuffer commands) {
        imageBarrier(f, commands, image_, 1, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        const VkBufferImageCopy region = wholeImage(width_, height_);
        f.vkCmdCopyImageToBuffer(commands, image_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.handle(), 1, &region);
        imageBarrier(f, commands, image_, 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                     VK_ACCESS_TRANSFER_READ_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    });
    std::memcpy(image.pixels().data(), staging.mapped(), bytes);
}

// Address map.

AddressMap::Resolved AddressMap::resolve(dxr::GpuVirtualAddress va, uint64_t bytes, std::string_view what) {
    const dxr::GpuBuffer* source = memory_.find(va, bytes ? bytes : 1);
    REFRAY_CHECK(source, what << ": " << bytes << " bytes at GPU address 0x" << std::hex << va << std::dec
                              << " are not inside one buffer of the emulator's GPU memory, so they have no Vulkan "
                                 "device address");
    auto it = buffers_.find(source->base);
    if (it == buffers_.end())
        it = buffers_.emplace(source->base, uploadBuffer(context_, source->bytes.data(), source->size(), kEmulatorBufferUsage))
                 .first;
    Resolved r;
    r.buffer = it->second.handle();
    r.offset = va - source->base;
    r.bytesToEnd = source->size() - r.offset;
    r.address = it->second.address() + r.offset;
    return r;
}

}  // namespace refray::gpu
