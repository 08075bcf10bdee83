#include "gpu/vulkan_bindings.h"

#include <cstring>
#include <sstream>

#include "emulator/limits.h"

namespace refray::gpu {

using dxr::DescriptorRangeType;
using dxr::RegisterBinding;

uint32_t bindingShift(DescriptorRangeType type) {
    switch (type) {
        case DescriptorRangeType::CBV: return kBindingShiftCBV;
        case DescriptorRangeType::SRV: return kBindingShiftSRV;
        case DescriptorRangeType::UAV: return kBindingShiftUAV;
        case DescriptorRangeType::Sampler: return kBindingShiftSampler;
    }
    return 0;
}

namespace {

VkDescriptorType bufferDescriptorType(DescriptorRangeType type) {
    return type == DescriptorRangeType::CBV ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

std::string registerName(DescriptorRangeType type, uint32_t reg, uint32_t space) {
    return std::string(1, dxr::registerLetter(type)) + std::to_string(reg) + ", space" + std::to_string(space);
}

}  // namespace

std::vector<DescriptorBinding> translateGlobalBindings(const dxr::RootArguments& globals, const dxr::Device& device) {
    const dxr::RootSignature& signature = *globals.signature();
    const auto argument = [&](uint32_t parameter) {
        uint64_t value = 0;
        std::memcpy(&value, globals.bytes().data() + signature.argumentOffset(parameter) - dxr::kShaderIdentifierSizeInBytes, 8);
        return value;
    };

    std::vector<DescriptorBinding> out;
    for (const RegisterBinding& b : signature.registerBindings()) {
        const std::string described = b.describe();
        REFRAY_CHECK(b.source != RegisterBinding::Source::RootConstants,
                     "global root signature '" << signature.name() << "': " << described
                                               << " are global root constants, which the Vulkan back end does not "
                                                  "map (gpu/shaders/CONTRACT.md binds buffers, images and the TLAS)");
        REFRAY_CHECK(b.source != RegisterBinding::Source::StaticSampler && b.type != DescriptorRangeType::Sampler,
                     "global root signature '" << signature.name() << "': " << described
                                               << " is a sampler; the Vulkan back end has no samplers or textures yet");
        REFRAY_CHECK(!b.unbounded(), "global root signature '" << signature.name() << "': " << described
                                                               << " is unbounded; the Vulkan back end binds "
                                                                  "bounded ranges only");

        if (b.source == RegisterBinding::Source::RootDescriptor) {
            DescriptorBinding d;
            d.set = b.space;
            d.binding = bindingShift(b.type) + b.firstRegister;
            d.address = argument(b.index);
            d.what = registerName(b.type, b.firstRegister, b.space) + " (root " + std::string(dxr::toString(b.type)) +
                     ", parameter [" + std::to_string(b.index) + "])";
            REFRAY_CHECK(globals.setMask()[signature.argumentOffset(b.index) - dxr::kShaderIdentifierSizeInBytes],
                         d.what << " was never set (SetComputeRoot*)");
            if (b.type == DescriptorRangeType::SRV && device.findTopLevelAS(d.address)) {
                d.type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
                d.resource = DescriptorBinding::Resource::AccelerationStructure;
            } else {
                d.type = bufferDescriptorType(b.type);
                d.resource = d.address ? DescriptorBinding::Resource::Buffer : DescriptorBinding::Resource::NullBuffer;
            }
            out.push_back(d);
            continue;
        }

        // A descriptor table range: one binding per descriptor.
        const dxr::GpuDescriptorHandle table = argument(b.index);
        const dxr::DescriptorHeap* heap = device.findDescriptorHeap(table);
        REFRAY_CHECK(heap, "global root signature '" << signature.name() << "': the table for " << described
                                                     << " points at no descriptor heap of this device");
        for (uint32_t r = 0; r < b.count; ++r) {
            const uint32_t reg = b.firstRegister + r;
            const dxr::Descriptor& descriptor = heap->at(table, b.offsetInTable + r);
            DescriptorBinding d;
            d.set = b.space;
            d.binding = bindingShift(b.type) + reg;
            d.what = registerName(b.type, reg, b.space) + " (descriptor " +
                     std::to_string(heap->indexOf(table) + b.offsetInTable + r) + " of heap '" + heap->name() + "')";
            switch (descriptor.kind) {
                case dxr::Descriptor::Kind::Null:
                    throw Error(d.what + " was never written (BIND-4)");
                case dxr::Descriptor::Kind::Buffer:
                    d.type = bufferDescriptorType(b.type);
                    d.address = descriptor.buffer.address;
                    d.size = descriptor.buffer.sizeInBytes;
                    d.resource = d.address ? DescriptorBinding::Resource::Buffer : DescriptorBinding::Resource::NullBuffer;
                    break;
                case dxr::Descriptor::Kind::Image:
                    REFRAY_CHECK(b.type == DescriptorRangeType::UAV && descriptor.image,
                                 d.what << " is an image SRV; the Vulkan back end binds images only as the render "
                                           "target UAV (a storage image)");
                    d.type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
                    d.resource = DescriptorBinding::Resource::StorageImage;
                    d.image = descriptor.image;
                    break;
                case dxr::Descriptor::Kind::Texture2D:
                case dxr::Descriptor::Kind::Sampler:
                    throw Error(d.what + " is a " + std::string(dxr::toString(descriptor.kind)) +
                                "; the Vulkan back end has no textures or samplers yet");
            }
            out.push_back(d);
        }
    }
    return out;
}

}  // namespace refray::gpu
