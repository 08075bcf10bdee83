// What the gpu/ tests share: the DXR state a reference scene hands to a dispatch back end, captured without a GPU.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "gpu/vulkan_shader_table.h"
#include "scenes/builtin_scene.h"
#include "scenes/scene.h"

namespace refray::gpu::testing {

// One dispatch as a back end receives it: Scene::render with RenderSettings::backend set to a recorder, so the
// tests see exactly the device, tables, state object and global arguments the Vulkan back end would translate.
struct CapturedDispatch {
    dxr::Device* device = nullptr;
    dxr::DispatchRaysDesc desc;
    dxr::StateObjectPtr stateObject;
    std::optional<dxr::GlobalRootArguments> globals;
    // Runs inside the dispatch, while what the global arguments point at (the render target) is alive.
    std::function<void(CapturedDispatch&)> inspect;
};

inline scenes::DispatchBackend recorder(CapturedDispatch& captured) {
    return [&captured](dxr::Device& device, const dxr::DispatchRaysDesc& desc, const dxr::StateObjectPtr& stateObject,
                       const dxr::GlobalRootArguments* globals, const dxr::DispatchOptions&) {
        captured.device = &device;
        captured.desc = desc;
        captured.stateObject = stateObject;
        if (globals) captured.globals.emplace(*globals);
        if (captured.inspect) captured.inspect(captured);
        return dxr::DispatchResult{};
    };
}

// "proceduray-mandel-julia-pac.json" -> "proceduray_mandel_julia_pac", a test name.
inline std::string sceneTestName(const ::testing::TestParamInfo<std::string>& p) {
    std::string name = p.param.substr(0, p.param.find('.'));
    for (char& c : name)
        if (c == '-') c = '_';
    return name;
}

inline std::string sceneFile(const std::string& name) { return std::string(REFRAY_SOURCE_DIR) + "/scenes/" + name; }

// A fake group handle for entry `entry`: every byte tells the entry, none is zero.
inline GroupHandle fakeHandle(uint32_t entry) {
    GroupHandle h;
    for (size_t i = 0; i < h.size(); ++i) h[i] = uint8_t(0x80 | ((entry * 7 + i) & 0x7F));
    return h;
}

// A fake device address: the GPU VA moved by a constant, so a rewritten root descriptor is recognisable.
inline constexpr uint64_t kFakeAddressOffset = 0x7000000000000ull;

inline ShaderTableTranslation fakeTranslation() {
    ShaderTableTranslation t;
    t.groupHandle = fakeHandle;
    t.deviceAddress = [](uint64_t address, std::string_view) { return address + kFakeAddressOffset; };
    return t;
}

}  // namespace refray::gpu::testing
