// D3D12 samplers -> VkSampler: a static sampler of the global root signature (an immutable sampler of the set
// layout) or a sampler descriptor in a sampler table. The emulator samples as emulator/texture.h describes (the
// D3D11.3 rules D3D12 inherits); the Vulkan sampler is made to filter the same texels with the same weights:
//
//   D3D12_FILTER bits: mip 0x1, mag 0x4, min 0x10  ->  mipmapMode, magFilter, minFilter (NEAREST / LINEAR)
//   FILTER_ANISOTROPIC                           ->  LINEAR, LINEAR, LINEAR, anisotropy off: the emulator's
//                                                    SampleLevel filters ANISOTROPIC as MIN_MAG_MIP_LINEAR, and the
//                                                    GLSL ports sample at an explicit LOD (textureLod) only
//   WRAP, MIRROR, CLAMP                          ->  REPEAT, MIRRORED_REPEAT, CLAMP_TO_EDGE
//   BORDER with a transparent black, opaque black or opaque white BorderColor -> CLAMP_TO_BORDER with that
//                                                    VkBorderColor (FLOAT_*); other colours need
//                                                    VK_EXT_custom_border_color and are refused
//   MIRROR_ONCE                                  ->  refused (MIRROR_CLAMP_TO_EDGE needs samplerMirrorClampToEdge,
//                                                    which refray does not enable)
//   MipLODBias, MinLOD, MaxLOD                   ->  mipLodBias, minLod, maxLod (the same clamp of the same LOD)
//
// Both sides pick the MAG filter at LOD <= 0 and the MIN filter above; MIP point rounds the LOD to the nearest
// level (D3D floor(lod + 0.5), Vulkan ceil(lod + 0.5) - 1: they differ only at exactly .5).
#pragma once

#include <string>

#include "emulator/texture.h"
#include "gpu/vulkan_context.h"

namespace refray::gpu {

// The create info for `desc`. Throws refray::Error naming `what` ("s0, space0 (static sampler 0)") for what Vulkan
// cannot express as above.
VkSamplerCreateInfo samplerCreateInfo(const dxr::SamplerDesc& desc, const std::string& what);

// A VkSampler made from samplerCreateInfo.
class Sampler {
public:
    Sampler(const VulkanContext& context, const dxr::SamplerDesc& desc, const std::string& what);
    ~Sampler();
    Sampler(const Sampler&) = delete;
    Sampler& operator=(const Sampler&) = delete;

    VkSampler handle() const { return sampler_; }

private:
    const VulkanContext& context_;
    VkSampler sampler_ = VK_NULL_HANDLE;
};

}  // namespace refray::gpu
