// Stage: extrinsic cohesive elements (fracture.model = "extrinsic"; cl_kernels/extrinsic.cl):
// after the integration, the copies of each mesh vertex joined through uninserted CE4s are
// moved as one (extrinsic_tie), then every CE4 whose edge's traction has reached the peak
// is inserted (extrinsic_insert). Its state (the flags, offsets and count) is the CE4
// stage's arrays (CohesiveForces::inserted(), ...), saved with them.
#pragma once
#include "engine/device/cl_context.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/memory_plan.hpp"
#include "engine/model/extrinsic.hpp"
#include "engine/model/model.hpp"
#include "engine/stages/cohesive_forces.hpp"

namespace fdem {

class Extrinsic {
 public:
  // Builds the tie lists (extrinsic_ties), uploads them, compiles and binds both kernels.
  // The model has no mass scaling (refused: node_mass is one real, the mass).
  Extrinsic(ClContext& cl, DeviceArrays& arrays, const Model& model, CohesiveForces& cohesive);
  // The arrays the constructor allocates for `model`.
  static MemoryPlan plan(const Model& model);
  // The tie (after the integration), then the insertions (reading this step's corner
  // forces and the tied positions); a split run exchanges its ghost nodes between the
  // two (Solver::step). Never wait.
  void enqueue_tie();
  void enqueue_insert();
  // After the CE4 flags were loaded (a checkpoint): marks every vertex with an inserted
  // CE4 at it, so the tie's fast path skips it (the insertion marks its own). Never waits.
  void mark_inserted();

 private:
  ClContext& cl_;
  size_t vertices_, ce4_;
  compute::kernel tie_, insert_, mark_;
  compute::buffer copy_start_, copy_node_, link_start_, link_, whole_, opposite_, ce4_vertex_;
};

}  // namespace fdem
