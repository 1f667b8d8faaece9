// Stage: contact activation "fractured" (cl_kernels/contact_activation.cl).
#pragma once
#include <array>
#include <vector>

#include "engine/cl_context.hpp"
#include "engine/device_arrays.hpp"

namespace fdem {

class ContactActivation {
 public:
  // `status`: the CE4 stage's (broken, mode) per CE4; `active`: the detection's
  // candidate mask (one uint per triangle).
  ContactActivation(ClContext& cl, const std::vector<std::array<int, 2>>& ce4_triangles, compute::buffer& status,
                    compute::buffer& active);
  // Marks the triangles of broken CE4s as candidates; true when any joined (waits).
  bool update();

 private:
  ClContext& cl_;
  size_t count_;
  compute::kernel kernel_;
  compute::buffer triangles_, changed_;
};

}  // namespace fdem
