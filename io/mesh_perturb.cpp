// mesh.perturb: random moves of the interior nodes of fracturable surfaces, with a quality
// and smallest-height guard (io/mesh.hpp explains the rule).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "io/mesh.hpp"

namespace fdem::io {
namespace {

// splitmix64: a counter-based generator, integer arithmetic only (the same on every machine).
uint64_t splitmix64(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Uniform in [-1, 1), exactly representable (53 random bits).
double unit_signed(uint64_t bits) { return static_cast<double>(bits >> 11) * (1.0 / 4503599627370496.0) - 1.0; }

struct Shape {
  double area, quality, min_height;
};

Shape shape(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double ax = x1 - x0, ay = y1 - y0, bx = x2 - x0, by = y2 - y0, cx = x2 - x1, cy = y2 - y1;
  const double area = 0.5 * (ax * by - bx * ay);
  const double a2 = ax * ax + ay * ay, b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double longest = std::sqrt(std::max({a2, b2, c2}));
  const double sum = a2 + b2 + c2;
  return {area, sum > 0 ? 4.0 * std::sqrt(3.0) * area / sum : 0.0, longest > 0 ? 2.0 * area / longest : 0.0};
}

}  // namespace

PerturbSummary perturb_mesh(Mesh& mesh, const std::vector<char>& movable_group, const PerturbOptions& options) {
  PerturbSummary summary;
  const size_t num_nodes = mesh.x.size(), num_tris = mesh.triangles.size();
  auto tri_shape = [&](size_t t) {
    const auto& n = mesh.triangles[t];
    return shape(mesh.x[n[0]], mesh.y[n[0]], mesh.x[n[1]], mesh.y[n[1]], mesh.x[n[2]], mesh.y[n[2]]);
  };
  auto in_movable = [&](size_t t) {
    const int g = mesh.triangle_group[t];
    return g >= 0 && static_cast<size_t>(g) < movable_group.size() && movable_group[g];
  };

  // Nodes: eligible until something pins them.
  std::vector<char> eligible(num_nodes, 0);
  std::vector<int> node_group(num_nodes, -1);
  for (size_t t = 0; t < num_tris; ++t)
    for (int n : mesh.triangles[t]) {
      if (node_group[n] == -1) {
        node_group[n] = mesh.triangle_group[t];
        eligible[n] = in_movable(t);
      } else if (node_group[n] != mesh.triangle_group[t] || !in_movable(t)) {
        eligible[n] = 0;  // on an interface between surfaces
      }
    }
  for (const auto& line : mesh.lines) eligible[line[0]] = eligible[line[1]] = 0;
  for (int p : mesh.points) eligible[p] = 0;
  // Boundary edges (one triangle) pin their nodes.
  std::vector<std::pair<uint64_t, int>> edges;
  edges.reserve(3 * num_tris);
  for (const auto& tri : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const auto [a, b] = std::minmax(tri[e], tri[(e + 1) % 3]);
      edges.emplace_back((static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b), 1);
    }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i != 2) {
      eligible[edges[i].first >> 32] = 0;
      eligible[edges[i].first & 0xffffffffu] = 0;
    }
    i = j;
  }

  // Triangles around each node (CSR).
  std::vector<int> start(num_nodes + 1, 0), around(3 * num_tris);
  for (const auto& tri : mesh.triangles)
    for (int n : tri) ++start[n + 1];
  for (size_t n = 0; n < num_nodes; ++n) start[n + 1] += start[n];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t t = 0; t < num_tris; ++t)
      for (int n : mesh.triangles[t]) around[fill[n]++] = static_cast<int>(t);
  }

  // The floor of the smallest height, and the quality before, over the movable surfaces.
  bool any = false;
  std::vector<double> quality_before(num_tris, 1.0);
  for (size_t t = 0; t < num_tris; ++t) {
    if (!in_movable(t)) continue;
    const Shape s = tri_shape(t);
    quality_before[t] = s.quality;
    summary.min_quality_before = std::min(summary.min_quality_before, s.quality);
    summary.min_height_before = any ? std::min(summary.min_height_before, s.min_height) : s.min_height;
    any = true;
  }
  const double height_floor = summary.min_height_before;

  for (size_t n = 0; n < num_nodes; ++n) {
    if (!eligible[n]) continue;
    ++summary.movable;
    if (!(options.amplitude > 0)) continue;
    // Mean length of the node's edges (each counted once per triangle: twice overall).
    double length_sum = 0;
    int length_count = 0;
    for (int k = start[n]; k < start[n + 1]; ++k)
      for (int m : mesh.triangles[around[k]])
        if (m != static_cast<int>(n)) {
          length_sum += std::sqrt((mesh.x[m] - mesh.x[n]) * (mesh.x[m] - mesh.x[n]) +
                                  (mesh.y[m] - mesh.y[n]) * (mesh.y[m] - mesh.y[n]));
          ++length_count;
        }
    const double radius = options.amplitude * length_sum / length_count;
    // A point uniform over the unit disc, by rejection from the square.
    const uint64_t tag = n < mesh.node_tags.size() ? static_cast<uint64_t>(mesh.node_tags[n]) : n;
    uint64_t state = splitmix64(options.seed ^ splitmix64(tag));
    double u = 0, v = 0;
    for (int draw = 0; draw < 64; ++draw) {
      state = splitmix64(state);
      u = unit_signed(state);
      state = splitmix64(state);
      v = unit_signed(state);
      if (u * u + v * v <= 1.0) break;
      u = v = 0;
    }
    const double x0 = mesh.x[n], y0 = mesh.y[n];
    double factor = 1.0;
    bool moved = false;
    for (int attempt = 0; attempt < 4 && !moved; ++attempt, factor *= 0.5) {
      mesh.x[n] = x0 + factor * radius * u;
      mesh.y[n] = y0 + factor * radius * v;
      bool ok = true;
      for (int k = start[n]; k < start[n + 1] && ok; ++k) {
        const Shape s = tri_shape(around[k]);
        ok = s.area > 0 && s.quality >= std::min(options.min_quality, quality_before[around[k]]) &&
             s.min_height >= height_floor;
      }
      moved = ok;
    }
    if (moved) {
      ++summary.moved;
    } else {
      mesh.x[n] = x0;
      mesh.y[n] = y0;
      ++summary.kept;
    }
  }
  bool first = true;
  for (size_t t = 0; t < num_tris; ++t) {
    if (!in_movable(t)) continue;
    const Shape s = tri_shape(t);
    summary.min_quality_after = first ? s.quality : std::min(summary.min_quality_after, s.quality);
    summary.min_height_after = first ? s.min_height : std::min(summary.min_height_after, s.min_height);
    first = false;
  }
  return summary;
}

}  // namespace fdem::io
