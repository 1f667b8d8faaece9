#include "engine/model/fluid_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "base/errors.hpp"
#include "engine/model/fluid_spring.hpp"
#include "engine/model/model.hpp"

namespace fdem {

namespace {

const Region* find_region(const Model& model, const std::string& name) {
  for (const auto& r : model.regions)
    if (r.name == name) return &r;
  return nullptr;
}

}  // namespace

double fluid_source_value(const io::PressureTable& table, double t) {
  const auto& ts = table.times;
  const auto& vs = table.values;
  if (ts.empty()) return 0.0;
  if (t <= ts.front()) return vs.front();
  if (t >= ts.back()) return vs.back();
  const size_t k = static_cast<size_t>(std::upper_bound(ts.begin(), ts.end(), t) - ts.begin());
  const double f = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
  return vs[k - 1] + f * (vs[k] - vs[k - 1]);
}

FluidModel build_fluid_model(const Model& model, const io::FluidConfig& c, const std::string& path) {
  FluidModel f;
  f.enabled = true;
  f.viscosity = c.viscosity, f.bulk_modulus = c.bulk_modulus;
  f.residual_aperture = c.residual_aperture, f.max_aperture = c.max_aperture, f.safety = c.safety;
  f.leak_off = c.leak_off;
  f.damaged_segments = c.damaged_segments;
  f.source_name = c.source, f.crack_name = c.crack;
  f.pressure_source = c.pressure.has_value();
  f.history = c.pressure ? *c.pressure : *c.rate;
  if (model.ce4.empty() || model.node_origin.empty())
    throw InputError(path + ": [fluid] needs cracks to flow in: the model has no CE4s (give a fracturable "
                            "[[material]] a [material.fracture] table)");

  // Vertices: the mesh vertices at the CE4s' ends, numbered in ascending mesh-vertex order.
  std::map<int, uint32_t> vertex_of;
  for (const auto& e : model.ce4) vertex_of[model.node_origin[e[0]]], vertex_of[model.node_origin[e[1]]];
  uint32_t next = 0;
  for (auto& [origin, v] : vertex_of) v = next++;
  f.vertices = next;
  f.vertex_mesh_node.assign(f.vertices, -1);
  for (size_t n = 0; n < model.num_nodes(); ++n) {
    auto it = vertex_of.find(model.node_origin[n]);
    if (it != vertex_of.end() && f.vertex_mesh_node[it->second] < 0) f.vertex_mesh_node[it->second] = static_cast<int>(n);
  }
  std::vector<std::vector<uint32_t>> ends(f.vertices);
  f.stable_dt = std::numeric_limits<double>::infinity();
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const auto& n = model.ce4[e];
    const uint32_t a = vertex_of.at(model.node_origin[n[0]]), b = vertex_of.at(model.node_origin[n[1]]);
    f.segment_vertex.push_back(a);
    f.segment_vertex.push_back(b);
    ends[a].push_back(static_cast<uint32_t>(2 * e));
    ends[b].push_back(static_cast<uint32_t>(2 * e + 1));
    const double h = std::hypot(model.x[n[1]] - model.x[n[0]], model.y[n[1]] - model.y[n[0]]);
    f.segment_length.push_back(h);
    const double dt = 3.0 * c.viscosity * h * h / (c.bulk_modulus * c.max_aperture * c.max_aperture);
    if (dt < f.stable_dt) f.stable_dt = dt, f.shortest_ce4 = e;
  }
  f.vertex_start.push_back(0);
  for (const auto& list : ends) {
    f.vertex_end.insert(f.vertex_end.end(), list.begin(), list.end());
    f.vertex_start.push_back(static_cast<uint32_t>(f.vertex_end.size()));
  }

  // The crack: CE4s with both ends on the physical curve.
  std::vector<char> crack_vertex(f.vertices, 0);
  if (!c.crack.empty()) {
    const Region* r = find_region(model, c.crack);
    if (!r) throw InputError(path + ": fluid.crack: no physical group '" + c.crack + "' in the mesh");
    std::vector<char> on(model.num_nodes(), 0);
    for (int n : r->nodes) on[n] = 1;
    for (size_t e = 0; e < model.ce4.size(); ++e)
      if (on[model.ce4[e][0]] && on[model.ce4[e][1]]) {
        f.crack_ce4.push_back(static_cast<uint32_t>(e));
        crack_vertex[f.segment_vertex[2 * e]] = crack_vertex[f.segment_vertex[2 * e + 1]] = 1;
      }
    if (f.crack_ce4.empty())
      throw InputError(path + ": fluid.crack: physical group '" + c.crack +
                       "' has no CE4 along it (it must be a curve inside a fracturable region)");
  }
  // The source: its vertices in the network; at the start each must be on the crack.
  const Region* s = find_region(model, c.source);
  if (!s) throw InputError(path + ": fluid.source: no physical group '" + c.source + "' in the mesh");
  for (int n : s->nodes) {
    auto it = vertex_of.find(model.node_origin[n]);
    if (it != vertex_of.end()) f.source_vertices.push_back(it->second);
  }
  std::sort(f.source_vertices.begin(), f.source_vertices.end());
  f.source_vertices.erase(std::unique(f.source_vertices.begin(), f.source_vertices.end()), f.source_vertices.end());
  if (f.source_vertices.empty())
    throw InputError(path + ": fluid.source: physical group '" + c.source + "' touches no CE4");
  for (uint32_t v : f.source_vertices)
    if (!crack_vertex[v])
      throw InputError(path + ": fluid.source: physical group '" + c.source +
                       "' has a vertex that is not on fluid.crack: the fluid injected there would have no room "
                       "(every source vertex must lie on the pre-existing crack)");
  return f;
}

FluidSpring fluid_spring(const Model& model) {
  // Lumped node masses (ρ A t / 3 per triangle corner).
  std::vector<double> mass(model.num_nodes(), 0.0);
  for (size_t m = 0; m < model.materials.size(); ++m)
    for (size_t t = model.block_start[m]; t < model.block_start[m + 1]; ++t) {
      const auto& tri = model.triangles[t];
      const double area = 0.5 * std::fabs((model.x[tri[1]] - model.x[tri[0]]) * (model.y[tri[2]] - model.y[tri[0]]) -
                                          (model.x[tri[2]] - model.x[tri[0]]) * (model.y[tri[1]] - model.y[tri[0]]));
      for (int k = 0; k < 3; ++k) mass[tri[k]] += model.materials[m].density * area * model.thickness / 3.0;
    }
  FluidSpring out;
  out.dt = std::numeric_limits<double>::infinity();
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const auto& n = model.ce4[e];
    double lightest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) lightest = std::min(lightest, mass[n[k]]);
    const double k_fluid = 9.0 / 16.0 * model.fluid.bulk_modulus * model.fluid.segment_length[e] * model.thickness /
                           model.fluid.residual_aperture;
    const double dt = std::sqrt(2.0 * lightest / k_fluid);
    if (lightest > 0 && dt < out.dt) out.dt = dt, out.ce4 = e;
  }
  return out;
}

}  // namespace fdem
