// Stage: cohesive-element (CE4) forces (cl_kernels/cohesive_forces.cl).
#pragma once
#include <utility>
#include <vector>

#include "engine/device/checkpoint.hpp"
#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/model/cohesive_model.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/memory_plan.hpp"
#include "engine/model/real.hpp"
#include "engine/model/in_situ.hpp"
#include "engine/stages/fluid_carriers.hpp"
#include "io/events_writer.hpp"

namespace fdem {

class CohesiveForces {
 public:
  // Computes the per-CE4 parameters on the host (h = initial edge length |X_j - X_i| read
  // from ref_position), uploads them, the connectivity and the zeroed state, compiles the
  // stage and binds everything once. Throws InputError for bad properties or a
  // zero-length edge.
  // `in_situ`: per CE4 the gaps that carry the in-situ field (in_situ_ce4_gaps), or empty
  // for none: then the kernel has no such argument and the stage no such array.
  // `ref_position`: the reference positions, one real2 per node as the device holds them
  // (DeviceArrays::reference_positions; the device keeps none without gravity).
  // `velocity`: the nodes' velocities, which moved them by velocity × model.dt in the
  // step before (the work term's displacements: cl_kernels/cohesive_forces.cl); the
  // positions in step 0 must be the reference positions.
  CohesiveForces(ClContext& cl, const CohesiveModel& model, compute::buffer& position, compute::buffer& velocity,
                 const std::vector<real2>& ref_position, const std::vector<InSituGaps>& in_situ = {});
  // The same with the reference positions read from a device array.
  CohesiveForces(ClContext& cl, const CohesiveModel& model, compute::buffer& position, compute::buffer& velocity,
                 compute::buffer& ref_position, const std::vector<InSituGaps>& in_situ = {})
      : CohesiveForces(cl, model, position, velocity,
                       download<real2>(cl, ref_position, ref_position.size() / sizeof(real2)), in_situ) {}
  // The arrays the constructor allocates for `ce4` CE4s (and, with `mesh_nodes` > 0, the
  // bonded fans' state, CohesiveModel::vertex_bonded, and the `nodes` nodes' mesh nodes,
  // CohesiveModel::node_origin; with `in_situ` the initial gaps).
  // `property_sets`: the fracture property sets (CohesiveModel::fracture).
  // `extrinsic`: some CE4's set has fracture.model = "extrinsic" (FractureProperties): the
  // insertion flags, offsets and count (cl_kernels/extrinsic.cl).
  // `excavations`: the number of [[excavation]] entries when some CE4 touches an excavated
  // triangle (CohesiveModel::excavation_of), else 0.
  static MemoryPlan plan(size_t ce4, size_t mesh_nodes = 0, size_t property_sets = 1, bool in_situ = false,
                         bool extrinsic = false, size_t excavations = 0, bool fluid = false, size_t nodes = 0);

  // Forces of every CE4 into its four slots (order i, j, j', i'), state update, breaking
  // test; `time` [s] is recorded for the CE4s that break in this step, `step` for those
  // that are released (a broken CE4 stays closed until its faces open). Never waits.
  void enqueue(double time, long step);
  // CohesiveModel::activate_on_break: the CE4s' triangle pairs (uint2 each,
  // FragmentLabels::ce4_triangles()) and the detection's candidate mask (uint per
  // triangle) that a breaking CE4 writes its triangles' join stamps into. Once, before
  // the first enqueue.
  void join_on_break(const compute::buffer& ce4_triangles, compute::buffer& active);

  compute::buffer& slots() { return slots_; }  // real2 ×4 per CE4 [N]
  // int2 per CE4: (state, mode); state 0 intact, 1 broken and closed, 2 + n broken and
  // released at step n (cl_kernels/cohesive_forces.cl).
  compute::buffer& status() { return status_; }
  // One cl_int: 1 + the last step in which the kernel changed some CE4's status (0: none
  // yet in this process), for the contact stage's sleeping couples.
  compute::buffer& status_step() { return status_step_; }
  // Three reals per Gauss point, three points per CE4: (D_max, o_max, max|s|), the first
  // 1 + χ once D_max is 1 (cohesive_forces.cl).
  compute::buffer& gauss_state() { return gp_state_; }
  // [fluid] (CohesiveModel::fluid_carriers): the CE4s that started to carry fluid, appended
  // by the kernel in the step they start (broke, or softened: fluid_carriers 2), and their
  // count; FluidFlow rebuilds the list from the status whenever it starts or restores.
  // nullptr without [fluid].
  const FluidCarriers* fluid_carriers() const { return carriers_.list.get() ? &carriers_ : nullptr; }
  // int per mesh node (CohesiveModel::vertex_bonded given): -1 fan not bonded, 0 every CE4
  // at it intact, 2 + n one of them broke at step n. Null without it.
  const compute::buffer* mesh_node_state() const { return fans_ ? &mesh_state_ : nullptr; }
  // With bonded fans: cl_uint per node, the mesh node it copies (CohesiveModel::node_origin;
  // the contact stage's corner couples read it too).
  const compute::buffer* node_origin() const { return fans_ ? &node_origin_ : nullptr; }
  size_t size() const { return count_; }
  // Extrinsic CE4s (the Extrinsic stage binds these): int per CE4, 0 while an extrinsic CE4
  // is not inserted (it then carries nothing), 1 once it is and for every intrinsic CE4;
  // real2 per CE4, the law's offsets (o₀, s₀) [m]; one uint, the insertions so far.
  bool extrinsic() const { return extrinsic_; }
  compute::buffer& inserted() { return inserted_; }
  compute::buffer& insertion_gaps() { return insertion_gaps_; }
  compute::buffer& inserted_count_buffer() { return inserted_count_; }
  size_t count_inserted();  // reads the count (waits); 0 without extrinsic CE4s
  std::vector<cl_int> inserted_flags();  // reads the flags (waits); empty without extrinsic CE4s
  compute::buffer& nodes() { return nodes_; }
  compute::buffer& lengths() { return length_; }
  compute::buffer& property() { return property_; }
  compute::buffer& property_rows() { return property_rows_; }
  compute::buffer& friction_slips() { return gp_slip_; }
  compute::buffer& energy() { return energy_; }
  const std::vector<real>& parameters() const { return params_; }  // layout::COH_STRIDE per CE4 (COH_*)

  // Host reads (wait; for output, history and tests). Damage, opening and slip are computed
  // from the state of the last step by cohesive_output into an output array of one column
  // made for the read; the break time is the w of the friction slips.
  std::vector<real> damage();       // max over the Gauss points of D_max
  std::vector<real> opening();      // mean opening o [m]
  std::vector<real> slip();         // mean slip s [m]
  std::vector<int> broken();        // 0/1
  std::vector<int> mode();          // 0 intact, 1 mode I, 2 mode II, 3 mixed
  void flags(std::vector<int>& broken, std::vector<int>& mode);  // both, from one read
  std::vector<real> broken_time();  // [s]; -1 while intact
  size_t count_broken();
  std::vector<real> work();         // work done on each CE4 so far [J]
  std::vector<real> dissipated();   // fracture dissipation of each CE4 so far [J] (cl_kernels/cohesive_forces.cl)
  std::vector<real> stored();       // elastic energy each CE4 holds now [J]
  const compute::buffer& energy_rows() const { return energy_; }  // three reals per CE4: (work, dissipation, stored)
  // [[excavation]] (CohesiveModel::excavation_of given): real2 per CE4, (Π of the last
  // step unscaled, energy carried out by the ramp so far [J]); .y is the account's
  // `excavated` share of the CE4s. excavating() is false without (no such array).
  bool excavating() const { return excavation_; }
  const compute::buffer& excavation_rows() const { return excavation_energy_; }
  std::vector<real> excavated();  // .y per CE4 [J] (waits)

  // Totals over all CE4s [J]: a device pass into a fixed number of partial sums, each over
  // a fixed stride of CE4s, then the partials summed in order on the host, so the totals
  // are reproducible; reads back the partials only (waits).
  // Recoverable elastic energy held by the intact CE4s at the positions of the last step.
  double stored_energy();
  // Energy dissipated by softening, breaking and the friction of the CE4s, cumulative;
  // never decreases. Work done on the CE4s = stored_energy() + fracture_dissipation().
  double fracture_dissipation();
  // Alias of fracture_dissipation() (older callers).
  double dissipated_total();
  // Both in one device pass: (fracture dissipation, stored energy).
  std::pair<double, double> energy_totals();

  // The break catalogue (cl_kernels/cohesive_forces.cl appends a record for each CE4 in
  // the step it breaks): reads the records appended since the last call (the counter and
  // those records only; waits), sorts them by (time, CE4) so the order does not depend
  // on the device's scheduling, adds them to catalogue() and returns them. Each record
  // has the CE4, time, midpoint, initial length, mode and energy; the triangles are
  // left at -1 (the Model has them). Called with the history rows.
  std::vector<io::BreakRecord> drain_breaks();
  // Every record drained so far (including those a checkpoint brought), in order.
  const std::vector<io::BreakRecord>& catalogue() const { return catalogue_; }

  // Every CE4's state (Gauss points, status, friction slips and break times, last forces and
  // gaps, energy), for checkpoints.
  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  std::vector<real> output_column(int k);
  std::vector<real> energy_column(int k);
  ClContext& cl_;
  size_t count_;
  size_t partials_;
  std::vector<real> params_;
  compute::kernel kernel_, partials_kernel_;
  KernelArg<real> time_;
  compute::buffer property_, property_rows_;  // per CE4 its property set; the sets' rows (COHP_*)
  bool fans_ = false;
  bool extrinsic_ = false;
  compute::buffer inserted_, insertion_gaps_, inserted_count_;
  size_t mesh_nodes_ = 0;
  compute::buffer node_origin_, mesh_state_;
  bool excavation_ = false;
  compute::buffer excavation_of_, excavation_time_, excavation_energy_;  // int2, real2 per excavation, real2 per CE4
  compute::buffer in_situ_gaps_;  // real ×6 per CE4 (o₀ at the 3 Gauss points, then s₀), [in_situ] only
  KernelArg<cl_int> step_;
  compute::program program_;  // for cohesive_output, built per output_column read
  size_t output_bytes_ = 0;    // the output array "ce4_output" (one column)
  compute::buffer nodes_, length_, gp_state_, gp_slip_, status_, slots_, status_step_;
  FluidCarriers carriers_;  // [fluid] only
  KernelArg<compute::buffer> join_triangles_, join_active_;  // activate_on_break only
  bool activate_on_break_ = false, joins_bound_ = false;
  compute::buffer energy_, partial_;  // three reals per CE4; real2 per partial
  compute::buffer position_;          // the nodes' positions (bound to the step; cohesive_output reads them)
  // The break log: a uint counter, int2 (CE4, mode) and real4 (time, x, y, energy) per
  // slot, one slot per CE4 (a CE4 breaks once, so it cannot overflow).
  compute::buffer break_count_, break_ids_, break_records_;
  size_t drained_ = 0;                       // log slots already in catalogue_
  std::vector<io::BreakRecord> catalogue_;   // sorted by (time, CE4)
  std::vector<io::BreakRecord> read_log(size_t first, size_t count) const;
};

}  // namespace fdem
