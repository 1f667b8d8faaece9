#include "engine/model/probes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "base/errors.hpp"

namespace fdem {

namespace {

struct Vec {
  double x, y;
};

// Nearest point of segment a-b to p.
Vec nearest_on_segment(Vec p, Vec a, Vec b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  double s = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  return {a.x + s * dx, a.y + s * dy};
}

// Distance from p to the (closed) triangle and the nearest point of it; 0 and p itself
// when p is inside. Inside is judged by the signs of the three edge cross products
// against a tolerance relative to the triangle's size, so a point on a shared edge is
// inside both triangles and the lower index wins.
double distance_to_triangle(Vec p, const Vec (&v)[3], Vec* nearest) {
  const double scale = std::max({std::hypot(v[1].x - v[0].x, v[1].y - v[0].y),
                                 std::hypot(v[2].x - v[1].x, v[2].y - v[1].y),
                                 std::hypot(v[0].x - v[2].x, v[0].y - v[2].y)});
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    const Vec a = v[k], b = v[(k + 1) % 3];
    const double cross = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);  // > 0: left of a→b
    if (cross < -1e-12 * scale * scale) inside = false;
  }
  if (inside) {
    *nearest = p;
    return 0.0;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const Vec q = nearest_on_segment(p, v[k], v[(k + 1) % 3]);
    const double d = std::hypot(p.x - q.x, p.y - q.y);
    if (d < best) best = d, *nearest = q;
  }
  return best;
}

double longest_edge(const Vec (&v)[3]) {
  double longest = 0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, std::hypot(v[(k + 1) % 3].x - v[k].x, v[(k + 1) % 3].y - v[k].y));
  return longest;
}

}  // namespace

std::vector<ProbeLocation> locate_probes(const Model& model, const std::vector<io::ProbeConfig>& probes,
                                         const std::string& case_path) {
  std::vector<ProbeLocation> out;
  for (size_t k = 0; k < probes.size(); ++k) {
    const auto& probe = probes[k];
    const Vec p{probe.point[0], probe.point[1]};
    ProbeLocation loc{probe.name, probe.point};

    double best = std::numeric_limits<double>::infinity();
    Vec best_point{p};
    for (size_t t = 0; t < model.num_triangles() && best > 0; ++t) {
      const auto& tri = model.triangles[t];
      const Vec v[3] = {{model.x[tri[0]], model.y[tri[0]]}, {model.x[tri[1]], model.y[tri[1]]}, {model.x[tri[2]], model.y[tri[2]]}};
      Vec q{};
      const double d = distance_to_triangle(p, v, &q);
      if (d < best) best = d, best_point = q, loc.triangle = static_cast<int>(t);
    }
    if (loc.triangle < 0)
      throw InputError(case_path + ": probe[" + std::to_string(k) + "] ('" + probe.name + "'): the model has no triangles");
    if (best > 0) {
      const auto& tri = model.triangles[loc.triangle];
      const Vec v[3] = {{model.x[tri[0]], model.y[tri[0]]}, {model.x[tri[1]], model.y[tri[1]]}, {model.x[tri[2]], model.y[tri[2]]}};
      if (best > 0.01 * longest_edge(v)) {
        std::ostringstream msg;
        msg << case_path << ": probe[" << k << "] ('" << probe.name << "'): point = [" << p.x << ", " << p.y
            << "] is outside the mesh (" << best << " m from its nearest point [" << best_point.x << ", "
            << best_point.y << "]); probe points are in metres, after mesh.scale";
        throw InputError(msg.str());
      }
    }

    double nearest = std::numeric_limits<double>::infinity();
    for (size_t n = 0; n < model.num_nodes(); ++n) {
      const double d = std::hypot(model.x[n] - p.x, model.y[n] - p.y);
      if (d < nearest) nearest = d, loc.node = static_cast<int>(n);
    }
    loc.node_distance = nearest;
    out.push_back(loc);
  }
  return out;
}

std::vector<io::HistoryVariable> PointProbes::variables(const Model& model) const {
  std::vector<io::HistoryVariable> vars;
  for (const auto& p : locations_) {
    // Where the values come from, as attributes the tools read: the point, and the node
    // and element in the Exodus file's 1-based numbering (elements of all TRI3 blocks in
    // block order, which is the model's triangle order).
    const std::vector<std::pair<std::string, std::vector<double>>> where = {
        {"probe_point", {p.point[0], p.point[1]}},
        {"probe_node", {double(p.node + 1)}},
        {"probe_node_point", {model.x[p.node], model.y[p.node]}},
        {"probe_element", {double(p.triangle + 1)}}};
    const std::string at = " at probe " + p.name;
    vars.push_back({p.name + "_vx", "m/s", "velocity x of the node nearest" + at, where});
    vars.push_back({p.name + "_vy", "m/s", "velocity y of the node nearest" + at, where});
    vars.push_back({p.name + "_sxx", "Pa", "Cauchy stress xx of the element" + at, where});
    vars.push_back({p.name + "_syy", "Pa", "Cauchy stress yy of the element" + at, where});
    vars.push_back({p.name + "_sxy", "Pa", "Cauchy stress xy of the element" + at, where});
    vars.push_back({p.name + "_ps1", "Pa", "largest principal stress (tension positive) of the element" + at, where});
  }
  return vars;
}

}  // namespace fdem
