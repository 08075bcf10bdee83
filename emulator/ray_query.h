// RayQuery (DXR 1.1 inline ray tracing, dxr-semantics.md section 18, RQ-1..RQ-33): the shader that owns the query
// drives traversal itself, one candidate at a time. No shader table and no other shader is involved.
//
// HLSL                                              C++ (a shader holding a ShaderContext& ctx)
//   RayQuery<RAY_FLAG_FORCE_OPAQUE> q;                RayQuery<RAY_FLAG_FORCE_OPAQUE> q(ctx);
//   q.TraceRayInline(AS, flags, mask, ray);           q.TraceRayInline(as, flags, mask, ray);
//   while (q.Proceed()) { ... q.CandidateType() ... } while (q.Proceed()) { ... q.CandidateType() ... }
//   q.CommittedStatus(), q.CommittedRayT(), ...       the same names
//
// Candidates are the ones TraceRay would meet (the same gathering, the same default or seeded adversarial order:
// RQ-13 leaves the order open), with the same culling and opacity rules (RQ-14). Every call in a state the
// specification's tables do not list is a diagnostic like the other [UB] rules (RQ-19): rule id, launch index,
// stage, and the query's state; under OnError::Continue the call does nothing and a getter returns zeros. A use
// that DXR defines but SPIR-V leaves undefined (18e) is recorded as a note, which never changes a result
// (docs/ray-query.md).
#pragma once

#include <array>
#include <cstdint>
#include <exception>
#include <memory>
#include <span>

#include "core/math.h"
#include "emulator/lane_mask.h"
#include "emulator/types.h"
#include "emulator/wave_call.h"

namespace refray::dxr {

class ShaderContext;

// RAYQUERY_FLAG (RQ-6).
inline constexpr uint32_t RAYQUERY_FLAG_NONE = 0x0;
inline constexpr uint32_t RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS = 0x1;
inline constexpr uint32_t RAYQUERY_FLAG_ALLOW_CLUSTERED_GEOMETRY = 0x2;
inline constexpr uint32_t kDefinedRayQueryFlags = 0x3;

// RAY_FLAG_FORCE_OMM_2_STATE (SM 6.9): refray's acceleration structures hold no opacity micromaps, so the flag
// changes nothing at trace time; it is defined here for the template-flag rule of RQ-33.
inline constexpr uint32_t RAY_FLAG_FORCE_OMM_2_STATE = 0x400;

// CANDIDATE_TYPE (RQ-17) and COMMITTED_STATUS (RQ-18).
inline constexpr uint32_t CANDIDATE_NON_OPAQUE_TRIANGLE = 0;
inline constexpr uint32_t CANDIDATE_PROCEDURAL_PRIMITIVE = 1;
inline constexpr uint32_t COMMITTED_NOTHING = 0;
inline constexpr uint32_t COMMITTED_TRIANGLE_HIT = 1;
inline constexpr uint32_t COMMITTED_PROCEDURAL_PRIMITIVE_HIT = 2;

// Why the template arguments of RayQuery<RayFlags, RayQueryFlags> do not compile in HLSL, or nullptr when they do:
// undefined bits (RQ-3), SKIP_CLOSEST_HIT_SHADER (RQ-4), FORCE_OMM_2_STATE without ALLOW_OPACITY_MICROMAPS (RQ-33).
// The mutual exclusions of RQ-5 are checked at TraceRayInline, on the OR'd flags.
constexpr const char* rayQueryTemplateError(uint32_t rayFlags, uint32_t rayQueryFlags) {
    if (rayFlags & RAY_FLAG_SKIP_CLOSEST_HIT_SHADER) return "RQ-4: RAY_FLAG_SKIP_CLOSEST_HIT_SHADER is not allowed in a RayQuery";
    if (rayFlags & ~(kDefinedRayFlags | RAY_FLAG_FORCE_OMM_2_STATE)) return "RQ-3: the ray flags set undefined bits";
    if (rayQueryFlags & ~kDefinedRayQueryFlags) return "RQ-6: the RAYQUERY_FLAGs set undefined bits";
    if ((rayFlags & RAY_FLAG_FORCE_OMM_2_STATE) && !(rayQueryFlags & RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS))
        return "RQ-33: RAY_FLAG_FORCE_OMM_2_STATE needs RAYQUERY_FLAG_ALLOW_OPACITY_MICROMAPS";
    return nullptr;
}

namespace detail {
struct RayQueryState;  // ray_query.cpp
}
class RayQueryObject;

// A TraceRayInline handed to the wave as a wave call (emulator/wave_call.h: traceRayInlineCall), so that the queries
// of a wave's lanes trace together: their rays' candidates are gathered in Embree packets. Each lane's TraceRayInline
// is the one RayQueryObject::TraceRayInline makes (its checks, diagnostics, counts, events and candidates); what
// stops the lane's launch in it is kept in `failure`, for the lane to rethrow when the call returns.
struct RayQueryTraceCall {
    RayQueryObject* query = nullptr;
    GpuVirtualAddress accelerationStructure = 0;
    uint32_t rayFlags = 0;
    uint32_t instanceInclusionMask = 0xFF;
    RayDesc ray;
    std::exception_ptr failure;
};

namespace detail {
void runTraceRayInlineCalls(std::span<void* const> lanes);
inline constexpr WaveFunction kTraceRayInlineCalls{runTraceRayInlineCalls, kMaxWaveWidth};
}

// The wave call of `state` (ShaderContext::callInWave, ShaderWave::CallInWave): the calls of a wave's lanes run
// together, whatever their queries and acceleration structures. Inline, so that the call is written where it goes
// (one returned from another file came back through memory and was copied across its narrow stores).
inline WaveCall traceRayInlineCall(RayQueryTraceCall& state) {
    return WaveCall{&detail::kTraceRayInlineCalls, {}, &state};
}

// The object behind RayQuery<...>: a handle. Copies refer to the same state machine (RQ-7), as an HLSL assignment
// or a by-reference parameter does. Lives no longer than the shader invocation that made it.
class RayQueryObject {
public:
    RayQueryObject(ShaderContext& ctx, uint32_t templateRayFlags, uint32_t rayQueryFlags);
    RayQueryObject(const RayQueryObject& other);
    RayQueryObject& operator=(const RayQueryObject& other);
    ~RayQueryObject();

    // --- State machine (RQ-9 .. RQ-16).
    // Initialises the query (RQ-9): effective flags = template | RayFlags (RQ-3..RQ-5); a null AS forces a miss,
    // only the low 8 mask bits count (RQ-10); the ray must be valid (RQ-11).
    void TraceRayInline(GpuVirtualAddress accelerationStructure, uint32_t RayFlags, uint32_t InstanceInclusionMask,
                        const RayDesc& Ray);
    // TRUE: a candidate needs the shader's decision; FALSE: the search is over, and stays over (RQ-12).
    bool Proceed();
    void Abort();  // RQ-15

    // --- The candidate (valid after Proceed returned TRUE; RQ-17, RQ-28).
    uint32_t CandidateType() const;
    bool CandidateProceduralPrimitiveNonOpaque() const;  // RQ-24
    uint32_t CandidateInstanceIndex() const;
    uint32_t CandidateInstanceID() const;
    uint32_t CandidateInstanceContributionToHitGroupIndex() const;
    uint32_t CandidateGeometryIndex() const;
    uint32_t CandidatePrimitiveIndex() const;
    vec3 CandidateObjectRayOrigin() const;
    vec3 CandidateObjectRayDirection() const;
    Matrix3x4 CandidateObjectToWorld3x4() const;
    std::array<std::array<float, 3>, 4> CandidateObjectToWorld4x3() const;
    Matrix3x4 CandidateWorldToObject3x4() const;
    std::array<std::array<float, 3>, 4> CandidateWorldToObject4x3() const;
    float CandidateTriangleRayT() const;              // triangle candidates only
    vec2 CandidateTriangleBarycentrics() const;       // RQ-30
    bool CandidateTriangleFrontFace() const;

    // --- Commits (RQ-20 .. RQ-23).
    void CommitNonOpaqueTriangleHit();
    // The shader must have checked RayTMin() <= tHit <= CommittedRayT() (RQ-22); refray checks it and reports
    // RQ-22 when it does not hold (the commit is then dropped).
    void CommitProceduralPrimitiveHit(float tHit);

    // --- The query and its committed hit (RQ-18, RQ-25 .. RQ-31).
    uint32_t CommittedStatus() const;
    uint32_t RayFlags() const;  // template | dynamic (RQ-26)
    vec3 WorldRayOrigin() const;
    vec3 WorldRayDirection() const;
    float RayTMin() const;
    float CommittedRayT() const;  // TMax while nothing is committed (RQ-27)
    uint32_t CommittedInstanceIndex() const;
    uint32_t CommittedInstanceID() const;
    uint32_t CommittedInstanceContributionToHitGroupIndex() const;
    uint32_t CommittedGeometryIndex() const;
    uint32_t CommittedPrimitiveIndex() const;
    vec3 CommittedObjectRayOrigin() const;
    vec3 CommittedObjectRayDirection() const;
    Matrix3x4 CommittedObjectToWorld3x4() const;
    std::array<std::array<float, 3>, 4> CommittedObjectToWorld4x3() const;
    Matrix3x4 CommittedWorldToObject3x4() const;
    std::array<std::array<float, 3>, 4> CommittedWorldToObject4x3() const;
    vec2 CommittedTriangleBarycentrics() const;  // COMMITTED_TRIANGLE_HIT only
    bool CommittedTriangleFrontFace() const;

    // RQ-32: Candidate/CommittedTriangleObjectPositions are planned for SM 6.10 and out of scope; calling them
    // stops the dispatch with RQ-32.
    std::array<vec3, 3> CandidateTriangleObjectPositions() const;
    std::array<vec3, 3> CommittedTriangleObjectPositions() const;

    // The same state machine (RQ-7).
    bool sameQueryAs(const RayQueryObject& other) const { return state_ == other.state_; }

private:
    friend void detail::runTraceRayInlineCalls(std::span<void* const> lanes);
    // TraceRayInline up to its candidates: true when the query's ray goes on to gather them (a valid ray in a TLAS).
    bool initialise(GpuVirtualAddress accelerationStructure, uint32_t rayFlags, uint32_t mask, const RayDesc& ray);

    // Counted by the handles that share it (RQ-7); a state none holds goes back to its worker thread's spares, to be
    // the next query's (each query allocated its state and its candidate list before: malloc and free were 2 % of
    // the ambient-occlusion scene's samples).
    detail::RayQueryState* state_;
};

// HLSL RayQuery<RAY_FLAGS[, RAYQUERY_FLAGS]> (RQ-2): both arguments are compile-time constants, checked as the
// HLSL compiler checks them.
template <uint32_t RayFlagsT, uint32_t RayQueryFlagsT = RAYQUERY_FLAG_NONE>
class RayQuery : public RayQueryObject {
    static_assert(rayQueryTemplateError(RayFlagsT, RayQueryFlagsT) == nullptr,
                  "invalid RayQuery template flags: see rayQueryTemplateError");

public:
    explicit RayQuery(ShaderContext& ctx) : RayQueryObject(ctx, RayFlagsT, RayQueryFlagsT) {}
};

}  // namespace refray::dxr
