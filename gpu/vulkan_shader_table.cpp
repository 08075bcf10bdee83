#include "gpu/vulkan_shader_table.h"

#include <cstring>
#include <sstream>
#include <string>

#include "core/error.h"
#include "emulator/limits.h"

namespace refray::gpu {

namespace {

uint64_t alignUp(uint64_t v, uint64_t a) { return a ? (v + a - 1) / a * a : v; }

struct TableSource {
    const char* name;
    uint64_t start = 0, size = 0, stride = 0;
    bool single = false;  // the ray generation record
};

// Rewrites one record (identifier + local root arguments) in `bytes`, which begins at the record and holds
// `available` bytes of it.
void translateRecord(uint8_t* record, uint64_t available, const std::string& where, const dxr::StateObject& stateObject,
                     const ShaderTableTranslation& t) {
    bool isNull = false;
    const dxr::ProgramEntry* entry = stateObject.resolve(record, isNull);
    if (isNull) return;  // all zeros: a null record in DXR and a null group in Vulkan alike
    REFRAY_CHECK(entry, where << " holds an identifier that is not one of state object '" << stateObject.name()
                              << "' (" << dxr::StateObject::describeForeignIdentifier(record)
                              << "); the emulator reports this as REC-8 when it dispatches");
    const GroupHandle handle = t.groupHandle(entry->index);
    std::memcpy(record, handle.data(), handle.size());

    const dxr::RootSignaturePtr& signature = entry->localRootSignature;
    if (!signature) return;
    for (uint32_t p = 0; p < signature->parameterCount(); ++p) {
        const dxr::RootParameter& parameter = signature->parameter(p);
        switch (parameter.parameterType) {
            case dxr::RootParameterType::Constants32Bit: break;  // verbatim
            case dxr::RootParameterType::DescriptorTable:
                throw Error(where + " ('" + entry->name + "'): parameter [" + std::to_string(p) +
                            "] of local root signature '" + signature->name() +
                            "' is a descriptor table; the Vulkan back end translates root constants and root "
                            "descriptors in records, not descriptor heap handles");
            case dxr::RootParameterType::CBV:
            case dxr::RootParameterType::SRV:
            case dxr::RootParameterType::UAV: {
                const uint32_t offset = signature->argumentOffset(p);
                if (offset + 8 > available) break;  // cut off by a short stride; the emulator reports that read
                uint64_t address = 0;
                std::memcpy(&address, record + offset, 8);
                if (address == 0) break;  // a null root descriptor stays null
                const uint64_t translated =
                    t.deviceAddress(address, where + " ('" + entry->name + "') root descriptor [" + std::to_string(p) +
                                                 "] of '" + signature->name() + "'");
                std::memcpy(record + offset, &translated, 8);
                break;
            }
        }
    }
}

}  // namespace

TranslatedShaderTables translateShaderTables(const dxr::DispatchRaysDesc& desc, const dxr::StateObject& stateObject,
                                             const dxr::GpuMemory& memory, const ShaderTableTranslation& t) {
    REFRAY_CHECK(t.groupHandle && t.deviceAddress, "translateShaderTables needs groupHandle and deviceAddress");
    TranslatedShaderTables out;
    const TableSource sources[4] = {
        {"ray generation record", desc.RayGenerationShaderRecord.StartAddress,
         desc.RayGenerationShaderRecord.SizeInBytes, 0, true},
        {"miss table", desc.MissShaderTable.StartAddress, desc.MissShaderTable.SizeInBytes,
         desc.MissShaderTable.StrideInBytes},
        {"hit-group table", desc.HitGroupTable.StartAddress, desc.HitGroupTable.SizeInBytes,
         desc.HitGroupTable.StrideInBytes},
        {"callable table", desc.CallableShaderTable.StartAddress, desc.CallableShaderTable.SizeInBytes,
         desc.CallableShaderTable.StrideInBytes},
    };
    ShaderTableRegion* regions[4] = {&out.rayGeneration, &out.miss, &out.hitGroup, &out.callable};

    for (int k = 0; k < 4; ++k) {
        const TableSource& s = sources[k];
        ShaderTableRegion& region = *regions[k];
        region.offset = alignUp(out.bytes.size(), t.baseAlignment);
        if (s.size == 0 || s.start == 0) {
            out.bytes.resize(region.offset);
            continue;
        }
        REFRAY_CHECK(s.single || s.stride % t.handleAlignment == 0,
                     "the " << s.name << "'s stride " << s.stride << " is not a multiple of Vulkan's "
                            << "shaderGroupHandleAlignment " << t.handleAlignment);
        const uint8_t* source = memory.read(s.start, s.size, s.name);
        const bool appendIndex = k == 2 && t.appendHitGroupRecordIndex;

        // Record i starts at i * stride in DXR. Records whose identifier lies inside the range are translated.
        const uint64_t stride = s.single ? s.size : s.stride;
        const uint64_t records = s.single || stride == 0 ? 1 : (s.size >= dxr::kShaderIdentifierSizeInBytes
                                                                    ? (s.size - dxr::kShaderIdentifierSizeInBytes) / stride + 1
                                                                    : 0);
        uint64_t vkStride = stride;
        if (s.single) vkStride = alignUp(s.size, t.handleAlignment);  // Vulkan: raygen size == stride
        if (appendIndex) {
            vkStride = alignUp(stride + 4, t.handleAlignment);
            out.recordIndexOffset = uint32_t(stride - dxr::kShaderIdentifierSizeInBytes);
        }
        region.stride = vkStride;
        region.records = records;
        region.size = s.single ? vkStride : (appendIndex ? records * vkStride : s.size);
        out.bytes.resize(region.offset + std::max(region.size, records * vkStride), 0);

        for (uint64_t i = 0; i < records; ++i) {
            const uint64_t from = i * stride;
            const uint64_t available = std::min(stride ? stride : s.size, s.size - from);
            uint8_t* record = out.bytes.data() + region.offset + i * vkStride;
            std::memcpy(record, source + from, available);
            std::ostringstream where;
            where << "record " << i << " of the " << s.name;
            translateRecord(record, available, where.str(), stateObject, t);
            if (appendIndex) {
                const uint32_t index = uint32_t(i);
                std::memcpy(record + stride, &index, 4);
            }
        }
        // Bytes of the range past the last whole record (a short final record) travel verbatim.
        if (!s.single && !appendIndex && stride > 0 && records * stride < s.size)
            std::memcpy(out.bytes.data() + region.offset + records * stride, source + records * stride,
                        s.size - records * stride);
    }
    out.bytes.resize(alignUp(std::max<size_t>(out.bytes.size(), 1), t.baseAlignment), 0);
    return out;
}

}  // namespace refray::gpu
