// Tests inspect/explain.cpp: one pixel's ray tree, recorded from the trace events of a one-pixel dispatch.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/json.h"
#include "inspect/explain.h"
#include "inspect/index_map.h"
#include "scenes/scene.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

using dxr::TraceEvent;

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";
const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

RenderSettings small(uint32_t w = 320, uint32_t h = 180) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.threads = 2;
    return s;
}

std::vector<const RecordedEvent*> ofKind(const Explanation& x, TraceEvent::Kind kind) {
    std::vector<const RecordedEvent*> out;
    for (const RecordedEvent& r : x.events)
        if (r.event.kind == kind) out.push_back(&r);
    return out;
}

// Proceduray, overview camera, 320x180, pixel (112, 100) lies on Pac-man A (instance 2, C = 4): the radiance ray
// selects record 0 + 2×0 + 4 = 4 at StartAddress + 96×4, the shadow ray from its closest hit meets the Julia box
// at record 1 + 2×0 + 2 = 3, and the reflection ray misses (miss record 0).
TEST(Explain, IDX_1_ProcedurayPixelOnPacmanMatchesTheHandComputation) {
    auto scene = loadScene(kProceduray);
    const Explanation x = explainPixel(*scene, small(), 112, 100);
    ASSERT_FALSE(x.error) << x.error->format();
    const uint64_t start = scene->tables(procedural::Precision::Float).HitGroupTable.StartAddress;

    const auto lookups = ofKind(x, TraceEvent::Kind::RecordLookup);
    const auto primary = std::find_if(lookups.begin(), lookups.end(), [](const RecordedEvent* r) {
        return r->event.hasTerms && r->event.depth == 1;
    });
    ASSERT_NE(primary, lookups.end());
    const TraceEvent& e = (*primary)->event;
    EXPECT_EQ(e.terms.rayContribution, 0u);
    EXPECT_EQ(e.terms.multiplier, 2u);
    EXPECT_EQ(e.terms.geometryIndex, 0u);
    EXPECT_EQ(e.terms.instanceContribution, 4u);
    EXPECT_EQ(e.terms.index, 4u);
    EXPECT_EQ(e.recordAddress, start + 96 * 4);
    EXPECT_EQ((*primary)->exportName, "HitGroup_Pacman");

    const std::string text = formatExplanation(x, scene->desc());
    EXPECT_CONTAINS(text, "TraceRay #1 (depth 1, ray type 'Radiance')");
    EXPECT_CONTAINS(text, "candidate: instance 2 'pacmanA' (InstanceID 0), geometry 0, primitive 0, AABB entered at t = ");
    EXPECT_CONTAINS(text, "hit-group record: I = R + M×G + C = 0 + 2×0 + 4 = 4; address = StartAddress + 96×4 = ");
    EXPECT_CONTAINS(text, "intersection shader 'Intersection_Pacman' runs (record 4)");
    EXPECT_CONTAINS(text, "closesthit shader 'ClosestHit_Pacman' runs (record 4)");
    EXPECT_CONTAINS(text, "TraceRay #2 (depth 2, ray type 'Shadow')");
    EXPECT_CONTAINS(text, "RayFlags FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|SKIP_CLOSEST_HIT_SHADER|CULL_BACK_FACING_TRIANGLES");
    EXPECT_CONTAINS(text, "hit-group record: I = R + M×G + C = 1 + 2×0 + 2 = 3; address = StartAddress + 96×3 = ");
    EXPECT_CONTAINS(text, "'HitGroup_Julia_Shadow'");
    EXPECT_CONTAINS(text, "miss shader table record 1 (MissShaderIndex & 0xFFFF); address = StartAddress + 32×1 = ");
    EXPECT_CONTAINS(text, "result of TraceRay #1: hit instance 2 'pacmanA'");
    EXPECT_CONTAINS(text, "payload in: ShadowRayPayload {dist=0, hit=true}");

    // The explanation runs the same shaders: its pixel is the full render's pixel, bit for bit.
    const RenderResult full = scene->render(small());
    ASSERT_TRUE(x.pixel);
    EXPECT_EQ(*x.pixel, full.image.at(112, 100));
}

// The D3D12 sample: the procedural BLAS holds ten AABB geometries, C = 2, M = 2. Pixel (238, 82) at 320x180 lies
// on geometry 3 (the index map agrees): 0 + 2×3 + 2 = 8, at StartAddress + 96×8.
TEST(Explain, IDX_1_D3D12PixelOnGeometryThreeMatchesTheHandComputation) {
    auto scene = loadScene(kD3D12);
    const IndexMap map = renderIndexMap(*scene, small(), IndexMapKind::Record);
    EXPECT_EQ(map.values[82 * 320 + 238], 8);
    const Explanation e = explainPixel(*scene, small(), 238, 82);
    ASSERT_FALSE(e.error);
    const std::string text = formatExplanation(e, scene->desc());
    EXPECT_CONTAINS(text, "hit-group record: I = R + M×G + C = 0 + 2×3 + 2 = 8; address = StartAddress + 96×8 = ");
    EXPECT_CONTAINS(text, "'MyHitGroup_AABB_SignedDistancePrimitive'");
    EXPECT_CONTAINS(text, "result of TraceRay #1: hit instance 1 'primitives' (InstanceID 0), geometry 3, primitive 0");
}

// docs/tutorial-indexing.md quotes these explanations; its hand computations must stay true.
TEST(Explain, TheTutorialQuotesTheExplanationsItComputesByHand) {
    const std::string tutorial = testing::readText(std::string(REFRAY_SOURCE_DIR) + "/docs/tutorial-indexing.md");
    struct Case {
        std::string scene;
        uint32_t x, y;
    };
    for (const Case& c : {Case{kProceduray, 112, 100}, Case{kD3D12, 238, 82}}) {
        auto scene = loadScene(c.scene);
        const std::string text = formatExplanation(explainPixel(*scene, small(), c.x, c.y), scene->desc());
        size_t quoted = 0;
        for (size_t at = 0, end; at < text.size(); at = end + 1) {
            end = text.find('\n', at);
            if (end == std::string::npos) end = text.size();
            std::string line = text.substr(at, end - at);
            line.erase(0, line.find_first_not_of(' '));
            if (line.rfind("hit-group record:", 0) == 0 || line.rfind("miss shader table record", 0) == 0 ||
                line.rfind("TraceRay #", 0) == 0) {
                if (tutorial.find(line) != std::string::npos) ++quoted;
            }
        }
        EXPECT_GE(quoted, 3u) << "the tutorial should quote the record lines of " << c.scene << " pixel " << c.x << "," << c.y;
    }
}

TEST(Explain, AMissIsExplainedWithItsMissRecord) {
    auto scene = loadScene(kProceduray);
    const Explanation x = explainPixel(*scene, small(), 300, 5);
    const std::string text = formatExplanation(x, scene->desc());
    EXPECT_CONTAINS(text, "miss shader table record 0 (MissShaderIndex & 0xFFFF); address = StartAddress + 32×0 = ");
    EXPECT_CONTAINS(text, "miss shader 'Miss' runs (record 0)");
    EXPECT_CONTAINS(text, "result of TraceRay #1: miss");
}

TEST(Explain, OnlyThePixelAskedForRuns) {
    auto scene = loadScene(kProceduray);
    const Explanation x = explainPixel(*scene, small(), 112, 100);
    ASSERT_FALSE(x.events.empty());
    for (const RecordedEvent& r : x.events) {
        if (r.event.depth == 0 && r.event.kind == TraceEvent::Kind::RecordLookup) continue;  // the ray generation record
        EXPECT_EQ(r.event.launchIndex, uvec3(112, 100, 0));
    }
}

TEST(Explain, JsonCarriesEveryEvent) {
    auto scene = loadScene(kProceduray);
    const Explanation x = explainPixel(*scene, small(), 112, 100);
    const json::Value doc = json::parse(explanationJson(x, scene->desc()), "explain.json");
    EXPECT_EQ(doc.asObject().size() > 0, true);
    const json::Value* events = nullptr;
    const json::Value* format = nullptr;
    for (const json::Member& m : doc.asObject()) {
        if (m.key == "events") events = &m.value;
        if (m.key == "format") format = &m.value;
    }
    ASSERT_TRUE(events && format);
    EXPECT_EQ(format->asString(), "refray-explain/1");
    EXPECT_EQ(events->asArray().size(), x.events.size());
    bool sawTerms = false;
    for (const json::Value& e : events->asArray())
        for (const json::Member& m : e.asObject())
            if (m.key == "I" && m.value.asUint32() == 4) sawTerms = true;
    EXPECT_TRUE(sawTerms);
}

TEST(Explain, APixelOutsideTheImageIsAClearError) {
    auto scene = loadScene(kProceduray);
    try {
        explainPixel(*scene, small(), 320, 10);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "--pixel 320,10 is outside the 320x180 image (x in 0..319, y in 0..179)");
    }
}

TEST(Explain, PayloadsAreDecodedFieldByField) {
    const std::vector<uint8_t> bytes = {0, 0, 128, 63, 7, 0, 0, 0};  // 1.0f, 7
    EXPECT_EQ(describePayload("refray::procedural::proceduray::ShadowRayPayload", bytes), "dist=1, hit=true");
    EXPECT_EQ(describePayload("SomethingElse", bytes), "0x3F800000 0x7");
}

// RQ-12, RQ-14, RQ-20, RQ-22: the AO compute scene at 640x360, pixel (288, 203) (docs/ray-query.md): the primary
// query is handed the volumetric primitive's box, the shader commits its hit, and the ground's triangle behind it
// is skipped by the system. Each Proceed line says its result once.
TEST(Explain, RQ_22_AComputeThreadsPrimaryQueryStepByStep) {
    auto scene = loadScene(std::string(REFRAY_SOURCE_DIR) + "/scenes/inline-ambient-occlusion.json");
    const Explanation x = explainPixel(*scene, small(640, 360), 288, 203);
    ASSERT_FALSE(x.error) << x.error->format();
    const std::string text = formatExplanation(x, scene->desc());
    EXPECT_CONTAINS(text, "RayQuery #1 in compute shader 'InlineAmbientOcclusionCS': TraceRayInline");
    EXPECT_CONTAINS(text, "RayQuery #1 Proceed() = TRUE: a procedural candidate for the shader to intersect (instance 1 'primitives' "
                          "(InstanceID 0), geometry 2, primitive 0, box entry t = ");
    EXPECT_CONTAINS(text, "RayQuery #1 commit: CommitProceduralPrimitiveHit (RQ-22): instance 1 'primitives' "
                          "(InstanceID 0), geometry 2, primitive 0, CommittedRayT = ");
    EXPECT_CONTAINS(text, "skipped by the system: t outside (RayTMin, CommittedRayT)");
    EXPECT_CONTAINS(text, "RayQuery #1 Proceed() = FALSE: the search is finished; CommittedRayT = ");
    EXPECT_CONTAINS(text, "RayQuery #9 in compute shader");
    EXPECT_EQ(text.find("TRUE: TRUE"), std::string::npos) << text;
    EXPECT_EQ(text.find("FALSE: FALSE"), std::string::npos) << text;
}

}  // namespace
}  // namespace refray::scenes
