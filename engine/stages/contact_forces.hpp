// Stage: contact forces between detected couples (cl_kernels/contact_forces.cl).
#pragma once
#include <algorithm>

#include "engine/device/checkpoint.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/model/model.hpp"
#include "engine/device/row_reads.hpp"
#include "engine/stages/contact_carry.hpp"
#include "engine/stages/monitor_ring.hpp"

namespace fdem {

class ContactForces {
 public:
  // `active`: the detection's candidate mask (cl_uint per triangle; join stamps under
  // "fractured", ContactActivation): a new couple found overlapping because a triangle
  // joined since the last detection waits. Null: every triangle is a candidate from the
  // start and none ever joins.
  // `ce4_status`: the CE4 stage's status words (CohesiveForces::status()), given when the
  // model has CE4s: the two triangles of an intact or closed CE4 are then no contact
  // couple (the CE4 carries them), and a couple whose CE4 was released in the last step
  // waits while it still overlaps, like a join's.
  // `mesh_node_state` (CohesiveForces::mesh_node_state()): likewise two triangles meeting
  // at a corner of a bonded fan while every CE4 at it is intact.
  // `ring`: given (with a contact skin), the history pool starts small and grows from
  // the rows taken that the clear kernel writes to the ring (ensure_pool); without it the
  // pool holds a row for every couple of the list (every list is then a new one, or the
  // caller gives its own lists), so it can never fill.
  // `shared_keys`: the stage keeps no copy of the couple list; it uses the buffer of the
  // last new list's enqueue, which the caller leaves alone until it calls
  // carry_before_detection() and makes the next list (the Solver: the detection's own).
  // `ce4_status_step` (CohesiveForces::status_step(), with `ce4_status`): the step + 1 in
  // which a CE4's status last changed. Given (and without [[excavation]]), the couples a
  // bond carries sleep between such changes: most steps classify only the others
  // (contact_classify's SLEEPERS).
  ContactForces(ClContext& cl, DeviceArrays& arrays, const Model& model, const compute::buffer* active = nullptr,
                const compute::buffer* ce4_status = nullptr, const compute::buffer* mesh_node_state = nullptr,
                const compute::buffer* node_origin = nullptr, MonitorRing* ring = nullptr, bool shared_keys = false,
                const compute::buffer* ce4_status_step = nullptr);

  // The couples the lists hold at first, and the capacity they grow to when a list of
  // `count` couples does not fit: an eighth more (the lists are the largest arrays,
  // about 120 bytes a couple; couples grow slowly once the first detection has run).
  static size_t first_capacity(size_t triangles) { return std::max<size_t>(1024, 4 * triangles); }
  static size_t grown(size_t count) { return count + count / 8 + 1024; }
  // The arrays the constructor allocates (`group_size`: ClContext::group_size();
  // `own_mask`: no candidate mask is given, the stage holds one of all ones).
  static MemoryPlan plan(const Model& model, size_t group_size, bool own_mask, bool monitored = false,
                         bool shared_keys = false);
  // The stage's own copy of the couple list (without shared keys), `capacity` couples.
  static MemoryPlan key_list(size_t capacity);
  // The CE4s on each triangle's edges, 3 per triangle (kNoBond where none).
  static std::vector<cl_uint> bond_ce4(const Model& model);
  static constexpr cl_uint kNoBond = 0xffffffffu;
  // The per-couple arrays at `capacity` couples (the constructor's, and what a list that
  // grows allocates again): pool slots, overlap list, live flags, stored-energy sums.
  // The per-couple arrays of a list of `capacity` couples (`bonds`: the model has CE4s,
  // and the list keeps a bond word per couple, and a list of the couples no bond carries
  // for a quarter of the capacity: sleepers(), below).
  static MemoryPlan couple_arrays(size_t capacity, size_t group_size, bool bonds);
  // Room in the list of couples no bond carries: beyond it every step classifies all.
  static size_t awake_capacity(size_t capacity) { return capacity / 4; }
  // Classifications that visited only the couples no bond carries, so far (0 without
  // sleeping couples). Waits.
  long lean_classifications();
  bool sleepers() const { return sleepers_; }
  // GPUs: contact_forces_lanes takes the lanes for at most this many overlapping couples
  // (one work-item a couple above): 64 a compute unit, 8,448 on a 132-SM H100 or H200,
  // about one and a half waves of the lanes' work-groups (six of 64 items an SM at the
  // kernel's 168 registers). On an H100 the blasting row (up to 8,153 touching) ran 7%
  // faster than with session 11's fixed 4,096, the whole blasting run (tens of thousands
  // touching late) as fast (docs/performance-notes.md, "Session 27").
  static unsigned long lanes_up_to(unsigned compute_units) { return 64ul * std::max(1u, compute_units); }
  // The history pool: `rows` rows of CONTACT_HISTORY reals and one stored energy each. A
  // couple takes a row at its first history write (a touching couple, or one that waits)
  // and keeps it until the next detection, which carries the histories over (ContactCarry)
  // and empties the pool. With a skin (a ring given) the pool starts at pool_first rows
  // and grows to pool_grown(rows seen) when the rows taken come within half the headroom
  // of its end; otherwise it has as many rows as the list has couples.
  static MemoryPlan pool_arrays(size_t rows);
  // Generous on purpose: a pool that fills stops the run (no exact rerun), so the margin
  // (half the headroom, a quarter of the TRI3 count) must cover any burst of new touching
  // couples within the ring's lag: a quarter of all triangles' worth in 7 steps. About
  // 80 B per TRI3; the rows of a full couple list cost about 800.
  static size_t pool_headroom(size_t triangles) {
    return pool_sizing().headroom ? pool_sizing().headroom : std::max<size_t>(1024, triangles / 2);
  }
  static size_t pool_first(size_t triangles) {
    return pool_sizing().first ? pool_sizing().first : std::max<size_t>(2048, triangles / 2);
  }
  // Other first rows and headroom than the defaults above (0: the default), for tests
  // that make the pool grow or fill on small models; plan() follows them.
  struct PoolSizing {
    size_t first = 0, headroom = 0;
  };
  static PoolSizing& pool_sizing() {
    static PoolSizing sizing;
    return sizing;
  }
  static size_t pool_grown(size_t rows, size_t triangles) { return rows + rows / 2 + pool_headroom(triangles); }
  // Before a step (skin only): grows the pool when `rows_seen` (the largest RING_POOL word
  // read since the last detection, ContactSkin::pool_rows_seen) leaves less than the
  // margin: half the headroom, or 2 × MonitorRing::kSlots × `rows_per_step` (the most rows
  // taken in one step of the last batch read, ContactSkin::pool_rows_per_step; 2: room
  // for the rate to double within the ring's lag) when more. It grows to pool_grown(rows_seen) plus
  // that margin; the rows are copied on the device, in order. Never waits.
  void ensure_pool(size_t rows_seen, size_t rows_per_step = 0);
  size_t pool_rows() const { return pool_rows_; }
  // The first step at which a couple found the pool full (its history was lost), or -1.
  // Waits. Solver::conditions() stops the run on it.
  long pool_overflow_step();
  void check_pool();  // NumericalError naming the step when a couple found the pool full (waits)
  // The same in two halves, for a caller that waits once for several reads: enqueues the
  // read of the pool's two state words into `state` (no wait), and, once the queue has
  // passed it, the check of what was read.
  void read_pool_state(cl_uint* state);
  std::function<std::vector<cl_uint>()> queue_pool_state(RowReads& reads);  // the same, into `reads`
  void check_pool(const cl_uint* state);

  // Fixed-point scale: the contact force on a node is contact_acc / force_scale() [N].
  double force_scale() const { return force_scale_; }

  // With shared keys, before the caller overwrites the list: copies the couples that hold
  // a history to the carry list (ContactCarry; waits once), for the next new list.
  // Without, enqueue(new_list) does it itself.
  void carry_before_detection();
  // The start of step `step`: the next enqueue's classification zeroes the contact
  // accumulator and the next overlap-list counter, and with a ring writes the pool's rows
  // taken to the ring slot of `step` (contact_classify; no launch of its own). Never waits.
  void begin_step(long step = 0);
  // Forces of the couples in `keys` (sorted cl_ulong keys, i << 32 | j). With new_list the
  // keys come from a fresh detection and each couple's history is carried over from the
  // previous list by key; otherwise the list is the one of the last call. With
  // energy_row the step also sums the stored energy of all couples (stored_energy()),
  // at the positions and slips this step's forces use; that costs a little in the force
  // kernel, so ask for it on history rows only. Never waits.
  void enqueue(const compute::buffer& keys, size_t count, bool new_list, double dt, bool energy_row = false,
               long step = 0);
  // Makes the next enqueue an energy row whatever its argument says (for callers that
  // do not make the enqueue call themselves, e.g. tests stepping a Solver).
  void request_energy_row() { energy_row_requested_ = true; }

  size_t couples() const { return count_; }
  // The current list extended in place to `count` couples (ContactDetection::extend_joined
  // appended the new ones to the shared keys): the step as enqueue's for the same list,
  // the appended couples starting without history (new, as in a new list). Never waits.
  void enqueue_extended(const compute::buffer& keys, size_t count, double dt, bool energy_row, long step);
  // Couples the list's own arrays hold: an extension past it needs a new detection
  // (0 when the list is not the detection's own, shared keys: then never extended).
  size_t list_capacity() const { return shared_keys_ ? list_capacity_ : 0; }
  // After a checkpoint is loaded: the detection restored the list into its own buffer
  // (shared keys), the stage reads it there again.
  void share_keys(const compute::buffer& keys) { if (shared_keys_) keys_ = keys; }
  size_t touching();             // couples in contact in the last step (waits; counts live flags)
  // Energy account [J] (each waits; 2⁻³² J resolution). stored_energy: the normal
  // penalty potential E = P_n t ∫_{c∩t}(φ_c + φ_t) dA (the normal forces are exactly −∇E)
  // plus the friction springs' ½ k s², summed over the couples at the last energy row (0
  // before the first); for a damped couple (Eq. 15) the work done on it not yet
  // dissipated, at most σ/σ_try × E. friction_dissipation, damping_dissipation:
  // cumulative (never decreasing but for rounding). Kinetic energy + these + the other
  // stages' energies is conserved to the integrator's O(Δt²) (tests/test_contact_energy.cpp).
  double stored_energy();
  double energy_scale() const { return energy_scale_; }
  std::vector<cl_long> energy_account();  // the CONTACT_ENERGY_WORDS fixed-point words (waits)
  // A split run's account (engine/solver.cpp): the keys of the list (i << 32 | j, local
  // triangles), which change only where list_generation() does (a new list, a load_state).
  // Waits.
  std::vector<cl_ulong> list_keys();
  size_t list_generation() const { return list_generation_; }
  // The couples whose stored energy of the last energy row (the values that
  // contact_stored_partials sums: 0 where the `live` flag is not 1) is not 0, by index in
  // the list, and the touching count, from one read of the flags. Waits.
  struct StoredCouples {
    size_t touching = 0;
    std::vector<cl_uint> index;  // ascending
    std::vector<real> value;
  };
  StoredCouples stored_couples();
  double friction_dissipation();
  double damping_dissipation();
  // A history row's contact terms: touching(), stored_energy(), friction_dissipation() and
  // damping_dissipation(), their reads queued into `reads` without waiting. The function
  // gives them (waiting if needed) and leaves touching() and energy_account() known for
  // the rest of the row, as a read of them would.
  struct RowTerms {
    size_t touching = 0;
    double stored = 0, friction = 0, damping = 0;
  };
  std::function<RowTerms()> queue_row(RowReads& reads);
  // friction_dissipation() + damping_dissipation() (one read).
  double dissipated_energy();
  std::vector<real> history();   // per couple, CONTACT_HISTORY reals, from the pool (waits; for tests)
  std::vector<cl_ulong> keys();  // the current couple list (waits; for tests)
  std::vector<real> couple_stored();  // per couple, the stored energy of the last energy row [J] (waits; for tests)

  // The couple list with each couple's history and live flag, and the energy sums (checkpoints).
  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  ClContext& cl_;
  DeviceArrays& arrays_;
  double force_scale_ = 1, energy_scale_ = 1;
  // A history row asks for the touching count and the energy words several times (the
  // account, its resolution, the row's columns); each read waits for the device, about
  // 10 µs on a GPU. They are read once per state: epoch_ counts every change this stage
  // enqueues (or loads), and a read remembers the epoch it saw.
  std::uint64_t epoch_ = 1, touching_epoch_ = 0, energy_epoch_ = 0;
  size_t touching_seen_ = 0;
  std::vector<cl_long> energy_seen_;
  compute::kernel classify_, forces_, release_;
  compute::buffer keys_, history_, energy_, counters_, pair_index_, pair_props_, overlap_list_, live_;
  compute::buffer carry_of_;  // per couple of a new list: its carry-list row (ContactCarry::locate)
  compute::buffer slot_;        // per couple: its pool row (ContactCarry::kNoSlot: none)
  compute::buffer pool_state_;  // rows taken, first step a couple found the pool full
  size_t capacity_ = 0, count_ = 0, list_capacity_ = 0, pool_rows_ = 0, triangles_ = 0;
  bool shared_keys_ = false, monitored_ = false;
  bool lanes_ = false;  // contact_forces_lanes (eight work-items a couple) instead of contact_forces
  bool carry_ready_ = false;  // carry_before_detection() ran for the next new list
  size_t carried_ = 0;        // what it carried
  cl_uint joined_since_last_list() const;
  size_t carry_old_list();
  void allocate_pool(size_t rows, bool keep);  // history_ and couple_stored_ at `rows` rows
  void reset_pool();                            // no row taken (a new list)
  std::vector<cl_uint> slots();                 // per couple of the list (waits)
  ContactCarry carry_;      // the histories a new list carries over (one history array, in place)
  compute::buffer active_;  // the candidate mask (the detection's, or ones_)
  compute::buffer bond_ce4_;  // 3 cl_uint per triangle: the CE4s on its edges (with CE4s only)
  compute::buffer node_origin_;  // cl_uint per node: the mesh node it copies (with bonded fans only; CohesiveForces's)
  // cl_uint per couple of the list (with CE4s only): what carries it instead of contact,
  // the CE4 or the corner's mesh node (contact_forces.cl, couple_bond); written by the
  // classification of a list's first step (bond_words_known_ false until then).
  compute::buffer bond_word_;
  bool bonds_ = false, bond_words_known_ = false;
  // Sleeping couples (see the constructor): the couples no bond carries, their counts
  // (three, rotating: contact_classify), the next launch's slot.
  bool sleepers_ = false;
  compute::buffer awake_, awake_count_;
  cl_uint rotation_ = 0;
  KernelArg<cl_uint> classify_full_forced_, classify_rotation_, classify_awake_capacity_;
  KernelArg<cl_int> classify_step_;
  KernelArg<compute::buffer> classify_awake_;
  bool prelisted_ = false;  // Model::ContactModel::list_ahead (PRELISTED in the kernels)
  size_t extended_from_ = static_cast<size_t>(-1);  // enqueue_extended: the couples before the extension
  KernelArg<compute::buffer> classify_bond_word_;
  KernelArg<cl_uint> classify_bond_words_known_;
  long last_list_step_ = -1;  // the step of the last new list (-1: none yet)
  size_t list_generation_ = 0;  // counts the lists (new ones and loaded ones)
  compute::buffer ones_;      // the candidate mask when none is given: all ones
  // The arguments set at each enqueue, per kernel.
  // The arguments contact_classify and contact_forces both take that change with the
  // couple list: the list and the previous one with its history, the history written, the
  // same-list flag, the overlap list and the live flags. Each kernel declares the first six
  // first, in this order (bind_list).
  struct ListArgs {
    KernelArg<cl_uint> count, previous_count, same_list, new_from;
    KernelArg<compute::buffer> keys, previous_keys, previous_history, history, overlap_list, live;
    void bind_list(KernelArgs& args, const compute::buffer& keys, const compute::buffer& history0,
                   const compute::buffer& history1);
  };
  ListArgs classify_list_, forces_list_;
  KernelArg<compute::buffer> classify_slot_, forces_slot_, stored_live_, stored_slot_;
  KernelArg<compute::buffer> classify_carry_of_, forces_carry_of_;
  KernelArg<cl_uint> forces_pool_capacity_, classify_monitor_slot_;
  // Which of the two counters (contact counters) counts this step's overlap list; flips
  // at each classification, which zeroes the other one for the next.
  cl_uint list_counter_ = 0;
  KernelArg<cl_uint> classify_list_counter_, forces_list_counter_;
  KernelArg<cl_uint> forces_energy_row_, forces_joined_since_;
  KernelArg<cl_int> forces_step_;
  // [[excavation]] (contact_classify drops couples of triangles being excavated).
  bool excavation_ = false;
  compute::buffer excavation_of_, excavation_time_;
  KernelArg<real> classify_excavation_dt_;
  KernelArg<cl_int> classify_excavation_step_;
  KernelArg<compute::buffer> forces_couple_stored_;
  KernelArg<real> forces_dt_;
  KernelArg<cl_uint> release_previous_count_, release_count_;
  KernelArg<compute::buffer> release_previous_keys_, release_previous_history_, release_keys_;
  KernelArg<cl_uint> stored_count_;
  KernelArg<compute::buffer> stored_values_, stored_slots_arg_;
  bool energy_row_requested_ = false;
  // The overlap list, live flags, pool slots and the per-work-group sums of the stored
  // energy at the last energy row, from couple_arrays(list_capacity_).
  void allocate_list(const MemoryPlan& arrays);
  compute::kernel stored_partials_;
  compute::buffer couple_stored_, stored_slots_;
  size_t stored_groups_ = 0;
};

}  // namespace fdem
