// Stage: node gather (cl_kernels/node_gather.cl): sums corner, edge, CE4 and contact
// contributions per node in a fixed order, the deterministic replacement for
// floating-point atomics.
#pragma once
#include "engine/device_arrays.hpp"

namespace fdem {

class NodeGather {
 public:
  // The force gather adds what the model has: the loaded edges' slots (when it has
  // loaded edges), the CE4 slots `ce4_slots` (4 real2 per CE4, through DeviceArrays'
  // node → CE4-slot map; null: no CE4s) and the fixed-point contact forces
  // contact_acc / contact_force_scale (0: no contact). The mass gather adds the corner
  // values only.
  NodeGather(ClContext& cl, DeviceArrays& arrays, const compute::buffer* ce4_slots, double contact_force_scale);
  // node_force = Σ corner_force + Σ edge_force + Σ CE4 slots + contact. Never waits.
  void enqueue_forces();
  // node_mass = Σ corner values (the corner masses written by LumpedMass). Never waits.
  void enqueue_corner_sums_into_mass();

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel forces_, masses_;
};

}  // namespace fdem
