// Stage: contact activation "fractured" (cl_kernels/contact_activation.cl).
#pragma once
#include <array>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/stages/monitor_ring.hpp"

namespace fdem {

class ContactActivation {
 public:
  // `status`: the CE4 stage's (broken, mode) per CE4; `active`: the detection's
  // candidate mask (one uint per triangle); `ring`: where a join is flagged (word
  // RING_JOINED) for the host to read later (ContactSkin).
  // `owned` (a split run, one per CE4; empty: all): only these flag a join (the owner's
  // candidate mask is right for both triangles of its CE4s; a rank's mask of a triangle
  // it holds only for a CE4's sake may lag, and must not flag a join one rank never sees).
  // `ce4_triangles`: the `ce4` CE4s' triangle pairs, uint2 each (FragmentLabels's copy,
  // FragmentLabels::ce4_triangles(): one array for both stages).
  ContactActivation(ClContext& cl, size_t ce4, const compute::buffer& ce4_triangles, compute::buffer& status,
                    compute::buffer& active, MonitorRing& ring, const std::vector<char>& owned = {});
  // The arrays the constructor allocates for `ce4` CE4s (with `owned`, the owned flags).
  static MemoryPlan plan(size_t ce4, bool owned = false);
  // Marks the triangles of broken CE4s as candidates (mask value join_stamp(step)) and
  // flags a join in the ring's slot of `step`. Never waits.
  void enqueue(long step);
  // The mask value of a triangle that joins in step `step` (1 means "from the start").
  static cl_uint join_stamp(long step) { return static_cast<cl_uint>(step + 2); }

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel kernel_;
  KernelArg<cl_uint> slot_, stamp_;
  compute::buffer triangles_, owned_;
};

}  // namespace fdem
