// A path-tracer scene built directly in C++: OBJ models in the global model buffers (scenes/model_buffers.h), one
// BLAS per model, one TLAS instance per object, and refray's path-tracing shader library
// (procedural/pathtracer/pathtracer_shaders.h) bound through its fixed root signature "PathTracerGlobal" — the host
// side of a DXR path tracer in the manner of the DXR-RTX Path Tracer project.
//
// DXR objects:
//   BLAS m        one triangle geometry (opaque) over model m's range of g_vertices (stride 48, position at byte 0,
//                 R32G32B32_FLOAT) and g_indices (R32_UINT, local to the model)
//   TLAS          instance o of object o: InstanceID = o (the index into g_objects), mask 0xFF,
//                 InstanceContributionToHitGroupIndex 0, the object's transform
//   hit groups    [PT_HitGroup, PT_ShadowHitGroup]: every object has one geometry (GeometryIndex 0), so
//                 I = rayType + 2 * 0 + 0 picks record 0 for radiance and 1 for shadow rays
//   miss table    [PT_Miss, PT_ShadowMiss]; no local root signatures
//   heap          [0] g_output (UAV), [1..6] the six structured buffers in table order, then the diffuse textures,
//                 then the normal textures (one null descriptor for an empty list)
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "emulator/device.h"
#include "procedural/pathtracer/pathtracer_shaders.h"
#include "scenes/model.h"
#include "scenes/model_buffers.h"
#include "scenes/render_settings.h"

namespace refray::scenes {

// The camera, in double as a scene file gives it: the MiniEngine model (scenes/camera_models.h), whose
// projectionToWorld the shaders unproject (only directions matter, so the planes just bracket the scene).
struct PathTracerCamera {
    glm::dvec3 eye{0.0, 0.0, 5.0};
    glm::dvec3 target{0.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    double fovYDegrees = 45.0;  // vertical
    double nearZ = 0.01;
    double farZ = 100.0;
};

struct PathTracerSceneDesc {
    std::string name = "path tracer";
    std::vector<Model> models;
    std::vector<ModelObjectDesc> objects;  // InstanceID = position here
    PathTracerCamera camera;
    vec3 backgroundColor{0.0f};  // the radiance of rays that leave the scene
};

// What a render does besides size, samples, seed and threads.
struct PathTracerRenderOptions {
    uint32_t maxBounces = 8;  // scattering events per path
    procedural::pathtracer::DebugMode debugMode = procedural::pathtracer::kDebugNone;
};

class PathTracerScene {
public:
    // Builds the buffers, the textures (read through OpenImageIO, linear, not sRGB), the acceleration structures,
    // the light list, the pipeline and the shader tables. Throws refray::Error for bad models or objects
    // (buildGlobalModelBuffers), an unreadable texture file, or no objects at all.
    explicit PathTracerScene(PathTracerSceneDesc desc);
    PathTracerScene(PathTracerScene&&) noexcept;
    PathTracerScene& operator=(PathTracerScene&&) noexcept;
    ~PathTracerScene();

    // `scenesDirectory` is the source tree's scenes/ folder (the library does not bake in a path).
    // <scenes>/cornell-box/cornell-box.obj (walls, short-block, tall-block, light) and the Cornell data's camera:
    // eye (278, 273, -800), target (278, 273, 0), up +y, vertical field of view 39.3077 degrees (planes 8 and
    // 8000); black background. scenes/cornell-box.json describes the same DXR objects.
    static PathTracerScene cornellBox(const std::filesystem::path& scenesDirectory);
    // <scenes>/textured-room/textured-room.obj (floor, back-wall, sphere, box, torus, light), seen from the front
    // and above so that every object shows; a dim blue-grey background (the room is open).
    // scenes/textured-room.json describes the same DXR objects.
    static PathTracerScene texturedRoom(const std::filesystem::path& scenesDirectory);

    // DispatchRays over width x height with `spp` paths per pixel; `threads` 0 uses every hardware thread. The
    // image is float RGBA radiance (alpha 1); the same arguments give bit-identical images at any thread count.
    RenderResult render(uint32_t width, uint32_t height, uint32_t spp, uint32_t seed, uint32_t threads,
                        const PathTracerRenderOptions& options = {});
    // The constant buffer a render of width x height uploads.
    procedural::pathtracer::PathTracerConstants constants(uint32_t width, uint32_t height, uint32_t spp, uint32_t seed,
                                                          const PathTracerRenderOptions& options = {}) const;

    const PathTracerSceneDesc& desc() const;
    const GlobalModelBuffers& buffers() const;
    // The emissive triangles of g_lights, world space.
    const std::vector<procedural::pathtracer::LightTriangleGPU>& lights() const;
    dxr::Device& device();
    const dxr::StateObjectPtr& pipeline() const;
    const dxr::DispatchRaysDesc& tables() const;
    dxr::GpuVirtualAddress tlas() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

// Every emissive triangle of the objects (a material with nonzero emission, a triangle of nonzero area), its
// vertices moved to world space by the object's transform, in object then triangle order.
std::vector<procedural::pathtracer::LightTriangleGPU> buildLightTriangles(const GlobalModelBuffers& buffers);

}  // namespace refray::scenes
