// What the hazard tests (hazards_fractals_test.cpp, hazards_d3d12_test.cpp, hazards_emulator_test.cpp) share:
// their namespace shorthands, the "[hazard]" report and the number formatting.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "tests/procedural/contract_support.h"
#include "tests/procedural/sweep_support.h"

namespace refray::hazards {

namespace pm = procedural::math;
namespace hlsl = procedural::hlsl;
using glm::dvec2;
using glm::dvec3;
using glm::dvec4;
using pm::fixtures::RayPair;
using pm::fixtures::randomUnit;
using pm::fixtures::rayPair;

// Prints "[hazard] key: text" and records it as a test property.
inline void report(const std::string& key, const std::string& text) {
    std::printf("[hazard] %-44s %s\n", key.c_str(), text.c_str());
    ::testing::Test::RecordProperty(key, text);
}

inline std::string fmt(const char* format, double a, double b = 0, double c = 0, double d = 0) {
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, format, a, b, c, d);
    return buffer;
}

inline double relative(double a, double b) { return std::fabs(a - b) / std::fabs(b); }

}  // namespace refray::hazards
