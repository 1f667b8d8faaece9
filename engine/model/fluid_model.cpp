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

// [fluid.gas]: the hole's wall polygon and volume, and its network vertices as the source.
void build_gas_hole(const Model& model, FluidModel& f, const std::string& path) {
  const std::string key = path + ": fluid.gas.hole: curve '" + f.hole_name + "'";
  std::vector<size_t> wall;  // the loaded edges of LoadKind::Gas, in model order
  for (size_t k = 0; k < model.loaded_edges.size(); ++k)
    if (model.loads[model.loaded_edges[k].load].kind == LoadKind::Gas) wall.push_back(k);
  if (wall.empty()) throw InputError(key + " has no boundary edge");
  // Walk the wall: the edge after edge k starts at the mesh vertex edge k ends at.
  std::map<int, size_t> starting_at;  // mesh vertex → wall edge starting there
  for (size_t k : wall) {
    const int origin = model.node_origin[model.loaded_edges[k].a];
    if (!starting_at.emplace(origin, k).second)
      throw InputError(key + " is not a single closed curve around a hole: two of its edges start at node " +
                       std::to_string(model.node_tags[model.loaded_edges[k].a]));
  }
  std::vector<size_t> order{wall.front()};
  for (;;) {
    auto next = starting_at.find(model.node_origin[model.loaded_edges[order.back()].b]);
    if (next == starting_at.end())
      throw InputError(key + " is not closed: it ends at node " +
                       std::to_string(model.node_tags[model.loaded_edges[order.back()].b]) +
                       " (the gas needs a hole: a closed curve with the body outside it)");
    if (next->second == order.front()) break;
    if (order.size() > wall.size())
      throw InputError(key + " is not a single closed curve around a hole");
    order.push_back(next->second);
  }
  if (order.size() != wall.size())
    throw InputError(key + " is not a single closed curve: " + std::to_string(wall.size() - order.size()) + " of its " +
                     std::to_string(wall.size()) + " edges are on another loop (one hole per case)");
  double twice_area = 0;
  for (size_t k : order) {
    f.hole_polygon.push_back(static_cast<uint32_t>(model.loaded_edges[k].a));
    f.hole_polygon.push_back(static_cast<uint32_t>(model.loaded_edges[k].b));
  }
  for (size_t i = 0; i < f.hole_polygon.size(); ++i) {
    const uint32_t p = f.hole_polygon[i], q = f.hole_polygon[(i + 1) % f.hole_polygon.size()];
    twice_area += model.x[p] * model.y[q] - model.x[q] * model.y[p];
  }
  // The body is on each edge's left, so a hole is walked clockwise (negative area).
  if (!(twice_area < 0))
    throw InputError(key + " does not enclose a hole: the body lies inside it (the gas fills a hole in the body, "
                           "e.g. a blast hole's wall)");
  f.hole_volume = -0.5 * twice_area * model.thickness;
  // The source: the wall's mesh vertices that are network vertices (every vertex of a
  // fracturable wall is: its CE4s run into the body from it).
  std::vector<char> on(f.vertices, 0);
  std::map<int, uint32_t> vertex_of;
  for (size_t v = 0; v < f.vertices; ++v) vertex_of[model.node_origin[size_t(f.vertex_mesh_node[v])]] = uint32_t(v);
  for (uint32_t n : f.hole_polygon) {
    auto it = vertex_of.find(model.node_origin[n]);
    if (it != vertex_of.end()) on[it->second] = 1;
  }
  for (uint32_t v = 0; v < f.vertices; ++v)
    if (on[v]) f.source_vertices.push_back(v);
  if (f.source_vertices.empty())
    throw InputError(key + " touches no CE4: the gas could not leave the hole (the rock around it must be fracturable)");
  f.source_name = f.hole_name;
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
  f.cap_aperture = c.cap_aperture;
  if (c.gas) {
    f.gas = true;
    f.gamma = c.gas->gamma, f.gas_density = c.gas->density, f.gas_pressure = c.gas->pressure;
    f.hole_name = c.gas->hole;
    f.pressure_source = true;  // the hole's wall vertices are held at the hole's pressure
  } else {
    f.pressure_source = c.pressure.has_value();
    f.history = c.pressure ? *c.pressure : *c.rate;
  }
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
    const double dt = 3.0 * c.viscosity * h * h / (f.stiffness() * c.max_aperture * c.max_aperture);
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
  if (f.gas) {
    build_gas_hole(model, f, path);
    return f;
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
    const double k_fluid = 9.0 / 16.0 * model.fluid.stiffness() * model.fluid.segment_length[e] * model.thickness /
                           model.fluid.residual_aperture;
    const double dt = std::sqrt(2.0 * lightest / k_fluid);
    if (lightest > 0 && dt < out.dt) out.dt = dt, out.ce4 = e;
  }
  return out;
}

}  // namespace fdem
