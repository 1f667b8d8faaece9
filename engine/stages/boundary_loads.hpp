// Stage: tractions, pressures (constant, tabulated, blast) and absorbing tractions on
// boundary edges (cl_kernels/boundary_loads.cl), with their work for the energy account.
#pragma once
#include "engine/device_arrays.hpp"
#include "engine/kernel_args.hpp"
#include "engine/checkpoint.hpp"
#include "engine/energy.hpp"

namespace fdem {

class BoundaryLoads {
 public:
  BoundaryLoads(ClContext& cl, DeviceArrays& arrays, double thickness, double dt);
  // The arrays the constructor allocates (`group_size`: ClContext::group_size()).
  static MemoryPlan plan(size_t loaded_edges, size_t group_size);
  // Edge forces at time `time` (absorbing edges use the current velocities) of step
  // `step`, and the loads' work over the step before. Never waits; does nothing when no
  // edge is loaded.
  void enqueue(double time, int step);
  // Load work and absorbed energy from t = 0 up to the current step's time (waits).
  void add_energy(EnergyTotals& totals);

  // The cumulative energy sums, for checkpoints.
  void save_state(StateWriter& out) const { out.group_slots("load_energy", group_energy_, groups_, 2); }
  void load_state(StateReader& in) { in.group_slots("load_energy", group_energy_, groups_, 2); }

 private:
  ClContext& cl_;
  size_t count_, groups_;
  compute::kernel kernel_;
  KernelArg<real> time_;
  KernelArg<cl_int> step_;
  compute::buffer group_energy_;  // real2 per work-group: (load work, absorbed energy)
};

}  // namespace fdem
