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
  // From now on each step also writes the contact skin test of the next step into ring
  // slot slot_of(step + 1) of `monitor` (ContactSkin), against `position_at_build`.
  void add_skin_test(compute::buffer& position_at_build, compute::buffer& monitor, unsigned (*slot_of)(long));

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel kernel_;
  unsigned (*slot_of_)(long) = nullptr;
};

}  // namespace fdem
