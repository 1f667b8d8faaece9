// Stage: tractions, pressures (constant, tabulated, blast) and absorbing tractions on
// boundary edges (cl_kernels/boundary_loads.cl).
#pragma once
#include "engine/device_arrays.hpp"

namespace fdem {

class BoundaryLoads {
 public:
  BoundaryLoads(ClContext& cl, DeviceArrays& arrays, double thickness);
  // Edge forces at time `time` (absorbing edges use the current velocities). Never
  // waits; does nothing when no edge is loaded.
  void enqueue(double time);

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel kernel_;
};

}  // namespace fdem
