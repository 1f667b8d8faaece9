#include "engine/stages/triangle_forces.hpp"

#include "engine/stages/fluid_flow.hpp"

#include <functional>
#include <map>
#include <string>

#include "base/errors.hpp"

#include "engine/device/kernel_args.hpp"
#include <vector>

namespace fdem {

MemoryPlan TriangleForces::plan(size_t triangles, size_t group_size, bool viscous, bool in_situ,
                                size_t excavations, bool item_rows) {
  MemoryPlan p;
  if (excavations > 0) {
    p.add("triangle excavation_of", std::max<size_t>(1, triangles) * sizeof(cl_int));
    p.add("triangle excavation_time", excavations * sizeof(real2));
    p.add("triangle excavation_energy", std::max<size_t>(1, triangles) * sizeof(real2));
  }
  // The in-situ reference stress S₀ per triangle, only in models with [in_situ].
  if (in_situ) p.add("triangle initial_stress", std::max<size_t>(1, triangles) * sizeof(real4));
  p.add("triangle group_energy", std::max<size_t>(1, groups_for(triangles, TriangleForces::group_size(group_size))) * sizeof(real2));
  // A t σ_viscous of the last step per triangle, for the trapezoid rule of its work.
  p.add("triangle viscous_stress", (viscous ? std::max<size_t>(1, triangles) : 1) * sizeof(real4));
  // (strain energy, viscous dissipation so far) at the last energy row: per block of
  // kOrderedBlock triangles, and per triangle only in a split run (keep_energy_rows).
  p.add("triangle energy partials", 2 * std::max<size_t>(1, groups_for(triangles, kOrderedBlock)) * sizeof(real));
  if (item_rows) p.add("triangle energy", std::max<size_t>(1, triangles) * sizeof(real2));
  p.add("triangle energy placeholder", sizeof(real2));
  // Bound as `stress` on the force steps, which write none (the output stress is
  // allocated for output steps only: DeviceArrays::output_stress).
  p.add("triangle stress placeholder", sizeof(real4));
  return p;
}

TriangleForces::TriangleForces(ClContext& cl, DeviceArrays& a, double thickness, double dt, bool viscous,
                               const std::vector<std::array<double, 3>>& initial_stress,
                               const TriangleExcavation& excavation, BoundaryLoads* boundary, FluidFlow* fluid)
    : cl_(cl),
      arrays_(a),
      count_(a.num_triangles),
      groups_(groups_for(a.num_triangles, group_size(cl.group_size()))),
      viscous_(viscous),
      excavation_(!excavation.of.empty()) {
  if (excavation_ && excavation.of.size() != count_)
    throw InputError("triangle forces: " + std::to_string(excavation.of.size()) + " excavation indices for " +
                     std::to_string(count_) + " triangles");
  const bool in_situ = !initial_stress.empty();
  if (in_situ && initial_stress.size() != count_)
    throw InputError("triangle forces: " + std::to_string(initial_stress.size()) + " in-situ stresses for " +
                     std::to_string(count_) + " triangles");
  local_ = group_size(cl.group_size());
  std::map<std::string, std::string> defines{{"GROUP_SIZE", std::to_string(local_)},
                                             {"ORDERED_BLOCK", std::to_string(kOrderedBlock)}};
  if (in_situ) defines["IN_SITU_STRESS"] = "1";
  if (a.young_count > 0) defines["HETEROGENEOUS_YOUNG"] = "1";
  if (excavation_) defines["EXCAVATION"] = "1";
  // NVIDIA: 96 registers a work-item fit two work-groups of 256 per SM, 80 three. H200,
  // 1.08M TRI3: 0.082 → 0.079 ms a step (64: 0.104, with spills; docs/performance-notes.md).
  std::vector<const KernelSource*> libraries;
  if (excavation_) libraries.push_back(&kernel_source::excavation);
  if (boundary && boundary->count() > 0) {
    boundary_ = boundary;
    defines["BOUNDARY_TAIL"] = "1";
    for (const auto& [name, value] : boundary->tail_defines()) defines[name] = value;
    libraries.push_back(&kernel_source::boundary_loads);
  }
  if (fluid && fluid->headed()) {
    fluid_head_on_ = true;
    for (const auto& [name, value] : fluid->head_defines()) defines[name] = value;
    libraries.push_back(&kernel_source::fluid_laws);
    libraries.push_back(&kernel_source::fluid_flow);
  }
  kernel_ = compute::kernel(cl.build(kernel_source::triangle_forces, defines, libraries, 80), "triangle_forces");
  const MemoryPlan arrays = plan(count_, cl.group_size(), viscous_, in_situ, excavation.times.size(), true);
  group_energy_ = arrays.allocate(cl, "triangle group_energy");
  upload(cl, group_energy_, std::vector<real2>(std::max<size_t>(1, groups_)));
  viscous_stress_ = arrays.allocate(cl, "triangle viscous_stress");
  upload(cl, viscous_stress_, std::vector<real4>(viscous_ ? std::max<size_t>(1, count_) : 1));
  triangle_energy_bytes_ = arrays.bytes("triangle energy");  // allocated by keep_energy_rows only
  triangle_energy_ = arrays.allocate(cl, "triangle energy placeholder");
  upload(cl, triangle_energy_, std::vector<real2>(1));
  energy_partials_ = arrays.allocate(cl, "triangle energy partials");
  // Written on energy rows only: zero until the first, so a total read before it is 0
  // (uninitialised device memory gave a viscous total of -4e252 J in the energy suite).
  upload(cl, energy_partials_, std::vector<real>(energy_partials_.size() / sizeof(real)));
  stress_placeholder_ = arrays.allocate(cl, "triangle stress placeholder");
  KernelArgs args(kernel_);
  args("n_triangles", static_cast<cl_uint>(count_))("tri_nodes", a.tri_nodes)("ref_inverse", a.ref_inverse)(
      "tri_material", a.tri_material)("materials", a.materials)("position", a.position)("velocity", a.velocity)(
      "thickness", static_cast<real>(thickness));
  write_stress_ = args.later("write_stress", cl_int(0));
  step_ = args.later("step", cl_int(0));
  args("corner_force", a.corner_force);
  stress_ = args.later("stress", stress_placeholder_);
  args("conditions", a.conditions);
  energy_mode_ = args.later("energy_mode", cl_int(0));
  args("dt", static_cast<real>(dt))("group_energy", group_energy_)("viscous_stress", viscous_stress_);
  item_rows_ = args.later("item_rows", cl_int(0));
  triangle_energy_arg_ = args.later("triangle_energy", triangle_energy_);
  args("energy_partials", energy_partials_);
  if (in_situ) {
    std::vector<real4> s0(std::max<size_t>(1, count_));
    for (size_t t = 0; t < count_; ++t)
      s0[t] = real4{real(initial_stress[t][0]), real(initial_stress[t][1]), real(initial_stress[t][2]), 0};
    initial_stress_ = arrays.allocate(cl, "triangle initial_stress");
    upload(cl, initial_stress_, s0);
    args("initial_stress", initial_stress_);
  }
  if (a.young_count > 0)
    args("young_factor", a.young_factor)("young_first", static_cast<cl_uint>(a.young_first))(
        "young_count", static_cast<cl_uint>(a.young_count));
  if (excavation_) {
    excavation_of_ = arrays.allocate(cl, "triangle excavation_of");
    std::vector<cl_int> of(excavation.of.begin(), excavation.of.end());
    upload(cl, excavation_of_, of);
    excavation_time_ = arrays.allocate(cl, "triangle excavation_time");
    std::vector<real2> times;
    for (const auto& e : excavation.times) times.push_back(real2{real(e[0]), real(e[1])});
    upload(cl, excavation_time_, times);
    excavation_energy_ = arrays.allocate(cl, "triangle excavation_energy");
    upload(cl, excavation_energy_, std::vector<real2>(count_));
    args("excavation_of", excavation_of_)("excavation_time", excavation_time_)("excavation_energy",
                                                                                excavation_energy_);
  }
  if (boundary_) {
    args("triangle_groups", static_cast<cl_uint>(groups_));
    boundary_->bind_tail(args);
  }
  if (fluid_head_on_) {
    fluid_head_ = args.later("fluid_head", cl_uint(1));
    fluid->bind_step(args);
  }
  args.done();
}

void TriangleForces::enqueue(int step, bool energy_row) {
  write_stress_.set(0);
  stress_.set(stress_placeholder_);
  step_.set(step);
  energy_mode_.set((viscous_ ? 1 : 0) | (energy_row ? 2 : 0));
  // With the liquid's step: its work-group first. With the boundary loads fused: the
  // triangles' groups, then one item a loaded edge.
  const size_t head = fluid_head_on_ ? local_ : 0;
  if (fluid_head_on_) fluid_head_.set(1);
  cl_.enqueue(kernel_, head + (boundary_ ? groups_ * local_ + boundary_->count() : count_), local_);
}

void TriangleForces::keep_energy_rows() {
  if (keep_rows_) return;
  keep_rows_ = true;
  triangle_energy_ = cl_.allocate(triangle_energy_bytes_, "triangle energy");
  upload(cl_, triangle_energy_, std::vector<real2>(std::max<size_t>(1, count_)));  // zero until the first row
  triangle_energy_arg_.set(triangle_energy_);
  item_rows_.set(1);
}

void TriangleForces::enqueue_stress(int step) {
  write_stress_.set(1);
  stress_.set(arrays_.output_stress(cl_));
  step_.set(step);
  energy_mode_.set(0);
  if (boundary_) boundary_->quiet_tail();  // the output's pass: no loads (the groups past the triangles' are not launched)
  if (fluid_head_on_) fluid_head_.set(0);  // nor the liquid's step
  cl_.enqueue(kernel_, count_, local_);
}

EnergyPart TriangleForces::queue_energy(const ItemSums& sums, RowReads* reads) {
  PendingSums pending;
  if (keep_rows_) {
    pending = sums(cl_, triangle_energy_, count_, 2, 0, 2, ItemKind::Triangle);
  } else {
    // The blocks' sums of the last energy row, added in block order (as OrderedSums does).
    const size_t blocks = groups_for(count_, kOrderedBlock);
    const size_t words = 2 * std::max<size_t>(1, blocks);
    std::function<std::vector<real>()> partial;
    if (reads) {
      partial = reads->read<real>(energy_partials_, words);
    } else {
      auto now = download<real>(cl_, energy_partials_, words);
      partial = [now] { return now; };
    }
    pending = [partial, blocks] {
      const auto values = partial();
      std::vector<double> sum(2, 0.0);
      for (size_t b = 0; b < blocks; ++b)
        for (int c = 0; c < 2; ++c) sum[c] += static_cast<double>(values[2 * b + c]);
      return sum;
    };
  }
  if (!excavation_)
    return [pending](EnergyTotals& e) {
      const auto sum = pending();
      e.strain += sum[0];
      e.viscous += sum[1];
    };
  PendingSums released = sums(cl_, excavation_energy_, count_, 2, 1, 1, ItemKind::Triangle);
  return [pending, released](EnergyTotals& e) {
    const auto sum = pending();
    e.strain += sum[0];
    e.viscous += sum[1];
    e.excavated += released()[0];
  };
}

}  // namespace fdem
