#include "engine/stages/integrate.hpp"

namespace fdem {

Integrate::Integrate(ClContext& cl, DeviceArrays& a, std::array<double, 2> gravity,
                     double local_damping, double dt)
    : cl_(cl), count_(a.num_nodes) {
  kernel_ = compute::kernel(cl.build("integrate"), "integrate");
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
}

void Integrate::enqueue(double time_after, int step) {
  kernel_.set_arg(11, static_cast<real>(time_after));
  kernel_.set_arg(12, cl_int(step));
  cl_.enqueue(kernel_, count_);
}

}  // namespace fdem
