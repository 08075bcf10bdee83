// A first end-to-end check of the harness: one triangle, one box, one ray each.
#include <gtest/gtest.h>

#include "harness.h"

namespace refray::test {

TEST(Harness, TriangleAndBoxAreHitThroughRealTables) {
    Harness h;
    h.addProbeShaders();
    std::vector<Probe> results(2);
    h.addTracingRayGen([](uvec3 i) { return RayDesc{vec3(i.x == 0 ? 0.0f : 10.0f, 0.2f, -5.0f), 0.0f, vec3(0, 0, 1), 100.0f}; },
                       {}, results);
    const auto tri = h.blas({h.triangles({{-1, -1, 0}, {0, 1, 0}, {1, -1, 0}})});
    const auto box = h.blas({h.aabbs({unitBox()})});
    h.tlas({Harness::instance(tri, 0), Harness::instance(box, 1, Matrix3x4::translation({10, 0, 0}))});
    h.stateObject.pipelineConfigs = {{1, 0}};
    const auto so = h.pipeline();
    h.dispatch(so, h.table(so, {"Miss_Probe"}), h.table(so, {"HG_Tri", "HG_Box"}), uvec3(2, 1, 1));
    EXPECT_EQ(results[0].closestHits, 1u);
    EXPECT_FLOAT_EQ(results[0].t, 5.0f);
    EXPECT_EQ(results[1].closestHits, 1u);
    EXPECT_EQ(results[1].instanceIndex, 1u);
    EXPECT_FLOAT_EQ(results[1].t, 4.0f);
}

}  // namespace refray::test
