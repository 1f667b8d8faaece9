#include "engine/stages/contact_activation.hpp"

#include <algorithm>

namespace fdem {

MemoryPlan ContactActivation::plan(size_t ce4) {
  return MemoryPlan().add("ce4_triangles", std::max<size_t>(2 * ce4, 2) * sizeof(cl_uint));
}

ContactActivation::ContactActivation(ClContext& cl, const std::vector<std::array<int, 2>>& ce4_triangles,
                                     compute::buffer& status, compute::buffer& active, MonitorRing& ring)
    : cl_(cl), count_(ce4_triangles.size()) {
  std::vector<cl_uint> pairs;
  for (const auto& t : ce4_triangles) pairs.insert(pairs.end(), {cl_uint(t[0]), cl_uint(t[1])});
  triangles_ = plan(count_).allocate(cl, "ce4_triangles");
  if (!pairs.empty()) upload(cl, triangles_, pairs);
  kernel_ = compute::kernel(cl.build(kernel_source::contact_activation), "activate_broken");
  KernelArgs args(kernel_);
  args("n_ce4", static_cast<cl_uint>(count_))("status", status)("ce4_triangles", triangles_)("active", active)(
      "monitor", ring.buffer());
  slot_ = args.later("slot", cl_uint(0));
  stamp_ = args.later("stamp", cl_uint(0));
  args.done();
}

void ContactActivation::enqueue(long step) {
  if (count_ == 0) return;
  slot_.set(MonitorRing::slot_of(step));
  stamp_.set(join_stamp(step));
  cl_.enqueue(kernel_, count_);
}

}  // namespace fdem
