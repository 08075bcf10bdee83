#include "gpu/vulkan_sampler.h"

#include "core/error.h"

namespace refray::gpu {

namespace {

VkFilter filterOf(uint32_t d3dFilter, uint32_t bit) {
    return (d3dFilter & bit) != 0 ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
}

VkSamplerAddressMode addressModeOf(dxr::TextureAddressMode mode, const char* field, const std::string& what) {
    switch (mode) {
        case dxr::TEXTURE_ADDRESS_MODE_WRAP: return VK_SAMPLER_ADDRESS_MODE_REPEAT;
        case dxr::TEXTURE_ADDRESS_MODE_MIRROR: return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
        case dxr::TEXTURE_ADDRESS_MODE_CLAMP: return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        case dxr::TEXTURE_ADDRESS_MODE_BORDER: return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
        case dxr::TEXTURE_ADDRESS_MODE_MIRROR_ONCE:
            throw Error(what + ": " + field + " is MIRROR_ONCE; its Vulkan twin MIRROR_CLAMP_TO_EDGE needs the "
                                              "samplerMirrorClampToEdge feature, which the Vulkan back end does not "
                                              "enable");
    }
    throw Error(what + ": " + field + " is not a D3D12_TEXTURE_ADDRESS_MODE (" + std::to_string(uint32_t(mode)) + ")");
}

}  // namespace

VkSamplerCreateInfo samplerCreateInfo(const dxr::SamplerDesc& desc, const std::string& what) {
    dxr::validateSamplerDesc(desc, what);  // the same refusals as the emulator (BIND-10)
    auto info = vkStruct<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
    // FILTER_ANISOTROPIC (0x55) has every linear bit set, so it maps to trilinear like the emulator's SampleLevel.
    const uint32_t filter = desc.Filter;
    info.mipmapMode = (filter & 0x1u) != 0 ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
    info.magFilter = filterOf(filter, 0x4u);
    info.minFilter = filterOf(filter, 0x10u);
    info.anisotropyEnable = VK_FALSE;
    info.maxAnisotropy = 1.0f;
    info.addressModeU = addressModeOf(desc.AddressU, "AddressU", what);
    info.addressModeV = addressModeOf(desc.AddressV, "AddressV", what);
    info.addressModeW = addressModeOf(desc.AddressW, "AddressW", what);
    info.mipLodBias = desc.MipLODBias;
    info.minLod = desc.MinLOD;
    info.maxLod = desc.MaxLOD;
    info.compareEnable = VK_FALSE;
    info.unnormalizedCoordinates = VK_FALSE;
    info.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
    const bool border = desc.AddressU == dxr::TEXTURE_ADDRESS_MODE_BORDER ||
                        desc.AddressV == dxr::TEXTURE_ADDRESS_MODE_BORDER ||
                        desc.AddressW == dxr::TEXTURE_ADDRESS_MODE_BORDER;
    if (border) {
        const vec4 c = desc.BorderColor;
        if (c == dxr::toColor(dxr::STATIC_BORDER_COLOR_TRANSPARENT_BLACK))
            info.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
        else if (c == dxr::toColor(dxr::STATIC_BORDER_COLOR_OPAQUE_BLACK))
            info.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_BLACK;
        else if (c == dxr::toColor(dxr::STATIC_BORDER_COLOR_OPAQUE_WHITE))
            info.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
        else
            throw Error(what + ": BorderColor (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " +
                        std::to_string(c.z) + ", " + std::to_string(c.w) +
                        ") is none of Vulkan's fixed border colours (transparent black, opaque black, opaque white); "
                        "others need VK_EXT_custom_border_color, which the Vulkan back end does not use");
    }
    return info;
}

Sampler::Sampler(const VulkanContext& context, const dxr::SamplerDesc& desc, const std::string& what)
    : context_(context) {
    const VkSamplerCreateInfo info = samplerCreateInfo(desc, what);
    REFRAY_VK(context.vk().vkCreateSampler(context.device(), &info, nullptr, &sampler_));
}

Sampler::~Sampler() {
    if (sampler_) context_.vk().vkDestroySampler(context_.device(), sampler_, nullptr);
}

}  // namespace refray::gpu
