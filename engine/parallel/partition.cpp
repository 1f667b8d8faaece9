#include "engine/parallel/partition.hpp"

#include <algorithm>
#include <optional>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>
#include "base/errors.hpp"
#include "engine/model/extrinsic.hpp"
#ifdef FDEM_HAVE_METIS
#include <metis.h>
#endif

namespace fdem {

std::vector<int64_t> triangle_work(const Model& model) {
  const size_t n = model.num_triangles();
  std::vector<int64_t> work(n, 4);
  for (const auto& pair : model.ce4_triangles)
    for (int t : pair) work[t] += 5;
  if (model.contact.enabled)
    for (size_t t = 0; t < n; ++t) {
      const bool candidate = model.contact_active.empty() || model.contact_active[t] != 0 ||
                             (t < model.triangle_fracturable.size() && model.triangle_fracturable[t]);
      if (candidate) work[t] += 100;
    }
  return work;
}

bool partition_has_metis() {
#ifdef FDEM_HAVE_METIS
  return true;
#else
  return false;
#endif
}

const char* partition_method_name(PartitionMethod method) {
  return method == PartitionMethod::Metis ? "metis" : "bisection";
}

namespace {

struct Centroids {
  std::vector<double> x, y;
};

Centroids centroids(const Model& m) {
  Centroids c;
  c.x.resize(m.num_triangles());
  c.y.resize(m.num_triangles());
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    const auto& v = m.triangles[t];
    c.x[t] = (m.x[v[0]] + m.x[v[1]] + m.x[v[2]]) / 3.0;
    c.y[t] = (m.y[v[0]] + m.y[v[1]] + m.y[v[2]]) / 3.0;
  }
  return c;
}

// Splits `ids` (triangles) into parts first_part … first_part + parts − 1: along the
// longer extent of their centroids, at the point where the work to the left reaches
// the left half's share. Ties in the coordinate are broken by triangle index, so the
// result does not depend on the sort's implementation.
void bisect(std::vector<int>& ids, size_t begin, size_t end, int first_part, int parts, const Centroids& c,
            const std::vector<int64_t>& work, std::vector<int>& out) {
  if (parts == 1) {
    for (size_t k = begin; k < end; ++k) out[ids[k]] = first_part;
    return;
  }
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  int64_t total = 0;
  for (size_t k = begin; k < end; ++k) {
    const int t = ids[k];
    xmin = std::min(xmin, c.x[t]), xmax = std::max(xmax, c.x[t]);
    ymin = std::min(ymin, c.y[t]), ymax = std::max(ymax, c.y[t]);
    total += work[t];
  }
  const std::vector<double>& coord = (xmax - xmin >= ymax - ymin) ? c.x : c.y;
  std::sort(ids.begin() + begin, ids.begin() + end,
            [&](int a, int b) { return coord[a] != coord[b] ? coord[a] < coord[b] : a < b; });
  const int left_parts = parts / 2;
  // Work wanted on the left: its share of the total, in exact integer arithmetic.
  const int64_t wanted = total * left_parts / parts;
  size_t cut = begin;
  int64_t sum = 0;
  while (cut < end && sum + work[ids[cut]] <= wanted) sum += work[ids[cut++]];
  // Whichever of the cut and the next triangle is closer to the share; each side keeps
  // at least one triangle per part.
  if (cut < end && (wanted - sum) * 2 > work[ids[cut]]) ++cut;
  cut = std::clamp(cut, begin + left_parts, end - (parts - left_parts));
  bisect(ids, begin, cut, first_part, left_parts, c, work, out);
  bisect(ids, cut, end, first_part + left_parts, parts - left_parts, c, work, out);
}

// Triangles joined across an edge (two shared nodes) or by a CE4, as adjacency lists
// sorted by index.
std::vector<std::vector<int>> triangle_graph(const Model& m) {
  std::vector<std::vector<int>> adj(m.num_triangles());
  std::unordered_map<uint64_t, int> first;  // edge (low node, high node) → first triangle
  first.reserve(3 * m.num_triangles());
  for (size_t t = 0; t < m.num_triangles(); ++t)
    for (int e = 0; e < 3; ++e) {
      uint64_t a = static_cast<uint32_t>(m.triangles[t][e]), b = static_cast<uint32_t>(m.triangles[t][(e + 1) % 3]);
      if (a > b) std::swap(a, b);
      const auto [it, fresh] = first.emplace((a << 32) | b, static_cast<int>(t));
      if (!fresh) {
        adj[t].push_back(it->second);
        adj[it->second].push_back(static_cast<int>(t));
      }
    }
  for (const auto& pair : m.ce4_triangles) {
    adj[pair[0]].push_back(pair[1]);
    adj[pair[1]].push_back(pair[0]);
  }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  return adj;
}

#ifdef FDEM_HAVE_METIS
std::vector<int> metis_parts(const Model& m, int parts, const std::vector<int64_t>& work) {
  const auto adj = triangle_graph(m);
  std::vector<idx_t> xadj{0}, adjncy, vwgt;
  for (size_t t = 0; t < adj.size(); ++t) {
    for (int u : adj[t]) adjncy.push_back(u);
    xadj.push_back(static_cast<idx_t>(adjncy.size()));
    vwgt.push_back(static_cast<idx_t>(work[t]));
  }
  idx_t nvtxs = static_cast<idx_t>(adj.size()), ncon = 1, nparts = parts, objval = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_CONTIG] = 0;
  std::vector<idx_t> part(adj.size(), 0);
  const int status = METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr, nullptr,
                                         &nparts, nullptr, nullptr, options, &objval, part.data());
  if (status != METIS_OK)
    throw InputError("METIS could not split the model's " + std::to_string(adj.size()) + " TRI3 into " +
                     std::to_string(parts) + " parts (status " + std::to_string(status) + ")");
  return std::vector<int>(part.begin(), part.end());
}
#endif

}  // namespace

Partition partition_model(const Model& model, int parts, PartitionMethod method) {
  const size_t n = model.num_triangles();
  if (parts < 1 || static_cast<size_t>(parts) > n)
    throw InputError("cannot split " + std::to_string(n) + " TRI3 into " + std::to_string(parts) +
                     " parts: the number of ranks must be between 1 and the number of triangles");
  Partition p;
  p.parts = parts;
  p.method = method;
  const auto work = triangle_work(model);
  if (parts == 1) {
    p.triangle_part.assign(n, 0);
    return p;
  }
  if (method == PartitionMethod::Metis) {
#ifdef FDEM_HAVE_METIS
    p.triangle_part = metis_parts(model, parts, work);
    return p;
#else
    throw InputError("this fdem was built without METIS (Debian package libmetis-dev): use the bisection partitioner");
#endif
  }
  p.triangle_part.assign(n, 0);
  std::vector<int> ids(n);
  std::iota(ids.begin(), ids.end(), 0);
  bisect(ids, 0, n, 0, parts, centroids(model), work, p.triangle_part);
  return p;
}

std::vector<int> node_owners(const Model& model, const Partition& partition) {
  std::vector<int> owner(model.num_nodes(), -1);
  for (size_t t = 0; t < model.num_triangles(); ++t)
    for (int v : model.triangles[t])
      if (owner[v] < 0) owner[v] = partition.triangle_part[t];
  return owner;
}

namespace {
// The reference (start-up) bounding boxes of a model's triangles, in a uniform grid of
// cells as large as the largest box plus `reach`, so that the triangles whose boxes lie
// within `reach` of a given one are found among its 3 x 3 cells. Used to choose contact
// ghosts, which are fixed at start-up from the reference mesh.
class NearBoxes {
 public:
  NearBoxes(const Model& model, double reach) : reach_(reach) {
    const size_t n = model.num_triangles();
    x0_.resize(n), y0_.resize(n), x1_.resize(n), y1_.resize(n);
    double extent = 0;
    for (size_t t = 0; t < n; ++t) {
      const auto& v = model.triangles[t];
      x0_[t] = std::min({model.x[v[0]], model.x[v[1]], model.x[v[2]]});
      x1_[t] = std::max({model.x[v[0]], model.x[v[1]], model.x[v[2]]});
      y0_[t] = std::min({model.y[v[0]], model.y[v[1]], model.y[v[2]]});
      y1_[t] = std::max({model.y[v[0]], model.y[v[1]], model.y[v[2]]});
      extent = std::max({extent, x1_[t] - x0_[t], y1_[t] - y0_[t]});
      gx_ = std::min(gx_, x0_[t]), gy_ = std::min(gy_, y0_[t]);
    }
    cell_ = std::max(extent + reach, 1e-300);
    for (size_t t = 0; t < n; ++t) grid_[cell_of(t)].push_back(static_cast<int>(t));
  }

  // Calls f(u) for every triangle u (t included) whose box lies within the reach of t's.
  template <class F>
  void for_each_near(size_t t, F&& f) const {
    const auto [i, j] = cell_of(t);
    for (int64_t di = -1; di <= 1; ++di)
      for (int64_t dj = -1; dj <= 1; ++dj) {
        const auto it = grid_.find({i + di, j + dj});
        if (it == grid_.end()) continue;
        for (int u : it->second)
          if (x0_[u] <= x1_[t] + reach_ && x1_[u] >= x0_[t] - reach_ && y0_[u] <= y1_[t] + reach_ &&
              y1_[u] >= y0_[t] - reach_)
            f(u);
      }
  }

 private:
  std::pair<int64_t, int64_t> cell_of(size_t t) const {
    return {static_cast<int64_t>((x0_[t] - gx_) / cell_), static_cast<int64_t>((y0_[t] - gy_) / cell_)};
  }
  double reach_, cell_ = 1, gx_ = 1e300, gy_ = 1e300;
  std::vector<double> x0_, y0_, x1_, y1_;
  std::map<std::pair<int64_t, int64_t>, std::vector<int>> grid_;  // cell of a box's lower corner -> triangles
};
}  // namespace

namespace {
void count_held(const Model& model, const Partition& partition, const std::vector<int>& owner, double contact_reach,
                const NearBoxes* boxes, std::vector<PartStats>& stats);
}  // namespace

std::vector<PartStats> partition_stats(const Model& model, const Partition& partition, double contact_reach) {
  const int parts = partition.parts;
  const auto& part = partition.triangle_part;
  const auto owner = node_owners(model, partition);
  const auto work = triangle_work(model);
  std::vector<PartStats> s(parts);
  // Elements each part holds: its own, then its ghosts (owned elsewhere, using a node it owns).
  std::vector<std::vector<int>> tris(parts), ce4s(parts);
  for (size_t t = 0; t < model.num_triangles(); ++t) {
    const int p = part[t];
    ++s[p].tri3;
    s[p].work += work[t];
    tris[p].push_back(static_cast<int>(t));
    int seen[3] = {p, p, p};
    for (int k = 0; k < 3; ++k) {
      const int q = owner[model.triangles[t][k]];
      if (q != p && q != seen[0] && q != seen[1] && q != seen[2]) {
        seen[k] = q;
        ++s[q].ghost_tri3;
        tris[q].push_back(static_cast<int>(t));
      }
    }
  }
  for (size_t c = 0; c < model.ce4.size(); ++c) {
    const int p = part[model.ce4_triangles[c][0]];
    ++s[p].ce4;
    ce4s[p].push_back(static_cast<int>(c));
    std::vector<int> seen{p};
    for (int v : model.ce4[c]) {
      const int q = owner[v];
      if (std::find(seen.begin(), seen.end(), q) == seen.end()) {
        seen.push_back(q);
        ++s[q].ghost_ce4;
        ce4s[q].push_back(static_cast<int>(c));
      }
    }
  }
  for (size_t v = 0; v < model.num_nodes(); ++v)
    if (owner[v] >= 0) ++s[owner[v]].nodes;
  std::vector<int> stamp(model.num_nodes(), -1);
  for (int p = 0; p < parts; ++p) {
    auto visit = [&](int v) {
      if (stamp[v] != p) {
        stamp[v] = p;
        if (owner[v] != p) ++s[p].ghost_nodes;
      }
    };
    for (int t : tris[p])
      for (int v : model.triangles[t]) visit(v);
    for (int c : ce4s[p])
      for (int v : model.ce4[c]) visit(v);
  }
  // The reference boxes within the contact reach: for the held counts and the contact ghosts.
  std::optional<NearBoxes> boxes;
  if (model.contact.enabled) boxes.emplace(model, contact_reach);
  count_held(model, partition, owner, contact_reach, boxes ? &*boxes : nullptr, s);
  if (!model.contact.enabled || parts == 1) return s;

  // Contact ghosts: other parts' triangles whose boxes lie within reach of one of p's.
  std::vector<uint64_t> ghost;  // (part << 32) | triangle
  for (size_t t = 0; t < model.num_triangles(); ++t)
    boxes->for_each_near(t, [&](int u) {
      if (part[u] != part[t]) ghost.push_back((static_cast<uint64_t>(part[t]) << 32) | static_cast<uint32_t>(u));
    });
  std::sort(ghost.begin(), ghost.end());
  ghost.erase(std::unique(ghost.begin(), ghost.end()), ghost.end());
  for (uint64_t g : ghost) ++s[g >> 32].contact_ghost_tri3;
  return s;
}

double partition_imbalance(const std::vector<PartStats>& stats) {
  int64_t total = 0, largest = 0;
  for (const auto& s : stats) total += s.work, largest = std::max(largest, s.work);
  return total == 0 ? 1.0 : static_cast<double>(largest) * stats.size() / static_cast<double>(total);
}

namespace {
// The triangles whose reference bounding box lies within the boxes' reach of the box of a
// `selected` triangle (the selected ones included).
std::vector<char> within_reach(const Model& model, const NearBoxes& boxes, const std::vector<char>& selected) {
  std::vector<char> out(selected);
  for (size_t t = 0; t < model.num_triangles(); ++t)
    if (selected[t]) boxes.for_each_near(t, [&](int u) { out[u] = 1; });
  return out;
}

// The triangles, CE4s and nodes `rank` holds (see partition.hpp).
struct Held {
  std::vector<char> tri, ce4, node;
};
// `boxes`: the reference boxes at partition.contact_reach when the caller has them (several
// ranks' counts share one set), else built here.
Held held(const Model& g, const Partition& partition, const std::vector<int>& owner, int rank,
          const NearBoxes* boxes = nullptr) {
  const auto& part = partition.triangle_part;
  auto touches_owned = [&](const auto& nodes) {
    for (int v : nodes)
      if (owner[v] == rank) return true;
    return false;
  };
  Held h;
  h.tri.assign(g.num_triangles(), 0);
  h.ce4.assign(g.ce4.size(), 0);
  h.node.assign(g.num_nodes(), 0);
  for (size_t t = 0; t < g.num_triangles(); ++t) h.tri[t] = part[t] == rank || touches_owned(g.triangles[t]);
  for (size_t c = 0; c < g.ce4.size(); ++c)
    if (part[g.ce4_triangles[c][0]] == rank || touches_owned(g.ce4[c])) {
      h.ce4[c] = 1;
      h.tri[g.ce4_triangles[c][0]] = h.tri[g.ce4_triangles[c][1]] = 1;
    }
  if (g.contact.enabled && partition.contact_reach > 0) {
    // Contact ghosts: every triangle within reach of an owned one (the lower triangle of a
    // couple is computed by its owner, which must hold the other).
    std::vector<char> owned(g.num_triangles(), 0);
    for (size_t t = 0; t < g.num_triangles(); ++t) owned[t] = part[t] == rank;
    std::optional<NearBoxes> own_boxes;
    if (!boxes) boxes = &own_boxes.emplace(g, partition.contact_reach);
    const auto near = within_reach(g, *boxes, owned);
    for (size_t t = 0; t < g.num_triangles(); ++t) h.tri[t] = h.tri[t] || near[t];
    // With CE4s, contact reads the states of the CE4s on a couple's triangles' edges (its
    // own CE4, the candidate mask's joins) and of every CE4 at their mesh nodes (the
    // corner fans' state words): every CE4 with an end at a mesh node of an owned or
    // contact ghost triangle is held, so it is computed here as its owner computes it.
    if (!g.ce4.empty() && g.node_origin.size() == g.num_nodes()) {
      std::vector<char> mesh(g.vertex_bonded.size(), 0);
      for (size_t t = 0; t < g.num_triangles(); ++t)
        if (near[t])
          for (int v : g.triangles[t]) mesh[g.node_origin[v]] = 1;
      for (size_t c = 0; c < g.ce4.size(); ++c)
        if (mesh[g.node_origin[g.ce4[c][0]]] || mesh[g.node_origin[g.ce4[c][1]]]) {
          h.ce4[c] = 1;
          h.tri[g.ce4_triangles[c][0]] = h.tri[g.ce4_triangles[c][1]] = 1;
        }
    }
  }
  // Extrinsic CE4s (engine/model/extrinsic.hpp): the tie moves all copies of a mesh node
  // as one, so a rank that owns a copy holds every copy (the triangles at the mesh node)
  // and every extrinsic CE4 with an end there (the links), with both their triangles:
  // after the post-integration exchange it ties the node as one rank does.
  const auto extrinsic = extrinsic_ce4(g);
  if (!extrinsic.empty() && g.node_origin.size() == g.num_nodes()) {
    std::vector<char> tied(size_t(*std::max_element(g.node_origin.begin(), g.node_origin.end())) + 1, 0);
    for (size_t c = 0; c < g.ce4.size(); ++c)
      if (extrinsic[c])
        for (int k : {0, 1})
          if (owner[g.ce4[c][k]] == rank || owner[g.ce4[c][3 - k]] == rank) tied[g.node_origin[g.ce4[c][k]]] = 1;
    for (size_t t = 0; t < g.num_triangles(); ++t)
      for (int v : g.triangles[t])
        if (tied[g.node_origin[v]]) h.tri[t] = 1;
    for (size_t c = 0; c < g.ce4.size(); ++c)
      if (extrinsic[c] && (tied[g.node_origin[g.ce4[c][0]]] || tied[g.node_origin[g.ce4[c][1]]])) {
        h.ce4[c] = 1;
        h.tri[g.ce4_triangles[c][0]] = h.tri[g.ce4_triangles[c][1]] = 1;
      }
  }
  for (size_t t = 0; t < g.num_triangles(); ++t)
    if (h.tri[t])
      for (int v : g.triangles[t]) h.node[v] = 1;
  for (size_t c = 0; c < g.ce4.size(); ++c)
    if (h.ce4[c])
      for (int v : g.ce4[c]) h.node[v] = 1;
  return h;
}
}  // namespace

namespace {
// What each part's split run holds (held(), the rule local_model follows), counted.
void count_held(const Model& model, const Partition& partition, const std::vector<int>& owner, double contact_reach,
                const NearBoxes* boxes, std::vector<PartStats>& stats) {
  Partition with_reach = partition;
  with_reach.contact_reach = model.contact.enabled ? contact_reach : 0.0;
  auto count = [](const std::vector<char>& flags) { return static_cast<size_t>(std::count(flags.begin(), flags.end(), 1)); };
  for (int p = 0; p < partition.parts; ++p) {
    const Held h = held(model, with_reach, owner, p, boxes);
    stats[p].held_tri3 = count(h.tri);
    stats[p].held_ce4 = count(h.ce4);
    stats[p].held_nodes = count(h.node);
  }
}
}  // namespace

std::vector<char> held_nodes(const Model& model, const Partition& partition, const std::vector<int>& owner, int rank) {
  return held(model, partition, owner, rank).node;
}

LocalModel local_model(const Model& g, const Partition& partition, int rank) {
  if (g.contact.enabled && !(partition.contact_reach > 0))
    throw InputError("a split model with contact needs a contact reach (Partition::contact_reach)");
  if (rank < 0 || rank >= partition.parts) throw InputError("rank " + std::to_string(rank) + " is not one of the partition's");
  const auto owner = node_owners(g, partition);
  const Held h = held(g, partition, owner, rank);
  const auto& keep_tri = h.tri;
  const auto& keep_ce4 = h.ce4;
  const auto& keep_node = h.node;

  LocalModel l;
  Model& m = l.model;
  std::vector<int> local_node(g.num_nodes(), -1), local_tri(g.num_triangles(), -1);
  for (size_t v = 0; v < g.num_nodes(); ++v)
    if (keep_node[v]) {
      local_node[v] = static_cast<int>(l.node_global.size());
      l.node_global.push_back(static_cast<int>(v));
      l.node_owner.push_back(owner[v]);
      if (owner[v] != rank) l.ghost_nodes.push_back(local_node[v]);
      m.x.push_back(g.x[v]), m.y.push_back(g.y[v]);
      m.node_tags.push_back(g.node_tags[v]);
      m.node_group.push_back(g.node_group[v]);
      m.vx0.push_back(g.vx0[v]), m.vy0.push_back(g.vy0[v]);
    }
  m.mesh_path = g.mesh_path;
  m.thickness = g.thickness;
  m.materials = g.materials;
  m.groups = g.groups;
  m.loads = g.loads;
  m.fracture = g.fracture;
  m.joint_names = g.joint_names;
  m.grain_mineral = g.grain_mineral, m.grain_area = g.grain_area, m.grain_boundary_fracture = g.grain_boundary_fracture;
  m.joint_broken = g.joint_broken;
  m.gravity = g.gravity;
  m.in_situ = g.in_situ;
  m.excavations = g.excavations;
  m.local_damping = g.local_damping;
  m.mass_scaling = g.mass_scaling;
  m.contact = g.contact;
  if (g.contact.enabled) {
    double longest = 0, reach = 0;
    for (const auto& tri : g.triangles)
      for (int e = 0; e < 3; ++e) {
        const int p = tri[e], q = tri[(e + 1) % 3];
        longest = std::max(longest, std::hypot(g.x[q] - g.x[p], g.y[q] - g.y[p]));
      }
    for (size_t i = 0; i < g.num_nodes(); ++i) reach = std::max({reach, std::fabs(g.x[i]), std::fabs(g.y[i])});
    m.whole_longest_edge = std::max(longest, 1e-300);
    m.whole_reach = reach;
    for (int v : l.node_global) m.node_owned.push_back(owner[v] == rank ? 1 : 0);
    // The corner fans by the whole mesh's node numbers (mesh_node_state is per mesh node).
    if (g.node_origin.size() == g.num_nodes()) {
      for (int v : l.node_global) m.node_origin.push_back(g.node_origin[v]);
      m.vertex_bonded = g.vertex_bonded;
    }
  } else if (g.node_origin.size() == g.num_nodes() && has_extrinsic(g)) {
    for (int v : l.node_global) m.node_origin.push_back(g.node_origin[v]);  // the tie's copies
  }
  // Triangles stay grouped by material: a filtered global order is still in blocks.
  m.block_start.assign(g.materials.size() + 1, 0);
  for (size_t t = 0; t < g.num_triangles(); ++t)
    if (keep_tri[t]) {
      local_tri[t] = static_cast<int>(l.triangle_global.size());
      l.triangle_global.push_back(static_cast<int>(t));
      m.triangles.push_back({local_node[g.triangles[t][0]], local_node[g.triangles[t][1]], local_node[g.triangles[t][2]]});
      m.triangle_material.push_back(g.triangle_material[t]);
      m.triangle_tags.push_back(g.triangle_tags[t]);
      if (!g.triangle_fracturable.empty()) m.triangle_fracturable.push_back(g.triangle_fracturable[t]);
      if (!g.young_factor.empty()) m.young_factor.push_back(g.young_factor[t]);
      if (!g.triangle_excavation.empty()) m.triangle_excavation.push_back(g.triangle_excavation[t]);
      if (!g.triangle_grain.empty()) m.triangle_grain.push_back(g.triangle_grain[t]);
      if (!g.contact_active.empty()) m.contact_active.push_back(g.contact_active[t]);
      if (g.contact.enabled) m.triangle_owned.push_back(partition.triangle_part[t] == rank ? 1 : 0);
      ++m.block_start[g.triangle_material[t] + 1];
    }
  for (size_t k = 1; k < m.block_start.size(); ++k) m.block_start[k] += m.block_start[k - 1];
  for (size_t c = 0; c < g.ce4.size(); ++c)
    if (keep_ce4[c]) {
      l.ce4_global.push_back(static_cast<int>(c));
      const auto& n = g.ce4[c];
      m.ce4.push_back({local_node[n[0]], local_node[n[1]], local_node[n[2]], local_node[n[3]]});
      m.ce4_triangles.push_back({local_tri[g.ce4_triangles[c][0]], local_tri[g.ce4_triangles[c][1]]});
      m.ce4_properties.push_back(g.ce4_properties[c]);
      if (!g.ce4_strength_factor.empty()) m.ce4_strength_factor.push_back(g.ce4_strength_factor[c]);
      if (!g.ce4_joint.empty()) m.ce4_joint.push_back(g.ce4_joint[c]);
      if (!g.ce4_grain_boundary.empty()) m.ce4_grain_boundary.push_back(g.ce4_grain_boundary[c]);
      if (g.contact.enabled) m.ce4_owned.push_back(partition.triangle_part[g.ce4_triangles[c][0]] == rank ? 1 : 0);
    }
  for (size_t k = 0; k < g.loaded_edges.size(); ++k) {
    const auto& e = g.loaded_edges[k];
    if (owner[e.a] == rank || owner[e.b] == rank) {
      m.loaded_edges.push_back({local_node[e.a], local_node[e.b], e.load});
      l.edge_global.push_back(static_cast<int>(k));
    }
  }
  for (const auto& r : g.regions) {
    Region lr{r.name, r.dim, {}, r.prescribed};
    for (int v : r.nodes)
      if (local_node[v] >= 0) lr.nodes.push_back(local_node[v]);
    m.regions.push_back(std::move(lr));
  }
  return l;
}

}  // namespace fdem
