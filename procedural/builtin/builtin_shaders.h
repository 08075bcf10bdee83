// Shaders of refray's small built-in scene: a triangle plane and an analytic sphere,
// radiance and shadow ray types, 2 hit groups x 2 ray types. Written against the
// shader API the way HLSL is written against DXR.
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include "core/math.h"
#include "emulator/state_object.h"
#include "procedural/math/hlsl.h"

namespace refray::procedural::builtin {

// Global root signature parameters.
enum GlobalRootParameter : uint32_t {
    kOutputTable = 0,    // descriptor table {UAV u0}: RWTexture2D<float4> g_output
    kAccelerationStructure = 1,  // root SRV t0: the TLAS
    kSceneConstants = 2,  // root CBV b0: SceneConstants
};
// Local root signature "Material": 4 root constants at b1 (MaterialConstants).
inline constexpr uint32_t kMaterialParameter = 0;

struct SceneConstants {
    vec4 cameraPosition;
    vec4 cameraRight;    // scaled by tan(fovY/2) * aspect
    vec4 cameraUp;       // scaled by tan(fovY/2)
    vec4 cameraForward;  // unit
    vec4 lightPosition;
    vec4 sphere;  // object-space centre (xyz) and radius (w)
};

struct MaterialConstants {
    vec4 albedo;  // .w = reflectance
};

struct RadiancePayload {
    vec4 color;
    uint32_t recursionDepth;
};

struct ShadowPayload {
    uint32_t hit;
};

struct SphereAttributes {
    vec3 normal;  // object space
};

inline constexpr uint32_t kRayTypeCount = 2;  // radiance = 0, shadow = 1
inline constexpr uint32_t kMaxRecursionDepth = 3;

// Where the shaders start shadow and reflection rays (issue 6; docs/numerical-stability.md, "Self-intersection").
enum class SecondaryRayOrigin {
    WaechterBinder,  // the hit point moved off the surface by offsetRayOrigin (core/ray_offset.h), TMin 0: the default
    FixedTMin,       // the hit point, TMin 0.001: a fixed epsilon (acne far from the origin)
    HitPoint,        // the hit point, TMin 0: no protection (acne everywhere)
};
std::string_view toString(SecondaryRayOrigin origin);

std::shared_ptr<dxr::ShaderLibrary> makeShaderLibrary(SecondaryRayOrigin origin = SecondaryRayOrigin::WaechterBinder);

// The shading math, shared by the shaders and by the raw-Embree baseline of the
// emulation-overhead benchmark (so both do exactly the same work per ray).
vec4 skyColor(vec3 direction);
vec3 checkerAlbedo(vec3 position, vec3 albedo);
// Lambert with a fixed ambient term; `shadowed` is the shadow ray's answer.
vec3 lambert(vec3 albedo, vec3 normal, vec3 toLightUnit, bool shadowed);
// Nearest root of |o + t d - centre| = radius within [tMin, tMax], if any. Written once for a float and for a
// wave's float lanes (procedural/math/lanes.h): per lane, bit for bit the float result.
template <class T>
math::LaneMask<T> intersectSphere(glm::vec<3, T> o, glm::vec<3, T> d, T radius, T tMin, T tMax, T& tHit) {
    const T a = d.x * d.x + d.y * d.y + d.z * d.z;  // glm::dot's order
    const T b = o.x * d.x + o.y * d.y + o.z * d.z;
    const T c = (o.x * o.x + o.y * o.y + o.z * o.z) - radius * radius;
    const T disc = b * b - a * c;
    const math::LaneMask<T> real = !(disc < T(0.0f));
    const T root = hlsl::sqrt(disc);
    const T near = (-b - root) / a, far = (-b + root) / a;
    const math::LaneMask<T> nearIn = real && near >= tMin && near <= tMax;
    const math::LaneMask<T> farIn = real && !nearIn && far >= tMin && far <= tMax;
    if constexpr (math::kIsLanes<T>) {
        tHit = math::select(nearIn, near, math::select(farIn, far, tHit));
    } else if (nearIn || farIn) {
        tHit = nearIn ? near : far;  // tHit is written only for a hit
    }
    return nearIn || farIn;
}
// The primary ray direction of pixel `index` (pinhole, pixel centre).
vec3 primaryDirection(const SceneConstants& sc, uvec3 index, uvec3 dims);

}  // namespace refray::procedural::builtin
