#include "engine/stages/boundary_loads.hpp"

namespace fdem {

BoundaryLoads::BoundaryLoads(ClContext& cl, DeviceArrays& a, double thickness)
    : cl_(cl), count_(a.num_loaded_edges) {
  kernel_ = compute::kernel(cl.build("boundary_loads"), "boundary_loads");
  kernel_.set_arg(0, static_cast<cl_uint>(count_));
  kernel_.set_arg(1, a.edge_nodes);
  kernel_.set_arg(2, a.edge_load);
  kernel_.set_arg(3, a.load_table);
  kernel_.set_arg(4, a.pressure_points);
  kernel_.set_arg(5, a.materials);
  kernel_.set_arg(6, a.ref_position);
  kernel_.set_arg(7, a.position);
  kernel_.set_arg(8, a.velocity);
  kernel_.set_arg(9, static_cast<real>(thickness));
  kernel_.set_arg(10, real(0));
  kernel_.set_arg(11, a.edge_force);
}

void BoundaryLoads::enqueue(double time) {
  if (count_ == 0) return;
  kernel_.set_arg(10, static_cast<real>(time));
  cl_.enqueue(kernel_, count_);
}

}  // namespace fdem
