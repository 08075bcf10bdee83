#include "gpu/vulkan_bindings.h"

#include <cstring>
#include <sstream>

#include "emulator/limits.h"
#include "gpu/vulkan_sampler.h"

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
                                                  "map (gpu/shaders/CONTRACT.md binds buffers, images, textures, "
                                                  "samplers and the TLAS)");

        if (b.source == RegisterBinding::Source::StaticSampler) {
            // An immutable sampler: baked into the set layout, as a static sampler is into the root signature.
            DescriptorBinding d;
            d.set = b.space;
            d.binding = kBindingShiftSampler + b.firstRegister;
            d.type = VK_DESCRIPTOR_TYPE_SAMPLER;
            d.resource = DescriptorBinding::Resource::Sampler;
            d.sampler = signature.staticSampler(b.index);
            d.staticSampler = true;
            d.what = "global root signature '" + signature.name() + "': " + described;
            samplerCreateInfo(d.sampler, d.what);  // refuses here, before any device work
            out.push_back(d);
            continue;
        }

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

        // A descriptor table range.
        const dxr::GpuDescriptorHandle table = argument(b.index);
        const dxr::DescriptorHeap* heap = device.findDescriptorHeap(table);
        REFRAY_CHECK(heap, "global root signature '" << signature.name() << "': the table for " << described
                                                     << " points at no descriptor heap of this device");
        const uint32_t first = heap->indexOf(table) + b.offsetInTable;  // the range's first descriptor in the heap
        const std::string heapName = "heap '" + heap->name() + "'";

        if (b.unbounded()) {
            // One arrayed binding over the run of Texture2D descriptors from the range's start (vulkan_bindings.h).
            DescriptorBinding d;
            d.set = b.space;
            d.binding = bindingShift(b.type) + b.firstRegister;
            d.type = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
            d.resource = DescriptorBinding::Resource::SampledImages;
            d.runtimeArray = true;
            d.what = std::string(1, dxr::registerLetter(b.type)) + std::to_string(b.firstRegister) + ".., space" +
                     std::to_string(b.space) + " (unbounded, descriptors " + std::to_string(first) + ".. of " +
                     heapName + ")";
            REFRAY_CHECK(b.type == DescriptorRangeType::SRV,
                         "global root signature '" << signature.name() << "': " << described << " is an unbounded "
                                                   << dxr::toString(b.type) << " range; the Vulkan back end binds "
                                                                                "unbounded ranges of Texture2D SRVs only");
            for (uint32_t i = first; i < heap->size() && heap->descriptor(i).kind == dxr::Descriptor::Kind::Texture2D; ++i)
                d.textures.push_back(heap->descriptor(i).texture.get());
            REFRAY_CHECK(!d.textures.empty(),
                         d.what << " starts at a " << (first < heap->size() ? dxr::toString(heap->descriptor(first).kind)
                                                                            : std::string_view("point past the heap"))
                                << " descriptor; the Vulkan back end binds unbounded ranges of Texture2D SRVs only");
            out.push_back(d);
            continue;
        }

        for (uint32_t r = 0; r < b.count; ++r) {
            const uint32_t reg = b.firstRegister + r;
            const dxr::Descriptor& descriptor = heap->at(table, b.offsetInTable + r);
            DescriptorBinding d;
            d.set = b.space;
            d.binding = bindingShift(b.type) + reg;
            d.what = registerName(b.type, reg, b.space) + " (descriptor " + std::to_string(first + r) + " of " +
                     heapName + ")";
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
                    d.type = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
                    d.resource = DescriptorBinding::Resource::SampledImages;
                    d.textures = {descriptor.texture.get()};
                    break;
                case dxr::Descriptor::Kind::Sampler:
                    d.type = VK_DESCRIPTOR_TYPE_SAMPLER;
                    d.resource = DescriptorBinding::Resource::Sampler;
                    d.sampler = descriptor.sampler;
                    samplerCreateInfo(d.sampler, d.what);
                    break;
            }
            out.push_back(d);
        }
    }
    return out;
}

}  // namespace refray::gpu
