// A second implementation's index maps against refray's: the indexing rule on another device (a GPU round's
// recorded maps, tests/gpu-renders; Mesa's lavapipe in every CI run, tests/lavapipe).
//
// Where the device's primary ray hit the same (instance, geometry, primitive) as refray's, the hit-group record it
// used must be the same: R + M*G + C, with no exception. Where it hit another object, the pixel must be
// order-dependent (DXR leaves the order of intersection-shader calls open, GEN-3) or lie on a silhouette of refray's
// map (a one-ulp difference in a distance or a root moves an edge by a pixel); anywhere else it is a stray hit.
// Every exception is listed with the reason it is legal (docs/gpu-crosscheck.md, "Index maps").
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "inspect/index_map.h"

namespace refray::scenes {

using IndexMapsByKind = std::map<IndexMapKind, std::vector<int64_t>>;

// Seeded adversarial orders that find refray's order-dependent pixels. With 2, the GPU's own order (its BVH
// traversal) still reached 28 pixels of the Mandelbulb close-up that no seed had flagged, next to the 423 the
// golden's 4 orders mark: where Pac-man B's and the Mandelbulb's boxes overlap, and the Proceduray intersection
// shaders report t in object units (hazard H1), so which one commits depends on the order. With 8, and the
// region's 8-neighbourhood, none is left.
constexpr uint64_t kCrosscheckAdversarialOrders = 8;

struct MapException {
    size_t pixel = 0;
    std::string text;  // "(12,40) device instance 3 geometry 0 primitive 0, refray instance 2 ...: on a silhouette ..."
};

struct MapCrosscheck {
    uint32_t width = 0, height = 0;
    uint64_t sameObject = 0;      // pixels whose primary ray hit the same object (or missed) on both
    uint64_t orderDependent = 0;  // another object, on an order-dependent pixel or next to one: legal
    uint64_t silhouette = 0;      // another object, on a silhouette of refray's map: legal
    std::vector<MapException> ruleBroken;  // same object, another record (or hit group): the indexing rule broken
    std::vector<MapException> stray;       // another object anywhere else
    std::vector<MapException> legal;       // every legal exception, with why it is legal
    std::vector<std::string> kindsCompared;

    bool passed() const { return ruleBroken.empty() && stray.empty(); }
    // One line: the counts.
    std::string summary(const std::string& name) const;
    // The failures (at most `limit` of each), for a test's failure message.
    std::string failures(size_t limit = 40) const;
    // Every legal exception with its reason, one per line.
    std::string exceptions() const;
};

// Compares `device` (at least the record, instance, geometry and primitive maps; hitgroup is compared where
// present) with refray's maps of the same scene and settings (spp 1). Order-dependent pixels: where refray's own
// primary hit changes under `adversarialOrders` seeded orders, plus `goldenMask` (an envelope's order mask, empty
// when none applies). Throws refray::Error when a required map is missing or has another size.
MapCrosscheck crosscheckIndexMaps(Scene& scene, const RenderSettings& settings, const IndexMapsByKind& device,
                                  const std::vector<uint8_t>& goldenMask,
                                  uint64_t adversarialOrders = kCrosscheckAdversarialOrders);

}  // namespace refray::scenes
