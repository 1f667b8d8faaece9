#include "engine/model/extrinsic.hpp"

#include <algorithm>
#include <string>

#include "base/errors.hpp"

namespace fdem {

std::vector<char> extrinsic_ce4(const Model& model) {
  std::vector<char> out;
  bool any = false;
  for (const auto& f : model.fracture) any = any || f.extrinsic;
  if (!any) return out;
  out.resize(model.ce4.size(), 0);
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const int p = model.ce4_properties[e];
    out[e] = p >= 0 && size_t(p) < model.fracture.size() && model.fracture[p].extrinsic ? 1 : 0;
  }
  return out;
}

bool has_extrinsic(const Model& model) {
  const auto flags = extrinsic_ce4(model);
  return std::any_of(flags.begin(), flags.end(), [](char c) { return c != 0; });
}

ExtrinsicTies extrinsic_ties(const Model& model) {
  ExtrinsicTies ties;
  const auto flags = extrinsic_ce4(model);
  if (flags.empty() || model.node_origin.empty()) return ties;
  const size_t vertices = size_t(*std::max_element(model.node_origin.begin(), model.node_origin.end())) + 1;
  // Copies of each mesh vertex, in node order.
  std::vector<std::vector<uint32_t>> copies(vertices);
  for (size_t i = 0; i < model.node_origin.size(); ++i) copies[size_t(model.node_origin[i])].push_back(uint32_t(i));
  // Links at each vertex: (i, i') and (j, j') of each extrinsic CE4, in CE4 order.
  std::vector<std::vector<std::array<uint32_t, 3>>> links(vertices);
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    if (!flags[e]) continue;
    const auto& c = model.ce4[e];
    for (const auto& [a, b] : {std::array<int, 2>{c[0], c[3]}, std::array<int, 2>{c[1], c[2]}})
      links[size_t(model.node_origin[a])].push_back({uint32_t(a), uint32_t(b), uint32_t(e)});
  }
  std::vector<uint32_t> tie_index(vertices, 0);
  for (size_t v = 0; v < vertices; ++v) {
    if (links[v].empty()) continue;
    tie_index[v] = uint32_t(ties.whole.size());
    const auto& cv = copies[v];
    if (cv.size() > size_t(kExtrinsicMaxCopies))
      throw InputError("mesh node " + std::to_string(model.node_tags.empty() ? long(v) : model.node_tags[cv[0]]) +
                       " has " + std::to_string(cv.size()) + " triangles in an extrinsic fracturable region; "
                       "fracture.model = \"extrinsic\" allows at most " + std::to_string(kExtrinsicMaxCopies) +
                       " at one node (remesh with better-shaped triangles there)");
    auto local = [&](uint32_t node) {
      return uint32_t(std::lower_bound(cv.begin(), cv.end(), node) - cv.begin());
    };
    for (const uint32_t node : cv) ties.copy_node.push_back(node);
    ties.copy_start.push_back(uint32_t(ties.copy_node.size()));
    for (const auto& l : links[v]) ties.link.push_back({local(l[0]), local(l[1]), l[2], 0});
    ties.link_start.push_back(uint32_t(ties.link.size()));
    // Whether the links join every copy (a vertex inside the region: its fan closes; one
    // where two parts of a region meet at a point, or on a region's edge, may not).
    std::vector<uint32_t> root(cv.size());
    for (uint32_t k = 0; k < root.size(); ++k) root[k] = k;
    auto find = [&root](uint32_t k) {
      while (root[k] != k) k = root[k] = root[root[k]];
      return k;
    };
    size_t runs = cv.size();
    for (const auto& l : links[v]) {
      const uint32_t a = find(local(l[0])), b = find(local(l[1]));
      if (a != b) root[std::max(a, b)] = std::min(a, b), --runs;
    }
    ties.whole.push_back(runs == 1 ? 1 : 0);
  }
  ties.ce4_vertex.resize(model.ce4.size(), {0, 0});
  for (size_t e = 0; e < model.ce4.size(); ++e)
    if (flags[e])
      ties.ce4_vertex[e] = {tie_index[size_t(model.node_origin[model.ce4[e][0]])],
                            tie_index[size_t(model.node_origin[model.ce4[e][1]])]};
  ties.opposite.resize(model.ce4.size(), {0, 0});
  for (size_t e = 0; e < model.ce4.size(); ++e) {
    const auto& c = model.ce4[e];
    for (int side = 0; side < 2; ++side) {
      const int t = model.ce4_triangles[e][side];
      const auto& tri = model.triangles[size_t(t)];
      const int a = side == 0 ? c[0] : c[3], b = side == 0 ? c[1] : c[2];
      int corner = 0;
      for (int k = 0; k < 3; ++k)
        if (tri[k] != a && tri[k] != b) corner = k;
      ties.opposite[e][side] = uint32_t(3 * t + corner);
    }
  }
  return ties;
}

std::string extrinsic_summary(const Model& model) {
  const auto flags = extrinsic_ce4(model);
  const size_t n = size_t(std::count(flags.begin(), flags.end(), char(1)));
  if (n == 0) return "";
  const ExtrinsicTies ties = extrinsic_ties(model);
  return std::to_string(n) + " of the CE4s (fracture.model = \"extrinsic\") carry nothing until their edge's traction "
         "reaches the peak; until then the copies of " + std::to_string(ties.vertices()) +
         " mesh nodes move as one";
}

void check_extrinsic(const Model& model, const io::CaseConfig& config) {
  if (!has_extrinsic(model)) return;
  std::string key;
  for (size_t m = 0; m < config.materials.size() && key.empty(); ++m)
    if (config.materials[m].fracture && config.materials[m].fracture->extrinsic)
      key = "material[" + std::to_string(m) + "] ('" + config.materials[m].name + "').fracture.model = \"extrinsic\"";
  for (size_t i = 0; i < config.interfaces.size() && key.empty(); ++i)
    if (config.interfaces[i].fracture.extrinsic) key = "interface[" + std::to_string(i) + "].model = \"extrinsic\"";
  auto refuse = [&](const std::string& what) {
    throw InputError(config.path + ": " + key + " cannot be combined with " + what +
                     " yet (extrinsic CE4s: issue 33, docs/case-format.md)");
  };
  if (model.local_damping != 0) refuse("damping.local (the tied copies' damping work is not accounted)");
  if (model.mass_scaling) refuse("damping.mass_scaling");
  if (model.in_situ.enabled) refuse("[in_situ]");
  if (model.fluid.enabled) refuse("[fluid]");
  (void)extrinsic_ties(model);  // a vertex with too many copies
}

}  // namespace fdem
