// The monitor ring: per-step words that kernels write on the device and the host reads
// late, so that the step loop never waits for the device. Slot slot_of(step) holds
// RING_WORDS uints (engine/model/layouts.hpp): the contact skin test's largest move and speed
// (written by the integration, Integrate with a ContactSkin) and the join flag (written
// by ContactActivation). ContactSkin reads it, kBatch slots at a time, and decides when
// detection runs again. One object, built before the stages that write it.
#pragma once
#include <vector>

#include "engine/device/device_arrays.hpp"
#include "engine/model/layouts.hpp"

namespace fdem {

class MonitorRing {
 public:
  static constexpr unsigned kSlots = 8, kBatch = 4;

  static MemoryPlan plan() { return MemoryPlan().add("monitor ring", layout::RING_WORDS * kSlots * sizeof(cl_uint)); }
  explicit MonitorRing(ClContext& cl) {
    buffer_ = plan().allocate(cl, "monitor ring");
    upload(cl, buffer_, std::vector<cl_uint>(layout::RING_WORDS * kSlots, 0));
  }
  compute::buffer& buffer() { return buffer_; }
  static unsigned slot_of(long step) { return static_cast<unsigned>(step % kSlots); }

 private:
  compute::buffer buffer_;
};

}  // namespace fdem
