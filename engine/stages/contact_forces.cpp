#include "engine/stages/contact_forces.hpp"

#include "engine/stages/contact_activation.hpp"

#include "engine/energy/energy.hpp"
#include "base/errors.hpp"
#include "engine/device/kernel_args.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>

namespace fdem {

namespace {
constexpr int kHistory = layout::CONTACT_HISTORY;

std::string pool_overflow_message(long step) {
  return "step " + std::to_string(step) +
         ": the contact history pool was full (more couples started to touch within 8 steps than its headroom "
         "holds), so some couples lost their history; please report this case. [contact] rebuild = \"step\" "
         "keeps a row for every couple and cannot fill";
}
}

MemoryPlan ContactForces::key_list(size_t capacity) {
  return MemoryPlan().add("contact_keys", capacity * sizeof(cl_ulong));
}

MemoryPlan ContactForces::couple_arrays(size_t capacity, size_t group_size, bool bonds) {
  return MemoryPlan()
      .add("contact history slots", capacity * sizeof(cl_uint))
      .add("contact carry rows", capacity * sizeof(cl_uint))
      .add(bonds ? MemoryPlan()
                       .add("contact bond words", capacity * sizeof(cl_uint))
                       .add("contact awake couples", std::max<size_t>(1, awake_capacity(capacity)) * sizeof(cl_uint))
                 : MemoryPlan())
      .add("contact overlap list", capacity * sizeof(cl_uint))
      .add("contact live flags", capacity * sizeof(cl_uchar))
      .add("contact stored slots", std::max<size_t>(1, groups_for(capacity, group_size)) * sizeof(real));
}

MemoryPlan ContactForces::pool_arrays(size_t rows) {
  return MemoryPlan()
      .add("contact_history", std::max<size_t>(1, rows) * kHistory * sizeof(real))
      .add("contact couple_stored", std::max<size_t>(1, rows) * sizeof(real));
}

MemoryPlan ContactForces::plan(const Model& model, size_t group_size, bool own_mask, bool monitored,
                               bool shared_keys) {
  MemoryPlan p;
  const size_t first = first_capacity(model.num_triangles());
  // Friction dissipated, damping dissipated (ENERGY_FRICTION, ENERGY_DAMPING).
  p.add("contact energy account", layout::CONTACT_ENERGY_WORDS * sizeof(cl_long))
      .add("contact counters (overlap list, two alternating)", 2 * sizeof(cl_uint))
      .add("contact pool state", 2 * sizeof(cl_uint))
      .add("contact awake counts", 4 * sizeof(cl_uint))
      .add(couple_arrays(first, group_size, !model.ce4_triangles.empty()))
      .add(shared_keys ? MemoryPlan() : key_list(first))
      .add(pool_arrays(monitored ? pool_first(model.num_triangles()) : first))
      .add(ContactCarry::plan(model.num_triangles(), first_capacity(model.num_triangles()), group_size))
      .add("contact_pair_index", model.contact.pair_index.size() * sizeof(cl_uint))
      .add("contact_pair_props", model.contact.pair_props.size() * sizeof(real));
  if (own_mask)
    p.add("contact candidate mask (all)", std::max<size_t>(1, model.num_triangles()) * sizeof(cl_uint));
  if (!model.ce4_triangles.empty()) p.add("contact bond CE4s", 3 * model.num_triangles() * sizeof(cl_uint));
  // [[excavation]]: per triangle its excavation, per excavation (start, duration).
  if (!model.triangle_excavation.empty())
    p.add("contact excavation_of", std::max<size_t>(1, model.num_triangles()) * sizeof(cl_int))
        .add("contact excavation_time", model.excavations.size() * sizeof(real2));
  return p;
}

std::vector<cl_uint> ContactForces::bond_ce4(const Model& model) {
  std::vector<cl_uint> bonds(3 * model.num_triangles(), kNoBond);
  for (size_t e = 0; e < model.ce4_triangles.size(); ++e)
    for (const int t : model.ce4_triangles[e]) {
      cl_uint* slot = &bonds[3 * size_t(t)];
      int k = 0;
      while (k < 3 && slot[k] != kNoBond) ++k;
      if (k == 3) throw InputError("triangle " + std::to_string(t) + " has more than three CE4s on its edges");
      slot[k] = static_cast<cl_uint>(e);
    }
  return bonds;
}

ContactForces::ContactForces(ClContext& cl, DeviceArrays& a, const Model& model, const compute::buffer* active,
                             const compute::buffer* ce4_status, const compute::buffer* mesh_node_state,
                             const compute::buffer* node_origin, MonitorRing* ring, bool shared_keys,
                             const compute::buffer* ce4_status_step)
    : cl_(cl),
      arrays_(a),
      triangles_(a.num_triangles),
      shared_keys_(shared_keys),
      monitored_(ring != nullptr),
      carry_(cl, a.num_triangles, first_capacity(a.num_triangles)) {
  const bool bonds = ce4_status != nullptr && !model.ce4_triangles.empty();
  const bool fans = bonds && mesh_node_state != nullptr && node_origin != nullptr &&
                    model.node_origin.size() == model.num_nodes();
  bonds_ = bonds;
  prelisted_ = model.contact.list_ahead && active != nullptr;
  // A bond word holds a CE4 index, or a mesh node's with the top bit set (contact_forces.cl).
  if (bonds && (model.ce4_triangles.size() >= 0x80000000u || model.num_nodes() >= 0x80000000u))
    throw InputError("the model has 2^31 CE4s or nodes or more; contact's bond words index them with 31 bits");
  // Fixed point: a node's contact force must fit in 62 bits whatever the couples add up
  // to. One edge pass gives at most P_n t L (the potential is ≤ 1); allow 300 of them per
  // node. The scale is a power of two so that the conversion is exact.
  double longest = 0;
  for (const auto& tri : model.triangles)
    for (int e = 0; e < 3; ++e) {
      const int p = tri[e], q = tri[(e + 1) % 3];
      longest = std::max(longest, std::hypot(model.x[q] - model.x[p], model.y[q] - model.y[p]));
    }
  if (model.whole_longest_edge > 0) longest = model.whole_longest_edge;  // a split run: one rank's scale
  const double worst_force = 300.0 * model.contact.max_normal_penalty * model.thickness * std::max(longest, 1e-300);
  force_scale_ = std::exp2(std::floor(std::log2(std::ldexp(1.0, 62) / worst_force)));
  energy_scale_ = std::ldexp(1.0, 32);  // 2^-32 J resolution, up to 2^31 J

  // Eight work-items per couple on GPUs (contact_forces_lanes). FDEM_CONTACT_LANES=1 or 0
  // takes a GPU's kernels on any device, with or without lanes (each force term added as
  // it comes, not summed per vertex first as on CPUs), to compare the two: they give the
  // same bits (tests/test_contact_lanes.cpp).
  lanes_ = cl.info().is_gpu;
  bool sum_per_couple = !cl.info().is_gpu;
  if (const char* env = std::getenv("FDEM_CONTACT_LANES"); env && *env) {
    if (std::string(env) != "0" && std::string(env) != "1")
      throw DeviceError(std::string("FDEM_CONTACT_LANES=") + env + " is neither 0 nor 1");
    lanes_ = *env == '1';
    sum_per_couple = false;
  }
  if (lanes_ && cl.device().max_work_group_size() < 64)
    throw DeviceError("contact_forces_lanes needs work-groups of 64; this device allows " +
                      std::to_string(cl.device().max_work_group_size()));
  std::map<std::string, std::string> defines;
  if (sum_per_couple) defines["CONTACT_SUM_PER_COUPLE"] = "1";
  if (lanes_) {
    defines["CONTACT_LANES"] = "1";
    // Above this many overlapping couples the lanes kernel takes one work-item a couple
    // (lanes_up_to: H100 and H200 measurements, docs/performance-notes.md);
    // FDEM_CONTACT_LANES_UP_TO overrides it.
    unsigned long up_to = lanes_up_to(cl.info().compute_units);
    if (const char* env = std::getenv("FDEM_CONTACT_LANES_UP_TO"); env && *env) {
      char* end = nullptr;
      up_to = std::strtoul(env, &end, 10);
      if (*end != '\0' || up_to > 0xffffffffUL)
        throw DeviceError(std::string("FDEM_CONTACT_LANES_UP_TO=") + env + " is not a count of couples");
    }
    defines["LANES_UP_TO"] = std::to_string(up_to) + "u";
    if (const char* env = std::getenv("FDEM_CONTACT_LANES_NARROW_FROM"); env && *env) {
      char* end = nullptr;
      const unsigned long from = std::strtoul(env, &end, 10);
      if (*end != '\0' || from > 0xffffffffUL)
        throw DeviceError(std::string("FDEM_CONTACT_LANES_NARROW_FROM=") + env + " is not a count of couples");
      defines["LANES_NARROW_FROM"] = std::to_string(from) + "u";
    }
  }
  defines["GROUP_SIZE"] = std::to_string(cl.group_size());
  defines["NO_SLOT"] = std::to_string(ContactCarry::kNoSlot) + "u";
  if (monitored_) defines["POOL_MONITOR"] = "1";
  if (bonds) {
    defines["CE4_BONDS"] = "1";
    defines["NO_BOND"] = std::to_string(kNoBond) + "u";
  }
  if (fans) defines["CORNER_FANS"] = "1";
  if (prelisted_) defines["PRELISTED"] = "1";
  excavation_ = !model.triangle_excavation.empty();
  if (excavation_) defines["EXCAVATION"] = "1";
  // An excavated couple stops acting at a time, not at a status change: none sleeps.
  // FDEM_CONTACT_SLEEPERS=0 classifies every couple every step (tests compare the two).
  sleepers_ = bonds && ce4_status_step != nullptr && !excavation_;
  if (const char* env = std::getenv("FDEM_CONTACT_SLEEPERS"); env && *env) {
    if (std::string(env) != "0" && std::string(env) != "1")
      throw DeviceError(std::string("FDEM_CONTACT_SLEEPERS=") + env + " is neither 0 nor 1");
    sleepers_ = sleepers_ && *env == '1';
  }
  if (sleepers_) defines["SLEEPERS"] = "1";
  std::vector<const KernelSource*> libraries{&kernel_source::couple_geometry};
  if (excavation_) libraries.push_back(&kernel_source::excavation);
  const auto program = cl.build(kernel_source::contact_forces, defines, libraries);
  stored_partials_ = compute::kernel(program, "contact_stored_partials");
  forces_ = compute::kernel(program, lanes_ ? "contact_forces_lanes" : "contact_forces");
  classify_ = compute::kernel(program, "contact_classify");
  release_ = compute::kernel(program, "release_vanished");
  const MemoryPlan arrays = plan(model, cl.group_size(), active == nullptr, monitored_, shared_keys_);
  energy_ = arrays.allocate(cl, "contact energy account");
  counters_ = arrays.allocate(cl, "contact counters (overlap list, two alternating)");
  pool_state_ = arrays.allocate(cl, "contact pool state");
  awake_count_ = arrays.allocate(cl, "contact awake counts");
  upload(cl, awake_count_, std::vector<cl_uint>{0, 0, 0, 0});
  upload(cl, energy_, std::vector<cl_long>{0, 0});
  upload(cl, counters_, std::vector<cl_uint>{0, 0});
  reset_pool();
  capacity_ = first_capacity(a.num_triangles);
  // Shared keys: none until the first list (the kernels are bound to a placeholder).
  keys_ = shared_keys_ ? pool_state_ : arrays.allocate(cl, "contact_keys");
  pool_rows_ = monitored_ ? pool_first(a.num_triangles) : capacity_;
  history_ = arrays.allocate(cl, "contact_history");
  couple_stored_ = arrays.allocate(cl, "contact couple_stored");
  list_capacity_ = capacity_;
  allocate_list(arrays);

  const size_t n_materials = model.materials.size();
  std::vector<cl_uint> index(model.contact.pair_index.begin(), model.contact.pair_index.end());
  std::vector<real> props(model.contact.pair_props.begin(), model.contact.pair_props.end());
  pair_index_ = arrays.allocate(cl, "contact_pair_index");
  pair_props_ = arrays.allocate(cl, "contact_pair_props");
  upload(cl, pair_index_, index);
  upload(cl, pair_props_, props);

  if (!active) {
    // A mask of ones: every triangle a candidate from the start, nobody ever joins.
    ones_ = arrays.allocate(cl, "contact candidate mask (all)");
    upload(cl, ones_, std::vector<cl_uint>(std::max<size_t>(1, a.num_triangles), 1u));
  }
  active_ = active ? *active : ones_;
  if (bonds) {
    bond_ce4_ = arrays.allocate(cl, "contact bond CE4s");
    upload(cl, bond_ce4_, bond_ce4(model));
  }
  if (excavation_) {
    if (model.triangle_excavation.size() != a.num_triangles)
      throw InputError("contact: " + std::to_string(a.num_triangles) + " triangles but " +
                       std::to_string(model.triangle_excavation.size()) + " excavation indices");
    std::vector<cl_int> of(model.triangle_excavation.begin(), model.triangle_excavation.end());
    std::vector<real2> times;
    for (const auto& x : model.excavations) times.push_back(real2{real(x.start), real(x.duration)});
    excavation_of_ = arrays.allocate(cl, "contact excavation_of");
    excavation_time_ = arrays.allocate(cl, "contact excavation_time");
    upload(cl, excavation_of_, of);
    upload(cl, excavation_time_, times);
  }
  if (fans) node_origin_ = *node_origin;  // the cohesive stage's
  const cl_uint none = 0;
  KernelArgs f(forces_);
  forces_list_.bind_list(f, keys_, history_, history_);
  f("tri_nodes", a.tri_nodes)("tri_material", a.tri_material)("n_materials", static_cast<cl_uint>(n_materials))(
      "pair_index", pair_index_)("pair_props", pair_props_)("position", a.position)("velocity", a.velocity)(
      "thickness", static_cast<real>(model.thickness));
  forces_dt_ = f.later("dt", real(0));
  f("force_scale", static_cast<real>(force_scale_))("energy_scale", static_cast<real>(energy_scale_))(
      "contact_acc", a.contact_acc)("energy", energy_)("counters", counters_);
  forces_list_.same_list = f.later("same_list", none);
  forces_list_.new_from = f.later("new_from", none);
  forces_list_.overlap_list = f.later("overlap_list", overlap_list_);
  forces_list_.live = f.later("live", live_);
  forces_slot_ = f.later("slot", slot_);
  forces_carry_of_ = f.later("carry_of", carry_of_);
  f("pool_state", pool_state_);
  forces_pool_capacity_ = f.later("pool_capacity", static_cast<cl_uint>(pool_rows_));
  forces_energy_row_ = f.later("energy_row", none);
  forces_couple_stored_ = f.later("couple_stored", couple_stored_);
  f("active", active_);
  forces_joined_since_ = f.later("joined_since", none);
  forces_step_ = f.later("step", cl_int(0));
  if (bonds) f("bond_ce4", bond_ce4_)("ce4_status", *ce4_status);
  if (fans) f("node_origin", node_origin_)("mesh_node_state", *mesh_node_state);
  forces_list_counter_ = f.later("list_counter", cl_uint(0));
  f.done();

  KernelArgs c(classify_);
  classify_list_.bind_list(c, keys_, history_, history_);
  c("tri_nodes", a.tri_nodes)("position", a.position)("energy_scale", static_cast<real>(energy_scale_))(
      "energy", energy_);
  classify_list_.same_list = c.later("same_list", none);
  classify_list_.new_from = c.later("new_from", none);
  c("counters", counters_);
  classify_list_.overlap_list = c.later("overlap_list", overlap_list_);
  classify_list_.live = c.later("live", live_);
  classify_slot_ = c.later("slot", slot_);
  classify_carry_of_ = c.later("carry_of", carry_of_);
  if (bonds) c("bond_ce4", bond_ce4_)("ce4_status", *ce4_status);
  if (fans) c("node_origin", node_origin_)("mesh_node_state", *mesh_node_state);
  if (bonds) {
    classify_bond_word_ = c.later("bond_word", bond_word_);
    classify_bond_words_known_ = c.later("bond_words_known", none);
  }
  if (prelisted_) c("active", active_);
  c("n_nodes", static_cast<cl_uint>(a.num_nodes))("contact_acc", a.contact_acc);
  classify_list_counter_ = c.later("list_counter", cl_uint(0));
  if (monitored_) {
    c("pool_state", pool_state_)("monitor", ring->buffer());
    classify_monitor_slot_ = c.later("monitor_slot", cl_uint(0));
  }
  if (sleepers_) {
    classify_full_forced_ = c.later("full_forced", cl_uint(1));
    c("ce4_status_step", *ce4_status_step);
    classify_step_ = c.later("step", cl_int(0));
    classify_awake_ = c.later("awake", awake_);
    c("awake_count", awake_count_);
    classify_rotation_ = c.later("rotation", cl_uint(0));
    classify_awake_capacity_ = c.later("awake_capacity", static_cast<cl_uint>(awake_capacity(list_capacity_)));
  }
  if (excavation_) {
    c("excavation_of", excavation_of_)("excavation_time", excavation_time_);
    classify_excavation_dt_ = c.later("excavation_dt", real(0));
    classify_excavation_step_ = c.later("excavation_step", cl_int(0));
  }
  c.done();

  KernelArgs r(release_);
  release_previous_count_ = r.later("n_previous", none);
  release_previous_keys_ = r.later("previous_keys", keys_);
  release_previous_history_ = r.later("previous_history", history_);
  release_count_ = r.later("n_couples", none);
  release_keys_ = r.later("keys", keys_);
  r("energy_scale", static_cast<real>(energy_scale_))("energy", energy_).done();

  KernelArgs p(stored_partials_);
  stored_count_ = p.later("n_couples", none);
  stored_live_ = p.later("live", live_);
  stored_slot_ = p.later("slot", slot_);
  stored_values_ = p.later("couple_stored", couple_stored_);
  stored_slots_arg_ = p.later("group_slots", stored_slots_);
  p.done();
}

void ContactForces::ListArgs::bind_list(KernelArgs& args, const compute::buffer& list_keys,
                                        const compute::buffer& history0, const compute::buffer& history1) {
  const cl_uint none = 0;
  count = args.later("n_couples", none);
  keys = args.later("keys", list_keys);
  previous_count = args.later("n_previous", none);
  previous_keys = args.later("previous_keys", list_keys);
  previous_history = args.later("previous_history", history0);
  history = args.later("history", history1);
}

void ContactForces::begin_step(long step) {
  ++epoch_;
  if (monitored_) classify_monitor_slot_.set(MonitorRing::slot_of(step));
}

void ContactForces::reset_pool() {
  const std::vector<cl_uint> empty{0, 0xffffffffu};
  cl_.queue().enqueue_write_buffer(pool_state_, 0, empty.size() * sizeof(cl_uint), empty.data());
}

void ContactForces::allocate_pool(size_t rows, bool keep) {
  const MemoryPlan arrays = pool_arrays(rows);
  compute::buffer history = arrays.allocate(cl_, "contact_history");
  if (keep && pool_rows_ > 0)
    cl_.queue().enqueue_copy_buffer(history_, history, 0, 0, pool_rows_ * kHistory * sizeof(real));
  history_ = history;
  // Written and read within one step: nothing to keep.
  couple_stored_ = compute::buffer();
  couple_stored_ = arrays.allocate(cl_, "contact couple_stored");
  pool_rows_ = rows;
}

void ContactForces::ensure_pool(size_t rows_seen, size_t rows_per_step) {
  const size_t margin = std::max(pool_headroom(triangles_) / 2, 2 * MonitorRing::kSlots * rows_per_step);
  if (!monitored_ || rows_seen + margin <= pool_rows_) return;
  allocate_pool(pool_grown(rows_seen, triangles_) + margin, true);
}

void ContactForces::check_pool() { check_pool(download<cl_uint>(cl_, pool_state_, 2).data()); }

void ContactForces::read_pool_state(cl_uint* state) {
  cl_.queue().enqueue_read_buffer_async(pool_state_, 0, 2 * sizeof(cl_uint), state);
}

std::function<std::vector<cl_uint>()> ContactForces::queue_pool_state(RowReads& reads) {
  return reads.read<cl_uint>(pool_state_, 2);
}

void ContactForces::check_pool(const cl_uint* state) {
  if (state[1] != 0xffffffffu) throw NumericalError(pool_overflow_message(static_cast<long>(state[1])));
}

long ContactForces::pool_overflow_step() {
  const auto state = download<cl_uint>(cl_, pool_state_, 2);
  return state[1] == 0xffffffffu ? -1 : static_cast<long>(state[1]);
}

void ContactForces::enqueue_extended(const compute::buffer& keys, size_t count, double dt, bool energy_row,
                                     long step) {
  if (!shared_keys_ || count > list_capacity_ || count < count_)
    throw DeviceError("contact: a list extension to " + std::to_string(count) + " couples does not fit its arrays (" +
                      std::to_string(list_capacity_) + ")");
  extended_from_ = count_;
  keys_ = keys;
  enqueue(keys, count, false, dt, energy_row, step);
}

void ContactForces::enqueue(const compute::buffer& keys, size_t count, bool new_list, double dt, bool energy_row,
                            long step) {
  ++epoch_;
  energy_row = energy_row || energy_row_requested_;
  energy_row_requested_ = false;
  // Couples listed ahead of joins: a couple is met over an overlap only in the step its
  // triangle joined (stamp join_stamp(step)); otherwise any join since the last list.
  const cl_uint joined_since = prelisted_ ? ContactActivation::join_stamp(step) : joined_since_last_list();
  // A new list: the couples of the last list that hold a history (and those next to a
  // join) go to the carry list, where the new list finds them by key (ContactCarry); the
  // pool is emptied, each couple taking a row again at its first write. Between
  // detections the list, its slots and the pool stay in place.
  size_t carried = 0;
  if (new_list) {
    carried = carry_ready_ ? carried_ : carry_old_list();
    carry_ready_ = false;
    if (!shared_keys_ && count > capacity_) {
      capacity_ = grown(count);
      keys_ = key_list(capacity_).allocate(cl_, "contact_keys");
    }
    if (count > list_capacity_) {
      list_capacity_ = grown(count);
      allocate_list(couple_arrays(list_capacity_, cl_.group_size(), bonds_));  // a new list writes every slot and flag
    }
    // Room for the carried couples and the headroom (with a skin), or a row per couple.
    const size_t rows = monitored_ ? pool_grown(carried, triangles_) : list_capacity_;
    if (rows > pool_rows_) allocate_pool(rows, false);
    reset_pool();
  }
  if (carried > 0) {
    release_previous_count_.set(static_cast<cl_uint>(carried));
    release_previous_keys_.set(carry_.keys());
    release_previous_history_.set(carry_.history());
    release_count_.set(static_cast<cl_uint>(count));
    release_keys_.set(keys);
    cl_.enqueue(release_, carried);
  }
  // Same list as the last step: couple c's history is at its pool row (no key search).
  const cl_uint same_list = new_list ? 0 : 1;
  const compute::buffer& list_keys = new_list ? keys : keys_;
  classify_slot_.set(slot_);
  forces_slot_.set(slot_);
  classify_carry_of_.set(carry_of_);
  forces_carry_of_.set(carry_of_);
  // A new list finds its carried couples' rows through carry_of (written here, read by
  // the classification and the forces of this step).
  if (new_list) carry_.locate(keys, count, carried, carry_of_);
  // A new list (or arrays just allocated or loaded) has its bond words written by this
  // step's classification; the later steps of the list read them.
  if (new_list) bond_words_known_ = false;
  // Couples appended since the last step (an extension) start fresh from new_from on;
  // otherwise every couple of the same list is old (new_from = count).
  const size_t new_from = new_list ? 0 : std::min(extended_from_, count);
  extended_from_ = static_cast<size_t>(-1);
  if (bonds_) {
    classify_bond_word_.set(bond_word_);
    classify_bond_words_known_.set(static_cast<cl_uint>(bond_words_known_ ? new_from : 0));
  }
  forces_pool_capacity_.set(static_cast<cl_uint>(pool_rows_));
  for (ListArgs* list : {&classify_list_, &forces_list_}) {
    list->count.set(static_cast<cl_uint>(count));
    list->keys.set(list_keys);
    list->previous_count.set(static_cast<cl_uint>(new_list ? carried : count_));
    list->previous_keys.set(new_list ? carry_.keys() : keys_);
    list->previous_history.set(new_list ? carry_.history() : history_);
    list->history.set(history_);
    list->same_list.set(same_list);
    list->new_from.set(static_cast<cl_uint>(new_from));
    list->overlap_list.set(overlap_list_);
    list->live.set(live_);
  }
  // The classification also starts the step (contact forces and the other counter
  // zeroed, the pool's rows to the ring): over the nodes as well as the couples.
  classify_list_counter_.set(list_counter_);
  forces_list_counter_.set(list_counter_);
  if (sleepers_) {
    // A new or extended list, or bond words not yet known: every couple is classified
    // (the kernel may decide so itself as well), counting into a zeroed slot.
    const bool full = !bond_words_known_ || new_from < count;
    classify_full_forced_.set(full ? 1u : 0u);
    if (full) {
      const cl_uint zero = 0;
      cl_.queue().enqueue_fill_buffer(awake_count_, &zero, sizeof(zero), 0, 3 * sizeof(cl_uint));  // not the lean count
    }
    classify_step_.set(static_cast<cl_int>(std::min<long>(step, std::numeric_limits<cl_int>::max() - 2)));
    classify_awake_.set(awake_);
    classify_awake_capacity_.set(static_cast<cl_uint>(awake_capacity(list_capacity_)));
    classify_rotation_.set(rotation_);
    rotation_ = (rotation_ + 1) % 3;
  }
  if (excavation_) {
    classify_excavation_dt_.set(static_cast<real>(dt));
    classify_excavation_step_.set(static_cast<cl_int>(std::min<long>(step, std::numeric_limits<cl_int>::max() - 2)));
  }
  cl_.enqueue(classify_, std::max<size_t>({count, arrays_.num_nodes, 1}));
  list_counter_ = 1 - list_counter_;
  bond_words_known_ = true;
  forces_dt_.set(static_cast<real>(dt));
  forces_energy_row_.set(energy_row ? 1 : 0);
  forces_couple_stored_.set(couple_stored_);
  forces_joined_since_.set(joined_since);
  forces_step_.set(static_cast<cl_int>(std::min<long>(step, std::numeric_limits<cl_int>::max() - 2)));
  if (new_list) last_list_step_ = step;
  // Work-groups of 64 on a GPU: the couples that overlap are the first entries of the
  // list, so small groups spread them over more compute units (H200, blasting: 94 → 88 µs a
  // step). The lanes kernel needs 64 (eight couples of eight work-items a group).
  cl_.enqueue(forces_, count, lanes_ ? 64 : cl_.info().is_gpu ? std::min<size_t>(64, cl_.group_size()) : 0);
  if (energy_row) {
    stored_groups_ = work_groups(cl_, count);
    if (count > 0) {
      stored_count_.set(static_cast<cl_uint>(count));
      stored_live_.set(live_);
      stored_slot_.set(slot_);
      stored_values_.set(couple_stored_);
      stored_slots_arg_.set(stored_slots_);
      cl_.enqueue(stored_partials_, count);
    }
  }
  if (!new_list) count_ = count;  // an extension grew the list in place
  if (new_list) {
    if (shared_keys_)
      keys_ = keys;  // the detection leaves them alone until carry_before_detection
    else if (count)
      cl_.queue().enqueue_copy_buffer(keys, keys_, 0, 0, count * sizeof(cl_ulong));
    count_ = count;
    ++list_generation_;
  }
}

cl_uint ContactForces::joined_since_last_list() const {
  // Joins since the last list (activation runs before detection in a step, so a join in
  // the last list's own step was in that list): stamps ≥ last_list_step_ + 3.
  return ContactActivation::join_stamp(last_list_step_ + 1);
}

size_t ContactForces::carry_old_list() {
  ++epoch_;
  // Listed ahead of joins, a couple is "old" only by its history: a join's couples were in
  // the last list too, and one met overlapping in its join's step must not be carried as
  // old by the join (no mask value reaches the largest stamp).
  const cl_uint joined_since = prelisted_ ? std::numeric_limits<cl_uint>::max() : joined_since_last_list();
  const size_t carried = carry_.carry(keys_, history_, slot_, live_, active_, count_, joined_since);
  // The carry waited for the device: a full pool in the steps since the last check stops here.
  check_pool();
  return carried;
}

void ContactForces::carry_before_detection() {
  carried_ = carry_old_list();
  carry_ready_ = true;
}

size_t ContactForces::touching() {
  if (count_ == 0) return 0;
  if (touching_epoch_ == epoch_) return touching_seen_;
  const auto live = download<cl_uchar>(cl_, live_, count_);
  touching_seen_ = static_cast<size_t>(std::count(live.begin(), live.end(), cl_uchar{1}));
  touching_epoch_ = epoch_;
  return touching_seen_;
}

std::vector<cl_long> ContactForces::energy_account() {
  if (energy_epoch_ != epoch_) {
    energy_seen_ = download<cl_long>(cl_, energy_, layout::CONTACT_ENERGY_WORDS);
    energy_epoch_ = epoch_;
  }
  return energy_seen_;
}

std::vector<cl_ulong> ContactForces::list_keys() {
  if (count_ == 0) return {};
  return download<cl_ulong>(cl_, keys_, count_);
}

ContactForces::StoredCouples ContactForces::stored_couples() {
  StoredCouples out;
  if (count_ == 0) return out;
  const auto live = download<cl_uchar>(cl_, live_, count_);
  const auto slot = slots();
  const auto rows = download<real>(cl_, couple_stored_, pool_rows_);
  for (size_t c = 0; c < count_; ++c) {
    if (live[c] != 1) continue;
    ++out.touching;
    if (slot[c] == ContactCarry::kNoSlot || slot[c] >= pool_rows_ || rows[slot[c]] == real(0)) continue;
    out.index.push_back(static_cast<cl_uint>(c));
    out.value.push_back(rows[slot[c]]);
  }
  return out;
}

std::function<ContactForces::RowTerms()> ContactForces::queue_row(RowReads& reads) {
  const bool touching_known = count_ == 0 || touching_epoch_ == epoch_;
  const bool words_known = energy_epoch_ == epoch_;
  auto live = touching_known ? std::function<std::vector<cl_uchar>()>() : reads.read<cl_uchar>(live_, count_);
  auto words = words_known ? std::function<std::vector<cl_long>()>()
                           : reads.read<cl_long>(energy_, layout::CONTACT_ENERGY_WORDS);
  auto slots = reads.read<real>(stored_slots_, stored_groups_);
  const std::uint64_t epoch = epoch_;
  return [this, live, words, slots, epoch] {
    RowTerms t;
    if (live) {
      const auto flags = live();
      const size_t n = static_cast<size_t>(std::count(flags.begin(), flags.end(), cl_uchar{1}));
      if (epoch_ == epoch) touching_seen_ = n, touching_epoch_ = epoch;
      t.touching = n;
    } else {
      t.touching = count_ == 0 ? 0 : touching_seen_;
    }
    std::vector<cl_long> e;
    if (words) {
      e = words();
      if (epoch_ == epoch) energy_seen_ = e, energy_epoch_ = epoch;
    } else {
      e = energy_seen_;
    }
    // Group order, in double (sum_group_slots).
    for (const real v : slots()) t.stored += static_cast<double>(v);
    t.friction = static_cast<double>(e[layout::ENERGY_FRICTION]) / energy_scale_;
    t.damping = static_cast<double>(e[layout::ENERGY_DAMPING]) / energy_scale_;
    return t;
  };
}

double ContactForces::stored_energy() { return sum_group_slots(cl_, stored_slots_, stored_groups_, 1)[0]; }

long ContactForces::lean_classifications() {
  return sleepers_ ? static_cast<long>(download<cl_uint>(cl_, awake_count_, 4)[3]) : 0;
}

void ContactForces::allocate_list(const MemoryPlan& arrays) {
  overlap_list_ = arrays.allocate(cl_, "contact overlap list");
  live_ = arrays.allocate(cl_, "contact live flags");
  slot_ = arrays.allocate(cl_, "contact history slots");
  carry_of_ = arrays.allocate(cl_, "contact carry rows");
  stored_slots_ = arrays.allocate(cl_, "contact stored slots");
  if (bonds_) {
    bond_word_ = arrays.allocate(cl_, "contact bond words");
    awake_ = arrays.allocate(cl_, "contact awake couples");
  }
  bond_words_known_ = false;
}
double ContactForces::friction_dissipation() { return static_cast<double>(energy_account()[layout::ENERGY_FRICTION]) / energy_scale_; }
double ContactForces::damping_dissipation() { return static_cast<double>(energy_account()[layout::ENERGY_DAMPING]) / energy_scale_; }

double ContactForces::dissipated_energy() {
  const auto e = energy_account();
  return static_cast<double>(e[layout::ENERGY_FRICTION] + e[layout::ENERGY_DAMPING]) / energy_scale_;
}

std::vector<cl_uint> ContactForces::slots() { return download<cl_uint>(cl_, slot_, count_); }

std::vector<real> ContactForces::history() {
  std::vector<real> out(count_ * kHistory, real(0));
  if (count_ == 0) return out;
  const auto slot = slots();
  const auto pool = download<real>(cl_, history_, pool_rows_ * kHistory);
  for (size_t c = 0; c < count_; ++c)
    if (slot[c] != ContactCarry::kNoSlot && slot[c] < pool_rows_)
      std::copy_n(&pool[size_t(slot[c]) * kHistory], kHistory, &out[c * kHistory]);
  return out;
}
std::vector<cl_ulong> ContactForces::keys() { return download<cl_ulong>(cl_, keys_, count_); }
std::vector<real> ContactForces::couple_stored() {
  std::vector<real> out(count_, real(0));
  if (count_ == 0) return out;
  const auto slot = slots();
  const auto live = download<cl_uchar>(cl_, live_, count_);
  const auto stored = download<real>(cl_, couple_stored_, pool_rows_);
  for (size_t c = 0; c < count_; ++c)
    if (live[c] == 1 && slot[c] != ContactCarry::kNoSlot && slot[c] < pool_rows_) out[c] = stored[slot[c]];
  return out;
}

void ContactForces::save_state(StateWriter& out) const {
  out.integer("contact_couples", static_cast<std::int64_t>(count_));
  out.integer("contact_last_list_step", static_cast<std::int64_t>(last_list_step_));
  out.buffer<cl_ulong>("contact_keys", keys_, count_);
  // Per couple, as the file has always held it (the pool rows gathered by slot).
  const auto history = const_cast<ContactForces*>(this)->history();
  out.host<real>("contact_history", history.data(), count_, kHistory);
  out.buffer<cl_uchar>("contact_live", live_, count_);
  out.buffer<cl_long>("contact_energy", energy_, layout::CONTACT_ENERGY_WORDS);
}

void ContactForces::load_state(StateReader& in) {
  ++epoch_;
  bond_words_known_ = false;  // the loaded list's are written by the next classification
  count_ = static_cast<size_t>(in.integer("contact_couples"));
  ++list_generation_;
  last_list_step_ = static_cast<long>(in.integer("contact_last_list_step"));
  if (shared_keys_ || count_ > capacity_) {
    // Shared: the detection's list is not restored; the contact stage holds its own
    // until the next detection.
    capacity_ = shared_keys_ ? std::max<size_t>(count_, 1) : grown(count_);
    keys_ = key_list(capacity_).allocate(cl_, "contact_keys");
  }
  if (count_ > list_capacity_) {
    list_capacity_ = grown(count_);
    allocate_list(couple_arrays(list_capacity_, cl_.group_size(), bonds_));
  }
  in.buffer<cl_ulong>("contact_keys", keys_, count_);
  // The file holds a history per couple: the couples with one that is not all zeros (or
  // a nonzero live flag) take pool rows in list order.
  std::vector<real> history(count_ * kHistory);
  in.host<real>("contact_history", history.data(), count_, kHistory);
  in.buffer<cl_uchar>("contact_live", live_, count_);
  const auto live = download<cl_uchar>(cl_, live_, count_);
  std::vector<cl_uint> slot(count_, ContactCarry::kNoSlot);
  std::vector<real> rows;
  for (size_t c = 0; c < count_; ++c) {
    const real* h = &history[c * kHistory];
    if (live[c] == 0 && std::all_of(h, h + kHistory, [](real v) { return v == real(0); })) continue;
    slot[c] = static_cast<cl_uint>(rows.size() / kHistory);
    rows.insert(rows.end(), h, h + kHistory);
  }
  const size_t taken = rows.size() / kHistory;
  const size_t needed = monitored_ ? pool_grown(taken, triangles_) : std::max(list_capacity_, taken);
  if (needed > pool_rows_) allocate_pool(needed, false);
  if (!rows.empty()) cl_.queue().enqueue_write_buffer(history_, 0, rows.size() * sizeof(real), rows.data());
  if (count_ > 0) cl_.queue().enqueue_write_buffer(slot_, 0, slot.size() * sizeof(cl_uint), slot.data());
  const std::vector<cl_uint> state{static_cast<cl_uint>(taken), 0xffffffffu};
  cl_.queue().enqueue_write_buffer(pool_state_, 0, state.size() * sizeof(cl_uint), state.data());
  cl_.finish();
  in.buffer<cl_long>("contact_energy", energy_, layout::CONTACT_ENERGY_WORDS);
}

}  // namespace fdem
