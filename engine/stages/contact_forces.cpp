#include "engine/stages/contact_forces.hpp"

#include "engine/stages/contact_activation.hpp"

#include "engine/energy.hpp"
#include "base/errors.hpp"
#include "engine/kernel_args.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace fdem {

namespace {
constexpr int kHistory = layout::CONTACT_HISTORY;
}

MemoryPlan ContactForces::couple_arrays(size_t capacity, size_t group_size) {
  return MemoryPlan()
      .add("contact_keys", capacity * sizeof(cl_ulong))
      .add("contact_history", capacity * kHistory * sizeof(real))
      .add("contact overlap list", capacity * sizeof(cl_uint))
      .add("contact live flags", capacity * sizeof(cl_uchar))
      .add("contact couple_stored", std::max<size_t>(1, capacity) * sizeof(real))
      .add("contact stored slots", std::max<size_t>(1, groups_for(capacity, group_size)) * sizeof(real));
}

MemoryPlan ContactForces::plan(const Model& model, size_t group_size, bool own_mask) {
  MemoryPlan p;
  // Friction dissipated, damping dissipated (ENERGY_FRICTION, ENERGY_DAMPING).
  p.add("contact energy account", layout::CONTACT_ENERGY_WORDS * sizeof(cl_long))
      .add("contact counters (touching, overlap list)", 2 * sizeof(cl_uint))
      .add(couple_arrays(first_capacity(model.num_triangles()), group_size))
      .add(ContactCarry::plan(model.num_triangles(), first_capacity(model.num_triangles()), group_size))
      .add("contact_pair_index", model.contact.pair_index.size() * sizeof(cl_uint))
      .add("contact_pair_props", model.contact.pair_props.size() * sizeof(real));
  if (own_mask)
    p.add("contact candidate mask (all)", std::max<size_t>(1, model.num_triangles()) * sizeof(cl_uint));
  if (!model.ce4_triangles.empty()) p.add("contact bond CE4s", 3 * model.num_triangles() * sizeof(cl_uint));
  if (!model.ce4_triangles.empty() && !model.node_origin.empty())
    p.add("contact node origins", model.num_nodes() * sizeof(cl_uint));
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
                             const compute::buffer* ce4_status, const compute::buffer* mesh_node_state)
    : cl_(cl), arrays_(a), carry_(cl, a.num_triangles, first_capacity(a.num_triangles)) {
  const bool bonds = ce4_status != nullptr && !model.ce4_triangles.empty();
  const bool fans = bonds && mesh_node_state != nullptr && model.node_origin.size() == model.num_nodes();
  // Fixed point: a node's contact force must fit in 62 bits whatever the couples add up
  // to. One edge pass gives at most P_n t L (the potential is ≤ 1); allow 300 of them per
  // node. The scale is a power of two so that the conversion is exact.
  double longest = 0;
  for (const auto& tri : model.triangles)
    for (int e = 0; e < 3; ++e) {
      const int p = tri[e], q = tri[(e + 1) % 3];
      longest = std::max(longest, std::hypot(model.x[q] - model.x[p], model.y[q] - model.y[p]));
    }
  const double worst_force = 300.0 * model.contact.max_normal_penalty * model.thickness * std::max(longest, 1e-300);
  force_scale_ = std::exp2(std::floor(std::log2(std::ldexp(1.0, 62) / worst_force)));
  energy_scale_ = std::ldexp(1.0, 32);  // 2^-32 J resolution, up to 2^31 J

  std::map<std::string, std::string> defines;
  if (!cl.info().is_gpu) defines["CONTACT_SUM_PER_COUPLE"] = "1";
  defines["GROUP_SIZE"] = std::to_string(cl.group_size());
  if (bonds) {
    defines["CE4_BONDS"] = "1";
    defines["NO_BOND"] = std::to_string(kNoBond) + "u";
  }
  if (fans) defines["CORNER_FANS"] = "1";
  const auto program = cl.build(kernel_source::contact_forces, defines);
  stored_partials_ = compute::kernel(program, "contact_stored_partials");
  forces_ = compute::kernel(program, "contact_forces");
  classify_ = compute::kernel(program, "contact_classify");
  clear_ = compute::kernel(program, "clear_contact_forces");
  release_ = compute::kernel(program, "release_vanished");
  const MemoryPlan arrays = plan(model, cl.group_size(), active == nullptr);
  energy_ = arrays.allocate(cl, "contact energy account");
  counters_ = arrays.allocate(cl, "contact counters (touching, overlap list)");
  upload(cl, energy_, std::vector<cl_long>{0, 0});
  upload(cl, counters_, std::vector<cl_uint>{0, 0});
  capacity_ = first_capacity(a.num_triangles);
  keys_ = arrays.allocate(cl, "contact_keys");
  history_ = arrays.allocate(cl, "contact_history");
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
  if (fans) {
    node_origin_ = arrays.allocate(cl, "contact node origins");
    upload(cl, node_origin_, std::vector<cl_uint>(model.node_origin.begin(), model.node_origin.end()));
  }
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
  forces_list_.overlap_list = f.later("overlap_list", overlap_list_);
  forces_list_.live = f.later("live", live_);
  forces_energy_row_ = f.later("energy_row", none);
  forces_couple_stored_ = f.later("couple_stored", couple_stored_);
  f("active", active_);
  forces_joined_since_ = f.later("joined_since", none);
  forces_step_ = f.later("step", cl_int(0));
  if (bonds) f("bond_ce4", bond_ce4_)("ce4_status", *ce4_status);
  if (fans) f("node_origin", node_origin_)("mesh_node_state", *mesh_node_state);
  f.done();

  KernelArgs c(classify_);
  classify_list_.bind_list(c, keys_, history_, history_);
  c("tri_nodes", a.tri_nodes)("position", a.position)("energy_scale", static_cast<real>(energy_scale_))(
      "energy", energy_);
  classify_list_.same_list = c.later("same_list", none);
  c("counters", counters_);
  classify_list_.overlap_list = c.later("overlap_list", overlap_list_);
  classify_list_.live = c.later("live", live_);
  if (bonds) c("bond_ce4", bond_ce4_)("ce4_status", *ce4_status);
  if (fans) c("node_origin", node_origin_)("mesh_node_state", *mesh_node_state);
  c.done();

  bind_args(clear_)("n_nodes", static_cast<cl_uint>(a.num_nodes))("contact_acc", a.contact_acc)(
      "counters", counters_)
      .done();

  KernelArgs r(release_);
  release_previous_count_ = r.later("n_previous", none);
  release_previous_keys_ = r.later("previous_keys", keys_);
  release_previous_history_ = r.later("previous_history", history_);
  release_count_ = r.later("n_couples", none);
  release_keys_ = r.later("keys", keys_);
  r("energy_scale", static_cast<real>(energy_scale_))("energy", energy_).done();

  KernelArgs p(stored_partials_);
  stored_count_ = p.later("n_couples", none);
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

void ContactForces::enqueue_clear() { cl_.enqueue(clear_, std::max<size_t>(arrays_.num_nodes, 1)); }

void ContactForces::enqueue(const compute::buffer& keys, size_t count, bool new_list, double dt, bool energy_row,
                            long step) {
  energy_row = energy_row || energy_row_requested_;
  energy_row_requested_ = false;
  // Joins since the last list (activation runs before detection in a step, so a join in
  // the last list's own step was in that list): stamps ≥ last_list_step_ + 3.
  const cl_uint joined_since = ContactActivation::join_stamp(last_list_step_ + 1);
  // A new list: the couples of the last list that hold a history (and those next to a
  // join) go to the carry list, where the new list finds them by key; the one history
  // array is then rewritten in place (ContactCarry). Between detections the list and its
  // history stay in place.
  size_t carried = 0;
  if (new_list) {
    carried = carry_.carry(keys_, history_, live_, active_, count_, joined_since);
    if (count > capacity_) {
      capacity_ = grown(count);
      const MemoryPlan arrays = couple_arrays(capacity_, cl_.group_size());
      history_ = arrays.allocate(cl_, "contact_history");  // what it held is carried
      keys_ = arrays.allocate(cl_, "contact_keys");
    }
  }
  if (carried > 0) {
    release_previous_count_.set(static_cast<cl_uint>(carried));
    release_previous_keys_.set(carry_.keys());
    release_previous_history_.set(carry_.history());
    release_count_.set(static_cast<cl_uint>(count));
    release_keys_.set(keys);
    cl_.enqueue(release_, carried);
  }
  if (count > list_capacity_) {
    list_capacity_ = grown(count);
    allocate_list(couple_arrays(list_capacity_, cl_.group_size()));  // a new list writes every flag
  }
  if (energy_row && count > 0) {
    const real zero = 0;
    cl_.queue().enqueue_fill_buffer(couple_stored_, &zero, sizeof(zero), 0, count * sizeof(real));
  }
  // Same list as the last step: couple c's history is at c, in place (no key search).
  const cl_uint same_list = new_list ? 0 : 1;
  const compute::buffer& list_keys = new_list ? keys : keys_;
  for (ListArgs* list : {&classify_list_, &forces_list_}) {
    list->count.set(static_cast<cl_uint>(count));
    list->keys.set(list_keys);
    list->previous_count.set(static_cast<cl_uint>(new_list ? carried : count_));
    list->previous_keys.set(new_list ? carry_.keys() : keys_);
    list->previous_history.set(new_list ? carry_.history() : history_);
    list->history.set(history_);
    list->same_list.set(same_list);
    list->overlap_list.set(overlap_list_);
    list->live.set(live_);
  }
  cl_.enqueue(classify_, count);
  forces_dt_.set(static_cast<real>(dt));
  forces_energy_row_.set(energy_row ? 1 : 0);
  forces_couple_stored_.set(couple_stored_);
  forces_joined_since_.set(joined_since);
  forces_step_.set(static_cast<cl_int>(std::min<long>(step, std::numeric_limits<cl_int>::max() - 2)));
  if (new_list) last_list_step_ = step;
  cl_.enqueue(forces_, count);
  if (energy_row) {
    stored_groups_ = work_groups(cl_, count);
    if (count > 0) {
      stored_count_.set(static_cast<cl_uint>(count));
      stored_values_.set(couple_stored_);
      stored_slots_arg_.set(stored_slots_);
      cl_.enqueue(stored_partials_, count);
    }
  }
  if (new_list) {
    if (count) cl_.queue().enqueue_copy_buffer(keys, keys_, 0, 0, count * sizeof(cl_ulong));
    count_ = count;
  }
}

size_t ContactForces::touching() {
  if (count_ == 0) return 0;
  const auto live = download<cl_uchar>(cl_, live_, count_);
  return static_cast<size_t>(std::count(live.begin(), live.end(), cl_uchar{1}));
}

std::vector<cl_long> ContactForces::energy_account() { return download<cl_long>(cl_, energy_, layout::CONTACT_ENERGY_WORDS); }

double ContactForces::stored_energy() { return sum_group_slots(cl_, stored_slots_, stored_groups_, 1)[0]; }

void ContactForces::allocate_list(const MemoryPlan& arrays) {
  overlap_list_ = arrays.allocate(cl_, "contact overlap list");
  live_ = arrays.allocate(cl_, "contact live flags");
  couple_stored_ = arrays.allocate(cl_, "contact couple_stored");
  stored_slots_ = arrays.allocate(cl_, "contact stored slots");
}
double ContactForces::friction_dissipation() { return static_cast<double>(energy_account()[layout::ENERGY_FRICTION]) / energy_scale_; }
double ContactForces::damping_dissipation() { return static_cast<double>(energy_account()[layout::ENERGY_DAMPING]) / energy_scale_; }

double ContactForces::dissipated_energy() {
  const auto e = energy_account();
  return static_cast<double>(e[layout::ENERGY_FRICTION] + e[layout::ENERGY_DAMPING]) / energy_scale_;
}

std::vector<real> ContactForces::history() { return download<real>(cl_, history_, count_ * kHistory); }
std::vector<cl_ulong> ContactForces::keys() { return download<cl_ulong>(cl_, keys_, count_); }
std::vector<real> ContactForces::couple_stored() { return download<real>(cl_, couple_stored_, count_); }

void ContactForces::save_state(StateWriter& out) const {
  out.integer("contact_couples", static_cast<std::int64_t>(count_));
  out.integer("contact_last_list_step", static_cast<std::int64_t>(last_list_step_));
  out.buffer<cl_ulong>("contact_keys", keys_, count_);
  out.buffer<real>("contact_history", history_, count_, kHistory);
  out.buffer<cl_uchar>("contact_live", live_, count_);
  out.buffer<cl_long>("contact_energy", energy_, layout::CONTACT_ENERGY_WORDS);
}

void ContactForces::load_state(StateReader& in) {
  count_ = static_cast<size_t>(in.integer("contact_couples"));
  last_list_step_ = static_cast<long>(in.integer("contact_last_list_step"));
  if (count_ > capacity_) {
    capacity_ = grown(count_);
    const MemoryPlan arrays = couple_arrays(capacity_, cl_.group_size());
    keys_ = arrays.allocate(cl_, "contact_keys");
    history_ = arrays.allocate(cl_, "contact_history");
  }
  if (count_ > list_capacity_) {
    list_capacity_ = grown(count_);
    allocate_list(couple_arrays(list_capacity_, cl_.group_size()));
  }
  in.buffer<cl_ulong>("contact_keys", keys_, count_);
  in.buffer<real>("contact_history", history_, count_, kHistory);
  in.buffer<cl_uchar>("contact_live", live_, count_);
  in.buffer<cl_long>("contact_energy", energy_, layout::CONTACT_ENERGY_WORDS);
}

}  // namespace fdem
