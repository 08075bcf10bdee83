#include "emulator/state_object.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <cxxabi.h>
#include <mutex>
#include <set>

#include "core/strings.h"
#include "emulator/closest_hit_wave.h"
#include "emulator/compute_wave.h"
#include "emulator/intersection_wave.h"
#include "emulator/ray_generation_wave.h"
#include "emulator/limits.h"
#include "emulator/validation.h"

namespace refray::dxr {

std::string TypeTag::name() const {
    if (!valid()) return "(none)";
    int status = 0;
    char* demangled = abi::__cxa_demangle(mangledName, nullptr, nullptr, &status);
    std::string out = status == 0 && demangled ? demangled : mangledName;
    std::free(demangled);
    return out;
}

std::string_view toString(ProgramEntry::Kind kind) {
    switch (kind) {
        case ProgramEntry::Kind::RayGeneration: return "ray generation shader";
        case ProgramEntry::Kind::Miss: return "miss shader";
        case ProgramEntry::Kind::Callable: return "callable shader";
        case ProgramEntry::Kind::HitGroup: return "hit group";
    }
    return "?";
}

void ShaderLibrary::addRayGeneration(std::string name, std::function<void(ShaderContext&)> fn) {
    add({std::move(name), ShaderStage::RayGeneration, {}, {}, {},
         [fn = std::move(fn)](ShaderContext& c, void*, const void*) { fn(c); }});
}

void ShaderLibrary::addWaveRayGeneration(std::string name, WaveRayGenerationShader fn) {
    REFRAY_CHECK(fn, "shader export '" << name << "' has no function");
    ShaderExport e{std::move(name), ShaderStage::RayGeneration, {}, {}, {},
                   [fn](ShaderContext& c, void*, const void*) { RayGenerationWave::runAlone(fn, c); }};
    e.waveRayGeneration = std::move(fn);
    add(std::move(e));
}

void ShaderLibrary::addWaveClosestHit(std::string name, TypeTag payload, TypeTag attributes, WaveClosestHitShader fn) {
    REFRAY_CHECK(fn, "shader export '" << name << "' has no function");
    ShaderExport e{std::move(name), ShaderStage::ClosestHit, payload, attributes, {},
                   [fn](ShaderContext& c, void* p, const void* a) { ClosestHitWave::runAlone(fn, c, p, a); }};
    e.waveClosestHit = std::move(fn);
    add(std::move(e));
}

namespace {

// A compute export of `numThreads`: D3D12's limits on [numthreads] checked.
ShaderExport computeExport(std::string name, uvec3 numThreads, ErasedShader function) {
    REFRAY_CHECK(numThreads.x >= 1 && numThreads.y >= 1 && numThreads.z >= 1 && numThreads.z <= 64 &&
                     uint64_t(numThreads.x) * numThreads.y * numThreads.z <= 1024 && numThreads.x <= 1024 &&
                     numThreads.y <= 1024,
                 "compute shader '" << name << "': numthreads(" << numThreads.x << ", " << numThreads.y << ", "
                                    << numThreads.z << ") is outside D3D12's limits (x, y <= 1024, z <= 64, "
                                    << "x*y*z <= 1024)");
    ShaderExport e{std::move(name), ShaderStage::Compute, {}, {}, {}, std::move(function)};
    e.numThreads = numThreads;
    return e;
}

}  // namespace

void ShaderLibrary::addCompute(std::string name, uvec3 numThreads, std::function<void(ShaderContext&)> fn) {
    add(computeExport(std::move(name), numThreads,
                      [fn = std::move(fn)](ShaderContext& c, void*, const void*) { fn(c); }));
}

void ShaderLibrary::addWaveCompute(std::string name, uvec3 numThreads, WaveComputeShader fn) {
    REFRAY_CHECK(fn, "shader export '" << name << "' has no function");
    ShaderExport e = computeExport(std::move(name), numThreads,
                                   [fn](ShaderContext& c, void*, const void*) { ComputeWave::runAlone(fn, c); });
    e.waveCompute = std::move(fn);
    add(std::move(e));
}

void ShaderLibrary::declareRayQueries(const std::string& name, std::vector<uint32_t> templateRayFlags) {
    auto it = exports_.find(name);
    REFRAY_CHECK(it != exports_.end(), "declareRayQueries: the library has no export '" << name << "'");
    it->second.rayQueryFlags = std::move(templateRayFlags);
}

void ShaderLibrary::add(ShaderExport e) {
    REFRAY_CHECK(!e.name.empty(), "a shader export needs a name");
    REFRAY_CHECK(e.function, "shader export '" << e.name << "' has no function");
    REFRAY_CHECK(!exports_.count(e.name), "shader library already exports '" << e.name << "'");
    const std::string name = e.name;
    exports_.emplace(name, std::move(e));
}

void ShaderLibrary::addWaveIntersection(std::string name, TypeTag attributes, int lanesPerCall,
                                        WaveIntersectionShader fn, ReportHitEnd end) {
    REFRAY_CHECK(fn, "shader export '" << name << "' has no function");
    REFRAY_CHECK(lanesPerCall >= 1 && lanesPerCall <= kMaxWaveWidth,
                 "shader export '" << name << "' takes " << lanesPerCall << " lanes a call, outside 1.." << kMaxWaveWidth);
    ShaderExport e{std::move(name), ShaderStage::Intersection, {}, attributes, {},
                   [fn](ShaderContext& c, void*, const void*) { IntersectionWave::runAlone(fn, c); }, end};
    e.waveIntersection = std::move(fn);
    e.waveLanesPerCall = lanesPerCall;
    add(std::move(e));
}

const ShaderExport* ShaderLibrary::find(const std::string& name) const {
    auto it = exports_.find(name);
    return it == exports_.end() ? nullptr : &it->second;
}

namespace {

constexpr uint8_t kIdentifierMagic[4] = {'R', 'F', 'Y', '1'};
std::atomic<uint32_t> nextFamilyId{1};

// Registry of every state object's export names, consulted only to explain a foreign identifier.
struct FamilyRegistry {
    std::mutex mutex;
    std::map<uint32_t, std::pair<std::string, std::vector<std::string>>> families;
};
FamilyRegistry& familyRegistry() {
    static FamilyRegistry registry;
    return registry;
}

uint64_t fnv1a(std::string_view s, uint64_t seed) {
    uint64_t h = 1469598103934665603ull ^ seed;
    for (unsigned char c : s) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

ShaderIdentifier makeIdentifier(uint32_t family, uint32_t index, ProgramEntry::Kind kind, const std::string& name) {
    ShaderIdentifier id{};
    std::memcpy(id.data(), kIdentifierMagic, 4);
    std::memcpy(id.data() + 4, &family, 4);
    std::memcpy(id.data() + 8, &index, 4);
    const uint32_t k = uint32_t(kind) + 1;
    std::memcpy(id.data() + 12, &k, 4);
    const uint64_t h1 = fnv1a(name, family), h2 = fnv1a(name, ~uint64_t(family));
    std::memcpy(id.data() + 16, &h1, 8);
    std::memcpy(id.data() + 24, &h2, 8);
    return id;
}

// Resolves which signature applies to `target` among explicit and default associations.
RootSignaturePtr resolveAssociation(const std::vector<RootSignatureAssociation>& associations,
                                    const std::string& target, const char* what) {
    std::vector<RootSignaturePtr> explicitOnes, defaults;
    for (const auto& a : associations) {
        if (a.exports.empty()) {
            defaults.push_back(a.signature);
        } else if (std::find(a.exports.begin(), a.exports.end(), target) != a.exports.end()) {
            explicitOnes.push_back(a.signature);
        }
    }
    auto pickUnique = [&](const std::vector<RootSignaturePtr>& list, const char* kind) -> RootSignaturePtr {
        for (const auto& s : list) {
            if (s != list.front())
                throw DxrError(diag("ASSOC-3", std::string("two different ") + kind + " " + what +
                                                   " associations on export '" + target + "'")
                                   .value("first", list.front()->name())
                                   .value("second", s->name()));
        }
        return list.empty() ? nullptr : list.front();
    };
    if (!explicitOnes.empty()) return pickUnique(explicitOnes, "explicit");
    return pickUnique(defaults, "default");
}

struct RegisterRange {
    char kind;  // b, t, u, s
    uint32_t space, first, last;
};

std::vector<RegisterRange> registersOf(const RootSignature& signature) {
    std::vector<RegisterRange> out;
    for (uint32_t i = 0; i < signature.parameterCount(); ++i) {
        const RootParameter& p = signature.parameter(i);
        switch (p.parameterType) {
            case RootParameterType::Constants32Bit:
            case RootParameterType::CBV: out.push_back({'b', p.registerSpace, p.shaderRegister, p.shaderRegister}); break;
            case RootParameterType::SRV: out.push_back({'t', p.registerSpace, p.shaderRegister, p.shaderRegister}); break;
            case RootParameterType::UAV: out.push_back({'u', p.registerSpace, p.shaderRegister, p.shaderRegister}); break;
            case RootParameterType::DescriptorTable:
                for (const DescriptorRange& r : p.ranges) {
                    static const char kinds[] = {'t', 'u', 'b', 's'};  // SRV, UAV, CBV, Sampler
                    const uint32_t last = r.numDescriptors == ~0u ? ~0u : r.baseShaderRegister + r.numDescriptors - 1;
                    out.push_back({kinds[size_t(r.rangeType)], r.registerSpace, r.baseShaderRegister, last});
                }
                break;
        }
    }
    return out;
}

// PIPE-7: a shader's local root signature must not bind registers its global one binds.
void checkRegisterOverlap(const std::string& exportName, const RootSignaturePtr& local, const RootSignaturePtr& global) {
    if (!local || !global) return;
    for (const RegisterRange& l : registersOf(*local))
        for (const RegisterRange& g : registersOf(*global))
            if (l.kind == g.kind && l.space == g.space && l.first <= g.last && g.first <= l.last)
                throw DxrError(diag("PIPE-7", "export '" + exportName + "': local root signature '" + local->name() +
                                                  "' and global root signature '" + global->name() + "' share a register")
                                   .value("register", std::string(1, l.kind) + std::to_string(std::max(l.first, g.first)))
                                   .value("space", l.space));
}

}  // namespace

std::shared_ptr<const StateObject> StateObject::create(const StateObjectDesc& desc) {
    auto so = std::shared_ptr<StateObject>(new StateObject());
    so->name_ = desc.name;
    so->familyId_ = nextFamilyId.fetch_add(1);

    // Shader and pipeline config: required, and every copy must match (PIPE-1, PIPE-2, ASSOC-5).
    if (desc.shaderConfigs.empty())
        throw DxrError(diag("ASSOC-5", "state object '" + desc.name + "' has no shader config subobject"));
    if (desc.pipelineConfigs.empty())
        throw DxrError(diag("ASSOC-5", "state object '" + desc.name + "' has no pipeline config subobject"));
    so->shaderConfig_ = desc.shaderConfigs.front();
    for (const auto& c : desc.shaderConfigs)
        if (c.MaxPayloadSizeInBytes != so->shaderConfig_.MaxPayloadSizeInBytes ||
            c.MaxAttributeSizeInBytes != so->shaderConfig_.MaxAttributeSizeInBytes)
            throw DxrError(diag("PIPE-1", "state object '" + desc.name + "' has shader configs that differ")
                               .value("first", std::to_string(so->shaderConfig_.MaxPayloadSizeInBytes) + "/" +
                                                   std::to_string(so->shaderConfig_.MaxAttributeSizeInBytes))
                               .value("other", std::to_string(c.MaxPayloadSizeInBytes) + "/" +
                                                   std::to_string(c.MaxAttributeSizeInBytes)));
    if (so->shaderConfig_.MaxAttributeSizeInBytes > kMaxAttributeSizeInBytes)
        throw DxrError(diag("PIPE-1", "MaxAttributeSizeInBytes is above the DXR maximum")
                           .value("MaxAttributeSizeInBytes", so->shaderConfig_.MaxAttributeSizeInBytes,
                                  std::to_string(kMaxAttributeSizeInBytes)));
    so->pipelineConfig_ = desc.pipelineConfigs.front();
    for (const auto& c : desc.pipelineConfigs)
        if (c.MaxTraceRecursionDepth != so->pipelineConfig_.MaxTraceRecursionDepth || c.Flags != so->pipelineConfig_.Flags)
            throw DxrError(diag("PIPE-2", "state object '" + desc.name + "' has pipeline configs that differ")
                               .value("first MaxTraceRecursionDepth", so->pipelineConfig_.MaxTraceRecursionDepth)
                               .value("other MaxTraceRecursionDepth", c.MaxTraceRecursionDepth)
                               .hex("first Flags", so->pipelineConfig_.Flags)
                               .hex("other Flags", c.Flags));
    if (so->pipelineConfig_.MaxTraceRecursionDepth > kMaxDeclarableTraceRecursionDepth)
        throw DxrError(diag("PIPE-2", "MaxTraceRecursionDepth is above the DXR maximum")
                           .value("MaxTraceRecursionDepth", so->pipelineConfig_.MaxTraceRecursionDepth,
                                  std::to_string(kMaxDeclarableTraceRecursionDepth)));
    if (so->pipelineConfig_.Flags & ~kDefinedPipelineFlags)
        throw DxrError(diag("PIPE-3", "pipeline config sets undefined flag bits")
                           .hex("Flags", so->pipelineConfig_.Flags)
                           .hex("undefined bits", so->pipelineConfig_.Flags & ~kDefinedPipelineFlags));

    // Collect the library exports.
    std::map<std::string, const ShaderExport*> shaders;
    for (const auto& lib : desc.libraries) {
        REFRAY_CHECK(lib.library, "state object '" << desc.name << "' has a DXIL library subobject without a library");
        so->libraries_.push_back(lib.library);
        std::vector<std::string> names;
        for (const auto& [n, e] : lib.library->exports()) names.push_back(n);
        const std::vector<std::string>& wanted = lib.exports.empty() ? names : lib.exports;
        for (const auto& n : wanted) {
            const ShaderExport* e = lib.library->find(n);
            REFRAY_CHECK(e, "state object '" << desc.name << "': the library has no export '" << n << "'"
                                             << didYouMean(n, names));
            REFRAY_CHECK(!shaders.count(n), "state object '" << desc.name << "': export '" << n
                                                             << "' comes from two libraries");
            shaders[n] = e;
            if (e->stage == ShaderStage::Compute) so->computeShaders_[n] = e;
        }
    }
    so->exports_ = shaders;
    std::vector<std::string> shaderNames;
    for (const auto& [n, e] : shaders) shaderNames.push_back(n);

    // Payload and attribute sizes against the shader config (PIPE-1, PAY-2, IS-5).
    for (const auto& [n, e] : shaders) {
        if (e->payload.valid() && e->payload.size > so->shaderConfig_.MaxPayloadSizeInBytes)
            throw DxrError(diag("PAY-2", "payload of export '" + n + "' is larger than MaxPayloadSizeInBytes")
                               .value("payload type", e->payload.name())
                               .value("payload bytes", e->payload.size,
                                      std::to_string(so->shaderConfig_.MaxPayloadSizeInBytes)));
        if (e->attributes.valid() && e->attributes.size > so->shaderConfig_.MaxAttributeSizeInBytes)
            throw DxrError(diag("IS-5", "attributes of export '" + n + "' are larger than MaxAttributeSizeInBytes")
                               .value("attribute type", e->attributes.name())
                               .value("attribute bytes", e->attributes.size,
                                      std::to_string(so->shaderConfig_.MaxAttributeSizeInBytes)));
    }

    // Every explicit association must name something that exists (ASSOC-1).
    std::vector<std::string> allNames = shaderNames;
    for (const auto& hg : desc.hitGroups) allNames.push_back(hg.HitGroupExport);
    for (const auto* list : {&desc.localRootSignatures, &desc.globalRootSignatures}) {
        for (const auto& a : *list) {
            REFRAY_CHECK(a.signature, "state object '" << desc.name << "' has a root-signature association without a signature");
            const bool wantLocal = list == &desc.localRootSignatures;
            if (a.signature->isLocal() != wantLocal)
                throw DxrError(diag("PIPE-7", "root signature '" + a.signature->name() + "' is used as a " +
                                                  (wantLocal ? "local" : "global") + " root signature but is " +
                                                  (wantLocal ? "not flagged LOCAL_ROOT_SIGNATURE" : "flagged local")));
            for (const auto& target : a.exports)
                if (std::find(allNames.begin(), allNames.end(), target) == allNames.end())
                    throw DxrError(diag("ASSOC-1", "root signature '" + a.signature->name() +
                                                       "' is associated with unknown export '" + target + "'" +
                                                       didYouMean(target, allNames)));
        }
    }

    auto addEntry = [&](ProgramEntry e) {
        checkRegisterOverlap(e.name, e.localRootSignature, e.globalRootSignature);
        e.index = uint32_t(so->entries_.size());
        e.identifier = makeIdentifier(so->familyId_, e.index, e.kind, e.name);
        so->byName_[e.name] = e.index;
        so->entries_.push_back(std::move(e));
    };

    // Ray generation, miss and callable shaders get identifiers of their own (PIPE-5).
    for (const auto& [n, e] : shaders) {
        ProgramEntry entry;
        entry.name = n;
        entry.shader = e;
        if (e->stage == ShaderStage::RayGeneration) entry.kind = ProgramEntry::Kind::RayGeneration;
        else if (e->stage == ShaderStage::Miss) entry.kind = ProgramEntry::Kind::Miss;
        else if (e->stage == ShaderStage::Callable) entry.kind = ProgramEntry::Kind::Callable;
        else continue;
        entry.payload = e->payload;
        entry.localRootSignature = resolveAssociation(desc.localRootSignatures, n, "local root signature");
        entry.globalRootSignature = resolveAssociation(desc.globalRootSignatures, n, "global root signature");
        addEntry(std::move(entry));
    }

    // Hit groups (PIPE-4, ASSOC-4, IS-5).
    for (const auto& hg : desc.hitGroups) {
        const std::string& g = hg.HitGroupExport;
        REFRAY_CHECK(!g.empty(), "state object '" << desc.name << "' has a hit group without a name");
        REFRAY_CHECK(!shaders.count(g) && !so->byName_.count(g),
                     "hit group name '" << g << "' is already used by another export");
        ProgramEntry entry;
        entry.kind = ProgramEntry::Kind::HitGroup;
        entry.name = g;
        entry.hitGroupType = hg.Type;
        auto importShader = [&](const std::string& name, ShaderStage stage) -> const ShaderExport* {
            if (name.empty()) return nullptr;
            auto it = shaders.find(name);
            if (it == shaders.end())
                throw DxrError(diag("PIPE-4", "hit group '" + g + "' imports unknown export '" + name + "'" +
                                                  didYouMean(name, shaderNames)));
            if (it->second->stage != stage)
                throw DxrError(diag("PIPE-4", "hit group '" + g + "' imports '" + name + "' as " +
                                                  std::string(toString(stage)) + " but it is a " +
                                                  std::string(toString(it->second->stage)) + " shader"));
            return it->second;
        };
        entry.intersection = importShader(hg.IntersectionShaderImport, ShaderStage::Intersection);
        entry.anyHit = importShader(hg.AnyHitShaderImport, ShaderStage::AnyHit);
        entry.closestHit = importShader(hg.ClosestHitShaderImport, ShaderStage::ClosestHit);
        if (hg.Type == HitGroupType::Triangles && entry.intersection)
            throw DxrError(diag("PIPE-4", "triangle hit group '" + g + "' names an intersection shader '" +
                                              hg.IntersectionShaderImport + "'; only procedural hit groups may"));
        if (hg.Type == HitGroupType::ProceduralPrimitive && !entry.intersection)
            throw DxrError(diag("PIPE-4", "procedural hit group '" + g + "' has no intersection shader"));

        // Attributes: built-in for triangles, the IS's struct for procedural hits (IS-5).
        entry.attributes = hg.Type == HitGroupType::Triangles ? typeTag<BuiltInTriangleIntersectionAttributes>()
                                                              : entry.intersection->attributes;
        for (const ShaderExport* s : {entry.anyHit, entry.closestHit}) {
            if (!s) continue;
            if (!(s->attributes == entry.attributes))
                throw DxrError(diag("IS-5", "hit group '" + g + "': " + std::string(toString(s->stage)) + " '" +
                                                s->name + "' takes attributes of another type than the hit group produces")
                                   .value("expected", entry.attributes.name())
                                   .value("declared", s->attributes.name()));
        }
        if (entry.anyHit && entry.closestHit && !(entry.anyHit->payload == entry.closestHit->payload))
            throw DxrError(diag("PAY-1", "hit group '" + g + "': any-hit and closest-hit shaders take different payload types")
                               .value("anyhit payload", entry.anyHit->payload.name())
                               .value("closesthit payload", entry.closestHit->payload.name()));
        entry.payload = entry.closestHit ? entry.closestHit->payload
                                         : (entry.anyHit ? entry.anyHit->payload : TypeTag{});

        // One local root signature per hit group (ASSOC-4): the group's and its components' must agree.
        for (const auto* list : {&desc.localRootSignatures, &desc.globalRootSignatures}) {
            const bool local = list == &desc.localRootSignatures;
            const char* what = local ? "local root signature" : "global root signature";
            RootSignaturePtr chosen;
            std::string chosenFrom;
            bool groupExplicit = false;
            for (const auto& a : *list)
                if (std::find(a.exports.begin(), a.exports.end(), g) != a.exports.end()) groupExplicit = true;
            if (groupExplicit) {
                chosen = resolveAssociation(*list, g, what);
                chosenFrom = "hit group '" + g + "'";
            }
            for (const ShaderExport* s : {entry.intersection, entry.anyHit, entry.closestHit}) {
                if (!s) continue;
                RootSignaturePtr sig = resolveAssociation(*list, s->name, what);
                if (!sig) continue;
                if (chosen && sig != chosen)
                    throw DxrError(diag("ASSOC-4", std::string("hit group '") + g + "' would have two " + what + "s")
                                       .value(chosenFrom, chosen->name())
                                       .value("component '" + s->name + "'", sig->name()));
                if (!chosen) {
                    chosen = sig;
                    chosenFrom = "component '" + s->name + "'";
                }
            }
            if (!chosen) chosen = resolveAssociation(*list, g, what);
            (local ? entry.localRootSignature : entry.globalRootSignature) = chosen;
        }
        addEntry(std::move(entry));
    }

    {
        auto& registry = familyRegistry();
        std::lock_guard lock(registry.mutex);
        std::vector<std::string> names;
        for (const auto& e : so->entries_) names.push_back(e.name);
        registry.families[so->familyId_] = {so->name_, std::move(names)};
    }
    return so;
}

const ProgramEntry* StateObject::findEntry(const std::string& exportName) const {
    auto it = byName_.find(exportName);
    return it == byName_.end() ? nullptr : &entries_[it->second];
}

const ShaderExport* StateObject::findComputeShader(const std::string& exportName) const {
    auto it = computeShaders_.find(exportName);
    return it == computeShaders_.end() ? nullptr : it->second;
}

const uint8_t* StateObject::GetShaderIdentifier(const std::string& exportName) const {
    const ProgramEntry* e = findEntry(exportName);
    return e ? e->identifier.data() : nullptr;
}

ShaderIdentifier StateObject::shaderIdentifier(const std::string& exportName) const {
    if (const ProgramEntry* e = findEntry(exportName)) return e->identifier;
    std::vector<std::string> names;
    for (const auto& e : entries_) names.push_back(e.name);
    for (const auto& lib : libraries_)
        if (const ShaderExport* s = lib->find(exportName))
            throw Error("'" + exportName + "' is a " + std::string(toString(s->stage)) +
                        " shader: it has no shader identifier of its own; use the hit group that contains it (REC-9)");
    throw Error("state object '" + name_ + "' has no export '" + exportName + "'" + didYouMean(exportName, names));
}

const ProgramEntry* StateObject::resolve(const uint8_t* identifier, bool& isNull) const {
    isNull = std::all_of(identifier, identifier + kShaderIdentifierSizeInBytes, [](uint8_t b) { return b == 0; });
    if (isNull) return nullptr;
    uint32_t family = 0, index = 0;
    std::memcpy(&family, identifier + 4, 4);
    std::memcpy(&index, identifier + 8, 4);
    if (std::memcmp(identifier, kIdentifierMagic, 4) != 0 || family != familyId_ || index >= entries_.size())
        return nullptr;
    const ProgramEntry& e = entries_[index];
    return std::memcmp(e.identifier.data(), identifier, kShaderIdentifierSizeInBytes) == 0 ? &e : nullptr;
}

std::string StateObject::describeForeignIdentifier(const uint8_t* identifier) {
    uint32_t family = 0, index = 0;
    std::memcpy(&family, identifier + 4, 4);
    std::memcpy(&index, identifier + 8, 4);
    if (std::memcmp(identifier, kIdentifierMagic, 4) == 0) {
        auto& registry = familyRegistry();
        std::lock_guard lock(registry.mutex);
        auto it = registry.families.find(family);
        if (it != registry.families.end() && index < it->second.second.size())
            return "'" + it->second.second[index] + "' of state object '" + it->second.first + "'";
    }
    char hex[80];
    std::snprintf(hex, sizeof hex, "bytes %02X %02X %02X %02X %02X %02X %02X %02X ...", identifier[0], identifier[1],
                  identifier[2], identifier[3], identifier[4], identifier[5], identifier[6], identifier[7]);
    return std::string("no known export (") + hex + ")";
}

}  // namespace refray::dxr
