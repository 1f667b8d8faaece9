#include "engine/stages/cohesive_forces.hpp"

#include <limits>
#include <map>
#include <string>

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/device/device_arrays.hpp"
#include "base/errors.hpp"

namespace fdem {

namespace {

void check_properties(const FractureProperties& p, size_t index) {
  const std::string where = "fracture properties " + std::to_string(index) + ": ";
  auto positive = [&](double value, const char* name) {
    if (!(value > 0.0) || !std::isfinite(value)) throw InputError(where + name + " must be positive, got " + std::to_string(value));
  };
  positive(p.tensile_strength, "tensile strength");
  positive(p.cohesion, "cohesion");
  positive(p.gf1, "mode I fracture energy");
  positive(p.gf2, "mode II fracture energy");
  positive(p.penalty_opening, "opening penalty");
  positive(p.penalty_sliding, "sliding penalty");
  positive(p.penalty_overlap, "overlap penalty");
  if (!(p.friction_angle >= 0.0 && p.friction_angle < 90.0))
    throw InputError(where + "friction angle must be in [0, 90) degrees, got " + std::to_string(p.friction_angle));
  if (!(p.a > 0.0 && p.b > 0.0 && p.c > 0.0 && p.a + p.b > 1.0))
    throw InputError(where + "softening shape needs a, b, c > 0 and a + b > 1");
}

// Partial sums of the energy totals: one per CE4 up to 4096 (at least one).
size_t energy_partials(size_t ce4) { return std::max<size_t>(1, std::min<size_t>(ce4, 4096)); }

}  // namespace

MemoryPlan CohesiveForces::plan(size_t ce4, size_t mesh_nodes, size_t property_sets, bool in_situ, bool extrinsic,
                                 size_t excavations, bool fluid, size_t nodes) {
  MemoryPlan p;
  // [fluid]: the list of the CE4s that carry fluid, and its length (fluid_carriers()).
  if (fluid)
    p.add("ce4_fluid_carriers", std::max<size_t>(1, ce4) * sizeof(cl_uint)).add("ce4_fluid_carrier_count", sizeof(cl_uint));
  // [[excavation]] with CE4s on excavated triangles: the ramp's indices, times and energy.
  if (excavations > 0)
    p.add("ce4_excavation_of", 2 * std::max<size_t>(1, ce4) * sizeof(cl_int))
        .add("ce4_excavation_time", excavations * sizeof(real2))
        .add("ce4_excavation_energy", std::max<size_t>(1, ce4) * sizeof(real2));
  if (extrinsic)
    p.add("ce4_inserted", std::max<size_t>(1, ce4) * sizeof(cl_int))
        .add("ce4_insertion_gaps", std::max<size_t>(1, ce4) * 4 * sizeof(real))
        .add("ce4_inserted_count", sizeof(cl_uint));
  // The openings and slips that carry the in-situ field, only in models with [in_situ].
  if (in_situ) p.add("ce4_in_situ_gaps", 6 * std::max<size_t>(1, ce4) * sizeof(real));
  p.add("ce4_property_rows", layout::COHP_STRIDE * std::max<size_t>(1, property_sets) * sizeof(real));
  if (mesh_nodes > 0)
    p.add("node origins", std::max<size_t>(1, nodes) * sizeof(cl_uint)).add("mesh_node_state", mesh_nodes * sizeof(cl_int));
  return p
      .add("ce4_nodes", 4 * ce4 * sizeof(cl_uint))
      // h only: o_p, s_p, o_overlap follow from it and the property row (layouts.hpp).
      .add("ce4_length", ce4 * sizeof(real))
      .add("ce4_property", ce4 * sizeof(cl_uint))
      .add("ce4_gauss_state", 9 * ce4 * sizeof(real))
      .add("ce4_friction_slip", ce4 * sizeof(real4))
      .add("ce4_status", 2 * ce4 * sizeof(cl_int))
      // One column of the frames' CE4 values (damage, mean opening or slip), computed
      // from the state by cohesive_output when one is read (output_column).
      .add("ce4_output", std::max<size_t>(1, ce4) * sizeof(real), MemoryPlan::Lifetime::Output)
      .add("ce4_force", 4 * ce4 * sizeof(real2))
      .add("ce4_energy", 3 * ce4 * sizeof(real))
      .add("ce4_energy_partials", energy_partials(ce4) * sizeof(real2))
      .add("ce4_break_count", sizeof(cl_uint))
      .add("ce4_status_step", sizeof(cl_int))
      .add("ce4_break_ids", 2 * ce4 * sizeof(cl_int))
      .add("ce4_break_records", ce4 * sizeof(real4));
}

CohesiveForces::CohesiveForces(ClContext& cl, const CohesiveModel& model, compute::buffer& position,
                               compute::buffer& velocity, const std::vector<real2>& ref,
                               const std::vector<InSituGaps>& in_situ)
    : cl_(cl), count_(model.ce4.size()), partials_(energy_partials(count_)), position_(position) {
  if (!(model.dt > 0.0) || !std::isfinite(model.dt))
    throw InputError("cohesive model: the time step must be positive and finite (got " + std::to_string(model.dt) + ")");
  const bool with_in_situ = !in_situ.empty();
  if (with_in_situ && in_situ.size() != count_)
    throw InputError("cohesive model: " + std::to_string(count_) + " CE4s but " + std::to_string(in_situ.size()) +
                     " in-situ gap sets");
  if (model.properties.size() != count_)
    throw InputError("cohesive model: " + std::to_string(count_) + " CE4s but " +
                     std::to_string(model.properties.size()) + " property indices");
  if (!(model.thickness > 0.0)) throw InputError("cohesive model: thickness must be positive");

  std::vector<double> integral(model.fracture.size());
  for (size_t k = 0; k < model.fracture.size(); ++k) {
    const auto& f = model.fracture[k];
    check_properties(f, k);
    integral[k] = softening_integral(f.a, f.b, f.c);
  }
  // Heterogeneous strengths: a set of its own for each CE4 whose factors are not (1, 1),
  // after the shared sets (T_s and c scaled, fracture energies and softening the same).
  if (!model.strength_factor.empty() && model.strength_factor.size() != count_)
    throw InputError("cohesive model: " + std::to_string(count_) + " CE4s but " +
                     std::to_string(model.strength_factor.size()) + " strength factors");
  std::vector<FractureProperties> sets = model.fracture;
  std::vector<int> own_set(count_, -1);
  for (size_t e = 0; e < model.strength_factor.size(); ++e) {
    const auto& factor = model.strength_factor[e];
    const int prop = model.properties[e];
    if ((factor[0] == 1.0 && factor[1] == 1.0) || prop < 0 || static_cast<size_t>(prop) >= model.fracture.size())
      continue;
    FractureProperties f = model.fracture[prop];
    f.tensile_strength *= factor[0];
    f.cohesion *= factor[1];
    check_properties(f, sets.size());
    own_set[e] = static_cast<int>(sets.size());
    sets.push_back(f);
    integral.push_back(integral[prop]);
  }

  const size_t num_nodes = ref.size();
  std::vector<cl_uint> nodes(4 * count_);
  params_.assign(layout::COH_STRIDE * count_, real(0));
  std::vector<cl_uint> property(count_);
  const double deg = std::acos(-1.0) / 180.0;
  for (size_t e = 0; e < count_; ++e) {
    for (int k = 0; k < 4; ++k) {
      const int node = model.ce4[e][k];
      if (node < 0 || static_cast<size_t>(node) >= num_nodes)
        throw InputError("CE4 " + std::to_string(e) + " names node " + std::to_string(node) + ", out of range");
      nodes[4 * e + k] = static_cast<cl_uint>(node);
    }
    const int prop = model.properties[e];
    if (prop < 0 || static_cast<size_t>(prop) >= model.fracture.size())
      throw InputError("CE4 " + std::to_string(e) + " names fracture properties " + std::to_string(prop) + ", out of range");
    const int set = own_set[e] >= 0 ? own_set[e] : prop;
    const auto& f = sets[set];
    const real2 a = ref[model.ce4[e][0]], b = ref[model.ce4[e][1]];
    const double h = std::hypot(double(b.x) - double(a.x), double(b.y) - double(a.y));
    if (!(h > 0.0)) throw InputError("CE4 " + std::to_string(e) + " has a zero-length edge");
    real* row = &params_[layout::COH_STRIDE * e];
    row[layout::COH_OP] = real(2.0 * h * f.tensile_strength / f.penalty_opening);
    row[layout::COH_SP] = real(2.0 * h * f.cohesion / f.penalty_sliding);
    row[layout::COH_OOV] = real(2.0 * h * f.tensile_strength / f.penalty_overlap);
    row[layout::COH_H] = real(h);
    property[e] = static_cast<cl_uint>(set);
  }
  std::vector<real> property_rows(layout::COHP_STRIDE * std::max<size_t>(1, sets.size()), real(0));
  for (size_t k = 0; k < sets.size(); ++k) {
    const auto& f = sets[k];
    real* row = &property_rows[layout::COHP_STRIDE * k];
    row[layout::COHP_OT] = real(f.gf1 / (f.tensile_strength * integral[k]));
    row[layout::COHP_ST] = real(f.gf2 / (f.cohesion * integral[k]));
    row[layout::COHP_TS] = real(f.tensile_strength);
    row[layout::COHP_C] = real(f.cohesion);
    row[layout::COHP_TANPHI] = real(std::tan(f.friction_angle * deg));
    row[layout::COHP_A] = real(f.a);
    row[layout::COHP_B] = real(f.b);
    row[layout::COHP_CEXP] = real(f.c);
    row[layout::COHP_PO] = real(f.penalty_opening);
    row[layout::COHP_PS] = real(f.penalty_sliding);
    row[layout::COHP_POV] = real(f.penalty_overlap);
  }

  fans_ = !model.vertex_bonded.empty();
  if (fans_ && model.node_origin.size() != ref.size())
    throw InputError("cohesive model: " + std::to_string(ref.size()) + " nodes but " +
                     std::to_string(model.node_origin.size()) + " mesh node origins");
  mesh_nodes_ = model.vertex_bonded.size();
  for (const auto& f : model.fracture) extrinsic_ = extrinsic_ || f.extrinsic;
  if (extrinsic_ && with_in_situ) throw InputError("cohesive model: extrinsic CE4s with [in_situ] are not supported yet");
  excavation_ = !model.excavation_of.empty();
  if (excavation_ && model.excavation_of.size() != count_)
    throw InputError("cohesive model: " + std::to_string(count_) + " CE4s but " +
                     std::to_string(model.excavation_of.size()) + " excavation pairs");
  // A ramped CE4 is intrinsic (engine/model/excavation.cpp refuses the others, naming the key).
  for (size_t e = 0; excavation_ && e < count_; ++e)
    if ((model.excavation_of[e][0] >= 0 || model.excavation_of[e][1] >= 0) && model.fracture[model.properties[e]].extrinsic)
      throw InputError("cohesive model: CE4 " + std::to_string(e) + " is extrinsic and on an excavated triangle");
  const MemoryPlan arrays = plan(count_, mesh_nodes_, sets.size(), with_in_situ, extrinsic_,
                                 excavation_ ? model.excavation_times.size() : 0, model.fluid_carriers != 0, ref.size());
  if (model.fluid_carriers != 0) {
    carriers_.list = arrays.allocate(cl, "ce4_fluid_carriers");
    carriers_.count = arrays.allocate(cl, "ce4_fluid_carrier_count");
    upload(cl, carriers_.count, std::vector<cl_uint>(1, 0));  // the fluid stage scans the CE4s before its first step
  }
  if (excavation_) {
    std::vector<cl_int> of(2 * std::max<size_t>(1, count_), -1);
    for (size_t e = 0; e < count_; ++e) {
      for (int k = 0; k < 2; ++k) {
        const int x = model.excavation_of[e][k];
        if (x >= static_cast<int>(model.excavation_times.size()))
          throw InputError("CE4 " + std::to_string(e) + " names excavation " + std::to_string(x) + ", out of range");
        of[2 * e + k] = x;
      }
    }
    std::vector<real2> times;
    for (const auto& t : model.excavation_times) times.push_back(real2{real(t[0]), real(t[1])});
    excavation_of_ = arrays.allocate(cl, "ce4_excavation_of");
    excavation_time_ = arrays.allocate(cl, "ce4_excavation_time");
    excavation_energy_ = arrays.allocate(cl, "ce4_excavation_energy");
    upload(cl, excavation_of_, of);
    upload(cl, excavation_time_, times);
    upload(cl, excavation_energy_, std::vector<real2>(std::max<size_t>(1, count_)));
  }
  if (extrinsic_) {
    std::vector<cl_int> inserted(std::max<size_t>(1, count_), 1);
    for (size_t e = 0; e < count_; ++e) inserted[e] = model.fracture[model.properties[e]].extrinsic ? 0 : 1;
    inserted_ = arrays.allocate(cl, "ce4_inserted");
    insertion_gaps_ = arrays.allocate(cl, "ce4_insertion_gaps");
    inserted_count_ = arrays.allocate(cl, "ce4_inserted_count");
    upload(cl, inserted_, inserted);
    upload(cl, insertion_gaps_, std::vector<real>(4 * std::max<size_t>(1, count_)));
    upload(cl, inserted_count_, std::vector<cl_uint>(1, 0));
  }
  if (fans_) {
    std::vector<cl_uint> origin(std::max<size_t>(1, ref.size()), 0);
    for (size_t n = 0; n < model.node_origin.size(); ++n) {
      const int v = model.node_origin[n];
      if (v < 0 || size_t(v) >= mesh_nodes_)
        throw InputError("node " + std::to_string(n) + " copies mesh node " + std::to_string(v) + ", out of range");
      origin[n] = cl_uint(v);
    }
    std::vector<cl_int> state(mesh_nodes_);
    for (size_t v = 0; v < mesh_nodes_; ++v) state[v] = model.vertex_bonded[v] ? 0 : -1;
    node_origin_ = arrays.allocate(cl, "node origins");
    mesh_state_ = arrays.allocate(cl, "mesh_node_state");
    upload(cl, node_origin_, origin);
    upload(cl, mesh_state_, state);
  }
  nodes_ = arrays.allocate(cl, "ce4_nodes");
  length_ = arrays.allocate(cl, "ce4_length");
  property_ = arrays.allocate(cl, "ce4_property");
  property_rows_ = arrays.allocate(cl, "ce4_property_rows");
  gp_state_ = arrays.allocate(cl, "ce4_gauss_state");
  gp_slip_ = arrays.allocate(cl, "ce4_friction_slip");
  status_ = arrays.allocate(cl, "ce4_status");
  output_bytes_ = arrays.bytes("ce4_output");  // allocated by each output_column only
  slots_ = arrays.allocate(cl, "ce4_force");
  energy_ = arrays.allocate(cl, "ce4_energy");
  partial_ = arrays.allocate(cl, "ce4_energy_partials");
  break_count_ = arrays.allocate(cl, "ce4_break_count");
  status_step_ = arrays.allocate(cl, "ce4_status_step");
  upload(cl, status_step_, std::vector<cl_int>(1, 0));
  break_ids_ = arrays.allocate(cl, "ce4_break_ids");
  break_records_ = arrays.allocate(cl, "ce4_break_records");
  upload(cl, break_count_, std::vector<cl_uint>(1, 0));
  upload(cl, nodes_, nodes);
  {
    std::vector<real> lengths(count_);
    for (size_t e = 0; e < count_; ++e) lengths[e] = params_[layout::COH_STRIDE * e + layout::COH_H];
    upload(cl, length_, lengths);
  }
  upload(cl, property_, property);
  upload(cl, property_rows_, property_rows);
  upload(cl, gp_state_, std::vector<real>(9 * count_));
  std::vector<real4> slips(count_, real4{0, 0, 0, real(-1)});  // w: break time, -1 intact
  if (with_in_situ) {
    // The friction elements start where the field's shear has put them (InSituGaps).
    std::vector<real> gaps(6 * std::max<size_t>(1, count_), real(0));
    for (size_t e = 0; e < count_; ++e) {
      const InSituGaps& g = in_situ[e];
      for (int k = 0; k < 3; ++k) gaps[6 * e + k] = real(g.opening[k]), gaps[6 * e + 3 + k] = real(g.slip[k]);
      slips[e] = real4{real(g.friction_slip[0]), real(g.friction_slip[1]), real(g.friction_slip[2]), real(-1)};
    }
    in_situ_gaps_ = arrays.allocate(cl, "ce4_in_situ_gaps");
    upload(cl, in_situ_gaps_, gaps);
  }
  if (!model.closed.empty() && model.closed.size() != count_)
    throw InputError("cohesive model: " + std::to_string(count_) + " CE4s but " + std::to_string(model.closed.size()) +
                     " closed flags");
  // A broken joint's CE4s start closed (status 1, mode 0: broken before the run, so no
  // record in the break log) with break time 0.
  std::vector<cl_int> status(2 * count_, 0);
  for (size_t e = 0; e < model.closed.size(); ++e)
    if (model.closed[e]) status[2 * e] = 1, slips[e].w = real(0);
  upload(cl, gp_slip_, slips);
  upload(cl, status_, status);
  upload(cl, slots_, std::vector<real2>(4 * count_));
  upload(cl, energy_, std::vector<real>(3 * count_));

  std::map<std::string, std::string> defines;
  if (fans_) defines["CORNER_FANS"] = "1";
  if (with_in_situ) defines["IN_SITU_GAPS"] = "1";
  if (extrinsic_) defines["EXTRINSIC"] = "1";
  if (excavation_) defines["EXCAVATION"] = "1";
  if (model.fluid_carriers != 0) defines["FLUID_CARRIERS"] = std::to_string(model.fluid_carriers);
  if (model.activate_on_break) defines["ACTIVATE_ON_BREAK"] = "1";
  // NVIDIA: the kernel takes 160 registers a work-item when free to, which leaves room for
  // one work-group of 256 per SM; at 128 two fit. H200, 1.08M TRI3: 0.557 → 0.405 ms a
  // step (48: 0.891, 64: 0.584, 96: 0.478; docs/performance-notes.md, session 7).
  std::vector<const KernelSource*> libraries;
  if (excavation_) libraries.push_back(&kernel_source::excavation);
  const auto program = cl.build(kernel_source::cohesive_forces, defines, libraries, 128);
  kernel_ = compute::kernel(program, "cohesive_forces");
  KernelArgs args(kernel_);
  args("n_ce4", static_cast<cl_uint>(count_))("ce4_nodes", nodes_)("ce4_length", length_)("property", property_)("property_rows", property_rows_)("position", position)(
      "velocity", velocity)("dt", static_cast<real>(model.dt))("thickness", static_cast<real>(model.thickness));
  time_ = args.later("time", real(0));
  step_ = args.later("step", cl_int(0));
  args("gp_state", gp_state_)("gp_slip", gp_slip_)("status", status_)("slots", slots_)("energy", energy_)("break_count", break_count_)(
      "break_ids", break_ids_)("break_records", break_records_)("status_step", status_step_);
  if (fans_) args("node_origin", node_origin_)("mesh_node_state", mesh_state_);
  if (with_in_situ) args("in_situ_gaps", in_situ_gaps_);
  if (extrinsic_) args("inserted", inserted_)("insertion_gaps", insertion_gaps_);
  if (excavation_)
    args("excavation_of", excavation_of_)("excavation_time", excavation_time_)("excavation_energy", excavation_energy_);
  if (model.fluid_carriers != 0) args("fluid_carriers", carriers_.list)("fluid_carrier_count", carriers_.count);
  if (model.activate_on_break) {
    // Bound by join_on_break once the arrays exist (enqueue refuses to run before).
    join_triangles_ = args.later("ce4_triangles", compute::buffer());
    join_active_ = args.later("active", compute::buffer());
    activate_on_break_ = true;
  }
  args.done();
  partials_kernel_ = compute::kernel(program, "cohesive_energy_partials");
  bind_args(partials_kernel_)("n_ce4", static_cast<cl_uint>(count_))("n_partials", static_cast<cl_uint>(partials_))(
      "energy", energy_)("partial", partial_)
      .done();
  program_ = program;
}

void CohesiveForces::join_on_break(const compute::buffer& ce4_triangles, compute::buffer& active) {
  if (!activate_on_break_) throw DeviceError("cohesive forces: join_on_break without CohesiveModel::activate_on_break");
  join_triangles_.set(ce4_triangles);
  join_active_.set(active);
  joins_bound_ = true;
}

void CohesiveForces::enqueue(double time, long step) {
  if (activate_on_break_ && !joins_bound_)
    throw DeviceError("cohesive forces: activate_on_break set but join_on_break never called");
  time_.set(static_cast<real>(time));
  // A released CE4 records 2 + its step in a 32-bit status word (the contact stage tells
  // the release of the last step from older ones); past 2³¹ − 3 steps the word saturates.
  step_.set(static_cast<cl_int>(std::min<long>(step, std::numeric_limits<cl_int>::max() - 2)));
  cl_.enqueue(kernel_, count_);
}

std::vector<real> CohesiveForces::output_column(int k) {
  std::vector<real> column(count_);
  if (count_ == 0) return column;
  if (k == 3) {  // the break time: w of the friction slips (state)
    const auto rows = download<real4>(cl_, gp_slip_, count_);
    for (size_t e = 0; e < count_; ++e) column[e] = rows[e].w;
    return column;
  }
  // An output array for this read only (MemoryPlan::Lifetime::Output).
  compute::buffer out = cl_.allocate(output_bytes_, "ce4_output");
  compute::kernel kernel(program_, "cohesive_output");
  bind_args(kernel)("n_ce4", static_cast<cl_uint>(count_))("column", cl_int(k))("gp_state", gp_state_)("ce4_nodes", nodes_)(
      "position", position_)("out", out)
      .done();
  cl_.enqueue(kernel, count_);
  column = download<real>(cl_, out, count_);
  return column;
}

std::vector<io::BreakRecord> CohesiveForces::read_log(size_t first, size_t count) const {
  std::vector<io::BreakRecord> out(count);
  if (count == 0) return out;
  std::vector<cl_int> ids(2 * count);
  std::vector<real4> rec(count);
  cl_.queue().enqueue_read_buffer(break_ids_, first * 2 * sizeof(cl_int), ids.size() * sizeof(cl_int), ids.data());
  cl_.queue().enqueue_read_buffer(break_records_, first * sizeof(real4), count * sizeof(real4), rec.data());
  for (size_t k = 0; k < count; ++k) {
    auto& b = out[k];
    b.ce4 = ids[2 * k];
    b.mode = ids[2 * k + 1];
    b.time = double(rec[k].x);
    b.x = double(rec[k].y);
    b.y = double(rec[k].z);
    b.energy = double(rec[k].w);
    b.length = double(params_[layout::COH_STRIDE * size_t(b.ce4) + layout::COH_H]);
  }
  std::sort(out.begin(), out.end(), [](const io::BreakRecord& a, const io::BreakRecord& b) {
    return a.time != b.time ? a.time < b.time : a.ce4 < b.ce4;
  });
  return out;
}

std::vector<io::BreakRecord> CohesiveForces::drain_breaks() {
  if (count_ == 0) return {};
  cl_uint count = 0;
  cl_.queue().enqueue_read_buffer(break_count_, 0, sizeof(cl_uint), &count);
  // The kernel writes at most one record per CE4; a larger count would mean a CE4 broke
  // twice, which the status forbids.
  if (count > count_)
    throw DeviceError("cohesive_forces: the break log counts " + std::to_string(count) + " breaks for " +
                      std::to_string(count_) + " CE4s");
  if (count <= drained_) return {};
  auto fresh = read_log(drained_, count - drained_);
  drained_ = count;
  catalogue_.insert(catalogue_.end(), fresh.begin(), fresh.end());
  return fresh;
}

void CohesiveForces::save_state(StateWriter& out) const {
  out.buffer<real>("ce4_gauss_state", gp_state_, 3 * count_, 3);
  out.buffer<cl_int>("ce4_status", status_, count_, 2);
  out.buffer<real>("ce4_force", slots_, 4 * count_, 2);
  out.buffer<real>("ce4_friction_slip", gp_slip_, count_, 4);
  out.buffer<real>("ce4_energy", energy_, count_, 3);
  if (fans_) out.buffer<cl_int>("mesh_node_state", mesh_state_, mesh_nodes_, 1);
  if (excavation_) out.buffer<real>("ce4_excavation_energy", excavation_energy_, count_, 2);
  if (extrinsic_) {
    out.buffer<cl_int>("ce4_inserted", inserted_, count_, 1);
    out.buffer<real>("ce4_insertion_gaps", insertion_gaps_, count_, 4);
    out.buffer<cl_int>("ce4_inserted_count", inserted_count_, 1, 1);
  }
  // The break log in catalogue order (the device's slot order is not reproducible).
  cl_uint count = 0;
  if (count_) cl_.queue().enqueue_read_buffer(break_count_, 0, sizeof(cl_uint), &count);
  const auto log = read_log(0, count);
  std::vector<cl_int> ids(2 * log.size());
  std::vector<real> rec(4 * log.size());
  for (size_t k = 0; k < log.size(); ++k) {
    ids[2 * k] = cl_int(log[k].ce4), ids[2 * k + 1] = log[k].mode;
    rec[4 * k] = real(log[k].time), rec[4 * k + 1] = real(log[k].x), rec[4 * k + 2] = real(log[k].y),
            rec[4 * k + 3] = real(log[k].energy);
  }
  out.integer("ce4_break_count", static_cast<std::int64_t>(log.size()));
  out.host<cl_int>("ce4_break_ids", ids.data(), ids.size());
  out.host<real>("ce4_break_records", rec.data(), rec.size());
}

void CohesiveForces::load_state(StateReader& in) {
  in.buffer<real>("ce4_gauss_state", gp_state_, 3 * count_, 3);
  in.buffer<cl_int>("ce4_status", status_, count_, 2);
  in.buffer<real>("ce4_force", slots_, 4 * count_, 2);
  in.buffer<real>("ce4_friction_slip", gp_slip_, count_, 4);
  in.buffer<real>("ce4_energy", energy_, count_, 3);
  if (fans_) in.buffer<cl_int>("mesh_node_state", mesh_state_, mesh_nodes_, 1);
  if (excavation_) in.buffer<real>("ce4_excavation_energy", excavation_energy_, count_, 2);
  if (extrinsic_) {
    in.buffer<cl_int>("ce4_inserted", inserted_, count_, 1);
    in.buffer<real>("ce4_insertion_gaps", insertion_gaps_, count_, 4);
    in.buffer<cl_int>("ce4_inserted_count", inserted_count_, 1, 1);
  }
  const std::int64_t n = in.integer("ce4_break_count");
  if (n < 0 || size_t(n) > count_) throw InputError("checkpoint: ce4_break_count " + std::to_string(n) + " is out of range");
  std::vector<cl_int> ids(2 * size_t(n));
  std::vector<real> rec(4 * size_t(n));
  in.host<cl_int>("ce4_break_ids", ids.data(), ids.size());
  in.host<real>("ce4_break_records", rec.data(), rec.size());
  const cl_uint count = static_cast<cl_uint>(n);
  if (count_) {
    cl_.queue().enqueue_write_buffer(break_count_, 0, sizeof(cl_uint), &count);
    if (n) {
      std::vector<real4> r(count);
      for (size_t k = 0; k < count; ++k) r[k] = real4{rec[4 * k], rec[4 * k + 1], rec[4 * k + 2], rec[4 * k + 3]};
      cl_.queue().enqueue_write_buffer(break_ids_, 0, ids.size() * sizeof(cl_int), ids.data());
      cl_.queue().enqueue_write_buffer(break_records_, 0, r.size() * sizeof(real4), r.data());
    }
  }
  // What the checkpointed run had recorded is the catalogue so far.
  catalogue_ = read_log(0, count);
  drained_ = count;
}

std::vector<real> CohesiveForces::damage() { return output_column(0); }
std::vector<real> CohesiveForces::opening() { return output_column(1); }
std::vector<real> CohesiveForces::slip() { return output_column(2); }
std::vector<real> CohesiveForces::broken_time() { return output_column(3); }

std::vector<cl_int> CohesiveForces::inserted_flags() {
  if (!extrinsic_) return {};
  return download<cl_int>(cl_, inserted_, count_);
}

std::vector<int> CohesiveForces::broken() {
  const auto s = download<cl_int>(cl_, status_, 2 * count_);
  std::vector<int> out(count_);
  for (size_t e = 0; e < count_; ++e) out[e] = s[2 * e] != 0 ? 1 : 0;  // closed (1) or released (2 + step)
  return out;
}

std::vector<int> CohesiveForces::mode() {
  const auto s = download<cl_int>(cl_, status_, 2 * count_);
  std::vector<int> out(count_);
  for (size_t e = 0; e < count_; ++e) out[e] = s[2 * e + 1];
  return out;
}

void CohesiveForces::flags(std::vector<int>& broken, std::vector<int>& mode) {
  const auto s = download<cl_int>(cl_, status_, 2 * count_);
  broken.resize(count_);
  mode.resize(count_);
  for (size_t e = 0; e < count_; ++e) broken[e] = s[2 * e] != 0 ? 1 : 0, mode[e] = s[2 * e + 1];
}

std::vector<real> CohesiveForces::energy_column(int k) {
  const auto rows = download<real>(cl_, energy_, 3 * count_);
  std::vector<real> column(count_);
  for (size_t e = 0; e < count_; ++e) column[e] = rows[3 * e + k];
  return column;
}

std::vector<real> CohesiveForces::excavated() {
  std::vector<real> column(count_, real(0));
  if (!excavation_ || count_ == 0) return column;
  const auto rows = download<real2>(cl_, excavation_energy_, count_);
  for (size_t e = 0; e < count_; ++e) column[e] = rows[e].y;
  return column;
}

std::vector<real> CohesiveForces::work() { return energy_column(0); }
std::vector<real> CohesiveForces::dissipated() { return energy_column(1); }
std::vector<real> CohesiveForces::stored() { return energy_column(2); }

std::pair<double, double> CohesiveForces::energy_totals() {
  if (count_ == 0) return {0.0, 0.0};
  cl_.enqueue(partials_kernel_, partials_);
  double dissipation = 0, stored = 0;
  for (const real2& v : download<real2>(cl_, partial_, partials_)) dissipation += double(v.x), stored += double(v.y);
  return {dissipation, stored};
}

double CohesiveForces::fracture_dissipation() { return energy_totals().first; }
double CohesiveForces::stored_energy() { return energy_totals().second; }
double CohesiveForces::dissipated_total() { return fracture_dissipation(); }

size_t CohesiveForces::count_inserted() {
  if (!extrinsic_) return 0;
  cl_uint n = 0;
  cl_.queue().enqueue_read_buffer(inserted_count_, 0, sizeof(cl_uint), &n);
  return n;
}

size_t CohesiveForces::count_broken() {
  size_t n = 0;
  for (int b : broken()) n += b != 0;
  return n;
}

}  // namespace fdem
