// Stage: node gather (cl_kernels/node_gather.cl): sums corner, edge, CE4 and contact
// contributions per node in a fixed order, the deterministic replacement for
// floating-point atomics.
#pragma once
#include <map>
#include <string>

#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"

namespace fdem {

class NodeGather {
 public:
  // The force gather adds what the model has: the loaded edges' slots (when it has
  // loaded edges), the CE4 slots `ce4_slots` (4 real2 per CE4, through DeviceArrays'
  // node → CE4-slot map; null: no CE4s) and the fixed-point contact forces
  // contact_acc / contact_force_scale (0: no contact). The mass gather adds the corner
  // values only.
  // `fluid_slots` (FluidFlow::slots(), 4 real2 per CE4 in the CE4 slots' order; null: no
  // [fluid]) are added through the same node → CE4-slot map at the nodes that
  // `fluid_nodes` (FluidFlow::loaded_nodes(), a byte a node) flags.
  NodeGather(ClContext& cl, DeviceArrays& arrays, const compute::buffer* ce4_slots, double contact_force_scale,
             const compute::buffer* fluid_slots = nullptr, const compute::buffer* fluid_nodes = nullptr);
  // node_force = Σ corner_force + Σ edge_force + Σ CE4 slots + contact. Never waits.
  // (The Solver's step leaves this to Integrate, which gathers the same sum itself.)
  void enqueue_forces();
  // The force gather's defines (GATHER_EDGES, GATHER_CE4, GATHER_CONTACT) and its
  // arguments, for a kernel that sums a node's force with gathered_sum
  // (cl_kernels/node_gather.cl): Integrate with a Gather, and this stage itself.
  static std::map<std::string, std::string> force_defines(const DeviceArrays& arrays, const compute::buffer* ce4_slots,
                                                          double contact_force_scale,
                                                          const compute::buffer* fluid_slots = nullptr);
  static void bind_force_sources(KernelArgs& args, const DeviceArrays& arrays, const compute::buffer* ce4_slots,
                                 double contact_force_scale, const compute::buffer* fluid_slots = nullptr,
                                 const compute::buffer* fluid_nodes = nullptr);
  // sums = Σ corner values per node (real2: the corner masses and stiffnesses written by
  // LumpedMass, into its set-up array). Never waits.
  void enqueue_corner_sums_into(const compute::buffer& sums);

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel forces_, masses_;
  KernelArg<compute::buffer> mass_sums_;  // the mass gather's target, set by each call
};

}  // namespace fdem
