// The accuracy knobs of a render (issue 7), by name: what `refray render --knob` sets and `refray sweep` varies.
// A knob is a RenderSettings field (precision, spp) or a procedural::Accuracy field of the shader library.
// Settings are written as "name=value,name=value" (`refray sweep --reference`, CSV rows, image metadata).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "scenes/render_settings.h"

namespace refray::scenes {

struct KnobInfo {
    std::string name;         // e.g. "steps"
    std::string description;  // one line for --help and the report
    std::string unit;         // "factor", "count", "" (a word for precision)
    bool higherIsMoreAccurate = true;  // false for threshold: smaller thresholds are stricter
};

// Every knob, in a fixed order (the order of `describeKnobs` and of CSV columns).
const std::vector<KnobInfo>& knobs();

// Sets knob `name` to `value` (its text). Throws refray::Error naming the knob and the accepted values for an
// unknown name (with a did-you-mean) or a value out of range. Setting a knob to the HLSL's value stores the default,
// so equal settings compare equal whichever way they were written; except recursion-depth, which is kept as given
// because it also overrides a scene file's "effects": {"reflectionDepth"}.
void applyKnob(RenderSettings& settings, std::string_view name, std::string_view value);
// "name=value" (one --knob argument).
void applyKnobAssignment(RenderSettings& settings, std::string_view assignment);
// "name=value,name=value"; empty text changes nothing.
void applyKnobList(RenderSettings& settings, std::string_view list);

// The value of knob `name` in `settings` as text, with defaults spelled out (e.g. "200" for julia-iterations).
std::string knobValue(const RenderSettings& settings, std::string_view name);
// The knobs that differ from a default render, "name=value,..." in knob order; "defaults" when none does.
std::string describeKnobs(const RenderSettings& settings);

// The shader library's knob defaults, written out (what knobValue reports for an unset Accuracy field).
inline constexpr uint32_t kDefaultMandelbulbIterations = 4;
inline constexpr uint32_t kDefaultJuliaIterations = 200;
inline constexpr uint32_t kDefaultMetaballSteps = 128;
inline constexpr uint32_t kDefaultRecursionDepth = 3;

}  // namespace refray::scenes
