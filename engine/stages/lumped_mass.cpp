#include "engine/stages/lumped_mass.hpp"

namespace fdem {

LumpedMass::LumpedMass(ClContext& cl, DeviceArrays& a, double thickness)
    : cl_(cl), triangles_(a.num_triangles), nodes_(a.num_nodes) {
  const auto program = cl.build("lumped_mass");
  corner_ = compute::kernel(program, "triangle_mass");
  corner_.set_arg(0, static_cast<cl_uint>(triangles_));
  corner_.set_arg(1, a.tri_nodes);
  corner_.set_arg(2, a.tri_material);
  corner_.set_arg(3, a.materials);
  corner_.set_arg(4, a.ref_position);
  corner_.set_arg(5, a.ref_inverse);
  corner_.set_arg(6, static_cast<real>(thickness));
  corner_.set_arg(7, a.corner_force);
  inertia_ = compute::kernel(program, "node_inertia");
  inertia_.set_arg(0, static_cast<cl_uint>(nodes_));
  inertia_.set_arg(3, a.node_mass);
  extra_ = cl.allocate(sizeof(real), "extra_stiffness");
  inertia_.set_arg(4, cl_int(0));
  inertia_.set_arg(5, extra_);
}

void LumpedMass::set_extra_stiffness(const std::vector<real>& per_node) {
  extra_ = cl_.allocate(per_node.size() * sizeof(real), "extra_stiffness");
  upload(cl_, extra_, per_node);
  inertia_.set_arg(4, cl_int(1));
  inertia_.set_arg(5, extra_);
}

void LumpedMass::enqueue(NodeGather& gather, bool mass_scaling, double dt) {
  cl_.enqueue(corner_, triangles_);
  gather.enqueue_corner_sums_into_mass();
  inertia_.set_arg(1, cl_int(mass_scaling ? 1 : 0));
  inertia_.set_arg(2, static_cast<real>(dt));
  cl_.enqueue(inertia_, nodes_);
}

}  // namespace fdem
