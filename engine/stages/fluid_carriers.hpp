// The CE4s that carry fluid, as the cohesive stage hands them to the fluid stage
// (CohesiveForces::fluid_carriers, FluidFlow). Carrying is irreversible (a broken CE4
// stays broken, D_max only grows), so the list only grows: cohesive_forces appends a CE4
// in the step it starts to carry, and FluidFlow rebuilds the list from the CE4s' state
// when it starts or restores a checkpoint. Its order depends on the atomics, its content
// does not, and the fluid stage's results do not depend on the order.
#pragma once
#include "engine/device/cl_context.hpp"

namespace fdem {

struct FluidCarriers {
  compute::buffer list;   // uint per CE4 (capacity): the carrying CE4s' indices
  compute::buffer count;  // one uint: the list's length
};

}  // namespace fdem
