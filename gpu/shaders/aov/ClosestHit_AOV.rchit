#version 460
// refray's AOV closest hit: not a port of any HLSL. In an AOV dispatch (gpu/vulkan_dispatch.h, dispatchAov) the
// host puts this shader in every hit group in place of the library's closest hit and Miss_AOV in place of every
// miss shader, keeping the intersection and any-hit shaders, so each launch traces its primary ray only and the
// same hit is committed. It records, for the first closest hit of its launch index, the hit-group record it ran
// from (the index the host appended to each record, docs/vulkan-backend.md "AOVs"), InstanceIndex, InstanceID,
// GeometryIndex and PrimitiveIndex.
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require

// Byte offset of the appended record index inside shaderRecordEXT (the DXR stride minus the 32-byte handle).
layout(constant_id = 0) const uint kRecordIndexOffset = 0;

// Sized for the largest record (4096 - 32 bytes; Vulkan allows no runtime-sized array here); only the word at
// kRecordIndexOffset is read.
layout(shaderRecordEXT, scalar) buffer ShaderRecord {
    uint words[1016];
} shaderRecord;

// Five uint32 per launch index, 0xFFFFFFFF until written: record, InstanceIndex, InstanceID, GeometryIndex,
// PrimitiveIndex.
layout(set = 0, binding = 1000, scalar) buffer AovValues {
    uint values[];
} aov;

void main() {
    const uint launch = (gl_LaunchIDEXT.z * gl_LaunchSizeEXT.y + gl_LaunchIDEXT.y) * gl_LaunchSizeEXT.x + gl_LaunchIDEXT.x;
    const uint base = launch * 5u;
    if (aov.values[base] != 0xFFFFFFFFu) return;  // a later ray of the same launch: the primary ray's hit stays
    aov.values[base + 0u] = shaderRecord.words[kRecordIndexOffset / 4u];
    aov.values[base + 1u] = uint(gl_InstanceID);
    aov.values[base + 2u] = uint(gl_InstanceCustomIndexEXT);
    aov.values[base + 3u] = uint(gl_GeometryIndexEXT);
    aov.values[base + 4u] = uint(gl_PrimitiveID);
}
