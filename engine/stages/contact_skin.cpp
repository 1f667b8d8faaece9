#include "engine/stages/contact_skin.hpp"

#include <cmath>
#include <cstring>

namespace fdem {

ContactSkin::ContactSkin(ClContext& cl, DeviceArrays& a) : cl_(cl), arrays_(a) {
  at_build_ = cl.allocate(a.num_nodes * sizeof(real2), "position_at_build");
  result_ = cl.allocate(sizeof(cl_uint), "largest_move");
  kernel_ = compute::kernel(cl.build("contact_skin"), "max_displacement");
  kernel_.set_arg(0, static_cast<cl_uint>(a.num_nodes));
  kernel_.set_arg(1, a.position);
  kernel_.set_arg(2, at_build_);
  kernel_.set_arg(3, result_);
}

void ContactSkin::mark() {
  cl_.queue().enqueue_copy_buffer(arrays_.position, at_build_, 0, 0, arrays_.num_nodes * sizeof(real2));
}

double ContactSkin::largest_move() {
  upload(cl_, result_, std::vector<cl_uint>{0});
  cl_.enqueue(kernel_, arrays_.num_nodes);
  const cl_uint bits = download<cl_uint>(cl_, result_, 1)[0];
  float moved;
  std::memcpy(&moved, &bits, sizeof moved);
  return std::nextafter(static_cast<double>(moved), 1e300);
}

}  // namespace fdem
