#include "io/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "base/errors.hpp"

namespace fdem::io {
namespace {

std::string format_point(const Mesh& m, int node) {
  char buf[96];
  long tag = node < static_cast<int>(m.node_tags.size()) ? m.node_tags[node] : node;
  std::snprintf(buf, sizeof buf, "%ld (%.9g, %.9g)", tag, m.x[node], m.y[node]);
  return buf;
}

}  // namespace

int orient_triangles(Mesh& mesh, std::vector<std::string>* notes, double degenerate_tol) {
  constexpr int kMaxNotes = 10;
  int flipped = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    auto& tri = mesh.triangles[t];
    const double x0 = mesh.x[tri[0]], y0 = mesh.y[tri[0]];
    const double ax = mesh.x[tri[1]] - x0, ay = mesh.y[tri[1]] - y0;
    const double bx = mesh.x[tri[2]] - x0, by = mesh.y[tri[2]] - y0;
    const double area = 0.5 * (ax * by - bx * ay);
    const double cx = bx - ax, cy = by - ay;
    const double longest2 = std::max({ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy});
    long tag = t < mesh.triangle_tags.size() ? mesh.triangle_tags[t] : static_cast<long>(t);
    // Written as !(a > b) so that NaN coordinates count as degenerate too.
    if (!(std::abs(area) > degenerate_tol * longest2)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.3g", area);
      throw InputError(mesh.source + ": degenerate triangle (Gmsh element " + std::to_string(tag) + ") with nodes " +
                       format_point(mesh, tri[0]) + ", " + format_point(mesh, tri[1]) + ", " + format_point(mesh, tri[2]) +
                       ": area " + buf + " is below the tolerance relative to its longest edge squared");
    }
    if (area < 0) {
      std::swap(tri[1], tri[2]);
      ++flipped;
      if (notes && flipped <= kMaxNotes)
        notes->push_back(mesh.source + ": triangle (Gmsh element " + std::to_string(tag) + ") was clockwise; re-oriented counter-clockwise");
    }
  }
  if (notes && flipped > kMaxNotes)
    notes->push_back(mesh.source + ": " + std::to_string(flipped) + " clockwise triangles re-oriented in all (" +
                     std::to_string(flipped - kMaxNotes) + " not listed)");
  return flipped;
}

}  // namespace fdem::io
