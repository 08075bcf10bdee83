// The device: GPU memory, descriptor heaps, acceleration-structure builds and DispatchRays.
// The host side of DXR, the way ID3D12Device5 + ID3D12GraphicsCommandList4 expose it.
#pragma once

#include <map>
#include <memory>
#include <mutex>

#include "emulator/acceleration_structure.h"
#include "emulator/descriptor_heap.h"
#include "emulator/dispatcher.h"
#include "emulator/gpu_memory.h"
#include "emulator/shader_table.h"
#include "emulator/state_object.h"

namespace refray::dxr {

namespace detail {
class EmbreeDevice;
}

class Device {
public:
    Device();
    ~Device();
    Device(const Device&) = delete;
    Device& operator=(const Device&) = delete;

    GpuMemory& memory() { return memory_; }
    const GpuMemory& memory() const { return memory_; }

    DescriptorHeap& createDescriptorHeap(uint32_t numDescriptors, std::string name);
    // The heap holding `handle`, or nullptr.
    const DescriptorHeap* findDescriptorHeap(GpuDescriptorHandle handle) const;

    // BuildRaytracingAccelerationStructure for a BLAS. Returns its GPU address. With
    // BUILD_FLAG_PERFORM_UPDATE, `source` names the structure to update in place (UPD-1).
    // Throws DxrError for every [UB] input the rules list (BLAS-*, DEGEN-2, UPD-*).
    GpuVirtualAddress buildBottomLevelAS(const BottomLevelInputs& inputs, GpuVirtualAddress source = 0);
    // The same for a TLAS; instance descs are read from GPU memory (INST-*).
    GpuVirtualAddress buildTopLevelAS(const TopLevelInputs& inputs, GpuVirtualAddress source = 0);

    const BottomLevelAS* findBottomLevelAS(GpuVirtualAddress address) const;
    const TopLevelAS* findTopLevelAS(GpuVirtualAddress address) const;

    // Build-time warnings (GEN-4) collected since the device was made.
    DiagnosticLog buildDiagnostics() const { return buildLog_.snapshot(); }

    // DispatchRays (RGS-1): runs Width*Height*Depth ray-generation threads over oneTBB
    // tiles. `pipeline` is the bound state object (RGS-3), `globalArguments` what
    // SetComputeRootSignature/SetComputeRoot* bound (may be null if no shader needs them).
    // Throws DxrError on the first error (OnError::Stop) or on an invalid desc.
    DispatchResult dispatchRays(const DispatchRaysDesc& desc, const StateObjectPtr& pipeline,
                                const GlobalRootArguments* globalArguments, const DispatchOptions& options = {});

    // Dispatch of a compute shader (RQ-1: inline ray tracing from compute): ThreadGroupCount* groups of the export's
    // numthreads, each thread one invocation of stage Compute with the global root arguments. TraceRay and
    // CallShader are not available there (RAY-2, CALL-2); RayQuery is. Throws DxrError for an unknown export or a
    // group count past 65535, and on the first error (OnError::Stop).
    DispatchResult dispatch(const DispatchDesc& desc, const StateObjectPtr& pipeline,
                            const GlobalRootArguments* globalArguments, const DispatchOptions& options = {});

    // Increments whenever any BLAS is built or updated (INST-8 staleness checks).
    uint64_t accelerationStructureEpoch() const { return epoch_.load(); }

private:
    GpuMemory memory_;
    std::unique_ptr<detail::EmbreeDevice> embree_;
    std::vector<std::unique_ptr<DescriptorHeap>> heaps_;
    std::map<GpuVirtualAddress, std::unique_ptr<BottomLevelAS>> bottomLevel_;
    std::map<GpuVirtualAddress, std::unique_ptr<TopLevelAS>> topLevel_;
    BuildLog buildLog_;
    std::atomic<uint64_t> epoch_{0};
};

}  // namespace refray::dxr
