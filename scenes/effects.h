// The effects a scene calls for (issue 8): which parts of the DXR pipeline and of the shaders a render of the scene
// exercises, each with the reason, decided from the scene (SceneDesc), the shader library's facts
// (ShaderLibraryFacts in scenes/shader_libraries.h) and the render settings. `refray render --stats` prints it; the
// builder and the dispatcher can configure only what is listed as simulated.
//
// The scene's "effects" block (EffectsDesc) switches effects off; libraryAccuracy and libraryEffects turn it into
// what the shader library is built with, so the render, the pipeline and this report agree.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "procedural/accuracy.h"
#include "procedural/effects.h"
#include "scenes/render_settings.h"
#include "scenes/scene_desc.h"

namespace refray::scenes {

struct Effect {
    std::string name;    // e.g. "shadow rays"
    bool on = false;     // simulated (true) or skipped
    std::string reason;  // one short sentence: why
};

struct EffectSet {
    Effect triangles;         // triangle geometry in a BLAS an instance holds
    Effect procedural;        // AABB geometry (intersection shaders) in a BLAS an instance holds
    Effect anyHit;            // an any-hit shader in a hit group a record references
    Effect triangleCulling;   // a ray type culls back- or front-facing triangles on an instance that allows it
    Effect geometrySkip;      // a pipeline flag (PIPE-3) skips the geometry type no ray can reach (pipelineFlags)
    Effect shadowRays;        // closest hits trace the shadow ray type (not switched off, depth allows)
    Effect reflections;       // closest hits trace reflection rays (MAX_RAY_RECURSION_DEPTH >= 2)
    Effect animation;         // a shader reads elapsedTime or a generated buffer moves with the time
    Effect supersampling;     // more than one camera ray per pixel
    Effect distanceFog;       // closest hits blend towards the background with the hit distance
    Effect rayDifferentials;  // closest hits filter a texture over the neighbouring pixels' camera-ray footprint
    Effect debugColours;      // the scene constants' debugFlag (debugMode) replaces shading with flat colours
    Effect textures;          // closest hits sample the models' diffuse textures (bound in a descriptor table)
    Effect normalMaps;        // closest hits perturb the shading normal with the models' normal maps
    // The shaders' MAX_RAY_RECURSION_DEPTH: TraceRay levels, camera rays being level 1 (1: camera rays only).
    uint32_t recursionDepth = 0;
    // The pipeline's MaxTraceRecursionDepth (at least recursionDepth).
    uint32_t pipelineRecursionDepth = 0;
    uint32_t spp = 1;
    // The pipeline's flags: PIPELINE_FLAG_SKIP_TRIANGLES or _SKIP_PROCEDURAL_PRIMITIVES when geometrySkip is on.
    uint32_t pipelineFlags = 0;

    // Every effect, in the order of the members above.
    std::vector<Effect> list() const;
};

// The effects of `scene` rendered with `settings` (its spp and recursion-depth knob count; camera, size and time do
// not change what is simulated). Throws refray::Error for an unknown shader library.
EffectSet computeEffects(const SceneDesc& scene, const RenderSettings& settings = {});

// The pipeline flags (PIPE-3, Tier 1.1) that skip the one geometry type no ray of `scene` can reach:
// PIPELINE_FLAG_SKIP_TRIANGLES without triangles, _SKIP_PROCEDURAL_PRIMITIVES without AABBs. None when the scene
// reaches both types or neither, or when a ray type's TraceRay flags would make the pair undefined (FLAG-4, FLAG-5).
// Scene's pipelines are built with them. They change no result: a skipped type has nothing to skip.
uint32_t geometrySkipPipelineFlags(const SceneDesc& scene);

// One line per effect, the simulated ones first: "simulated: NAME - REASON" or "skipped: NAME - REASON".
std::string describeEffects(const EffectSet& effects);

// What the shader library is built with for a render whose knobs are `knobs`: the scene's reflectionDepth becomes
// Accuracy::maxRecursionDepth unless the recursion-depth knob sets it.
procedural::Accuracy libraryAccuracy(const SceneDesc& scene, const procedural::Accuracy& knobs);
// The call sites the scene's effects block switches off.
procedural::Effects libraryEffects(const SceneDesc& scene);
// The pipeline's MaxTraceRecursionDepth: the scene's, raised to the shaders' depth (a library built with another
// MAX_RAY_RECURSION_DEPTH is the shaders and the host recompiled with it).
uint32_t pipelineRecursionDepth(const SceneDesc& scene, const procedural::Accuracy& libraryAccuracy);

// The scene's effects block as "shadows=off,reflectionDepth=1" (image metadata); "defaults" when it changes nothing.
std::string describeEffectsBlock(const EffectsDesc& block);

}  // namespace refray::scenes
