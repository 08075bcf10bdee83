// `refray explain`: the whole ray tree of one pixel, recorded from the trace events (emulator/trace.h) of a
// dispatch that runs only that pixel, and written out as text or JSON with the indexing rule's terms spelt out.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "emulator/trace.h"
#include "emulator/validation.h"
#include "scenes/scene.h"

namespace refray::scenes {

// A trace event that owns its strings and payload bytes (the emulator's views die with the call).
struct RecordedEvent {
    dxr::TraceEvent event;  // its string views and payload pointer are cleared; use the members below
    std::string table;
    std::string exportName;
    std::string note;
    std::string payloadType;  // demangled
    std::vector<uint8_t> payload;
};

// Collects the events of every launch index it is given (use with a one-pixel LaunchRegion).
class EventRecorder : public dxr::TraceObserver {
public:
    void onEvent(const dxr::TraceEvent& event) override;
    std::vector<RecordedEvent> events;
};

struct Explanation {
    std::string scene, camera, time, precision;
    uint32_t width = 0, height = 0, x = 0, y = 0;
    std::vector<RecordedEvent> events;
    std::optional<dxr::Diagnostic> error;  // the diagnostic that stopped the pixel (the dispatch stops on errors)
    std::vector<dxr::Diagnostic> warnings;
    std::optional<vec4> pixel;  // what the ray generation shader wrote (absent when an error stopped it)
};

// Renders only pixel (x, y) of `settings` (size, camera, time, precision; spp must be 1) with a recorder.
// Errors in the scene's shader tables do not throw: they end the explanation (Explanation::error).
Explanation explainPixel(Scene& scene, const RenderSettings& settings, uint32_t x, uint32_t y);

// The explanation as indented text: one block per TraceRay, the record index written as `R + M×G + C = I`
// with the actual numbers and the byte address, payloads decoded field by field.
std::string formatExplanation(const Explanation& explanation, const SceneDesc& scene);
// The same as a JSON document (format "refray-explain/1").
std::string explanationJson(const Explanation& explanation, const SceneDesc& scene);

// Every pixel's ray tree in brief, for the interactive page (`refray explain --html`): per TraceRay its depth,
// arguments, the committed hit and the record index of the hit (IDX-1).
struct RaySummary {
    uint32_t depth = 0;
    uint32_t rayContribution = 0, multiplier = 0, missShaderIndex = 0, rayFlags = 0;
    bool hit = false;
    uint32_t instanceIndex = 0, geometryIndex = 0, primitiveIndex = 0;
    dxr::HitGroupIndexTerms terms;  // of the committed hit (hit only)
    float t = 0.0f;
};
struct PixelTrees {
    uint32_t width = 0, height = 0;
    Image image;                                // the render
    std::vector<std::vector<RaySummary>> rays;  // per pixel (row-major), in TraceRay order
    dxr::DispatchResult dispatch;
};
// Renders the whole image (spp 1) with a recorder that keeps each pixel's rays.
PixelTrees explainAllPixels(Scene& scene, const RenderSettings& settings);

// A payload's fields as text ("color=(0.1, 0.2, 0.3, 1) recursionDepth=1"), for the payload types of the
// registered shader libraries; other types print as 32-bit words in hex.
std::string describePayload(const std::string& typeName, const std::vector<uint8_t>& bytes);

}  // namespace refray::scenes
