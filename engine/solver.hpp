// The solver: the model's arrays on the device and the step as a plain list of stages.
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include "engine/device/checkpoint.hpp"
#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/energy/energy.hpp"
#include "engine/model/model.hpp"
#include "engine/stages/boundary_loads.hpp"
#include "engine/stages/cohesive_forces.hpp"
#include "engine/stages/extrinsic.hpp"
#include "engine/stages/contact_activation.hpp"
#include "engine/stages/contact_detection.hpp"
#include "engine/stages/contact_forces.hpp"
#include "engine/stages/contact_skin.hpp"
#include "engine/stages/fluid_flow.hpp"
#include "engine/stages/fragment_labels.hpp"
#include "engine/stages/integrate.hpp"
#include "engine/stages/lumped_mass.hpp"
#include "engine/stages/monitor_ring.hpp"
#include "engine/stages/node_gather.hpp"
#include "engine/stages/triangle_forces.hpp"

namespace fdem {

// First offender of each kind found by the kernels since the start (-1: none).
struct Conditions {
  int bad_node = -1, bad_node_step = -1;
  int inverted_triangle = -1, inverted_step = -1;
  bool ok() const { return bad_node < 0 && inverted_triangle < 0; }
};

class Solver {
 public:
  // Uploads the model, compiles every stage and computes the lumped masses.
  // `account` false leaves out the per-step energy sums that only the account needs (the
  // reactions' and local damping's work, the viscous work): for `fdem bench` to measure
  // what the account costs. Runs always keep it.
  // Throws DeviceError ("too little device memory …") when plan(...).total() exceeds
  // the device's memory, before allocating anything.
  Solver(ClContext& cl, const Model& model, double dt, bool account = true);

  // The parts of the step that `model` has (the conditions under which the constructor
  // builds each stage; written only here).
  struct Parts {
    bool ce4 = false;         // CohesiveForces
    bool contact = false;     // MonitorRing, ContactDetection, ContactForces
    bool skin = false;        // ContactSkin (contact with rebuild = "skin")
    bool activation = false;  // ContactActivation (contact, activation "fractured", CE4s)
    // The activation done by the CE4 stage where a CE4 breaks (CohesiveModel::
    // activate_on_break): activation with couples listed ahead of joins, on one rank, unless
    // FDEM_ACTIVATE_ON_BREAK=0. ContactActivation then runs only in the first step and the
    // first after a restore (for CE4s that start broken or broke before the checkpoint).
    bool activation_on_break = false;
    bool viscous = false;     // TriangleForces accounts viscous work (account on, a viscous material)
    bool prescribed = false;  // some node has a prescribed velocity (a BC group besides 0)
    bool account_work = false;  // Integrate accounts reactions' and damping work
    bool fluid = false;         // FluidFlow ([fluid], with CE4s)
    bool extrinsic = false;     // Extrinsic (some CE4 has fracture.model = "extrinsic")
  };
  static Parts parts(const Model& model, bool account = true);
  // The contact detection of `model` as the Solver builds it (null unless `wanted`): under
  // activation "fractured" with the candidate mask and the CE4 couples (fdem check uses it).
  static std::unique_ptr<ContactDetection> build_detection(bool wanted, ClContext& cl, DeviceArrays& arrays,
                                                           const Model& model);
  // Every device array the Solver of `model` allocates: DeviceArrays' and each built
  // stage's plan and the set-up LumpedMass's (the Solver's checkpoint copies are on the
  // host; `group_size`: ClContext::group_size() of the device it will run on).
  // ClContext::device_bytes_in_use() rises by plan(...).resident() when the Solver is built.
  static MemoryPlan plan(const Model& model, size_t group_size, bool account = true);
  // Device memory the run needs, in bytes: plan(...).total() (resident arrays, contact
  // lists at their first capacity, plus the largest transient array), plus what the
  // contact lists grow by when the couples a run meets (expected_couples) outgrow their
  // first capacity, and the contact history pool at expected_touching couples. The
  // too-little-memory refusal uses it.
  static size_t bytes_needed(const Model& model, size_t group_size, bool account = true);
  // The couples a contact run typically holds: 7 per candidate triangle (5.9 measured on
  // fdem bench's models with activation "all" and 6.1 on the blasting case at 400 µs,
  // since a detection drops couples further apart than the skin; 7 before that), plus
  // one per CE4 (its two triangles are a couple from the start) under "fractured". 0
  // without contact.
  static size_t expected_couples(const Model& model);
  // The couples that hold a contact history (touching, or waiting) at a time, for the
  // history pool's plan: expected_couples / 32 (0.22 per TRI3 with activation "all";
  // fdem bench's 60k model: 0.21 after 320 steps).
  static size_t expected_touching(const Model& model);

  // Enqueues one step (t → t + Δt). Never waits, but for the very first step, whose
  // energy account (read once) starts the balance. With `energy_row` the step also
  // evaluates the stored energies at t (the positions its forces use) for energy().
  void step(bool energy_row = false);
  // step() in its three parts, for a test that steps emulated ranks in one process and
  // exchanges their ghosts between the parts (what the extrinsic hooks do in a split
  // run): the forces and the integration; the extrinsic tie; the insertions and the rest.
  // step(r) is step_forces(r), the first hook, step_tie(), the second, step_finish().
  void step_forces(bool energy_row = false);
  void step_tie();
  void step_finish();
  // The energy account at the time of the last energy row (waits): stored terms at that
  // time, dissipated and supplied terms from t = 0 up to it.
  EnergyTotals energy();
  // The same with its reads queued into row_reads() (one rank; a split run reads at once,
  // its sums being collective): the function gives the account, waiting once for every
  // read queued since row_reads().begin() if they have not landed.
  std::function<EnergyTotals()> queue_energy();
  // A history row's reads (RowReads): queue_energy, queue_conditions, queue_positions and
  // queue_forces put theirs here, and the first value asked for lands them all.
  RowReads& row_reads() { return row_reads_; }
  // Time of the last energy row [s] (one step before time() when the row was the last step).
  double energy_time() const { return energy_row_step_ * dt_; }
  EnergyBalance& balance() { return balance_; }
  // Enqueues a stress evaluation of the current state (for output), into a stress array
  // allocated for it when there is none (DeviceArrays::output_stress). Never waits.
  void enqueue_stress();
  // Gives back the output-only arrays (the stress) once a step's output has read them;
  // the next enqueue_stress() allocates them again (MemoryPlan::Lifetime::Output).
  void release_output() { arrays_.release_output(); }

  long steps_done() const { return steps_; }
  double time() const { return steps_ * dt_; }
  double dt() const { return dt_; }

  // Read-backs: these wait for the queue.
  std::vector<real2> positions();
  std::vector<real2> velocities();
  std::vector<real2> forces();   // out-of-balance force of the last step (incl. gravity)
  std::vector<real2> masses();   // (lumped mass, inertia)
  std::vector<real4> stresses(); // as of the last enqueue_stress() (none since release_output: DeviceError)
  Conditions conditions();
  // conditions(), positions() and forces() with their reads queued into row_reads().
  std::function<Conditions()> queue_conditions();
  std::function<std::vector<real2>()> queue_positions();
  std::function<std::vector<real2>()> queue_forces();

  // A host copy of positions and velocities (read back, waits), taken at a check that
  // passed, so a failed run can still write its last good frame.
  void save_checkpoint();
  bool has_checkpoint() const { return checkpoint_step_ >= 0; }
  long checkpoint_step() const { return checkpoint_step_; }
  // Puts the checkpoint back into the live arrays (the run is over; for output only).
  void restore_checkpoint();

  // Contact (all zero / empty when the case has no [contact]).
  bool has_contact() const { return contact_ != nullptr; }
  // In a split run the whole model's counts as of the last energy() (every rank's list).
  size_t contact_candidates() const { return scope_ ? split_candidates_ : contact_ ? contact_->couples() : 0; }
  size_t contact_touching() { return scope_ ? split_touching_ : contact_ ? contact_->touching() : 0; }
  size_t contact_pool_rows() const { return contact_ ? contact_->pool_rows() : 0; }  // ContactForces::pool_rows
  double contact_dissipated() { return contact_ ? contact_->dissipated_energy() : 0.0; }
  std::vector<real2> contact_forces();  // per node [N] (waits)
  long contact_rebuilds() const { return rebuilds_; }
  ContactDetection* detection() { return detection_.get(); }
  // Host-clock milliseconds of one contact detection of the current positions, as a step
  // runs it (boxes, grid, counts, one count read, keys written), the mean of `repeats`
  // back to back after the queue drained. The lists they write replace the contact
  // stage's, so the solver must not step again: for `fdem bench`, after a row's last step.
  double time_detections(int repeats);
  CohesiveForces* cohesive() { return cohesive_.get(); }
  FluidFlow* fluid() { return fluid_.get(); }
  // The pieces of the body now (models with CE4s; empty otherwise): per triangle, the
  // smallest triangle index of its piece (FragmentLabels). Waits. The pieces depend only
  // on which CE4s are broken, and CE4s never heal, so the labels are kept and reused at
  // the same step, or when the caller passes `broken`, the number of broken CE4s now
  // (it has read them anyway), and it equals the number at the last labelling.
  const std::vector<int>& fragment_labels(long broken = -1);
  FragmentLabels* fragments() { return fragments_.get(); }
  ContactForces* contact() { return contact_.get(); }

  // The whole state a run continues from (checkpoints): positions, velocities, every
  // stage's history and energy sums, the step counter. save_state waits for the queue.
  void save_state(StateWriter& out);
  // Replaces the state by a saved one (same model; InputError when a piece does not fit).
  void load_state(StateReader& in);

  // A split run (engine/run/split_run.*): which items this rank accounts for in energy(),
  // which is then collective (every rank calls it at the same step). Null: all items.
  // Set before the first step; collective when not null (the block lists of SplitSums).
  void set_scope(const ItemScope* scope);
  // A split run with contact (engine/run/split_run.*): `before_detection` runs on the host
  // just before each contact detection (collective: the decision is the same on every
  // rank); the exchange of the fixed-point contact forces that one rank's couples put on
  // nodes another owns: `contact_sent` right after the contact stage is enqueued (it must
  // not wait), `contact_received` after the other force stages and before the node gather
  // reads them, so that the messages overlap those stages on the device. Set before the
  // first step.
  void set_split_hooks(std::function<void()> before_detection, std::function<void()> contact_sent,
                       std::function<void()> contact_received) {
    before_detection_ = std::move(before_detection);
    contact_sent_ = std::move(contact_sent);
    contact_received_ = std::move(contact_received);
  }
  // A split run with extrinsic CE4s (engine/run/split_run.*): the ghost exchanges inside
  // the step, `after_integration` before the tie (a rank ties every mesh node it owns a
  // copy of, so it needs every copy's integrated state) and `after_tie` before the
  // insertions (which read the tied positions of ghost CE4s' nodes too). Collective; set
  // before the first step. Not set: nothing is exchanged inside the step.
  void set_extrinsic_hooks(std::function<void()> after_integration, std::function<void()> after_tie) {
    after_integration_ = std::move(after_integration);
    after_tie_ = std::move(after_tie);
  }
  bool has_extrinsic_stage() const { return extrinsic_ != nullptr; }
  ContactSkin* skin() { return skin_.get(); }
  // The round-off floor of the strain energy (EnergyTotals::resolution) of `model`; a
  // split run sets the whole model's (its local model would give its own share).
  static double strain_round_off(const Model& model);
  void set_strain_round_off(double value) { strain_round_off_ = value; }

  ClContext& context() { return cl_; }
  DeviceArrays& arrays() { return arrays_; }

 private:
  // The parts of `model`, after checking that its arrays fit on the device.
  static Parts fitting_parts(const ClContext& cl, const Model& model, bool account);

  ClContext& cl_;
  double dt_;
  long steps_ = 0;
  const Parts parts_;
  DeviceArrays arrays_;
  // The stages, each built once from what the model has, in this order: a stage is
  // handed the ones built before it that it reads or writes (engine/solver.cpp).
  std::unique_ptr<CohesiveForces> cohesive_;     // the model has CE4s
  std::unique_ptr<FragmentLabels> fragments_;    // the model has CE4s (not in the step)
  std::vector<int> labels_;
  long labels_step_ = -1, labels_broken_ = -1;
  std::unique_ptr<MonitorRing> ring_;            // contact: the skin test's and the joins' ring
  std::unique_ptr<ContactDetection> detection_;  // contact
  std::unique_ptr<ContactSkin> skin_;            // contact with rebuild = "skin"
  std::unique_ptr<ContactActivation> activation_;  // contact with activation "fractured" and CE4s
  std::unique_ptr<ContactForces> contact_;       // contact
  std::unique_ptr<FluidFlow> fluid_;             // [fluid]
  BoundaryLoads boundary_loads_;    // launched by triangle_forces_ (fused) unless FDEM_BOUNDARY_FUSED=0
  TriangleForces triangle_forces_;
  NodeGather gather_;
  Integrate integrate_;
  std::unique_ptr<Extrinsic> extrinsic_;  // extrinsic CE4s: ties and insertions after the integration
  OrderedSums ordered_;  // the energy account's sums in item order (engine/energy/energy.hpp)
  RowReads row_reads_;
  size_t ce4_count_ = 0;
  long rebuilds_ = 0;
  // List extensions by joins (2026-12 until couples were listed ahead of joins): kept as
  // the checkpoint's "contact_extensions" word, 0 in new runs.
  long extensions_ = 0;
  bool list_ahead_ = false;      // Model's contact.list_ahead: joins never need a new list
  long activation_catch_up_ = 0;  // with Parts::activation_on_break: the step ContactActivation runs in
  bool detect_after_load_ = false;  // a checkpoint from before list_ahead: detect at the next step
  long energy_row_step_ = 0;
  double strain_round_off_ = 0;  // Σ ½ C (4 ε |x|max / h)² A t over the triangles [J]
  double contact_round_off_ = 0;  // P_n t ε |x|_max × 3 × longest edge [J] (EnergyTotals::resolution)
  EnergyBalance balance_;
  const ItemScope* scope_ = nullptr;
  std::unique_ptr<SplitSums> split_sums_;  // with scope_
  // With scope_ and contact: the list's keys in global triangles (sorted), read once per
  // list (ContactForces::list_generation), for the couples' global positions.
  std::vector<cl_ulong> split_keys_;
  size_t split_keys_generation_ = ~size_t(0);  // none read yet
  std::function<void()> before_detection_, contact_sent_, contact_received_;
  std::function<void()> after_integration_, after_tie_;
  size_t split_touching_ = 0, split_candidates_ = 0;
  // A split run: the contact terms of energy() over every rank (collective).
  void add_split_contact_energy(EnergyTotals& e);
  std::vector<real2> saved_position_, saved_velocity_;  // the checkpoint, on the host
  long checkpoint_step_ = -1;
};

}  // namespace fdem
