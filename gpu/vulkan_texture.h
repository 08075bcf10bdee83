// A read-only Texture2D SRV (emulator/texture.h) as a Vulkan sampled image: every MIP level the emulator samples,
// with the texels the emulator filters (Texture2D::readLevel: expanded to RGBA, sRGB decoded per texel), so the
// Vulkan sampler (vulkan_sampler.h) and the emulator weigh the same values.
//
// Format R32G32B32A32_SFLOAT whatever the file's: an 8-bit file's texels are value / 255 in float, exactly what
// the emulator reads, and an sRGB texture arrives decoded (a *_SRGB format decodes per texel before filtering
// too). Layout SHADER_READ_ONLY_OPTIMAL after the upload.
#pragma once

#include <cstdint>
#include <string>

#include "emulator/texture.h"
#include "gpu/vulkan_context.h"

namespace refray::gpu {

class SampledTexture {
public:
    // Uploads `texture`; nullptr makes D3D's null descriptor, a 1x1 texture of (0, 0, 0, 0). Throws refray::Error
    // naming `what` and the file when the device cannot sample rgba32f images with linear filtering, or when the
    // file's own MIP levels are not the chain Vulkan requires (level m = max(1, size >> m)).
    SampledTexture(const VulkanContext& context, const dxr::Texture2D* texture, const std::string& what);
    ~SampledTexture();
    SampledTexture(const SampledTexture&) = delete;
    SampledTexture& operator=(const SampledTexture&) = delete;

    VkImageView view() const { return view_; }
    uint32_t mipLevels() const { return mipLevels_; }

private:
    void release();
    const VulkanContext& context_;
    uint32_t mipLevels_ = 1;
    VkImage image_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkImageView view_ = VK_NULL_HANDLE;
};

}  // namespace refray::gpu
