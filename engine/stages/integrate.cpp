#include "engine/stages/integrate.hpp"

#include <string>
#include <vector>

namespace fdem {

Integrate::Integrate(ClContext& cl, DeviceArrays& a, std::array<double, 2> gravity,
                     double local_damping, double dt, bool prescribed, bool account)
    : cl_(cl), count_(a.num_nodes), groups_(work_groups(cl, a.num_nodes)),
      account_work_(account && (prescribed || local_damping != 0)) {
  kernel_ = compute::kernel(cl.build("integrate", {{"GROUP_SIZE", std::to_string(cl.group_size())}}), "integrate");
  group_work_ = cl.allocate(std::max<size_t>(1, groups_) * sizeof(real2), "integrate group_work");
  group_row_ = cl.allocate(std::max<size_t>(1, groups_) * sizeof(real4), "integrate group_row");
  upload(cl, group_work_, std::vector<real2>(std::max<size_t>(1, groups_)));
  upload(cl, group_row_, std::vector<real4>(std::max<size_t>(1, groups_)));
  const size_t work_items = account_work_ ? std::max<size_t>(1, count_) : 1;
  node_work_ = cl.allocate(work_items * sizeof(real2), "integrate node_work");
  upload(cl, node_work_, std::vector<real2>(work_items));
  kernel_.set_arg(0, static_cast<cl_uint>(count_));
  kernel_.set_arg(1, a.position);
  kernel_.set_arg(2, a.velocity);
  kernel_.set_arg(3, a.node_force);
  kernel_.set_arg(4, a.node_mass);
  kernel_.set_arg(5, a.node_group);
  kernel_.set_arg(6, a.group_table);
  kernel_.set_arg(7, static_cast<real>(gravity[0]));
  kernel_.set_arg(8, static_cast<real>(gravity[1]));
  kernel_.set_arg(9, static_cast<real>(local_damping));
  kernel_.set_arg(10, static_cast<real>(dt));
  kernel_.set_arg(11, real(0));
  kernel_.set_arg(12, cl_int(0));
  kernel_.set_arg(13, a.conditions);
  // No skin test until add_skin_test(); the buffers only need to be valid.
  kernel_.set_arg(14, cl_int(0));
  kernel_.set_arg(15, a.position);
  kernel_.set_arg(16, a.conditions);
  kernel_.set_arg(17, cl_uint(0));
  kernel_.set_arg(18, cl_uint(0));
  kernel_.set_arg(19, a.ref_position);
  kernel_.set_arg(20, cl_int(account_work_ ? 1 : 0));
  kernel_.set_arg(21, cl_int(0));
  kernel_.set_arg(22, group_work_);
  kernel_.set_arg(23, group_row_);
  kernel_.set_arg(24, node_work_);
}

void Integrate::add_skin_test(compute::buffer& position_at_build, compute::buffer& monitor,
                              unsigned (*slot_of)(long)) {
  kernel_.set_arg(14, cl_int(1));
  kernel_.set_arg(15, position_at_build);
  kernel_.set_arg(16, monitor);
  slot_of_ = slot_of;
}

void Integrate::enqueue(double time_after, int step, bool energy_row) {
  kernel_.set_arg(11, static_cast<real>(time_after));
  kernel_.set_arg(12, cl_int(step));
  kernel_.set_arg(21, cl_int(energy_row ? 1 : 0));
  if (slot_of_) {
    kernel_.set_arg(17, static_cast<cl_uint>(slot_of_(step + 1)));
    kernel_.set_arg(18, static_cast<cl_uint>(slot_of_(step + 2)));
  }
  cl_.enqueue(kernel_, count_);
}

void Integrate::add_energy(EnergyTotals& e) {
  const auto row = sum_group_slots(cl_, group_row_, groups_, 4);
  e.kinetic += row[0];
  e.gravity_potential += row[1];
  if (!account_work_) return;
  const auto work = sum_group_slots(cl_, group_work_, groups_, 2);
  // The cumulative sums hold this step's forward halves too; the row runs to t.
  e.local_damping += -(work[0] - row[2]);
  e.boundary_work += work[1] - row[3];
}

}  // namespace fdem
