#include "engine/stages/triangle_forces.hpp"

#include <string>
#include <vector>

namespace fdem {

TriangleForces::TriangleForces(ClContext& cl, DeviceArrays& a, double thickness, double dt, bool viscous)
    : cl_(cl), count_(a.num_triangles), groups_(work_groups(cl, a.num_triangles)), viscous_(viscous) {
  kernel_ = compute::kernel(cl.build("triangle_forces", {{"GROUP_SIZE", std::to_string(cl.group_size())}}),
                            "triangle_forces");
  group_energy_ = cl.allocate(std::max<size_t>(1, groups_) * sizeof(real2), "triangle group_energy");
  upload(cl, group_energy_, std::vector<real2>(std::max<size_t>(1, groups_)));
  // A t σ_viscous of the last step per triangle, for the trapezoid rule of its work.
  const size_t viscous_items = viscous_ ? std::max<size_t>(1, count_) : 1;
  viscous_stress_ = cl.allocate(viscous_items * sizeof(real4), "triangle viscous_stress");
  upload(cl, viscous_stress_, std::vector<real4>(viscous_items));
  kernel_.set_arg(0, static_cast<cl_uint>(count_));
  kernel_.set_arg(1, a.tri_nodes);
  kernel_.set_arg(2, a.ref_inverse);
  kernel_.set_arg(3, a.tri_material);
  kernel_.set_arg(4, a.materials);
  kernel_.set_arg(5, a.position);
  kernel_.set_arg(6, a.velocity);
  kernel_.set_arg(7, static_cast<real>(thickness));
  kernel_.set_arg(8, cl_int(0));
  kernel_.set_arg(9, cl_int(0));
  kernel_.set_arg(10, a.corner_force);
  kernel_.set_arg(11, a.stress);
  kernel_.set_arg(12, a.conditions);
  kernel_.set_arg(13, cl_int(0));
  kernel_.set_arg(14, static_cast<real>(dt));
  kernel_.set_arg(15, group_energy_);
  kernel_.set_arg(16, viscous_stress_);
}

void TriangleForces::enqueue(int step, bool energy_row) {
  kernel_.set_arg(8, cl_int(0));
  kernel_.set_arg(9, cl_int(step));
  kernel_.set_arg(13, cl_int((viscous_ ? 1 : 0) | (energy_row ? 2 : 0)));
  cl_.enqueue(kernel_, count_);
}

void TriangleForces::enqueue_stress(int step) {
  kernel_.set_arg(8, cl_int(1));
  kernel_.set_arg(9, cl_int(step));
  kernel_.set_arg(13, cl_int(0));
  cl_.enqueue(kernel_, count_);
}

void TriangleForces::add_energy(EnergyTotals& e) {
  const auto sum = sum_group_slots(cl_, group_energy_, groups_, 2);
  e.strain += sum[0];
  e.viscous += sum[1];
}

}  // namespace fdem
