#include "engine/stages/fluid_flow.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>

#include <climits>

#include "base/errors.hpp"
#include "engine/stages/triangle_forces.hpp"

namespace fdem {

MemoryPlan FluidFlow::plan(const Model& model) {
  const size_t ce4 = std::max<size_t>(model.ce4.size(), 1), v = std::max<size_t>(model.fluid.vertices, 1);
  const size_t nodes = std::max<size_t>(model.num_nodes(), 1);
  return MemoryPlan()
      .add("fluid ce4_nodes", ce4 * sizeof(cl_uint4))
      .add("fluid seg_vertex", ce4 * sizeof(cl_uint2))
      .add("fluid seg_h", ce4 * sizeof(real))
      .add("fluid seg_geom", ce4 * sizeof(real4))
      .add("fluid front", v * sizeof(real2))
      .add("fluid wet", v * sizeof(cl_uint))
      .add("fluid wet_count", 4 * sizeof(cl_uint))
      .add("fluid in_net", v * sizeof(cl_uint))
      .add("fluid net_vertices", v * sizeof(cl_uint))
      .add("fluid net_count", 2 * sizeof(cl_uint))
      .add("fluid back", v * sizeof(real2))
      .add("fluid slots", 4 * ce4 * sizeof(real2))
      .add("fluid loaded_node", nodes * sizeof(cl_uchar))
      .add("fluid vertex_start", (v + 1) * sizeof(cl_uint))
      .add("fluid vertex_end", 2 * ce4 * sizeof(cl_uint))
      .add("fluid source", v * sizeof(cl_uchar))
      .add("fluid vertex_state", v * sizeof(real4))
      .add("fluid vertex_energy", v * sizeof(real4))
      .add("fluid too_wide", 2 * sizeof(cl_int))
      .add("fluid seg_exposed", ce4 * sizeof(real))
      .add("fluid vertex_leak", v * sizeof(real2))
      .add("fluid gas_hole", sizeof(real4))
      .add("fluid seg_joined", (model.fluid.gas ? ce4 : 1) * sizeof(cl_uchar))
      .add("fluid vertex_rate", v * sizeof(real))
      .add("fluid hole_polygon", std::max<size_t>(model.fluid.hole_polygon.size(), 1) * sizeof(cl_uint))
      .add("fluid hole_sources", std::max<size_t>(model.fluid.gas ? model.fluid.source_vertices.size() : 0, 1) * sizeof(cl_uint));
}

long FluidFlow::substeps(const FluidModel& f, double dt) {
  return std::max(1L, static_cast<long>(std::ceil(dt / (f.safety * f.stable_dt))));
}

FluidFlow::FluidFlow(ClContext& cl, const Model& model, compute::buffer& position, compute::buffer& status,
                     compute::buffer& gauss_state, double dt, const FluidCarriers* carriers)
    : cl_(cl),
      fluid_(model.fluid),
      ce4_(model.ce4.size()),
      vertices_(model.fluid.vertices),
      dt_(dt),
      thickness_(model.thickness),
      substeps_(substeps(model.fluid, dt)),
      source_share_(1.0 / static_cast<double>(model.fluid.source_vertices.size())) {
  const MemoryPlan arrays = plan(model);
  auto make = [&](const char* name) { return arrays.allocate(cl, name); };
  nodes_ = make("fluid ce4_nodes"), seg_vertex_ = make("fluid seg_vertex"), seg_h_ = make("fluid seg_h");
  seg_geom_ = make("fluid seg_geom");
  front_ = make("fluid front"), back_ = make("fluid back"), wet_ = make("fluid wet");
  wet_count_ = make("fluid wet_count");
  in_net_ = make("fluid in_net"), net_vertices_ = make("fluid net_vertices"), net_count_ = make("fluid net_count");
  slots_ = make("fluid slots"), loaded_node_ = make("fluid loaded_node");
  vertex_start_ = make("fluid vertex_start"), vertex_end_ = make("fluid vertex_end");
  source_ = make("fluid source"), vertex_state_ = make("fluid vertex_state");
  vertex_energy_ = make("fluid vertex_energy"), too_wide_ = make("fluid too_wide");
  seg_exposed_ = make("fluid seg_exposed"), vertex_leak_ = make("fluid vertex_leak");
  seg_joined_ = make("fluid seg_joined");
  upload(cl, seg_joined_, std::vector<cl_uchar>(fluid_.gas ? ce4_ : 1, 0));
  vertex_rate_ = make("fluid vertex_rate");
  upload(cl, vertex_rate_, std::vector<real>(vertices_, 0));
  gas_hole_ = make("fluid gas_hole"), hole_polygon_ = make("fluid hole_polygon"), hole_sources_ = make("fluid hole_sources");

  std::vector<cl_uint4> nodes;
  for (const auto& e : model.ce4) nodes.push_back({{cl_uint(e[0]), cl_uint(e[1]), cl_uint(e[2]), cl_uint(e[3])}});
  upload(cl, nodes_, nodes);
  upload(cl, seg_vertex_, fluid_.segment_vertex);
  upload(cl, seg_h_, std::vector<real>(fluid_.segment_length.begin(), fluid_.segment_length.end()));
  upload(cl, seg_geom_, std::vector<real4>(ce4_));
  upload(cl, front_, std::vector<real2>(vertices_));
  upload(cl, back_, std::vector<real2>(vertices_));
  upload(cl, wet_, std::vector<cl_uint>(vertices_, 0));
  upload(cl, wet_count_, std::vector<cl_uint>(4, 0));
  upload(cl, slots_, std::vector<real2>(4 * ce4_));
  upload(cl, loaded_node_, std::vector<cl_uchar>(std::max<size_t>(model.num_nodes(), 1), 0));
  upload(cl, vertex_start_, fluid_.vertex_start);
  upload(cl, vertex_end_, fluid_.vertex_end);
  std::vector<cl_uchar> source(vertices_, 0);
  for (uint32_t v : fluid_.source_vertices) source[v] = 1;
  upload(cl, source_, source);
  upload(cl, vertex_state_, std::vector<real4>(vertices_));
  upload(cl, vertex_energy_, std::vector<real4>(vertices_));
  upload(cl, too_wide_, std::vector<cl_int>{INT_MAX, INT_MAX});
  upload(cl, seg_exposed_, std::vector<real>(ce4_, real(-1)));  // not exposed yet
  upload(cl, vertex_leak_, std::vector<real2>(vertices_));
  // The pre-existing crack: broken and closed (status 1, mode 0: it has no failure mode)
  // from the start; it opens, and the CE4 stage releases it, as the fluid pushes.
  if (!fluid_.crack_ce4.empty()) {
    auto st = download<cl_int2>(cl, status, ce4_);
    for (uint32_t e : fluid_.crack_ce4) st[e] = {{1, 0}};
    upload(cl, status, st);
  }

  const real thickness = static_cast<real>(model.thickness), bulk = static_cast<real>(fluid_.bulk_modulus);
  const real dt_sub = static_cast<real>(dt / static_cast<double>(substeps_));
  const bool leak = fluid_.leak_off > 0;
  // Sub-steps from the network's current rate (never more than the plan's): for a source
  // constant in time (its value does not depend on where the sub-steps fall) or the gas's
  // hole, and no leak-off (its exposure times are the sub-steps'). FDEM_FLUID_ADAPTIVE=0
  // keeps the plan's count.
  const char* adaptive_env = std::getenv("FDEM_FLUID_ADAPTIVE");
  adaptive_ = !leak && (fluid_.gas || fluid_.history.times.size() == 1) &&
              !(adaptive_env && std::string(adaptive_env) == "0");
  // The group kernel's local path for small wet networks (fluid_substeps_group):
  // FDEM_FLUID_LOCAL=0 keeps them on its global path (the tests compare the two).
  const char* local_env = std::getenv("FDEM_FLUID_LOCAL");
  const bool local_choice = !(local_env && std::string(local_env) == "0");
  // The group kernel's size: on a GPU the gas's sub-steps visit a wet network of thousands
  // of vertices (the blasting case's own mesh) from one work-group, whose loads wait in a
  // chain per vertex, so more work-items hide more of it: 1024 there (the liquid keeps 256:
  // its small networks take the local path, whose registers 1024 items would spill).
  // FDEM_FLUID_GROUP_SIZE (a power of two from 64 to the device's limit) overrides it; the
  // bits do not depend on it (each vertex's sub-step is the same whichever item does it).
  fluid_group_ = (fluid_.gas && cl.info().is_gpu) ? std::min<size_t>(kFluidGroupWide, cl.device().max_work_group_size())
                                                  : kFluidGroup;
  if (const size_t size = cl.group_size_from_env("FDEM_FLUID_GROUP_SIZE", 64)) fluid_group_ = size;
  // All sub-steps in one launch of one work-group when the source's value is the same in
  // every sub-step (a constant rate or pressure, or the gas's hole), no leak-off (its
  // exposure times are per sub-step) and, on a CPU device, a network of at most
  // kFluidGroupUpTo vertices (one work-group is one core there: a large wet network would
  // wait on it). On a GPU whatever the network's size: the group visits only the wet
  // vertices, while each launch of the other path costs some 4 µs and covers the whole
  // network (the kgd:2 bench row, 37,409 vertices, 88 sub-steps: +983% with launches on
  // an H100, docs/performance-notes.md "Session 21"). The same bits as the launches
  // (tests/test_fluid.cpp); FDEM_FLUID_GROUP=0 keeps the launches, =1 takes the group
  // whatever the device and the network's size.
  const char* group_env = std::getenv("FDEM_FLUID_GROUP");
  const std::string group_choice = group_env ? group_env : "";
  one_group_ = !leak && (fluid_.gas || fluid_.history.times.size() == 1) && group_choice != "0" &&
               (group_choice == "1" || cl.info().is_gpu || vertices_ <= kFluidGroupUpTo);
  // The gas always: its group follows the hole's gas from one sub-step to the next.
  if (fluid_.gas) one_group_ = true;
  // The liquid's whole step in one launch of one work-group (fluid_step_group) wherever its
  // sub-steps take one (above), given the cohesive stage's list of carrying CE4s: on a GPU
  // each of the stage's four launches cost about what a small model's mechanics costs
  // (issue 32's fluid rows), and the launches' passes over every CE4 and vertex follow
  // the model, while the fused step's follow the network. The same bits as the four
  // launches (tests/test_fluid.cpp); FDEM_FLUID_FUSED=0 keeps the launches.
  const char* fused_env = std::getenv("FDEM_FLUID_FUSED");
  fused_ = one_group_ && !fluid_.gas && carriers != nullptr && !(fused_env && std::string(fused_env) == "0");
  // The fused step as the first work-group of the triangle stage's launch (TriangleForces,
  // FLUID_HEAD: neither reads what the other writes, so the step's chain of memory waits on
  // one compute unit runs beside the triangles' on the others, and one launch a step less).
  // FDEM_FLUID_HEAD=1 takes it wherever the step is fused, on any device (the step then
  // takes the triangle stage's work-group size, a GPU's 256 as before: the bits do not
  // depend on it). Off by default until a GPU has measured it (no GPU could be had in the
  // session that wrote it: docs/performance-notes.md, "Session 29").
  const char* head_env = std::getenv("FDEM_FLUID_HEAD");
  const std::string head_choice = head_env ? head_env : "";
  const size_t triangle_group = TriangleForces::group_size(cl.group_size());
  if (fused_ && head_choice == "1") fluid_group_ = triangle_group;
  std::map<std::string, std::string> defines{{"PRESSURE_SOURCE", fluid_.pressure_source ? "1" : "0"},
                                             {"LEAK_OFF", leak ? "1" : "0"},
                                             {"DAMAGED_SEGMENTS", fluid_.damaged_segments ? "1" : "0"},
                                             {"CAP_APERTURE", fluid_.cap_aperture ? "1" : "0"},
                                             {"GAS", fluid_.gas ? "1" : "0"},
                                             {"FLUID_GROUP", std::to_string(fluid_group_)},
                                             {"FLUID_LOCAL", local_choice ? "1" : "0"},
                                             {"FUSED", fused_ ? "1" : "0"},
                                             {"ADAPTIVE", adaptive_ ? "1" : "0"}};
  {
    char text[64];
    std::snprintf(text, sizeof text, "((real)%.17g)", fluid_.stiffness());
    defines["FLUID_MODULUS"] = text;
  }
  if (fluid_.gas) {  // the gas's constants, every digit of the doubles
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", fluid_.gas_pressure);
    defines["GAS_P0"] = text;
    std::snprintf(text, sizeof text, "%.17g", fluid_.gamma);
    defines["GAS_GAMMA"] = text;
  }
  // The state laws and the segments' geometry ahead of the stage (cl_kernels/fluid_laws.cl).
  const std::vector<const KernelSource*> libraries{&kernel_source::fluid_laws};
  compute::program program = cl.build(kernel_source::fluid_flow, defines, libraries);
  // The largest work-group a compiled one-group kernel takes here (its registers decide).
  auto group_limit = [&](const compute::program& built) {
    size_t limit = compute::kernel(built, "fluid_substeps_group").get_work_group_info<size_t>(cl.device(), CL_KERNEL_WORK_GROUP_SIZE);
    if (fused_)
      limit = std::min(limit, compute::kernel(built, "fluid_step_group").get_work_group_info<size_t>(cl.device(), CL_KERNEL_WORK_GROUP_SIZE));
    return limit;
  };
  if (fluid_group_ > kFluidGroup && group_limit(program) < fluid_group_) {  // too many items for it here: the usual size
    fluid_group_ = kFluidGroup;
    defines["FLUID_GROUP"] = std::to_string(fluid_group_);
    program = cl.build(kernel_source::fluid_flow, defines, libraries);
  }
  defines_ = defines;  // the program's defines (the triangle stage's build takes them with FLUID_HEAD)
  // (after the build: a group the compiled step cannot take falls back to kFluidGroup above)
  headed_ = fused_ && head_choice == "1" && fluid_group_ == triangle_group;
  segments_ = compute::kernel(program, "fluid_segments");
  KernelArgs s(segments_);
  s("n_ce4", cl_uint(ce4_))("ce4_nodes", nodes_)("position", position)("status", status);
  if (fluid_.damaged_segments) s("gp_state", gauss_state);
  s("seg_h", seg_h_)(
      "thickness", thickness)("residual", real(fluid_.residual_aperture))("max_aperture", real(fluid_.max_aperture))(
      "viscosity", real(fluid_.viscosity));
  step_ = s.later("step", cl_int(0));
  s("seg_geom", seg_geom_);
  if (fluid_.gas) s("seg_joined", seg_joined_);
  s("too_wide", too_wide_)("wet_count", wet_count_).done();

  vertices_kernel_ = compute::kernel(program, "fluid_vertices");
  KernelArgs v(vertices_kernel_);
  v("n_vertices", cl_uint(vertices_))("vertex_start", vertex_start_)("vertex_end", vertex_end_)("seg_geom", seg_geom_)(
       "bulk", bulk)("source", source_);
  if (leak) v("seg_exposed", seg_exposed_);
  if (fluid_.gas) v("seg_joined", seg_joined_);
  v("vertex_rate", vertex_rate_);
  v("vertex_state", vertex_state_)("vertex_energy", vertex_energy_)("front", front_)("wet_count", wet_count_)("wet", wet_)
      .done();

  // Two copies of one sub-step kernel: the first reads the neighbours from front_ and
  // writes back_, the second the other way, so the sub-steps swap without setting arguments.
  // (The gas always takes the group kernel below; its program has no fluid_substep.)
  for (int copy = 0; copy < (fluid_.gas ? 0 : 2); ++copy) {
    substep_[copy] = compute::kernel(program, "fluid_substep");
    KernelArgs b(substep_[copy]);
    b("wet_count", wet_count_)("wet", wet_)("vertex_start", vertex_start_)("vertex_end", vertex_end_)(
        "seg_vertex", seg_vertex_)("seg_geom", seg_geom_)("front", copy == 0 ? front_ : back_)("source", source_);
    source_value_[copy] = b.later("source_value", real(0));
    b("bulk", bulk);
    if (adaptive_) {
      b("dt", real(dt))("safety", real(fluid_.safety))("planned", cl_uint(substeps_));
      k_sub_[copy] = b.later("k_sub", cl_uint(0));
    } else {
      b("dt_sub", dt_sub);
    }
    if (leak) {
      sub_time_[copy] = b.later("t_sub", real(0));
      b("leak_off", real(fluid_.leak_off))("thickness", thickness)("seg_h", seg_h_)("seg_exposed", seg_exposed_)(
          "vertex_leak", vertex_leak_);
    }
    b("vertex_state", vertex_state_)("vertex_energy", vertex_energy_)("back", copy == 0 ? back_ : front_).done();
  }

  if (one_group_) {
    const double value = fluid_.gas ? 0.0 : fluid_source_value(fluid_.history, 0.0);
    group_kernel_ = compute::kernel(program, "fluid_substeps_group");
    KernelArgs b(group_kernel_);
    b("planned", cl_uint(substeps_))("wet_count", wet_count_)("wet", wet_)("vertex_start", vertex_start_)(
        "vertex_end", vertex_end_)("seg_vertex", seg_vertex_)("seg_geom", seg_geom_)("front", front_)("source", source_)(
        "source_value", static_cast<real>(fluid_.pressure_source ? value : value * thickness_ * source_share_))(
        "bulk", bulk);
    if (adaptive_)
      b("dt", real(dt))("safety", real(fluid_.safety));
    else
      b("dt_sub", dt_sub);
    if (fluid_.gas)
      b("gas_hole", gas_hole_)("n_source", cl_uint(fluid_.source_vertices.size()))("source_vertices", hole_sources_)(
          "hole_gas0", real(fluid_.hole_volume));
    b("vertex_state", vertex_state_)("vertex_energy", vertex_energy_)("back", back_).done();
  }

  if (fused_) {
    const double value = fluid_source_value(fluid_.history, 0.0);
    step_operands_ = StepOperands{carriers, status, gauss_state,
                                  static_cast<real>(fluid_.pressure_source ? value : value * thickness_ * source_share_),
                                  dt_sub, bulk};
    network_clear_ = compute::kernel(program, "fluid_network_clear");
    bind_args(network_clear_)("n_vertices", cl_uint(vertices_))("in_net", in_net_)("net_count", net_count_)(
        "carrier_count", carriers->count)
        .done();
    network_scan_ = compute::kernel(program, "fluid_network_scan");
    KernelArgs n(network_scan_);
    n("n_ce4", cl_uint(ce4_))("n_vertices", cl_uint(vertices_))("status", status);
    if (fluid_.damaged_segments) n("gp_state", gauss_state);
    n("source", source_)("carriers", carriers->list)("carrier_count", carriers->count)("in_net", in_net_)(
        "net_vertices", net_vertices_)("net_count", net_count_)
        .done();
    if (!headed_) {  // headed, the triangle stage's launch takes the step (bind_step)
      fused_kernel_ = compute::kernel(program, "fluid_step_group");
      KernelArgs f(fused_kernel_);
      f("position", position)("thickness", thickness);
      fused_step_ = f.later("step", cl_int(0));
      if (adaptive_) f("dt", real(dt));
      bind_step(f);
      f.done();
    }
  }

  forces_ = compute::kernel(program, "fluid_forces");
  KernelArgs g(forces_);
  g("n_ce4", cl_uint(ce4_))("ce4_nodes", nodes_)("position", position)("seg_vertex", seg_vertex_)("seg_geom", seg_geom_)(
       "seg_h", seg_h_)("vertex_state", vertex_state_);
  g("vertex_rate", vertex_rate_);
  if (fluid_.gas) g("residual", real(fluid_.residual_aperture));
  g("thickness", thickness)("fluid_slots", slots_)("fluid_loaded_node", loaded_node_).done();

  if (fluid_.gas) {
    upload(cl, hole_polygon_, fluid_.hole_polygon);
    upload(cl, hole_sources_, fluid_.source_vertices);
    hole_kernel_ = compute::kernel(program, "gas_hole_state");
    KernelArgs h(hole_kernel_);
    h("n_polygon", cl_uint(fluid_.hole_polygon.size()))("polygon", hole_polygon_)("position", position)(
        "thickness", thickness)("n_source", cl_uint(fluid_.source_vertices.size()))("source_vertices", hole_sources_)(
        "vertex_energy", vertex_energy_)("hole_gas0", real(fluid_.hole_volume))("gas_hole", gas_hole_)
        .done();
    // The hole full of gas at ρ0: its V₀ is its volume, so p = p0 (up to rounding).
    cl_.enqueue(hole_kernel_, 1);
  } else {
    upload(cl, gas_hole_, std::vector<real4>(1));
  }
}

void FluidFlow::bind_step(KernelArgs& f) const {
  const StepOperands& o = step_operands_;
  f("carriers", o.carriers->list)("carrier_count", o.carriers->count)("in_net", in_net_)("net_vertices", net_vertices_)(
      "net_count", net_count_)("ce4_nodes", nodes_)("status", o.status);
  if (fluid_.damaged_segments) f("gp_state", o.gauss_state);
  f("seg_h", seg_h_)("residual", real(fluid_.residual_aperture))("max_aperture", real(fluid_.max_aperture))(
      "viscosity", real(fluid_.viscosity))("seg_geom", seg_geom_)("too_wide", too_wide_)("vertex_start", vertex_start_)(
      "vertex_end", vertex_end_)("seg_vertex", seg_vertex_)("bulk", o.bulk)("source", source_)(
      "source_value", o.source_value)("planned", cl_uint(substeps_));
  if (adaptive_)
    f("safety", real(fluid_.safety));
  else
    f("dt_sub", o.dt_sub);
  f("vertex_rate", vertex_rate_)("vertex_state", vertex_state_)("vertex_energy", vertex_energy_)("front", front_)(
      "back", back_)("wet_count", wet_count_)("wet", wet_)("fluid_slots", slots_)("fluid_loaded_node", loaded_node_);
}

std::map<std::string, std::string> FluidFlow::head_defines() const {
  std::map<std::string, std::string> defines = defines_;
  defines["FLUID_HEAD"] = "1";
  // The sub-steps on the group's global path: on an H100 (NVIDIA OpenCL) the local path
  // inside the triangle launch gave other bits than the four launches (tests/test_fluid.cpp,
  // "one work-group": 4,807 values of the KGD rate case, 350 of Sneddon's), the global path
  // and the local path on the fluid's own launch the same; PoCL gave the same bits on both.
  // The cause is not found (docs/performance-notes.md, "Session 30"); FDEM_FLUID_HEAD_LOCAL=1
  // keeps the local path, for the experiments that look for it.
  const char* keep_local = std::getenv("FDEM_FLUID_HEAD_LOCAL");
  if (!(keep_local && std::string(keep_local) == "1")) defines["FLUID_LOCAL"] = "0";
  return defines;
}

void FluidFlow::enqueue(double time, long step) {
  if (fused_) {  // the liquid's whole step in one work-group
    if (rescan_) {  // the lists anew from the CE4s' state (the first step, or after a restore)
      cl_.enqueue(network_clear_, vertices_);
      cl_.enqueue(network_scan_, std::max(ce4_, vertices_));
      rescan_ = false;
    }
    if (headed_) return;  // the triangle stage's launch, next in the queue, takes the step
    fused_step_.set(static_cast<cl_int>(step));
    cl_.enqueue(fused_kernel_, fluid_group_, fluid_group_);
    return;
  }
  step_.set(static_cast<cl_int>(step));
  cl_.enqueue(segments_, ce4_);
  cl_.enqueue(vertices_kernel_, vertices_);
  const double dt_sub = dt_ / static_cast<double>(substeps_);
  if (one_group_) cl_.enqueue(group_kernel_, fluid_group_, fluid_group_);
  for (long k = 0; !one_group_ && k < substeps_; ++k) {
    // The source at the sub-step's middle (a rate) or its end (a held pressure).
    const double t = time + dt_sub * (static_cast<double>(k) + (fluid_.pressure_source ? 1.0 : 0.5));
    const double value = fluid_source_value(fluid_.history, t);
    // A rate is per unit thickness, shared equally by the source's vertices.
    const int copy = static_cast<int>(k & 1);
    source_value_[copy].set(static_cast<real>(fluid_.pressure_source ? value : value * thickness_ * source_share_));
    if (adaptive_) k_sub_[copy].set(static_cast<cl_uint>(k));
    if (fluid_.leak_off > 0)  // the sub-step's start, for Carter's √(t - t_exposed)
      sub_time_[copy].set(static_cast<real>(time + dt_sub * static_cast<double>(k)));
    cl_.enqueue(substep_[copy], vertices_);
  }
  cl_.enqueue(forces_, ce4_);
  if (fluid_.gas) cl_.enqueue(hole_kernel_, 1);  // the hole's gas for the next step's wall and sub-steps
}

EnergyPart FluidFlow::queue_energy(const ItemSums& sums) {
  // Per vertex: V₀, V and U (state columns 0, 1 and 3: one sum of 4 columns), the
  // injection work, the faces' work, the injected V₀ and the viscous dissipation
  // (energy columns 0-3). The items are in network order, one rank (a split run refuses [fluid]).
  PendingSums state = sums(cl_, vertex_state_, vertices_, 4, 0, 4, ItemKind::Node);
  PendingSums energy = sums(cl_, vertex_energy_, vertices_, 4, 0, 4, ItemKind::Node);
  // Carter's leak-off: per vertex the leaked V₀ and the energy it took (columns 0-1).
  PendingSums leak = fluid_.leak_off > 0 ? sums(cl_, vertex_leak_, vertices_, 2, 0, 2, ItemKind::Node)
                                         : sums_now({0.0, 0.0});
  // The wellbore pressure: the mean over the source's vertices (read when the sums land).
  const std::vector<uint32_t> wells = fluid_.source_vertices;
  ClContext* cl = &cl_;
  const compute::buffer states = vertex_state_, hole = gas_hole_;
  const bool gas = fluid_.gas;
  const double density = fluid_.gas_density;
  const compute::buffer counts = wet_count_;
  const bool adaptive = adaptive_;
  const long planned = substeps_;
  return [state, energy, leak, wells, cl, states, hole, gas, density, counts, adaptive, planned](EnergyTotals& e) {
    e.fluid_substeps = static_cast<double>(planned);
    if (adaptive) {  // the count the last step's kernel took (substeps_now, fluid_flow.cl); 1 before any step
      const cl_uint taken = download<cl_uint>(*cl, counts, 4)[3];
      e.fluid_substeps = taken > 0 ? double(taken) : 1.0;
    }
    if (gas) {  // the hole's gas as the end of the last step left it
      const real4 h = download<real4>(*cl, hole, 1)[0];
      e.hole_pressure = double(h.x), e.hole_volume = double(h.y);
      e.hole_gas_mass = density * double(h.z), e.hole_gas_energy = double(h.w);
      e.gas_density = density;
    }
    const auto s = state();
    const auto w = energy();
    const auto l = leak();
    e.fluid_leaked_volume += l[0];
    e.fluid_leak_off += l[1];
    e.fluid_volume += s[0];
    e.crack_volume += s[1];
    e.fluid_stored += s[3];
    e.fluid_injection += w[0];
    e.fluid_face_work += w[1];
    e.fluid_injected_volume += w[2];
    e.fluid_viscous += w[3];
    double p = 0;
    if (!wells.empty()) {  // one read of the source's range of vertices (ascending)
      const auto s = download<real4>(*cl, states, wells.back() - wells.front() + 1, wells.front());
      for (uint32_t v : wells) p += double(s[v - wells.front()].z);
    }
    e.wellbore_pressure = wells.empty() ? 0.0 : p / double(wells.size());
  };
}

std::pair<int, int> FluidFlow::too_wide() {
  const auto w = download<cl_int>(cl_, too_wide_, 2);
  if (w[0] == INT_MAX) return {-1, -1};
  return {w[0], w[1]};
}

void FluidFlow::check_too_wide(const std::vector<cl_int>& w) const {
  if (w[0] == INT_MAX) return;
  throw NumericalError("fluid: CE4 " + std::to_string(w[0]) + " opened wider than fluid.max_aperture = " +
                       std::to_string(fluid_.max_aperture) + " m by step " + std::to_string(w[1]) +
                       ": the fluid's sub-step was planned for that aperture; raise fluid.max_aperture (the fluid "
                       "step falls as its square)");
}

std::vector<real4> FluidFlow::vertex_state() { return download<real4>(cl_, vertex_state_, vertices_); }
std::vector<real> FluidFlow::vertex_rate() { return download<real>(cl_, vertex_rate_, vertices_); }

void FluidFlow::segment_fields(std::vector<real>& pressure, std::vector<real>& aperture) {
  const auto geom = download<real4>(cl_, seg_geom_, ce4_);
  const auto state = vertex_state();
  pressure.assign(ce4_, 0);
  aperture.assign(ce4_, 0);
  for (size_t e = 0; e < ce4_; ++e) {
    if (geom[e].z == real(0)) continue;  // closed: no conductance, no fluid
    pressure[e] = real(0.5) * (state[fluid_.segment_vertex[2 * e]].z + state[fluid_.segment_vertex[2 * e + 1]].z);
    aperture[e] = geom[e].w;
  }
}

void FluidFlow::save_state(StateWriter& out) const {
  out.buffer<real>("fluid_vertex_state", vertex_state_, vertices_, 4);
  out.buffer<real>("fluid_vertex_energy", vertex_energy_, vertices_, 4);
  out.buffer<real>("fluid_vertex_rate", vertex_rate_, vertices_, 1);  // the mid-step predictor's last change
  if (fluid_.leak_off > 0) {  // only then: checkpoints without leak-off keep their items
    out.buffer<real>("fluid_seg_exposed", seg_exposed_, ce4_, 1);
    out.buffer<real>("fluid_vertex_leak", vertex_leak_, vertices_, 2);
  }
  if (fluid_.gas) {
    out.buffer<real>("fluid_gas_hole", gas_hole_, 1, 4);
    out.buffer<real>("fluid_seg_geom", seg_geom_, ce4_, 4);  // which segments carried: the next step's joins
  }
}

void FluidFlow::load_state(StateReader& in) {
  rescan_ = true;  // the CE4s' state is the checkpoint's: the fused step's lists anew
  in.buffer<real>("fluid_vertex_state", vertex_state_, vertices_, 4);
  in.buffer<real>("fluid_vertex_energy", vertex_energy_, vertices_, 4);
  in.buffer<real>("fluid_vertex_rate", vertex_rate_, vertices_, 1);
  if (fluid_.leak_off > 0) {
    in.buffer<real>("fluid_seg_exposed", seg_exposed_, ce4_, 1);
    in.buffer<real>("fluid_vertex_leak", vertex_leak_, vertices_, 2);
  }
  if (fluid_.gas) {
    in.buffer<real>("fluid_gas_hole", gas_hole_, 1, 4);
    in.buffer<real>("fluid_seg_geom", seg_geom_, ce4_, 4);
  }
}

}  // namespace fdem
