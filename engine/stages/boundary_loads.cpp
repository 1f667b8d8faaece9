#include "engine/stages/boundary_loads.hpp"

#include <map>
#include <string>

#include "engine/device/kernel_args.hpp"
#include <vector>

namespace fdem {

MemoryPlan BoundaryLoads::plan(size_t loaded_edges, size_t group_size) {
  (void)group_size;
  return MemoryPlan().add("boundary_loads edge_energy", std::max<size_t>(1, loaded_edges) * sizeof(real2));
}

BoundaryLoads::BoundaryLoads(ClContext& cl, DeviceArrays& a, double thickness, double dt, bool in_situ,
                             compute::buffer* gas_hole)
    : cl_(cl),
      count_(a.num_loaded_edges),
      groups_(work_groups(cl, a.num_loaded_edges)),
      arrays_(a),
      gas_hole_(gas_hole),
      in_situ_(in_situ) {
  std::map<std::string, std::string> defines = tail_defines();
  defines["GROUP_SIZE"] = std::to_string(cl.group_size());
  kernel_ = compute::kernel(cl.build(kernel_source::boundary_loads, defines), "boundary_loads");
  edge_energy_ = plan(count_, cl.group_size()).allocate(cl, "boundary_loads edge_energy");
  upload(cl, edge_energy_, std::vector<real2>(std::max<size_t>(1, count_)));
  KernelArgs args(kernel_);
  args("n_edges", static_cast<cl_uint>(count_))("materials", a.materials)("position", a.position)("velocity", a.velocity)(
      "thickness", static_cast<real>(thickness))("dt", static_cast<real>(dt));
  step_ = args.later("step", cl_int(0));
  time_ = bind_edges(args);
  args.done();
}

KernelArg<real> BoundaryLoads::bind_edges(KernelArgs& args) {
  args("edge_nodes", arrays_.edge_nodes)("edge_load", arrays_.edge_load)("load_table", arrays_.load_table)(
      "pressure_points", arrays_.pressure_points)("edge_ref_position", arrays_.edge_ref_position);
  const KernelArg<real> time = args.later("time", real(0));
  args("edge_force", arrays_.edge_force)("edge_energy", edge_energy_);
  if (gas_hole_) args("gas_hole", *gas_hole_);
  return time;
}

std::map<std::string, std::string> BoundaryLoads::tail_defines() const {
  std::map<std::string, std::string> defines;
  if (in_situ_) defines["IN_SITU_LOADS"] = "1";  // a model without them builds the kernel it always had
  if (gas_hole_) defines["GAS_LOADS"] = "1";
  return defines;
}

void BoundaryLoads::bind_tail(KernelArgs& args) {
  tail_edges_ = args.later("n_edges", static_cast<cl_uint>(0));
  tail_time_ = bind_edges(args);
  fused_ = true;
}

void BoundaryLoads::quiet_tail() {
  if (fused_) tail_edges_.set(0);
}

void BoundaryLoads::enqueue(double time, int step) {
  if (count_ == 0) return;
  if (fused_) {  // TriangleForces launches it (its own step argument is the same step)
    tail_time_.set(static_cast<real>(time));
    tail_edges_.set(static_cast<cl_uint>(count_));
    return;
  }
  time_.set(static_cast<real>(time));
  step_.set(step);
  cl_.enqueue(kernel_, count_);
}

EnergyPart BoundaryLoads::queue_energy(const ItemSums& sums) {
  PendingSums pending = sums(cl_, edge_energy_, count_, 2, 0, 2, ItemKind::LoadedEdge);
  return [pending](EnergyTotals& e) {
    const auto sum = pending();
    e.load_work += sum[0];
    e.absorbed += sum[1];
  };
}

}  // namespace fdem
