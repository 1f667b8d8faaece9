// Stage: fragment labelling (cl_kernels/fragments.cl). Not part of the step: run on
// demand at output frames and history rows (engine/run/run.cpp, engine/outputs/history_table.cpp).
#pragma once
#include <array>
#include <vector>

#include "engine/device/cl_context.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/memory_plan.hpp"

namespace fdem {

class FragmentLabels {
 public:
  // The graph of `triangles` triangles whose corners `tri_nodes` (uint ×3 per triangle)
  // name `nodes` nodes, and of the CE4 pairs `ce4_triangles`, intact while their entry
  // of `status` (the CE4 stage's int2 (broken, mode)) has broken == 0. `status` may be
  // null only when there are no CE4s.
  FragmentLabels(ClContext& cl, size_t triangles, size_t nodes, compute::buffer& tri_nodes,
                 const std::vector<std::array<int, 2>>& ce4_triangles, compute::buffer* status);
  // The arrays: the CE4s' triangle pairs and the change flag (the constructor's), and one
  // label per triangle and node (an output array, allocated by each labels() call).
  static MemoryPlan plan(size_t triangles, size_t nodes, size_t ce4);
  // uint2 per CE4: its two triangles (ContactActivation reads the same array).
  const compute::buffer& ce4_triangles() const { return pairs_; }

  // Labels the pieces now: per triangle, the smallest triangle index of its piece.
  // Waits: a flag read per round on a CPU, every second round from the fourth on a GPU
  // (rounds() says how many the last call took).
  std::vector<int> labels();
  int rounds() const { return rounds_; }

 private:
  ClContext& cl_;
  size_t triangles_, vertices_, ce4_;
  int rounds_ = 0;
  compute::kernel init_, hook_triangles_, hook_ce4_, shortcut_;
  compute::buffer pairs_, changed_;
  size_t label_bytes_ = 0;                            // the labels: allocated by labels() for the call
  std::vector<KernelArg<compute::buffer>> label_args_;  // each kernel's `label` (the change flag between calls)
};

}  // namespace fdem
