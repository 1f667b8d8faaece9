#include "engine/stages/contact_skin.hpp"

#include <cmath>
#include <cstring>
#include <string>

namespace fdem {

namespace {

double as_value(cl_uint bits) {
  float value;
  std::memcpy(&value, &bits, sizeof value);
  // The device rounded the double to float; step up one double so the value is not below it.
  return std::nextafter(static_cast<double>(value), 1e300);
}

}  // namespace

ContactSkin::ContactSkin(ClContext& cl, DeviceArrays& a, double skin, double dt)
    : cl_(cl), arrays_(a), half_skin_(0.5 * skin), dt_(dt), host_(4 * kSlots, 0) {
  at_build_ = cl.allocate(a.num_nodes * sizeof(real2), "position_at_build");
  monitor_ = cl.allocate(4 * kSlots * sizeof(cl_uint), "skin monitor ring");
  upload(cl, monitor_, host_);
  kernel_ = compute::kernel(cl.build("contact_skin", {{"GROUP_SIZE", std::to_string(cl.group_size())}}), "max_displacement");
  kernel_.set_arg(0, static_cast<cl_uint>(a.num_nodes));
  kernel_.set_arg(1, a.position);
  kernel_.set_arg(2, a.velocity);
  kernel_.set_arg(3, at_build_);
  kernel_.set_arg(4, monitor_);
}

void ContactSkin::mark() {
  cl_.queue().enqueue_copy_buffer(arrays_.position, at_build_, 0, 0, arrays_.num_nodes * sizeof(real2));
  ++generation_;
}

bool ContactSkin::decide(unsigned slot, bool exact) {
  reads_[slot].wait();
  pending_[slot] = false;
  const cl_uint* w = &host_[4 * slot];
  const double moved = as_value(w[0]);
  largest_speed_ = as_value(w[1]);
  if (generation_of_[slot] != generation_) return false;  // measured against an older detection
  if (w[2] != 0) return true;                              // triangles joined the candidates
  const double margin = exact ? 0.0 : 2.0 * kSlots * largest_speed_ * dt_;
  return !(moved + margin <= half_skin_);                  // NaN: rebuild (the NaN check stops the run)
}

bool ContactSkin::rebuild_due(long step) {
  const unsigned slot = slot_of(step), next = slot_of(step + 1);
  // The far margin would eat more than half of the half-skin: test this step exactly.
  const bool exact = !(2.0 * kSlots * largest_speed_ * dt_ <= 0.5 * half_skin_);
  // The oldest test still in flight is the next slot's: read it before its words are
  // cleared (its activation flag counts in both modes).
  bool due = pending_[next] && decide(next, false);
  kernel_.set_arg(5, static_cast<cl_uint>(slot));
  kernel_.set_arg(6, static_cast<cl_uint>(next));
  cl_.enqueue(kernel_, arrays_.num_nodes);
  reads_[slot] = cl_.queue().enqueue_read_buffer_async(monitor_, 4 * slot * sizeof(cl_uint), 4 * sizeof(cl_uint),
                                                       &host_[4 * slot]);
  generation_of_[slot] = generation_;
  pending_[slot] = true;
  if (exact) {
    ++synchronous_;
    due = decide(slot, true) || due;
  }
  return due;
}

}  // namespace fdem
