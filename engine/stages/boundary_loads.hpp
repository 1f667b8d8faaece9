// Stage: tractions, pressures (constant, tabulated, blast) and absorbing tractions on
// boundary edges (cl_kernels/boundary_loads.cl), with their work for the energy account.
#pragma once
#include <map>
#include <string>

#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/checkpoint.hpp"
#include "engine/energy/energy.hpp"

namespace fdem {

class BoundaryLoads {
 public:
  // `in_situ`: the model has in-situ tractions (LoadKind::InSitu); without, the kernel is
  // built without their branch.
  // `gas_hole`: FluidFlow::gas_hole() when the model has a [fluid.gas] hole (LoadKind::Gas
  // edges read its pressure), else null.
  BoundaryLoads(ClContext& cl, DeviceArrays& arrays, double thickness, double dt, bool in_situ = false,
                compute::buffer* gas_hole = nullptr);
  // The arrays the constructor allocates (`group_size`: ClContext::group_size()).
  static MemoryPlan plan(size_t loaded_edges, size_t group_size);
  // Edge forces at time `time` (absorbing edges use the current velocities) of step
  // `step`, and the loads' work over the step before. Never waits; does nothing when no
  // edge is loaded.
  void enqueue(double time, int step);

  // Fused into TriangleForces' launch (one launch a step less; the step's order allows
  // it: neither stage reads what the other writes): tail_defines() go into that
  // program's build, with boundary_loads.cl as a library, and bind_tail binds this
  // stage's arguments after the triangle kernel's own (BOUNDARY_TAIL in
  // triangle_forces.cl). enqueue then sets the time and edge count and launches nothing;
  // quiet_tail() keeps the next launch of that kernel (the output's stress pass) off the
  // edges until enqueue sets them again.
  std::map<std::string, std::string> tail_defines() const;
  void bind_tail(KernelArgs& args);
  void quiet_tail();
  bool fused() const { return fused_; }
  size_t count() const { return count_; }
  // Load work and absorbed energy from t = 0 up to the last step, summed per edge by `sums` (waits).
  void add_energy(EnergyTotals& totals, const ItemSums& sums = all_items) { queue_energy(sums)(totals); }
  EnergyPart queue_energy(const ItemSums& sums);  // the same, added once `sums` have landed

  // The cumulative energy sums, for checkpoints.
  void save_state(StateWriter& out) const { out.buffer<real>("load_edge_energy", edge_energy_, count_, 2); }
  void load_state(StateReader& in) { in.buffer<real>("load_edge_energy", edge_energy_, count_, 2); }

 private:
  // The loaded edges' own arguments (BOUNDARY_EDGE_ARGS), after the ones a kernel shares
  // with them; returns the time's.
  KernelArg<real> bind_edges(KernelArgs& args);
  ClContext& cl_;
  size_t count_, groups_;
  compute::kernel kernel_;
  KernelArg<real> time_;
  KernelArg<cl_int> step_;
  compute::buffer edge_energy_;  // real2 per loaded edge: (load work, absorbed energy) so far
  DeviceArrays& arrays_;
  compute::buffer* gas_hole_;
  bool in_situ_, fused_ = false;
  KernelArg<real> tail_time_;
  KernelArg<cl_uint> tail_edges_;
};

}  // namespace fdem
