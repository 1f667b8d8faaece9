#include "engine/stages/contact_activation.hpp"

namespace fdem {

ContactActivation::ContactActivation(ClContext& cl, const std::vector<std::array<int, 2>>& ce4_triangles,
                                     compute::buffer& status, compute::buffer& active)
    : cl_(cl), count_(ce4_triangles.size()) {
  std::vector<cl_uint> pairs;
  for (const auto& t : ce4_triangles) pairs.insert(pairs.end(), {cl_uint(t[0]), cl_uint(t[1])});
  triangles_ = cl.allocate(pairs.size() * sizeof(cl_uint), "ce4_triangles");
  changed_ = cl.allocate(sizeof(cl_uint), "activation_changed");
  upload(cl, triangles_, pairs);
  upload(cl, changed_, std::vector<cl_uint>{0});
  kernel_ = compute::kernel(cl.build("contact_activation"), "activate_broken");
  kernel_.set_arg(0, static_cast<cl_uint>(count_));
  kernel_.set_arg(1, status);
  kernel_.set_arg(2, triangles_);
  kernel_.set_arg(3, active);
  kernel_.set_arg(4, changed_);
}

bool ContactActivation::update() {
  cl_.enqueue(kernel_, count_);
  const bool changed = download<cl_uint>(cl_, changed_, 1)[0] != 0;
  if (changed) upload(cl_, changed_, std::vector<cl_uint>{0});
  return changed;
}

}  // namespace fdem
