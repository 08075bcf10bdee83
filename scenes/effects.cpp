#include "scenes/effects.h"

#include <algorithm>
#include <cstring>
#include <optional>

#include "core/strings.h"
#include "scenes/shader_libraries.h"

namespace refray::scenes {

namespace {

using dxr::HitGroupDesc;

// The parts appended in order (GCC 12's -Wrestrict misfires on "literal" + string + "literal" chains).
template <class... Parts>
std::string concat(const Parts&... parts) {
    std::string text;
    ((text += parts), ...);
    return text;
}

std::string quotedList(const std::vector<std::string>& names) {
    std::vector<std::string> quoted;
    for (const std::string& n : names) quoted.push_back(inQuotes(n));
    return joined(quoted);
}

// "1 triangle geometry", "3 AABB geometries".
std::string counted(size_t n, const std::string& singular, const std::string& plural) {
    std::string text = std::to_string(n);
    text += ' ';
    text += n == 1 ? singular : plural;
    return text;
}

Effect effect(const char* name, bool on, std::string reason) { return {name, on, std::move(reason)}; }

const HitGroupDesc* findHitGroup(const SceneDesc& scene, const std::string& name) {
    for (const HitGroupDesc& g : scene.hitGroups)
        if (g.HitGroupExport == name) return &g;
    return nullptr;
}

// The hit groups the hit-group records name, in record order (a NULL record names none).
std::vector<const HitGroupDesc*> referencedHitGroups(const SceneDesc& scene) {
    std::vector<const HitGroupDesc*> groups;
    for (const RecordDesc& r : scene.hitGroupRecords) {
        const HitGroupDesc* g = r.hitGroup.empty() ? nullptr : findHitGroup(scene, r.hitGroup);
        if (g && std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
    }
    return groups;
}

bool hitGroupRuns(const HitGroupDesc& g, const std::string& exportName) {
    return g.ClosestHitShaderImport == exportName || g.AnyHitShaderImport == exportName ||
           g.IntersectionShaderImport == exportName;
}

// Whether record `r` passes a use's material gate: the root-constant field named gateField, where the record's
// struct has one, must exceed gateAbove. A record without the field cannot be decided and counts as passing.
bool passesGate(const SceneDesc& scene, const RecordDesc& r, const ShaderEffectUse& use) {
    for (const RecordDesc::Argument& a : r.arguments) {
        if (a.structIndex < 0) continue;
        for (const StructField& f : scene.structs[size_t(a.structIndex)].fields) {
            if (f.name != use.gateField || f.kind != StructField::Kind::Float || f.offset >= a.dwords.size()) continue;
            float value;
            std::memcpy(&value, &a.dwords[f.offset], sizeof value);
            return value > use.gateAbove;
        }
    }
    return true;
}

// Which exports of the library do `effect` in this scene: the ray generation shader, or a shader of a hit group a
// record names (and whose material passes the use's gate).
struct Activity {
    bool libraryHasIt = false;            // some export of the library does it
    std::vector<std::string> exports;     // those the scene runs, facts order
    std::vector<std::string> described;   // "export (what)" or "export"
    std::string gateField;
    float gateAbove = 0.0f;
    size_t gatedRecords = 0, passingRecords = 0;
};

Activity activity(const SceneDesc& scene, const ShaderLibraryFacts& facts, ShaderEffect which) {
    Activity a;
    for (const ShaderEffectUse& use : facts.uses) {
        if (use.effect != which) continue;
        a.libraryHasIt = true;
        // A compute scene runs its compute shader only: none of its records (docs/ray-query.md).
        const bool compute = !scene.computeShader.empty();
        bool active = use.exportName == (compute ? scene.computeShader : scene.rayGeneration);
        for (const RecordDesc& r : scene.hitGroupRecords) {
            if (compute) break;
            const HitGroupDesc* g = r.hitGroup.empty() ? nullptr : findHitGroup(scene, r.hitGroup);
            if (!g || !hitGroupRuns(*g, use.exportName)) continue;
            if (use.gateField.empty()) {
                active = true;
                continue;
            }
            a.gateField = use.gateField;
            a.gateAbove = use.gateAbove;
            ++a.gatedRecords;
            if (passesGate(scene, r, use)) {
                ++a.passingRecords;
                active = true;
            }
        }
        if (!active || std::find(a.exports.begin(), a.exports.end(), use.exportName) != a.exports.end()) continue;
        a.exports.push_back(use.exportName);
        a.described.push_back(use.what.empty() ? use.exportName : concat(use.exportName, " (", use.what, ")"));
    }
    return a;
}

// "X does", "X, Y do".
std::string subject(const std::vector<std::string>& names, const char* singularVerb, const char* pluralVerb) {
    std::string text = joined(names);
    text += ' ';
    text += names.size() == 1 ? singularVerb : pluralVerb;
    return text;
}

// Why a shader effect is off when no export the scene runs does it.
std::string notRun(const Activity& a, const SceneDesc& scene, const char* what) {
    std::string text;
    if (!a.libraryHasIt) {
        text = "no shader of library ";
        text += inQuotes(scene.shaderLibrary);
        text += ' ';
        text += what;
        return text;
    }
    if (a.gatedRecords > 0) {
        text = "no record that runs a shader which ";
        text += what;
        text += " has ";
        text += a.gateField;
        text += " > ";
        text += shortestFloat(a.gateAbove);
        return text;
    }
    text = "no shader the scene runs ";
    text += what;
    return text;
}

// Geometry of one type in the BLASes of the instances some ray type can reach (INST-4: mask & inclusion mask): the
// "triangles" or the "procedural primitives" effect.
Effect geometryEffect(const SceneDesc& scene, dxr::GeometryType type) {
    const bool triangles = type == dxr::GeometryType::Triangles;
    const char* name = triangles ? "triangles" : "procedural primitives";
    const std::string kind = triangles ? "triangle" : "AABB";
    uint32_t rayMask = 0;
    for (const RayTypeDesc& t : scene.rayTypes) rayMask |= t.instanceInclusionMask;
    std::vector<std::string> blases, instances;
    size_t geometries = 0;
    for (const InstanceDescFile& i : scene.instances) {
        if ((i.mask & rayMask & 0xFFu) == 0) continue;
        const BlasDesc& blas = scene.blases[i.blas];
        size_t n = 0;
        for (const GeometryDescFile& g : blas.geometries) n += g.type == type ? 1 : 0;
        if (n == 0) continue;
        if (std::find(blases.begin(), blases.end(), blas.name) == blases.end()) {
            blases.push_back(blas.name);
            geometries += n;
        }
        instances.push_back(i.name);
    }
    if (blases.empty()) return effect(name, false, concat("no instance a ray can reach holds ", kind, " geometry"));
    std::string reason = blases.size() == 1 ? "BLAS " : "BLASes ";
    reason += quotedList(blases);
    reason += " (";
    reason += counted(geometries, concat(kind, " geometry"), concat(kind, " geometries"));
    reason += ") under ";
    reason += instances.size() == 1 ? concat("instance ", inQuotes(instances[0])) : counted(instances.size(), "", "instances");
    return effect(name, true, reason);
}

Effect anyHitEffect(const SceneDesc& scene) {
    const std::vector<const HitGroupDesc*> groups = referencedHitGroups(scene);
    std::vector<std::string> with;
    for (const HitGroupDesc* g : groups)
        if (!g->AnyHitShaderImport.empty()) with.push_back(concat(inQuotes(g->HitGroupExport), " (", g->AnyHitShaderImport, ")"));
    if (!with.empty())
        return effect("any-hit shaders", true,
                      concat(with.size() == 1 ? "hit group " : "hit groups ", joined(with), " run an any-hit shader"));
    if (groups.empty()) return effect("any-hit shaders", false, "no record names a hit group");
    if (groups.size() == 1)
        return effect("any-hit shaders", false, concat("hit group ", inQuotes(groups[0]->HitGroupExport), " has no any-hit shader"));
    return effect("any-hit shaders", false,
                  concat("none of the ", std::to_string(groups.size()), " hit groups the records name has an any-hit shader"));
}

Effect cullingEffect(const SceneDesc& scene, const ShaderLibraryFacts& facts, const Effect& triangles) {
    const char* name = "triangle culling";
    if (!triangles.on) return effect(name, false, "no triangle geometry");
    std::vector<std::string> back, front;
    for (size_t r = 0; r < scene.rayTypes.size() && r < facts.rayFlags.size(); ++r) {
        if (facts.rayFlags[r] & dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES) back.push_back(inQuotes(scene.rayTypes[r].name));
        if (facts.rayFlags[r] & dxr::RAY_FLAG_CULL_FRONT_FACING_TRIANGLES) front.push_back(inQuotes(scene.rayTypes[r].name));
    }
    if (back.empty() && front.empty()) return effect(name, false, "no ray type's TraceRay passes a triangle culling flag");
    std::vector<std::string> cullable;
    size_t triangleInstances = 0;
    for (const InstanceDescFile& i : scene.instances) {
        bool hasTriangles = false;
        for (const GeometryDescFile& g : scene.blases[i.blas].geometries)
            hasTriangles = hasTriangles || g.type == dxr::GeometryType::Triangles;
        if (!hasTriangles) continue;
        ++triangleInstances;
        if (!(i.flags & dxr::INSTANCE_FLAG_TRIANGLE_CULL_DISABLE)) cullable.push_back(inQuotes(i.name));
    }
    if (cullable.empty())
        return effect(name, false, concat("every triangle instance sets TRIANGLE_CULL_DISABLE (",
                                              counted(triangleInstances, "instance", "instances"), ")"));
    std::string reason;
    if (!back.empty()) {
        reason += joined(back);
        reason += " rays cull back-facing triangles";
    }
    if (!front.empty()) {
        if (!reason.empty()) reason += "; ";
        reason += joined(front);
        reason += " rays cull front-facing triangles";
    }
    reason += cullable.size() == 1 ? " of instance " : " of instances ";
    reason += joined(cullable);
    return effect(name, true, reason);
}

// geometrySkipPipelineFlags, with the reason. `triangles` and `procedural` are the geometry effects.
Effect geometrySkipEffect(const SceneDesc& scene, const ShaderLibraryFacts& facts, const Effect& triangles,
                          const Effect& procedural, uint32_t& flags) {
    const char* name = "geometry-skipping pipeline flag";
    flags = dxr::PIPELINE_FLAG_NONE;
    if (triangles.on == procedural.on)
        return effect(name, false, triangles.on ? "rays reach both triangle and AABB geometry"
                                                : "rays reach no geometry at all");
    // FLAG-4/5 on the effective flags: SKIP_TRIANGLES excludes CULL_*_FACING_TRIANGLES and SKIP_PROCEDURAL_PRIMITIVES;
    // SKIP_PROCEDURAL_PRIMITIVES excludes SKIP_TRIANGLES.
    const uint32_t candidate = triangles.on ? dxr::PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES : dxr::PIPELINE_FLAG_SKIP_TRIANGLES;
    const uint32_t excluded = triangles.on ? dxr::RAY_FLAG_SKIP_TRIANGLES
                                           : dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES |
                                                 dxr::RAY_FLAG_CULL_FRONT_FACING_TRIANGLES |
                                                 dxr::RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES;
    for (size_t r = 0; r < scene.rayTypes.size() && r < facts.rayFlags.size(); ++r)
        if (facts.rayFlags[r] & excluded)
            return effect(name, false,
                          concat("pipeline flag ", dxr::pipelineFlagsToString(candidate), " would be undefined with the ",
                                 dxr::rayFlagsToString(facts.rayFlags[r] & excluded), " of ray type ",
                                 inQuotes(scene.rayTypes[r].name), " (FLAG-4, FLAG-5)"));
    flags = candidate;
    return effect(name, true,
                  concat("pipeline flag ", dxr::pipelineFlagsToString(candidate), ": no instance a ray can reach holds ",
                         triangles.on ? "AABB" : "triangle", " geometry"));
}

std::string depthSource(const SceneDesc& scene, const procedural::Accuracy& knobs) {
    if (knobs.maxRecursionDepth) return "the recursion-depth knob";
    if (scene.effects.reflectionDepth) return "the scene's reflectionDepth";
    return "the HLSL's";
}

// Whether every export that does an effect is the ray generation shader: it traces iteratively (a path), at depth 1,
// so MAX_RAY_RECURSION_DEPTH does not limit it.
bool tracedByRayGeneration(const Activity& a, const SceneDesc& scene) {
    return !a.exports.empty() && std::all_of(a.exports.begin(), a.exports.end(),
                                             [&](const std::string& x) { return x == scene.rayGeneration; });
}

// The path length of a library whose constants hold maxBounces: the scene constants buffer's (its name and value).
struct PathLength {
    std::string buffer;
    uint32_t maxBounces = 0;
};
std::optional<PathLength> pathLength(const SceneDesc& scene, const ShaderLibraryBinding& binding) {
    const auto& keys = binding.constantsKeys;
    if (std::find(keys.begin(), keys.end(), "maxBounces") == keys.end()) return std::nullopt;
    for (const BufferDesc& b : scene.buffers)
        if (b.kind == BufferDesc::Kind::SceneConstants) return PathLength{b.name, b.maxBounces};
    return std::nullopt;
}

// Textures or normal maps of the models' materials that a table binds ({"textures": ...}).
Effect textureEffect(const SceneDesc& scene, const ShaderLibraryFacts& facts, ShaderEffect which, const char* name,
                     const char* does, const char* singular, const char* plural, const char* mtlKeys) {
    const Activity a = activity(scene, facts, which);
    if (a.exports.empty()) return effect(name, false, notRun(a, scene, concat(does, " ", plural).c_str()));
    const auto& paths =
        which == ShaderEffect::Textures ? scene.modelBuffers.diffuseTextures : scene.modelBuffers.normalTextures;
    size_t bound = 0;
    for (const GlobalArgumentDesc& argument : scene.globalArguments)
        for (const GlobalArgumentDesc::TableEntry& entry : argument.table)
            bound += entry.isTexture && std::find(paths.begin(), paths.end(), entry.texture) != paths.end() ? 1 : 0;
    if (paths.empty())
        return effect(name, false, concat("no material of the models has a ", singular, " (", mtlKeys, ")"));
    if (bound == 0)
        return effect(name, false, concat("the models have ", counted(paths.size(), singular, plural),
                                          ", but no descriptor table binds them"));
    return effect(name, true, concat(subject(a.exports, does, does), " ", counted(paths.size(), singular, plural),
                                     " (", mtlKeys, ")"));
}

}  // namespace

std::vector<Effect> EffectSet::list() const {
    return {triangles,   procedural,    anyHit,      triangleCulling,  geometrySkip, shadowRays, reflections,
            animation,   supersampling, distanceFog, rayDifferentials, debugColours, textures,   normalMaps};
}

procedural::Accuracy libraryAccuracy(const SceneDesc& scene, const procedural::Accuracy& knobs) {
    procedural::Accuracy accuracy = knobs;
    if (!accuracy.maxRecursionDepth) accuracy.maxRecursionDepth = scene.effects.reflectionDepth;
    return accuracy;
}

procedural::Effects libraryEffects(const SceneDesc& scene) {
    procedural::Effects effects;
    effects.traceShadowRays = scene.effects.shadows;
    return effects;
}

uint32_t pipelineRecursionDepth(const SceneDesc& scene, const procedural::Accuracy& accuracy) {
    return std::max(scene.maxRecursionDepth, accuracy.maxRecursionDepth.value_or(0));
}

std::string describeEffectsBlock(const EffectsDesc& block) {
    std::string text;
    if (!block.shadows) text += "shadows=off";
    if (block.reflectionDepth) {
        if (!text.empty()) text += ',';
        text += "reflectionDepth=";
        text += std::to_string(*block.reflectionDepth);
    }
    return text.empty() ? "defaults" : text;
}

EffectSet computeEffects(const SceneDesc& scene, const RenderSettings& settings) {
    const ShaderLibraryBinding& binding = findShaderLibrary(scene.shaderLibrary);
    const ShaderLibraryFacts& facts = binding.facts;
    const std::optional<PathLength> path = pathLength(scene, binding);
    const procedural::Accuracy accuracy = libraryAccuracy(scene, settings.accuracy);
    EffectSet e;
    e.recursionDepth = accuracy.maxRecursionDepth.value_or(facts.maxRayRecursionDepth);
    e.pipelineRecursionDepth = pipelineRecursionDepth(scene, accuracy);
    e.spp = settings.spp;
    std::string depthText = "MAX_RAY_RECURSION_DEPTH ";
    depthText += std::to_string(e.recursionDepth);
    depthText += " (";
    depthText += depthSource(scene, settings.accuracy);
    depthText += ')';

    // Geometry and the pipeline's shader stages.
    e.triangles = geometryEffect(scene, dxr::GeometryType::Triangles);
    e.procedural = geometryEffect(scene, dxr::GeometryType::ProceduralPrimitiveAABBs);
    e.anyHit = anyHitEffect(scene);
    e.triangleCulling = cullingEffect(scene, facts, e.triangles);
    e.geometrySkip = geometrySkipEffect(scene, facts, e.triangles, e.procedural, e.pipelineFlags);

    // Shadow rays: traced by closest hits at depth d < MAX_RAY_RECURSION_DEPTH, unless switched off.
    {
        const Activity a = activity(scene, facts, ShaderEffect::ShadowRays);
        const char* name = "shadow rays";
        const std::string shadowType = scene.rayTypes.size() > facts.shadowRayType
                                           ? inQuotes(scene.rayTypes[facts.shadowRayType].name)
                                           : std::string("shadow");
        if (a.exports.empty()) {
            e.shadowRays = effect(name, false, notRun(a, scene, "traces shadow rays"));
        } else if (!scene.effects.shadows) {
            e.shadowRays = effect(name, false, concat("the scene's effects block sets \"shadows\": false, so ",
                                                          subject(a.exports, "takes", "take"), " every point as lit"));
        } else if (tracedByRayGeneration(a, scene)) {
            const uint32_t lights = scene.lightTriangleCount();
            if (path && path->maxBounces == 0)
                e.shadowRays = effect(name, false, concat("maxBounces is 0 in buffer ", inQuotes(path->buffer),
                                                          ": paths end at their first hit, before light sampling"));
            else if (lights == 0)
                e.shadowRays = effect(name, false, "the scene has no light triangles (lightCount 0) to sample");
            else
                e.shadowRays = effect(name, true,
                                      concat(subject(a.described, "traces", "trace"), " ", shadowType,
                                             " rays from every path vertex to a point on one of ",
                                             counted(lights, "light triangle", "light triangles")));
        } else if (e.recursionDepth < 2) {
            e.shadowRays = effect(name, false, concat(depthText, ": hits at depth 1 trace no shadow rays"));
        } else {
            std::string reason = subject(a.exports, "traces", "trace");
            reason += ' ';
            reason += shadowType;
            reason += " rays towards the light from hits at depth 1";
            if (e.recursionDepth > 2) {
                reason += "..";
                reason += std::to_string(e.recursionDepth - 1);
            }
            reason += ", ";
            reason += depthText;
            e.shadowRays = effect(name, true, reason);
        }
    }

    // Reflections: radiance rays from closest hits, up to MAX_RAY_RECURSION_DEPTH levels in all.
    {
        const Activity a = activity(scene, facts, ShaderEffect::Reflections);
        const char* name = "reflections";
        if (a.exports.empty()) {
            e.reflections = effect(name, false, notRun(a, scene, "traces reflection rays"));
        } else if (tracedByRayGeneration(a, scene)) {
            if (path && path->maxBounces == 0)
                e.reflections = effect(name, false, concat("maxBounces is 0 in buffer ", inQuotes(path->buffer),
                                                           ": paths end at their first hit"));
            else
                e.reflections = effect(
                    name, true,
                    concat(subject(a.described, "traces", "trace"), " them in a loop at depth 1",
                           path ? concat(", up to maxBounces ", std::to_string(path->maxBounces), " per path (buffer ",
                                         inQuotes(path->buffer), ")")
                                : std::string()));
        } else if (e.recursionDepth < 2) {
            e.reflections = effect(name, false, concat(depthText, ": hits at depth 1 trace no reflection rays"));
        } else {
            std::string reason = subject(a.exports, "traces", "trace");
            reason += " them";
            if (a.gatedRecords > 0) {
                reason += " (";
                reason += a.gateField;
                reason += " > ";
                reason += shortestFloat(a.gateAbove);
                reason += " in ";
                reason += std::to_string(a.passingRecords);
                reason += " of ";
                reason += std::to_string(a.gatedRecords);
                reason += " records)";
            }
            reason += ", ";
            reason += std::to_string(e.recursionDepth - 1);
            reason += e.recursionDepth == 2 ? " bounce: " : " bounces: ";
            reason += depthText;
            reason += ", pipeline MaxTraceRecursionDepth ";
            reason += std::to_string(e.pipelineRecursionDepth);
            e.reflections = effect(name, true, reason);
        }
    }

    // Animation: a shader the scene runs reads elapsedTime, or a primitiveTransforms buffer spins.
    {
        const Activity a = activity(scene, facts, ShaderEffect::Animation);
        std::vector<std::string> parts;
        for (const BufferDesc& b : scene.buffers) {
            if (b.kind != BufferDesc::Kind::PrimitiveTransforms) continue;
            size_t spinning = 0;
            for (const PrimitiveTransformDesc& p : b.primitives) spinning += p.spinYPerSecond != 0.0 ? 1 : 0;
            if (spinning > 0)
                parts.push_back(concat("buffer ", inQuotes(b.name), " spins ", counted(spinning, "primitive", "primitives")));
        }
        if (!a.exports.empty()) parts.push_back(concat(subject(a.described, "reads", "read"), " elapsedTime"));
        if (parts.empty())
            e.animation = effect("animation", false,
                                 "no shader the scene runs reads elapsedTime and no primitiveTransforms buffer spins");
        else
            e.animation = effect("animation", true, joined(parts, "; "));
    }

    // Supersampling: a grid of pixel centres, or the shader's own random samples.
    if (binding.samplesInShader) {
        e.supersampling = effect("supersampling", settings.spp > 1,
                                 settings.spp > 1
                                     ? concat("spp ", std::to_string(settings.spp), ": ", std::to_string(settings.spp),
                                              " random paths per pixel (samplesPerPixel), each through a jittered "
                                              "point of the pixel, averaged by ",
                                              scene.rayGeneration)
                                     : std::string("spp 1: one random path per pixel"));
    } else {
        uint32_t k = 1;
        while ((k + 1) * (k + 1) <= settings.spp) ++k;
        std::string reason = "spp ";
        reason += std::to_string(settings.spp);
        if (settings.spp > 1) {
            reason += ": ";
            reason += std::to_string(k);
            reason += 'x';
            reason += std::to_string(k);
            reason += " camera rays per pixel, averaged";
        } else {
            reason += ": one camera ray per pixel";
        }
        e.supersampling = effect("supersampling", settings.spp > 1, reason);
    }

    // The shaders' own effects.
    {
        const Activity a = activity(scene, facts, ShaderEffect::DistanceFog);
        e.distanceFog = a.exports.empty()
                            ? effect("distance fog", false, notRun(a, scene, "applies distance fog"))
                            : effect("distance fog", true,
                                     subject(a.exports, "blends", "blend") +
                                         " towards the background by hit distance (visibility falloff)");
    }
    {
        const Activity a = activity(scene, facts, ShaderEffect::RayDifferentials);
        e.rayDifferentials =
            a.exports.empty()
                ? effect("ray-differential checkers", false, notRun(a, scene, "filters a texture with ray differentials"))
                : effect("ray-differential checkers", true,
                         subject(a.described, "filters", "filter") +
                             " over the footprint of the neighbouring pixels' camera rays");
    }
    {
        std::vector<std::string> flagged, clear;
        for (const BufferDesc& b : scene.buffers) {
            if (b.kind != BufferDesc::Kind::SceneConstants) continue;
            (b.debugFlag != 0 ? flagged : clear).push_back(inQuotes(b.name));
        }
        const std::string& flag = binding.debugFlagName;
        if (!binding.hasDebugFlag)
            e.debugColours = effect("debug colours", false,
                                    concat("library ", inQuotes(scene.shaderLibrary), " has no debugFlag"));
        else if (!flagged.empty())
            e.debugColours = effect("debug colours", true,
                                    concat(flag, " is set in ", joined(flagged),
                                           flag == "debugFlag" ? ": hits report t = 0 in flat colours"
                                                               : ": the first hit's attributes, not its radiance"));
        else
            e.debugColours = effect("debug colours", false,
                                    clear.empty() ? std::string("no sceneConstants buffer")
                                                  : concat(flag, " is 0 in ", joined(clear)));
    }
    e.textures = textureEffect(scene, facts, ShaderEffect::Textures, "textures", "samples", "diffuse texture",
                               "diffuse textures", "map_Kd");
    e.normalMaps = textureEffect(scene, facts, ShaderEffect::NormalMaps, "normal maps", "perturbs normals with",
                                 "normal map", "normal maps", "norm, map_Bump");
    return e;
}

uint32_t geometrySkipPipelineFlags(const SceneDesc& scene) {
    uint32_t flags = dxr::PIPELINE_FLAG_NONE;
    geometrySkipEffect(scene, findShaderLibrary(scene.shaderLibrary).facts,
                       geometryEffect(scene, dxr::GeometryType::Triangles),
                       geometryEffect(scene, dxr::GeometryType::ProceduralPrimitiveAABBs),
                       flags);
    return flags;
}

std::string describeEffects(const EffectSet& effects) {
    std::string text;
    for (const bool on : {true, false})
        for (const Effect& e : effects.list()) {
            if (e.on != on) continue;
            text += on ? "simulated: " : "skipped: ";
            text += e.name;
            text += " - ";
            text += e.reason;
            text += '\n';
        }
    return text;
}

}  // namespace refray::scenes
