// refray's small built-in scene: a checkered triangle plane and a reflective analytic
// sphere, with radiance and shadow rays, 2 hit groups x 2 ray types. Everything goes
// through real shader-table bytes, Embree and DispatchRays.
#pragma once

#include <memory>

#include "emulator/device.h"
#include "procedural/builtin/builtin_shaders.h"
#include "scenes/render_settings.h"

namespace refray::scenes {

// Variations of the built-in scene for the self-intersection study (issue 6).
struct BuiltinSceneOptions {
    vec3 worldOffset{0.0f};  // everything (plane, sphere, camera, light) moved by this much
    procedural::builtin::SecondaryRayOrigin secondaryRays = procedural::builtin::SecondaryRayOrigin::WaechterBinder;
};

class BuiltinScene {
public:
    // The scene's geometry and materials (also used by the raw-Embree benchmark baseline).
    static constexpr float kPlaneHalfSize = 6.0f;
    static constexpr vec3 kSphereCentre{0.0f, 1.0f, 0.0f};
    static constexpr float kSphereRadius = 1.0f;
    static constexpr vec4 kPlaneAlbedo{0.9f, 0.85f, 0.75f, 0.0f};
    static constexpr vec4 kSphereAlbedo{0.8f, 0.25f, 0.2f, 0.35f};  // .w: reflectance

    explicit BuiltinScene(const BuiltinSceneOptions& options = {});
    RenderResult render(const RenderSettings& settings);
    // Camera and light constants for a width x height image, everything moved by `worldOffset`.
    static procedural::builtin::SceneConstants sceneConstants(uint32_t width, uint32_t height, vec3 worldOffset = vec3(0.0f));

    dxr::Device& device() { return device_; }
    const dxr::StateObjectPtr& pipeline() const { return pipeline_; }
    const dxr::DispatchRaysDesc& tables() const { return tables_; }
    dxr::GpuVirtualAddress tlas() const { return tlas_; }

private:
    BuiltinSceneOptions options_;
    dxr::Device device_;
    dxr::StateObjectPtr pipeline_;
    dxr::RootSignaturePtr globalSignature_;
    dxr::DispatchRaysDesc tables_;
    dxr::GpuVirtualAddress tlas_ = 0;
    dxr::DescriptorHeap* outputHeap_ = nullptr;
};

}  // namespace refray::scenes
