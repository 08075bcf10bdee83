#include "gpu/vulkan_descriptor_sets.h"

#include <algorithm>
#include <map>

namespace refray::gpu {

namespace {
// Every binding is visible to the ray-tracing stages and to compute: DXR's global root signature is shared by
// DispatchRays and Dispatch (a compute pipeline uses the same layout).
constexpr VkShaderStageFlags kShaderStages =
    VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_ANY_HIT_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR |
    VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR |
    VK_SHADER_STAGE_COMPUTE_BIT;
}

DescriptorSets::DescriptorSets(const VulkanContext& context, const std::vector<DescriptorWrite>& writes)
    : context_(context) {
    const VulkanFunctions& f = context.vk();
    uint32_t setCount = 0;
    for (const DescriptorWrite& w : writes) setCount = std::max(setCount, w.set + 1);
    // set = register space (CONTRACT.md), so the highest space in use decides how many sets are bound.
    REFRAY_CHECK(setCount <= context.limits().maxBoundDescriptorSets,
                 "the global root signature binds registers in space" << setCount - 1 << ", which needs " << setCount
                     << " descriptor sets; the device binds at most " << context.limits().maxBoundDescriptorSets);

    // Layouts.
    std::map<VkDescriptorType, uint32_t> typeCounts;
    for (uint32_t set = 0; set < setCount; ++set) {
        std::vector<VkDescriptorSetLayoutBinding> bindings;
        for (const DescriptorWrite& w : writes) {
            if (w.set != set) continue;
            REFRAY_CHECK(std::none_of(bindings.begin(), bindings.end(),
                                      [&](const VkDescriptorSetLayoutBinding& b) { return b.binding == w.binding; }),
                         "two descriptors at binding " << w.binding << " of set " << set);
            REFRAY_CHECK(w.descriptorCount() > 0, "binding " << w.binding << " of set " << set << " holds no descriptors");
            bindings.push_back({w.binding, w.type, w.descriptorCount(), kShaderStages,
                                w.immutableSampler ? &w.sampler : nullptr});
            typeCounts[w.type] += w.descriptorCount();
        }
        auto info = vkStruct<VkDescriptorSetLayoutCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
        info.bindingCount = uint32_t(bindings.size());
        info.pBindings = bindings.data();
        VkDescriptorSetLayout layout = VK_NULL_HANDLE;
        REFRAY_VK(f.vkCreateDescriptorSetLayout(context.device(), &info, nullptr, &layout));
        layouts_.push_back(layout);
    }

    auto layoutInfo = vkStruct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    layoutInfo.setLayoutCount = uint32_t(layouts_.size());
    layoutInfo.pSetLayouts = layouts_.data();
    REFRAY_VK(f.vkCreatePipelineLayout(context.device(), &layoutInfo, nullptr, &pipelineLayout_));
    if (setCount == 0) return;

    // Pool and sets.
    std::vector<VkDescriptorPoolSize> sizes;
    for (const auto& [type, count] : typeCounts) sizes.push_back({type, count});
    auto poolInfo = vkStruct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
    poolInfo.maxSets = setCount;
    poolInfo.poolSizeCount = uint32_t(sizes.size());
    poolInfo.pPoolSizes = sizes.data();
    REFRAY_VK(f.vkCreateDescriptorPool(context.device(), &poolInfo, nullptr, &pool_));
    auto allocate = vkStruct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    allocate.descriptorPool = pool_;
    allocate.descriptorSetCount = setCount;
    allocate.pSetLayouts = layouts_.data();
    sets_.resize(setCount);
    REFRAY_VK(f.vkAllocateDescriptorSets(context.device(), &allocate, sets_.data()));

    // Writes. The structures they point at live in `writes` and `imageInfos`/`asInfos` (reserved, never moved).
    std::vector<VkWriteDescriptorSet> updates;
    std::vector<VkDescriptorImageInfo> imageInfos;
    std::vector<VkWriteDescriptorSetAccelerationStructureKHR> asInfos;
    size_t imageCount = 0;
    for (const DescriptorWrite& w : writes) imageCount += w.descriptorCount();
    imageInfos.reserve(imageCount);
    asInfos.reserve(writes.size());
    for (const DescriptorWrite& w : writes) {
        if (w.immutableSampler) continue;  // the layout holds it
        auto u = vkStruct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
        u.dstSet = sets_[w.set];
        u.dstBinding = w.binding;
        u.descriptorCount = w.descriptorCount();
        u.descriptorType = w.type;
        switch (w.type) {
            case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE:
                imageInfos.push_back({VK_NULL_HANDLE, w.imageView, VK_IMAGE_LAYOUT_GENERAL});
                u.pImageInfo = &imageInfos.back();
                break;
            case VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE:
                u.pImageInfo = imageInfos.data() + imageInfos.size();
                for (VkImageView view : w.sampledImages)
                    imageInfos.push_back({VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
                break;
            case VK_DESCRIPTOR_TYPE_SAMPLER:
                imageInfos.push_back({w.sampler, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED});
                u.pImageInfo = &imageInfos.back();
                break;
            case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR: {
                auto as = vkStruct<VkWriteDescriptorSetAccelerationStructureKHR>(
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR);
                as.accelerationStructureCount = 1;
                as.pAccelerationStructures = &w.accelerationStructure;
                asInfos.push_back(as);
                u.pNext = &asInfos.back();
                break;
            }
            default: u.pBufferInfo = &w.buffer; break;
        }
        updates.push_back(u);
    }
    f.vkUpdateDescriptorSets(context.device(), uint32_t(updates.size()), updates.data(), 0, nullptr);
}

DescriptorSets::~DescriptorSets() {
    const VulkanFunctions& f = context_.vk();
    if (pipelineLayout_) f.vkDestroyPipelineLayout(context_.device(), pipelineLayout_, nullptr);
    if (pool_) f.vkDestroyDescriptorPool(context_.device(), pool_, nullptr);
    for (VkDescriptorSetLayout l : layouts_) f.vkDestroyDescriptorSetLayout(context_.device(), l, nullptr);
}

}  // namespace refray::gpu
