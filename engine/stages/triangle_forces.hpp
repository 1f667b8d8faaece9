// Stage: TRI3 internal forces (cl_kernels/triangle_forces.cl), with the strain energy and
// viscous dissipation of the energy account.
#pragma once
#include <algorithm>
#include <array>
#include <vector>

#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/checkpoint.hpp"
#include "engine/energy/energy.hpp"
#include "engine/stages/boundary_loads.hpp"

namespace fdem {

class FluidFlow;

// [[excavation]] as the stage takes it (cl_kernels/triangle_forces.cl, EXCAVATION): per
// triangle the excavation that removes it (-1: none) and per excavation (start,
// duration) [s]. Empty: no excavation (the kernel has no such arguments).
struct TriangleExcavation {
  std::vector<int> of;
  std::vector<std::array<double, 2>> times;
};

class TriangleForces {
 public:
  // Compiles the stage and binds its arrays once. `viscous`: some material has η > 0
  // (then every step accounts the viscous dissipation).
  // `initial_stress`: per triangle the in-situ reference stress (σxx, σyy, σxy) [Pa]
  // (in_situ_triangle_stress), or empty for none: then the kernel has no such argument
  // and the stage holds no such array.
  // `boundary` (optional, with loaded edges): the boundary loads ride in this stage's
  // launch (BoundaryLoads::bind_tail); its enqueue must come before this stage's in a step.
  // `fluid` (optional, FluidFlow::headed()): the liquid's fused step rides as this launch's
  // first work-group (FluidFlow::bind_step); its enqueue, and the cohesive stage's, whose
  // carriers and status it reads, must come before this stage's in a step.
  TriangleForces(ClContext& cl, DeviceArrays& arrays, double thickness, double dt, bool viscous,
                 const std::vector<std::array<double, 3>>& initial_stress = {},
                 const TriangleExcavation& excavation = {}, BoundaryLoads* boundary = nullptr,
                 FluidFlow* fluid = nullptr);
  // The arrays the constructor allocates (`group_size`: ClContext::group_size();
  // `item_rows`: a split run's rank, which keeps the energy rows' per-triangle values,
  // keep_energy_rows()).
  static MemoryPlan plan(size_t triangles, size_t group_size, bool viscous, bool in_situ = false,
                         size_t excavations = 0, bool item_rows = false);
  // The kernel's work-group size: the device's, at least kOrderedBlock (the energy rows'
  // block sums are taken within a work-group).
  static size_t group_size(size_t device_group) { return std::max(device_group, kOrderedBlock); }
  // One step's corner forces; with energy_row also the strain energy of the current shape
  // for energy(). Never waits.
  void enqueue(int step, bool energy_row = false);
  // The stress of the current state into the arrays' `stress`, which it allocates when
  // it is not (DeviceArrays::output_stress; for output, no energy accounted). Never waits.
  void enqueue_stress(int step);
  // Strain energy at the last energy row and viscous dissipation up to it (waits).
  void add_energy(EnergyTotals& totals, const ItemSums& sums = all_items) { queue_energy(sums)(totals); }
  // The same, added once `sums` have landed; one rank: from the block sums the energy-row
  // step took on the device, read into `reads` (nullptr: at once).
  EnergyPart queue_energy(const ItemSums& sums, RowReads* reads = nullptr);
  // A split run (Solver::set_scope): the per-triangle energies of the rows stay on the
  // device (resident from now on) for energy()'s gather of the owned triangles' values.
  void keep_energy_rows();

  // The energy state, for checkpoints: the last row's sums and, per triangle, the viscous
  // stress of the last step and its dissipation so far.
  void save_state(StateWriter& out) const {
    out.group_slots("triangle_energy", group_energy_, groups_, 2);
    if (viscous_) out.buffer<real>("triangle_viscous_stress", viscous_stress_, count_, 4);
    if (excavation_) out.buffer<real>("triangle_excavation_energy", excavation_energy_, count_, 2);
  }
  void load_state(StateReader& in) {
    in.group_slots("triangle_energy", group_energy_, groups_, 2);
    if (viscous_) in.buffer<real>("triangle_viscous_stress", viscous_stress_, count_, 4);
    if (excavation_) in.buffer<real>("triangle_excavation_energy", excavation_energy_, count_, 2);
  }

 private:
  ClContext& cl_;
  DeviceArrays& arrays_;
  size_t count_, groups_;
  bool viscous_;
  bool excavation_ = false;
  compute::kernel kernel_;
  KernelArg<cl_int> write_stress_, step_, energy_mode_;
  KernelArg<compute::buffer> stress_;  // the output stress, or the placeholder on force steps
  compute::buffer stress_placeholder_;  // one real4: the force steps write no stress
  compute::buffer group_energy_;  // real2 per work-group: (strain energy, viscous dissipation) at the last row
  // real4 per triangle when viscous: A t σ_viscous of the last step (xyz), its viscous dissipation so far (w)
  compute::buffer viscous_stress_;
  // (strain energy, viscous dissipation) at the last energy row: summed per block of
  // kOrderedBlock triangles into energy_partials_ (2 reals a block); per triangle
  // (real2) only after keep_energy_rows (else a one-real2 placeholder is bound).
  compute::buffer triangle_energy_, energy_partials_;
  KernelArg<compute::buffer> triangle_energy_arg_;
  KernelArg<cl_int> item_rows_;
  size_t local_ = 0, triangle_energy_bytes_ = 0;
  bool keep_rows_ = false;
  compute::buffer initial_stress_;   // real4 per triangle (S₀xx, S₀yy, S₀xy, 0), models with [in_situ] only
  // Models with [[excavation]] only: per triangle its excavation (int, -1 none), per
  // excavation (start, duration) (real2), per triangle (W of the last step, strain energy
  // released so far) (real2).
  compute::buffer excavation_of_, excavation_time_, excavation_energy_;
  BoundaryLoads* boundary_ = nullptr;  // fused into this launch (its edges after the triangles' groups)
  // The liquid's step as this launch's first work-group: fluid_head_ 1 on force steps, 0
  // on the output's stress pass (then no such group is launched).
  bool fluid_head_on_ = false;
  KernelArg<cl_uint> fluid_head_;
};

}  // namespace fdem
