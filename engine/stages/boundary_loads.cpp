#include "engine/stages/boundary_loads.hpp"

#include <string>
#include <vector>

namespace fdem {

BoundaryLoads::BoundaryLoads(ClContext& cl, DeviceArrays& a, double thickness, double dt)
    : cl_(cl), count_(a.num_loaded_edges), groups_(work_groups(cl, a.num_loaded_edges)) {
  kernel_ = compute::kernel(cl.build("boundary_loads", {{"GROUP_SIZE", std::to_string(cl.group_size())}}),
                            "boundary_loads");
  group_energy_ = cl.allocate(std::max<size_t>(1, groups_) * sizeof(real2), "boundary_loads group_energy");
  upload(cl, group_energy_, std::vector<real2>(std::max<size_t>(1, groups_)));
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
  kernel_.set_arg(12, static_cast<real>(dt));
  kernel_.set_arg(13, cl_int(0));
  kernel_.set_arg(14, group_energy_);
}

void BoundaryLoads::enqueue(double time, int step) {
  if (count_ == 0) return;
  kernel_.set_arg(10, static_cast<real>(time));
  kernel_.set_arg(13, cl_int(step));
  cl_.enqueue(kernel_, count_);
}

void BoundaryLoads::add_energy(EnergyTotals& e) {
  const auto sum = sum_group_slots(cl_, group_energy_, groups_, 2);
  e.load_work += sum[0];
  e.absorbed += sum[1];
}

}  // namespace fdem
