// Stage: node gather (cl_kernels/gather.cl): sums corner and edge contributions per node
// in a fixed order, the deterministic replacement for floating-point atomics.
#pragma once
#include "engine/device_arrays.hpp"

namespace fdem {

class NodeGather {
 public:
  NodeGather(ClContext& cl, DeviceArrays& arrays);
  // From now on the force gather also adds the fixed-point contact forces
  // (contact_acc / force_scale).
  void add_contact(double force_scale);
  // From now on the force gather also adds the CE4 slots (4 real2 per CE4, through the
  // node → CE4-slot map of DeviceArrays).
  void add_cohesive(const compute::buffer& ce4_slots);
  // node_force = Σ corner_force + Σ edge_force (+ contact). Never waits.
  void enqueue_forces();
  // node_mass = Σ corner values (the corner masses written by LumpedMass). Never waits.
  void enqueue_corner_sums_into_mass();

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel forces_, masses_;
};

}  // namespace fdem
