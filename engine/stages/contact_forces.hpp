// Stage: contact forces between detected couples (cl_kernels/contact_forces.cl).
#pragma once
#include "engine/checkpoint.hpp"
#include "engine/device_arrays.hpp"
#include "engine/model.hpp"

namespace fdem {

class ContactForces {
 public:
  ContactForces(ClContext& cl, DeviceArrays& arrays, const Model& model);

  // Fixed-point scale: the contact force on a node is contact_acc / force_scale() [N].
  double force_scale() const { return force_scale_; }

  // Zeroes the contact accumulator and the overlap list length. Never waits.
  void enqueue_clear();
  // Forces of the couples in `keys` (sorted cl_ulong keys, i << 32 | j). With new_list the
  // keys come from a fresh detection and each couple's history is carried over from the
  // previous list by key; otherwise the list is the one of the last call. Never waits.
  void enqueue(const compute::buffer& keys, size_t count, bool new_list, double dt);

  size_t couples() const { return count_; }
  size_t touching();             // couples in contact in the last step (waits; counts live flags)
  // Friction (as it slips) + damping (when a couple lets go), cumulative [J] (waits).
  double dissipated_energy();
  std::vector<real> history();   // per couple, 10 reals (waits; for tests)
  std::vector<cl_ulong> keys();  // the current couple list (waits; for tests)

  // The couple list with each couple's history and live flag, and the energy sums (checkpoints).
  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  ClContext& cl_;
  DeviceArrays& arrays_;
  double force_scale_ = 1, energy_scale_ = 1;
  compute::kernel classify_, forces_, clear_, release_;
  compute::buffer keys_, history_[2], dissipated_, counters_, pair_index_, pair_props_, overlap_list_, live_;
  size_t capacity_ = 0, count_ = 0, list_capacity_ = 0;
  int current_ = 0;
};

}  // namespace fdem
