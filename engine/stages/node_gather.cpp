#include "engine/stages/node_gather.hpp"

#include "engine/kernel_args.hpp"

namespace fdem {

NodeGather::NodeGather(ClContext& cl, DeviceArrays& a, const compute::buffer* ce4_slots, double contact_force_scale)
    : cl_(cl), count_(a.num_nodes) {
  const bool edges = a.num_loaded_edges > 0, ce4 = ce4_slots != nullptr, contact = contact_force_scale > 0;
  auto program = [&](bool with_edges, bool with_ce4, bool with_contact) {
    return cl.build(kernel_source::node_gather, {{"GATHER_EDGES", with_edges ? "1" : "0"},
                                                 {"GATHER_CE4", with_ce4 ? "1" : "0"},
                                                 {"GATHER_CONTACT", with_contact ? "1" : "0"}});
  };
  forces_ = compute::kernel(program(edges, ce4, contact), "gather_node_sums");
  KernelArgs f(forces_);
  f("n_nodes", static_cast<cl_uint>(count_))("corner_start", a.corner_start)("corner_slot", a.corner_slot)(
      "corner_value", a.corner_force);
  if (edges) f("edge_start", a.edge_start)("edge_slot", a.edge_slot)("edge_value", a.edge_force);
  if (ce4) f("ce4_start", a.ce4_start)("ce4_slot", a.ce4_slot)("ce4_value", *ce4_slots);
  if (contact) f("contact_acc", a.contact_acc)("contact_unit", static_cast<real>(1.0 / contact_force_scale));
  f("node_sum", a.node_force).done();

  masses_ = compute::kernel(program(false, false, false), "gather_node_sums");
  KernelArgs m(masses_);
  m("n_nodes", static_cast<cl_uint>(count_))("corner_start", a.corner_start)("corner_slot", a.corner_slot)(
       "corner_value", a.corner_force)("node_sum", a.node_mass)
      .done();
}

void NodeGather::enqueue_forces() { cl_.enqueue(forces_, count_); }
void NodeGather::enqueue_corner_sums_into_mass() { cl_.enqueue(masses_, count_); }

}  // namespace fdem
