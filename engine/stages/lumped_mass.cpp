#include "engine/stages/lumped_mass.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "engine/device/kernel_args.hpp"

namespace fdem {

std::vector<real> ce4_node_stiffness(const Model& model) {
  // An intact CE4 of penalty P on an edge of length L (= its h) is a spring of at most
  // (P/h) L t between its faces; the absolute row sums of its stiffness at a node are
  // below √2 P t (∫N = ½ per node, two faces, the normal/tangent mix of x and y). In
  // shear the cohesive part and the friction element's stick spring add: 2 P_tan.
  std::vector<real> extra(model.num_nodes(), 0);
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const auto& f = model.fracture[model.ce4_properties[e]];
    const double k =
        std::sqrt(2.0) * std::max({f.penalty_opening, 2.0 * f.penalty_sliding, f.penalty_overlap}) * model.thickness;
    for (int n : model.ce4[e]) extra[n] += static_cast<real>(k);
  }
  return extra;
}

MemoryPlan LumpedMass::plan(size_t nodes, bool ce4) {
  MemoryPlan p;
  if (ce4) p.add("extra_stiffness", nodes * sizeof(real), MemoryPlan::Lifetime::SetUp);
  return p;
}

LumpedMass::LumpedMass(ClContext& cl, DeviceArrays& a, const Model& model, double dt)
    : cl_(cl), triangles_(a.num_triangles), nodes_(a.num_nodes), node_force_(a.node_force) {
  // node_force holds nothing before the first step: it takes the reference positions for
  // triangle_mass (the device keeps none without gravity: DeviceArrays), then the sums
  // (mass, Σk) for node_inertia, and is zeroed again when the masses are done (enqueue).
  upload(cl, a.node_force, DeviceArrays::reference_positions(model));
  const bool ce4 = !model.ce4.empty();
  std::map<std::string, std::string> defines{{"CE4_STIFFNESS", ce4 ? "1" : "0"},
                                             {"MASS_SCALING", model.mass_scaling ? "1" : "0"}};
  if (a.young_count > 0) defines["HETEROGENEOUS_YOUNG"] = "1";
  const auto program = cl.build(kernel_source::lumped_mass, defines);
  corner_ = compute::kernel(program, "triangle_mass");
  KernelArgs corner(corner_);
  corner("n_triangles", static_cast<cl_uint>(triangles_))("tri_nodes", a.tri_nodes)("tri_material", a.tri_material)(
      "materials", a.materials)("ref_position", a.node_force)("ref_inverse", a.ref_inverse)(
      "thickness", static_cast<real>(model.thickness))("corner_mass", a.corner_force);
  if (a.young_count > 0)
    corner("young_factor", a.young_factor)("young_first", static_cast<cl_uint>(a.young_first))(
        "young_count", static_cast<cl_uint>(a.young_count));
  corner.done();
  inertia_ = compute::kernel(program, "node_inertia");
  KernelArgs inertia(inertia_);
  inertia("n_nodes", static_cast<cl_uint>(nodes_))("dt", static_cast<real>(dt))("node_sums", a.node_force)(
      "node_mass", a.node_mass);
  if (ce4) {
    const auto extra = ce4_node_stiffness(model);
    extra_ = plan(nodes_, ce4).allocate(cl, "extra_stiffness");
    upload(cl, extra_, extra);
    inertia("extra_stiffness", extra_);
  }
  inertia.done();
}

void LumpedMass::enqueue(NodeGather& gather) {
  cl_.enqueue(corner_, triangles_);
  gather.enqueue_corner_sums_into(node_force_);  // the reference positions are read: overwrite them
  cl_.enqueue(inertia_, nodes_);
  upload(cl_, node_force_, std::vector<real2>(nodes_));
}

}  // namespace fdem
