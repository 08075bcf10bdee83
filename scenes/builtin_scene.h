// refray's small built-in scene: a checkered triangle plane and a reflective analytic
// sphere, with radiance and shadow rays, 2 hit groups x 2 ray types. Everything goes
// through real shader-table bytes, Embree and DispatchRays.
#pragma once

#include <memory>

#include "emulator/device.h"
#include "scenes/render_settings.h"

namespace refray::scenes {

class BuiltinScene {
public:
    BuiltinScene();
    RenderResult render(const RenderSettings& settings);

    dxr::Device& device() { return device_; }
    const dxr::StateObjectPtr& pipeline() const { return pipeline_; }
    const dxr::DispatchRaysDesc& tables() const { return tables_; }
    dxr::GpuVirtualAddress tlas() const { return tlas_; }

private:
    dxr::Device device_;
    dxr::StateObjectPtr pipeline_;
    dxr::RootSignaturePtr globalSignature_;
    dxr::DispatchRaysDesc tables_;
    dxr::GpuVirtualAddress tlas_ = 0;
};

}  // namespace refray::scenes
