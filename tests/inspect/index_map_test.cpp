// Tests inspect/index_map.cpp: the record / instance / hit group / depth of each pixel's primary ray.
#include <gtest/gtest.h>

#include <set>

#include "inspect/index_map.h"
#include "scenes/scene.h"
#include "tests/error_of.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";

RenderSettings small() {
    RenderSettings s;
    s.width = 160;
    s.height = 90;
    s.threads = 2;
    return s;
}

std::set<int64_t> valuesOf(const IndexMap& map) { return {map.values.begin(), map.values.end()}; }

TEST(IndexMap, ProcedurayPrimaryRaysReachTheRadianceRecordOfEachInstance) {
    auto scene = loadScene(kProceduray);
    const IndexMap records = renderIndexMap(*scene, small(), IndexMapKind::Record);
    const IndexMap instances = renderIndexMap(*scene, small(), IndexMapKind::Instance);
    // Radiance rays: R = 0, M = 2, G = 0, so record = C = 2 x InstanceIndex in this scene; -1 = miss.
    EXPECT_EQ(valuesOf(records), (std::set<int64_t>{-1, 0, 2, 4, 6, 8}));
    ASSERT_EQ(records.values.size(), instances.values.size());
    for (size_t i = 0; i < records.values.size(); ++i)
        EXPECT_EQ(records.values[i], instances.values[i] < 0 ? -1 : 2 * instances.values[i]) << "pixel " << i;
    EXPECT_EQ(records.legend.front().label, "miss (MissShaderIndex 0)");
    EXPECT_EQ(records.legend[2].label, "record 2: HitGroup_Julia (I = 0 + 2*0 + 2)");
    EXPECT_EQ(instances.legend[3].label, "instance 2 'pacmanA' (BLAS 'Pacman', InstanceContribution 4)");
    // Colours follow the legend.
    for (size_t i = 0; i < records.values.size(); ++i) {
        const auto e = std::find_if(records.legend.begin(), records.legend.end(),
                                    [&](const IndexMapEntry& l) { return l.value == records.values[i]; });
        ASSERT_NE(e, records.legend.end());
        ASSERT_EQ(records.map.pixels()[i], e->colour);
    }
}

TEST(IndexMap, HitGroupAndDepthMaps) {
    auto scene = loadScene(kProceduray);
    const IndexMap groups = renderIndexMap(*scene, small(), IndexMapKind::HitGroup);
    std::set<std::string> names;
    for (const IndexMapEntry& e : groups.legend) names.insert(e.label);
    EXPECT_EQ(names, (std::set<std::string>{"miss (MissShaderIndex 0)", "HitGroup_Triangle", "HitGroup_Julia",
                                            "HitGroup_Pacman", "HitGroup_Mandelbulb"}));
    const IndexMap depth = renderIndexMap(*scene, small(), IndexMapKind::Depth);
    // Primary misses end at depth 1; a lit hit adds a shadow ray (2); its reflection adds depth 3 (MAX_RAY_RECURSION_DEPTH).
    EXPECT_EQ(valuesOf(depth), (std::set<int64_t>{1, 2, 3}));
}

TEST(IndexMap, RecordingDoesNotChangeTheImage) {
    auto scene = loadScene(kProceduray);
    RenderSettings plain = small();
    const Image without = scene->render(plain).image;
    class CountingObserver : public dxr::TraceObserver {
    public:
        void onEvent(const dxr::TraceEvent&) override { ++count; }
        std::atomic<uint64_t> count{0};
    } observer;
    plain.observer = &observer;
    const Image with = scene->render(plain).image;
    EXPECT_GT(observer.count.load(), 160u * 90u);
    EXPECT_EQ(with.pixels(), without.pixels());
}

TEST(IndexMap, TheLegendIsDrawnBesideTheMap) {
    auto scene = loadScene(kProceduray);
    const IndexMap records = renderIndexMap(*scene, small(), IndexMapKind::Record);
    bool drewText = false;
    const Image image = withLegend(records, "records", &drewText);
    ASSERT_TRUE(drewText) << "no font: tools/setup.sh installs fonts-dejavu-core";
    EXPECT_GT(image.width(), records.map.width() + 200);
    EXPECT_GE(image.height(), records.map.height());
    EXPECT_EQ(image.at(5, 5), records.map.at(5, 5));
}

TEST(IndexMap, KindNames) {
    EXPECT_EQ(parseIndexMapKind("hitgroup"), IndexMapKind::HitGroup);
    EXPECT_EQ(parseIndexMapKind("depth"), IndexMapKind::Depth);
    EXPECT_FALSE(parseIndexMapKind("records"));
}

TEST(IndexMap, TheValuesImageHoldsTheValuesExactly) {
    auto scene = loadScene(kProceduray);
    const IndexMap records = renderIndexMap(*scene, small(), IndexMapKind::Record);
    const Image values = indexValuesImage(records);
    EXPECT_EQ(values.metadata.at("aov"), "record");
    EXPECT_EQ(readIndexValues(values), records.values);
    Image bad = values;
    bad.pixels()[3].g = 7.0f;
    EXPECT_EQ(refray::testing::errorOf([&] { readIndexValues(bad); }),
              "pixel (3,0) of the index values is (-1, 7, -1), not one index in R, G and B");
}

TEST(IndexMap, ADeviceReportedRecordIsTheValueAndItsLabelSaysSo) {
    auto scene = loadScene(kProceduray);
    const RenderSettings s = small();
    std::vector<PrimaryHit> hits = renderPrimaryHits(*scene, s);
    const IndexMap fromTrace = indexMapOf(scene->desc(), s.width, s.height, IndexMapKind::Record, hits);
    // A device that reports the record R + M*G + C gives the same map.
    for (PrimaryHit& h : hits)
        if (h.hit) h.record = 2 * h.instanceIndex;
    EXPECT_EQ(indexMapOf(scene->desc(), s.width, s.height, IndexMapKind::Record, hits).legend[2].label,
              fromTrace.legend[2].label);
    EXPECT_EQ(indexMapOf(scene->desc(), s.width, s.height, IndexMapKind::Record, hits).values, fromTrace.values);
    // One that reports another record: its value, and the equation it broke.
    for (PrimaryHit& h : hits)
        if (h.hit && h.instanceIndex == 1) h.record = 3;
    const IndexMap other = indexMapOf(scene->desc(), s.width, s.height, IndexMapKind::Record, hits);
    EXPECT_EQ(other.legend[2].label, "record 3: HitGroup_Julia_Shadow (reported; R + M*G + C = 0 + 2*0 + 2 = 2)");
}

// RQ-31, dxr-semantics.md 18e: Vulkan's rayQueryGetIntersectionInstanceIdEXT is DXR's InstanceIndex, and
// ...InstanceCustomIndexEXT DXR's InstanceID; a port that crosses them reads the wrong one. Neither inline scene's
// shaders read either, so no image shows the mistake; the instance map of the compute scene (each thread's first
// query's committed InstanceIndex) does, because the scene's InstanceIDs (0, 0) are not its InstanceIndices (0, 1):
// a back end whose map reports InstanceID puts 0 on every pixel of the procedural primitives.
TEST(IndexMap, RQ_31_AComputeScenesInstanceMapTellsInstanceIndexFromInstanceID) {
    auto scene = loadScene(std::string(REFRAY_SOURCE_DIR) + "/scenes/inline-ambient-occlusion.json");
    const RenderSettings s = small();
    const std::vector<PrimaryHit> hits = renderPrimaryHits(*scene, s);
    std::vector<PrimaryHit> crossed = hits;
    uint64_t primitives = 0;
    for (PrimaryHit& h : crossed) {
        if (!h.hit) continue;
        ASSERT_TRUE(h.instanceID.has_value());
        primitives += h.instanceIndex == 1;
        h.instanceIndex = *h.instanceID;  // what a crossed port reports as InstanceIndex
    }
    EXPECT_GT(primitives, 0u);
    const IndexMap right = indexMapOf(scene->desc(), s.width, s.height, IndexMapKind::Instance, hits);
    const IndexMap wrong = indexMapOf(scene->desc(), s.width, s.height, IndexMapKind::Instance, crossed);
    EXPECT_EQ(right.values, renderIndexMap(*scene, s, IndexMapKind::Instance).values);
    EXPECT_EQ(valuesOf(right), (std::set<int64_t>{-1, 0, 1}));
    uint64_t differ = 0;
    for (size_t i = 0; i < right.values.size(); ++i) differ += right.values[i] != wrong.values[i];
    EXPECT_EQ(differ, primitives);
}

}  // namespace
}  // namespace refray::scenes
