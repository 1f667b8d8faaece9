#include "engine/stages/node_gather.hpp"

namespace fdem {

NodeGather::NodeGather(ClContext& cl, DeviceArrays& a) : cl_(cl), count_(a.num_nodes) {
  const auto program = cl.build("gather");
  forces_ = compute::kernel(program, "gather_node_sums");
  masses_ = compute::kernel(program, "gather_node_sums");
  for (auto* k : {&forces_, &masses_}) {
    k->set_arg(0, static_cast<cl_uint>(count_));
    k->set_arg(1, a.corner_start);
    k->set_arg(2, a.corner_slot);
    k->set_arg(3, a.corner_force);
    k->set_arg(5, a.edge_start);
    k->set_arg(6, a.edge_slot);
    k->set_arg(7, a.edge_force);
    k->set_arg(8, cl_int(0));
    k->set_arg(9, a.ce4_start);
    k->set_arg(10, a.ce4_slot);
    k->set_arg(11, a.edge_force);  // placeholder until add_cohesive
    k->set_arg(12, cl_int(0));
    k->set_arg(13, a.contact_acc);
    k->set_arg(14, real(0));
  }
  forces_.set_arg(4, cl_int(a.num_loaded_edges > 0 ? 1 : 0));
  forces_.set_arg(15, a.node_force);
  masses_.set_arg(4, cl_int(0));
  masses_.set_arg(15, a.node_mass);
}

void NodeGather::add_contact(double force_scale) {
  forces_.set_arg(12, cl_int(1));
  forces_.set_arg(14, static_cast<real>(1.0 / force_scale));
}

void NodeGather::add_cohesive(const compute::buffer& ce4_slots) {
  forces_.set_arg(8, cl_int(1));
  forces_.set_arg(11, ce4_slots);
}

void NodeGather::enqueue_forces() { cl_.enqueue(forces_, count_); }
void NodeGather::enqueue_corner_sums_into_mass() { cl_.enqueue(masses_, count_); }

}  // namespace fdem
