// Stage: skin rebuild test for contact detection (cl_kernels/contact_skin.cl).
#pragma once
#include <array>
#include <vector>

#include "engine/device_arrays.hpp"

namespace fdem {

// Decides when contact detection must run again with a skin: a couple can only appear
// once some node has moved more than half the skin since the last detection. The test
// runs on the device every step and is read back SKIN_SLOTS − 1 steps late (the host
// never waits for the device in the step loop); the nodes can move a little in those
// steps, so the test asks for a margin of 2 × (slots) × (largest speed seen) × Δt on
// top (2: room for the speed to double in that time). When that margin would exceed a
// quarter of the skin (very fast nodes or a thin skin), the step waits for the test of
// its own step instead, which is exact.
class ContactSkin {
 public:
  static constexpr unsigned kSlots = 4;

  ContactSkin(ClContext& cl, DeviceArrays& arrays, double skin, double dt);
  // Remembers the current positions as those of the last detection. Never waits.
  void mark();
  // Enqueues this step's test (positions now against those at mark()) and says whether
  // detection must run now. Waits only for a test enqueued kSlots − 1 steps ago, or for
  // its own in the exact mode described above.
  bool rebuild_due(long step);
  // The device ring that the activation stage flags in (word 2 of a slot).
  compute::buffer& monitor() { return monitor_; }
  static unsigned slot_of(long step) { return static_cast<unsigned>(step % kSlots); }
  long synchronous_checks() const { return synchronous_; }

 private:
  bool decide(unsigned slot, bool exact);

  ClContext& cl_;
  DeviceArrays& arrays_;
  double half_skin_, dt_;
  compute::kernel kernel_;
  compute::buffer at_build_, monitor_;
  std::vector<cl_uint> host_;                  // kSlots × 4 words, filled by async reads
  std::array<compute::event, kSlots> reads_;
  std::array<long, kSlots> generation_of_{};   // mark() count when the slot was measured
  std::array<bool, kSlots> pending_{};
  long generation_ = 0;
  double largest_speed_ = 0;                   // from the latest test read [m/s]
  long synchronous_ = 0;
};

}  // namespace fdem
