#include "verify/order_check.h"

#include <cstring>
#include <filesystem>

namespace refray::scenes {

std::string orderMaskPath(const std::string& imagePath) {
    const std::filesystem::path p(imagePath);
    return (p.parent_path() / (p.stem().string() + ".order-mask.png")).string();
}

OrderCheckResult checkTraversalOrder(Scene& scene, const RenderSettings& settings, uint32_t adversarialOrders) {
    OrderCheckResult result;
    RenderSettings s = settings;
    s.order = dxr::TraversalOrder::Ordered;
    s.adversarialSeed = 0;
    result.ordered = scene.render(s);
    const Image& reference = result.ordered.image;
    result.mask = Image(reference.width(), reference.height(), vec4(0.0f, 0.0f, 0.0f, 1.0f));
    s.order = dxr::TraversalOrder::Adversarial;
    for (uint32_t seed = 1; seed <= adversarialOrders; ++seed) {
        s.adversarialSeed = seed;
        const RenderResult other = scene.render(s);
        for (uint32_t y = 0; y < reference.height(); ++y)
            for (uint32_t x = 0; x < reference.width(); ++x)
                if (std::memcmp(&reference.at(x, y), &other.image.at(x, y), sizeof(vec4)) != 0)
                    result.mask.at(x, y) = vec4(1.0f);
    }
    result.orders = adversarialOrders;
    for (const vec4& p : result.mask.pixels()) result.orderDependentPixels += p.r > 0.0f ? 1 : 0;
    auto& meta = result.ordered.image.metadata;
    meta["order_check_orders"] = std::to_string(adversarialOrders);
    meta["order_dependent_pixels"] = std::to_string(result.orderDependentPixels);
    result.mask.metadata = meta;
    result.mask.metadata["content"] = "order-dependence mask: 1 = the pixel changes under an adversarial traversal order";
    return result;
}

}  // namespace refray::scenes
