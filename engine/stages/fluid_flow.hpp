// Stage: fluid in the cracks (cl_kernels/fluid_flow.cl; docs/case-format.md "[fluid]").
// Cubic-law flow along the broken CE4s between the network's vertices, a slightly
// compressible fluid (K_f), a source (rate or pressure), and the pressure on the faces
// written into four slots per CE4 that the node gather adds through the CE4 map.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "engine/device/checkpoint.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/device/kernel_args.hpp"
#include "engine/device/memory_plan.hpp"
#include "engine/device/row_reads.hpp"
#include "engine/energy/energy.hpp"
#include "engine/model/fluid_model.hpp"
#include "engine/model/model.hpp"
#include "engine/stages/fluid_carriers.hpp"

namespace fdem {

class FluidFlow {
 public:
  // Builds the network of model.fluid on the device. `status`: CohesiveForces::status();
  // the CE4s on the case's crack are set broken (closed, status 1) there, once: a
  // restart's checkpoint then overwrites it with its own. `gauss_state`:
  // CohesiveForces::gauss_state(), read when softened CE4s carry fluid (fluid.segments).
  // `carriers` (CohesiveForces::fluid_carriers(), or none): the list of the carrying CE4s
  // that the fused step (fluid_step_group) walks instead of every CE4.
  FluidFlow(ClContext& cl, const Model& model, compute::buffer& position, compute::buffer& status,
            compute::buffer& gauss_state, double dt, const FluidCarriers* carriers = nullptr);
  static MemoryPlan plan(const Model& model);
  // Sub-steps of the flow per mechanical step of `dt`: ceil(dt / (safety × stable_dt)).
  static long substeps(const FluidModel& fluid, double dt);

  // The step at time t (positions of the step's start): apertures, volumes, `substeps`
  // flow sub-steps over [t, t + dt], the pressures' forces into slots(). Never waits.
  void enqueue(double time, long step);
  compute::buffer& slots() { return slots_; }  // real2 ×4 per CE4 (i, j, j', i') [N]
  // uchar per node: 1 once some CE4 at the node has had its fluid forces written (the
  // gather reads the fluid slots only there; elsewhere they are the +0s they were made
  // with). Only ever set, by the step's forces pass, before the gather reads it.
  compute::buffer& loaded_nodes() { return loaded_node_; }
  // [fluid.gas]: the hole's gas, one real4 (p [Pa], V [m³], V₀ left [m³], U [J]) as the
  // end of the last step left it (BoundaryLoads' LOAD_GAS edges read p).
  compute::buffer& gas_hole() { return gas_hole_; }

  // The fluid's terms of the account and its history figures, summed in item order.
  EnergyPart queue_energy(const ItemSums& sums);
  // The first CE4 that opened wider than fluid.max_aperture and the step (waits; -1: none).
  std::pair<int, int> too_wide();
  // The same read queued with a row's (RowReads), and the check of what it read: a
  // NumericalError naming the CE4, the step and the key when some segment was too wide
  // (the stable fluid step assumed fluid.max_aperture).
  std::function<std::vector<cl_int>()> queue_too_wide(RowReads& reads) { return reads.read<cl_int>(too_wide_, 2); }
  void check_too_wide(const std::vector<cl_int>& words) const;
  // Per vertex (V₀, V, p, U) (waits; tests and output).
  std::vector<real4> vertex_state();
  // Per vertex the room's change over the last step, ΔV (the forces' mid-step prediction; waits; tests).
  std::vector<real> vertex_rate();
  // Per CE4 the mean pressure of its two vertices [Pa] and its mean aperture w_m [m] as
  // this step's flow had them; both 0 on a segment that carries no fluid (waits; frames).
  void segment_fields(std::vector<real>& pressure, std::vector<real>& aperture);
  const FluidModel& network() const { return fluid_; }
  long substeps() const { return substeps_; }
  bool one_group() const { return one_group_; }  // the sub-steps in one work-group's launch
  bool fused() const { return fused_; }          // the whole step in one work-group's launch
  bool adaptive() const { return adaptive_; }     // as many sub-steps as the network's rate asks
  // The fused step rides as the first work-group of the triangle stage's launch
  // (TriangleForces, cl_kernels/triangle_forces.cl FLUID_HEAD): that program is built with
  // head_defines() and fluid_laws.cl and fluid_flow.cl as libraries, binds its own
  // position, thickness, step and (adaptive) dt, then bind_step's arguments
  // (FLUID_STEP_ARGS). enqueue() then launches only the lists' rescans, so it must come
  // before the triangle stage's enqueue in a step. FDEM_FLUID_HEAD=1 only, for now; the
  // headed step always takes the group's global path (head_defines()).
  bool headed() const { return headed_; }
  std::map<std::string, std::string> head_defines() const;
  void bind_step(KernelArgs& args) const;

  void save_state(StateWriter& out) const;
  void load_state(StateReader& in);

 private:
  ClContext& cl_;
  FluidModel fluid_;
  size_t ce4_, vertices_;
  double dt_, thickness_;
  long substeps_;
  double source_share_;  // a rate source's share per vertex: 1 / number of source vertices
  compute::kernel segments_, vertices_kernel_, forces_;
  compute::kernel substep_[2];  // fluid_substep reading front_ (writing back_), and the other way
  KernelArg<cl_int> step_;
  KernelArg<real> source_value_[2], sub_time_[2];
  compute::buffer nodes_, seg_vertex_, seg_h_, seg_geom_, front_, back_, wet_, wet_count_, vertex_start_, vertex_end_, source_,
      vertex_state_, vertex_energy_, too_wide_, slots_, loaded_node_;
  compute::buffer seg_exposed_;  // per CE4: Carter's exposure time [s], -1 before (leak-off only)
  compute::buffer vertex_leak_;  // per vertex: leaked V₀ [m³], the energy it took [J], cumulative
  compute::kernel hole_kernel_;  // gas_hole_state ([fluid.gas])
  // fluid_substeps_group: every sub-step of a step in one work-group of kFluidGroup items.
  static constexpr size_t kFluidGroup = 256, kFluidGroupWide = 1024, kFluidGroupUpTo = 16384;
  // fluid_step_group (FUSED): the liquid's whole step in one work-group over the network's
  // lists; fluid_network_clear and fluid_network_scan rebuild them (rescan_) before the
  // first step and after a checkpoint is restored.
  bool fused_ = false, rescan_ = true, headed_ = false;
  // What bind_step binds beside the stage's own arrays: the cohesive stage's carriers,
  // status and Gauss-point state, and the step's constants.
  struct StepOperands {
    const FluidCarriers* carriers = nullptr;
    compute::buffer status, gauss_state;
    real source_value = 0, dt_sub = 0, bulk = 0;
  } step_operands_;
  std::map<std::string, std::string> defines_;  // the stage program's
  compute::kernel fused_kernel_, network_clear_, network_scan_;
  KernelArg<cl_int> fused_step_;
  compute::buffer in_net_, net_vertices_, net_count_;  // per vertex: in the network; the list; (length, carriers joined)
  size_t fluid_group_ = kFluidGroup;  // its work-items (the program's FLUID_GROUP)
  bool one_group_ = false;
  bool adaptive_ = false;  // sub-steps from the network's rate (ADAPTIVE in fluid_flow.cl)
  KernelArg<cl_uint> k_sub_[2];
  compute::kernel group_kernel_;
  compute::buffer gas_hole_, hole_polygon_, hole_sources_;
  compute::buffer seg_joined_;  // per CE4 (gas): 1 in the step it joined the network
  compute::buffer vertex_rate_;  // per vertex: its volume's change over the last step (gas: joins excluded) [m³]
};

}  // namespace fdem
