#include "gpu/vulkan_texture.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "gpu/vulkan_memory.h"

namespace refray::gpu {

namespace {

constexpr VkFormat kTextureFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

struct Level {
    uint32_t width = 1, height = 1;
    std::vector<vec4> texels;
};

// The levels to upload: the texture's own, checked against the chain Vulkan derives from level 0.
std::vector<Level> levelsOf(const dxr::Texture2D* texture, const std::string& what) {
    if (!texture) return {Level{1, 1, {vec4(0.0f)}}};
    std::vector<Level> levels(texture->mipLevels());
    for (uint32_t m = 0; m < levels.size(); ++m) {
        const uint32_t width = std::max(1u, texture->width() >> m), height = std::max(1u, texture->height() >> m);
        REFRAY_CHECK(texture->width(m) == width && texture->height(m) == height,
                     what << ": MIP level " << m << " of texture '" << texture->path() << "' is " << texture->width(m)
                          << "x" << texture->height(m) << "; Vulkan's chain has " << width << "x" << height
                          << " there (each level halves the last, rounding down, at least 1)");
        levels[m].width = width;
        levels[m].height = height;
        levels[m].texels = texture->readLevel(m);
    }
    return levels;
}

}  // namespace

SampledTexture::SampledTexture(const VulkanContext& context, const dxr::Texture2D* texture, const std::string& what)
    : context_(context) {
    const VulkanFunctions& f = context.vk();
    VkFormatProperties format{};
    f.vkGetPhysicalDeviceFormatProperties(context.physicalDevice(), kTextureFormat, &format);
    constexpr VkFormatFeatureFlags kNeeded =
        VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
    REFRAY_CHECK((format.optimalTilingFeatures & kNeeded) == kNeeded,
                 what << ": the device cannot sample R32G32B32A32_SFLOAT images with linear filtering, the format the "
                         "Vulkan back end uploads textures in");
    const std::vector<Level> levels = levelsOf(texture, what);
    mipLevels_ = uint32_t(levels.size());

    try {
        createDeviceImage2D(context, kTextureFormat, levels[0].width, levels[0].height, mipLevels_,
                            VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, image_, memory_, view_);

        // Every level through one staging buffer, one copy region per level.
        VkDeviceSize bytes = 0;
        std::vector<VkBufferImageCopy> regions;
        for (uint32_t m = 0; m < mipLevels_; ++m) {
            VkBufferImageCopy region{};
            region.bufferOffset = bytes;
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
            region.imageExtent = {levels[m].width, levels[m].height, 1};
            regions.push_back(region);
            bytes += levels[m].texels.size() * sizeof(vec4);
        }
        Buffer staging(context, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryLocation::Host);
        for (uint32_t m = 0; m < mipLevels_; ++m)
            std::memcpy(staging.mapped() + regions[m].bufferOffset, levels[m].texels.data(),
                        levels[m].texels.size() * sizeof(vec4));
        context.submitAndWait([&](VkCommandBuffer commands) {
            imageBarrier(f, commands, image_, mipLevels_, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT);
            f.vkCmdCopyBufferToImage(commands, staging.handle(), image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                     uint32_t(regions.size()), regions.data());
            imageBarrier(f, commands, image_, mipLevels_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_ACCESS_SHADER_READ_BIT);
        });
    } catch (...) {
        release();  // a constructor that throws runs no destructor
        throw;
    }
}

SampledTexture::~SampledTexture() { release(); }

void SampledTexture::release() {
    const VulkanFunctions& f = context_.vk();
    if (view_) f.vkDestroyImageView(context_.device(), view_, nullptr);
    if (image_) f.vkDestroyImage(context_.device(), image_, nullptr);
    if (memory_) f.vkFreeMemory(context_.device(), memory_, nullptr);
    view_ = VK_NULL_HANDLE;
    image_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
}

}  // namespace refray::gpu
