// Stage: tractions, pressures (constant, tabulated, blast) and absorbing tractions on
// boundary edges (cl_kernels/boundary_loads.cl), with their work for the energy account.
#pragma once
#include "engine/device_arrays.hpp"
#include "engine/energy.hpp"

namespace fdem {

class BoundaryLoads {
 public:
  BoundaryLoads(ClContext& cl, DeviceArrays& arrays, double thickness, double dt);
  // Edge forces at time `time` (absorbing edges use the current velocities) of step
  // `step`, and the loads' work over the step before. Never waits; does nothing when no
  // edge is loaded.
  void enqueue(double time, int step);
  // Load work and absorbed energy from t = 0 up to the current step's time (waits).
  void add_energy(EnergyTotals& totals);

 private:
  ClContext& cl_;
  size_t count_, groups_;
  compute::kernel kernel_;
  compute::buffer group_energy_;  // real2 per work-group: (load work, absorbed energy)
};

}  // namespace fdem
