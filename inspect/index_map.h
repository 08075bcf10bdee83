// Index maps (`refray render --aov ...`): one false colour per record, instance, geometry, primitive, hit group
// or ray-tree depth that each pixel's primary ray reached, with a legend (colour -> record / export name).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/image.h"
#include "scenes/scene.h"

namespace refray::scenes {

enum class IndexMapKind { Record, Instance, Geometry, Primitive, HitGroup, Depth };

// "record", "instance", "geometry", "primitive", "hitgroup", "depth".
std::optional<IndexMapKind> parseIndexMapKind(const std::string& name);
const std::vector<std::string>& indexMapKindNames();

struct IndexMapEntry {
    int64_t value = -1;  // the record index, InstanceIndex, ...; -1: the primary ray missed
    std::string label;   // "record 4: HitGroup_Pacman (instance 'pacmanA', geometry 0, ray type 'Radiance')"
    vec4 colour{0.0f};
    uint64_t pixels = 0;
};

struct IndexMap {
    IndexMapKind kind = IndexMapKind::Record;
    Image map;                          // width x height, one false colour per value
    std::vector<IndexMapEntry> legend;  // the values present, in increasing order
    std::vector<int64_t> values;        // per pixel (row-major), the value behind its colour
    dxr::DispatchResult dispatch;
};

// What one pixel's primary ray (the first TraceRay of depth 1) did: from the emulator's trace
// (renderIndexMap), or from a GPU's AOV dispatch (tools/render_device.h, `--device vulkan --aov`).
struct PrimaryHit {
    bool traced = false;  // a primary ray was traced
    bool hit = false;     // it committed a hit
    uint32_t rayContribution = 0, multiplier = 0, missShaderIndex = 0;  // its TraceRay arguments R, M, miss index
    uint32_t instanceIndex = 0, geometryIndex = 0, primitiveIndex = 0;  // of the committed hit
    // The hit-group record the committed hit used: the emulator computes R + M×G + C (IDX-1); a GPU reports the
    // record its hardware chose. Unset: R + M×G + C.
    std::optional<uint64_t> record;
    std::optional<uint32_t> instanceID;  // InstanceID() of the committed hit, where a device reports it
    uint32_t maxDepth = 0;  // the deepest TraceRay of the pixel's ray tree (0: none, or not known)
};

// Renders the scene with a recorder and returns each pixel's primary hit (row-major); `rendered` (optional)
// receives the render. Needs spp 1.
std::vector<PrimaryHit> renderPrimaryHits(Scene& scene, const RenderSettings& settings, RenderResult* rendered = nullptr);

// Renders the scene with a recorder and classifies each pixel by its primary ray (the first TraceRay of
// depth 1): record = R + M×G + C of the committed hit (IDX-1), hitgroup = the hit group that record holds,
// depth = the deepest TraceRay of the pixel's ray tree. Needs spp 1.
IndexMap renderIndexMap(Scene& scene, const RenderSettings& settings, IndexMapKind kind);

// Classifies width x height primary hits (row-major) as renderIndexMap does: the same values, labels, colours
// and legend. The map's metadata is left empty.
IndexMap indexMapOf(const SceneDesc& desc, uint32_t width, uint32_t height, IndexMapKind kind,
                    const std::vector<PrimaryHit>& pixels);

// The map's values losslessly, for exact comparison (`refray render --aov K -o map.exr`): R = G = B = the value
// (-1: miss), A = 1, float32 (exact below 2^24, checked), with the map's metadata. readIndexValues is its inverse
// and throws refray::Error naming the first pixel that is not such a value.
Image indexValuesImage(const IndexMap& map);
std::vector<int64_t> readIndexValues(const Image& image);

// The map with its legend drawn beside it (swatch, label, share of the pixels). When no font is installed the
// map is returned alone and `drewText` is false; the legend is then only in IndexMap::legend.
Image withLegend(const IndexMap& map, const std::string& title, bool* drewText = nullptr);

}  // namespace refray::scenes
