#include "engine/stages/triangle_forces.hpp"

namespace fdem {

TriangleForces::TriangleForces(ClContext& cl, DeviceArrays& a, double thickness)
    : cl_(cl), count_(a.num_triangles) {
  kernel_ = compute::kernel(cl.build("triangle_forces"), "triangle_forces");
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
}

void TriangleForces::enqueue(int step, bool write_stress) {
  kernel_.set_arg(8, cl_int(write_stress ? 1 : 0));
  kernel_.set_arg(9, cl_int(step));
  cl_.enqueue(kernel_, count_);
}

}  // namespace fdem
