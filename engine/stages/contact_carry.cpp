#include "engine/stages/contact_carry.hpp"

#include <map>
#include <string>

#include "engine/model/layouts.hpp"

namespace fdem {

MemoryPlan ContactCarry::carry_list(size_t capacity) {
  return MemoryPlan()
      .add("contact carry keys", capacity * sizeof(cl_ulong))
      .add("contact carry history", capacity * layout::CONTACT_HISTORY * sizeof(real));
}

MemoryPlan ContactCarry::offsets(size_t list_capacity, size_t group_size) {
  return MemoryPlan().add("contact carry offsets", std::max<size_t>(1, groups_for(list_capacity, group_size)) * sizeof(cl_uint));
}

MemoryPlan ContactCarry::plan(size_t triangles, size_t list_capacity, size_t group_size) {
  return MemoryPlan()
      .add(carry_list(first_capacity(triangles)))
      .add("contact carry count", sizeof(cl_uint))
      .add(offsets(list_capacity, group_size));
}

ContactCarry::ContactCarry(ClContext& cl, size_t triangles, size_t list_capacity)
    : cl_(cl), capacity_(first_capacity(triangles)), offsets_capacity_(list_capacity) {
  const MemoryPlan arrays = plan(triangles, list_capacity, cl.group_size());
  keys_ = arrays.allocate(cl, "contact carry keys");
  history_ = arrays.allocate(cl, "contact carry history");
  count_ = arrays.allocate(cl, "contact carry count");
  offsets_ = arrays.allocate(cl, "contact carry offsets");
  const std::map<std::string, std::string> defines{{"GROUP_SIZE", std::to_string(cl.group_size())},
                                                   {"NO_SLOT", std::to_string(kNoSlot) + "u"}};
  const auto program = cl.build(kernel_source::contact_carry, defines);
  count_kernel_ = compute::kernel(program, "carry_count");
  offsets_kernel_ = compute::kernel(program, "carry_offsets");
  scatter_kernel_ = compute::kernel(program, "carry_scatter");
  locate_kernel_ = compute::kernel(program, "carry_locate");
}

void ContactCarry::locate(const compute::buffer& keys, size_t count, size_t carried, const compute::buffer& carry_of) {
  if (count == 0) return;
  const cl_uint none = kNoSlot;
  cl_.queue().enqueue_fill_buffer(carry_of, &none, sizeof(none), 0, count * sizeof(cl_uint));
  if (carried == 0) return;
  bind_args(locate_kernel_)("n_carried", static_cast<cl_uint>(carried))("carry_keys", keys_)(
      "n_couples", static_cast<cl_uint>(count))("keys", keys)("carry_of", carry_of)
      .done();
  cl_.enqueue(locate_kernel_, carried);
}

size_t ContactCarry::carry(const compute::buffer& keys, const compute::buffer& history, const compute::buffer& slot,
                           const compute::buffer& live, const compute::buffer& active, size_t n_couples,
                           cl_uint joined_since) {
  if (n_couples == 0) return 0;
  if (n_couples > offsets_capacity_) {
    offsets_capacity_ = n_couples;
    offsets_ = offsets(offsets_capacity_, cl_.group_size()).allocate(cl_, "contact carry offsets");
  }
  const cl_uint n = static_cast<cl_uint>(n_couples), groups = static_cast<cl_uint>(groups_for(n_couples, cl_.group_size()));
  bind_args(count_kernel_)("n_couples", n)("live", live)("keys", keys)("active", active)("joined_since", joined_since)(
      "group_counts", offsets_)
      .done();
  cl_.enqueue(count_kernel_, n_couples);
  bind_args(offsets_kernel_)("n_groups", groups)("group_counts", offsets_)("carry_count", count_).done();
  cl_.enqueue(offsets_kernel_, cl_.group_size());  // one work-group
  const size_t carried = download<cl_uint>(cl_, count_, 1)[0];
  if (carried > capacity_) {
    capacity_ = grown(carried);
    const MemoryPlan list = carry_list(capacity_);
    keys_ = list.allocate(cl_, "contact carry keys");
    history_ = list.allocate(cl_, "contact carry history");
  }
  if (carried == 0) return 0;
  bind_args(scatter_kernel_)("n_couples", n)("live", live)("keys", keys)("active", active)("joined_since", joined_since)(
      "history", history)("slot", slot)("group_offsets", offsets_)("carry_keys", keys_)("carry_history", history_)
      .done();
  cl_.enqueue(scatter_kernel_, n_couples);
  return carried;
}

}  // namespace fdem
