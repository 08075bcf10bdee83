// The resource intrinsics of ShaderContext: memory reads, descriptor-table views, textures and samplers, each
// checked against what the dispatch bound. Register/space resolution implements the BIND rules of
// docs/emulator.md, "Resource binding (BIND)".
#include <algorithm>
#include <cstring>
#include <sstream>

#include "core/error.h"
#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/dispatch_state.h"
#include "emulator/limits.h"
#include "emulator/shader_api.h"

namespace refray::dxr {

using detail::stageError;

const uint8_t* ShaderContext::readMemory(GpuVirtualAddress address, uint64_t size) const {
    requireLive("a memory read");
    if (const GpuBuffer* buffer =
            detail::lookupCache(inv_).findBuffer(*inv_.dispatch->memory, address, std::max<uint64_t>(size, 1)))
        return buffer->bytes.data() + (address - buffer->base);
    try {  // outside every buffer: GpuMemory::read says so
        return inv_.dispatch->memory->read(address, size, "shader memory read");
    } catch (const Error& e) {
        stageError(inv_, "GEN-1", e.what());
    }
}

Image& ShaderContext::rwTexture2D(GpuDescriptorHandle tableHandle, uint32_t offset) const {
    requireLive("RWTexture2D");
    const DescriptorHeap* heap = inv_.dispatch->device->findDescriptorHeap(tableHandle);
    if (!heap) stageError(inv_, "GEN-1", "descriptor handle is not in any descriptor heap");
    const Descriptor& d = heap->at(tableHandle, offset);
    if (d.kind != Descriptor::Kind::Image || d.type != DescriptorRangeType::UAV)
        stageError(inv_, "GEN-1",
                   "descriptor " + std::to_string(offset) + " of heap '" + heap->name() +
                       "' is not a Texture2D UAV (RWTexture2D)");
    return *d.image;
}

void ShaderContext::readBufferView(GpuDescriptorHandle tableHandle, uint32_t offset, uint64_t byteOffset, uint64_t size,
                                   void* out) const {
    requireLive("a buffer view read");
    const DescriptorHeap* heap = inv_.dispatch->device->findDescriptorHeap(tableHandle);
    if (!heap) stageError(inv_, "GEN-1", "descriptor handle is not in any descriptor heap");
    const Descriptor& d = heap->at(tableHandle, offset);
    if (d.kind != Descriptor::Kind::Buffer)
        stageError(inv_, "GEN-1",
                   "descriptor " + std::to_string(offset) + " of heap '" + heap->name() + "' is not a buffer view");
    std::memset(out, 0, size);
    if (byteOffset >= d.buffer.sizeInBytes) return;  // wholly out of range: zeros
    const uint64_t inRange = std::min(size, d.buffer.sizeInBytes - byteOffset);
    std::memcpy(out, readMemory(d.buffer.address + byteOffset, inRange), inRange);
}

// ---------------------------------------------------------------------------------------
// Resources by register and space.

namespace detail {

// What one register/space/index resolved to.
struct BoundResource {
    // The access, for messages.
    const char* hlslType = "";
    DescriptorRangeType type = DescriptorRangeType::SRV;
    uint32_t shaderRegister = 0, space = 0, arrayIndex = 0;
    // The binding, in the global or the local root signature.
    const RootSignature* signature = nullptr;
    bool local = false;
    const RegisterBinding* binding = nullptr;
    // A descriptor table: the descriptor and where it sits.
    const DescriptorHeap* heap = nullptr;
    uint64_t heapIndex = 0;
    const Descriptor* descriptor = nullptr;
    // A root descriptor: its GPU address.
    GpuVirtualAddress rootAddress = 0;

    // "Texture2D t0, space5, index 1".
    std::string access() const {
        return std::string(hlslType) + " " + registerLetter(type) + std::to_string(shaderRegister) + ", space" +
               std::to_string(space) + ", index " + std::to_string(arrayIndex);
    }
    // "descriptor 7 of heap 'H' (range 0 of the descriptor table in parameter [1] of 'Global')".
    std::string source() const {
        std::string s;
        if (descriptor) s = "descriptor " + std::to_string(heapIndex) + " of heap '" + heap->name() + "', bound by ";
        if (binding) s += binding->describe();
        if (signature) s += (local ? " of local root signature '" : " of root signature '") + signature->name() + "'";
        return s;
    }
};

}  // namespace detail

using detail::BoundResource;

void ShaderContext::bindingError(const char* rule, const BoundResource& bound, const std::string& what) const {
    stageError(inv_, rule, bound.access() + ": " + what);
}

BoundResource ShaderContext::resolve(DescriptorRangeType type, uint32_t shaderRegister, uint32_t space,
                                     uint32_t arrayIndex, const char* hlslType) const {
    requireLive(hlslType);
    BoundResource r;
    r.hlslType = hlslType;
    r.type = type;
    r.shaderRegister = shaderRegister;
    r.space = space;
    r.arrayIndex = arrayIndex;
    const char letter = registerLetter(type);

    // BIND-1: a binding of the global root signature, or of the shader record's local one, covers the register
    // (PIPE-7 keeps the two apart, so at most one does).
    const RootSignature* global = inv_.dispatch->global ? inv_.dispatch->global->signature().get() : nullptr;
    const RootSignature* local =
        inv_.record && inv_.record->entry ? inv_.record->entry->localRootSignature.get() : nullptr;
    if (global) r.binding = global->findRegister(type, space, shaderRegister);
    r.signature = global;
    if (!r.binding && local) {
        r.binding = local->findRegister(type, space, shaderRegister);
        if (r.binding) {
            r.signature = local;
            r.local = true;
        }
    }
    if (!r.binding) {
        const std::string at = letter + std::to_string(shaderRegister) + " in space" + std::to_string(space);
        auto nearby = [&](const RootSignature& signature) {
            std::string bound;
            for (const RegisterBinding& b : signature.registerBindings())
                if (b.type == type && b.space == space) bound += (bound.empty() ? "" : "; ") + b.describe();
            return " (its " + std::string(1, letter) + " bindings in space" + std::to_string(space) + ": " +
                   (bound.empty() ? "none" : bound) + ")";
        };
        std::string what =
            global ? "global root signature '" + global->name() + "' binds nothing at " + at + nearby(*global)
                   : std::string("the dispatch has no global root signature (no global root arguments)");
        if (local) what += ", nor does local root signature '" + local->name() + "'" + nearby(*local);
        bindingError("BIND-1", r, what);
    }

    // BIND-2: the element lies in that binding.
    const RegisterBinding& b = *r.binding;
    const uint64_t element = uint64_t(shaderRegister - b.firstRegister) + arrayIndex;
    if (!b.unbounded() && element >= b.count)
        bindingError("BIND-2", r,
                     "index " + std::to_string(arrayIndex) + " is past the end of " + b.describe() + " of '" +
                         r.signature->name() + "', which holds " + std::to_string(b.count) + " register" +
                         (b.count == 1 ? "" : "s") + " (element " + std::to_string(element) + " of it)");
    switch (b.source) {
        case RegisterBinding::Source::StaticSampler:
        case RegisterBinding::Source::RootConstants: return r;
        case RegisterBinding::Source::RootDescriptor:
            r.rootAddress = r.local ? localRootDescriptor(b.index) : globalRootDescriptor(b.index);
            return r;
        case RegisterBinding::Source::DescriptorTable: break;
    }

    // The descriptor: table start + range offset + element, inside the heap the table handle points into.
    const GpuDescriptorHandle table = r.local ? localRootDescriptor(b.index) : globalDescriptorTable(b.index);
    r.heap = inv_.dispatch->device->findDescriptorHeap(table);
    if (!r.heap) {
        std::ostringstream s;
        s << "the descriptor table handle 0x" << std::hex << table << std::dec << " set for parameter [" << b.index
          << "] of " << (r.local ? "local" : "global") << " root signature '" << r.signature->name()
          << "' is in no descriptor heap";
        bindingError("BIND-2", r, s.str());
    }
    const uint64_t tableStart = r.heap->indexOf(table);
    r.heapIndex = tableStart + b.offsetInTable + element;
    if (r.heapIndex >= r.heap->size())
        bindingError("BIND-2", r,
                     "descriptor " + std::to_string(r.heapIndex) + " is past the end of heap '" + r.heap->name() +
                         "' (" + std::to_string(r.heap->size()) + " descriptors): table start " +
                         std::to_string(tableStart) + " + range offset " + std::to_string(b.offsetInTable) +
                         " + element " + std::to_string(element) + ", for " + b.describe() + " of '" +
                         r.signature->name() + "'");
    r.descriptor = &r.heap->descriptor(uint32_t(r.heapIndex));

    // BIND-4: a descriptor nobody wrote is undefined in D3D12 (a null descriptor has to be written as one).
    if (r.descriptor->kind == Descriptor::Kind::Null)
        bindingError("BIND-4", r,
                     r.source() +
                         ", was never written; D3D12 leaves its contents undefined (write a null descriptor "
                         "to read zeros)");
    return r;
}

namespace {

// "a buffer UAV", "a Texture2D SRV", "a sampler".
std::string describeDescriptor(const Descriptor& d) {
    if (d.kind == Descriptor::Kind::Sampler) return "a sampler";
    std::string s = d.kind == Descriptor::Kind::Image ? "an " : "a ";
    s += std::string(toString(d.kind)) + " " + std::string(toString(d.type));
    if (d.kind == Descriptor::Kind::Buffer)
        s += d.buffer.address == 0 ? " (null)"
             : d.buffer.structureByteStride
                 ? " (structured, stride " + std::to_string(d.buffer.structureByteStride) + ")"
                 : " (raw)";
    return s;
}

bool holds(const BoundResource& r, Descriptor::Kind kind, DescriptorRangeType type) {
    return r.descriptor->kind == kind && r.descriptor->type == type;
}

// The BIND-3 message.
std::string wrongDescriptor(const BoundResource& r, const char* wanted) {
    return r.source() + ", holds " + describeDescriptor(*r.descriptor) + ", not " + wanted;
}

}  // namespace

Texture2DRef ShaderContext::Texture2D(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex) const {
    const BoundResource r = resolve(DescriptorRangeType::SRV, shaderRegister, space, arrayIndex, "Texture2D");
    if (!r.descriptor)
        bindingError("BIND-3", r, r.source() + " is a buffer address; a Texture2D needs a descriptor table range");
    if (r.descriptor->kind == Descriptor::Kind::Image)
        bindingError("BIND-3", r,
                     r.source() +
                         ", holds an Image (an RWTexture2D target); a Texture2D SRV is a dxr::Texture2D "
                         "written with DescriptorHeap::setTexture2D(index, texture)");
    if (!holds(r, Descriptor::Kind::Texture2D, DescriptorRangeType::SRV))
        bindingError("BIND-3", r, wrongDescriptor(r, "a Texture2D SRV"));
    return Texture2DRef(*this, r.descriptor->texture.get(), shaderRegister, space, arrayIndex);
}

SamplerRef ShaderContext::SamplerState(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex) const {
    const BoundResource r = resolve(DescriptorRangeType::Sampler, shaderRegister, space, arrayIndex, "SamplerState");
    if (r.binding->source == RegisterBinding::Source::StaticSampler)
        return SamplerRef(&r.signature->staticSampler(r.binding->index));
    if (!holds(r, Descriptor::Kind::Sampler, DescriptorRangeType::Sampler))
        bindingError("BIND-3", r, wrongDescriptor(r, "a sampler"));
    return SamplerRef(&r.descriptor->sampler);
}

void ShaderContext::readStructured(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex, uint64_t elementIndex,
                                   uint64_t size, void* out) const {
    const BoundResource r = resolve(DescriptorRangeType::SRV, shaderRegister, space, arrayIndex, "StructuredBuffer");
    std::memset(out, 0, size);
    if (!r.descriptor) {  // a root SRV: an address, no view to check against
        std::memcpy(out, readMemory(r.rootAddress + elementIndex * size, size), size);
        return;
    }
    if (!holds(r, Descriptor::Kind::Buffer, DescriptorRangeType::SRV))
        bindingError("BIND-3", r, wrongDescriptor(r, "a buffer SRV"));
    const BufferView& view = r.descriptor->buffer;
    if (view.address == 0) return;  // a null descriptor
    if (view.structureByteStride != size)
        bindingError("BIND-5", r,
                     "the shader reads " + std::to_string(size) + "-byte elements but " + r.source() + ", is " +
                         (view.structureByteStride
                              ? "a structured view of StructureByteStride " + std::to_string(view.structureByteStride)
                              : std::string("a raw view (StructureByteStride 0)")));
    if (elementIndex >= view.sizeInBytes / size) return;  // past the view: zeros
    std::memcpy(out, readMemory(view.address + elementIndex * size, size), size);
}

void ShaderContext::readByteAddress(uint32_t shaderRegister, uint32_t space, uint32_t arrayIndex, uint64_t byteOffset,
                                    uint64_t size, void* out) const {
    const BoundResource r = resolve(DescriptorRangeType::SRV, shaderRegister, space, arrayIndex, "ByteAddressBuffer");
    if (byteOffset % 4 != 0)
        bindingError("BIND-5", r, "byte offset " + std::to_string(byteOffset) + " is not a multiple of 4");
    std::memset(out, 0, size);
    if (!r.descriptor) {
        std::memcpy(out, readMemory(r.rootAddress + byteOffset, size), size);
        return;
    }
    if (!holds(r, Descriptor::Kind::Buffer, DescriptorRangeType::SRV))
        bindingError("BIND-3", r, wrongDescriptor(r, "a buffer SRV"));
    const BufferView& view = r.descriptor->buffer;
    if (view.address == 0) return;
    if (view.structureByteStride != 0)
        bindingError("BIND-5", r,
                     r.source() + ", is a structured view (StructureByteStride " +
                         std::to_string(view.structureByteStride) + "); a ByteAddressBuffer needs a raw view");
    if (byteOffset >= view.sizeInBytes) return;
    const uint64_t inRange = std::min(size, view.sizeInBytes - byteOffset);
    std::memcpy(out, readMemory(view.address + byteOffset, inRange), inRange);
}

void ShaderContext::readConstantBuffer(uint32_t shaderRegister, uint32_t space, uint64_t size, void* out) const {
    const BoundResource r = resolve(DescriptorRangeType::CBV, shaderRegister, space, 0, "ConstantBuffer");
    std::memset(out, 0, size);
    switch (r.binding->source) {
        case RegisterBinding::Source::RootConstants: {
            const RootParameter& p = r.signature->parameter(r.binding->index);
            if (size > 4ull * p.num32BitValues)
                bindingError("BIND-5", r,
                             "the shader reads " + std::to_string(size) + " bytes but " + r.source() + " holds " +
                                 std::to_string(4 * p.num32BitValues) + " bytes of constants");
            const auto [bytes, written, available] = detail::argumentBytes(inv_, *inv_.dispatch, r.local);
            const std::string which = r.local ? "local" : "global";
            const uint32_t offset = r.signature->argumentOffset(r.binding->index) - kShaderIdentifierSizeInBytes;
            if (offset + size > available)
                stageError(inv_, "REC-11",
                           r.access() + ": " + which + " root parameter " + std::to_string(r.binding->index) +
                               " lies past the bytes available to the record");
            if (std::memchr(written + offset, 0, size))
                stageError(inv_, "REC-7",
                           r.access() + ": the shader reads " + which + " root parameter " +
                               std::to_string(r.binding->index) + " of '" + r.signature->name() +
                               "', whose bytes were never written");
            std::memcpy(out, bytes + offset, size);
            return;
        }
        case RegisterBinding::Source::RootDescriptor: std::memcpy(out, readMemory(r.rootAddress, size), size); return;
        default: break;
    }
    if (!holds(r, Descriptor::Kind::Buffer, DescriptorRangeType::CBV))
        bindingError("BIND-3", r, wrongDescriptor(r, "a CBV"));
    const BufferView& view = r.descriptor->buffer;
    if (view.address == 0) return;
    const uint64_t inRange = std::min(size, view.sizeInBytes);
    if (inRange) std::memcpy(out, readMemory(view.address, inRange), inRange);
}

// ---------------------------------------------------------------------------------------
// Texture2DRef.

void Texture2DRef::readFailed(const char* method, const std::string& why) const {
    stageError(ctx_->inv_, "BIND-6",
               "Texture2D t" + std::to_string(register_) + ", space" + std::to_string(space_) + ", index " +
                   std::to_string(index_) + ": " + method + " cannot read the texture: " + why);
}

vec4 Texture2DRef::SampleLevel(SamplerRef S, vec2 Location, float LOD) const {
    if (!texture_) return vec4(0.0f);
    try {
        return texture_->SampleLevel(S.desc(), Location, LOD);
    } catch (const Error& e) {
        readFailed("SampleLevel", e.what());
    }
}

vec4 Texture2DRef::SampleGrad(SamplerRef S, vec2 Location, vec2 DDX, vec2 DDY) const {
    if (!texture_) return vec4(0.0f);
    try {
        return texture_->SampleGrad(S.desc(), Location, DDX, DDY);
    } catch (const Error& e) {
        readFailed("SampleGrad", e.what());
    }
}

vec4 Texture2DRef::Load(glm::ivec3 Location) const {
    if (!texture_) return vec4(0.0f);
    try {
        return texture_->Load(ivec2(Location.x, Location.y), Location.z);
    } catch (const Error& e) {
        readFailed("Load", e.what());
    }
}

void Texture2DRef::GetDimensions(uint32_t MipLevel, uint32_t& Width, uint32_t& Height, uint32_t& NumberOfLevels) const {
    Width = texture_ ? texture_->width(MipLevel) : 0;
    Height = texture_ ? texture_->height(MipLevel) : 0;
    NumberOfLevels = texture_ ? texture_->mipLevels() : 0;
}

void Texture2DRef::GetDimensions(uint32_t& Width, uint32_t& Height) const {
    uint32_t levels = 0;
    GetDimensions(0, Width, Height, levels);
}

}  // namespace refray::dxr
