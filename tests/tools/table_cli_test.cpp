// `refray table` as a user runs it: the text report, --json read back with core/json.h, --check's exit status
// and the message for a scene that cannot be read.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/json.h"
#include "tests/tools/cli_run.h"

namespace {

using refray::testing::CliRun;

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";

CliRun run(const std::string& arguments) { return refray::testing::runRefray(arguments); }

// One AABB instance and two records in explicit layout; `contribution` is the instance's C.
std::string oneBoxScene(int contribution) {
    std::ostringstream s;
    s << R"({
  "format": "refray-scene/1",
  "name": "one-box",
  "shaderLibrary": "d3d12-procedural-geometry",
  "layout": "explicit",
  "pipeline": {"rayGeneration": "MyRaygenShader", "maxRecursionDepth": 3, "maxPayloadBytes": 20, "maxAttributeBytes": 12},
  "rayTypes": [
    {"name": "Radiance", "miss": "MyMissShader", "payload": "RayPayload"},
    {"name": "Shadow", "miss": "MyMissShader_ShadowRay", "payload": "ShadowRayPayload"}
  ],
  "hitGroups": [
    {"name": "Box", "type": "procedural", "intersection": "MyIntersectionShader_AnalyticPrimitive", "closestHit": "MyClosestHitShader_AABB"},
    {"name": "Box_Shadow", "type": "procedural", "intersection": "MyIntersectionShader_AnalyticPrimitive"}
  ],
  "rootSignatures": {"global": {"name": "Global", "parameters": []}},
  "buffers": {},
  "bottomLevel": [{"name": "BoxBLAS", "geometries": [{"type": "aabbs", "flags": ["OPAQUE"], "aabbs": [[-1, -1, -1, 1, 1, 1]]}]}],
  "instances": [{"name": "box", "blas": "BoxBLAS", "contribution": )"
      << contribution << R"(}],
  "shaderTable": {
    "miss": ["MyMissShader", "MyMissShader_ShadowRay"],
    "hitGroups": [{"hitGroup": "Box"}, {"hitGroup": "Box_Shadow"}]
  },
  "globalArguments": {},
  "cameras": [{"name": "front", "model": "directxmath-lh", "eye": [0, 0, -5], "target": [0, 0, 0], "up": [0, 1, 0],
               "fovYDegrees": 45, "near": 0.01, "far": 125}],
  "light": {"position": [0, 18, -20, 0], "ambientColor": [0.25, 0.25, 0.25, 1], "diffuseColor": [0.6, 0.6, 0.6, 1]}
})";
    return s.str();
}

std::string writeScene(const std::string& name, const std::string& text) {
    std::filesystem::create_directories(REFRAY_TEST_OUTPUT_DIR);
    const std::string path = std::string(REFRAY_TEST_OUTPUT_DIR) + "/" + name;
    std::ofstream(path) << text;
    return path;
}

// The first line of `text` that contains every one of `parts`, or "".
std::string lineWith(const std::string& text, std::initializer_list<std::string> parts) {
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        bool all = true;
        for (const std::string& p : parts) all = all && line.find(p) != std::string::npos;
        if (all) return line;
    }
    return "";
}

}  // namespace

TEST(TableCli, TextShowsTablesRecordsReachabilityAndFindings) {
    const CliRun r = run("table " + kProceduray);
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string& out = r.output;
    EXPECT_NE(out.find("Scene 'proceduray-mandel-julia-pac': shader library 'proceduray', float shaders"), std::string::npos) << out;
    EXPECT_NE(out.find("Hit-group table: StartAddress 0x"), std::string::npos) << out;
    EXPECT_NE(out.find("SizeInBytes 952, StrideInBytes 96, 10 records (largest record: 88 bytes)"), std::string::npos) << out;
    EXPECT_NE(out.find("Miss shader table: StartAddress 0x"), std::string::npos) << out;
    EXPECT_NE(out.find("Ray generation record: StartAddress 0x"), std::string::npos) << out;
    // Record 4 and its decoded arguments.
    EXPECT_NE(lineWith(out, {"  4 ", "384", "hit group 'HitGroup_Pacman' (procedural)", "Procedural (88 bytes)"}), "") << out;
    EXPECT_NE(out.find("intersection Intersection_Pacman, closest-hit ClosestHit_Pacman"), std::string::npos) << out;
    EXPECT_NE(out.find("[0] root constants b1 @32 (PrimitiveConstantBuffer): albedo = (1.0, 1.0, 0.0, 1.0), "
                       "reflectanceCoef = 0.3,"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("[1] root constants b2 @80 (PrimitiveInstanceConstantBuffer): instanceIndex = 1, primitiveType = 1"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("from the scene file: instance 'pacmanA', geometry 0 of BLAS 'Pacman', ray type 'Radiance'"),
              std::string::npos)
        << out;
    // Ray types, instances, BLASes.
    EXPECT_NE(lineWith(out, {"Shadow", "ShadowRayPayload", "1: Miss_Shadow"}), "") << out;
    EXPECT_NE(lineWith(out, {"pacmanB", "0x01", "NONE", " 6 ", "Pacman"}), "") << out;
    EXPECT_NE(lineWith(out, {"GlobalGeometry", "triangles", "OPAQUE", "12"}), "") << out;
    // Reachability of (pacmanA, geometry 0, Shadow).
    EXPECT_NE(lineWith(out, {"pacmanA", "Shadow", "1 + 2*0 + 4 = 5", "hit group 'HitGroup_Pacman_Shadow'"}), "") << out;
    EXPECT_NE(out.find("Findings: 0 errors, 0 warnings, 0 notes"), std::string::npos) << out;
}

TEST(TableCli, JsonHasTheSameModel) {
    const CliRun r = run("table " + kProceduray + " --json");
    ASSERT_EQ(r.status, 0) << r.output;
    const refray::json::Value v = refray::json::parse(r.output, "table.json");
    EXPECT_EQ(v.find("scene")->asString(), "proceduray-mandel-julia-pac");
    EXPECT_EQ(v.find("precision")->asString(), "float");
    const auto& rayTypes = v.find("rayTypes")->asArray();
    ASSERT_EQ(rayTypes.size(), 2u);
    EXPECT_EQ(rayTypes[1].find("RayContributionToHitGroupIndex")->asInt(), 1);
    EXPECT_EQ(rayTypes[1].find("MultiplierForGeometryContributionToHitGroupIndex")->asInt(), 2);
    EXPECT_EQ(rayTypes[1].find("missExport")->asString(), "Miss_Shadow");
    const auto& instances = v.find("instances")->asArray();
    ASSERT_EQ(instances.size(), 5u);
    for (size_t i = 0; i < 5; ++i) EXPECT_EQ(instances[i].find("InstanceContributionToHitGroupIndex")->asInt(), int64_t(2 * i));
    EXPECT_EQ(instances[2].find("blas")->asString(), "Pacman");
    EXPECT_EQ(v.find("blases")->asArray()[0].find("geometries")->asArray()[0].find("primitiveCount")->asInt(), 12);

    const auto& tables = v.find("tables")->asArray();
    ASSERT_EQ(tables.size(), 3u);
    const refray::json::Value& hits = tables[2];
    EXPECT_EQ(hits.find("table")->asString(), "hitGroup");
    EXPECT_EQ(hits.find("StrideInBytes")->asInt(), 96);
    EXPECT_EQ(hits.find("SizeInBytes")->asInt(), 952);
    const auto& records = hits.find("records")->asArray();
    ASSERT_EQ(records.size(), 10u);
    const refray::json::Value& pacman = records[4];
    EXPECT_EQ(pacman.find("offset")->asInt(), 384);
    EXPECT_EQ(pacman.find("address")->asInt(), hits.find("StartAddress")->asInt() + 384);
    EXPECT_EQ(pacman.find("export")->asString(), "HitGroup_Pacman");
    EXPECT_EQ(pacman.find("hitGroupType")->asString(), "procedural");
    EXPECT_EQ(pacman.find("intersection")->asString(), "Intersection_Pacman");
    EXPECT_TRUE(pacman.find("anyHit")->isNull());
    EXPECT_EQ(pacman.find("localRootSignature")->asString(), "Procedural");
    const auto& arguments = pacman.find("arguments")->asArray();
    ASSERT_EQ(arguments.size(), 2u);
    const auto& material = arguments[0].find("fields")->asArray();
    EXPECT_EQ(material[0].find("name")->asString(), "albedo");
    EXPECT_EQ(material[0].find("type")->asString(), "float4");
    EXPECT_EQ(material[0].find("value")->asArray()[3].asFloat(), 1.0f);
    EXPECT_EQ(material[1].find("value")->asArray()[0].asFloat(), 0.3f);
    EXPECT_EQ(material[1].find("text")->asString(), "0.3");
    const auto& aabb = arguments[1].find("fields")->asArray();
    EXPECT_EQ(aabb[0].find("name")->asString(), "instanceIndex");
    EXPECT_EQ(aabb[0].find("value")->asArray()[0].asInt(), 1);

    bool found = false;
    for (const refray::json::Value& reach : v.find("reachability")->asArray()) {
        if (reach.find("instance")->asString() != "pacmanA" || reach.find("rayType")->asString() != "Shadow") continue;
        found = true;
        EXPECT_EQ(reach.find("R")->asInt(), 1);
        EXPECT_EQ(reach.find("M")->asInt(), 2);
        EXPECT_EQ(reach.find("G")->asInt(), 0);
        EXPECT_EQ(reach.find("C")->asInt(), 4);
        EXPECT_EQ(reach.find("I")->asInt(), 5);
        EXPECT_EQ(reach.find("equation")->asString(), "1 + 2*0 + 4 = 5");
        EXPECT_EQ(reach.find("record")->asInt(), 5);
        EXPECT_EQ(reach.find("holds")->asString(), "hit group 'HitGroup_Pacman_Shadow'");
    }
    EXPECT_TRUE(found);
    EXPECT_TRUE(v.find("findings")->asArray().empty());
    EXPECT_EQ(v.find("summary")->find("errors")->asInt(), 0);
}

TEST(TableCli, CheckExitsOneOnlyForErrors) {
    EXPECT_EQ(run("table " + kProceduray + " --check").status, 0);
    const std::string clean = writeScene("table-one-box.json", oneBoxScene(0));
    const CliRun ok = run("table " + clean + " --check");
    EXPECT_EQ(ok.status, 0) << ok.output;
    EXPECT_NE(ok.output.find("Findings: 0 errors, 0 warnings, 0 notes"), std::string::npos) << ok.output;

    // C = 1: the radiance ray lands on Box_Shadow, the shadow ray (I = 2) past the end of the two records.
    const std::string broken = writeScene("table-one-box-c1.json", oneBoxScene(1));
    const CliRun bad = run("table " + broken + " --check");
    EXPECT_EQ(bad.status, 1) << bad.output;
    EXPECT_NE(bad.output.find("Findings: 1 error, 0 warnings, 1 note"), std::string::npos) << bad.output;
    EXPECT_NE(bad.output.find("  error IDX-11: instance 'box' (InstanceIndex 0), geometry 0, ray type 'Shadow': "
                              "I = R + M*G + C = 1 + 2*0 + 1 = 2 is past the end of the hit-group table (R = 1, M = 2, "
                              "G = 0, C = 1; stride 32, SizeInBytes 64: 2 records)"),
              std::string::npos)
        << bad.output;
    EXPECT_NE(bad.output.find("  note IDX-12: hit-group record 0 (hit group 'Box') is reached by no instance, geometry and "
                              "ray type"),
              std::string::npos)
        << bad.output;
    // Without --check the report is the same and the status 0.
    EXPECT_EQ(run("table " + broken).status, 0);
    // --json --check: the findings are in the JSON and the status still says there is an error.
    const CliRun json = run("table " + broken + " --json --check");
    EXPECT_EQ(json.status, 1);
    const refray::json::Value v = refray::json::parse(json.output, "table.json");
    ASSERT_EQ(v.find("findings")->asArray().size(), 2u);
    EXPECT_EQ(v.find("findings")->asArray()[0].find("level")->asString(), "error");
    EXPECT_EQ(v.find("findings")->asArray()[0].find("rule")->asString(), "IDX-11");
    EXPECT_TRUE(v.find("reachability")->asArray()[1].find("record")->isNull());
}

TEST(TableCli, DoublePrecisionUsesItsOwnStateObject) {
    const CliRun r = run("table " + kProceduray + " --precision double");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("double shaders, state object 'proceduray-mandel-julia-pac (double)'"), std::string::npos)
        << r.output;
    const CliRun bad = run("table " + kProceduray + " --precision half");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.output.find("--precision"), std::string::npos) << bad.output;
}

TEST(TableCli, UnreadableSceneExitsTwo) {
    const CliRun r = run("table /nonexistent/scene.json");
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("refray table: cannot read scene file '/nonexistent/scene.json': no such file or directory"), std::string::npos) << r.output;
    const std::string broken = writeScene("table-broken.json", "{\"format\": \"refray-scene/1\",");
    const CliRun parse = run("table " + broken + " --check");
    EXPECT_EQ(parse.status, 2) << parse.output;
    EXPECT_NE(parse.output.find("refray table: " + broken + ":1:"), std::string::npos) << parse.output;
}

// Issue 26: `refray table` says which shaders own RayQuery objects, with their template flags, and that a compute
// scene's tables are not read.
TEST(TableCli, TextNamesTheRayQueryOwnersAndTheComputeDispatch) {
    const CliRun r = run("table " + std::string(REFRAY_SOURCE_DIR) + "/scenes/inline-ambient-occlusion.json");
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string& out = r.output;
    EXPECT_NE(out.find("Renders with a compute dispatch: Dispatch of compute shader 'InlineAmbientOcclusionCS', "
                       "numthreads(8, 8, 1), one thread per pixel (Device::dispatch). The ray-tracing pipeline and the "
                       "shader tables below are built but not read by it"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("RayQuery objects (RQ-2"), std::string::npos) << out;
    EXPECT_NE(lineWith(out, {"InlineAmbientOcclusionCS", "compute", "RayQuery<CULL_BACK_FACING_TRIANGLES>, "
                             "RayQuery<FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES>",
                             "the scene's compute dispatch, numthreads(8, 8, 1)"}),
              "")
        << out;
    EXPECT_NE(lineWith(out, {"MyClosestHitShader_Triangle_InlineShadow", "hit group 'MyHitGroup_Triangle' (in the "
                             "pipeline; the compute dispatch runs no hit group)"}),
              "")
        << out;

    const CliRun inlineShadows = run("table " + std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry-inline.json");
    ASSERT_EQ(inlineShadows.status, 0) << inlineShadows.output;
    EXPECT_EQ(inlineShadows.output.find("compute dispatch"), std::string::npos) << inlineShadows.output;
    EXPECT_NE(lineWith(inlineShadows.output,
                       {"MyClosestHitShader_Triangle_InlineShadow", "closesthit",
                        "RayQuery<FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES>",
                        "hit group 'MyHitGroup_Triangle'"}),
              "")
        << inlineShadows.output;
    // A scene without queries prints no such section.
    EXPECT_EQ(run("table " + kProceduray).output.find("RayQuery"), std::string::npos);
}

TEST(TableCli, JsonNamesTheRayQueryOwnersAndTheComputeDispatch) {
    const CliRun r = run("table " + std::string(REFRAY_SOURCE_DIR) + "/scenes/inline-ambient-occlusion.json --json");
    ASSERT_EQ(r.status, 0) << r.output;
    const refray::json::Value v = refray::json::parse(r.output, "table.json");
    const refray::json::Value& dispatch = *v.find("dispatch");
    EXPECT_EQ(dispatch.find("kind")->asString(), "compute");
    EXPECT_EQ(dispatch.find("computeShader")->asString(), "InlineAmbientOcclusionCS");
    EXPECT_EQ(dispatch.find("numThreads")->asArray()[0].asInt(), 8);
    EXPECT_EQ(dispatch.find("numThreads")->asArray()[2].asInt(), 1);
    EXPECT_FALSE(dispatch.find("shaderTablesRead")->asBool());
    // The compute shader, then the inline-shadow closest hits that the (unread) pipeline's hit groups import.
    const auto& owners = v.find("rayQueryOwners")->asArray();
    ASSERT_EQ(owners.size(), 3u);
    EXPECT_EQ(owners[1].find("export")->asString(), "MyClosestHitShader_AABB_InlineShadow");
    EXPECT_FALSE(owners[1].find("computeDispatch")->asBool());
    EXPECT_EQ(owners[1].find("hitGroups")->asArray().size(), 3u);
    EXPECT_EQ(owners[0].find("export")->asString(), "InlineAmbientOcclusionCS");
    EXPECT_TRUE(owners[0].find("computeDispatch")->asBool());
    const auto& queries = owners[0].find("rayQueries")->asArray();
    ASSERT_EQ(queries.size(), 2u);
    EXPECT_EQ(queries[0].find("templateRayFlags")->asInt(), 0x10);
    EXPECT_EQ(queries[1].find("flagNames")->asString(), "FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES");
    EXPECT_EQ(queries[1].find("declaration")->asString(),
              "RayQuery<FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES>");

    const CliRun plain = run("table " + kProceduray + " --json");
    const refray::json::Value p = refray::json::parse(plain.output, "table.json");
    EXPECT_EQ(p.find("dispatch")->find("kind")->asString(), "DispatchRays");
    EXPECT_TRUE(p.find("rayQueryOwners")->asArray().empty());
}
