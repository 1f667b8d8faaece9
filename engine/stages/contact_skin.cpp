#include "engine/stages/contact_skin.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "base/errors.hpp"

namespace fdem {

namespace {

double as_value(cl_uint bits) {
  float value;
  std::memcpy(&value, &bits, sizeof value);
  // The device rounded the double to float; step up one double so the value is not below it.
  return std::nextafter(static_cast<double>(value), 1e300);
}

}  // namespace

ContactSkin::ContactSkin(ClContext& cl, DeviceArrays& a, MonitorRing& ring, double skin, double dt,
                         const std::vector<char>& node_owned)
    : cl_(cl), arrays_(a), half_skin_(0.5 * skin), dt_(dt), ring_(ring), host_(cl, layout::RING_WORDS * kSlots) {
  owned_ = !node_owned.empty();
  const MemoryPlan arrays = plan(a.num_nodes, owned_);
  at_build_ = arrays.allocate(cl, "position_at_build");
  if (owned_) {
    if (node_owned.size() != a.num_nodes) throw DeviceError("contact skin: the owned-node mask has the wrong size");
    node_owned_ = arrays.allocate(cl, "skin node_owned");
    upload(cl, node_owned_, std::vector<cl_uchar>(node_owned.begin(), node_owned.end()));
  }
}

void ContactSkin::adapt(double box_side, size_t triangles) {
  adaptive_ = box_side > 0 && std::isfinite(box_side);
  box_side_ = box_side;
  triangles_ = triangles;
}

double ContactSkin::choose(size_t listed) {
  if (!adaptive_) return skin();
  const double now = skin(), v = largest_speed_;
  if (v > 0 && std::isfinite(v) && dt_ > 0) {
    const double b = box_side_, lo = std::max(0.5 * now, 1e-3 * b), hi = std::min(2.0 * now, b);
    const double count = static_cast<double>(std::max<size_t>(listed, 1));
    auto cost = [&](double s) {
      const double grown = (b + s) / (b + now);
      const double list = count * grown * grown;
      const double detection = kDetectionFixed + kDetectionPerTriangle * static_cast<double>(triangles_) +
                               kDetectionPerCouple * list;
      const double steps = std::max(1.0, s / (2.0 * v * dt_));
      return detection / steps + list;
    };
    if (lo < hi) {
      double best = now, best_cost = cost(now);
      constexpr int kPoints = 64;
      for (int k = 0; k <= kPoints; ++k) {
        const double s = lo * std::pow(hi / lo, static_cast<double>(k) / kPoints);
        const double c = cost(s);
        if (c < best_cost) best = s, best_cost = c;
      }
      half_skin_ = 0.5 * best;
    }
  }
  const double picked = skin();
  smallest_skin_ = smallest_skin_ > 0 ? std::min(smallest_skin_, picked) : picked;
  largest_skin_ = std::max(largest_skin_, picked);
  return picked;
}

void ContactSkin::mark() {
  cl_.queue().enqueue_copy_buffer(arrays_.position, at_build_, 0, 0, arrays_.num_nodes * sizeof(real2));
  ++generation_;
  pool_seen_ = 0;  // a new list empties the contact history pool
}

namespace {
ContactSkin::Due worst(ContactSkin::Due a, ContactSkin::Due b) { return a > b ? a : b; }
}  // namespace

ContactSkin::Due ContactSkin::decide(unsigned slot, bool exact) {
  const cl_uint* w = &host_[layout::RING_WORDS * slot];
  const double moved = as_value(w[layout::RING_MOVED]);
  largest_speed_ = std::max(largest_speed_, as_value(w[layout::RING_SPEED]));
  if (generation_of_[slot] != generation_) return Due::Nothing;  // measured against an older detection
  pool_seen_ = std::max<size_t>(pool_seen_, w[layout::RING_POOL]);
  const double margin = exact ? 0.0 : 2.0 * kSlots * largest_speed_ * dt_;
  if (!(moved + margin <= half_skin_)) return Due::Moved;  // NaN: rebuild (the NaN check stops the run)
  // Triangles joined the candidates in a step whose joins the list does not hold yet.
  return w[layout::RING_JOINED] != 0 && step_of_[slot] > joins_covered_step_ ? Due::Joined : Due::Nothing;
}

ContactSkin::Due ContactSkin::decide_batch() {
  if (batch_read_.get()) batch_read_.wait();  // none after a restart: the checkpoint held the batch
  batch_pending_ = false;
  if (reduce_) reduce_(&host_[layout::RING_WORDS * batch_first_], kBatch);
  speed_known_ = true;
  largest_speed_ = 0;  // the batch's own speeds (decide() takes their maximum)
  Due due = Due::Nothing;
  for (unsigned k = 0; k < kBatch; ++k) due = worst(decide(batch_first_ + k, false), due);
  // The most history pool rows taken in one step (consecutive slots of this detection),
  // the batch's own, like the speeds.
  pool_rate_ = 0;
  for (unsigned k = 1; k < kBatch; ++k) {
    const unsigned a = batch_first_ + k - 1, b = batch_first_ + k;
    if (generation_of_[a] != generation_ || generation_of_[b] != generation_) continue;
    const cl_uint before = host_[layout::RING_WORDS * a + layout::RING_POOL], after = host_[layout::RING_WORDS * b + layout::RING_POOL];
    if (after > before) pool_rate_ = std::max<size_t>(pool_rate_, after - before);
  }
  return due;
}

void ContactSkin::measured(long step) {
  generation_of_[MonitorRing::slot_of(step)] = generation_;
  step_of_[MonitorRing::slot_of(step)] = step;
}

ContactSkin::Due ContactSkin::rebuild_due(long step) {
  const unsigned slot = MonitorRing::slot_of(step);
  const bool batch_ends = slot % kBatch == kBatch - 1;
  // The far margin would eat more than half of the half-skin: test this step exactly.
  // Until a first batch has told the speeds, every step is exact too.
  const bool exact = !speed_known_ || !(2.0 * kSlots * largest_speed_ * dt_ <= 0.5 * half_skin_);
  Due due = Due::Nothing;
  // The batch read kBatch steps ago: look at it before its slots are measured again.
  if (batch_ends && batch_pending_) due = decide_batch();
  if (exact) {
    ++synchronous_;
    constexpr size_t words = layout::RING_WORDS;
    cl_.queue().enqueue_read_buffer(ring_.buffer(), words * slot * sizeof(cl_uint), words * sizeof(cl_uint),
                                    &host_[words * slot]);
    if (reduce_) reduce_(&host_[words * slot], 1);
    const double speed_before = largest_speed_;
    due = worst(decide(slot, true), due);
    largest_speed_ = std::max(speed_before, largest_speed_);
  }
  if (batch_ends) {
    batch_first_ = slot + 1 - kBatch;
    constexpr size_t words = layout::RING_WORDS;
    batch_read_ = cl_.queue().enqueue_read_buffer_async(ring_.buffer(), words * batch_first_ * sizeof(cl_uint),
                                                        words * kBatch * sizeof(cl_uint), &host_[words * batch_first_]);
    batch_pending_ = true;
  }
  return due;
}

void ContactSkin::save_state(StateWriter& out) {
  cl_.finish();  // a batch read in flight lands in host_
  out.buffer<real>("skin_position_at_build", at_build_, arrays_.num_nodes, 2);
  out.buffer<cl_uint>("skin_ring", ring_.buffer(), layout::RING_WORDS * kSlots);
  out.host<cl_uint>("skin_ring_read", host_.data(), host_.size());
  std::vector<cl_long> generations(generation_of_.begin(), generation_of_.end());
  generations.push_back(generation_);
  out.host<cl_long>("skin_generations", generations.data(), generations.size());
  out.integer("skin_batch_first", batch_first_);
  out.integer("skin_flags", (batch_pending_ ? 1 : 0) | (speed_known_ ? 2 : 0));
  out.number("skin_largest_speed", largest_speed_);
  out.integer("skin_synchronous", synchronous_);
  out.number("skin_current", skin());  // an adaptive skin's last pick (the positions above were marked with it)
  out.number("skin_smallest", smallest_skin_);
  out.number("skin_largest", largest_skin_);
  std::vector<cl_long> steps(step_of_.begin(), step_of_.end());
  steps.push_back(joins_covered_step_);
  out.host<cl_long>("skin_slot_steps", steps.data(), steps.size());
}

void ContactSkin::load_state(StateReader& in) {
  in.buffer<real>("skin_position_at_build", at_build_, arrays_.num_nodes, 2);
  in.buffer<cl_uint>("skin_ring", ring_.buffer(), layout::RING_WORDS * kSlots);
  in.host<cl_uint>("skin_ring_read", host_.data(), host_.size());
  std::vector<cl_long> generations(kSlots + 1);
  in.host<cl_long>("skin_generations", generations.data(), generations.size());
  for (unsigned k = 0; k < kSlots; ++k) generation_of_[k] = generations[k];
  generation_ = generations[kSlots];
  batch_first_ = static_cast<unsigned>(in.integer("skin_batch_first"));
  const auto flags = in.integer("skin_flags");
  batch_pending_ = flags & 1;
  speed_known_ = flags & 2;
  largest_speed_ = in.number("skin_largest_speed");
  synchronous_ = static_cast<long>(in.integer("skin_synchronous"));
  // Checkpoints written before adaptive skins: the skin was fixed, the model's own.
  if (in.has_number("skin_current")) {
    const double current = in.number("skin_current");
    if (!(current > 0) || !std::isfinite(current))
      throw InputError("checkpoint: skin_current = " + std::to_string(current) + " is not a length above 0");
    half_skin_ = 0.5 * current;
    smallest_skin_ = in.number("skin_smallest");
    largest_skin_ = in.number("skin_largest");
  }
  // Checkpoints written before lists were extended: every join flag counts again (an
  // extension that finds nothing new costs a count, no couple twice).
  std::vector<cl_long> steps(kSlots + 1, -1);
  if (in.has("skin_slot_steps")) in.host<cl_long>("skin_slot_steps", steps.data(), steps.size());
  for (unsigned k = 0; k < kSlots; ++k) step_of_[k] = in.has("skin_slot_steps") ? steps[k] : 0;
  joins_covered_step_ = steps[kSlots];
  batch_read_ = compute::event();
}

}  // namespace fdem
