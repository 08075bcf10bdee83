// The descriptor sets and pipeline layout of one dispatch: the translated global bindings (vulkan_bindings.h)
// with their Vulkan resources.
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/vulkan_context.h"

namespace refray::gpu {

// One binding with the Vulkan objects it names: a buffer, a storage image view, an acceleration structure, the
// views of a sampled-image array (SAMPLED_IMAGE: one element per view; the binding's descriptorCount) or a sampler
// (SAMPLER; `immutableSampler`: baked into the set layout, the mapping of a static sampler, and never written).
struct DescriptorWrite {
    uint32_t set = 0;
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    VkDescriptorBufferInfo buffer{};
    VkImageView imageView = VK_NULL_HANDLE;
    VkAccelerationStructureKHR accelerationStructure = VK_NULL_HANDLE;
    std::vector<VkImageView> sampledImages;
    VkSampler sampler = VK_NULL_HANDLE;
    bool immutableSampler = false;

    uint32_t descriptorCount() const {
        return type == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE ? uint32_t(sampledImages.size()) : 1u;
    }
};

class DescriptorSets {
public:
    // Sets 0 .. the highest set written (sets in between are empty); every binding is visible to every
    // ray-tracing stage and to compute.
    DescriptorSets(const VulkanContext& context, const std::vector<DescriptorWrite>& writes);
    ~DescriptorSets();
    DescriptorSets(const DescriptorSets&) = delete;
    DescriptorSets& operator=(const DescriptorSets&) = delete;

    VkPipelineLayout pipelineLayout() const { return pipelineLayout_; }
    const std::vector<VkDescriptorSet>& sets() const { return sets_; }

private:
    const VulkanContext& context_;
    std::vector<VkDescriptorSetLayout> layouts_;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    std::vector<VkDescriptorSet> sets_;
    VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
};

}  // namespace refray::gpu
