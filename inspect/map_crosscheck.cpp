#include "inspect/map_crosscheck.h"

#include <algorithm>
#include <functional>
#include <sstream>

#include "core/error.h"

namespace refray::scenes {

namespace {

// What a pixel's primary ray hit, as (instance, geometry, primitive); -1 everywhere for a miss.
struct HitObject {
    int64_t instance = -1, geometry = -1, primitive = -1;
    friend bool operator==(const HitObject&, const HitObject&) = default;
};

std::vector<HitObject> hitObjects(const IndexMapsByKind& maps, size_t pixels) {
    std::vector<HitObject> objects(pixels);
    for (size_t i = 0; i < pixels; ++i)
        objects[i] = {maps.at(IndexMapKind::Instance)[i], maps.at(IndexMapKind::Geometry)[i],
                      maps.at(IndexMapKind::Primitive)[i]};
    return objects;
}

std::string pixelName(size_t i, uint32_t width) {
    std::ostringstream name;
    name << '(' << i % width << ',' << i / width << ')';
    return name.str();
}

std::string objectName(const HitObject& o) {
    if (o.instance < 0) return "a miss";
    std::ostringstream s;
    s << "instance " << o.instance << " geometry " << o.geometry << " primitive " << o.primitive;
    return s.str();
}

// The first of the 8-neighbourhood of pixel i (itself included) for which `test` holds, or -1.
int64_t firstNeighbour(size_t i, uint32_t width, uint32_t height, const std::function<bool(size_t)>& test) {
    const int64_t x = int64_t(i % width), y = int64_t(i / width);
    for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
            const int64_t nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= int64_t(width) || ny >= int64_t(height)) continue;
            if (test(size_t(ny) * width + size_t(nx))) return ny * int64_t(width) + nx;
        }
    return -1;
}

}  // namespace

std::string MapCrosscheck::summary(const std::string& name) const {
    std::ostringstream s;
    s << name << ": " << sameObject << " pixels hit the same object (records equal on all but " << ruleBroken.size()
      << "), " << orderDependent << " another object on an order-dependent pixel, " << silhouette
      << " on a silhouette, " << stray.size() << " elsewhere";
    return s.str();
}

std::string MapCrosscheck::failures(size_t limit) const {
    std::ostringstream s;
    if (!ruleBroken.empty()) {
        s << "the device used another hit-group record than R + M*G + C on " << ruleBroken.size()
          << " pixels that hit the same object; the first:\n";
        for (size_t i = 0; i < std::min(limit, ruleBroken.size()); ++i) s << "  " << ruleBroken[i].text << "\n";
    }
    if (!stray.empty()) {
        s << "the device hit another object than refray on " << stray.size()
          << " pixels that are neither order-dependent nor on a silhouette; the first:\n";
        for (size_t i = 0; i < std::min(limit, stray.size()); ++i) s << "  " << stray[i].text << "\n";
    }
    return s.str();
}

std::string MapCrosscheck::exceptions() const {
    std::ostringstream s;
    for (const MapException& e : legal) s << "  " << e.text << "\n";
    return s.str();
}

MapCrosscheck crosscheckIndexMaps(Scene& scene, const RenderSettings& settings, const IndexMapsByKind& device,
                                  const std::vector<uint8_t>& goldenMask, uint64_t adversarialOrders) {
    MapCrosscheck out;
    const uint32_t width = settings.width, height = settings.height;
    const size_t pixels = size_t(width) * height;
    out.width = width, out.height = height;
    for (IndexMapKind kind : {IndexMapKind::Record, IndexMapKind::Instance, IndexMapKind::Geometry, IndexMapKind::Primitive}) {
        if (kind == IndexMapKind::Record && !scene.desc().computeShader.empty()) continue;  // RayQuery: no record (RQ-31)
        const auto it = device.find(kind);
        REFRAY_CHECK(it != device.end(), "the device's " << indexMapKindNames()[size_t(kind)] << " map is missing");
    }
    for (const auto& [kind, values] : device) {
        REFRAY_CHECK(values.size() == pixels, "the device's " << indexMapKindNames()[size_t(kind)] << " map has "
                                                              << values.size() << " pixels, not " << width << "x"
                                                              << height);
        out.kindsCompared.push_back(indexMapKindNames()[size_t(kind)]);
    }
    REFRAY_CHECK(goldenMask.empty() || goldenMask.size() == pixels,
                 "the order mask has " << goldenMask.size() << " pixels, not " << width << "x" << height);

    const SceneDesc& desc = scene.desc();
    const std::vector<PrimaryHit> hits = renderPrimaryHits(scene, settings);
    std::vector<std::vector<PrimaryHit>> adversarial;
    for (uint64_t seed = 1; seed <= adversarialOrders; ++seed) {
        RenderSettings s = settings;
        s.order = dxr::TraversalOrder::Adversarial;
        s.adversarialSeed = seed;
        adversarial.push_back(renderPrimaryHits(scene, s));
    }
    IndexMapsByKind cpu;
    std::vector<IndexMapsByKind> others(adversarial.size());
    for (const auto& [kind, values] : device) {
        cpu[kind] = indexMapOf(desc, width, height, kind, hits).values;
        if (kind == IndexMapKind::Instance || kind == IndexMapKind::Geometry || kind == IndexMapKind::Primitive)
            for (size_t a = 0; a < adversarial.size(); ++a)
                others[a][kind] = indexMapOf(desc, width, height, kind, adversarial[a]).values;
    }
    const std::vector<HitObject> cpuObjects = hitObjects(cpu, pixels), gpuObjects = hitObjects(device, pixels);
    std::vector<std::vector<HitObject>> otherObjects;
    for (const IndexMapsByKind& o : others) otherObjects.push_back(hitObjects(o, pixels));

    // Where refray's own hit depends on the order (the seed that shows it), or the golden's mask says so.
    std::vector<int64_t> orderSeed(pixels, 0);  // 0: not order-dependent; -1: the golden's mask; else the seed
    for (size_t i = 0; i < pixels; ++i) {
        if (!goldenMask.empty() && goldenMask[i] != 0) orderSeed[i] = -1;
        for (size_t a = 0; a < otherObjects.size() && orderSeed[i] == 0; ++a)
            if (!(otherObjects[a][i] == cpuObjects[i])) orderSeed[i] = int64_t(a + 1);
    }

    const auto recordOf = [](const IndexMapsByKind& maps, IndexMapKind kind, size_t i) {
        const auto it = maps.find(kind);
        return it == maps.end() ? int64_t(-2) : it->second[i];
    };
    for (size_t i = 0; i < pixels; ++i) {
        std::ostringstream what;
        what << pixelName(i, width) << " device " << objectName(gpuObjects[i]) << ", refray " << objectName(cpuObjects[i]);
        if (gpuObjects[i] == cpuObjects[i]) {
            ++out.sameObject;
            for (IndexMapKind kind : {IndexMapKind::Record, IndexMapKind::HitGroup}) {
                if (!device.contains(kind)) continue;
                const int64_t d = recordOf(device, kind, i), c = recordOf(cpu, kind, i);
                if (d == c) continue;
                std::ostringstream broken;
                broken << pixelName(i, width) << " " << objectName(cpuObjects[i]) << ": device "
                       << indexMapKindNames()[size_t(kind)] << " " << d << ", refray " << c;
                out.ruleBroken.push_back({i, broken.str()});
                break;
            }
            continue;
        }
        const int64_t ordered = firstNeighbour(i, width, height, [&](size_t n) { return orderSeed[n] != 0; });
        if (ordered >= 0) {
            ++out.orderDependent;
            std::ostringstream why;
            why << what.str() << ": order-dependent, ";
            if (size_t(ordered) != i) why << "next to " << pixelName(size_t(ordered), width) << ", where ";
            if (orderSeed[size_t(ordered)] < 0) why << "the golden's order mask is set";
            else why << "refray's own primary ray hits " << objectName(otherObjects[size_t(orderSeed[size_t(ordered)] - 1)][size_t(ordered)])
                     << " under adversarial order seed " << orderSeed[size_t(ordered)] << " (GEN-3)";
            out.legal.push_back({i, why.str()});
            continue;
        }
        const int64_t edge = firstNeighbour(i, width, height, [&](size_t n) { return !(cpuObjects[n] == cpuObjects[i]); });
        if (edge >= 0) {
            ++out.silhouette;
            std::ostringstream why;
            why << what.str() << ": on a silhouette, refray's neighbour " << pixelName(size_t(edge), width) << " shows "
                << objectName(cpuObjects[size_t(edge)]);
            out.legal.push_back({i, why.str()});
            continue;
        }
        out.stray.push_back({i, what.str()});
    }
    return out;
}

}  // namespace refray::scenes
