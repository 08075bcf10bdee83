// Tests inspect/table_view.cpp: the shader tables of both reference scenes read back from GPU memory, checked
// against the fact sheets (reference-scene-proceduray.md §1.2-1.8, reference-scene-d3d12-procedural.md §1.2-1.8),
// and the reachability findings of small scenes whose explicit layout is broken on purpose.
#include <gtest/gtest.h>

#include <memory>

#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "inspect/table_view.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

using procedural::Precision;
using Level = TableFinding::Level;

const std::string kProceduray = std::string(REFRAY_SOURCE_DIR) + "/scenes/proceduray-mandel-julia-pac.json";
const std::string kD3D12 = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry.json";

// The scene-format example (docs/scene-format.md) in explicit layout: the D3D12 sample's ground plane (instance
// 'ground', C = 0) and one AABB with its analytic spheres (instance 'spheres', C = 2); records 0 Ground,
// 1 Ground_Shadow, 2 Spheres, 3 Spheres_Shadow. Triangle records are 32 + 48 bytes, AABB records 32 + 56.
const std::string kExplicit = testing::readText(std::string(REFRAY_SOURCE_DIR) +
                                                "/tests/scenes/data/ground-and-spheres-explicit.json");

const std::string kSpheresShadowRecord = R"(,
      {"hitGroup": "Spheres_Shadow", "localRootSignature": "AABB",
       "arguments": {"l_materialCB": "chrome", "l_aabbCB": {"instanceIndex": 0, "primitiveType": 1}}})";

// The view of kExplicit with `from` replaced by `to` (`from` must occur once; both empty: unchanged).
TableView explicitView(const std::string& from = "", const std::string& to = "") {
    const std::string text = from.empty() ? kExplicit : testing::edited(kExplicit, from, to);
    Scene scene(parseScene(text, "broken.json"));
    return buildTableView(scene, Precision::Float);
}

std::vector<std::string> formatted(const TableView& view, Level level) {
    std::vector<std::string> out;
    for (const TableFinding& f : view.findings)
        if (f.level == level) out.push_back(f.format());
    return out;
}

const ConstantFieldView& field(const RootArgumentView& a, const std::string& name) {
    for (const ConstantFieldView& f : a.fields)
        if (f.name == name) return f;
    throw Error("no field " + name);
}

// ---- the reference scenes

TEST(TableView, ProcedurayHitGroupTableFollowsTheFactSheet) {
    auto scene = loadScene(kProceduray);
    const TableView view = buildTableView(*scene, Precision::Float);
    EXPECT_EQ(view.scene, "proceduray-mandel-julia-pac");
    EXPECT_EQ(view.precision, "float");

    // §1.5: 10 records, stride 32 + 56 rounded up to 96; the last record is not padded.
    const ShaderTableView& hits = view.table("hitGroup");
    EXPECT_EQ(hits.startAddress, scene->tables(Precision::Float).HitGroupTable.StartAddress);
    EXPECT_EQ(hits.strideInBytes, 96u);
    EXPECT_EQ(hits.recordCount, 10u);
    EXPECT_EQ(hits.sizeInBytes, 9u * 96u + 88u);
    ASSERT_EQ(hits.records.size(), 10u);
    const char* groups[10] = {"HitGroup_Triangle",   "HitGroup_Triangle_Shadow", "HitGroup_Julia",  "HitGroup_Julia_Shadow",
                              "HitGroup_Pacman",     "HitGroup_Pacman_Shadow",   "HitGroup_Pacman", "HitGroup_Pacman_Shadow",
                              "HitGroup_Mandelbulb", "HitGroup_Mandelbulb_Shadow"};
    for (uint64_t i = 0; i < 10; ++i) {
        const RecordView& r = hits.records[i];
        EXPECT_EQ(r.index, i);
        EXPECT_EQ(r.offset, 96 * i);
        EXPECT_EQ(r.address, hits.startAddress + 96 * i);
        EXPECT_EQ(r.contents, RecordView::Contents::Export);
        EXPECT_EQ(r.kind, "hit group");
        EXPECT_EQ(r.exportName, groups[i]);
        EXPECT_EQ(r.layoutSize, i < 2 ? 80u : 88u) << i;  // Triangle: 12 constants; Procedural: 12 + 2
    }

    // Record 4: HitGroup_Pacman with material[1] and aabbCB {1, 1}.
    const RecordView& pacman = hits.records[4];
    EXPECT_EQ(pacman.describe(), "hit group 'HitGroup_Pacman'");
    EXPECT_EQ(pacman.hitGroupType, "procedural");
    EXPECT_EQ(pacman.intersection, "Intersection_Pacman");
    EXPECT_EQ(pacman.anyHit, "");
    EXPECT_EQ(pacman.closestHit, "ClosestHit_Pacman");
    EXPECT_EQ(pacman.payload, "RayPayload");
    EXPECT_EQ(pacman.localRootSignature, "Procedural");
    EXPECT_EQ(pacman.origin, "instance 'pacmanA', geometry 0 of BLAS 'Pacman', ray type 'Radiance'");
    ASSERT_EQ(pacman.arguments.size(), 2u);
    const RootArgumentView& material = pacman.arguments[0];
    EXPECT_EQ(material.kind, "root constants");
    EXPECT_EQ(material.shaderRegister, "b1");
    EXPECT_EQ(material.offset, 32u);
    EXPECT_EQ(material.size, 48u);
    EXPECT_EQ(material.structName, "PrimitiveConstantBuffer");
    EXPECT_TRUE(material.written);
    EXPECT_EQ(field(material, "albedo").text(), "(1.0, 1.0, 0.0, 1.0)");
    EXPECT_EQ(field(material, "albedo").typeName(), "float4");
    EXPECT_EQ(field(material, "reflectanceCoef").text(), "0.3");
    EXPECT_EQ(field(material, "diffuseCoef").text(), "0.3");
    EXPECT_EQ(field(material, "specularCoef").text(), "0.7");
    EXPECT_EQ(field(material, "specularPower").text(), "50.0");
    EXPECT_EQ(field(material, "stepScale").text(), "1.0");
    EXPECT_EQ(field(material, "padding").text(), "(0.0, 0.0, 0.0)");
    const RootArgumentView& aabb = pacman.arguments[1];
    EXPECT_EQ(aabb.shaderRegister, "b2");
    EXPECT_EQ(aabb.offset, 80u);
    EXPECT_EQ(aabb.structName, "PrimitiveInstanceConstantBuffer");
    EXPECT_EQ(field(aabb, "instanceIndex").text(), "1");
    EXPECT_EQ(field(aabb, "instanceIndex").typeName(), "uint");
    EXPECT_EQ(field(aabb, "primitiveType").text(), "1");
    // Record 6 is the same hit group for pacmanB: the trap of §1.5, aabbCB.instanceIndex 2 but InstanceIndex 3.
    EXPECT_EQ(field(hits.records[6].arguments[1], "instanceIndex").text(), "2");
    EXPECT_EQ(hits.records[5].closestHit, "");  // shadow hit groups have no closest-hit shader
}

TEST(TableView, ProcedurayInstancesMissTableAndRayGeneration) {
    auto scene = loadScene(kProceduray);
    const TableView view = buildTableView(*scene, Precision::Float);
    // §1.2: contributions 0, 2, 4, 6, 8; mask 1; flags NONE; one geometry each.
    ASSERT_EQ(view.instances.size(), 5u);
    const char* names[5] = {"slab", "julia", "pacmanA", "pacmanB", "mandelbulb"};
    const char* blases[5] = {"GlobalGeometry", "Julia", "Pacman", "Pacman", "Mandelbulb"};
    for (uint32_t i = 0; i < 5; ++i) {
        const InstanceView& inst = view.instances[i];
        EXPECT_EQ(inst.instanceIndex, i);
        EXPECT_EQ(inst.name, names[i]);
        EXPECT_EQ(inst.contribution, 2 * i);
        EXPECT_EQ(inst.instanceMask, 1u);
        EXPECT_EQ(inst.instanceID, 0u);
        EXPECT_EQ(inst.flagNames, "NONE");
        ASSERT_GE(inst.blas, 0);
        EXPECT_EQ(view.blases[size_t(inst.blas)].name, blases[i]);
    }
    ASSERT_EQ(view.blases.size(), 4u);
    ASSERT_EQ(view.blases[0].geometries.size(), 1u);
    EXPECT_EQ(view.blases[0].geometries[0].type, "triangles");
    EXPECT_EQ(view.blases[0].geometries[0].primitiveCount, 12u);  // §1.1: 36 indices
    EXPECT_EQ(view.blases[0].geometries[0].flagNames, "OPAQUE");
    EXPECT_EQ(view.blases[2].geometries[0].type, "AABBs");

    // §1.3-1.4: two ray types, R = r, M = 2, miss index r.
    ASSERT_EQ(view.rayTypes.size(), 2u);
    EXPECT_EQ(view.rayTypes[1].name, "Shadow");
    EXPECT_EQ(view.rayTypes[1].payload, "ShadowRayPayload");
    EXPECT_EQ(view.rayTypes[1].rayContribution, 1u);
    EXPECT_EQ(view.rayTypes[1].multiplier, 2u);
    EXPECT_EQ(view.rayTypes[1].missShaderIndex, 1u);
    EXPECT_EQ(view.rayTypes[1].missRecord, 1);
    EXPECT_EQ(view.rayTypes[1].missExport, "Miss_Shadow");
    EXPECT_EQ(view.rayTypes[1].instanceInclusionMask & 0xFF, 0xFFu);

    const ShaderTableView& miss = view.table("miss");
    EXPECT_EQ(miss.strideInBytes, 32u);
    EXPECT_EQ(miss.recordCount, 2u);
    EXPECT_EQ(miss.records[0].describe(), "miss shader 'Miss'");
    EXPECT_EQ(miss.records[1].payload, "ShadowRayPayload");
    const ShaderTableView& rayGen = view.table("rayGeneration");
    EXPECT_EQ(rayGen.sizeInBytes, 32u);
    ASSERT_EQ(rayGen.records.size(), 1u);
    EXPECT_EQ(rayGen.records[0].describe(), "ray generation shader 'Raygen'");
    EXPECT_EQ(view.tables.size(), 3u);  // no callable table
}

TEST(TableView, IDX_1_ProcedurayShadowRayOnPacmanAUsesRecord5) {
    auto scene = loadScene(kProceduray);
    const TableView view = buildTableView(*scene, Precision::Float);
    const ReachView& r = view.reach("pacmanA", 0, "Shadow");
    EXPECT_EQ(r.equation(), "1 + 2*0 + 4 = 5");
    EXPECT_EQ(r.terms.rayContribution, 1u);
    EXPECT_EQ(r.terms.multiplier, 2u);
    EXPECT_EQ(r.terms.geometryIndex, 0u);
    EXPECT_EQ(r.terms.instanceContribution, 4u);
    EXPECT_EQ(r.record, 5);
    EXPECT_EQ(r.address, view.table("hitGroup").startAddress + 5 * 96);
    EXPECT_EQ(r.holds, "hit group 'HitGroup_Pacman_Shadow'");
    EXPECT_FALSE(r.maskedOut);
    // The scene-format worked example: a shadow ray on pacmanB uses 1 + 2*0 + 6 = 7.
    EXPECT_EQ(view.reach("pacmanB", 0, "Shadow").equation(), "1 + 2*0 + 6 = 7");
    EXPECT_EQ(view.reachability.size(), 10u);  // 5 instances x 1 geometry x 2 ray types
    // A correct scene has nothing to report: every record is reached and fits.
    EXPECT_TRUE(view.findings.empty()) << view.findings.front().format();
}

TEST(TableView, DoublePrecisionReadsItsOwnStateObject) {
    auto scene = loadScene(kProceduray);
    const TableView view = buildTableView(*scene, Precision::Double);
    EXPECT_EQ(view.precision, "double");
    EXPECT_EQ(view.stateObject, "proceduray-mandel-julia-pac (double)");
    EXPECT_EQ(view.table("hitGroup").startAddress, scene->tables(Precision::Double).HitGroupTable.StartAddress);
    EXPECT_EQ(view.table("hitGroup").records[4].exportName, "HitGroup_Pacman");
    EXPECT_TRUE(view.findings.empty());
}

TEST(TableView, D3D12TablesFollowTheFactSheet) {
    auto scene = loadScene(kD3D12);
    const TableView view = buildTableView(*scene, Precision::Float);
    // §1.8: 22 records at stride 96 (the sample pads the last one to 2112 bytes; refray's builder does not).
    const ShaderTableView& hits = view.table("hitGroup");
    EXPECT_EQ(hits.strideInBytes, 96u);
    EXPECT_EQ(hits.recordCount, 22u);
    EXPECT_EQ(hits.sizeInBytes, 21u * 96u + 88u);
    EXPECT_EQ(hits.records[0].exportName, "MyHitGroup_Triangle");
    EXPECT_EQ(hits.records[0].closestHit, "MyClosestHitShader_Triangle");
    EXPECT_EQ(hits.records[0].layoutSize, 80u);
    EXPECT_EQ(hits.records[1].exportName, "MyHitGroup_Triangle_ShadowRay");
    EXPECT_EQ(hits.records[6].exportName, "MyHitGroup_AABB_VolumetricPrimitive");
    EXPECT_EQ(hits.records[6].intersection, "MyIntersectionShader_VolumetricPrimitive");
    EXPECT_EQ(hits.records[21].exportName, "MyHitGroup_AABB_SignedDistancePrimitive_ShadowRay");
    EXPECT_EQ(hits.records[21].layoutSize, 88u);
    // §1.4: the pyramid's (record 2 + 2*9) material has stepScale 0.8; the twisted torus (2 + 2*6) 0.5.
    EXPECT_EQ(field(hits.records[20].arguments[0], "stepScale").text(), "0.8");
    EXPECT_EQ(field(hits.records[14].arguments[0], "stepScale").text(), "0.5");
    EXPECT_EQ(field(hits.records[20].arguments[1], "primitiveType").text(), "6");

    // §1.2: instance contributions 0 and 2; the AABB BLAS has 10 opaque geometries of one AABB each.
    ASSERT_EQ(view.instances.size(), 2u);
    EXPECT_EQ(view.instances[1].contribution, 2u);
    const BlasView& aabbs = view.blases[size_t(view.instances[1].blas)];
    EXPECT_EQ(aabbs.name, "ProceduralPrimitives");
    ASSERT_EQ(aabbs.geometries.size(), 10u);
    for (const GeometryView& g : aabbs.geometries) {
        EXPECT_EQ(g.type, "AABBs");
        EXPECT_EQ(g.flagNames, "OPAQUE");
        EXPECT_EQ(g.primitiveCount, 1u);
    }
    EXPECT_EQ(view.blases[size_t(view.instances[0].blas)].geometries[0].primitiveCount, 2u);

    // The readme's example: a shadow ray on the second AABB geometry (the spheres) uses 1 + 2*1 + 2 = 5,
    // the analytic shadow hit group with the chrome material and {instanceIndex 1, primitiveType 1}.
    const ReachView& r = view.reach("primitives", 1, "Shadow");
    EXPECT_EQ(r.equation(), "1 + 2*1 + 2 = 5");
    ASSERT_EQ(r.record, 5);
    const RecordView& spheres = hits.records[5];
    EXPECT_EQ(spheres.exportName, "MyHitGroup_AABB_AnalyticPrimitive_ShadowRay");
    EXPECT_EQ(spheres.closestHit, "");
    EXPECT_EQ(field(spheres.arguments[0], "albedo").text(), "(0.549, 0.556, 0.554, 1.0)");
    EXPECT_EQ(field(spheres.arguments[0], "reflectanceCoef").text(), "1.0");
    EXPECT_EQ(field(spheres.arguments[1], "instanceIndex").dwords, std::vector<uint32_t>{1});
    EXPECT_EQ(field(spheres.arguments[1], "primitiveType").dwords, std::vector<uint32_t>{1});
    EXPECT_EQ(view.reachability.size(), 22u);  // (1 + 10 geometries) x 2 ray types
    EXPECT_TRUE(view.findings.empty()) << view.findings.front().format();
}

// ---- findings on broken layouts

TEST(TableView, TheExplicitExampleIsClean) {
    const TableView view = explicitView();
    EXPECT_EQ(view.table("hitGroup").recordCount, 4u);
    EXPECT_EQ(view.reach("spheres", 0, "Shadow").equation(), "1 + 2*0 + 2 = 3");
    EXPECT_EQ(view.table("hitGroup").records[3].origin, "hit-group record 3");
    EXPECT_TRUE(view.findings.empty()) << view.findings.front().format();
}

TEST(TableView, IDX_11_RecordMissingAtTheEnd) {
    const TableView view = explicitView(kSpheresShadowRecord, "");
    // 3 records: 2 x 96 + 88 = 280 bytes, so record 3 (offset 288) is past the end.
    EXPECT_EQ(view.table("hitGroup").sizeInBytes, 280u);
    EXPECT_EQ(view.reach("spheres", 0, "Shadow").record, -1);
    EXPECT_EQ(view.reach("spheres", 0, "Shadow").holds, "past the end of the table");
    EXPECT_EQ(formatted(view, Level::Error),
              std::vector<std::string>{
                  "error IDX-11: instance 'spheres' (InstanceIndex 1), geometry 0, ray type 'Shadow': I = R + M*G + C = "
                  "1 + 2*0 + 2 = 3 is past the end of the hit-group table (R = 1, M = 2, G = 0, C = 2; stride 96, "
                  "SizeInBytes 280: 3 records)"});
    EXPECT_EQ(view.findings.size(), 1u);
}

TEST(TableView, IDX_10_StrideSmallerThanTheRecord) {
    const TableView view = explicitView(R"("miss": ["MyMissShader", "MyMissShader_ShadowRay"],)",
                                        R"("miss": ["MyMissShader", "MyMissShader_ShadowRay"], "hitGroupStride": 64,)");
    const ShaderTableView& hits = view.table("hitGroup");
    EXPECT_EQ(hits.strideInBytes, 64u);
    EXPECT_EQ(hits.recordCount, 4u);
    // The identifiers survive (each record's is written after the previous record's arguments) ...
    EXPECT_EQ(hits.records[1].exportName, "Ground_Shadow");
    // ... but record 0's last 16 argument bytes are record 1's identifier: that is what a shader would read.
    EXPECT_NE(field(hits.records[0].arguments[0], "padding").dwords, (std::vector<uint32_t>{0, 0, 0}));
    EXPECT_EQ(formatted(view, Level::Error),
              (std::vector<std::string>{
                  "error IDX-10: the hit-group table stride (64) is smaller than hit-group record 0: hit group 'Ground' "
                  "with local root signature 'Triangle' needs 80 bytes (REC-5)",
                  "error IDX-10: the hit-group table stride (64) is smaller than hit-group record 1: hit group "
                  "'Ground_Shadow' with local root signature 'Triangle' needs 80 bytes (REC-5)",
                  "error IDX-10: the hit-group table stride (64) is smaller than hit-group record 2: hit group 'Spheres' "
                  "with local root signature 'AABB' needs 88 bytes (REC-5)",
                  "error IDX-10: the hit-group table stride (64) is smaller than hit-group record 3: hit group "
                  "'Spheres_Shadow' with local root signature 'AABB' needs 88 bytes (REC-5)"}));
    EXPECT_EQ(view.findings.size(), 4u);
}

TEST(TableView, INST_4_InstanceMaskZero) {
    const TableView view = explicitView(R"("name": "ground", "blas": "Plane", "mask": 1,)",
                                        R"("name": "ground", "blas": "Plane", "mask": 0,)");
    EXPECT_EQ(view.instances[0].instanceMask, 0u);
    EXPECT_TRUE(view.reach("ground", 0, "Radiance").maskedOut);
    EXPECT_TRUE(formatted(view, Level::Error).empty());
    EXPECT_EQ(formatted(view, Level::Warning),
              (std::vector<std::string>{
                  "warning INST-4: instance 'ground' (InstanceIndex 0) is never hit by 'Radiance' rays: InstanceMask "
                  "0x00 & InstanceInclusionMask 0xFF = 0",
                  "warning INST-4: instance 'ground' (InstanceIndex 0) is never hit by 'Shadow' rays: InstanceMask 0x00 "
                  "& InstanceInclusionMask 0xFF = 0"}));
    // Its records are then reached by nothing (IDX-12).
    EXPECT_EQ(formatted(view, Level::Note),
              (std::vector<std::string>{
                  "note IDX-12: hit-group record 0 (hit group 'Ground') is reached by no instance, geometry and ray type",
                  "note IDX-12: hit-group record 1 (hit group 'Ground_Shadow') is reached by no instance, geometry and "
                  "ray type"}));
}

TEST(TableView, INST_4_RayTypeInclusionMask) {
    SceneDesc desc = parseScene(kExplicit, "masks.json");
    desc.instances[1].mask = 0x2;            // spheres
    desc.rayTypes[1].instanceInclusionMask = 0x1;  // shadow rays see only mask bit 0
    Scene scene(std::move(desc));
    const TableView view = buildTableView(scene, Precision::Float);
    EXPECT_EQ(formatted(view, Level::Warning),
              std::vector<std::string>{"warning INST-4: instance 'spheres' (InstanceIndex 1) is never hit by 'Shadow' "
                                       "rays: InstanceMask 0x02 & InstanceInclusionMask 0x01 = 0"});
    EXPECT_FALSE(view.reach("spheres", 0, "Radiance").maskedOut);
    EXPECT_TRUE(view.reach("spheres", 0, "Shadow").maskedOut);
}

TEST(TableView, IDX_14_ContributionOffByOne) {
    // 'spheres' with C = 1: its radiance rays land on the ground's shadow record, its shadow rays on 'Spheres'.
    const TableView view = explicitView(R"("mask": 1, "contribution": 2})", R"("mask": 1, "contribution": 1})");
    EXPECT_EQ(view.instances[1].contribution, 1u);
    EXPECT_EQ(formatted(view, Level::Error),
              std::vector<std::string>{
                  "error IDX-14: instance 'spheres' (InstanceIndex 1), geometry 0, ray type 'Radiance': I = R + M*G + C "
                  "= 0 + 2*0 + 1 = 1 selects hit group 'Ground_Shadow', a triangles hit group, for AABB geometry"});
    EXPECT_EQ(formatted(view, Level::Warning),
              std::vector<std::string>{
                  "warning PAY-1: instance 'spheres' (InstanceIndex 1), geometry 0, ray type 'Shadow': I = R + M*G + C "
                  "= 1 + 2*0 + 1 = 2 selects hit group 'Spheres', whose closest-hit shader 'MyClosestHitShader_AABB' "
                  "takes payload 'RayPayload', not the ray type's 'ShadowRayPayload' (undefined if its closest-hit "
                  "shader runs)"});
    EXPECT_EQ(formatted(view, Level::Note),
              std::vector<std::string>{"note IDX-12: hit-group record 3 (hit group 'Spheres_Shadow') is reached by no "
                                       "instance, geometry and ray type"});
}

TEST(TableView, REC_8_NullRecordsThatAreReached) {
    const TableView view =
        explicitView(R"({"hitGroup": "Ground_Shadow", "localRootSignature": "Triangle", "arguments": {"l_materialCB": "ground"}},)",
                     R"({"hitGroup": null},)");
    const TableView aabb = explicitView(R"({"hitGroup": "Spheres_Shadow", "localRootSignature": "AABB",)",
                                        R"({"hitGroup": null, "localRootSignature": "AABB",)");
    EXPECT_EQ(view.table("hitGroup").records[1].describe(), "NULL");
    EXPECT_EQ(formatted(view, Level::Note),
              std::vector<std::string>{"note REC-8: instance 'ground' (InstanceIndex 0), geometry 0, ray type 'Shadow': "
                                       "I = R + M*G + C = 1 + 2*0 + 0 = 1 lands on a NULL record: the hit counts, but no "
                                       "any-hit or closest-hit shader runs"});
    EXPECT_EQ(formatted(aabb, Level::Note),
              std::vector<std::string>{"note REC-8: instance 'spheres' (InstanceIndex 1), geometry 0, ray type 'Shadow': "
                                       "I = R + M*G + C = 1 + 2*0 + 2 = 3 lands on a NULL record: no intersection shader "
                                       "runs, so these rays never hit the AABBs"});
    EXPECT_TRUE(formatted(view, Level::Error).empty());
}

TEST(TableView, IDX_2_DroppedIndexBitsAreWarnedAndMasked) {
    SceneDesc desc = parseScene(kExplicit, "bits.json");
    desc.rayTypes[1].rayContribution = 17;  // low 4 bits: 1
    Scene scene(std::move(desc));
    const TableView view = buildTableView(scene, Precision::Float);
    EXPECT_EQ(formatted(view, Level::Warning),
              std::vector<std::string>{"warning IDX-2: ray type 'Shadow': RayContributionToHitGroupIndex 17 keeps only "
                                       "its low 4 bits: R = 1"});
    EXPECT_EQ(view.reach("spheres", 0, "Shadow").equation(), "1 + 2*0 + 2 = 3");
    EXPECT_TRUE(formatted(view, Level::Error).empty());
}

TEST(TableView, MissRecordPastTheEndAndUnusedMissRecords) {
    const TableView view = explicitView(R"("miss": ["MyMissShader", "MyMissShader_ShadowRay"],)", R"("miss": ["MyMissShader"],)");
    EXPECT_EQ(view.rayTypes[1].missRecord, -1);
    EXPECT_EQ(formatted(view, Level::Error),
              std::vector<std::string>{"error IDX-11: ray type 'Shadow': miss record MissShaderIndex 1 is past the end of "
                                       "the miss shader table (stride 32, SizeInBytes 32: 1 record)"});
    const TableView swapped = explicitView(R"("miss": ["MyMissShader", "MyMissShader_ShadowRay"],)",
                                           R"("miss": ["MyMissShader", "MyMissShader", "MyMissShader_ShadowRay"],)");
    EXPECT_EQ(formatted(swapped, Level::Error),
              std::vector<std::string>{"error PAY-1: ray type 'Shadow': miss record 1 holds miss shader 'MyMissShader', "
                                       "which takes payload 'RayPayload', not the ray type's 'ShadowRayPayload'"});
    EXPECT_EQ(formatted(swapped, Level::Note),
              std::vector<std::string>{"note IDX-12: miss record 2 (miss shader 'MyMissShader_ShadowRay') is used by no "
                                       "ray type"});
}

TEST(TableView, FindingsAreOrderedErrorsWarningsNotes) {
    const TableView view = explicitView(R"("mask": 1, "contribution": 2})", R"("mask": 1, "contribution": 1})");
    ASSERT_EQ(view.findings.size(), 3u);
    EXPECT_EQ(view.findings[0].level, Level::Error);
    EXPECT_EQ(view.findings[1].level, Level::Warning);
    EXPECT_EQ(view.findings[2].level, Level::Note);
    EXPECT_EQ(view.count(Level::Error), 1u);
    EXPECT_EQ(view.count(Level::Note), 1u);
}

// ---- RayQuery owners (issue 26): which exports own RayQuery objects, and what renders a compute scene

const std::string kInline = std::string(REFRAY_SOURCE_DIR) + "/scenes/d3d12-procedural-geometry-inline.json";
const std::string kInlineAO = std::string(REFRAY_SOURCE_DIR) + "/scenes/inline-ambient-occlusion.json";

const RayQueryOwnerView* ownerOf(const TableView& view, const std::string& exportName) {
    for (const RayQueryOwnerView& o : view.rayQueryOwners)
        if (o.exportName == exportName) return &o;
    return nullptr;
}

TEST(TableView, RQ_2_TheInlineShadowClosestHitsOwnTheirQueries) {
    auto scene = loadScene(kInline);
    const TableView view = buildTableView(*scene, Precision::Float);
    EXPECT_TRUE(view.compute.shader.empty());
    // Only the exports the scene runs: the two inline-shadow closest hits (the AO compute shader is in the library
    // but not the scene's compute shader; the sample's TraceRay closest hits own no query).
    ASSERT_EQ(view.rayQueryOwners.size(), 2u);
    const RayQueryOwnerView* aabb = ownerOf(view, "MyClosestHitShader_AABB_InlineShadow");
    ASSERT_NE(aabb, nullptr);
    EXPECT_EQ(aabb->stage, "closesthit");
    EXPECT_EQ(aabb->declarations(),
              std::vector<std::string>{"RayQuery<FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES>"});
    EXPECT_EQ(aabb->hitGroups, (std::vector<std::string>{"MyHitGroup_AABB_AnalyticPrimitive",
                                                         "MyHitGroup_AABB_VolumetricPrimitive",
                                                         "MyHitGroup_AABB_SignedDistancePrimitive"}));
    const RayQueryOwnerView* triangle = ownerOf(view, "MyClosestHitShader_Triangle_InlineShadow");
    ASSERT_NE(triangle, nullptr);
    EXPECT_EQ(triangle->hitGroups, std::vector<std::string>{"MyHitGroup_Triangle"});
    EXPECT_EQ(triangle->templateFlags, std::vector<uint32_t>{dxr::RAY_FLAG_CULL_BACK_FACING_TRIANGLES |
                                                             dxr::RAY_FLAG_FORCE_OPAQUE |
                                                             dxr::RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH});
}

TEST(TableView, ATraceRaySceneOwnsNoQueries) {
    auto scene = loadScene(kD3D12);
    const TableView view = buildTableView(*scene, Precision::Float);
    EXPECT_TRUE(view.rayQueryOwners.empty());
    EXPECT_TRUE(view.compute.shader.empty());
}

TEST(TableView, AComputeSceneNamesItsDispatchAndItsQueries) {
    auto scene = loadScene(kInlineAO);
    const TableView view = buildTableView(*scene, Precision::Float);
    EXPECT_EQ(view.compute.shader, "InlineAmbientOcclusionCS");
    EXPECT_EQ(std::vector<uint32_t>(view.compute.numThreads, view.compute.numThreads + 3),
              (std::vector<uint32_t>{8, 8, 1}));
    // The closest hits of the pipeline's hit groups own queries too, though the dispatch runs none of them.
    EXPECT_EQ(view.rayQueryOwners.size(), 3u);
    const RayQueryOwnerView* cs = ownerOf(view, "InlineAmbientOcclusionCS");
    ASSERT_NE(cs, nullptr);
    EXPECT_EQ(cs->stage, "compute");
    EXPECT_TRUE(cs->hitGroups.empty());
    EXPECT_EQ(cs->declarations(),
              (std::vector<std::string>{"RayQuery<CULL_BACK_FACING_TRIANGLES>",
                                        "RayQuery<FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES>"}));
}

TEST(TableView, RayQueryDeclarationNamesTheFlags) {
    EXPECT_EQ(rayQueryDeclaration(0), "RayQuery<NONE>");
    EXPECT_EQ(rayQueryDeclaration(dxr::RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES), "RayQuery<SKIP_PROCEDURAL_PRIMITIVES>");
}

}  // namespace
}  // namespace refray::scenes
