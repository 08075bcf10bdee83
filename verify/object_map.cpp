#include "verify/object_map.h"

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "emulator/trace.h"

namespace refray::scenes {

namespace {

constexpr const char* kNamesKey = "object_names";

// Keeps each pixel's first primary ray's committed hit: the first TraceRay of depth 1, or in a compute scene the
// first RayQuery of the thread (its last commit is its committed hit). Each launch index is written by one thread.
class PrimaryObjectRecorder : public dxr::TraceObserver {
public:
    PrimaryObjectRecorder(uint32_t width, uint32_t height)
        : width_(width), ids_(size_t(width) * height, -1), done_(ids_.size(), 0) {}
    void onEvent(const dxr::TraceEvent& e) override {
        if (e.kind == dxr::TraceEvent::Kind::QueryCommit && e.queryId == 1 && e.stage == dxr::ShaderStage::Compute) {
            const size_t i = size_t(e.launchIndex.y) * width_ + e.launchIndex.x;
            if (i < ids_.size()) ids_[i] = objectId(e.instanceIndex, e.geometryIndex);
            return;
        }
        if (e.kind != dxr::TraceEvent::Kind::TraceRayEnd || e.depth != 1) return;
        const size_t i = size_t(e.launchIndex.y) * width_ + e.launchIndex.x;
        if (i >= ids_.size() || done_[i]) return;
        done_[i] = 1;
        ids_[i] = e.committed ? objectId(e.instanceIndex, e.geometryIndex) : -1;
    }
    const std::vector<int32_t>& ids() const { return ids_; }

private:
    uint32_t width_;
    std::vector<int32_t> ids_;
    std::vector<char> done_;
};

}  // namespace

ObjectMap renderObjectMap(Scene& scene, const RenderSettings& settings) {
    PrimaryObjectRecorder recorder(settings.width, settings.height);
    RenderSettings s = settings;
    s.observer = &recorder;
    scene.render(s);
    ObjectMap map;
    map.ids = recorder.ids();
    const SceneDesc& desc = scene.desc();
    for (int32_t id : map.ids) {
        if (map.names.count(id)) continue;
        if (id < 0) {
            map.names[id] = "the background";
            continue;
        }
        const uint32_t instance = uint32_t(id / kMaxObjectGeometries), geometry = uint32_t(id % kMaxObjectGeometries);
        std::string name = "instance " + std::to_string(instance);
        size_t geometries = 1;
        if (instance < desc.instances.size()) {
            const InstanceDescFile& inst = desc.instances[instance];
            if (!inst.name.empty()) name = "'" + inst.name + "'";
            if (inst.blas < desc.blases.size()) geometries = desc.blases[inst.blas].geometries.size();
        }
        map.names[id] = "object " + name + (geometries > 1 ? " geometry " + std::to_string(geometry) : "");
    }
    return map;
}

Image objectMapImage(const ObjectMap& objects, uint32_t width, uint32_t height) {
    REFRAY_CHECK(objects.ids.size() == size_t(width) * height,
                 "an object map of " << objects.ids.size() << " pixels for an image of " << width << "x" << height);
    Image image(width, height);
    for (size_t i = 0; i < objects.ids.size(); ++i) {
        const float id = float(objects.ids[i]);
        image.pixels()[i] = vec4(id, id, id, 1.0f);
    }
    std::string names;
    for (const auto& [id, name] : objects.names) {
        if (!names.empty()) names += '\n';
        names += std::to_string(id);
        names += '=';
        names += name;
    }
    image.metadata[kNamesKey] = names;
    return image;
}

ObjectMap objectMapOf(const Image& image) {
    ObjectMap map;
    map.ids.resize(image.pixels().size());
    for (size_t i = 0; i < map.ids.size(); ++i) {
        const float id = image.pixels()[i].r;
        REFRAY_CHECK(id >= -1.0f && id < 16777216.0f && id == std::floor(id),
                     "not an object map: pixel (" << i % image.width() << ", " << i / image.width() << ") holds "
                                                  << id);
        map.ids[i] = int32_t(id);
    }
    const auto names = image.metadata.find(kNamesKey);
    REFRAY_CHECK(names != image.metadata.end(), "not an object map: no " << kNamesKey << " metadata");
    std::istringstream lines(names->second);
    for (std::string line; std::getline(lines, line);) {
        const size_t eq = line.find('=');
        REFRAY_CHECK(eq != std::string::npos, "not an object map: the name line '" << line << "' is no id=name");
        map.names[int32_t(std::stol(line.substr(0, eq)))] = line.substr(eq + 1);
    }
    return map;
}

}  // namespace refray::scenes
