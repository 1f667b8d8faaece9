#include "engine/model/extrinsic.hpp"
#include "engine/outputs/history_table.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <memory>


namespace fdem {

std::string netcdf_name(const std::string& region) {
  std::string out;
  for (char c : region) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "r_" + out;
  return out;
}

const PieceAreas& HistoryRow::pieces(const Model& model) {
  if (!pieces_) pieces_ = piece_areas(model, snap.labels, snap.positions);
  return *pieces_;
}

namespace {

// Largest out-of-balance force component on a free degree of freedom, and the mean
// internal-force magnitude per node (the out-of-balance force less gravity).
struct Unbalance {
  double largest = 0, mean_internal = 0;
};
// With extrinsic CE4s the tie moves the copies of a mesh vertex joined by uninserted CE4s
// as one body, and each copy's force is only its own triangle's share: the body's
// out-of-balance force is their sum. `vertex_start`: per node, the first node of its run
// of consecutive nodes that copy one mesh vertex with an extrinsic CE4 at it (extrinsic
// models number their nodes by vertex), else the node itself; empty for models without
// extrinsic CE4s. Within a run, the copies at bitwise the same position (what the tie
// leaves) are one body; every other node counts alone.
std::vector<uint32_t> vertex_runs(const Model& model) {
  std::vector<uint32_t> first;
  const auto extrinsic = extrinsic_ce4(model);
  if (extrinsic.empty() || model.node_origin.size() != model.num_nodes()) return first;
  std::vector<char> tied(size_t(*std::max_element(model.node_origin.begin(), model.node_origin.end())) + 1, 0);
  for (size_t e = 0; e < model.ce4.size(); ++e)
    if (extrinsic[e])
      for (int k : {0, 1}) tied[size_t(model.node_origin[model.ce4[e][k]])] = 1;
  first.resize(model.num_nodes());
  for (size_t i = 0; i < model.num_nodes(); ++i)
    first[i] = i > 0 && tied[size_t(model.node_origin[i])] && model.node_origin[i] == model.node_origin[i - 1]
                   ? first[i - 1] : uint32_t(i);
  return first;
}
// fixed[i]: node i's prescribed components (bit 0: x, bit 1: y), from its group's mask.
Unbalance unbalance(const Model& model, const std::vector<double>& mass, const std::vector<uint8_t>& fixed,
                    const std::vector<uint32_t>& vertex_start, HistoryRow& row) {
  if (row.unbalance) return {(*row.unbalance)[0], (*row.unbalance)[1]};
  const auto& f = row.snap.forces;
  Unbalance u;
  double internal_sum = 0;
  size_t bodies = 0;
  // One body (a node, or tied copies): its summed force and mass.
  auto body = [&](size_t i, double fx, double fy, double m) {
    if (!(fixed[i] & 1u)) u.largest = std::max(u.largest, std::fabs(fx));
    if (!(fixed[i] & 2u)) u.largest = std::max(u.largest, std::fabs(fy));
    // sqrt(x² + y²), not std::hypot: no force comes near where x² overflows, and glibc's
    // hypot made this loop most of a history row's host time (4 ms a row at 139k nodes).
    const double gx = fx - m * model.gravity[0], gy = fy - m * model.gravity[1];
    internal_sum += std::sqrt(gx * gx + gy * gy);
    ++bodies;
  };
  const auto& x = row.snap.positions;
  if (vertex_start.size() != f.size() || x.size() != f.size()) {
    for (size_t i = 0; i < f.size(); ++i) body(i, f[i].x, f[i].y, mass[i]);
  } else {
    std::vector<char> taken;
    for (size_t a = 0; a < f.size();) {
      size_t b = a + 1;
      while (b < f.size() && vertex_start[b] == a) ++b;
      taken.assign(b - a, 0);
      for (size_t i = a; i < b; ++i) {
        if (taken[i - a]) continue;
        double fx = f[i].x, fy = f[i].y, m = mass[i];
        for (size_t k = i + 1; k < b; ++k)
          if (!taken[k - a] && x[k].x == x[i].x && x[k].y == x[i].y)
            taken[k - a] = 1, fx += f[k].x, fy += f[k].y, m += mass[k];
        body(i, fx, fy, m);
      }
      a = b;
    }
  }
  u.mean_internal = bodies == 0 ? 0 : internal_sum / bodies;
  row.unbalance = std::array<double, 2>{u.largest, u.mean_internal};
  return u;
}

}  // namespace

Needs HistoryTable::needs(const Model& model, const PointProbes& probes) {
  // The account; the out-of-balance force, reactions and mean displacements.
  Needs needs = Need::Energy | Need::Forces | Need::Positions;
  if (model.contact.enabled) needs |= Need::ContactCounts;
  if (!model.ce4.empty()) needs |= Need::Ce4Flags | Need::FragmentLabels;
  if (!probes.empty()) needs |= Need::Probes;
  return needs;
}

HistoryTable::HistoryTable(const Model& model, const std::vector<real2>& masses, const PointProbes& probes) {
  auto add = [&](std::string name, std::string unit, std::string description, std::function<double(HistoryRow&)> f) {
    columns_.push_back({{std::move(name), std::move(unit), std::move(description), {}}, std::move(f)});
  };
  // The energy account (docs/case-format.md defines each term). Its values are those of
  // the row's last step's start, t - Δt: the positions that step's forces used.
  add("kinetic_energy", "J", "kinetic energy, 1/2 m v(t-dt/2).v(t+dt/2) with the integrator's (scaled) masses",
      [](HistoryRow& r) { return r.snap.energy.kinetic; });
  add("strain_energy", "J", "hyperelastic potential of the triangles (Eq. 1 or Eqs. 2-3)",
      [](HistoryRow& r) { return r.snap.energy.strain; });
  add("cohesive_stored_energy", "J", "recoverable elastic energy held by the intact CE4s",
      [](HistoryRow& r) { return r.snap.energy.cohesive_stored; });
  add("contact_stored_energy", "J", "normal penalty potential and tangential springs of the contact couples",
      [](HistoryRow& r) { return r.snap.energy.contact_stored; });
  add("gravity_potential", "J", "-sum m g.(x - X), relative to the reference positions",
      [](HistoryRow& r) { return r.snap.energy.gravity_potential; });
  add("viscous_dissipation", "J", "work of the viscous stress eta D, cumulative",
      [](HistoryRow& r) { return r.snap.energy.viscous; });
  add("local_damping_dissipation", "J", "work of the local (Cundall) damping forces, cumulative",
      [](HistoryRow& r) { return r.snap.energy.local_damping; });
  add("friction_dissipation", "J", "contact friction work, cumulative", [](HistoryRow& r) { return r.snap.energy.friction; });
  add("contact_damping_dissipation", "J", "work of the contact damping (Eq. 15), cumulative",
      [](HistoryRow& r) { return r.snap.energy.contact_damping; });
  add("fracture_dissipation", "J", "energy dissipated by CE4 softening and breaking, cumulative",
      [](HistoryRow& r) { return r.snap.energy.fracture; });
  add("absorbed_energy", "J", "energy taken out by absorbing boundaries, cumulative",
      [](HistoryRow& r) { return r.snap.energy.absorbed; });
  if (!model.excavations.empty())
    add("excavated_energy", "J", "strain energy carried out by excavated triangles as their forces ramp to zero, cumulative",
        [](HistoryRow& r) { return r.snap.energy.excavated; });
  add("boundary_work", "J", "work of the reactions of prescribed velocities and fixed components, cumulative",
      [](HistoryRow& r) { return r.snap.energy.boundary_work; });
  add("load_work", "J", "work of tractions, pressures and blast loads, cumulative",
      [](HistoryRow& r) { return r.snap.energy.load_work; });
  add("energy_error", "1", "(stored + dissipated - supplied - initial stored) / max(|supplied|, initial stored, peak kinetic)",
      [](HistoryRow& r) { return r.snap.energy_error; });
  add("energy_ratio", "1", "(stored + dissipated) / (initial stored + supplied)",
      [](HistoryRow& r) { return r.snap.energy_ratio; });

  if (model.fluid.enabled) {  // [fluid]: its terms of the account and its figures (FluidFlow)
    add("fluid_stored_energy", "J", "energy of the compressed fluid in the cracks",
        [](HistoryRow& r) { return r.snap.energy.fluid_stored; });
    add("fluid_viscous_dissipation", "J", "viscous dissipation of the flow in the cracks (cubic law), cumulative",
        [](HistoryRow& r) { return r.snap.energy.fluid_viscous; });
    add("fluid_injection_work", "J", "work of the fluid source, integral of p Q dt, cumulative",
        [](HistoryRow& r) { return r.snap.energy.fluid_injection; });
    add("fluid_face_work", "J", "work of the fluid pressure on the crack faces, cumulative (passed to the solid; not a term of energy_error)",
        [](HistoryRow& r) { return r.snap.energy.fluid_face_work; });
    add("injected_volume", "m3", "fluid volume injected by the source (at zero pressure), cumulative",
        [](HistoryRow& r) { return r.snap.energy.fluid_injected_volume; });
    add("fluid_volume", "m3", "fluid volume in the network (at zero pressure)",
        [](HistoryRow& r) { return r.snap.energy.fluid_volume; });
    add("crack_volume", "m3", "volume of the broken CE4s' openings plus the residual aperture",
        [](HistoryRow& r) { return r.snap.energy.crack_volume; });
    if (model.fluid.leak_off > 0) {  // Carter's leak-off (fluid.leak_off)
      add("leaked_volume", "m3", "fluid volume leaked off into the rock (Carter, at zero pressure), cumulative",
          [](HistoryRow& r) { return r.snap.energy.fluid_leaked_volume; });
      add("fluid_leak_off_energy", "J", "energy of the compressed fluid that leaked off, cumulative (leaves the model)",
          [](HistoryRow& r) { return r.snap.energy.fluid_leak_off; });
    }
    add("wellbore_pressure", "Pa", "fluid pressure at the source (mean over its vertices)",
        [](HistoryRow& r) { return r.snap.energy.wellbore_pressure; });
    add("fluid_substeps", "1", "sub-steps of the flow in the last step (the plan's from fluid.max_aperture, or fewer when the network's rate allows)",
        [](HistoryRow& r) { return r.snap.energy.fluid_substeps; });
    if (model.fluid.gas) {  // [fluid.gas]: the blast hole's gas, and the masses
      add("hole_pressure", "Pa", "pressure of the gas in the blast hole, p0 (rho/rho0)^gamma",
          [](HistoryRow& r) { return r.snap.energy.hole_pressure; });
      add("hole_volume", "m3", "volume of the blast hole (its wall polygon's area times the thickness)",
          [](HistoryRow& r) { return r.snap.energy.hole_volume; });
      add("hole_gas_mass", "kg", "mass of gas left in the blast hole",
          [](HistoryRow& r) { return r.snap.energy.hole_gas_mass; });
      add("network_gas_mass", "kg", "mass of gas in the cracks (rho0 times fluid_volume)",
          [](HistoryRow& r) { return r.snap.energy.gas_density * r.snap.energy.fluid_volume; });
      add("hole_gas_energy", "J", "energy of the gas left in the blast hole, p V / (gamma - 1) (outside the account: the hole is the source)",
          [](HistoryRow& r) { return r.snap.energy.hole_gas_energy; });
    }
  }

  // Per node, not through node_group and groups at each row (half of a row's host time at 139k nodes).
  auto mass = std::make_shared<std::vector<double>>();
  for (const auto& mk : masses) mass->push_back(mk.x);
  auto fixed = std::make_shared<std::vector<uint8_t>>(model.num_nodes());
  for (size_t i = 0; i < fixed->size(); ++i) (*fixed)[i] = static_cast<uint8_t>(model.groups[model.node_group[i]].mask & 3u);
  auto runs = std::make_shared<std::vector<uint32_t>>(vertex_runs(model));
  add("max_unbalanced_force", "N",
      runs->empty() ? "largest out-of-balance force component on a free degree of freedom"
                    : "largest out-of-balance force component on a free degree of freedom (tied copies summed)",
      [&model, mass, fixed, runs](HistoryRow& r) { return unbalance(model, *mass, *fixed, *runs, r).largest; });
  add("unbalanced_ratio", "1", "max_unbalanced_force / mean internal-force magnitude per node",
      [&model, mass, fixed, runs](HistoryRow& r) {
        const Unbalance u = unbalance(model, *mass, *fixed, *runs, r);
        return u.mean_internal > 0 ? u.largest / u.mean_internal : 0.0;
      });

  if (model.contact.enabled) {
    add("contact_couples", "1", "triangle couples in contact (overlapping) in the last step",
        [](HistoryRow& r) { return double(r.snap.contact_touching); });
    add("contact_candidates", "1", "candidate couples from the last contact detection",
        [](HistoryRow& r) { return double(r.snap.contact_candidates); });
    add("contact_rebuilds", "1", "contact detections run since the start",
        [](HistoryRow& r) { return double(r.snap.contact_rebuilds); });
  }
  if (!model.ce4.empty()) {
    std::vector<double> length;  // initial length of each CE4 [m]
    for (const auto& c : model.ce4) length.push_back(std::hypot(model.x[c[1]] - model.x[c[0]], model.y[c[1]] - model.y[c[0]]));
    auto count = [](HistoryRow& r, int mode) {
      const auto& broken = r.snap.broken;
      const auto& modes = r.snap.mode;
      double n = 0;
      for (size_t e = 0; e < broken.size(); ++e) n += broken[e] && (mode == 0 || modes[e] == mode) ? 1 : 0;
      return n;
    };
    if (has_extrinsic(model))  // fracture.model = "extrinsic": CE4s appear during the run
      add("inserted_ce4", "1", "extrinsic CE4s inserted so far (their edges reached the peak traction)",
          [](HistoryRow& r) { return double(r.snap.inserted_ce4); });
    add("broken_ce4", "1", "broken cohesive elements", [count](HistoryRow& r) { return count(r, 0); });
    add("broken_mode1", "1", "CE4s broken in mode I", [count](HistoryRow& r) { return count(r, 1); });
    add("broken_mode2", "1", "CE4s broken in mode II", [count](HistoryRow& r) { return count(r, 2); });
    add("broken_mixed", "1", "CE4s broken in mixed mode I-II", [count](HistoryRow& r) { return count(r, 3); });
    add("crack_length", "m", "total initial length of the broken CE4s", [length](HistoryRow& r) {
      const auto& broken = r.snap.broken;
      double sum = 0;
      for (size_t e = 0; e < broken.size(); ++e) sum += broken[e] ? length[e] : 0.0;
      return sum;
    });
    // The pieces: triangles joined by intact CE4s or shared nodes (FragmentLabels).
    add("fragments", "1", "connected pieces of the body (triangles joined by intact CE4s or shared nodes)",
        [&model](HistoryRow& r) { return double(r.pieces(model).count); });
    add("largest_fragment", "1", "area of the largest piece / total area (current areas)",
        [&model](HistoryRow& r) { return r.pieces(model).largest_fraction; });
  }

  for (const Region& region : model.regions) {
    const std::string n = netcdf_name(region.name);
    const Region* r = &region;
    // Reaction on a prescribed component: minus the out-of-balance force there.
    auto reaction = [&model, r](HistoryRow& row, uint32_t bit, int axis) {
      const auto& f = row.snap.forces;
      double sum = 0;
      for (int node : r->nodes)
        if (model.groups[model.node_group[node]].mask & bit) sum -= axis ? f[node].y : f[node].x;
      return sum;
    };
    auto mean_displacement = [&model, r](HistoryRow& row, int axis) {
      const auto& x = row.snap.positions;
      double sum = 0;
      for (int node : r->nodes) sum += axis ? x[node].y - model.y[node] : x[node].x - model.x[node];
      return sum / double(r->nodes.size());
    };
    if (r->prescribed) {
      add(n + "_force_x", "N", "reaction force on region " + r->name + ", x (prescribed components)",
          [reaction](HistoryRow& row) { return reaction(row, 1u, 0); });
      add(n + "_force_y", "N", "reaction force on region " + r->name + ", y (prescribed components)",
          [reaction](HistoryRow& row) { return reaction(row, 2u, 1); });
    }
    add(n + "_disp_x", "m", "mean displacement of region " + r->name + ", x",
        [mean_displacement](HistoryRow& row) { return mean_displacement(row, 0); });
    add(n + "_disp_y", "m", "mean displacement of region " + r->name + ", y",
        [mean_displacement](HistoryRow& row) { return mean_displacement(row, 1); });
  }

  const auto probe_variables = probes.variables(model);
  for (size_t k = 0; k < probe_variables.size(); ++k)
    columns_.push_back({probe_variables[k], [k](HistoryRow& r) { return r.snap.probes[k]; }});
}

std::vector<io::HistoryVariable> HistoryTable::variables() const {
  std::vector<io::HistoryVariable> out;
  for (const auto& c : columns_) out.push_back(c.variable);
  return out;
}

std::vector<double> HistoryTable::values(HistoryRow& row) const {
  std::vector<double> out;
  out.reserve(columns_.size());
  for (const auto& c : columns_) out.push_back(c.value(row));
  return out;
}

int HistoryTable::index(const std::string& name) const {
  for (size_t k = 0; k < columns_.size(); ++k)
    if (columns_[k].variable.name == name) return static_cast<int>(k);
  return -1;
}

}  // namespace fdem
