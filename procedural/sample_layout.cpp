#include "procedural/sample_layout.h"

namespace refray::procedural {

using namespace refray::dxr;

RootSignatureDesc sampleGlobalRootSignatureDesc(std::string name) {
    RootSignatureDesc desc;
    desc.name = std::move(name);
    desc.parameters = {
        RootParameter::table({DescriptorRange{DescriptorRangeType::UAV, 1, 0, 0, 0}}),  // u0
        RootParameter::srv(0),                                                           // t0
        RootParameter::cbv(0),                                                           // b0
        RootParameter::srv(3),                                                           // t3
        RootParameter::table({DescriptorRange{DescriptorRangeType::SRV, 2, 1, 0, 0}}),  // t1, t2
    };
    return desc;
}

RootSignatureDesc sampleTriangleLocalRootSignatureDesc(std::string name, uint32_t materialBytes) {
    RootSignatureDesc desc;
    desc.name = std::move(name);
    desc.flags = ROOT_SIGNATURE_FLAG_LOCAL_ROOT_SIGNATURE;
    desc.parameters = {RootParameter::constants(materialBytes / 4, 1)};
    return desc;
}

RootSignatureDesc sampleProceduralLocalRootSignatureDesc(std::string name, uint32_t materialBytes,
                                                         uint32_t instanceBytes) {
    RootSignatureDesc desc = sampleTriangleLocalRootSignatureDesc(std::move(name), materialBytes);
    desc.parameters.push_back(RootParameter::constants(instanceBytes / 4, 2));
    return desc;
}

}  // namespace refray::procedural
