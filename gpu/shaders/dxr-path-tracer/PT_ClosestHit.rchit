// Ports the export PT_ClosestHit of refray's C++ procedural/pathtracer/pathtracer_shaders.cpp (no HLSL original).
// Closest hit of PT_HitGroup (triangles, radiance rays): the per-object indirection InstanceID -> g_objects ->
// indices -> vertices, the material and its textures, written into the payload for PT_RayGen to shade.
#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_nonuniform_qualifier : require
#extension GL_GOOGLE_include_directive : require

#define DXR_STAGE_CLOSEST_HIT
#include "dxr-path-tracer/pathtracer.glsl"

rayPayloadInEXT RadiancePayload payload;
hitAttributeEXT vec2 attr;  // BuiltInTriangleIntersectionAttributes: barycentrics of v1 and v2

vec3 interpolate(vec3 a, vec3 b, vec3 c, vec3 barycentrics) {
    return barycentrics.x * a + barycentrics.y * b + barycentrics.z * c;
}

vec2 interpolate(vec2 a, vec2 b, vec2 c, vec3 barycentrics) {
    return barycentrics.x * a + barycentrics.y * b + barycentrics.z * c;
}

// mul(n, (float3x3)WorldToObject4x3()): an object-space normal in world space (the inverse transpose).
// PORT: the C++ sums worldToObject.m[i][j] * n[i] over the rows i; with GLSL's column-major mat4x3 (element
// [column][row]) that is the row vector n times the upper 3x3.
vec3 normalToWorld(mat4x3 worldToObject, vec3 n) { return n * mat3(worldToObject); }

// PORT: SampleLevel(g_sampler, uv, lod) on an element of an unbounded array is textureLod on the combined
// sampler2D; the index may differ between the invocations of one launch, hence nonuniformEXT.
vec4 sampleDiffuse(uint index, vec2 uv) {
    return textureLod(sampler2D(g_diffuseTextures[nonuniformEXT(index)], g_sampler), uv, 0.0);
}

vec4 sampleNormal(uint index, vec2 uv) {
    return textureLod(sampler2D(g_normalTextures[nonuniformEXT(index)], g_sampler), uv, 0.0);
}

void main() {
    // The object, its triangle and the triangle's corners (InstanceID() is the object's index).
    const uint instanceID = InstanceID();
    const uint primitiveIndex = PrimitiveIndex();
    const ObjectGPU object = g_objects[instanceID];
    const uint baseIndex = object.indexOffset + 3u * primitiveIndex;
    const VertexGPU vertex0 = g_vertices[object.vertexOffset + g_indices[baseIndex + 0u]];
    const VertexGPU vertex1 = g_vertices[object.vertexOffset + g_indices[baseIndex + 1u]];
    const VertexGPU vertex2 = g_vertices[object.vertexOffset + g_indices[baseIndex + 2u]];
    const vec3 barycentrics = vec3(1.0 - attr.x - attr.y, attr.x, attr.y);

    // Position, geometric normal and area from the world-space triangle.
    const mat4x3 objectToWorld = ObjectToWorld3x4();
    const vec3 p0 = objectToWorld * vec4(vertex0.position, 1.0);
    const vec3 p1 = objectToWorld * vec4(vertex1.position, 1.0);
    const vec3 p2 = objectToWorld * vec4(vertex2.position, 1.0);
    const vec3 edgeCross = cross(p1 - p0, p2 - p0);
    const float crossLength = length(edgeCross);
    payload.position = interpolate(p0, p1, p2, barycentrics);
    payload.geometricNormal = crossLength > 0.0 ? edgeCross / crossLength : vec3(0.0, 0.0, 1.0);
    payload.area = 0.5 * crossLength;
    payload.hitT = RayTCurrent();

    // Interpolated attributes.
    const vec3 objectNormal = interpolate(vertex0.normal, vertex1.normal, vertex2.normal, barycentrics);
    const vec2 uv = interpolate(vec2(vertex0.u, vertex0.v), vec2(vertex1.u, vertex1.v), vec2(vertex2.u, vertex2.v),
                                barycentrics);
    vec3 normal = normalize(normalToWorld(WorldToObject3x4(), objectNormal));
    if (!isFinite(normal.x)) normal = payload.geometricNormal;

    // The material and its textures.
    const uint materialIndex = g_triangleMaterials[object.triangleOffset + primitiveIndex];
    const MaterialGPU material = g_materials[materialIndex];
    vec3 albedo = material.albedo.xyz;
    if (material.diffuseTextureIndex >= 0) albedo *= sampleDiffuse(uint(material.diffuseTextureIndex), uv).xyz;
    const vec3 objectTangent =
        interpolate(vertex0.tangent.xyz, vertex1.tangent.xyz, vertex2.tangent.xyz, barycentrics);
    if (material.normalTextureIndex >= 0 && !isZero(objectTangent)) {
        // Tangent space, DirectX convention: x along +u, y along +v (down the image), z along the normal.
        const vec3 mapped = sampleNormal(uint(material.normalTextureIndex), uv).xyz * 2.0 - 1.0;
        const float handedness = vertex0.tangent.w < 0.0 ? -1.0 : 1.0;
        const vec3 objectBitangent = handedness * cross(objectNormal, objectTangent);
        // Matrix3x4::transformVector: the upper 3x3 times the vector.
        vec3 tangent = mat3(objectToWorld) * objectTangent;
        vec3 bitangent = mat3(objectToWorld) * objectBitangent;
        tangent = normalize(tangent - normal * dot(normal, tangent));
        bitangent = normalize(bitangent - normal * dot(normal, bitangent) - tangent * dot(tangent, bitangent));
        const vec3 perturbed = normalize(mapped.x * tangent + mapped.y * bitangent + mapped.z * normal);
        if (isFinite(perturbed.x)) normal = perturbed;
    }

    payload.shadingNormal = normal;
    payload.instanceID = instanceID;
    payload.primitiveIndex = primitiveIndex;
    payload.materialIndex = materialIndex;
    payload.albedo = albedo;
    payload.shininess = material.shininess;
    payload.specular = material.specularRoughness.xyz;
    payload.emission = material.emission.xyz;
}
