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

// Renders the scene with a recorder and classifies each pixel by its primary ray (the first TraceRay of
// depth 1): record = R + M×G + C of the committed hit (IDX-1), hitgroup = the hit group that record holds,
// depth = the deepest TraceRay of the pixel's ray tree. Needs spp 1.
IndexMap renderIndexMap(Scene& scene, const RenderSettings& settings, IndexMapKind kind);

// The map with its legend drawn beside it (swatch, label, share of the pixels). When no font is installed the
// map is returned alone and `drewText` is false; the legend is then only in IndexMap::legend.
Image withLegend(const IndexMap& map, const std::string& title, bool* drewText = nullptr);

}  // namespace refray::scenes
