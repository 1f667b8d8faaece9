// Stage: skin rebuild test for contact detection (cl_kernels/contact_skin.cl).
#pragma once
#include "engine/device_arrays.hpp"

namespace fdem {

class ContactSkin {
 public:
  ContactSkin(ClContext& cl, DeviceArrays& arrays);
  // Remembers the current positions as those of the last detection. Never waits.
  void mark();
  // The largest distance a node moved since mark() [m] (waits; rounded up to float).
  double largest_move();

 private:
  ClContext& cl_;
  DeviceArrays& arrays_;
  compute::kernel kernel_;
  compute::buffer at_build_, result_;
};

}  // namespace fdem
