// The shader tables of a built scene as the GPU sees them, and a static check of the indexing rule.
//
// Everything here is read back from the device: the records are the bytes in GPU memory at the addresses of
// the scene's DispatchRaysDesc, each 32-byte identifier resolved through the state object (REC-8, REC-9), the
// instances are the TLAS's instance descs (INST-1) and the geometries the BLASes' build inputs (IDX-4). The
// scene file (SceneDesc) only adds names: instance and BLAS names, the structs that decode root constants and
// where each record came from.
//
// The reachability check runs DXR's hit-group indexing rule, `dxr::hitGroupRecordIndex` (IDX-1..3), for every
// instance x geometry x ray type and reports by rule id what a dispatch would meet at those records: IDX-10,
// IDX-11, IDX-13, IDX-14, REC-8 and PAY-1, plus INST-4 (instances a ray type never hits), IDX-2/IDX-7 (dropped
// index bits) and IDX-12 (records nothing reaches). A dispatch checks a record only when a shader needs it
// (IDX-12), so an error here is an error on the first ray that reaches the record.
//
// The messages are stable (tests and the tutorial quote them). REACH stands for
//   instance 'NAME' (InstanceIndex i), geometry g, ray type 'RAY': I = R + M*G + C = r + m*g + c = I
// and RECORD for "hit-group record n", "miss record n" or "ray generation record".
//   error   IDX-11  REACH is past the end of the hit-group table (R = r, M = m, G = g, C = c; stride S, SizeInBytes N: K records)
//   error   IDX-14  REACH selects hit group 'HG', a triangles|procedural hit group, for AABB|triangle geometry
//   warning PAY-1   REACH selects hit group 'HG', whose closest-hit|any-hit shader 'X' takes payload 'P', not the ray
//                   type's 'Q' (undefined if its closest-hit|any-hit shader runs)
//   note    REC-8   REACH lands on a NULL record: the hit counts, but no any-hit or closest-hit shader runs
//   note    REC-8   REACH lands on a NULL record: no intersection shader runs, so these rays never hit the AABBs
//   warning INST-4  instance 'NAME' (InstanceIndex i) is never hit by 'RAY' rays: InstanceMask 0xMM & InstanceInclusionMask 0xMM = 0
//   warning INST-9  instance 'NAME' (InstanceIndex i) has a singular or non-finite transform and is never traversed
//   error   IDX-10  the hit-group table stride (S) is smaller than RECORD: hit group 'HG' with local root signature 'L'
//                   needs B bytes (REC-5)
//   error   IDX-11  RECORD does not fit in the TABLE: ... needs B bytes (REC-5) from offset O, but SizeInBytes is N
//                   (REC-11 when the stride is 0, IDX-9 for the ray generation record)
//   error   IDX-11  the identifier of RECORD was never written (uninitialized record)
//   error   REC-8   RECORD holds an identifier that is not an export of state object 'SO': it is ...
//   error   IDX-13  RECORD holds miss shader 'X', which does not belong in the hit-group table
//   note    IDX-12  hit-group record n (HOLDS) is reached by no instance, geometry and ray type
//   note    IDX-12  miss record n (HOLDS) is used by no ray type
//   warning IDX-2   ray type 'RAY': RayContributionToHitGroupIndex v keeps only its low 4 bits: R = r
//   warning IDX-2   ray type 'RAY': MultiplierForGeometryContributionToHitGroupIndex v keeps only its low 4 bits: M = m
//   warning IDX-7   ray type 'RAY': MissShaderIndex v keeps only its low 16 bits: i
//   error   IDX-11  ray type 'RAY': miss record MissShaderIndex i is past the end of the miss shader table (stride S,
//                   SizeInBytes N: K records)
//   note    REC-8   ray type 'RAY': miss record i is NULL: a miss runs no shader
//   error   PAY-1   ray type 'RAY': miss record i holds miss shader 'X', which takes payload 'P', not the ray type's 'Q'
// Only records that some unmasked (instance, geometry, ray type) reaches are checked, as a dispatch would.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "emulator/shader_table.h"
#include "procedural/precision.h"
#include "scenes/scene_desc.h"

namespace refray::scenes {

class Scene;

// One field of a root-constants argument, decoded with the scene file's struct (or one plain float per dword).
struct ConstantFieldView {
    std::string name;  // the struct field's name, or "[i]" for plain floats
    StructField::Kind kind = StructField::Kind::Float;
    uint32_t components = 1;
    std::vector<uint32_t> dwords;  // the bits in the record
    bool written = true;           // every byte was written by the host (REC-7)

    std::string typeName() const;  // "float4", "uint", ...
    // "(1.0, 0.9, 0.7, 1.0)", "0.3", "50.0", "-2", "7": floats keep a decimal point, so types show.
    std::string text() const;
};

// One root argument of a record, decoded with its local root signature (REC-5).
struct RootArgumentView {
    uint32_t parameter = 0;      // root parameter index
    std::string kind;            // "root constants", "root CBV", "root SRV", "root UAV" or "descriptor table"
    std::string shaderRegister;  // "b1", "t3", "u0 space1", ...; empty for a table
    uint32_t offset = 0;         // from the record start
    uint32_t size = 0;           // bytes
    bool inTable = true;         // false: the bytes lie past SizeInBytes (nothing decoded)
    bool written = true;         // every byte was written by the host (REC-7)
    // Root constants: the scene file's struct ("" for plain floats) and its fields.
    std::string structName;
    std::vector<ConstantFieldView> fields;
    // Root descriptors and tables: the GPU VA (or descriptor handle) and the buffer it points into.
    uint64_t address = 0;
    std::string buffer;  // "" when no buffer holds the address
    uint64_t bufferOffset = 0;
};

// One record of a shader table.
struct RecordView {
    uint64_t index = 0;
    uint64_t offset = 0;  // from StartAddress
    dxr::GpuVirtualAddress address = 0;
    enum class Contents : uint8_t {
        Export,       // an identifier of the state object: `kind`, `exportName`, ...
        Null,         // all 32 bytes zero (REC-8)
        Unknown,      // bytes that are not an identifier of this state object (`unknown` says what they are)
        Unwritten     // the identifier bytes were never written (REC-7)
    };
    Contents contents = Contents::Null;
    std::string kind;        // "ray generation shader", "miss shader", "callable shader" or "hit group"
    std::string exportName;
    std::string hitGroupType;  // hit groups: "triangles" or "procedural"
    std::string intersection, anyHit, closestHit;  // hit groups: export names, "" for none
    std::string payload;     // hit groups: the payload type their closest-hit / any-hit take; miss: its payload
    std::string unknown;
    std::string localRootSignature;  // "" for none
    uint32_t layoutSize = dxr::kShaderIdentifierSizeInBytes;  // identifier + arguments (REC-5)
    std::vector<RootArgumentView> arguments;
    std::string origin;  // where the scene file wrote this record ("" if the file does not say)

    // "hit group 'HitGroup_Pacman'", "miss shader 'Miss'", "NULL", "never-written bytes", "an unknown identifier".
    std::string describe() const;
};

struct ShaderTableView {
    std::string key;   // "rayGeneration", "miss", "hitGroup" or "callable"
    std::string name;  // "ray generation record", "miss shader table", "hit-group table", "callable shader table"
    dxr::GpuVirtualAddress startAddress = 0;
    uint64_t sizeInBytes = 0;
    uint64_t strideInBytes = 0;  // 0 for the ray generation record
    // Record starts whose identifier lies inside SizeInBytes: (SizeInBytes - 32) / stride + 1 (1 at stride 0).
    uint64_t recordCount = 0;
    std::vector<RecordView> records;
};

struct GeometryView {
    uint32_t geometryIndex = 0;
    std::string type;  // "triangles" or "AABBs"
    uint32_t flags = 0;
    std::string flagNames;  // "OPAQUE", "NONE", ...
    uint32_t primitiveCount = 0;
};

struct BlasView {
    std::string name;
    dxr::GpuVirtualAddress address = 0;
    std::vector<GeometryView> geometries;
};

struct InstanceView {
    uint32_t instanceIndex = 0;
    std::string name;
    uint32_t instanceID = 0;
    uint32_t instanceMask = 0;
    uint32_t flags = 0;
    std::string flagNames;
    uint32_t contribution = 0;  // InstanceContributionToHitGroupIndex
    int32_t blas = -1;          // index into TableView::blases; -1: inactive (BLAS address 0, INST-6)
    dxr::GpuVirtualAddress blasAddress = 0;
};

// A ray type: the TraceRay arguments its shaders pass.
struct RayTypeView {
    uint32_t index = 0;
    std::string name;
    std::string payload;
    uint32_t rayContribution = 0;  // R, as the shaders pass it (IDX-2 masks it)
    uint32_t multiplier = 0;       // M
    uint32_t missShaderIndex = 0;
    uint32_t instanceInclusionMask = 0xFF;
    int64_t missRecord = -1;       // the miss record it uses (IDX-7); -1: past the end of the miss table
    std::string missExport;        // what that record holds: an export name, "NULL", ...
};

// One (instance, geometry, ray type): the record the indexing rule selects.
struct ReachView {
    uint32_t instanceIndex = 0;
    uint32_t geometryIndex = 0;
    uint32_t rayType = 0;
    dxr::HitGroupIndexTerms terms;  // from dxr::hitGroupRecordIndex
    dxr::GpuVirtualAddress address = 0;
    bool maskedOut = false;  // InstanceMask & InstanceInclusionMask & 0xFF == 0: never traversed (INST-4)
    int64_t record = -1;     // index into the hit-group table's records; -1: past its end (IDX-11)
    std::string holds;       // RecordView::describe() of that record, or "past the end of the table"

    // "1 + 2*0 + 4 = 5"
    std::string equation() const;
};

// An export that declares RayQuery objects (RQ-2): their template ray flags, in the order the export declares them
// (ShaderLibrary::declareRayQueries), and where the export runs.
struct RayQueryOwnerView {
    std::string exportName;
    std::string stage;                    // "closesthit", "compute", ... (ShaderStage)
    std::vector<uint32_t> templateFlags;  // one per RayQuery object
    std::vector<std::string> hitGroups;   // the hit groups that import it (hit-group stages)
    uint32_t numThreads[3] = {1, 1, 1};   // compute: [numthreads(x, y, z)]

    // "RayQuery<FORCE_OPAQUE|ACCEPT_FIRST_HIT_AND_END_SEARCH|CULL_BACK_FACING_TRIANGLES>", one per object.
    std::vector<std::string> declarations() const;
};
// "RayQuery<NAMES>" for template ray flags: the names of rayFlagsToString, "NONE" for none.
std::string rayQueryDeclaration(uint32_t templateFlags);

// How the scene renders when it is not DispatchRays: a compute dispatch (SceneDesc::computeShader).
struct ComputeDispatchView {
    std::string shader;                  // empty: the scene renders with DispatchRays
    uint32_t numThreads[3] = {1, 1, 1};  // its [numthreads]
};

struct TableFinding {
    enum class Level : uint8_t { Error, Warning, Note };
    Level level = Level::Error;
    std::string rule;     // "IDX-11"
    std::string message;  // stable text, without the level and rule
    // "error IDX-11: ..."
    std::string format() const;
};
std::string_view toString(TableFinding::Level level);  // "error", "warning", "note"

struct TableView {
    std::string scene;
    std::string shaderLibrary;
    std::string precision;    // "float" or "double"
    std::string stateObject;  // its name
    std::vector<RayTypeView> rayTypes;
    std::vector<InstanceView> instances;  // InstanceIndex order
    std::vector<BlasView> blases;         // the scene file's order
    // Ray generation record, miss table, hit-group table, then the callable table if the dispatch has one.
    std::vector<ShaderTableView> tables;
    std::vector<ReachView> reachability;  // instance, then geometry, then ray type
    std::vector<TableFinding> findings;   // errors, then warnings, then notes; each in the order found
    // Every export of the state object that declares RayQuery objects, by export name.
    std::vector<RayQueryOwnerView> rayQueryOwners;
    // A compute scene: the shader Device::dispatch runs, one thread per pixel; none of the tables above is read.
    ComputeDispatchView compute;

    const ShaderTableView& table(const std::string& key) const;  // throws refray::Error for an unknown key
    size_t count(TableFinding::Level level) const;
    // The reach of (instance name, geometry, ray type name); throws refray::Error if there is none.
    const ReachView& reach(const std::string& instance, uint32_t geometry, const std::string& rayType) const;
};

// Reads the tables of `precision` (building that pipeline if needed) and runs the reachability check.
TableView buildTableView(Scene& scene, procedural::Precision precision);

}  // namespace refray::scenes
