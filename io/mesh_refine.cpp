// Uniform refinement of a mesh as read: every triangle into four at its edge midpoints
// (io/mesh.hpp documents the numbering). Shared edges are found through a node →
// triangles table (no hash map), so the midpoints' order follows the triangles' order
// alone and a refined mesh is the same on every run and machine.
#include <algorithm>
#include <array>
#include <climits>
#include <unistd.h>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "base/errors.hpp"
#include "io/mesh.hpp"

namespace fdem::io {
namespace {

// The triangles of each node, in increasing triangle order (CSR).
struct NodeTriangles {
  std::vector<int> start, list;
  NodeTriangles(const Mesh& m) : start(m.x.size() + 1, 0) {
    for (const auto& t : m.triangles)
      for (int n : t) ++start[n + 1];
    for (size_t n = 0; n < m.x.size(); ++n) start[n + 1] += start[n];
    list.resize(start.back());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t t = 0; t < m.triangles.size(); ++t)
      for (int n : m.triangles[t]) list[fill[n]++] = static_cast<int>(t);
  }
};

// Slot 3t + e of the edge {a, b} in the first triangle t that has it (edge e runs from
// corner e to corner e+1), or -1 when no triangle has it.
int first_slot(const Mesh& m, const NodeTriangles& nt, int a, int b) {
  for (int k = nt.start[a]; k < nt.start[a + 1]; ++k) {
    const int t = nt.list[k];
    const auto& tri = m.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const int p = tri[e], q = tri[(e + 1) % 3];
      if ((p == a && q == b) || (p == b && q == a)) return 3 * t + e;
    }
  }
  return -1;
}

long largest(const std::vector<long>& tags, long start) {
  for (long t : tags) start = std::max(start, t);
  return start;
}

void refine_once(Mesh& m, const std::string& what) {
  const size_t n_tri = m.triangles.size(), n_lines = m.lines.size();
  const NodeTriangles nt(m);
  long next_node_tag = largest(m.node_tags, 0) + 1;
  const long element_base = largest(m.line_tags, largest(m.triangle_tags, m.max_element_tag));

  auto add_node = [&](int a, int b) {
    if (m.x.size() >= static_cast<size_t>(INT_MAX))
      throw InputError(what + ": the refined mesh would have more than 2^31 - 1 nodes");
    m.x.push_back(0.5 * (m.x[a] + m.x[b]));
    m.y.push_back(0.5 * (m.y[a] + m.y[b]));
    m.node_tags.push_back(next_node_tag++);
    return static_cast<int>(m.x.size() - 1);
  };

  // Midpoint of every triangle edge, created in the first triangle that has the edge.
  std::vector<int> mid(3 * n_tri, -1);
  for (size_t t = 0; t < n_tri; ++t)
    for (int e = 0; e < 3; ++e) {
      const int a = m.triangles[t][e], b = m.triangles[t][(e + 1) % 3];
      const int first = first_slot(m, nt, a, b);
      mid[3 * t + e] = first == static_cast<int>(3 * t + e) ? add_node(a, b) : mid[first];
    }
  // Line elements on triangle edges take those midpoints; the others get their own,
  // shared between line elements on the same segment.
  std::vector<int> line_mid(n_lines);
  std::map<std::pair<int, int>, int> loose;
  for (size_t l = 0; l < n_lines; ++l) {
    const int a = m.lines[l][0], b = m.lines[l][1];
    const int slot = first_slot(m, nt, a, b);
    if (slot >= 0) {
      line_mid[l] = mid[slot];
      continue;
    }
    const auto key = std::minmax(a, b);
    auto found = loose.find(key);
    line_mid[l] = found != loose.end() ? found->second : (loose[key] = add_node(a, b));
  }

  std::vector<std::array<int, 3>> triangles;
  std::vector<int> triangle_group;
  std::vector<long> triangle_tags;
  triangles.reserve(4 * n_tri);
  triangle_group.reserve(4 * n_tri);
  triangle_tags.reserve(4 * n_tri);
  for (size_t t = 0; t < n_tri; ++t) {
    const auto [a, b, c] = m.triangles[t];
    const int ab = mid[3 * t], bc = mid[3 * t + 1], ca = mid[3 * t + 2];
    const std::array<std::array<int, 3>, 4> children{{{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}}};
    for (int k = 0; k < 4; ++k) {
      triangles.push_back(children[k]);
      triangle_group.push_back(m.triangle_group[t]);
      triangle_tags.push_back(element_base + 4 * static_cast<long>(t) + k + 1);
    }
  }
  std::vector<std::array<int, 2>> lines;
  std::vector<int> line_group;
  std::vector<long> line_tags;
  const long line_base = element_base + 4 * static_cast<long>(n_tri);
  for (size_t l = 0; l < n_lines; ++l) {
    const auto [a, b] = m.lines[l];
    lines.push_back({a, line_mid[l]});
    lines.push_back({line_mid[l], b});
    for (int k = 0; k < 2; ++k) {
      line_group.push_back(m.line_group[l]);
      line_tags.push_back(line_base + 2 * static_cast<long>(l) + k + 1);
    }
  }
  m.triangles = std::move(triangles);
  m.triangle_group = std::move(triangle_group);
  m.triangle_tags = std::move(triangle_tags);
  m.lines = std::move(lines);
  m.line_group = std::move(line_group);
  m.line_tags = std::move(line_tags);
  m.max_element_tag = line_base + 2 * static_cast<long>(n_lines);
}

}  // namespace

void refine_mesh(Mesh& mesh, int levels, const std::string& what) {
  if (levels <= 0) return;
  mesh.triangle_entity.clear();  // as read only (io/joint_geometry.cpp reads it from an unrefined mesh)
  // Refuse before any work when the triangles alone would not fit the int indices.
  long double triangles = static_cast<long double>(mesh.triangles.size());
  for (int k = 0; k < levels && triangles <= INT_MAX; ++k) triangles *= 4;
  if (triangles > INT_MAX)
    throw InputError(what + ": " + std::to_string(mesh.triangles.size()) + " triangles refined " +
                     std::to_string(levels) + " times would be more than 2^31 - 1 triangles");
  // And when the model built from them would not fit this machine's memory: about 1 KB
  // of host memory per triangle of a fracturable model (measured: 204 MB of resident
  // memory for `fdem check` on 233k TRI3 with 347k CE4s), so a mistyped level is a clear
  // refusal, not the system killing the run.
  constexpr long double kHostBytesPerTriangle = 1024;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0 && triangles * kHostBytesPerTriangle > static_cast<long double>(pages) * page)
    throw InputError(what + ": " + std::to_string(mesh.triangles.size()) + " triangles refined " +
                     std::to_string(levels) + " times would be " + std::to_string(static_cast<long long>(triangles)) +
                     " triangles, about " + std::to_string(static_cast<long long>(triangles * kHostBytesPerTriangle / 1e9)) +
                     " GB of host memory at 1 KB each; this machine has " +
                     std::to_string(static_cast<long long>(static_cast<long double>(pages) * page / 1e9)) + " GB");
  for (int k = 0; k < levels; ++k) refine_once(mesh, what);
}

}  // namespace fdem::io
