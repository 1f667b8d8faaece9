// Stage: central-difference integration with gravity, local damping and prescribed
// velocities (cl_kernels/integrate.cl), and the nodal part of the energy account.
#pragma once
#include <algorithm>
#include <array>
#include <optional>

#include "engine/device/device_arrays.hpp"
#include "engine/device/checkpoint.hpp"
#include "engine/energy/energy.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/stages/contact_skin.hpp"

namespace fdem {

class Integrate {
 public:
  // `prescribed`: some node has a prescribed velocity component (then the reactions'
  // work is accounted every step, as is the local damping's when local_damping > 0);
  // `account` false leaves both out (Solver's switch for measuring the account's cost).
  // With a `skin`, each step also writes the contact skin test of the next step into its
  // ring (MonitorRing slot slot_of(step + 1)), against the skin's position_at_build.
  //
  // With a `gather` the step sums each node's force itself, as NodeGather::enqueue_forces
  // would (the same sum, the same bits; the Solver's step), and writes node_force as
  // before; without one it reads node_force as a gather left it (the stage used alone).
  struct Gather {
    const compute::buffer* ce4_slots = nullptr;  // NodeGather's arguments
    double contact_force_scale = 0;
    const compute::buffer* fluid_slots = nullptr;  // FluidFlow::slots(), through the CE4 map
    const compute::buffer* fluid_nodes = nullptr;  // FluidFlow::loaded_nodes(): where they are read
  };
  Integrate(ClContext& cl, DeviceArrays& arrays, std::array<double, 2> gravity, double local_damping, double dt,
            bool prescribed, bool account = true, ContactSkin* skin = nullptr, std::optional<Gather> gather = std::nullopt);
  // Whether the stage accounts the reactions' and local damping's work every step.
  static bool accounts_work(bool prescribed, double local_damping, bool account) {
    return account && (prescribed || local_damping != 0);
  }
  // The rows of the accumulated work (node_work): without local damping only nodes with a
  // prescribed-motion group (node_group ≠ 0) do work, so each of them gets a row and the
  // device's node_group word carries it (by_group; at most 255 groups and 2²⁴ such nodes);
  // with local damping, or past those limits, every node has its row.
  struct WorkRows {
    bool by_group = false;
    size_t rows = 0;
  };
  static WorkRows work_rows(const std::vector<uint32_t>& node_group, size_t groups, double local_damping);
  // The arrays the constructor allocates (`group_size`: ClContext::group_size();
  // `account_work`: accounts_work(...); `node_rows`: a split run's rank, which keeps the
  // energy rows' per-node values, keep_energy_rows(); `work_rows`: work_rows(...).rows).
  static MemoryPlan plan(size_t nodes, size_t group_size, bool account_work, bool node_rows, size_t work_rows);
  // The kernel's work-group size: the device's, at least kOrderedBlock (the energy rows'
  // block sums are taken within a work-group).
  static size_t group_size(size_t device_group) { return std::max(device_group, kOrderedBlock); }
  // Advances every node from t to time_after = t + Δt. With energy_row, the step also
  // evaluates the kinetic energy and gravity potential at t (positions before the
  // update) for energy(). Never waits.
  void enqueue(double time_after, int step, bool energy_row = false);
  // Whether the step sums the nodes' forces itself (built with a Gather).
  bool gathers() const { return gathers_; }

  // Kinetic energy and gravity potential at the last energy row, and the local damping
  // dissipation and boundary (reaction) work from t = 0 up to it (waits).
  // One rank: from the block sums the energy-row step took on the device (`sums` unused);
  // after keep_energy_rows() `sums` of the per-node energies.
  void add_energy(EnergyTotals& totals, const ItemSums& sums = all_items) { queue_energy(sums)(totals); }
  // The same, its reads queued: into `reads` without waiting (nullptr: read at once).
  EnergyPart queue_energy(const ItemSums& sums, RowReads* reads = nullptr);
  // A split run (Solver::set_scope): the per-node energies of the rows stay on the device
  // (resident from now on) for energy()'s gather of the owned nodes' values.
  void keep_energy_rows();

  // The cumulative energy sums, for checkpoints.
  // The work totals are saved per node whatever their rows (the same file either way).
  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  ClContext& cl_;
  size_t count_, groups_;
  bool account_work_, skin_test_, gathers_ = false;
  compute::kernel kernel_;
  KernelArg<real> time_after_;
  KernelArg<cl_int> step_, energy_row_;
  KernelArg<cl_uint> slot_, next_slot_;
  compute::buffer group_work_, group_row_;  // real2, real4 per work-group (the last energy row's sums)
  compute::buffer node_work_;  // real2 per work row when accounted: (local damping work, reaction work) so far
  WorkRows work_rows_;
  std::vector<cl_uint> row_node_;  // by_group: the node of each work row
  // Energy rows: the kernel sums the nodes' (kinetic, gravity, damping, reaction work)
  // into partials_ (4 reals per kOrderedBlock nodes, in node order); a split run also keeps
  // them per node in node_energy_ (real4 per node, after keep_energy_rows; else a
  // one-real4 placeholder is bound).
  compute::buffer node_energy_, placeholder_, partials_;
  KernelArg<compute::buffer> node_energy_arg_;
  KernelArg<cl_int> node_rows_;
  bool needs_reference_ = false, has_reference_ = false;  // gravity; ref_position on the device
  size_t node_energy_bytes_ = 0, local_ = 0;
  bool keep_rows_ = false;
};

}  // namespace fdem
