// Traversal-order dependence (GEN-3): DXR leaves the order of intersection-shader calls to the implementation,
// and shaders that report t in the wrong units (Proceduray's H1) give different images under different orders.
// An order check renders the ordered policy and N seeded adversarial orders and marks every pixel whose value
// differs, so goldens can ship with a mask and comparisons can report those pixels apart.
#pragma once

#include <cstdint>
#include <string>

#include "core/image.h"
#include "scenes/scene.h"

namespace refray::scenes {

struct OrderCheckResult {
    RenderResult ordered;  // the render under the default (ordered) policy
    Image mask;            // 1 where any adversarial render differs from the ordered one (bitwise, RGBA), else 0
    uint64_t orderDependentPixels = 0;
    uint32_t orders = 0;  // adversarial renders made (seeds 1..orders)
};

// Where the mask of the image at `imagePath` goes: "out.png" -> "out.order-mask.png" beside it.
std::string orderMaskPath(const std::string& imagePath);

// `settings.order` and `settings.adversarialSeed` are ignored: the first render is ordered, then seeds 1..n.
// `settings.progress`, when set, sees each render in turn.
OrderCheckResult checkTraversalOrder(Scene& scene, const RenderSettings& settings, uint32_t adversarialOrders);

}  // namespace refray::scenes
