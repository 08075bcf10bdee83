// The ray-tracing state object: shader exports as C++ callables, hit groups, root-signature
// associations, shader and pipeline config, and shader identifiers (PIPE, ASSOC, REC-8..10).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <typeinfo>
#include <type_traits>
#include <vector>

#include "emulator/lane_mask.h"
#include "emulator/root_signature.h"
#include "emulator/types.h"

namespace refray::dxr {

class ShaderContext;

// Identifies a payload / attribute / parameter struct: same id <=> same C++ type.
struct TypeTag {
    const void* id = nullptr;
    uint32_t size = 0;
    const char* mangledName = "";
    bool operator==(const TypeTag& o) const { return id == o.id; }
    bool valid() const { return id != nullptr; }
    std::string name() const;  // demangled
};

// T's tag, made once: a reference to it is copied from memory long written (a TypeTag made at each call came back
// through memory and was read with wider loads than its stores, a store-forwarding stall per call).
template <class T>
const TypeTag& typeTag() {
    static_assert(std::is_trivially_copyable_v<T>, "payloads, attributes and parameters are plain HLSL-like structs");
    static const char anchor = 0;
    static const TypeTag tag{&anchor, uint32_t(sizeof(T)), typeid(T).name()};
    return tag;
}

// What the emulator calls: payload/attributes are type-erased pointers whose types
// were checked against the export's declared TypeTags before the call.
using ErasedShader = std::function<void(ShaderContext&, void* payload, const void* attributes)>;

// An intersection shader written for waves (emulator/intersection_wave.h): run once over the lanes of a record group.
class IntersectionWave;
class RayGenerationWave;
class ClosestHitWave;
class ComputeWave;
using WaveIntersectionShader = std::function<void(IntersectionWave&)>;
using WaveRayGenerationShader = std::function<void(RayGenerationWave&)>;
using WaveClosestHitShader = std::function<void(ClosestHitWave&)>;
using WaveComputeShader = std::function<void(ComputeWave&)>;

// How an intersection shader ends when one of its ReportHit calls ends the search (IS-10: FLAG-8, or an any-hit
// shader's AcceptHitAndEndSearch). docs/emulator.md, "Ending an intersection shader".
enum class ReportHitEnd : uint8_t {
    // ReportHit does not return: an exception unwinds the shader back to traversal, so no code after the call runs.
    // Right for every shader; costs a C++ unwind (tens of thousands of instructions) per ended search.
    Unwind,
    // ReportHit returns true and the shader returns by itself. The shader promises that each ReportHit it makes is
    // its last action, as in HLSL's `if (hit) ReportHit(t, kind, attr); }`. Every ported intersection shader is
    // written that way. An intrinsic called after the search ended breaks the promise: an IS-10 error stops the
    // dispatch. DispatchOptions::specialise = false unwinds these shaders too.
    Return,
};

struct ShaderExport {
    std::string name;
    ShaderStage stage = ShaderStage::RayGeneration;
    TypeTag payload;     // AHS, CHS, miss
    TypeTag attributes;  // IS (what it reports), AHS, CHS
    TypeTag parameters;  // callable
    ErasedShader function;
    ReportHitEnd reportHitEnd = ReportHitEnd::Unwind;  // IS
    uvec3 numThreads{1u};  // compute: [numthreads(x, y, z)]
    // The RayQuery objects the shader's code declares (RQ-2), by their template ray flags, in source order: what
    // DXIL records and `refray table` shows. A shader that makes a RayQuery it does not declare stops with RQ-2.
    std::vector<uint32_t> rayQueryFlags = {};
    // IS written for waves: the wave's record groups call this; `function` runs it for one lane alone.
    WaveIntersectionShader waveIntersection = {};
    // The most lanes one waveIntersection call takes (the width of its SIMD math): a larger record group runs in
    // parts of at most this many lanes, each part's lanes numbered from 0.
    int waveLanesPerCall = kMaxWaveWidth;
    // Ray generation written for waves: a wave of launches calls this once; `function` runs it for one lane alone.
    WaveRayGenerationShader waveRayGeneration = {};
    // Closest hit written for waves: the lanes of a wave whose rays selected it call this once; `function` runs it
    // for one lane alone.
    WaveClosestHitShader waveClosestHit = {};
    // Compute written for waves: a wave of dispatch threads calls this once; `function` runs it for one thread alone.
    WaveComputeShader waveCompute = {};
};

// A DXIL library: named shader exports. Signatures mirror HLSL entry points:
//   [shader("closesthit")] void CH(inout Payload p, in Attributes a)
//     -> addClosestHit<Payload, Attributes>("CH", [](ShaderContext& ctx, Payload& p, const Attributes& a) {...})
class ShaderLibrary {
public:
    void addRayGeneration(std::string name, std::function<void(ShaderContext&)> fn);
    // A ray generation shader written for waves (emulator/ray_generation_wave.h): one call runs a wave's launches,
    // whose TraceRays it issues together through RayGenerationWave::TraceRay.
    void addWaveRayGeneration(std::string name, WaveRayGenerationShader fn);
    // [numthreads(x, y, z)] [shader("compute")] void CS(uint3 id : SV_DispatchThreadID): run by Device::dispatch, not
    // part of the ray-tracing pipeline (no identifier); it reads its thread ids from ShaderContext.
    void addCompute(std::string name, uvec3 numThreads, std::function<void(ShaderContext&)> fn);
    // A compute shader written for waves (emulator/compute_wave.h): one call runs a wave of its threads, whose wave
    // calls (a RayQuery's procedural tests) it makes together through ComputeWave::CallsInLoop.
    void addWaveCompute(std::string name, uvec3 numThreads, WaveComputeShader fn);
    template <class Attributes>
    void addIntersection(std::string name, std::function<void(ShaderContext&)> fn,
                         ReportHitEnd end = ReportHitEnd::Unwind) {
        add({std::move(name), ShaderStage::Intersection, {}, typeTag<Attributes>(), {},
             [fn = std::move(fn)](ShaderContext& c, void*, const void*) { fn(c); }, end});
    }
    // An intersection shader written for waves (emulator/intersection_wave.h): one call computes up to
    // `lanesPerCall` (1..kMaxWaveWidth) lanes of a record group together, numbered from 0; each lane's ReportHit goes
    // through IntersectionWave::ReportHit.
    template <class Attributes>
    void addWaveIntersection(std::string name, int lanesPerCall, WaveIntersectionShader fn,
                             ReportHitEnd end = ReportHitEnd::Unwind) {
        addWaveIntersection(std::move(name), typeTag<Attributes>(), lanesPerCall, std::move(fn), end);
    }
    template <class Payload, class Attributes>
    void addAnyHit(std::string name, std::function<void(ShaderContext&, Payload&, const Attributes&)> fn) {
        add({std::move(name), ShaderStage::AnyHit, typeTag<Payload>(), typeTag<Attributes>(), {},
             [fn = std::move(fn)](ShaderContext& c, void* p, const void* a) {
                 fn(c, *static_cast<Payload*>(p), *static_cast<const Attributes*>(a));
             }});
    }
    template <class Payload, class Attributes>
    void addClosestHit(std::string name, std::function<void(ShaderContext&, Payload&, const Attributes&)> fn) {
        add({std::move(name), ShaderStage::ClosestHit, typeTag<Payload>(), typeTag<Attributes>(), {},
             [fn = std::move(fn)](ShaderContext& c, void* p, const void* a) {
                 fn(c, *static_cast<Payload*>(p), *static_cast<const Attributes*>(a));
             }});
    }
    // A closest-hit shader written for waves (emulator/closest_hit_wave.h): one call runs it for the lanes of a wave
    // whose rays selected it, whose TraceRays it issues together through ClosestHitWave::TraceRay; each lane's
    // payload and attributes are ClosestHitWave::payload<Payload> and attributes<Attributes>.
    template <class Payload, class Attributes>
    void addWaveClosestHit(std::string name, WaveClosestHitShader fn) {
        addWaveClosestHit(std::move(name), typeTag<Payload>(), typeTag<Attributes>(), std::move(fn));
    }
    template <class Payload>
    void addMiss(std::string name, std::function<void(ShaderContext&, Payload&)> fn) {
        add({std::move(name), ShaderStage::Miss, typeTag<Payload>(), {}, {},
             [fn = std::move(fn)](ShaderContext& c, void* p, const void*) { fn(c, *static_cast<Payload*>(p)); }});
    }
    template <class Parameters>
    void addCallable(std::string name, std::function<void(ShaderContext&, Parameters&)> fn) {
        add({std::move(name), ShaderStage::Callable, {}, {}, typeTag<Parameters>(),
             [fn = std::move(fn)](ShaderContext& c, void* p, const void*) { fn(c, *static_cast<Parameters*>(p)); }});
    }

    // Records that export `name` declares RayQuery objects with these template ray flags (ShaderExport::rayQueryFlags).
    void declareRayQueries(const std::string& name, std::vector<uint32_t> templateRayFlags);

    const std::map<std::string, ShaderExport>& exports() const { return exports_; }
    const ShaderExport* find(const std::string& name) const;

private:
    void add(ShaderExport e);
    void addWaveIntersection(std::string name, TypeTag attributes, int lanesPerCall, WaveIntersectionShader fn,
                             ReportHitEnd end);
    void addWaveClosestHit(std::string name, TypeTag payload, TypeTag attributes, WaveClosestHitShader fn);
    std::map<std::string, ShaderExport> exports_;
};

enum class HitGroupType : uint8_t { Triangles = 0, ProceduralPrimitive = 1 };

// D3D12_HIT_GROUP_DESC (PIPE-4); an empty import leaves the slot empty.
struct HitGroupDesc {
    std::string HitGroupExport;
    HitGroupType Type = HitGroupType::Triangles;
    std::string AnyHitShaderImport;
    std::string ClosestHitShaderImport;
    std::string IntersectionShaderImport;
};

// A root-signature subobject and its association. An empty export list makes it a
// default association (ASSOC-2); otherwise it is explicit for exactly those exports.
struct RootSignatureAssociation {
    RootSignaturePtr signature;
    std::vector<std::string> exports;
};

struct ShaderConfig {  // D3D12_RAYTRACING_SHADER_CONFIG (PIPE-1)
    uint32_t MaxPayloadSizeInBytes = 0;
    uint32_t MaxAttributeSizeInBytes = 0;
};

struct PipelineConfig {  // D3D12_RAYTRACING_PIPELINE_CONFIG1 (PIPE-2, PIPE-3)
    uint32_t MaxTraceRecursionDepth = 1;
    uint32_t Flags = PIPELINE_FLAG_NONE;
};

struct DxilLibraryDesc {
    std::shared_ptr<const ShaderLibrary> library;
    std::vector<std::string> exports;  // empty: every export of the library
};

// D3D12_STATE_OBJECT_DESC of type RAYTRACING_PIPELINE, as lists of subobjects.
struct StateObjectDesc {
    std::string name = "pipeline";
    std::vector<DxilLibraryDesc> libraries;
    std::vector<HitGroupDesc> hitGroups;
    std::vector<RootSignatureAssociation> localRootSignatures;
    std::vector<RootSignatureAssociation> globalRootSignatures;
    std::vector<ShaderConfig> shaderConfigs;      // required; every copy must match
    std::vector<PipelineConfig> pipelineConfigs;  // required; every copy must match
};

using ShaderIdentifier = std::array<uint8_t, 32>;

// What a shader identifier names: a ray generation, miss or callable shader, or a hit group.
struct ProgramEntry {
    enum class Kind : uint8_t { RayGeneration, Miss, Callable, HitGroup };
    Kind kind = Kind::RayGeneration;
    std::string name;
    uint32_t index = 0;
    ShaderIdentifier identifier{};
    const ShaderExport* shader = nullptr;  // non-hit-group entries
    HitGroupType hitGroupType = HitGroupType::Triangles;
    const ShaderExport* intersection = nullptr;
    const ShaderExport* anyHit = nullptr;
    const ShaderExport* closestHit = nullptr;
    TypeTag payload;     // hit groups: the payload their AHS/CHS take (may be empty)
    TypeTag attributes;  // hit groups: the attribute struct of their hits
    RootSignaturePtr localRootSignature;   // may be null: no local arguments
    RootSignaturePtr globalRootSignature;  // may be null
};
std::string_view toString(ProgramEntry::Kind kind);

class StateObject {
public:
    // Validates and resolves associations. Throws DxrError naming the export and rule.
    static std::shared_ptr<const StateObject> create(const StateObjectDesc& desc);

    const std::string& name() const { return name_; }
    uint32_t familyId() const { return familyId_; }
    uint32_t maxTraceRecursionDepth() const { return pipelineConfig_.MaxTraceRecursionDepth; }
    uint32_t pipelineFlags() const { return pipelineConfig_.Flags; }
    const ShaderConfig& shaderConfig() const { return shaderConfig_; }
    const std::vector<ProgramEntry>& entries() const { return entries_; }

    // ID3D12StateObjectProperties::GetShaderIdentifier: nullptr for an unknown name or
    // for an IS/AHS/CHS export, which have no identifier (REC-9).
    const uint8_t* GetShaderIdentifier(const std::string& exportName) const;
    // The same, but throws refray::Error with a "did you mean" for an unknown name.
    ShaderIdentifier shaderIdentifier(const std::string& exportName) const;
    const ProgramEntry* findEntry(const std::string& exportName) const;
    // A compute export of the state object's libraries (Device::dispatch), or nullptr.
    const ShaderExport* findComputeShader(const std::string& exportName) const;
    // Every compute export, by name.
    const std::map<std::string, const ShaderExport*>& computeShaders() const { return computeShaders_; }
    // Every export of the state object's libraries (those its DXIL library subobjects export), by name: what
    // `refray table` lists the RayQuery objects of (ShaderExport::rayQueryFlags).
    const std::map<std::string, const ShaderExport*>& exports() const { return exports_; }

    // Decodes 32 identifier bytes: the entry, or nullptr when they are not an identifier
    // of this state object (the caller reports REC-8/REC-9). isNull is set for all zeros.
    const ProgramEntry* resolve(const uint8_t* identifier, bool& isNull) const;
    // For diagnostics: what another state object's identifier names ("'X' of state object 'Y'").
    static std::string describeForeignIdentifier(const uint8_t* identifier);

private:
    std::string name_;
    uint32_t familyId_ = 0;
    ShaderConfig shaderConfig_;
    PipelineConfig pipelineConfig_;
    std::vector<ProgramEntry> entries_;
    std::map<std::string, uint32_t> byName_;
    std::map<std::string, const ShaderExport*> computeShaders_;
    std::map<std::string, const ShaderExport*> exports_;
    std::vector<std::shared_ptr<const ShaderLibrary>> libraries_;  // keeps exports alive
};

using StateObjectPtr = std::shared_ptr<const StateObject>;

}  // namespace refray::dxr
