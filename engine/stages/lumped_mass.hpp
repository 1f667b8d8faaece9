// Stage: lumped mass and the integrator's inertia (cl_kernels/lumped_mass.cl), run once
// at set-up. Uses the corner_force array as scratch for the corner masses.
#pragma once
#include "engine/device_arrays.hpp"
#include "engine/stages/node_gather.hpp"

namespace fdem {

class LumpedMass {
 public:
  LumpedMass(ClContext& cl, DeviceArrays& arrays, double thickness);
  // Extra stiffness per node [N/m] that mass scaling must cover (intact CE4 springs).
  void set_extra_stiffness(const std::vector<real>& per_node);
  // node_mass = (Σ ρA₀t/3, inertia); inertia = 0.3 Δt²Σk with mass scaling, else the mass.
  void enqueue(NodeGather& gather, bool mass_scaling, double dt);

 private:
  ClContext& cl_;
  size_t triangles_, nodes_;
  compute::kernel corner_, inertia_;
  compute::buffer extra_;
};

}  // namespace fdem
