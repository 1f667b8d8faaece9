// Stage: TRI3 internal forces (cl_kernels/triangle_forces.cl).
#pragma once
#include "engine/device_arrays.hpp"

namespace fdem {

class TriangleForces {
 public:
  // Compiles the stage and binds its arrays once.
  TriangleForces(ClContext& cl, DeviceArrays& arrays, double thickness);
  // Writes every triangle's corner forces (and, when write_stress, its stress). Never waits.
  void enqueue(int step, bool write_stress);

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel kernel_;
};

}  // namespace fdem
