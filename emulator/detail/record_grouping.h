// Record grouping (docs/emulator.md, "Waves"): the lanes of a packet that wait for an intersection shader, grouped
// by the shader and the hit-group record that runs it, as a GPU gathers the threads that call the same shader with
// the same record before running it once over them. Groups keep the order of their first lanes. The lanes whose
// closest-hit shader is written for waves are grouped by the shader alone (record 0: each lane keeps its own).
#pragma once

#include <array>
#include <cstdint>

#include "emulator/lane_mask.h"
#include "emulator/types.h"

namespace refray::dxr {
struct ShaderExport;
}

namespace refray::dxr::detail {

class RecordGroups {
public:
    struct Group {
        const ShaderExport* shader = nullptr;
        GpuVirtualAddress record = 0;
        LaneMask lanes;
    };

    void clear() { count_ = 0; }
    // Lane `lane` waits for `shader` with the record at `record`.
    void add(int lane, const ShaderExport* shader, GpuVirtualAddress record) {
        for (size_t g = 0; g < count_; ++g)
            if (groups_[g].shader == shader && groups_[g].record == record) {
                groups_[g].lanes.set(lane);
                return;
            }
        groups_[count_++] = Group{shader, record, LaneMask::only(lane)};
    }
    const Group* begin() const { return groups_.data(); }
    const Group* end() const { return groups_.data() + count_; }

private:
    std::array<Group, kMaxWaveWidth> groups_{};  // at most one group per lane
    size_t count_ = 0;
};

}  // namespace refray::dxr::detail
