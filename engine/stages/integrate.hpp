// Stage: central-difference integration with gravity, local damping and prescribed
// velocities (cl_kernels/integrate.cl).
#pragma once
#include <array>

#include "engine/device_arrays.hpp"

namespace fdem {

class Integrate {
 public:
  Integrate(ClContext& cl, DeviceArrays& arrays, std::array<double, 2> gravity,
            double local_damping, double dt);
  // Advances every node from t to time_after = t + Δt. Never waits.
  void enqueue(double time_after, int step);

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel kernel_;
};

}  // namespace fdem
