// What the two reference scenes share: Proceduray's engine inherited the D3D12 procedural
// sample's HLSL matrix type and root-signature layout.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "emulator/root_signature.h"

namespace refray::procedural {

// An HLSL float4x4 compiled with /Zpr: row-major, used with row vectors (mul(v, M) = v·M,
// translation in row 3). Same memory layout as a DirectXMath XMMATRIX.
struct Float4x4 {
    std::array<std::array<float, 4>, 4> m{};
};
static_assert(sizeof(Float4x4) == 64);

// Global: [0] table {UAV u0} render target, [1] root SRV t0 TLAS, [2] root CBV b0 scene
// constants, [3] root SRV t3 instance buffer, [4] table {SRV t1, t2} indices and vertices.
dxr::RootSignatureDesc sampleGlobalRootSignatureDesc(std::string name);
// Local, triangles: the material as root constants at b1.
dxr::RootSignatureDesc sampleTriangleLocalRootSignatureDesc(std::string name, uint32_t materialBytes);
// Local, procedural: the material at b1, then the per-instance constants at b2.
dxr::RootSignatureDesc sampleProceduralLocalRootSignatureDesc(std::string name, uint32_t materialBytes,
                                                              uint32_t instanceBytes);

}  // namespace refray::procedural
