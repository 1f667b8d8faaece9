#include "engine/stages/contact_activation.hpp"

namespace fdem {

ContactActivation::ContactActivation(ClContext& cl, const std::vector<std::array<int, 2>>& ce4_triangles,
                                     compute::buffer& status, compute::buffer& active, compute::buffer& monitor)
    : cl_(cl), count_(ce4_triangles.size()) {
  std::vector<cl_uint> pairs;
  for (const auto& t : ce4_triangles) pairs.insert(pairs.end(), {cl_uint(t[0]), cl_uint(t[1])});
  triangles_ = cl.allocate(std::max<size_t>(pairs.size(), 2) * sizeof(cl_uint), "ce4_triangles");
  if (!pairs.empty()) upload(cl, triangles_, pairs);
  kernel_ = compute::kernel(cl.build("contact_activation"), "activate_broken");
  kernel_.set_arg(0, static_cast<cl_uint>(count_));
  kernel_.set_arg(1, status);
  kernel_.set_arg(2, triangles_);
  kernel_.set_arg(3, active);
  kernel_.set_arg(4, monitor);
}

void ContactActivation::enqueue(unsigned slot, long step) {
  if (count_ == 0) return;
  kernel_.set_arg(5, static_cast<cl_uint>(slot));
  kernel_.set_arg(6, join_stamp(step));
  cl_.enqueue(kernel_, count_);
}

}  // namespace fdem
