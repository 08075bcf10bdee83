#include "inspect/index_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/draw.h"
#include "core/error.h"
#include "core/strings.h"

namespace refray::scenes {

using dxr::TraceEvent;

const std::vector<std::string>& indexMapKindNames() {
    static const std::vector<std::string> names = {"record", "instance", "geometry", "primitive", "hitgroup", "depth"};
    return names;
}

std::optional<IndexMapKind> parseIndexMapKind(const std::string& name) {
    const auto& names = indexMapKindNames();
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) return std::nullopt;
    return IndexMapKind(it - names.begin());
}

namespace {

// Fills each pixel's PrimaryHit from the trace events. Each launch index is written by one thread only.
class PixelRecorder : public dxr::TraceObserver {
public:
    PixelRecorder(uint32_t width, uint32_t height) : width_(width), pixels_(size_t(width) * height) {}
    void onEvent(const TraceEvent& e) override {
        if (e.queryId == 1 && e.stage == dxr::ShaderStage::Compute) {  // a compute scene: its first RayQuery
            PrimaryHit& p = pixels_[size_t(e.launchIndex.y) * width_ + e.launchIndex.x];
            if (e.kind == TraceEvent::Kind::QueryInit) p.traced = true;
            if (e.kind == TraceEvent::Kind::QueryCommit) {  // the last commit is the committed hit
                p.hit = true;
                p.instanceIndex = e.instanceIndex;
                p.geometryIndex = e.geometryIndex;
                p.primitiveIndex = e.primitiveIndex;
                p.instanceID = e.instanceID;
            }
            return;
        }
        if (e.kind != TraceEvent::Kind::TraceRay && e.kind != TraceEvent::Kind::TraceRayEnd) return;
        const size_t i = size_t(e.launchIndex.y) * width_ + e.launchIndex.x;
        PrimaryHit& p = pixels_[i];
        if (e.kind == TraceEvent::Kind::TraceRay) {
            p.maxDepth = std::max(p.maxDepth, e.depth);
            if (e.depth == 1 && !p.traced) {
                p.traced = true;
                p.rayContribution = e.rayContribution;
                p.multiplier = e.multiplier;
                p.missShaderIndex = e.missShaderIndex;
            }
        } else if (e.depth == 1 && p.traced && !done_[i]) {
            done_[i] = true;
            p.hit = e.committed;
            p.instanceIndex = e.instanceIndex;
            p.geometryIndex = e.geometryIndex;
            p.primitiveIndex = e.primitiveIndex;
        }
    }
    const std::vector<PrimaryHit>& pixels() const { return pixels_; }

private:
    uint32_t width_;
    std::vector<PrimaryHit> pixels_;
    std::vector<char> done_ = std::vector<char>(pixels_.size(), 0);  // the primary ray's TraceRayEnd was seen
};

// Distinct colours for the values of one map by their rank: Kelly's 20 colours of maximum contrast (white
// and black left out, black means "miss"), repeating after 20.
vec4 categoricalColour(int64_t value) {
    if (value < 0) return vec4(0.0f, 0.0f, 0.0f, 1.0f);
    static const uint32_t kelly[20] = {0xF3C300, 0x875692, 0xF38400, 0xA1CAF1, 0xBE0032, 0xC2B280, 0x848482,
                                       0x008856, 0xE68FAC, 0x0067A5, 0xF99379, 0x604E97, 0xF6A600, 0xB3446C,
                                       0xDCD300, 0x882D17, 0x8DB600, 0x654522, 0xE25822, 0x2B3D26};
    const uint32_t c = kelly[value % 20];
    return vec4(float((c >> 16) & 0xFF) / 255.0f, float((c >> 8) & 0xFF) / 255.0f, float(c & 0xFF) / 255.0f, 1.0f);
}

// Depth: a ramp from dark blue (1) to yellow (the deepest).
vec4 depthColour(int64_t depth, int64_t deepest) {
    if (depth <= 0) return vec4(0.0f, 0.0f, 0.0f, 1.0f);
    const float t = deepest > 1 ? float(depth - 1) / float(deepest - 1) : 1.0f;
    const vec3 a(0.19f, 0.07f, 0.42f), b(0.13f, 0.57f, 0.55f), c(0.99f, 0.91f, 0.15f);
    return vec4(t < 0.5f ? glm::mix(a, b, t * 2.0f) : glm::mix(b, c, t * 2.0f - 1.0f), 1.0f);
}


}  // namespace

std::vector<PrimaryHit> renderPrimaryHits(Scene& scene, const RenderSettings& settings, RenderResult* rendered) {
    REFRAY_CHECK(settings.spp == 1, "index maps show the GPU's one primary ray per pixel; --aov needs --spp 1");
    PixelRecorder recorder(settings.width, settings.height);
    RenderSettings s = settings;
    s.observer = &recorder;
    RenderResult result = scene.render(s);
    if (rendered) *rendered = std::move(result);
    return recorder.pixels();
}

IndexMap renderIndexMap(Scene& scene, const RenderSettings& settings, IndexMapKind kind) {
    RenderResult rendered;
    IndexMap out = indexMapOf(scene.desc(), settings.width, settings.height, kind,
                              renderPrimaryHits(scene, settings, &rendered));
    out.dispatch = std::move(rendered.dispatch);
    out.map.metadata = std::move(rendered.image.metadata);
    out.map.metadata["aov"] = indexMapKindNames()[size_t(kind)];
    return out;
}

IndexMap indexMapOf(const SceneDesc& desc, uint32_t width, uint32_t height, IndexMapKind kind,
                    const std::vector<PrimaryHit>& pixels) {
    REFRAY_CHECK(desc.computeShader.empty() || (kind != IndexMapKind::Record && kind != IndexMapKind::HitGroup),
                 "scene '" << desc.name << "' renders with the compute shader '" << desc.computeShader
                           << "': its primary rays are RayQuery objects, which read no shader record (RQ-31); "
                              "the instance, geometry, primitive and depth maps apply");
    REFRAY_CHECK(pixels.size() == size_t(width) * height,
                 "an index map of " << width << "x" << height << " needs " << size_t(width) * height
                                    << " primary hits, got " << pixels.size());
    IndexMap out;
    out.kind = kind;
    // Pixel -> value.
    out.values.resize(pixels.size(), -1);
    std::map<int64_t, std::string> labels;
    int64_t deepest = 0;
    for (size_t i = 0; i < pixels.size(); ++i) {
        const PrimaryHit& p = pixels[i];
        int64_t value = -1;
        std::string label;
        if (kind == IndexMapKind::Depth) {
            value = p.maxDepth;
            label = p.maxDepth == 0 ? "no TraceRay" : "ray tree depth " + std::to_string(p.maxDepth);
        } else if (!p.traced || !p.hit) {
            value = -1;
            label = p.traced ? "miss (MissShaderIndex " + std::to_string(p.missShaderIndex) + ")" : "no primary ray";
        } else {
            REFRAY_CHECK(p.instanceIndex < desc.instances.size(),
                         "pixel (" << i % width << "," << i / width << ") hit InstanceIndex " << p.instanceIndex
                                   << "; the scene has " << desc.instances.size() << " instances");
            const InstanceDescFile& inst = desc.instances[p.instanceIndex];
            const dxr::HitGroupIndexTerms terms =
                dxr::hitGroupRecordIndex(p.rayContribution, p.multiplier, p.geometryIndex, inst.contribution);
            const uint64_t record = p.record.value_or(terms.index);
            const bool inTable = record < desc.hitGroupRecords.size();
            const std::string group = !inTable ? "(past the end of the table)"
                                      : desc.hitGroupRecords[record].hitGroup.empty()
                                          ? "NULL"
                                          : desc.hitGroupRecords[record].hitGroup;
            const std::string equation = std::to_string(terms.rayContribution) + " + " + std::to_string(terms.multiplier) +
                                         "*" + std::to_string(terms.geometryIndex) + " + " +
                                         std::to_string(terms.instanceContribution);
            switch (kind) {
                case IndexMapKind::Record:
                    value = int64_t(record);
                    label = "record " + std::to_string(record) + ": " + group +
                            (record == terms.index ? " (I = " + equation + ")"
                                                   : " (reported; R + M*G + C = " + equation + " = " +
                                                         std::to_string(terms.index) + ")");
                    break;
                case IndexMapKind::Instance:
                    value = p.instanceIndex;
                    label = "instance " + std::to_string(p.instanceIndex) + " " + inQuotes(inst.name) + " (BLAS " +
                            inQuotes(desc.blases.at(inst.blas).name) + ", InstanceContribution " + std::to_string(inst.contribution) + ")";
                    break;
                case IndexMapKind::Geometry:
                    value = p.geometryIndex;
                    label = "GeometryIndex " + std::to_string(p.geometryIndex);
                    break;
                case IndexMapKind::Primitive:
                    value = p.primitiveIndex;
                    label = "PrimitiveIndex " + std::to_string(p.primitiveIndex);
                    break;
                case IndexMapKind::HitGroup: {
                    const auto it = std::find_if(desc.hitGroups.begin(), desc.hitGroups.end(),
                                                 [&](const dxr::HitGroupDesc& g) { return g.HitGroupExport == group; });
                    value = it == desc.hitGroups.end() ? int64_t(desc.hitGroups.size()) : int64_t(it - desc.hitGroups.begin());
                    label = group;
                    break;
                }
                case IndexMapKind::Depth: break;
            }
        }
        out.values[i] = value;
        deepest = std::max(deepest, value);
        labels.emplace(value, label);
    }

    // Colours and legend.
    out.map = Image(width, height);
    std::map<int64_t, IndexMapEntry> entries;
    int64_t rank = 0;
    for (const auto& [value, label] : labels) {
        IndexMapEntry e;
        e.value = value;
        e.label = label;
        e.colour = kind == IndexMapKind::Depth ? depthColour(value, deepest) : categoricalColour(value < 0 ? -1 : rank++);
        entries.emplace(value, e);
    }
    for (size_t i = 0; i < out.values.size(); ++i) {
        IndexMapEntry& e = entries.at(out.values[i]);
        e.pixels++;
        out.map.pixels()[i] = e.colour;
    }
    for (auto& [value, e] : entries) out.legend.push_back(e);
    return out;
}

Image indexValuesImage(const IndexMap& map) {
    Image out(map.map.width(), map.map.height());
    for (size_t i = 0; i < map.values.size(); ++i) {
        const int64_t v = map.values[i];
        REFRAY_CHECK(v >= -1 && v < (int64_t(1) << 24),
                     "index value " << v << " at pixel " << i << " has no exact float32; the map's EXR cannot hold it");
        out.pixels()[i] = vec4(float(v), float(v), float(v), 1.0f);
    }
    out.metadata = map.map.metadata;
    out.metadata["aov_values"] = "R = G = B = the index (-1: miss), exact in float32";
    return out;
}

std::vector<int64_t> readIndexValues(const Image& image) {
    std::vector<int64_t> values(image.pixels().size());
    for (size_t i = 0; i < values.size(); ++i) {
        const vec4 p = image.pixels()[i];
        const int64_t v = int64_t(p.r);
        REFRAY_CHECK(p.r == p.g && p.r == p.b && float(v) == p.r && v >= -1,
                     "pixel (" << i % image.width() << "," << i / image.width() << ") of the index values is ("
                               << p.r << ", " << p.g << ", " << p.b << "), not one index in R, G and B");
        values[i] = v;
    }
    return values;
}

Image withLegend(const IndexMap& map, const std::string& title, bool* drewText) {
    constexpr int kText = 13, kRow = 19, kPad = 10, kSwatch = 13;
    const double total = double(map.values.size());
    std::vector<std::string> lines;
    int widest = textExtent(title, kText + 2).first;
    for (const IndexMapEntry& e : map.legend) {
        char share[32];
        std::snprintf(share, sizeof share, "  %.1f%%", 100.0 * double(e.pixels) / total);
        lines.push_back(e.label + share);
        widest = std::max(widest, textExtent(lines.back(), kText).first);
    }
    if (widest == 0) {  // no font
        if (drewText) *drewText = false;
        Image alone = map.map;
        return alone;
    }
    const int panel = kPad * 3 + kSwatch + widest;
    const int height = std::max(int(map.map.height()), kPad * 2 + kRow * int(lines.size() + 1));
    Image out(map.map.width() + uint32_t(panel), uint32_t(height), vec4(0.12f, 0.12f, 0.12f, 1.0f));
    for (uint32_t y = 0; y < map.map.height(); ++y)
        for (uint32_t x = 0; x < map.map.width(); ++x) out.at(x, y) = map.map.at(x, y);
    const int left = int(map.map.width()) + kPad;
    bool ok = drawText(out, left, kPad + kText, title, kText + 2, vec4(1.0f));
    for (size_t i = 0; i < lines.size(); ++i) {
        const int top = kPad + kRow * int(i + 1) + 4;
        fillRect(out, left, top, kSwatch, kSwatch, vec4(0.8f, 0.8f, 0.8f, 1.0f));
        fillRect(out, left + 1, top + 1, kSwatch - 2, kSwatch - 2, map.legend[i].colour);
        ok = drawText(out, left + kSwatch + kPad, top + kSwatch - 2, lines[i], kText, vec4(0.92f, 0.92f, 0.92f, 1.0f)) && ok;
    }
    if (drewText) *drewText = ok;
    out.metadata = map.map.metadata;
    return out;
}

}  // namespace refray::scenes
