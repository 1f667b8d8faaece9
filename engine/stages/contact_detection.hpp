// Stage: contact detection (cl_kernels/contact_detection.cl).
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "engine/checkpoint.hpp"
#include "engine/device_arrays.hpp"
#include "engine/kernel_args.hpp"

namespace fdem {

class ContactDetection {
 public:
  // skin: margin [m] added around every triangle's bounding box (0 = touching boxes only).
  // initial_capacity: couples the output can hold before growing (0 = 8 per triangle).
  // bonds: pairs of triangles (each joined by a CE4) that are candidates whatever the
  // active mask says (activation "fractured"; see find_couples in the kernel file). A
  // triangle has at most three (one per edge).
  // owned_first (a split run, one per triangle; empty: every triangle): only couples whose
  // lower triangle i has owned_first[i] != 0 are listed, so each couple of the whole
  // model is listed by exactly one rank (ARCHITECTURE.md, "Scale-out").
  ContactDetection(ClContext& cl, DeviceArrays& arrays, double skin, size_t initial_capacity = 0,
                   const std::vector<std::array<int, 2>>& bonds = {}, const std::vector<char>& owned_first = {});
  static constexpr cl_uint kNoPartner = 0xffffffffu;  // an empty bond_partners entry
  // Sorts of at most this many entries run in one work-group's local memory (16 KiB of
  // ulongs), not through Boost.Compute (use_radix_sort(true) still forces the library's).
  static constexpr size_t kSmallSort = 2048;
  // The couples the output holds at first (initial_capacity 0: 8 per triangle), and the
  // capacity it grows to when a scan finds `needed` couples (×1.5).
  static size_t first_capacity(size_t triangles, size_t initial_capacity = 0) {
    return initial_capacity ? initial_capacity : std::max<size_t>(8 * triangles, 1);
  }
  static size_t grown(size_t needed) { return needed + (needed + 1) / 2; }
  // The arrays the constructor allocates (`group_size`: ClContext::group_size(); `bonds`:
  // some are given), and the scratch of the sorts of a run (Boost.Compute's own
  // allocations, outside ClContext, while a detection runs).
  static MemoryPlan plan(size_t triangles, size_t group_size, size_t initial_capacity = 0, bool bonds = false,
                         bool owned_first = false);
  // The couple list of `capacity` couples (the constructor's and grow()'s).
  static MemoryPlan couple_list(size_t capacity);
  // Finds every couple of triangles (i < j) whose bounding boxes, each grown by skin/2 on
  // every side, overlap, and that share no node. Writes them to couple_keys() as
  // cl_ulong keys (ulong(i) << 32 | j), sorted ascending, unique; returns their count.
  // Waits (it reads the count to grow the buffer on overflow and rerun: never drops a couple).
  // The final sort of the keys is enqueued on the (in-order) queue after that read.
  size_t run();
  compute::buffer& couple_keys();        // cl_ulong × capacity(); the first `count` are valid
  size_t capacity() const;
  size_t last_count() const;
  struct Grid { double cell_size, x0, y0; unsigned nx, ny; };
  Grid grid();                           // the grid of the last run (host read; for `fdem check` and tests)
  // Optional candidate mask for later (fracture activation): one cl_uint per triangle, nonzero =
  // takes part. Default: every triangle takes part.
  void set_active(const std::vector<uint32_t>& active);
  compute::buffer& active_mask() { return active_; }  // cl_uint per triangle, on the device

  // Forces Boost.Compute's radix sort for both sorts (the path it takes on GPUs) instead of
  // its device-dependent dispatch (merge sort on CPU devices). The couples do not depend on it.
  void use_radix_sort(bool on) { force_radix_ = on; }
  // Most grid cells a run may use (nx·ny ≤ this): 4 per triangle + 1024.
  size_t max_cells() const { return max_cells_; }
  // The candidate mask (activation changes it as CE4s break), for checkpoints.
  void save_state(StateWriter& out) const { out.buffer<cl_uint>("contact_active", active_, count_); }
  void load_state(StateReader& in) { in.buffer<cl_uint>("contact_active", active_, count_); }

 private:
  void grow(size_t needed);
  void find_couples();  // resets the counter and enqueues the scan
  // The arrays of one detection (MemoryPlan::Lifetime::Detection), bound by name in the
  // kernels that use them: allocated and bound (on), or released (off; the kernels then
  // hold the counter, and no kernel of the detection runs until the next run()).
  enum { kBoxes, kCellFirst, kCellLast, kHash, kTri, kDetectionArrays };
  void bind_later(KernelArgs& args, const char* name, int array);
  void hold_arrays(bool on);

  ClContext& cl_;
  size_t count_;        // triangles
  size_t groups_;       // work-groups of the box kernel
  size_t max_cells_;
  size_t capacity_ = 0;
  size_t last_count_ = 0;
  bool force_radix_ = false;

  compute::buffer boxes_, partial_bounds_, partial_side_, grid_, dims_;
  compute::buffer cell_first_, cell_last_, hash_, tri_, active_, counter_, keys_, owned_first_;
  compute::buffer bond_partners_;  // 3 cl_uint per triangle (only when bonds are given)
  MemoryPlan detection_arrays_;    // the plan, for the sizes of boxes_ ... tri_ (null between runs)
  std::vector<std::pair<int, KernelArg<compute::buffer>>> detection_args_;
  compute::kernel boxes_kernel_, grid_kernel_, clear_kernel_, hash_kernel_, range_kernel_, couples_kernel_;
  // Sorts of up to kSmallSort entries: one work-group in local memory (a small model's
  // detection would otherwise spend its time launching the library sort's passes).
  compute::kernel small_pairs_kernel_, small_keys_kernel_;
  KernelArg<cl_uint> small_keys_count_;
  KernelArg<compute::buffer> small_keys_keys_;
  KernelArg<cl_uint> couples_capacity_;
  KernelArg<compute::buffer> couples_keys_;
};

}  // namespace fdem
