#include "engine/model/model.hpp"
#include "engine/model/extrinsic.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "engine/model/fluid_spring.hpp"
#include "engine/model/heterogeneity.hpp"
#include "io/grain_geometry.hpp"
#include "io/joint_geometry.hpp"
#include "io/mesh.hpp"
#include "io/suggest.hpp"

namespace fdem {

namespace {

std::string dim_word(int dim) { return dim == 2 ? "surface" : dim == 1 ? "curve" : "point"; }

std::vector<std::string> group_names(const io::Mesh& mesh, int dim = -1) {
  std::vector<std::string> names;
  for (const auto& g : mesh.groups)
    if ((dim < 0 || g.dim == dim) && !g.name.empty()) names.push_back(g.name);
  return names;
}

std::string list_names(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out.empty() ? "(none)" : out;
}

// Group indices with this name (any dimension), or an InputError with a suggestion.
std::vector<int> find_region(const io::Mesh& mesh, const std::string& name, const std::string& where) {
  std::vector<int> found;
  for (size_t g = 0; g < mesh.groups.size(); ++g)
    if (mesh.groups[g].name == name) found.push_back(static_cast<int>(g));
  if (found.empty())
    throw InputError(where + ": region '" + name + "' is not a physical group of mesh " +
                     mesh.source + io::did_you_mean(name, group_names(mesh)) +
                     "; its physical groups are " + list_names(group_names(mesh)));
  return found;
}

struct EdgeOwner {
  int triangle = -1;
  int a = 0, b = 0;  // the edge in the triangle's counter-clockwise order
  int count = 0;     // triangles sharing the edge
};

std::pair<int, int> edge_key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

// Position of cell (x, y) of a 65,536 × 65,536 grid along the Hilbert curve that fills it
// (the classic rotate-and-flip walk, one quadrant per bit pair).
uint64_t hilbert_index(uint32_t x, uint32_t y) {
  uint64_t d = 0;
  for (uint32_t s = 1u << 15; s > 0; s >>= 1) {
    const uint32_t rx = (x & s) ? 1u : 0u, ry = (y & s) ? 1u : 0u;
    d += uint64_t(s) * uint64_t(s) * ((3u * rx) ^ ry);
    if (ry == 0) {
      if (rx == 1) x = 65535u - x, y = 65535u - y;  // flips the lower bits, which are what is left to read
      std::swap(x, y);
    }
  }
  return d;
}

}  // namespace

double mean_edge_length(const Model& model) {
  double sum = 0;
  size_t edges = 0;
  for (const auto& tri : model.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      sum += std::hypot(model.x[b] - model.x[a], model.y[b] - model.y[a]);
      ++edges;
    }
  return edges ? sum / static_cast<double>(edges) : 0.0;
}

double default_skin(const Model& model) { return kDefaultSkinFraction * mean_edge_length(model); }

double default_tangential_penalty(double normal_penalty, double mean_edge) {
  return kTangentialPenaltyFactor * normal_penalty / mean_edge;
}

namespace {

// `mean_edge`: mean_edge_length of the model, the h of the default P_tan.
ContactModel build_contact(const io::ContactConfig& c, const io::CaseConfig& config, double mean_edge) {
  ContactModel contact;
  contact.enabled = true;
  contact.rebuild_skin = c.rebuild == io::ContactRebuild::Skin;
  contact.skin = c.skin.value_or(0.0);  // a skin rebuild without `skin`: set from the mesh (default_skin)
  contact.skin_from_mesh = contact.rebuild_skin && !c.skin;
  contact.skin_auto = contact.rebuild_skin && c.skin_auto;
  contact.list_ahead = contact.rebuild_skin && c.activation == "fractured";
  const size_t n = config.materials.size();
  auto row = [&](double pn, double ptan, double mu, const std::optional<io::ContactDampingConfig>& d) {
    const double T = d ? d->transition : std::numeric_limits<double>::infinity();
    const double b = d ? d->exponent : 1.0;
    const bool damped = d && (std::isfinite(T) || b != 1.0);
    std::array<double, layout::CONTACT_PROPS> props{};
    props[layout::PAIR_NORMAL_PENALTY] = pn;
    props[layout::PAIR_TANGENTIAL_PENALTY] = ptan;
    props[layout::PAIR_FRICTION] = mu;
    props[layout::PAIR_TENSILE] = std::isfinite(T) ? T : std::numeric_limits<double>::max();
    props[layout::PAIR_DAMPING] = b;
    props[layout::PAIR_DAMPED] = damped ? 1.0 : 0.0;
    contact.pair_props.insert(contact.pair_props.end(), props.begin(), props.end());
    contact.max_normal_penalty = std::max(contact.max_normal_penalty, pn);
    contact.max_tangential_penalty = std::max(contact.max_tangential_penalty, ptan);
    return static_cast<uint32_t>(contact.pair_props.size() / layout::CONTACT_PROPS - 1);
  };
  // P_tan not given in the pair nor in [contact]: consistent with the pair's own P_n.
  auto tangential = [&](const std::optional<double>& pair_value, double pn) {
    return pair_value ? *pair_value
                      : c.tangential_penalty ? *c.tangential_penalty : default_tangential_penalty(pn, mean_edge);
  };
  const uint32_t defaults =
      row(c.normal_penalty, tangential(std::nullopt, c.normal_penalty), c.friction, c.damping);
  contact.pair_index.assign(n * n, defaults);
  auto index_of = [&](const std::string& name) {
    for (size_t m = 0; m < n; ++m)
      if (config.materials[m].name == name) return m;
    throw InputError(config.path + ": contact.pair names unknown material '" + name + "'");
  };
  for (const auto& pair : c.pairs) {
    const size_t a = index_of(pair.materials[0]), b = index_of(pair.materials[1]);
    const double pn = pair.normal_penalty.value_or(c.normal_penalty);
    const uint32_t r = row(pn, tangential(pair.tangential_penalty, pn), pair.friction.value_or(c.friction),
                           pair.damping ? pair.damping : c.damping);
    contact.pair_index[a * n + b] = contact.pair_index[b * n + a] = r;
  }
  return contact;
}

FractureProperties fracture_properties(const io::FractureConfig& f) {
  FractureProperties p;
  p.tensile_strength = f.tensile_strength;
  p.cohesion = f.cohesion;
  p.friction_angle = f.friction_angle;
  p.gf1 = f.gf1;
  p.gf2 = f.gf2;
  p.penalty_opening = f.penalty_opening;
  p.penalty_sliding = f.penalty_sliding;
  p.penalty_overlap = f.penalty_overlap;
  p.a = f.softening_a;
  p.b = f.softening_b;
  p.c = f.softening_c;
  p.extrinsic = f.extrinsic;
  return p;
}

// Gives every triangle of a fracturable material its own three nodes and puts a CE4 on
// every interior edge between two fracturable triangles (same material, or two
// materials joined by an [[interface]]). Every node-indexed array of the model follows:
// a region, boundary condition or initial velocity on an original node applies to all
// of its copies; a loaded edge moves to the copies of its one triangle.
// `joint_edges`: the [[joint]] of each mesh edge on a joint's curves (model node indices,
// edge_key order); such an edge gets a CE4 of the joint's properties whatever its
// materials' (both must be fracturable; joint_edges checks that).
void split_fracturable(Model& model, const io::CaseConfig& config, const std::map<std::pair<int, int>, int>& joint_edges,
                       std::vector<std::string>& notes) {
  const size_t n_materials = config.materials.size();
  std::vector<int> material_fracture(n_materials, -1);
  for (size_t m = 0; m < n_materials; ++m)
    if (config.materials[m].fracture) {
      material_fracture[m] = static_cast<int>(model.fracture.size());
      model.fracture.push_back(fracture_properties(*config.materials[m].fracture));
    }
  model.triangle_fracturable.assign(model.num_triangles(), false);
  bool any = false;
  for (size_t t = 0; t < model.num_triangles(); ++t)
    any |= model.triangle_fracturable[t] = material_fracture[model.triangle_material[t]] >= 0;
  if (!any) return;
  std::vector<int> pair_fracture(n_materials * n_materials, -1);
  for (size_t m = 0; m < n_materials; ++m) pair_fracture[m * n_materials + m] = material_fracture[m];
  for (const auto& interface : config.interfaces) {
    size_t a = 0, b = 0;
    for (size_t m = 0; m < n_materials; ++m) {
      if (config.materials[m].name == interface.materials[0]) a = m;
      if (config.materials[m].name == interface.materials[1]) b = m;
    }
    const int index = static_cast<int>(model.fracture.size());
    model.fracture.push_back(fracture_properties(interface.fracture));
    pair_fracture[a * n_materials + b] = pair_fracture[b * n_materials + a] = index;
  }
  const int first_joint = static_cast<int>(model.fracture.size());
  for (const auto& joint : config.joints) {
    model.fracture.push_back(fracture_properties(joint.fracture));
    model.joint_names.push_back(joint.name);
    model.joint_broken.push_back(joint.broken ? 1 : 0);
  }
  auto joint_of = [&](const std::pair<int, int>& key) {
    const auto it = joint_edges.find(key);
    return it == joint_edges.end() ? -1 : it->second;
  };
  // [grains]: the grain-boundary set after the joints'.
  if (config.grains) {
    model.grain_boundary_fracture = static_cast<int>(model.fracture.size());
    model.fracture.push_back(fracture_properties(config.grains->boundary));
  }
  // 1 on a grain boundary, 0 inside a grain, -1 not between two grains' triangles.
  auto grain_side = [&](int t1, int t2) {
    if (model.triangle_grain.empty() || model.triangle_grain[t1] < 0 || model.triangle_grain[t2] < 0) return -1;
    return model.triangle_grain[t1] != model.triangle_grain[t2] ? 1 : 0;
  };
  // The fracture set of an interior edge: its joint's, a grain boundary's, or its pair of
  // materials' (-1: none, an unbonded interface).
  auto props_of = [&](const std::pair<int, int>& key, int t1, int t2) {
    const int joint = joint_of(key);
    if (joint >= 0) return first_joint + joint;
    if (grain_side(t1, t2) == 1) return model.grain_boundary_fracture;
    return pair_fracture[model.triangle_material[t1] * n_materials + model.triangle_material[t2]];
  };

  // Interior edges of the unsplit mesh: (a, b) of triangle t1 in its CCW order, the
  // twin (b, a) of t2.
  struct Side {
    int triangle = -1, corner = 0;  // the edge runs from corner to corner + 1
  };
  std::map<std::pair<int, int>, std::array<Side, 2>> edges;
  for (size_t t = 0; t < model.num_triangles(); ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = model.triangles[t][e], b = model.triangles[t][(e + 1) % 3];
      auto& sides = edges[edge_key(a, b)];
      sides[sides[0].triangle < 0 ? 0 : 1] = {static_cast<int>(t), e};
    }

  // New nodes in triangle order (keeps neighbours close in memory): a shared node keeps
  // one index for the non-fracturable triangles; each fracturable corner gets its own.
  const size_t old_nodes = model.num_nodes();
  std::vector<int> shared_index(old_nodes, -1);
  std::vector<std::vector<int>> copies(old_nodes);
  std::vector<int> origin;  // original node of each new node
  auto new_node = [&](int old) {
    origin.push_back(old);
    copies[old].push_back(static_cast<int>(origin.size() - 1));
    return static_cast<int>(origin.size() - 1);
  };
  std::vector<std::array<int, 3>> triangles = model.triangles;
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int old = model.triangles[t][k];
      if (model.triangle_fracturable[t]) {
        triangles[t][k] = new_node(old);
      } else {
        if (shared_index[old] < 0) shared_index[old] = new_node(old);
        triangles[t][k] = shared_index[old];
      }
    }

  // With extrinsic CE4s the copies of each mesh vertex are numbered consecutively (nodes
  // in mesh-vertex order, a vertex's copies in triangle order): the tie kernel
  // (cl_kernels/extrinsic.cl), which reads and writes every copy of a vertex each step,
  // then reads one short run of memory per vertex instead of one line per copy.
  // Intrinsic models keep the triangle order: their triangle and gather kernels read a
  // triangle's three nodes as one run (H200, 1.08M TRI3: 0.956 ms a step, 1.023 ms in
  // vertex order; docs/performance-notes.md).
  const bool vertex_order = std::any_of(model.fracture.begin(), model.fracture.end(),
                                        [](const FractureProperties& f) { return f.extrinsic; });
  if (vertex_order) {
    std::vector<int> renumbered(origin.size());
    std::vector<int> next(old_nodes + 1, 0);
    for (int o : origin) ++next[size_t(o) + 1];
    for (size_t v = 0; v < old_nodes; ++v) next[v + 1] += next[v];
    std::vector<int> new_origin(origin.size());
    for (size_t n = 0; n < origin.size(); ++n) {  // n in creation (triangle) order
      renumbered[n] = next[size_t(origin[n])]++;
      new_origin[size_t(renumbered[n])] = origin[n];
    }
    for (auto& tri : triangles)
      for (int& n : tri) n = renumbered[size_t(n)];
    for (auto& list : copies)
      for (int& n : list) n = renumbered[size_t(n)];
    origin = std::move(new_origin);
  }

  // CE4s on interior fracturable edges.
  size_t unbonded = 0;
  for (const auto& [key, sides] : edges) {
    if (sides[1].triangle < 0) continue;  // boundary edge
    const int t1 = sides[0].triangle, t2 = sides[1].triangle;
    if (!model.triangle_fracturable[t1] || !model.triangle_fracturable[t2]) continue;
    const int joint = joint_of(key);
    const int props = props_of(key, t1, t2);
    if (props < 0) {
      ++unbonded;
      continue;
    }
    const int c1 = sides[0].corner, c2 = sides[1].corner;
    // t1 runs a → b, t2 runs b → a: i = a in t1, j = b in t1, j' = b in t2, i' = a in t2.
    model.ce4.push_back({triangles[t1][c1], triangles[t1][(c1 + 1) % 3], triangles[t2][c2], triangles[t2][(c2 + 1) % 3]});
    model.ce4_triangles.push_back({t1, t2});
    model.ce4_properties.push_back(props);
    if (!config.joints.empty()) model.ce4_joint.push_back(joint);
    if (config.grains) model.ce4_grain_boundary.push_back(grain_side(t1, t2));
  }
  if (unbonded)
    notes.push_back(std::to_string(unbonded) + " edges between two different fracturable materials have no [[interface]]: "
                    "they are not bonded (free surfaces in contact)");

  // Bonded fans: a mesh node whose triangles are all fracturable and whose interior edges
  // all got a CE4 (an unbonded interface or a non-fracturable neighbour breaks the fan).
  model.vertex_bonded.assign(old_nodes, 1);
  for (size_t t = 0; t < model.num_triangles(); ++t)
    if (!model.triangle_fracturable[t])
      for (int v : model.triangles[t]) model.vertex_bonded[v] = 0;
  for (const auto& [key, sides] : edges) {
    if (sides[1].triangle < 0) continue;
    const int t1 = sides[0].triangle, t2 = sides[1].triangle;
    // A broken joint's CE4s start closed: their fan is not bonded (contact handles its
    // corner couples, as at an unbonded interface).
    const int joint = joint_of(key);
    const bool bonded = model.triangle_fracturable[t1] && model.triangle_fracturable[t2] &&
                        (joint >= 0 ? !model.joint_broken[joint] : props_of(key, t1, t2) >= 0);
    if (!bonded) model.vertex_bonded[key.first] = model.vertex_bonded[key.second] = 0;
  }
  model.node_origin = origin;

  // Node-indexed arrays follow the split.
  const Model old = model;
  model.x.clear(), model.y.clear(), model.node_tags.clear(), model.node_group.clear();
  model.vx0.clear(), model.vy0.clear();
  for (int o : origin) {
    model.x.push_back(old.x[o]);
    model.y.push_back(old.y[o]);
    model.node_tags.push_back(old.node_tags[o]);
    model.node_group.push_back(old.node_group[o]);
    model.vx0.push_back(old.vx0[o]);
    model.vy0.push_back(old.vy0[o]);
  }
  for (auto& region : model.regions) {
    std::vector<int> nodes;
    for (int o : region.nodes) nodes.insert(nodes.end(), copies[o].begin(), copies[o].end());
    std::sort(nodes.begin(), nodes.end());
    region.nodes = nodes;
  }
  for (auto& edge : model.loaded_edges) {
    const auto& sides = edges.at(edge_key(edge.a, edge.b));
    const Side& side = sides[0];  // a loaded edge is a boundary edge: one triangle
    edge.a = triangles[side.triangle][side.corner];
    edge.b = triangles[side.triangle][(side.corner + 1) % 3];
  }
  model.triangles = triangles;
  notes.push_back("fracturable regions split: " + std::to_string(old_nodes) + " → " + std::to_string(model.num_nodes()) +
                  " nodes, " + std::to_string(model.ce4.size()) + " CE4s");
}

// Contact candidates for activation = "fractured": triangles with a node in a listed region.
std::vector<uint32_t> initial_candidates(const Model& model, const io::ContactConfig& contact) {
  if (contact.activation != "fractured") return {};
  std::vector<char> listed(model.num_nodes(), 0);
  for (const auto& name : contact.regions)
    for (const auto& region : model.regions)
      if (region.name == name)
        for (int n : region.nodes) listed[n] = 1;
  std::vector<uint32_t> active(model.num_triangles(), 0);
  for (size_t t = 0; t < model.num_triangles(); ++t)
    for (int n : model.triangles[t]) active[t] |= listed[n];
  return active;
}

}  // namespace

// The [in_situ] field of the model, checked against what the model can hold: a field that
// grows with depth needs gravity along -y (the field is then in equilibrium with the
// rock's weight when its ρ is the rock's) and a datum on or above the mesh; a CE4 holds
// it only in compression and below its peak shear (in_situ_gaps). Messages name the key.
FractureProperties ce4_fracture(const Model& model, size_t e);

void set_in_situ(Model& model, const io::CaseConfig& config) {
  const io::InSituConfig& c = *config.in_situ;
  const std::string table_key = c.datum ? "in_situ.datum" : config.settings.count("in_situ.principal") ? "in_situ.principal" : "in_situ.stress";
  auto fail = [&](const std::string& key, const std::string& what) -> void {
    throw InputError(io::origin_of(config, key) + ": " + what);
  };
  InSituField& f = model.in_situ;
  f.enabled = true;
  f.uniform = c.stress;
  if (c.datum) {
    f.datum = *c.datum;
    if (model.gravity[0] != 0.0 || !(model.gravity[1] < 0.0))
      fail("in_situ.datum", "in_situ.datum: a stress that grows with depth needs [gravity] g = [0, -g] (depth is "
                            "along -y; the field is held by the rock's weight), found g = [" +
                                format_number(model.gravity[0], 6) + ", " + format_number(model.gravity[1], 6) + "]");
    double density = 0;
    if (c.density) {
      density = *c.density;
    } else {
      for (const auto& m : config.materials)
        if (density != 0 && m.density != density)
          fail("in_situ.datum", "in_situ.density is needed: the materials have different densities (" +
                                    format_number(density, 6) + " and " + format_number(m.density, 6) + " kg/m³)");
        else
          density = m.density;
    }
    const double alpha = c.azimuth * std::acos(-1.0) / 180.0;
    const double k_x = c.k_H * std::cos(alpha) * std::cos(alpha) + c.k_h * std::sin(alpha) * std::sin(alpha);
    const double unit_weight = density * -model.gravity[1];
    f.gradient = {-unit_weight * k_x, -unit_weight, 0.0};
    double top = -std::numeric_limits<double>::infinity();
    for (double y : model.y) top = std::max(top, y);
    double extent = 0;
    for (double y : model.y) extent = std::max(extent, std::fabs(y));
    if (top > f.datum + 1e-9 * std::max(1.0, extent))
      fail("in_situ.datum", "in_situ.datum = " + format_number(f.datum, 9) + " m is below the top of the mesh (y = " +
                                format_number(top, 9) + " m): the field would be tension above the surface");
  }
  for (double v : f.uniform)
    if (!std::isfinite(v)) fail(table_key, "[in_situ]: the stress is not finite");
  // The CE4s must carry it from the start.
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const auto& ce = model.ce4[e];
    std::string problem;
    in_situ_gaps(f, ce4_fracture(model, e), {model.x[ce[0]], model.y[ce[0]]},
                 {model.x[ce[1]], model.y[ce[1]]}, problem);
    if (!problem.empty()) {
      const int tri = model.ce4_triangles[e][0];
      fail(table_key, "[in_situ]: " + problem + " (material '" +
                          config.materials[model.triangle_material[tri]].name + "')");
    }
  }
}

// CE4 e's fracture properties, with its own strengths where they vary.
FractureProperties ce4_fracture(const Model& model, size_t e) {
  FractureProperties f = model.fracture[model.ce4_properties[e]];
  if (!model.ce4_strength_factor.empty()) {
    f.tensile_strength *= model.ce4_strength_factor[e][0];
    f.cohesion *= model.ce4_strength_factor[e][1];
  }
  return f;
}

// The Weibull draws of [material.heterogeneity] (engine/heterogeneity.hpp): E per
// triangle by its rank within its material's block, T_s and c per CE4 of the material's
// own fracture set by its rank among those CE4s. Any other material's elements keep
// factor 1. Nothing is drawn when no material asks for it.
void set_heterogeneity(Model& model, const io::CaseConfig& config) {
  bool any_young = false, any_strength = false;
  for (const auto& m : config.materials)
    if (m.heterogeneity) {
      any_young |= m.heterogeneity->young;
      any_strength |= m.heterogeneity->tensile_strength || m.heterogeneity->cohesion;
    }
  if (any_young) {
    model.young_factor.assign(model.num_triangles(), 1.0);
    for (size_t m = 0; m < config.materials.size(); ++m) {
      const auto& h = config.materials[m].heterogeneity;
      if (!h || !h->young) continue;
      for (size_t t = model.block_start[m]; t < model.block_start[m + 1]; ++t)
        model.young_factor[t] = weibull_factor(h->homogeneity, h->seed, WeibullProperty::Young, t - model.block_start[m]);
    }
  }
  if (any_strength && !model.ce4.empty()) {
    model.ce4_strength_factor.assign(model.ce4.size(), {1.0, 1.0});
    // The fracture set of each fracturable material (split_fracturable's order).
    std::vector<int> own_set(config.materials.size(), -1);
    for (size_t m = 0, k = 0; m < config.materials.size(); ++m)
      if (config.materials[m].fracture) own_set[m] = static_cast<int>(k++);
    for (size_t m = 0; m < config.materials.size(); ++m) {
      const auto& h = config.materials[m].heterogeneity;
      if (!h || !(h->tensile_strength || h->cohesion)) continue;
      std::uint64_t rank = 0;
      for (size_t e = 0; e < model.ce4.size(); ++e) {
        if (model.ce4_properties[e] != own_set[m]) continue;
        auto& f = model.ce4_strength_factor[e];
        if (h->tensile_strength) f[0] = weibull_factor(h->homogeneity, h->seed, WeibullProperty::TensileStrength, rank);
        if (h->cohesion) f[1] = weibull_factor(h->homogeneity, h->seed, WeibullProperty::Cohesion, rank);
        ++rank;
      }
    }
  }
}

std::string grains_summary(const Model& model, const io::CaseConfig& config) {
  if (!config.grains) return "";
  const io::GrainsConfig& g = *config.grains;
  double total = 0;
  size_t present = 0;
  std::vector<double> by_material(model.materials.size(), 0.0);
  for (size_t k = 0; k < model.grain_area.size(); ++k) {
    total += model.grain_area[k];
    present += model.grain_area[k] > 0;
    by_material[size_t(model.grain_mineral[k])] += model.grain_area[k];
  }
  const double mean = present ? total / double(present) : 0.0;
  std::string line = std::to_string(model.grain_area.size()) + " grains in '" + g.region + "' (seed " +
                     std::to_string(g.seed) + "), mean size " + format_number(std::sqrt(4 * mean / std::acos(-1.0)), 4) +
                     " m (diameter of a disc of the mean area " + format_number(mean, 4) + " m²); minerals (asked / achieved area fraction):";
  for (size_t m = 0; m < g.minerals.size(); ++m)
    for (size_t k = 0; k < config.materials.size(); ++k)
      if (config.materials[k].name == g.minerals[m]) {
        char text[64];
        std::snprintf(text, sizeof text, " %.3f / %.3f", g.fractions[m], total > 0 ? by_material[k] / total : 0.0);
        line += (m ? ", '" : " '") + g.minerals[m] + "'" + text;
      }
  size_t boundary = 0;
  for (int b : model.ce4_grain_boundary) boundary += b == 1;
  line += "; " + std::to_string(boundary) + " grain-boundary CE4s (T_s " + format_number(g.boundary.tensile_strength) +
          " Pa, c " + format_number(g.boundary.cohesion) + " Pa, phi " + format_number(g.boundary.friction_angle) +
          " deg, GI " + format_number(g.boundary.gf1) + ", GII " + format_number(g.boundary.gf2) + " J/m²)";
  return line;
}

std::vector<std::string> joint_summary(const Model& model, const io::CaseConfig& config) {
  std::vector<std::string> out;
  for (size_t j = 0; j < config.joints.size(); ++j) {
    const io::JointConfig& joint = config.joints[j];
    size_t count = 0;
    double length = 0;
    for (size_t e = 0; e < model.ce4_joint.size(); ++e)
      if (model.ce4_joint[e] == static_cast<int>(j)) {
        ++count;
        const auto& c = model.ce4[e];
        length += std::hypot(model.x[c[1]] - model.x[c[0]], model.y[c[1]] - model.y[c[0]]);
      }
    std::string curves;
    for (const auto& c : joint.curves) curves += (curves.empty() ? "'" : ", '") + c + "'";
    if (!joint.file.empty()) curves += (curves.empty() ? "file " : ", file ") + joint.file;
    if (joint.set)
      curves += (curves.empty() ? "" : ", ") + std::string("a set (angle ") + format_number(joint.set->angle) +
                "°, kappa " + format_number(joint.set->kappa) + ", spacing " + format_number(joint.set->spacing) +
                " m, trace length " + format_number(joint.set->trace_length) + " m, persistence " +
                format_number(joint.set->persistence) + ", seed " + std::to_string(joint.set->seed) + ")";
    const io::FractureConfig& f = joint.fracture;
    std::string line = "joint[" + std::to_string(j) + "] '" + joint.name + "' on " + curves + ": " +
                       std::to_string(count) + " CE4s, " + format_number(length, 4) + " m; ";
    if (joint.broken)
      line += "broken (closed, friction only), friction angle " + format_number(f.friction_angle) + "°";
    else
      line += "T_s " + format_number(f.tensile_strength) + " Pa, c " + format_number(f.cohesion) + " Pa, friction angle " +
              format_number(f.friction_angle) + "°, G_fI " + format_number(f.gf1) + " J/m², G_fII " +
              format_number(f.gf2) + " J/m²";
    out.push_back(line);
  }
  return out;
}

std::vector<std::string> heterogeneity_summary(const Model& model, const io::CaseConfig& config) {
  std::vector<std::string> out;
  std::vector<int> own_set(config.materials.size(), -1);
  for (size_t m = 0, k = 0; m < config.materials.size(); ++m)
    if (config.materials[m].fracture) own_set[m] = static_cast<int>(k++);
  for (size_t m = 0; m < config.materials.size(); ++m) {
    const auto& h = config.materials[m].heterogeneity;
    if (!h) continue;
    std::string line = "material '" + config.materials[m].name + "': Weibull m = " + format_number(h->homogeneity) +
                       ", seed " + std::to_string(h->seed);
    auto describe = [&](const char* what, const std::vector<double>& v) {
      if (v.empty()) return;
      const auto [low, high] = std::minmax_element(v.begin(), v.end());
      double mean = 0;
      for (double x : v) mean += x;
      line += std::string("; ") + what + " x " + format_number(*low, 3) + " to " + format_number(*high, 3) + " (mean " +
              format_number(mean / double(v.size()), 3) + ", " + std::to_string(v.size()) + " elements)";
    };
    std::vector<double> e, ts, c;
    if (h->young && !model.young_factor.empty())
      for (size_t t = model.block_start[m]; t < model.block_start[m + 1]; ++t) e.push_back(model.young_factor[t]);
    if (!model.ce4_strength_factor.empty())
      for (size_t k = 0; k < model.ce4.size(); ++k)
        if (model.ce4_properties[k] == own_set[m]) {
          if (h->tensile_strength) ts.push_back(model.ce4_strength_factor[k][0]);
          if (h->cohesion) c.push_back(model.ce4_strength_factor[k][1]);
        }
    describe("E", e);
    describe("T_s", ts);
    describe("c", c);
    out.push_back(line);
  }
  return out;
}

size_t Model::young_first() const {
  for (size_t t = 0; t < young_factor.size(); ++t)
    if (young_factor[t] != 1.0) return t;
  return 0;
}

size_t Model::young_count() const {
  size_t last = 0;
  bool any = false;
  for (size_t t = 0; t < young_factor.size(); ++t)
    if (young_factor[t] != 1.0) last = t, any = true;
  return any ? last + 1 - young_first() : 0;
}

std::vector<std::array<double, 3>> in_situ_triangle_stress(const Model& model) {
  std::vector<std::array<double, 3>> out;
  if (!model.in_situ.enabled) return out;
  out.reserve(model.num_triangles());
  // The field is linear in y, so its value at the centroid is its mean over the triangle:
  // the triangle's nodal forces are then exactly those of the field (docs/energy-notes.md).
  for (const auto& tri : model.triangles)
    out.push_back(model.in_situ.at((model.y[tri[0]] + model.y[tri[1]] + model.y[tri[2]]) / 3.0));
  return out;
}

std::string in_situ_summary(const Model& model) {
  const InSituField& f = model.in_situ;
  if (!f.enabled) return "";
  auto triple = [](const std::array<double, 3>& v) {
    return "(" + format_number(v[0], 6) + ", " + format_number(v[1], 6) + ", " + format_number(v[2], 6) + ")";
  };
  std::string out = "stress (sxx, syy, sxy) = " + triple(f.uniform) + " Pa";
  const bool depth = f.gradient != std::array<double, 3>{0.0, 0.0, 0.0};
  if (depth) out += " + (" + format_number(f.datum, 9) + " m - y) x " + triple(f.gradient) + " Pa/m";
  if (depth && model.num_nodes() > 0) {
    const auto [low, high] = std::minmax_element(model.y.begin(), model.y.end());
    out += "; at the top (y = " + format_number(*high, 6) + " m) " + triple(f.at(*high)) + " Pa, at the bottom (y = " +
           format_number(*low, 6) + " m) " + triple(f.at(*low)) + " Pa";
  }
  long edges = 0;
  for (const auto& e : model.loaded_edges) edges += model.loads[e.load].kind == LoadKind::InSitu;
  out += "; on " + std::to_string(model.num_triangles()) + " TRI3" +
         (model.ce4.empty() ? "" : " and " + std::to_string(model.ce4.size()) + " CE4s") + ", its traction on " +
         std::to_string(edges) + " boundary edges";
  return out;
}

std::vector<InSituGaps> in_situ_ce4_gaps(const Model& model) {
  std::vector<InSituGaps> out;
  if (!model.in_situ.enabled) return out;
  out.reserve(model.ce4.size());
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const auto& c = model.ce4[e];
    std::string problem;
    out.push_back(in_situ_gaps(model.in_situ, ce4_fracture(model, e), {model.x[c[0]], model.y[c[0]]},
                               {model.x[c[1]], model.y[c[1]]}, problem));
    if (!problem.empty()) throw InputError("[in_situ]: CE4 " + std::to_string(e) + ": " + problem);
  }
  return out;
}

namespace {

// The mesh edges of each [[joint]]'s curves (model node indices) → the joint's index.
// Every edge must lie between two triangles of fracturable materials (a CE4 can only go
// there) and belong to one joint; messages name the joint's key and the curve.
std::map<std::pair<int, int>, int> joint_edges(const io::Mesh& mesh, const std::vector<int>& new_index,
                                               const Model& model, const io::CaseConfig& config) {
  std::map<std::pair<int, int>, int> joints;
  if (config.joints.empty()) return joints;
  std::map<std::pair<int, int>, std::array<int, 2>> sides;  // the (up to) two triangles of each edge
  for (size_t t = 0; t < model.num_triangles(); ++t)
    for (int e = 0; e < 3; ++e) {
      auto& s = sides.try_emplace(edge_key(model.triangles[t][e], model.triangles[t][(e + 1) % 3]),
                                  std::array<int, 2>{-1, -1})
                    .first->second;
      s[s[0] < 0 ? 0 : 1] = static_cast<int>(t);
    }
  for (size_t j = 0; j < config.joints.size(); ++j) {
    const io::JointConfig& joint = config.joints[j];
    const std::string where = io::origin_of(config, "joint." + std::to_string(j) + ".curves") + ": joint[" +
                              std::to_string(j) + "] ('" + joint.name + "').curves";
    // The curves named, and those the front end embedded from the joint's file and set.
    std::vector<std::string> curves = joint.curves;
    if ((!joint.file.empty() || joint.set) && mesh.find_group(io::embedded_joint_curve(int(j)), 1) >= 0)
      curves.push_back(io::embedded_joint_curve(int(j)));
    for (const std::string& curve : curves) {
      const int g = mesh.find_group(curve, 1);
      if (g < 0) {
        if (mesh.find_group(curve, 2) >= 0)
          throw InputError(where + ": '" + curve + "' is a physical surface of " + mesh.source +
                           ", not a curve; a joint runs along physical curves");
        throw InputError(where + ": no physical curve '" + curve + "' in " + mesh.source +
                         io::did_you_mean(curve, group_names(mesh, 1)) + "; its curves are " +
                         list_names(group_names(mesh, 1)));
      }
      size_t count = 0;
      for (size_t l = 0; l < mesh.lines.size(); ++l) {
        if (mesh.line_group[l] != g) continue;
        ++count;
        const int a = new_index[mesh.lines[l][0]], b = new_index[mesh.lines[l][1]];
        const auto it = (a >= 0 && b >= 0) ? sides.find(edge_key(a, b)) : sides.end();
        const std::string element = "line element " + std::to_string(mesh.line_tags[l]) + " of curve '" + curve + "'";
        if (it == sides.end())
          throw InputError(where + ": " + element + " is not an edge of any triangle (embed the curve in its surface, "
                                   "e.g. Curve{..} In Surface{..}, or make it a boundary between surfaces)");
        const auto [t1, t2] = it->second;
        if (t2 < 0)
          throw InputError(where + ": " + element + " lies on the boundary of the body: a joint runs inside it, "
                                   "between two triangles");
        for (int t : {t1, t2})
          if (!config.materials[model.triangle_material[t]].fracture)
            throw InputError(where + ": " + element + " borders material '" +
                             config.materials[model.triangle_material[t]].name +
                             "', which has no [material.fracture]: a joint's CE4s join fracturable triangles (give "
                             "the material a [material.fracture], as strong as the intact rock is)");
        joints[it->first] = static_cast<int>(j);
      }
      if (count == 0)
        throw InputError(where + ": physical curve '" + curve + "' of " + mesh.source + " has no line elements");
    }
  }
  return joints;
}

}  // namespace

Model build_model(const io::Mesh& source_mesh, const io::CaseConfig& config,
                  std::vector<std::string>& notes) {
  io::Mesh mesh = source_mesh;
  const int flipped = io::orient_triangles(mesh, &notes);
  (void)flipped;
  // Refinement comes before anything reads the mesh, so materials, fracturable regions,
  // boundary curves, loads, probes and contact all see the refined one. Orientation is
  // checked first: the children keep their parent's counter-clockwise order, and notes
  // about the file name its own element tags.
  if (config.mesh.refine > 0) {
    const size_t nodes = mesh.x.size(), triangles = mesh.triangles.size(), lines = mesh.lines.size();
    const std::string key = "mesh.refine = " + std::to_string(config.mesh.refine);
    io::refine_mesh(mesh, config.mesh.refine, config.path + ": " + key);
    notes.push_back(mesh.source + " refined (" + key + "): " + std::to_string(triangles) + " → " +
                    std::to_string(mesh.triangles.size()) + " triangles, " + std::to_string(nodes) + " → " +
                    std::to_string(mesh.x.size()) + " nodes, " + std::to_string(lines) + " → " +
                    std::to_string(mesh.lines.size()) + " line elements");
  }
  const double scale = config.mesh.scale;

  Model model;
  model.mesh_path = mesh.source;
  model.thickness = config.mesh.thickness;
  model.gravity = config.gravity.g;
  model.local_damping = config.damping.local_enabled ? config.damping.local : 0.0;
  model.mass_scaling = config.damping.mass_scaling;

  // Materials own physical surfaces.
  std::vector<int> group_material(mesh.groups.size(), -1);
  for (size_t m = 0; m < config.materials.size(); ++m) {
    const auto& mat = config.materials[m];
    for (const auto& region : mat.regions) {
      const std::string where = config.path + ": material[" + std::to_string(m) + "] ('" + mat.name + "').regions";
      const int g = mesh.find_group(region, 2);
      if (g < 0) {
        if (mesh.find_group(region, 1) >= 0)
          throw InputError(where + ": '" + region + "' is a physical curve of " + mesh.source +
                           ", not a surface; materials take physical surfaces");
        throw InputError(where + ": no physical surface '" + region + "' in " + mesh.source +
                         io::did_you_mean(region, group_names(mesh, 2)) + "; its surfaces are " +
                         list_names(group_names(mesh, 2)));
      }
      if (group_material[g] >= 0 && group_material[g] != static_cast<int>(m))
        throw InputError(where + ": surface '" + region + "' already belongs to material '" +
                         config.materials[group_material[g]].name + "'");
      group_material[g] = static_cast<int>(m);
    }
  }
  // [grains]: the region's triangles take their grain's mineral (the front end drew the
  // seeds, io::draw_grains); the region itself belongs to no material.
  std::vector<int> triangle_material(mesh.triangles.size(), -1), mesh_grain;
  int grain_group = -1;
  if (config.grains) {
    const io::GrainsConfig& grains = *config.grains;
    const std::string where = io::origin_of(config, "grains.region") + ": grains.region = \"" + grains.region + "\"";
    grain_group = mesh.find_group(grains.region, 2);
    if (grain_group < 0)
      throw InputError(where + " is not a physical surface of " + mesh.source +
                       io::did_you_mean(grains.region, group_names(mesh, 2)) + "; its surfaces are " +
                       list_names(group_names(mesh, 2)));
    if (group_material[grain_group] >= 0)
      throw InputError(where + " is in the regions of material '" + config.materials[group_material[grain_group]].name +
                       "': the grains' triangles take their minerals' materials; take it out of that material's regions");
    if (grains.points.empty())
      throw InputError(where + ": the grains were not drawn (the case must be prepared from its .geo: fdem check or fdem run)");
    std::vector<int> mineral_material;
    for (const std::string& name : grains.minerals)
      for (size_t m = 0; m < config.materials.size(); ++m)
        if (config.materials[m].name == name) mineral_material.push_back(static_cast<int>(m));
    const io::GrainFinder finder(grains.points);
    mesh_grain.assign(mesh.triangles.size(), -1);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (mesh.triangle_group[t] != grain_group) continue;
      const auto& tri = mesh.triangles[t];
      const io::Point2 c{(mesh.x[tri[0]] + mesh.x[tri[1]] + mesh.x[tri[2]]) / 3 * scale,
                         (mesh.y[tri[0]] + mesh.y[tri[1]] + mesh.y[tri[2]]) / 3 * scale};
      mesh_grain[t] = io::grain_at(finder, grains.cells, c);
      triangle_material[t] = mineral_material[size_t(grains.mineral[size_t(mesh_grain[t])])];
    }
    for (int m : grains.mineral) model.grain_mineral.push_back(mineral_material[size_t(m)]);
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const int g = mesh.triangle_group[t];
    if (g == grain_group) continue;
    triangle_material[t] = group_material[g];
    if (group_material[g] < 0) {
      const auto& group = mesh.groups[g];
      throw InputError(mesh.source + ": physical surface '" + group.name + "' (tag " +
                       std::to_string(group.tag) + ", e.g. element " +
                       std::to_string(mesh.triangle_tags[t]) +
                       ") has no material: list it in the regions of a [[material]] in " + config.path);
    }
  }

  // mesh.perturb: interior nodes of the fracturable surfaces moved at random (a crack runs
  // along edges, so a lattice-like mesh would steer it), before anything measures the mesh.
  if (config.mesh.perturb > 0) {
    std::vector<char> movable(mesh.groups.size(), 0);
    for (size_t g = 0; g < mesh.groups.size(); ++g)
      movable[g] = group_material[g] >= 0 && config.materials[group_material[g]].fracture.has_value();
    const io::PerturbSummary s = io::perturb_mesh(
        mesh, movable, io::PerturbOptions{config.mesh.perturb, static_cast<unsigned long long>(config.mesh.perturb_seed),
                                          config.mesh.perturb_min_quality});
    char text[320];
    std::snprintf(text, sizeof text,
                  "mesh.perturb (amplitude %g, seed %ld, min_quality %g): %ld of %ld interior nodes of the fracturable "
                  "surfaces moved, %ld kept in place by the guard; smallest quality %.3f -> %.3f, smallest height "
                  "%.4g -> %.4g (mesh units)",
                  config.mesh.perturb, config.mesh.perturb_seed, config.mesh.perturb_min_quality, s.moved, s.movable,
                  s.kept, s.min_quality_before, s.min_quality_after, s.min_height_before, s.min_height_after);
    notes.push_back(text);
  }

  // Triangles grouped by material; within a material, mesh.order = "hilbert" (the default)
  // sorts them along a Hilbert curve through their centroids, "file" keeps the file's order.
  // Why: every per-element stage reads its neighbours' nodes (a CE4 the nodes of its two
  // triangles, the node gather the slots of the CE4s at a node), and gmsh's numbering puts
  // neighbours thousands of triangles apart (the blasting mesh: median 4,250), so each such
  // read missed the caches (docs/performance-notes.md, session 19).
  std::vector<uint64_t> curve(mesh.triangles.size(), 0);
  if (config.mesh.order == "hilbert" && !mesh.triangles.empty()) {
    double lo_x = mesh.x[0], hi_x = mesh.x[0], lo_y = mesh.y[0], hi_y = mesh.y[0];
    for (size_t n = 0; n < mesh.x.size(); ++n) {
      lo_x = std::min(lo_x, mesh.x[n]), hi_x = std::max(hi_x, mesh.x[n]);
      lo_y = std::min(lo_y, mesh.y[n]), hi_y = std::max(hi_y, mesh.y[n]);
    }
    const double span = std::max({hi_x - lo_x, hi_y - lo_y, std::numeric_limits<double>::min()});
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      const double cx = (mesh.x[tri[0]] + mesh.x[tri[1]] + mesh.x[tri[2]]) / 3, cy = (mesh.y[tri[0]] + mesh.y[tri[1]] + mesh.y[tri[2]]) / 3;
      curve[t] = hilbert_index(static_cast<uint32_t>(std::clamp((cx - lo_x) / span, 0.0, 1.0) * 65535.0),
                               static_cast<uint32_t>(std::clamp((cy - lo_y) / span, 0.0, 1.0) * 65535.0));
    }
  }
  std::vector<size_t> order(mesh.triangles.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return triangle_material[a] != triangle_material[b] ? triangle_material[a] < triangle_material[b] : curve[a] < curve[b];
  });

  // Nodes used by triangles, renumbered: "hilbert" in the order the sorted triangles first
  // use them, "file" in the file's order.
  std::vector<int> new_index(mesh.x.size(), -1);
  std::vector<size_t> node_order;
  if (config.mesh.order == "hilbert") {
    std::vector<char> seen(mesh.x.size(), 0);
    for (size_t k : order)
      for (int n : mesh.triangles[k])
        if (!seen[size_t(n)]) seen[size_t(n)] = 1, node_order.push_back(size_t(n));
  } else {
    for (const auto& tri : mesh.triangles)
      for (int n : tri) new_index[n] = 0;
    for (size_t n = 0; n < mesh.x.size(); ++n)
      if (new_index[n] >= 0) node_order.push_back(n);
  }
  size_t used = 0;
  for (size_t n : node_order) {
    new_index[n] = static_cast<int>(used++);
    model.x.push_back(mesh.x[n] * scale);
    model.y.push_back(mesh.y[n] * scale);
    model.node_tags.push_back(mesh.node_tags[n]);
  }
  if (used < mesh.x.size())
    notes.push_back(std::to_string(mesh.x.size() - used) + " mesh nodes belong to no triangle and were dropped");

  model.block_start.assign(config.materials.size() + 1, 0);
  std::vector<double> edge_sum(config.materials.size(), 0.0);
  std::vector<int> triangle_group;  // the mesh's physical group of each model triangle
  for (size_t k : order) {
    const auto& tri = mesh.triangles[k];
    triangle_group.push_back(mesh.triangle_group[k]);
    const int mat = triangle_material[k];
    if (!mesh_grain.empty()) model.triangle_grain.push_back(mesh_grain[k]);
    model.triangles.push_back({new_index[tri[0]], new_index[tri[1]], new_index[tri[2]]});
    model.triangle_material.push_back(mat);
    model.triangle_tags.push_back(mesh.triangle_tags[k]);
    model.block_start[mat + 1]++;
    const auto& t = model.triangles.back();
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      edge_sum[mat] += std::hypot(model.x[b] - model.x[a], model.y[b] - model.y[a]);
    }
  }
  for (size_t m = 0; m < config.materials.size(); ++m) {
    const size_t count = model.block_start[m + 1];
    model.block_start[m + 1] += model.block_start[m];
    if (count == 0)
      notes.push_back("material '" + config.materials[m].name + "' has no triangles");
    model.materials.push_back(make_material(config.materials[m], count ? edge_sum[m] / (3.0 * count) : 0.0));
  }

  // Regions named by boundary and initial entries.
  auto region_nodes = [&](const std::string& name, const std::string& where, int* dim_out) {
    const auto groups = find_region(mesh, name, where);
    std::vector<int> nodes;
    int dim = 0;
    for (int g : groups) {
      dim = std::max(dim, mesh.groups[g].dim);
      for (size_t t = 0; t < mesh.triangles.size(); ++t)
        if (mesh.triangle_group[t] == g) nodes.insert(nodes.end(), mesh.triangles[t].begin(), mesh.triangles[t].end());
      for (size_t l = 0; l < mesh.lines.size(); ++l)
        if (mesh.line_group[l] == g) nodes.insert(nodes.end(), mesh.lines[l].begin(), mesh.lines[l].end());
      for (size_t p = 0; p < mesh.points.size(); ++p)
        if (mesh.point_group[p] == g) nodes.push_back(mesh.points[p]);
    }
    std::vector<int> mapped;
    for (int n : nodes)
      if (new_index[n] >= 0) mapped.push_back(new_index[n]);
    std::sort(mapped.begin(), mapped.end());
    mapped.erase(std::unique(mapped.begin(), mapped.end()), mapped.end());
    if (mapped.empty())
      throw InputError(where + ": region '" + name + "' of " + mesh.source + " has no nodes on any triangle");
    if (dim_out) *dim_out = dim;
    return mapped;
  };
  auto remember_region = [&](const std::string& name, int dim, const std::vector<int>& nodes, bool prescribed) {
    for (auto& r : model.regions)
      if (r.name == name) {
        r.prescribed = r.prescribed || prescribed;
        return;
      }
    model.regions.push_back({name, dim, nodes, prescribed});
  };

  // Prescribed motion, combined per node (a corner node may be fixed in x by one
  // entry and in y by another).
  std::vector<BoundaryGroup> node_bc(model.num_nodes());
  std::vector<int> node_bc_entry(2 * model.num_nodes(), -1);  // which entry set vx / vy
  // Edges of the triangles, for orienting loaded curves.
  std::map<std::pair<int, int>, EdgeOwner> edges;
  auto build_edges = [&]() {
    if (!edges.empty()) return;
    for (size_t t = 0; t < model.triangles.size(); ++t)
      for (int e = 0; e < 3; ++e) {
        const int a = model.triangles[t][e], b = model.triangles[t][(e + 1) % 3];
        auto& owner = edges[edge_key(a, b)];
        owner.triangle = static_cast<int>(t);
        owner.a = a;
        owner.b = b;
        owner.count++;
      }
  };

  // [fluid.gas]: the hole's wall carries the gas's pressure (LoadKind::Gas), one more entry.
  std::vector<io::BoundaryConfig> boundaries = config.boundaries;
  if (config.fluid && config.fluid->gas) {
    for (size_t i = 0; i < boundaries.size(); ++i) {
      const auto& b = boundaries[i];
      if (b.region == config.fluid->gas->hole && (b.traction || b.pressure || b.pressure_table || b.blast || b.absorbing || b.in_situ))
        throw InputError(config.path + ": boundary[" + std::to_string(i) + "] loads region '" + b.region +
                         "', the hole of [fluid.gas] whose pressure the gas gives: remove that load (fluid.gas.hole)");
    }
    io::BoundaryConfig hole;
    hole.region = config.fluid->gas->hole;
    hole.gas = true;
    boundaries.push_back(hole);
  }
  for (size_t i = 0; i < boundaries.size(); ++i) {
    const auto& bc = boundaries[i];
    const std::string where = bc.gas ? config.path + ": fluid.gas.hole" : config.path + ": boundary[" + std::to_string(i) + "]";
    int dim = 0;
    const auto nodes = region_nodes(bc.region, where, &dim);
    const bool prescribes = bc.fix_x || bc.fix_y || bc.velocity.has_value();
    remember_region(bc.region, dim, nodes, prescribes);

    if (prescribes) {
      for (int n : nodes) {
        for (int axis = 0; axis < 2; ++axis) {
          const bool set = (axis == 0 ? bc.fix_x : bc.fix_y) || bc.velocity.has_value();
          if (!set) continue;
          const double v = bc.velocity ? (*bc.velocity)[axis] : 0.0;
          auto& g = node_bc[n];
          const uint32_t bit = 1u << axis;
          double& gv = axis == 0 ? g.vx : g.vy;
          if ((g.mask & bit) && gv != v) {
            const auto& other = boundaries[node_bc_entry[2 * n + axis]];
            throw InputError(where + ": region '" + bc.region + "' prescribes v" + "xy"[axis] + " = " +
                             std::to_string(v) + " on node " + std::to_string(model.node_tags[n]) +
                             ", which region '" + other.region + "' already prescribes as " +
                             std::to_string(gv));
          }
          if (v != 0.0 && bc.rise > 0.0) {
            if (g.rise > 0.0 && g.rise != bc.rise)
              throw InputError(where + ": node " + std::to_string(model.node_tags[n]) +
                               " gets two different rise times for its prescribed velocity");
            g.rise = bc.rise;
          }
          g.mask |= bit;
          gv = v;
          node_bc_entry[2 * n + axis] = static_cast<int>(i);
        }
      }
    }

    if (bc.traction || bc.pressure || bc.pressure_table || bc.blast || bc.absorbing || bc.in_situ || bc.gas) {
      if (dim != 1)
        throw InputError(where + ": loads and absorbing boundaries act on a physical curve; '" + bc.region +
                         "' is a " + dim_word(dim));
      build_edges();
      EdgeLoad load;
      if (bc.traction) load.tx = (*bc.traction)[0], load.ty = (*bc.traction)[1];
      if (bc.pressure) load.kind = LoadKind::Pressure, load.pressure = *bc.pressure;
      load.rise = bc.rise;
      if (bc.pressure_table) {
        load.kind = LoadKind::Table;
        load.times = bc.pressure_table->times;
        load.values = bc.pressure_table->values;
      }
      if (bc.blast) {
        load.kind = LoadKind::Blast;
        load.pressure = bc.blast->peak;
        load.rise = bc.blast->rise;
        load.ratio = bc.blast->ratio;
      }
      if (bc.absorbing) load.kind = LoadKind::Absorbing;
      if (bc.in_situ) load.kind = LoadKind::InSitu;
      if (bc.gas) load.kind = LoadKind::Gas;
      // An absorbing edge needs the impedance of its own material: one load per
      // material along the curve.
      std::map<int, int> load_of_material;
      auto load_for = [&](int triangle) {
        const int material = load.kind == LoadKind::Absorbing ? model.triangle_material[triangle] : -1;
        auto found = load_of_material.find(material);
        if (found != load_of_material.end()) return found->second;
        load.material = material;
        model.loads.push_back(load);
        return load_of_material[material] = static_cast<int>(model.loads.size() - 1);
      };
      for (int g : find_region(mesh, bc.region, where)) {
        for (size_t l = 0; l < mesh.lines.size(); ++l) {
          if (mesh.line_group[l] != g) continue;
          const int a = new_index[mesh.lines[l][0]], b = new_index[mesh.lines[l][1]];
          auto it = (a >= 0 && b >= 0) ? edges.find(edge_key(a, b)) : edges.end();
          if (it == edges.end())
            throw InputError(mesh.source + ": line element " + std::to_string(mesh.line_tags[l]) + " of curve '" +
                             bc.region + "' is not an edge of any triangle (the curve must be meshed with the surface)");
          if (it->second.count != 1)
            throw InputError(where + ": curve '" + bc.region + "' runs inside the body (line element " +
                             std::to_string(mesh.line_tags[l]) + " lies between two triangles); loads act on the boundary");
          model.loaded_edges.push_back({it->second.a, it->second.b, load_for(it->second.triangle)});
        }
      }
    }
  }

  // Deduplicate per-node prescriptions into groups; group 0 is the free node.
  model.groups.push_back(BoundaryGroup{});
  model.node_group.assign(model.num_nodes(), 0);
  for (size_t n = 0; n < model.num_nodes(); ++n) {
    if (node_bc[n].mask == 0) continue;
    auto it = std::find(model.groups.begin() + 1, model.groups.end(), node_bc[n]);
    if (it == model.groups.end()) {
      model.groups.push_back(node_bc[n]);
      it = model.groups.end() - 1;
    }
    model.node_group[n] = static_cast<uint32_t>(it - model.groups.begin());
  }

  model.vx0.assign(model.num_nodes(), 0.0);
  model.vy0.assign(model.num_nodes(), 0.0);
  for (size_t i = 0; i < config.initials.size(); ++i) {
    const auto& init = config.initials[i];
    const std::string where = config.path + ": initial[" + std::to_string(i) + "]";
    int dim = 0;
    const auto nodes = region_nodes(init.region, where, &dim);
    remember_region(init.region, dim, nodes, false);
    for (int n : nodes) {
      model.vx0[n] = init.velocity[0];
      model.vy0[n] = init.velocity[1];
    }
  }
  for (const auto& name : config.output.regions) {
    int dim = 0;
    const auto nodes = region_nodes(name, config.path + ": output.regions", &dim);
    remember_region(name, dim, nodes, false);
  }
  if (config.contact) {
    model.contact = build_contact(*config.contact, config, mean_edge_length(model));
    if (model.contact.skin_from_mesh) model.contact.skin = default_skin(model);
    for (const auto& name : config.contact->regions) {
      int dim = 0;
      const auto nodes = region_nodes(name, config.path + ": contact.regions", &dim);
      remember_region(name, dim, nodes, false);
    }
  }

  // Prescribed velocities hold from the start.
  for (size_t n = 0; n < model.num_nodes(); ++n) {
    const auto& g = model.groups[model.node_group[n]];
    if (g.rise > 0) continue;
    if (g.mask & 1u) model.vx0[n] = g.vx;
    if (g.mask & 2u) model.vy0[n] = g.vy;
  }
  if (config.fluid) {  // the crack and the source, split with the others
    int dim = 0;
    if (!config.fluid->crack.empty())
      remember_region(config.fluid->crack, dim, region_nodes(config.fluid->crack, config.path + ": fluid.crack", &dim), false);
    if (config.fluid->gas)
      remember_region(config.fluid->gas->hole, dim,
                      region_nodes(config.fluid->gas->hole, config.path + ": fluid.gas.hole", &dim), false);
    else
      remember_region(config.fluid->source, dim, region_nodes(config.fluid->source, config.path + ": fluid.source", &dim), false);
  }
  if (config.grains) {  // each grain's area, from its triangles
    model.grain_area.assign(model.grain_mineral.size(), 0.0);
    for (size_t t = 0; t < model.num_triangles(); ++t) {
      if (model.triangle_grain[t] < 0) continue;
      const auto& tri = model.triangles[t];
      model.grain_area[size_t(model.triangle_grain[t])] +=
          0.5 * std::fabs((model.x[tri[1]] - model.x[tri[0]]) * (model.y[tri[2]] - model.y[tri[0]]) -
                          (model.x[tri[2]] - model.x[tri[0]]) * (model.y[tri[1]] - model.y[tri[0]]));
    }
  }
  split_fracturable(model, config, joint_edges(mesh, new_index, model, config), notes);
  if (config.fluid) model.fluid = build_fluid_model(model, *config.fluid, config.path);
  if (config.contact) model.contact_active = initial_candidates(model, *config.contact);
  set_heterogeneity(model, config);
  if (config.in_situ) set_in_situ(model, config);
  check_extrinsic(model, config);  // after everything it refuses is set
  set_excavations(model, mesh, triangle_group, config);
  return model;
}

BlastPulse blast_pulse(double peak, double rise, double ratio) {
  // t₀ = ln r / (β − α) with β = r α gives α = ln r / (t₀ (r − 1)).
  BlastPulse p;
  p.alpha = std::log(ratio) / (rise * (ratio - 1.0));
  p.beta = ratio * p.alpha;
  p.scale = peak / (std::exp(-p.alpha * rise) - std::exp(-p.beta * rise));
  return p;
}

StableStep stable_time_step(const Model& model) {
  // Absorbing edges (keyed by their nodes, the triangle's own copies) and their length.
  std::map<std::pair<int, int>, double> absorbing;
  for (const auto& e : model.loaded_edges)
    if (model.loads[e.load].kind == LoadKind::Absorbing)
      absorbing[edge_key(e.a, e.b)] += std::hypot(model.x[e.b] - model.x[e.a], model.y[e.b] - model.y[e.a]);
  StableStep best{std::numeric_limits<double>::infinity(), 0};
  for (size_t t = 0; t < model.num_triangles(); ++t) {
    const auto& tri = model.triangles[t];
    const auto& m = model.materials[model.triangle_material[t]];
    double dashpot_length = 0;  // absorbing edges of this triangle [m]
    if (!absorbing.empty())
      for (int e = 0; e < 3; ++e)
        if (auto it = absorbing.find(edge_key(tri[e], tri[(e + 1) % 3])); it != absorbing.end()) dashpot_length += it->second;
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
      const int a = tri[e], b = tri[(e + 1) % 3];
      longest = std::max(longest, std::hypot(model.x[b] - model.x[a], model.y[b] - model.y[a]));
    }
    const double area2 = (model.x[tri[1]] - model.x[tri[0]]) * (model.y[tri[2]] - model.y[tri[0]]) -
                         (model.y[tri[1]] - model.y[tri[0]]) * (model.x[tri[2]] - model.x[tri[0]]);
    const double h = area2 / longest;  // smallest height
    // Contact springs: two triangles of height H overlapping by d over L push back with
    // about 6 P_n d L / H, a modulus of about 6 P_n; the friction spring P_tan × L is
    // a modulus of about P_tan × h.
    // A heterogeneous E scales the triangle's own wave modulus (young_factor).
    const double wave_modulus = m.wave_modulus * (model.young_factor.empty() ? 1.0 : model.young_factor[t]);
    double modulus = model.contact.enabled ? std::max({wave_modulus, 6.0 * model.contact.max_normal_penalty,
                                                        model.contact.max_tangential_penalty * h})
                                           : wave_modulus;
    // Intact CE4s: the traction slope at the origin is P/h on an element of size h, a
    // modulus of about P (the largest of the opening, sliding and overlap penalties). In
    // shear under compression the cohesive part and the friction element's stick spring
    // (cl_kernels/cohesive_forces.cl) act together: 2 P_tan.
    if (!model.triangle_fracturable.empty() && model.triangle_fracturable[t])
      for (const auto& f : model.fracture)
        modulus = std::max({modulus, f.penalty_opening, 2.0 * f.penalty_sliding, f.penalty_overlap});
    const double c = std::sqrt(modulus / m.density);
    const double omega = 2.0 * c / h;
    double xi = m.viscosity * omega / (2.0 * modulus);
    // An absorbing edge is an explicit dashpot c_d = ρV L t/2 on each of its nodes; on a
    // node held only by this triangle (mass ρAt/3) it adds the damping ratio
    // c_d / (2 m ω) (at most 0.75 h/h_edge: the step shrinks by up to half).
    if (dashpot_length > 0) xi += 0.75 * std::sqrt(m.density * m.wave_modulus) * dashpot_length / (m.density * 0.5 * area2 * omega);
    const double dt = h / c * (std::sqrt(1.0 + xi * xi) - xi);
    if (dt < best.dt) best = {dt, t};
  }
  return best;
}

double speed_scale(const Model& model, const io::CaseConfig& config) {
  double speed = 0, lowest_impedance = 0;
  for (const auto& m : model.materials) {
    const double z = std::sqrt(m.density * m.wave_modulus);
    if (z > 0 && (lowest_impedance == 0 || z < lowest_impedance)) lowest_impedance = z;
  }
  auto push = [&](double stress) {  // a stress wave's particle speed, σ / (ρ c)
    if (lowest_impedance > 0) speed = std::max(speed, std::fabs(stress) / lowest_impedance);
  };
  for (const auto& b : config.boundaries) {
    if (b.velocity) speed = std::max(speed, std::hypot((*b.velocity)[0], (*b.velocity)[1]));
    if (b.traction) push(std::hypot((*b.traction)[0], (*b.traction)[1]));
    if (b.pressure) push(*b.pressure);
    if (b.pressure_table)
      for (double v : b.pressure_table->values) push(v);
    if (b.blast) push(b.blast->peak);
  }
  if (config.fluid && config.fluid->gas) push(config.fluid->gas->pressure);
  for (const auto& i : config.initials) speed = std::max(speed, std::hypot(i.velocity[0], i.velocity[1]));
  return speed;
}

std::vector<std::string> model_warnings(const Model& model, const io::CaseConfig& config, double dt) {
  std::vector<std::string> out;
  auto where = [&](const std::string& key) { return io::origin_of(config, key) + ": "; };
  // [fluid]: the fluid in a closed crack is a stiff spring the mechanical step does not
  // see (FluidModel::spring_dt); with mass scaling the masses are the engine's to choose.
  const FluidSpring spring = model.fluid.enabled ? fluid_spring(model) : FluidSpring{};
  if (model.fluid.enabled && !model.mass_scaling && dt > 0 && dt >= spring.dt)
    out.push_back(where("fluid.bulk_modulus") + "the fluid in a closed crack pushes back with (9/16) K_f h t / w_r, stable " +
                  "below " + format_number(spring.dt) + " s (CE4 " + std::to_string(spring.ce4) +
                  "), and the step is " + format_number(dt) + " s: the faces of a crack the fluid fills can oscillate " +
                  "and grow; lower fluid.bulk_modulus, raise fluid.residual_aperture or the step's safety");
  // A skin that the loads' speed crosses in a few steps: a detection nearly every step.
  if (config.contact && config.contact->rebuild == io::ContactRebuild::Skin && config.contact->skin && dt > 0) {
    const double speed = speed_scale(model, config), skin = *config.contact->skin;
    const double steps = speed > 0 ? 0.5 * skin / (2 * speed * dt) : 0;
    if (speed > 0 && steps < 30)
      out.push_back(where("contact.skin") + "contact.skin = " + format_number(skin) + " m: nodes moving at " +
                    format_number(speed) + " m/s (the loads' particle speed, σ / (ρ c), or a prescribed speed; " +
                    "fragments can fly at twice that) cross half of it in about " + format_number(std::ceil(steps)) +
                    " steps of " + format_number(dt) + " s, so the run detects contact about that often; leave " +
                    "`skin` out (or write \"auto\") and the engine picks it at each detection from the nodes' speeds");
  }
  if (config.contact) {
    const io::ContactConfig& c = *config.contact;
    const double h = mean_edge_length(model);
    // One check per place a P_tan is written: [contact], then each [[contact.pair]].
    auto check = [&](const std::string& key, const std::string& shown, std::optional<double> ptan, double pn,
                     double mu) {
      if (!ptan || mu == 0) return;  // a default is consistent; without friction P_tan does nothing
      const double consistent = default_tangential_penalty(pn, h);
      if (*ptan == 0) {
        out.push_back(where(key) + shown + " = 0 turns the tangential contact force off, so friction = " +
                      format_number(mu) + " has no effect");
      } else if (*ptan > 10 * consistent || *ptan < consistent / 10) {
        out.push_back(where(key) + shown + " = " + format_number(*ptan) + " Pa/m is more than 10x away from " +
                      "6 P_n / h = " + format_number(consistent) + " Pa/m (P_n " + format_number(pn) +
                      " Pa, h " + format_number(h) + " m, the mean triangle edge)" +
                      (*ptan < consistent ? ": the elastic slip before sliding is much larger than the overlap, and a "
                                            "block that must stick creeps (cases/sliding/README.md)"
                                          : ": the friction spring is much stiffer than the normal one and sets the "
                                            "stable step") +
                      "; leave tangential_penalty out for 6 P_n / h");
      }
    };
    check("contact.tangential_penalty", "contact.tangential_penalty", c.tangential_penalty, c.normal_penalty,
          c.friction);
    for (size_t k = 0; k < c.pairs.size(); ++k) {
      const auto& p = c.pairs[k];
      const std::string index = std::to_string(k);
      const double pn = p.normal_penalty.value_or(c.normal_penalty), mu = p.friction.value_or(c.friction);
      if (p.tangential_penalty)
        check("contact.pair." + index + ".tangential_penalty", "contact.pair[" + index + "].tangential_penalty",
              p.tangential_penalty, pn, mu);
      else if (pn != c.normal_penalty || (mu > 0) != (c.friction > 0))  // else [contact]'s warning says it
        check("contact.tangential_penalty", "contact.tangential_penalty (taken by contact.pair[" + index + "])",
              c.tangential_penalty, pn, mu);
    }
  }
  // CE4 penalties against the stiffest fracturable material's E (seed paper, Sections 2.1
  // and 3.4): an intact rock made compliant by its CE4s, and slower waves.
  if (!model.ce4.empty()) {
    double stiffest = 0;
    for (const auto& m : config.materials)
      if (m.fracture) stiffest = std::max(stiffest, m.young);
    const bool dynamic = !config.damping.mass_scaling;
    auto check = [&](const std::string& prefix, const std::string& shown, const io::FractureConfig& f) {
      for (const auto& [key, value] : {std::pair<const char*, double>{"opening", f.penalty_opening},
                                       {"sliding", f.penalty_sliding},
                                       {"overlap", f.penalty_overlap}})
        if (value < 10 * stiffest)
          out.push_back(where(prefix + ".penalty." + key) + shown + ".penalty." + key + " = " + format_number(value) +
                        " Pa is below 10 E = " + format_number(10 * stiffest) +
                        " Pa (E of the stiffest fracturable material): the intact CE4s make the rock too compliant "
                        "and stress waves too slow" +
                        (dynamic ? "; the seed paper (Section 3.4) measured 4660 m/s instead of 5000 m/s with "
                                   "penalties = E, and says penalties near E must not be used for dynamic fracture "
                                   "analysis (it uses 50 E)"
                                 : " (seed paper, Section 2.1)"));
    };
    for (size_t m = 0; m < config.materials.size(); ++m)
      if (config.materials[m].fracture)
        check("material." + std::to_string(m) + ".fracture", "material[" + std::to_string(m) + "].fracture",
              *config.materials[m].fracture);
    for (size_t i = 0; i < config.interfaces.size(); ++i)
      check("interface." + std::to_string(i), "interface[" + std::to_string(i) + "]", config.interfaces[i].fracture);
    for (size_t j = 0; j < config.joints.size(); ++j)
      check("joint." + std::to_string(j), "joint[" + std::to_string(j) + "]", config.joints[j].fracture);
  }
  // An in-situ field that grows with depth at another ρ than the rock's is not in
  // equilibrium with the rock's weight: the body settles (or heaves) from the start.
  if (config.in_situ && config.in_situ->datum && config.in_situ->density)
    for (size_t m = 0; m < config.materials.size(); ++m)
      if (config.materials[m].density != *config.in_situ->density)
        out.push_back(where("in_situ.density") + "in_situ.density = " + format_number(*config.in_situ->density) +
                      " kg/m³ differs from material[" + std::to_string(m) + "].density = " +
                      format_number(config.materials[m].density) +
                      " kg/m³: the field is not in equilibrium with that rock's weight, so the body moves from the "
                      "start");
  // Free boundary edges across which the field has a traction: nothing holds it there.
  if (model.in_situ.enabled) {
    std::map<std::pair<int, int>, int> count;
    for (const auto& tri : model.triangles)
      for (int k = 0; k < 3; ++k) ++count[edge_key(tri[k], tri[(k + 1) % 3])];
    for (const auto& c : model.ce4) ++count[edge_key(c[0], c[1])], ++count[edge_key(c[2], c[3])];  // bonded faces
    std::map<std::pair<int, int>, bool> loaded;
    for (const auto& e : model.loaded_edges)
      if (model.loads[e.load].kind == LoadKind::InSitu) loaded[edge_key(e.a, e.b)] = true;
    long unheld = 0;
    std::string example;
    for (const auto& tri : model.triangles)
      for (int k = 0; k < 3; ++k) {
        const int a = tri[k], b = tri[(k + 1) % 3];
        if (count[edge_key(a, b)] != 1 || loaded.count(edge_key(a, b))) continue;
        const auto& ga = model.groups[model.node_group[a]];
        const auto& gb = model.groups[model.node_group[b]];
        const double ex = model.x[b] - model.x[a], ey = model.y[b] - model.y[a];
        const auto s = model.in_situ.at(0.5 * (model.y[a] + model.y[b]));
        const double tx = s[0] * ey - s[2] * ex, ty = s[2] * ey - s[1] * ex;  // σ₀ (n L), n L = (e.y, -e.x)
        const double scale = std::max({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])}) * std::hypot(ex, ey);
        const bool held_x = std::fabs(tx) <= 1e-9 * scale || ((ga.mask & 1u) && (gb.mask & 1u));
        const bool held_y = std::fabs(ty) <= 1e-9 * scale || ((ga.mask & 2u) && (gb.mask & 2u));
        if (held_x && held_y) continue;
        if (unheld++ == 0)
          example = " (e.g. the edge from (" + format_number(model.x[a]) + ", " + format_number(model.y[a]) + ") to (" +
                    format_number(model.x[b]) + ", " + format_number(model.y[b]) + ") m)";
      }
    if (unheld > 0)
      out.push_back(where(config.in_situ->datum ? "in_situ.datum" : "in_situ.stress") + "[in_situ]: " +
                    std::to_string(unheld) + " boundary edges" + example +
                    " have a traction σ₀·n that nothing holds (no `in_situ = true` load, no fixity on that axis): "
                    "the body moves there from the start");
  }
  return out;
}

}  // namespace fdem
