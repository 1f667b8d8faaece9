// Stage: contact detection (cl_kernels/contact_detection.cl).
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "engine/device/checkpoint.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"

namespace fdem {

class ContactDetection {
 public:
  // skin: margin [m] added around every triangle's bounding box (0 = touching boxes only).
  // initial_capacity: couples the output can hold before growing (0 = 7 per triangle).
  // bonds: pairs of triangles (each joined by a CE4) that are candidates whatever the
  // active mask says (activation "fractured"; see find_couples in the kernel file). A
  // triangle has at most three (one per edge).
  // owned_first (a split run, one per triangle; empty: every triangle): only couples whose
  // lower triangle i has owned_first[i] != 0 are listed, so each couple of the whole
  // model is listed by exactly one rank (ARCHITECTURE.md, "Scale-out").
  // list_inactive (activation "fractured" with a skin): run() lists the couples of every
  // triangle, whatever the active mask says (see LIST_INACTIVE in the kernel file).
  ContactDetection(ClContext& cl, DeviceArrays& arrays, double skin, size_t initial_capacity = 0,
                   const std::vector<std::array<int, 2>>& bonds = {}, const std::vector<char>& owned_first = {},
                   bool list_inactive = false);
  static constexpr cl_uint kNoPartner = 0xffffffffu;  // an empty bond_partners entry
  // The couples the output holds at first (initial_capacity 0: 7 per triangle: a mesh's
  // neighbours across its CE4s and fans are about 6 couples per triangle, the couples a
  // detection lists in an intact mesh since it drops those further apart than the skin), and the
  // capacity it grows to when a scan finds `needed` couples (×1.5).
  static size_t first_capacity(size_t triangles, size_t initial_capacity = 0) {
    return initial_capacity ? initial_capacity : std::max<size_t>(7 * triangles, 1);
  }
  static size_t grown(size_t needed) { return needed + (needed + 1) / 2; }
  // The arrays the constructor allocates (`group_size`: ClContext::group_size(); `bonds`:
  // some are given). A detection allocates nothing more (unless the list grows).
  static MemoryPlan plan(size_t triangles, size_t group_size, size_t initial_capacity = 0, bool bonds = false,
                         bool owned_first = false);
  // The couple list of `capacity` couples (the constructor's and grow()'s).
  static MemoryPlan couple_list(size_t capacity);
  // The cells' entries: one per small triangle, one per covered cell of a large one; at
  // first room for two per triangle, grown (×1.5) to what a detection finds.
  static size_t first_entries(size_t triangles) { return 2 * std::max<size_t>(triangles, 1); }
  static MemoryPlan cell_entries(size_t capacity);
  // Finds every couple of triangles (i < j) whose bounding boxes, each grown by skin/2 on
  // every side, overlap, that share no node, and that no edge line of either sets apart
  // by more than the skin (the kernel's apart_beyond: such a couple cannot touch before
  // some node has moved half the skin). Writes them to couple_keys() as
  // cl_ulong keys (ulong(i) << 32 | j), sorted ascending, unique; returns their count.
  // Waits once, for the count (the list grows to it before the keys are written: never
  // drops a couple); the writing of the keys is enqueued after that read.
  size_t run();
  // The margin the next run() grows the boxes by (an adaptive skin, ContactSkin::choose).
  void set_skin(double skin);
  compute::buffer& couple_keys();        // cl_ulong × capacity(); the first `count` are valid

  // Extends the list of `listed` couples (run()'s, and earlier extensions) by the couples
  // of the triangles that joined the candidates since (activation "fractured": mask value
  // above covered_stamp()), found with the last run's boxes and grid, so without a new
  // detection: the couples that run() would have listed then had those triangles been
  // candidates (with a skin, every couple that can touch before the next detection is
  // due). Appended after the others, each joining triangle's couples sorted; no couple
  // twice. Returns the new count, or 0 when there is nothing to extend from (no run yet,
  // a split run, or `limit` couples would be exceeded: then run() instead). Waits once (the count).
  // positions_at_run: the node positions of the last run() (ContactSkin::position_at_build),
  // on which the couples' gaps are measured as the run measured them.
  size_t extend_joined(size_t listed, size_t limit, cl_uint covered_to, const compute::buffer& positions_at_run);
  // Join stamps up to this are in the list (run() at step s covers join_stamp(s); an
  // extension covers what it is given).
  cl_uint covered_stamp() const { return covered_; }
  void set_covered_stamp(cl_uint stamp) { covered_ = stamp; }
  // After a checkpoint is loaded: the last run's boxes and grid again, from the positions
  // it ran on (the skin's copy), for extend_joined. The couple list is left alone.
  void rebuild_grid(const compute::buffer& positions_at_run);
  // After a checkpoint is loaded: the contact stage's list (its keys, "contact_keys") into
  // this stage's buffer, which the contact stage then reads (shared keys). False for a split run.
  bool restore_list(StateReader& in);
  size_t capacity() const;
  size_t last_count() const;
  // Work-items per triangle in the couple search (GPU 9, CPU 1; the list does not depend
  // on it). For tests of the GPU's way on a CPU.
  void set_parts(size_t parts);
  size_t parts() const { return parts_; }
  struct Grid { double cell_size, x0, y0; unsigned nx, ny; double small_side; };  // small_side: the largest box side entered in one cell
  Grid grid();                           // the grid of the last run (host read; for `fdem check` and tests)
  // Optional candidate mask for later (fracture activation): one cl_uint per triangle, nonzero =
  // takes part. Default: every triangle takes part.
  void set_active(const std::vector<uint32_t>& active);
  compute::buffer& active_mask() { return active_; }  // cl_uint per triangle, on the device

  // Most grid cells a run may use (nx·ny ≤ this): 4 per triangle + 1024.
  size_t max_cells() const { return max_cells_; }
  // The candidate mask (activation changes it as CE4s break), for checkpoints.
  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  static constexpr cl_uint kDetection = 0xffffffffu;  // the couple kernels' `covered` for a detection
  void grow(size_t needed);
  // Exclusive prefix sum of the first `entries` uints of `data`, in place (three launches).
  void exclusive_scan(const compute::buffer& data, size_t entries);
  // (boxes: and the grid around them, first) the counting sort of the triangles into cells.
  void bin_triangles(bool boxes);
  void count_couples(cl_uint covered);     // per triangle, then their prefix sum
  std::array<size_t, 2> read_totals();     // cell entries, couples (waits)
  // bin_triangles and count_couples, again with more room when the entries overflowed;
  // returns the couples' total.
  size_t bin_and_count(bool boxes, cl_uint covered);
  void write_couples(cl_uint covered, size_t listed);
  // The positions the boxes and the couples' gaps are taken from (positions_ but while a
  // grid is rebuilt or a list extended).
  void bind_positions(const compute::buffer& positions);

  ClContext& cl_;
  size_t count_;        // triangles
  size_t groups_;       // work-groups of the box kernel
  size_t max_cells_;
  size_t capacity_ = 0;
  size_t entries_capacity_ = 0;
  size_t last_count_ = 0;
  size_t parts_ = 1;    // work-items per triangle in couple_count and couple_write
  bool split_ = false;
  bool can_extend_ = false;    // a run's grid is in place (and not a split run)
  bool stamp_loaded_ = true;   // false after loading a checkpoint without covered_
  cl_uint covered_ = 0;

  compute::buffer boxes_, partial_bounds_, partial_side_, grid_, dims_;
  compute::buffer cell_start_;   // max_cells + 1: the cells' counts (at c + 1), then their starts and ends
  compute::buffer sorted_tri_;   // the cells' entries (triangles), cell after cell
  compute::buffer offsets_;      // triangles + 1: each one's couple count, then its segment's start (after couple_write its end)
  compute::buffer scan_blocks_;  // the prefix sums' block totals
  compute::buffer active_, keys_, owned_first_;
  compute::buffer bond_partners_;  // 3 cl_uint per triangle (only when bonds are given)
  compute::buffer positions_;      // the node positions the boxes are taken from (rebuild_grid binds others for a while)
  compute::kernel boxes_kernel_, grid_kernel_, cell_count_kernel_, cell_scatter_kernel_;
  compute::kernel scan_blocks_kernel_, scan_sums_kernel_, scan_add_kernel_;
  compute::kernel couple_count_kernel_, couple_write_kernel_, sort_kernel_;
  KernelArg<cl_uint> sort_listed_;
  KernelArg<compute::buffer> sort_keys_;
  KernelArg<compute::buffer> box_positions_, scatter_entries_;
  KernelArg<real> half_skin_;
  KernelArg<cl_uint> scatter_capacity_;
  struct Couples {
    KernelArg<cl_uint> parts, covered, listed, n_entries;
    KernelArg<compute::buffer> entries, keys, position;
    KernelArg<real> reach;
  } count_args_, write_args_;
};

}  // namespace fdem
