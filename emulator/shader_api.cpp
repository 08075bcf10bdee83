// The intrinsics of ShaderContext (shader_api.h) other than resources (shader_resources.cpp): stage checks,
// system values, ReportHit, IgnoreHit, AcceptHitAndEndSearch, TraceRay, CallShader and root arguments.
#include "emulator/shader_api.h"

#include <cstring>

#include "emulator/detail/candidate_processing.h"
#include "emulator/detail/dispatch_errors.h"
#include "emulator/detail/dispatch_state.h"
#include "emulator/detail/shader_invocation.h"
#include "emulator/detail/thread_state.h"
#include "emulator/detail/trace_ray.h"
#include "emulator/detail/wave.h"
#include "emulator/limits.h"

namespace refray::dxr {

using detail::Invocation;
using detail::stageError;

namespace detail {
LookupCache& lookupCache(Invocation& inv) { return *inv.thread->lookups; }
}  // namespace detail

void ShaderContext::stageViolation(const char* intrinsic) const {
    stageError(inv_, "SV-1", std::string(intrinsic) + "() may not be called from a " + std::string(toString(inv_.stage)) +
                                 " shader");
}

void ShaderContext::calledAfterSearchEnded(const char* intrinsic) const {
    // `intrinsic` is an intrinsic's name ("RayTCurrent") or a description ("a memory read").
    std::string what = intrinsic;
    if (what.find(' ') == std::string::npos) what += "()";
    stageError(inv_, "IS-10", "intersection shader '" + inv_.shader->name + "' is registered with ReportHitEnd::Return " +
                                  "(each ReportHit is its last action) but used " + what +
                                  " after a ReportHit that ended the search");
}

uvec3 ShaderContext::DispatchRaysIndex() const {
    requireStage(kRayTracingStages, "DispatchRaysIndex");
    return inv_.thread->launchIndex;
}

uvec3 ShaderContext::DispatchRaysDimensions() const {
    requireStage(kRayTracingStages, "DispatchRaysDimensions");
    const DispatchRaysDesc& d = *inv_.dispatch->desc;
    return {d.Width, d.Height, d.Depth};
}

uvec3 ShaderContext::DispatchThreadID() const {
    requireStage(bit(ShaderStage::Compute), "DispatchThreadID");
    return inv_.thread->launchIndex;
}

uvec3 ShaderContext::GroupID() const {
    requireStage(bit(ShaderStage::Compute), "GroupID");
    return inv_.thread->launchIndex / inv_.shader->numThreads;
}

uvec3 ShaderContext::GroupThreadID() const {
    requireStage(bit(ShaderStage::Compute), "GroupThreadID");
    return inv_.thread->launchIndex % inv_.shader->numThreads;
}

uint32_t ShaderContext::GroupIndex() const {
    requireStage(bit(ShaderStage::Compute), "GroupIndex");
    const uvec3 t = inv_.thread->launchIndex % inv_.shader->numThreads;
    const uvec3 n = inv_.shader->numThreads;
    return (t.z * n.y + t.y) * n.x + t.x;
}

float ShaderContext::RayTCurrent() const {
    requireStage(kRay, "RayTCurrent");
    switch (inv_.stage) {  // SV-5
        case ShaderStage::Intersection: return inv_.ray->tCurrent;
        case ShaderStage::AnyHit:
        case ShaderStage::ClosestHit: return inv_.hit->t;
        default: return inv_.ray->ray.TMax;
    }
}

uint32_t ShaderContext::InstanceID() const { return hitInfo("InstanceID").instance->desc.InstanceID; }

Matrix3x4 ShaderContext::ObjectToWorld3x4() const { return hitInfo("ObjectToWorld3x4").instance->objectToWorld; }
std::array<std::array<float, 3>, 4> ShaderContext::ObjectToWorld4x3() const {
    return transposed(hitInfo("ObjectToWorld4x3").instance->objectToWorld);
}
Matrix3x4 ShaderContext::WorldToObject3x4() const { return hitInfo("WorldToObject3x4").instance->worldToObject; }
std::array<std::array<float, 3>, 4> ShaderContext::WorldToObject4x3() const {
    return transposed(hitInfo("WorldToObject4x3").instance->worldToObject);
}

uint32_t ShaderContext::HitKind() const {
    requireStage(bit(ShaderStage::AnyHit) | bit(ShaderStage::ClosestHit), "HitKind");
    return inv_.hit->hitKind;
}

bool ShaderContext::reportHit(float tHit, uint32_t hitKind, const void* attributes, TypeTag type) {
    requireStage(bit(ShaderStage::Intersection), "ReportHit");
    return detail::reportHit(inv_, tHit, hitKind, attributes, type);
}

void ShaderContext::IgnoreHit() {
    requireStage(bit(ShaderStage::AnyHit), "IgnoreHit");
    throw detail::IgnoreHitSignal{};
}

void ShaderContext::AcceptHitAndEndSearch() {
    requireStage(bit(ShaderStage::AnyHit), "AcceptHitAndEndSearch");
    throw detail::AcceptHitAndEndSearchSignal{};
}

void ShaderContext::TraceRay(const TraceRayCall& call) {
    requireLive("TraceRay");
    if (!(bit(inv_.stage) & (bit(ShaderStage::RayGeneration) | bit(ShaderStage::ClosestHit) | bit(ShaderStage::Miss))))
        stageError(inv_, "RAY-2", "TraceRay() may not be called from a " + std::string(toString(inv_.stage)) + " shader");
    // Timed here rather than inside detail::traceRay: a cleanup there would lengthen the unwind table that
    // every end-search signal caught in it walks. The shaders it invokes charge their own time.
    const detail::ProfileScope traversal(*inv_.thread, ProfileStage::Traversal);
    detail::traceRay(inv_, call);
}

void ShaderContext::callShader(uint32_t index, void* parameters, TypeTag type) {
    requireLive("CallShader");
    if (!(bit(inv_.stage) & (bit(ShaderStage::RayGeneration) | bit(ShaderStage::ClosestHit) | bit(ShaderStage::Miss) |
                             bit(ShaderStage::Callable))))
        stageError(inv_, "CALL-2", "CallShader() may not be called from a " + std::string(toString(inv_.stage)) + " shader");
    detail::callShader(inv_, index, parameters, type);
}

void ShaderContext::callInWave(const WaveFunction& function, const WaveCallKey& key, void* state) const {
    requireLive("a wave call");
    detail::awaitWaveCall(*inv_.thread, function, key, state);
}

const uint8_t* ShaderContext::rootArgument(bool local, uint32_t parameter, size_t size, TypeTag type) const {
    requireLive(local ? "a local root argument read" : "a global root argument read");
    // Arguments that passed rootArgumentChecked's checks pass them again (LookupCache): the same argument bytes
    // (those of one record, or the dispatch's global ones), parameter, size and type.
    const detail::ArgumentBytes arguments = detail::argumentBytes(inv_, *inv_.dispatch, local);
    const detail::LookupCache::RootArgument& cached =
        inv_.thread->lookups->rootArguments[detail::LookupCache::rootArgumentSlot(arguments.bytes, parameter)];
    if (arguments.bytes && cached.arguments == arguments.bytes && cached.available == arguments.available &&
        cached.parameter == parameter && cached.size == size && cached.type == type.id)
        return cached.bytes;
    return rootArgumentChecked(local, parameter, size, type, arguments);
}

const uint8_t* ShaderContext::rootArgumentChecked(bool local, uint32_t parameter, size_t size, TypeTag type,
                                                  const detail::ArgumentBytes& arguments) const {
    const RootSignature* signature = nullptr;
    if (local) {
        if (inv_.record && inv_.record->entry) signature = inv_.record->entry->localRootSignature.get();
    } else if (inv_.dispatch->global) {
        signature = inv_.dispatch->global->signature().get();
    }
    const auto& [bytes, written, available] = arguments;
    const char* which = local ? "local" : "global";
    if (!signature)
        stageError(inv_, local ? "REC-11" : "PIPE-6",
                   std::string("shader reads ") + which + " root parameter " + std::to_string(parameter) + " but has no " +
                       which + " root signature");
    if (parameter >= signature->parameterCount())
        stageError(inv_, local ? "REC-11" : "PIPE-6",
                   std::string(which) + " root signature '" + signature->name() + "' has " +
                       std::to_string(signature->parameterCount()) + " parameters; the shader reads parameter " +
                       std::to_string(parameter));
    const RootParameter& p = signature->parameter(parameter);
    const bool wantConstants = type.valid();
    if (wantConstants != (p.parameterType == RootParameterType::Constants32Bit) ||
        (wantConstants && size != p.num32BitValues * 4u))
        stageError(inv_, "REC-11",
                   std::string(which) + " root parameter " + std::to_string(parameter) + " of '" + signature->name() +
                       "' is " + std::string(toString(p.parameterType)) +
                       (p.parameterType == RootParameterType::Constants32Bit ? " (" + std::to_string(p.num32BitValues * 4) + " bytes)" : std::string()) +
                       "; the shader reads it as " + (wantConstants ? type.name() + " (" + std::to_string(size) + " bytes)" : std::string("a descriptor")));
    const uint32_t offset = signature->argumentOffset(parameter) - kShaderIdentifierSizeInBytes;
    if (offset + size > available)
        stageError(inv_, "REC-11", std::string(which) + " root parameter " + std::to_string(parameter) +
                                       " lies past the bytes available to the record");
    if (std::memchr(written + offset, 0, size))
        stageError(inv_, "REC-7", std::string("shader reads ") + which + " root parameter " + std::to_string(parameter) +
                                      " of '" + signature->name() + "', whose bytes were never written");
    inv_.thread->lookups->rootArguments[detail::LookupCache::rootArgumentSlot(bytes, parameter)] = {
        bytes, available, parameter, uint32_t(size), type.id, bytes + offset};
    return bytes + offset;
}

GpuVirtualAddress ShaderContext::localRootDescriptor(uint32_t parameter) const {
    GpuVirtualAddress va;
    std::memcpy(&va, rootArgument(true, parameter, 8, TypeTag{}), 8);
    return va;
}

GpuVirtualAddress ShaderContext::globalRootDescriptor(uint32_t parameter) const {
    GpuVirtualAddress va;
    std::memcpy(&va, rootArgument(false, parameter, 8, TypeTag{}), 8);
    return va;
}

GpuDescriptorHandle ShaderContext::globalDescriptorTable(uint32_t parameter) const { return globalRootDescriptor(parameter); }

}  // namespace refray::dxr
