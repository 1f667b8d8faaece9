// Contact history carry-over at a new detection (cl_kernels/contact_carry.cl), for
// ContactForces: the couples that hold a history are copied to a compact list, so the
// contact stage keeps one history array, rewritten in place by each new list.
#pragma once
#include <algorithm>

#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/memory_plan.hpp"

namespace fdem {

class ContactCarry {
 public:
  // `list_capacity`: the couples the contact list holds at first.
  ContactCarry(ClContext& cl, size_t triangles, size_t list_capacity);
  // An empty entry of the contact stage's slot array (the couple holds no history row).
  static constexpr cl_uint kNoSlot = 0xffffffffu;
  // The carry list at first (one couple per four triangles, at least 1024: the bench's
  // 1.08M-TRI3 model has 0.2-0.3 touching couples per TRI3 once the CE4s' own couples are
  // left to the CE4s), and the capacity it grows to when `count` couples must be carried
  // (an eighth more; carry() reads the count anyway).
  static size_t first_capacity(size_t triangles) { return std::max<size_t>(1024, triangles / 4); }
  static size_t grown(size_t count) { return count + count / 8 + 1024; }
  // The arrays the constructor allocates.
  static MemoryPlan plan(size_t triangles, size_t list_capacity, size_t group_size);
  // The carry list of `capacity` couples: keys and histories.
  static MemoryPlan carry_list(size_t capacity);
  // The per-work-group offsets for a contact list of `list_capacity` couples.
  static MemoryPlan offsets(size_t list_capacity, size_t group_size);

  // Copies the couples of the list (`keys`, `live`, n_couples of them; couple c's history
  // at row slot[c] of the pool `history`, none when kNoSlot) that hold a history (live
  // flag nonzero) or of which a triangle's `active` mask value is at least `joined_since`,
  // in list order, to keys() and history(); returns their number. Waits once (for the
  // number, to grow the carry list when it does not fit).
  size_t carry(const compute::buffer& keys, const compute::buffer& history, const compute::buffer& slot,
               const compute::buffer& live, const compute::buffer& active, size_t n_couples, cl_uint joined_since);
  // For a new list of `count` keys (ascending): carry_of[c] = the carry-list row of couple
  // c, NO_SLOT for couples that were not carried. Never waits.
  void locate(const compute::buffer& keys, size_t count, size_t carried, const compute::buffer& carry_of);
  const compute::buffer& keys() const { return keys_; }
  const compute::buffer& history() const { return history_; }
  size_t capacity() const { return capacity_; }

 private:
  ClContext& cl_;
  size_t capacity_, offsets_capacity_;
  compute::buffer keys_, history_, count_, offsets_;
  compute::kernel count_kernel_, offsets_kernel_, scatter_kernel_, locate_kernel_;
};

}  // namespace fdem
