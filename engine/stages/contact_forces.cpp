#include "engine/stages/contact_forces.hpp"

#include "engine/stages/contact_activation.hpp"

#include "engine/energy.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace fdem {

namespace {
constexpr int kHistory = 12;  // CONTACT_HISTORY in contact_forces.cl

// Room for a grown couple list: an eighth more (the lists are the largest arrays, about
// 170 bytes a couple; couples grow slowly once the first detection has run).
size_t grown(size_t count) { return count + count / 8 + 1024; }
}

ContactForces::ContactForces(ClContext& cl, DeviceArrays& a, const Model& model) : cl_(cl), arrays_(a) {
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
  const auto program = cl.build("contact_forces", defines);
  stored_partials_ = compute::kernel(program, "contact_stored_partials");
  forces_ = compute::kernel(program, "contact_forces");
  classify_ = compute::kernel(program, "contact_classify");
  clear_ = compute::kernel(program, "clear_contact_forces");
  release_ = compute::kernel(program, "release_vanished");
  // Friction dissipated, damping dissipated (ENERGY_FRICTION, ENERGY_DAMPING in contact_forces.cl).
  energy_ = cl.allocate(2 * sizeof(cl_long), "contact energy account");
  counters_ = cl.allocate(2 * sizeof(cl_uint), "contact counters (touching, overlap list)");
  upload(cl, energy_, std::vector<cl_long>{0, 0});
  upload(cl, counters_, std::vector<cl_uint>{0, 0});
  capacity_ = std::max<size_t>(1024, 4 * a.num_triangles);
  keys_ = cl.allocate(capacity_ * sizeof(cl_ulong), "contact_keys");
  for (auto& h : history_) h = cl.allocate(capacity_ * kHistory * sizeof(real), "contact_history");
  list_capacity_ = capacity_;
  overlap_list_ = cl.allocate(list_capacity_ * sizeof(cl_uint), "contact overlap list");
  live_ = cl.allocate(list_capacity_, "contact live flags");
  allocate_stored(list_capacity_);

  const size_t n_materials = model.materials.size();
  std::vector<cl_uint> index(model.contact.pair_index.begin(), model.contact.pair_index.end());
  std::vector<real> props(model.contact.pair_props.begin(), model.contact.pair_props.end());
  pair_index_ = cl.allocate(index.size() * sizeof(cl_uint), "contact_pair_index");
  pair_props_ = cl.allocate(props.size() * sizeof(real), "contact_pair_props");
  upload(cl, pair_index_, index);
  upload(cl, pair_props_, props);

  forces_.set_arg(6, a.tri_nodes);
  forces_.set_arg(7, a.tri_material);
  forces_.set_arg(8, static_cast<cl_uint>(n_materials));
  forces_.set_arg(9, pair_index_);
  forces_.set_arg(10, pair_props_);
  forces_.set_arg(11, a.position);
  forces_.set_arg(12, a.velocity);
  forces_.set_arg(13, static_cast<real>(model.thickness));
  forces_.set_arg(15, static_cast<real>(force_scale_));
  forces_.set_arg(16, static_cast<real>(energy_scale_));
  forces_.set_arg(17, a.contact_acc);
  forces_.set_arg(18, energy_);
  forces_.set_arg(19, counters_);
  ones_ = cl.allocate(std::max<size_t>(1, a.num_triangles) * sizeof(cl_uint), "contact default candidate mask");
  upload(cl, ones_, std::vector<cl_uint>(std::max<size_t>(1, a.num_triangles), 1u));
  forces_.set_arg(25, ones_);
  classify_.set_arg(6, a.tri_nodes);
  classify_.set_arg(7, a.position);
  classify_.set_arg(8, static_cast<real>(energy_scale_));
  classify_.set_arg(9, energy_);
  classify_.set_arg(11, counters_);
  clear_.set_arg(0, static_cast<cl_uint>(a.num_nodes));
  clear_.set_arg(1, a.contact_acc);
  clear_.set_arg(2, counters_);
}

void ContactForces::enqueue_clear() { cl_.enqueue(clear_, std::max<size_t>(arrays_.num_nodes, 1)); }

void ContactForces::enqueue(const compute::buffer& keys, size_t count, bool new_list, double dt, bool energy_row,
                            long step) {
  energy_row = energy_row || energy_row_requested_;
  energy_row_requested_ = false;
  const int next = new_list ? 1 - current_ : current_;
  if (new_list && count > capacity_) {
    // Grow the write side now; the previous list and history stay readable for this call.
    history_[next] = cl_.allocate(grown(count) * kHistory * sizeof(real), "contact_history");
  }
  if (new_list && count_ > 0) {
    release_.set_arg(0, static_cast<cl_uint>(count_));
    release_.set_arg(1, keys_);
    release_.set_arg(2, history_[current_]);
    release_.set_arg(3, static_cast<cl_uint>(count));
    release_.set_arg(4, keys);
    release_.set_arg(5, static_cast<real>(energy_scale_));
    release_.set_arg(6, energy_);
    cl_.enqueue(release_, count_);
  }
  if (count > list_capacity_) {
    list_capacity_ = grown(count);
    overlap_list_ = cl_.allocate(list_capacity_ * sizeof(cl_uint), "contact overlap list");
    live_ = cl_.allocate(list_capacity_, "contact live flags");  // a new list writes every flag
    allocate_stored(list_capacity_);
  }
  if (energy_row && count > 0) {
    const real zero = 0;
    cl_.queue().enqueue_fill_buffer(couple_stored_, &zero, sizeof(zero), 0, count * sizeof(real));
  }
  // Same list as the last step: couple c's history is at c, in place (no key search).
  const cl_uint same_list = new_list ? 0 : 1;
  const compute::buffer& list_keys = new_list ? keys : keys_;
  classify_.set_arg(0, static_cast<cl_uint>(count));
  classify_.set_arg(1, list_keys);
  classify_.set_arg(2, static_cast<cl_uint>(count_));
  classify_.set_arg(3, keys_);
  classify_.set_arg(4, history_[current_]);
  classify_.set_arg(5, history_[next]);
  classify_.set_arg(10, same_list);
  classify_.set_arg(12, overlap_list_);
  classify_.set_arg(13, live_);
  cl_.enqueue(classify_, count);
  forces_.set_arg(0, static_cast<cl_uint>(count));
  forces_.set_arg(1, list_keys);
  forces_.set_arg(2, static_cast<cl_uint>(count_));
  forces_.set_arg(3, keys_);
  forces_.set_arg(4, history_[current_]);
  forces_.set_arg(5, history_[next]);
  forces_.set_arg(14, static_cast<real>(dt));
  forces_.set_arg(20, same_list);
  forces_.set_arg(21, overlap_list_);
  forces_.set_arg(22, live_);
  forces_.set_arg(23, static_cast<cl_uint>(energy_row ? 1 : 0));
  forces_.set_arg(24, couple_stored_);
  // Joins since the last list (activation runs before detection in a step, so a join in
  // the last list's own step was in that list): stamps ≥ last_list_step_ + 3.
  forces_.set_arg(26, static_cast<cl_uint>(ContactActivation::join_stamp(last_list_step_ + 1)));
  if (new_list) last_list_step_ = step;
  cl_.enqueue(forces_, count);
  if (energy_row) {
    stored_groups_ = work_groups(cl_, count);
    if (count > 0) {
      stored_partials_.set_arg(0, static_cast<cl_uint>(count));
      stored_partials_.set_arg(1, couple_stored_);
      stored_partials_.set_arg(2, stored_slots_);
      cl_.enqueue(stored_partials_, count);
    }
  }
  if (new_list) {
    if (count > capacity_) {
      capacity_ = grown(count);
      keys_ = cl_.allocate(capacity_ * sizeof(cl_ulong), "contact_keys");  // the kernel holds the old one
      history_[current_] = cl_.allocate(capacity_ * kHistory * sizeof(real), "contact_history");
    }
    if (count) cl_.queue().enqueue_copy_buffer(keys, keys_, 0, 0, count * sizeof(cl_ulong));
    current_ = next;
    count_ = count;
  }
}

size_t ContactForces::touching() {
  if (count_ == 0) return 0;
  const auto live = download<cl_uchar>(cl_, live_, count_);
  return static_cast<size_t>(std::count(live.begin(), live.end(), cl_uchar{1}));
}

std::vector<cl_long> ContactForces::energy_account() { return download<cl_long>(cl_, energy_, 2); }

double ContactForces::stored_energy() { return sum_group_slots(cl_, stored_slots_, stored_groups_, 1)[0]; }

void ContactForces::allocate_stored(size_t couples) {
  couple_stored_ = cl_.allocate(std::max<size_t>(1, couples) * sizeof(real), "contact couple_stored");
  stored_slots_ = cl_.allocate(std::max<size_t>(1, work_groups(cl_, couples)) * sizeof(real), "contact stored slots");
}
double ContactForces::friction_dissipation() { return static_cast<double>(energy_account()[0]) / energy_scale_; }
double ContactForces::damping_dissipation() { return static_cast<double>(energy_account()[1]) / energy_scale_; }

double ContactForces::dissipated_energy() {
  const auto e = energy_account();
  return static_cast<double>(e[0] + e[1]) / energy_scale_;
}

std::vector<real> ContactForces::history() { return download<real>(cl_, history_[current_], count_ * kHistory); }
std::vector<cl_ulong> ContactForces::keys() { return download<cl_ulong>(cl_, keys_, count_); }
std::vector<real> ContactForces::couple_stored() { return download<real>(cl_, couple_stored_, count_); }

void ContactForces::save_state(StateWriter& out) const {
  out.integer("contact_couples", static_cast<std::int64_t>(count_));
  out.integer("contact_last_list_step", static_cast<std::int64_t>(last_list_step_));
  out.buffer<cl_ulong>("contact_keys", keys_, count_);
  out.buffer<real>("contact_history", history_[current_], count_, kHistory);
  out.buffer<cl_uchar>("contact_live", live_, count_);
  out.buffer<cl_long>("contact_energy", energy_, 2);
}

void ContactForces::load_state(StateReader& in) {
  count_ = static_cast<size_t>(in.integer("contact_couples"));
  last_list_step_ = static_cast<long>(in.integer("contact_last_list_step"));
  if (count_ > capacity_) {
    capacity_ = grown(count_);
    keys_ = cl_.allocate(capacity_ * sizeof(cl_ulong), "contact_keys");
    for (auto& h : history_) h = cl_.allocate(capacity_ * kHistory * sizeof(real), "contact_history");
  }
  if (count_ > list_capacity_) {
    list_capacity_ = grown(count_);
    overlap_list_ = cl_.allocate(list_capacity_ * sizeof(cl_uint), "contact overlap list");
    live_ = cl_.allocate(list_capacity_, "contact live flags");
    allocate_stored(list_capacity_);
  }
  in.buffer<cl_ulong>("contact_keys", keys_, count_);
  in.buffer<real>("contact_history", history_[current_], count_, kHistory);
  in.buffer<cl_uchar>("contact_live", live_, count_);
  in.buffer<cl_long>("contact_energy", energy_, 2);
}

}  // namespace fdem
