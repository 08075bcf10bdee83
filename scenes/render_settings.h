// What a render is asked to do, and what it returns.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/image.h"
#include "core/progress.h"
#include "emulator/dispatcher.h"

namespace refray::scenes {

struct RenderSettings {
    uint32_t width = 640;
    uint32_t height = 360;
    uint32_t threads = 0;  // 0: all hardware threads
    dxr::TraversalOrder order = dxr::TraversalOrder::Ordered;
    uint64_t adversarialSeed = 0;
    dxr::OnError onError = dxr::OnError::Stop;
    Progress::Sink progress;  // optional
};

struct RenderResult {
    Image image;  // the render target as the shaders wrote it (float RGBA)
    dxr::DispatchResult dispatch;
};

}  // namespace refray::scenes
