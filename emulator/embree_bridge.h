// The only place that sees Embree (style rule 2). BLAS = an Embree scene of user
// geometries (one per DXR geometry, geometry id = GeometryIndex); TLAS = an Embree
// scene of instances (instance id = InstanceIndex, geometry mask = InstanceMask).
//
// Embree is the broad phase: it walks its BVH and calls back for every primitive whose
// (slightly enlarged) bounds the ray touches. The callbacks run refray's own exact tests
// (intersection.h) and record candidates; the dispatcher then applies every DXR rule to
// them in a documented order. Nothing thrown ever crosses Embree (style rule 9).
#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "emulator/acceleration_structure.h"

namespace refray::dxr::detail {

struct EmbreeDeviceImpl;

class EmbreeDevice {
public:
    EmbreeDevice();
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;
    EmbreeDeviceImpl& impl() { return *impl_; }

private:
    std::unique_ptr<EmbreeDeviceImpl> impl_;
};

struct EmbreeScene {
    void* scene = nullptr;  // RTCScene
    std::vector<std::unique_ptr<struct UserGeometry>> userGeometries;
    ~EmbreeScene();
};

std::unique_ptr<EmbreeScene> buildBottomLevelScene(EmbreeDevice& device, const BottomLevelAS& blas);
std::unique_ptr<EmbreeScene> buildTopLevelScene(EmbreeDevice& device, const TopLevelAS& tlas);

// A potential hit found by the broad phase and confirmed by the exact test.
struct Candidate {
    float key = 0.0f;  // ordering key: the triangle t, or the AABB entry t
    uint32_t instanceIndex = 0;
    uint32_t geometryIndex = 0;
    uint32_t primitiveIndex = 0;
    bool procedural = false;
    float t = 0.0f;           // triangles
    vec2 barycentrics{0.0f};  // triangles
    vec3 objectRayOrigin{0.0f};
    vec3 objectRayDirection{0.0f};
};

// How the broad phase hands candidates over (DispatchOptions::specialise; docs/emulator.md, "Traversal
// shortcuts").
enum class GatherMode : uint8_t {
    // Every candidate in [tMin, tMax], for the dispatcher to order and process: observed rays, adversarial
    // order, or shortcuts switched off.
    All,
    // As All, but a triangle that is sure to commit when the ordered loop reaches it (`commitsSurely`)
    // shrinks Embree's interval to its t, and candidates starting beyond the nearest such t are dropped: the
    // ordered loop would skip them (TRV-2), so no result, invocation or diagnostic changes.
    Closest,
    // rtcOccluded1: each candidate goes to `onCandidate` as Embree meets it, and traversal stops once that
    // returns true. For rays whose outcome cannot depend on the order (ACCEPT_FIRST_HIT_AND_END_SEARCH with
    // SKIP_CLOSEST_HIT_SHADER, and no any-hit shader in the pipeline).
    FirstHit,
};

struct GatherRequest {
    const TopLevelAS* tlas = nullptr;
    vec3 origin{0.0f};
    vec3 direction{0.0f};
    float tMin = 0.0f;
    float tMax = 0.0f;
    uint32_t instanceInclusionMask = 0xFF;
    bool skipTriangles = false;
    bool skipProcedural = false;
    bool alternateEdgeRule = false;
    GatherMode mode = GatherMode::All;
    // Closest: true if the ordered loop would commit this in-range triangle candidate whenever it reaches it.
    bool (*commitsSurely)(const void* user, const Candidate& c) = nullptr;
    // FirstHit: processes one candidate; returns true when the search has ended.
    bool (*onCandidate)(void* user, const Candidate& c) = nullptr;
    void* user = nullptr;
    std::vector<Candidate>* out = nullptr;  // All, Closest
};

// Hands every primitive of an active, unmasked instance that truly overlaps [tMin, tMax] (triangles: the
// exact hit at tMin <= t <= tMax; AABBs: the box touches the interval, inclusive) to the request, as its
// mode says. Throws refray::Error if Embree reported an error, and rethrows what a callback threw.
void gatherCandidates(const GatherRequest& request);

// The most rays one gather packet takes (Embree's widest packet).
inline constexpr int kMaxGatherPacket = 16;

// gatherCandidates for up to kMaxGatherPacket requests of one TLAS, in mode All or Closest, traced as one Embree
// packet (the narrowest of rtcIntersect1, 4, 8 and 16 that holds them). Each request gets the candidates it gets
// alone (in the order Embree meets them, which the caller orders, GEN-3). What failed for request i goes to
// errors[i]; the others are unaffected.
void gatherCandidatesPacket(std::span<const GatherRequest* const> requests, std::span<std::exception_ptr> errors);

}  // namespace refray::dxr::detail
