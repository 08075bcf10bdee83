// A scene file turned into DXR objects: one device with the BLASes, the TLAS, the data and model buffers and the
// models' textures, and per precision a state object with its shader tables. Renders any camera, time, size and
// sample count.
#pragma once

#include <map>
#include <memory>

#include "emulator/device.h"
#include "scenes/render_settings.h"
#include "scenes/scene_desc.h"

namespace refray::scenes {

class Scene {
public:
    // Builds everything the scene describes; DXR validation errors (DxrError) name the rule.
    explicit Scene(SceneDesc desc);

    // Throws refray::Error for an unknown camera or a bad sample count.
    RenderResult render(const RenderSettings& settings);

    const SceneDesc& desc() const { return desc_; }
    // The warnings building the acceleration structures gave (DEGEN-8 inverted AABBs, INST-9 singular instance
    // transforms, ...), once each, every message starting with the scene file position of what it is about.
    const std::vector<dxr::Diagnostic>& buildWarnings() const { return buildWarnings_; }
    dxr::Device& device() { return device_; }
    dxr::GpuVirtualAddress tlas() const { return tlas_; }
    // The GPU address of BLAS `index` (SceneDesc::blases order).
    dxr::GpuVirtualAddress blasAddress(size_t index) const { return blasAddresses_.at(index); }
    // The state object and tables of `precision` and `accuracy` (the render's knobs; the scene's effects block is
    // applied on top, scenes/effects.h), built on first use.
    const dxr::StateObjectPtr& pipeline(procedural::Precision precision, const procedural::Accuracy& accuracy = {}) {
        return pipelineFor({precision, accuracy, std::nullopt}).stateObject;
    }
    const dxr::DispatchRaysDesc& tables(procedural::Precision precision, const procedural::Accuracy& accuracy = {}) {
        return pipelineFor({precision, accuracy, std::nullopt}).tables;
    }

private:
    struct Pipeline {
        dxr::StateObjectPtr stateObject;
        dxr::DispatchRaysDesc tables;
    };
    // What a shader library is built with: one state object per distinct value.
    struct LibraryOptions {
        procedural::Precision precision = procedural::Precision::Float;
        procedural::Accuracy accuracy;
        std::optional<procedural::Perturbation> perturbation;
        friend auto operator<=>(const LibraryOptions&, const LibraryOptions&) = default;
    };
    Pipeline& pipelineFor(const LibraryOptions& options);
    dxr::GpuVirtualAddress generateBuffer(const BufferDesc& buffer, const CameraDesc& camera, float time, uint32_t width,
                                          uint32_t height, uint32_t seed, uint32_t samplesPerPixel);

    SceneDesc desc_;
    dxr::Device device_;
    std::vector<dxr::Diagnostic> buildWarnings_;
    std::vector<dxr::GpuVirtualAddress> bufferAddresses_;  // data buffers (0 for generated ones)
    std::vector<dxr::GpuVirtualAddress> blasAddresses_;
    dxr::GpuVirtualAddress tlas_ = 0;
    dxr::RootSignaturePtr globalSignature_;
    std::vector<dxr::RootSignaturePtr> localSignatures_;
    std::map<LibraryOptions, Pipeline> pipelines_;
    dxr::DescriptorHeap* heap_ = nullptr;
    uint32_t heapSize_ = 0;
    // Per global argument and table entry: the Texture2D of a texture entry (null otherwise, or for a null one).
    std::vector<std::vector<dxr::Texture2DPtr>> tableTextures_;
};

// Loads, validates and builds a scene file.
std::unique_ptr<Scene> loadScene(const std::filesystem::path& path);

}  // namespace refray::scenes
