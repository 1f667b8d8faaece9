// Stage: lumped mass and the integrator's inertia (cl_kernels/lumped_mass.cl), run once
// at set-up. Uses the corner_force array as scratch for the corner masses, node_force for
// the reference positions and the nodes' sums.
#pragma once
#include "engine/device/device_arrays.hpp"
#include "engine/model/model.hpp"
#include "engine/stages/node_gather.hpp"

namespace fdem {

class LumpedMass {
 public:
  // Binds the model's triangles and, when it has CE4s, the stiffness per node that mass
  // scaling must also cover: an intact CE4 of penalty P is a spring between its faces
  // (ce4_node_stiffness).
  LumpedMass(ClContext& cl, DeviceArrays& arrays, const Model& model, double dt);
  // The arrays the constructor allocates: set-up only (the Solver drops this stage once
  // the masses are computed).
  static MemoryPlan plan(size_t nodes, bool ce4);
  // With mass scaling node_mass = (Σ ρA₀t/3, inertia), inertia = 0.3 Δt²Σk; without, the
  // inertia is the mass and node_mass holds it once (one real per node, 8 B instead of 16:
  // DeviceArrays::plan). The reference positions and the sums (mass, Σk) pass through
  // node_force, unused before the first step, which is zero again afterwards.
  void enqueue(NodeGather& gather);

 private:
  ClContext& cl_;
  size_t triangles_, nodes_;
  compute::kernel corner_, inertia_;
  compute::buffer extra_, node_force_;
};

// The stiffness per node [N/m] of the intact CE4s at it: an upper bound of the absolute
// row sums of their stiffness (one entry per node; all zero without CE4s).
std::vector<real> ce4_node_stiffness(const Model& model);

}  // namespace fdem
