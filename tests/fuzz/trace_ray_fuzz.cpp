// libFuzzer: TraceRay's inputs (origin, direction, TMin, TMax, flags, mask, R, M, miss index) from the ray
// generation shader of a small scene: a non-opaque triangle (any-hit shader) and a procedural box, each instance
// with its own records. Every rule the input breaks must end in a diagnostic (refray::dxr::DxrError in
// OnError::Stop, a logged one in Continue); a crash, a sanitizer report or a hang is a finding.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "core/error.h"
#include "tests/emulator/harness.h"

namespace {

using namespace refray::dxr;
using refray::test::Harness;
using refray::test::Probe;
using refray::Matrix3x4;
using refray::uvec3;
using refray::vec3;

struct Input {
    float origin[3];
    float tMin;
    float direction[3];
    float tMax;
    uint32_t flags, mask, rayContribution, multiplier, missIndex;
    uint8_t options;  // bit 0: OnError::Continue, bit 1: adversarial order, bit 2: a second, nested TraceRay
};

struct Fixture {
    Harness h;
    Input input{};
    StateObjectPtr so;
    GpuVirtualAddressRangeAndStride miss, hitGroups;

    Fixture() {
        h.addProbeShaders();
        h.library->addRayGeneration("RG_Fuzz", [this](ShaderContext& ctx) {
            const RayDesc ray{vec3(input.origin[0], input.origin[1], input.origin[2]), input.tMin,
                              vec3(input.direction[0], input.direction[1], input.direction[2]), input.tMax};
            Probe p;
            ctx.TraceRay(h.scene, input.flags, input.mask, input.rayContribution, input.multiplier, input.missIndex, ray, p);
            if (input.options & 4)
                ctx.TraceRay(h.scene, input.flags, input.mask, input.multiplier, input.rayContribution, input.missIndex, ray, p);
        });
        const GpuVirtualAddress triangle =
            h.blas({h.triangles({{-1, -1, 0}, {0, 1, 0}, {1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {0, 1, 2}}, GEOMETRY_FLAG_NONE)});
        const GpuVirtualAddress box = h.blas({h.aabbs({refray::test::unitBox()})});
        h.tlas({Harness::instance(triangle, 0), Harness::instance(box, 2, Matrix3x4::translation({3, 0, 1}), 0x0F)});
        so = h.pipeline();
        miss = h.table(so, {"Miss_Probe", ""});
        hitGroups = h.table(so, {"HG_TriAH", "HG_Tri", "HG_Box", ""});
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static Fixture* fixture = new Fixture();  // built once; never freed (libFuzzer exits without teardown)
    if (size < sizeof(Input)) return 0;
    std::memcpy(&fixture->input, data, sizeof(Input));
    DispatchOptions options;
    options.threads = 1;
    options.onError = (fixture->input.options & 1) ? OnError::Continue : OnError::Stop;
    options.order = (fixture->input.options & 2) ? TraversalOrder::Adversarial : TraversalOrder::Ordered;
    options.adversarialSeed = fixture->input.flags ^ fixture->input.mask;
    try {
        fixture->h.dispatch(fixture->so, fixture->miss, fixture->hitGroups, uvec3(1u), options, nullptr, {}, "RG_Fuzz");
    } catch (const refray::Error&) {
        // A diagnostic: what bad input must produce.
    }
    return 0;
}
