#include "gpu/vulkan_sampler.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace refray::gpu {
namespace {

dxr::SamplerDesc samplerWith(dxr::SamplerFilter filter,
                             dxr::TextureAddressMode address = dxr::TEXTURE_ADDRESS_MODE_WRAP) {
    dxr::SamplerDesc s;
    s.Filter = filter;
    s.AddressU = s.AddressV = s.AddressW = address;
    return s;
}

std::string errorOf(const dxr::SamplerDesc& desc) {
    try {
        samplerCreateInfo(desc, "s2, space3 (static sampler 0)");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// Each D3D12_FILTER bit (mip 0x1, mag 0x4, min 0x10) picks LINEAR or NEAREST for its own stage.
TEST(VulkanSampler, FilterBitsMapStageByStage) {
    struct Case {
        dxr::SamplerFilter filter;
        VkFilter min, mag;
        VkSamplerMipmapMode mip;
    };
    const Case cases[] = {
        {dxr::FILTER_MIN_MAG_MIP_POINT, VK_FILTER_NEAREST, VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST},
        {dxr::FILTER_MIN_MAG_POINT_MIP_LINEAR, VK_FILTER_NEAREST, VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_LINEAR},
        {dxr::FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT, VK_FILTER_NEAREST, VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST},
        {dxr::FILTER_MIN_LINEAR_MAG_MIP_POINT, VK_FILTER_LINEAR, VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST},
        {dxr::FILTER_MIN_MAG_LINEAR_MIP_POINT, VK_FILTER_LINEAR, VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST},
        {dxr::FILTER_MIN_MAG_MIP_LINEAR, VK_FILTER_LINEAR, VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR},
    };
    for (const Case& c : cases) {
        const VkSamplerCreateInfo info = samplerCreateInfo(samplerWith(c.filter), "s0");
        EXPECT_EQ(info.minFilter, c.min) << dxr::toString(c.filter);
        EXPECT_EQ(info.magFilter, c.mag) << dxr::toString(c.filter);
        EXPECT_EQ(info.mipmapMode, c.mip) << dxr::toString(c.filter);
        EXPECT_EQ(info.anisotropyEnable, VK_FALSE);
    }
}

// The emulator's SampleLevel filters ANISOTROPIC as MIN_MAG_MIP_LINEAR (emulator/texture.h), and the ports sample at an
// explicit LOD: the Vulkan sampler is trilinear with anisotropy off, whatever MaxAnisotropy says.
TEST(VulkanSampler, AnisotropicIsTrilinearAsTheEmulatorsSampleLevel) {
    dxr::SamplerDesc s = samplerWith(dxr::FILTER_ANISOTROPIC);
    s.MaxAnisotropy = 16;
    const VkSamplerCreateInfo info = samplerCreateInfo(s, "s0");
    EXPECT_EQ(info.minFilter, VK_FILTER_LINEAR);
    EXPECT_EQ(info.magFilter, VK_FILTER_LINEAR);
    EXPECT_EQ(info.mipmapMode, VK_SAMPLER_MIPMAP_MODE_LINEAR);
    EXPECT_EQ(info.anisotropyEnable, VK_FALSE);
    EXPECT_EQ(info.unnormalizedCoordinates, VK_FALSE);
    EXPECT_EQ(info.compareEnable, VK_FALSE);
}

TEST(VulkanSampler, AddressModesAndLodClampsCarryOver) {
    dxr::SamplerDesc s = samplerWith(dxr::FILTER_MIN_MAG_MIP_LINEAR);
    s.AddressU = dxr::TEXTURE_ADDRESS_MODE_WRAP;
    s.AddressV = dxr::TEXTURE_ADDRESS_MODE_MIRROR;
    s.AddressW = dxr::TEXTURE_ADDRESS_MODE_CLAMP;
    s.MipLODBias = -1.5f;
    s.MinLOD = 0.5f;
    s.MaxLOD = 3.0f;
    const VkSamplerCreateInfo info = samplerCreateInfo(s, "s0");
    EXPECT_EQ(info.addressModeU, VK_SAMPLER_ADDRESS_MODE_REPEAT);
    EXPECT_EQ(info.addressModeV, VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT);
    EXPECT_EQ(info.addressModeW, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
    EXPECT_EQ(info.mipLodBias, -1.5f);
    EXPECT_EQ(info.minLod, 0.5f);
    EXPECT_EQ(info.maxLod, 3.0f);
}

// BORDER takes Vulkan's fixed border colour equal to the sampler's (the three a D3D12 static sampler can have).
TEST(VulkanSampler, BorderColoursMapToVulkansFixedOnes) {
    const std::pair<dxr::StaticBorderColor, VkBorderColor> colours[] = {
        {dxr::STATIC_BORDER_COLOR_TRANSPARENT_BLACK, VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK},
        {dxr::STATIC_BORDER_COLOR_OPAQUE_BLACK, VK_BORDER_COLOR_FLOAT_OPAQUE_BLACK},
        {dxr::STATIC_BORDER_COLOR_OPAQUE_WHITE, VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE},
    };
    for (const auto& [d3d, vulkan] : colours) {
        dxr::SamplerDesc s = samplerWith(dxr::FILTER_MIN_MAG_MIP_POINT, dxr::TEXTURE_ADDRESS_MODE_BORDER);
        s.BorderColor = dxr::toColor(d3d);
        const VkSamplerCreateInfo info = samplerCreateInfo(s, "s0");
        EXPECT_EQ(info.addressModeU, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER);
        EXPECT_EQ(info.borderColor, vulkan) << d3d;
    }
}

TEST(VulkanSampler, WhatVulkanCannotExpressIsRefusedNamingTheRegister) {
    dxr::SamplerDesc grey = samplerWith(dxr::FILTER_MIN_MAG_MIP_LINEAR, dxr::TEXTURE_ADDRESS_MODE_BORDER);
    grey.BorderColor = vec4(0.5f, 0.5f, 0.5f, 1.0f);
    const std::string greyError = errorOf(grey);
    EXPECT_NE(greyError.find("s2, space3"), std::string::npos) << greyError;
    EXPECT_NE(greyError.find("VK_EXT_custom_border_color"), std::string::npos) << greyError;

    dxr::SamplerDesc mirrorOnce = samplerWith(dxr::FILTER_MIN_MAG_MIP_LINEAR);
    mirrorOnce.AddressW = dxr::TEXTURE_ADDRESS_MODE_MIRROR_ONCE;
    const std::string mirrorError = errorOf(mirrorOnce);
    EXPECT_NE(mirrorError.find("s2, space3"), std::string::npos) << mirrorError;
    EXPECT_NE(mirrorError.find("AddressW is MIRROR_ONCE"), std::string::npos) << mirrorError;

    // What the emulator refuses (BIND-10), the translation refuses too.
    dxr::SamplerDesc badBias = samplerWith(dxr::FILTER_MIN_MAG_MIP_LINEAR);
    badBias.MipLODBias = 20.0f;
    EXPECT_NE(errorOf(badBias).find("MipLODBias"), std::string::npos) << errorOf(badBias);
    // A border colour does not matter where no address mode is BORDER.
    dxr::SamplerDesc unused = samplerWith(dxr::FILTER_MIN_MAG_MIP_LINEAR);
    unused.BorderColor = vec4(0.5f);
    EXPECT_EQ(errorOf(unused), "");
}

}  // namespace
}  // namespace refray::gpu
