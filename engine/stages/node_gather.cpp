#include "engine/stages/node_gather.hpp"

namespace fdem {

std::map<std::string, std::string> NodeGather::force_defines(const DeviceArrays& a, const compute::buffer* ce4_slots,
                                                             double contact_force_scale, const compute::buffer* fluid_slots) {
  return {{"GATHER_EDGES", a.num_loaded_edges > 0 ? "1" : "0"},
          {"GATHER_CE4", ce4_slots != nullptr ? "1" : "0"},
          {"GATHER_CONTACT", contact_force_scale > 0 ? "1" : "0"},
          {"GATHER_FLUID", ce4_slots != nullptr && fluid_slots != nullptr ? "1" : "0"}};
}

void NodeGather::bind_force_sources(KernelArgs& f, const DeviceArrays& a, const compute::buffer* ce4_slots,
                                    double contact_force_scale, const compute::buffer* fluid_slots,
                                    const compute::buffer* fluid_nodes) {
  f("node_start", a.node_start)("node_slot", a.node_slot)("corner_value", a.corner_force);
  if (a.num_loaded_edges > 0) f("edge_value", a.edge_force);
  if (ce4_slots) f("ce4_value", *ce4_slots);
  if (ce4_slots && fluid_slots) {
    if (!fluid_nodes) throw DeviceError("node gather: fluid slots without the fluid stage's node flags");
    f("fluid_value", *fluid_slots)("fluid_loaded_node", *fluid_nodes);
  }
  if (contact_force_scale > 0)
    f("contact_acc", a.contact_acc)("contact_unit", static_cast<real>(1.0 / contact_force_scale));
}

NodeGather::NodeGather(ClContext& cl, DeviceArrays& a, const compute::buffer* ce4_slots, double contact_force_scale,
                       const compute::buffer* fluid_slots, const compute::buffer* fluid_nodes)
    : cl_(cl), count_(a.num_nodes) {
  forces_ = compute::kernel(
      cl.build(kernel_source::node_gather, force_defines(a, ce4_slots, contact_force_scale, fluid_slots)), "gather_node_sums");
  KernelArgs f(forces_);
  f("n_nodes", static_cast<cl_uint>(count_));
  bind_force_sources(f, a, ce4_slots, contact_force_scale, fluid_slots, fluid_nodes);
  f("node_sum", a.node_force).done();

  const std::map<std::string, std::string> corners_only{{"GATHER_EDGES", "0"}, {"GATHER_CE4", "0"}, {"GATHER_CONTACT", "0"},
                                                                {"GATHER_FLUID", "0"}};
  masses_ = compute::kernel(cl.build(kernel_source::node_gather, corners_only), "gather_node_sums");
  KernelArgs m(masses_);
  m("n_nodes", static_cast<cl_uint>(count_))("node_start", a.node_start)("node_slot", a.node_slot)(
       "corner_value", a.corner_force);
  mass_sums_ = m.later("node_sum", a.node_force);  // a placeholder until the call names its target
  m.done();
}

void NodeGather::enqueue_forces() { cl_.enqueue(forces_, count_); }
void NodeGather::enqueue_corner_sums_into(const compute::buffer& sums) {
  mass_sums_.set(sums);
  cl_.enqueue(masses_, count_);
}

}  // namespace fdem
