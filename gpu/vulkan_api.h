// The Vulkan headers as the gpu/ layer includes them: prototypes off (every entry point comes through
// VulkanLoader), plus the VkResult names and the check macro for calls that return one.
#pragma once

#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#include <vulkan/vulkan.h>

#include <string>

#include "core/error.h"

namespace refray::gpu {

// A Vulkan structure, zeroed, with its sType (and pNext) set:
//   auto info = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
template <class T>
T vkStruct(VkStructureType type, void* next = nullptr) {
    T value{};
    value.sType = type;
    value.pNext = next;
    return value;
}

// "VK_ERROR_OUT_OF_DEVICE_MEMORY (-2)".
std::string resultName(VkResult result);

}  // namespace refray::gpu

// REFRAY_VK(call): throws refray::Error naming the call and its VkResult when it does not return VK_SUCCESS.
#define REFRAY_VK(call)                                                                                  \
    do {                                                                                                 \
        const VkResult refray_vk_result_ = (call);                                                       \
        REFRAY_CHECK(refray_vk_result_ == VK_SUCCESS,                                                    \
                     "Vulkan: " << #call << " returned " << ::refray::gpu::resultName(refray_vk_result_)); \
    } while (false)
