#include "io/grain_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <set>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "io/suggest.hpp"

namespace fdem::io {

namespace {

const double kPi = std::acos(-1.0);
constexpr long kMaxGrainCount = 5000;  // io/case_tables.hpp's kMaxGrains

std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Uniform draws in [0, 1): the seed, then a counter (integer arithmetic only).
class Stream {
 public:
  explicit Stream(std::uint64_t seed) : state_(splitmix64(seed ^ 0x677261696e73ULL)) {}
  double uniform() {
    state_ = splitmix64(state_);
    return double(state_ >> 11) * 0x1.0p-53;
  }
  std::uint64_t below(std::uint64_t n) {
    state_ = splitmix64(state_);
    return state_ % n;
  }

 private:
  std::uint64_t state_;
};

// The region's triangles in metres, with a grid of buckets: is a point inside?
class RegionLocator {
 public:
  RegionLocator(std::vector<std::array<Point2, 3>> tris, Point2 lo, Point2 hi) : tris_(std::move(tris)), lo_(lo) {
    const double w = std::max(hi[0] - lo[0], 1e-300), h = std::max(hi[1] - lo[1], 1e-300);
    const double n = std::max<double>(1, std::sqrt(double(tris_.size())));
    cell_ = std::max(w, h) / n;
    nx_ = std::max(1, int(std::ceil(w / cell_))), ny_ = std::max(1, int(std::ceil(h / cell_)));
    buckets_.resize(size_t(nx_) * ny_);
    for (size_t t = 0; t < tris_.size(); ++t) {
      double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
      for (const Point2& p : tris_[t]) x0 = std::min(x0, p[0]), y0 = std::min(y0, p[1]), x1 = std::max(x1, p[0]), y1 = std::max(y1, p[1]);
      for (int j = std::max(0, cy(y0)); j <= std::min(ny_ - 1, cy(y1)); ++j)
        for (int i = std::max(0, cx(x0)); i <= std::min(nx_ - 1, cx(x1)); ++i) buckets_[size_t(j) * nx_ + i].push_back(int(t));
    }
  }
  bool inside(Point2 p) const {
    const int i = cx(p[0]), j = cy(p[1]);
    if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return false;
    for (int t : buckets_[size_t(j) * nx_ + i]) {
      const auto& q = tris_[size_t(t)];
      const double a = cross(q[0], q[1], p), b = cross(q[1], q[2], p), c = cross(q[2], q[0], p);
      if ((a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0)) return true;
    }
    return false;
  }

 private:
  static double cross(Point2 o, Point2 a, Point2 b) { return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]); }
  int cx(double x) const { return int(std::floor((x - lo_[0]) / cell_)); }
  int cy(double y) const { return int(std::floor((y - lo_[1]) / cell_)); }
  std::vector<std::array<Point2, 3>> tris_;
  Point2 lo_;
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> buckets_;
};

// A vertex of a Voronoi cell, named by what it lies on: two bisectors (the three seeds,
// sorted), or one bisector and a side of the box (seed, seed, -1 - side), or a corner of
// the box (-1, -1, -1 - corner).
using VertexKey = std::array<long, 3>;

}  // namespace

GrainFinder::GrainFinder(const std::vector<Point2>& points) : points_(points) {
  if (points.empty()) return;
  Point2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (const Point2& p : points) lo = {std::min(lo[0], p[0]), std::min(lo[1], p[1])}, hi = {std::max(hi[0], p[0]), std::max(hi[1], p[1])};
  lo_ = lo;
  const double w = hi[0] - lo[0], h = hi[1] - lo[1];
  cell_ = std::max(std::sqrt(std::max(w * h, 1e-300) / double(points.size())), std::max(w, h) / 4096.0);
  if (!(cell_ > 0)) cell_ = 1;
  nx_ = std::max(1, int(w / cell_) + 1), ny_ = std::max(1, int(h / cell_) + 1);
  buckets_.resize(size_t(nx_) * ny_);
  for (size_t k = 0; k < points.size(); ++k) {
    const int i = std::clamp(int((points[k][0] - lo[0]) / cell_), 0, nx_ - 1);
    const int j = std::clamp(int((points[k][1] - lo[1]) / cell_), 0, ny_ - 1);
    buckets_[size_t(j) * nx_ + i].push_back(int(k));
  }
}

int GrainFinder::nearest(Point2 p) const {
  if (points_.empty()) return -1;
  const int ci = std::clamp(int(std::floor((p[0] - lo_[0]) / cell_)), 0, nx_ - 1);
  const int cj = std::clamp(int(std::floor((p[1] - lo_[1]) / cell_)), 0, ny_ - 1);
  int best = -1;
  double best_d2 = 0;
  // Rings of buckets around p's; a ring r lies at least (r - 1) cells away.
  for (int r = 0; r <= std::max(nx_, ny_); ++r) {
    if (best >= 0) {
      const double reach = (r - 1) * cell_;
      if (reach > 0 && reach * reach > best_d2) break;
    }
    for (int j = cj - r; j <= cj + r; ++j)
      for (int i = ci - r; i <= ci + r; ++i) {
        if (std::max(std::abs(i - ci), std::abs(j - cj)) != r || i < 0 || j < 0 || i >= nx_ || j >= ny_) continue;
        for (int k : buckets_[size_t(j) * nx_ + i]) {
          const double dx = points_[size_t(k)][0] - p[0], dy = points_[size_t(k)][1] - p[1], d2 = dx * dx + dy * dy;
          if (best < 0 || d2 < best_d2 || (d2 == best_d2 && k < best)) best = k, best_d2 = d2;
        }
      }
  }
  return best;
}

GrainDraw draw_grains(GrainsConfig& g, const Mesh& mesh, double scale, const CaseConfig& config) {
  GrainDraw d;
  const int group = mesh.find_group(g.region, 2);
  if (group < 0) {
    std::vector<std::string> surfaces;
    for (const auto& pg : mesh.groups)
      if (pg.dim == 2) surfaces.push_back(pg.name);
    std::string list;
    for (const auto& s : surfaces) list += (list.empty() ? "'" : ", '") + s + "'";
    throw InputError(origin_of(config, "grains.region") + ": grains.region = \"" + g.region + "\" is not a physical surface of " +
                     mesh.source + did_you_mean(g.region, surfaces) + "; its surfaces are " + list);
  }
  std::vector<std::array<Point2, 3>> tris;
  d.lo = {1e300, 1e300}, d.hi = {-1e300, -1e300};
  double edges = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mesh.triangle_group[t] != group) continue;
    std::array<Point2, 3> q;
    for (int k = 0; k < 3; ++k) {
      const int n = mesh.triangles[t][k];
      q[k] = {mesh.x[n] * scale, mesh.y[n] * scale};
      d.lo = {std::min(d.lo[0], q[k][0]), std::min(d.lo[1], q[k][1])};
      d.hi = {std::max(d.hi[0], q[k][0]), std::max(d.hi[1], q[k][1])};
    }
    d.area += 0.5 * std::fabs((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
    for (int k = 0; k < 3; ++k) edges += std::hypot(q[(k + 1) % 3][0] - q[k][0], q[(k + 1) % 3][1] - q[k][1]);
    tris.push_back(q);
  }
  if (tris.empty())
    throw InputError(origin_of(config, "grains.region") + ": grains.region = \"" + g.region + "\" has no triangles in " +
                     mesh.source);
  d.mean_edge = edges / (3.0 * double(tris.size()));
  const std::string key = g.count > 0 ? "grains.count" : "grains.size";
  const std::string given = g.count > 0 ? "grains.count = " + std::to_string(g.count)
                                        : "grains.size = " + format_number(g.size) + " m";
  const double grains = g.count > 0 ? double(g.count) : std::max(1.0, std::round(d.area / (kPi * g.size * g.size / 4)));
  if (grains > double(kMaxGrainCount))
    throw InputError(origin_of(config, key) + ": " + given + " makes " + format_number(grains) + " grains of region '" +
                     g.region + "' (" + format_number(d.area, 4) + " m²), more than the " + std::to_string(kMaxGrainCount) +
                     " allowed");
  const long n = long(grains);
  const double diameter = std::sqrt(4 * d.area / (kPi * double(n)));
  if (diameter < 3 * d.mean_edge)
    throw InputError(origin_of(config, key) + ": " + given + " is too small for the mesh: a mean grain diameter of " +
                     format_number(diameter, 4) + " m spans fewer than 3 elements of region '" + g.region +
                     "' (mean element edge " + format_number(d.mean_edge, 4) + " m); give " +
                     (g.count > 0 ? "fewer grains" : "a larger size") + " or a finer mesh (mesh.size)");
  const RegionLocator region(tris, d.lo, d.hi);
  Stream s(g.seed);
  g.points.clear();
  const double gap2 = 0.25 * diameter * diameter;
  const long tries = 1000 * n + 1000;
  for (long k = 0; k < tries && long(g.points.size()) < n; ++k) {
    const Point2 p{d.lo[0] + s.uniform() * (d.hi[0] - d.lo[0]), d.lo[1] + s.uniform() * (d.hi[1] - d.lo[1])};
    if (!region.inside(p)) continue;
    bool near = false;
    for (const Point2& q : g.points)
      if ((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) < gap2) {
        near = true;
        break;
      }
    if (!near) g.points.push_back(p);
  }
  if (long(g.points.size()) < n)
    throw InputError(origin_of(config, key) + ": " + given + ": only " + std::to_string(g.points.size()) + " of " +
                     std::to_string(n) + " grain seeds could be placed in region '" + g.region +
                     "' half a mean diameter apart (a thin region: give fewer grains)");
  // Areas: the region's triangles by the seed nearest their centroid.
  std::vector<double> area(size_t(n), 0.0);
  const GrainFinder finder(g.points);
  for (const auto& q : tris) {
    const Point2 c{(q[0][0] + q[1][0] + q[2][0]) / 3, (q[0][1] + q[1][1] + q[2][1]) / 3};
    area[size_t(finder.nearest(c))] +=
        0.5 * std::fabs((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
  }
  std::vector<size_t> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  for (size_t k = order.size(); k > 1; --k) std::swap(order[k - 1], order[s.below(k)]);  // Fisher–Yates
  g.mineral.assign(size_t(n), 0);
  std::vector<double> taken(g.minerals.size(), 0.0);
  double total = 0;
  for (size_t k : order) {
    total += area[k];
    size_t best = 0;
    double deficit = -1e300;
    for (size_t m = 0; m < g.minerals.size(); ++m) {
      const double want = g.fractions[m] * total - taken[m];
      if (want > deficit) deficit = want, best = m;
    }
    g.mineral[k] = int(best);
    taken[best] += area[k];
  }
  return d;
}

namespace {
// Even–odd rule.
bool in_polygon(const std::vector<Point2>& poly, Point2 p) {
  bool in = false;
  for (size_t a = 0, b = poly.size() - 1; a < poly.size(); b = a++) {
    if ((poly[a][1] > p[1]) != (poly[b][1] > p[1]) &&
        p[0] < (poly[b][0] - poly[a][0]) * (p[1] - poly[a][1]) / (poly[b][1] - poly[a][1]) + poly[a][0])
      in = !in;
  }
  return in;
}
}  // namespace

int grain_at(const GrainFinder& finder, const std::vector<std::vector<Point2>>& cells, Point2 p) {
  const int near = finder.nearest(p);
  if (near < 0 || cells.empty() || in_polygon(cells[size_t(near)], p)) return near;
  for (size_t k = 0; k < cells.size(); ++k)
    if (int(k) != near && cells[k].size() >= 3 && in_polygon(cells[k], p)) return int(k);
  return near;
}

std::vector<JointSegment> grain_boundaries(const std::vector<Point2>& points, Point2 lo, Point2 hi, double merge,
                                           std::vector<std::vector<Point2>>* cells) {
  const double gx = 0.1 * (hi[0] - lo[0]) + 1e-9, gy = 0.1 * (hi[1] - lo[1]) + 1e-9;
  const Point2 blo{lo[0] - gx, lo[1] - gy}, bhi{hi[0] + gx, hi[1] + gy};
  const size_t n = points.size();
  // Box sides: 0 bottom (y = blo), 1 right (x = bhi), 2 top (y = bhi), 3 left (x = blo).
  auto side_point = [&](long i, long j, int side) {  // bisector of i < j meets the side
    const Point2 a = points[size_t(i)], b = points[size_t(j)];
    const Point2 m{0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])}, dir{-(b[1] - a[1]), b[0] - a[0]};
    if (side == 0 || side == 2) {
      const double y = side == 0 ? blo[1] : bhi[1];
      return Point2{m[0] + dir[0] * (y - m[1]) / dir[1], y};
    }
    const double x = side == 1 ? bhi[0] : blo[0];
    return Point2{x, m[1] + dir[1] * (x - m[0]) / dir[0]};
  };
  auto vertex = [&](const VertexKey& k) -> Point2 {
    if (k[0] < 0) {
      const int c = int(-1 - k[2]);
      return {c == 1 || c == 2 ? bhi[0] : blo[0], c >= 2 ? bhi[1] : blo[1]};
    }
    if (k[2] < 0) return side_point(k[0], k[1], int(-1 - k[2]));
    const Point2 a = points[size_t(k[0])], b = points[size_t(k[1])], c = points[size_t(k[2])];
    const double bx = b[0] - a[0], by = b[1] - a[1], cx = c[0] - a[0], cy = c[1] - a[1];
    const double dd = 2 * (bx * cy - by * cx);
    const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    return {a[0] + (cy * b2 - by * c2) / dd, a[1] + (bx * c2 - cx * b2) / dd};
  };
  // The key of the vertex between two edges of cell i labelled p and q (a seed index, or
  // -1 - side for a side of the box).
  auto key_of = [&](long i, long p, long q) -> VertexKey {
    if (p < 0 && q < 0) {
      const long s1 = -1 - p, s2 = -1 - q;  // adjacent sides s and s + 1 meet at corner s + 1
      const long corner = (std::min(s1, s2) == 0 && std::max(s1, s2) == 3) ? 0 : std::max(s1, s2);
      return {-1, -1, -1 - corner};
    }
    if (p < 0 || q < 0) {
      const long j = p < 0 ? q : p, side = p < 0 ? p : q;
      return {std::min(i, j), std::max(i, j), side};
    }
    std::array<long, 3> t{i, p, q};
    std::sort(t.begin(), t.end());
    return t;
  };
  // Each cell: the box clipped by the half-planes nearer its seed, as a cycle of edge
  // labels (edge k runs from vertex k to vertex k + 1).
  const GrainFinder finder(points);
  std::vector<size_t> by_distance(n);
  std::map<std::pair<VertexKey, VertexKey>, std::pair<long, long>> edges;  // (a, b) → the two seeds
  std::vector<std::vector<VertexKey>> cell_keys(n);
  for (size_t i = 0; i < n; ++i) {
    std::vector<Point2> poly = {blo, {bhi[0], blo[1]}, bhi, {blo[0], bhi[1]}};
    std::vector<long> label = {-1, -2, -3, -4};
    const Point2 p = points[i];
    std::iota(by_distance.begin(), by_distance.end(), 0);
    auto d2 = [&](size_t k) {
      return (points[k][0] - p[0]) * (points[k][0] - p[0]) + (points[k][1] - p[1]) * (points[k][1] - p[1]);
    };
    std::sort(by_distance.begin(), by_distance.end(), [&](size_t a, size_t b) { return d2(a) < d2(b) || (d2(a) == d2(b) && a < b); });
    for (size_t j : by_distance) {
      if (j == i) continue;
      double reach = 0;
      for (const Point2& v : poly) reach = std::max(reach, (v[0] - p[0]) * (v[0] - p[0]) + (v[1] - p[1]) * (v[1] - p[1]));
      if (d2(j) > 4 * reach) break;  // the bisector lies beyond every vertex
      const Point2 q = points[j];
      const Point2 m{0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])}, nrm{q[0] - p[0], q[1] - p[1]};
      auto side = [&](Point2 v) { return (v[0] - m[0]) * nrm[0] + (v[1] - m[1]) * nrm[1]; };  // > 0: nearer q
      std::vector<Point2> out;
      std::vector<long> out_label;
      const size_t k = poly.size();
      bool cut = false;
      for (size_t a = 0; a < k; ++a) {
        const Point2 u = poly[a], v = poly[(a + 1) % k];
        const double su = side(u), sv = side(v);
        if (su <= 0) out.push_back(u), out_label.push_back(label[a]);
        if ((su <= 0) != (sv <= 0)) {
          const double t = su / (su - sv);
          out.push_back({u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1])});
          // Entering the far side: the new vertex starts the bisector edge; leaving it: the
          // rest of edge a.
          if (su <= 0) out_label.back() = label[a], out_label.push_back(long(j));
          else out_label.push_back(label[a]);
          cut = true;
        }
        if (su > 0) cut = true;
      }
      if (!cut) continue;
      poly = std::move(out), label = std::move(out_label);
      if (poly.size() < 3) break;
    }
    const size_t k = label.size();
    for (size_t a = 0; a < k; ++a) cell_keys[i].push_back(key_of(long(i), label[(a + k - 1) % k], label[a]));
    for (size_t a = 0; a < k; ++a) {
      const long j = label[a];
      if (j < 0 || size_t(j) < i) continue;  // box sides, and each bisector once (from its lower seed)
      const VertexKey va = key_of(long(i), label[(a + k - 1) % k], j), vb = key_of(long(i), j, label[(a + 1) % k]);
      edges[{va, vb}] = {long(i), j};
    }
  }
  // Merge vertices closer than `merge` (union–find; the representative is the least key).
  std::map<VertexKey, VertexKey> parent;
  std::function<VertexKey(const VertexKey&)> root = [&](const VertexKey& k) -> VertexKey {
    auto it = parent.find(k);
    if (it == parent.end() || it->second == k) return k;
    return it->second = root(it->second);
  };
  for (const auto& [ends, seeds] : edges) {
    const Point2 a = vertex(ends.first), b = vertex(ends.second);
    if (std::hypot(b[0] - a[0], b[1] - a[1]) < merge) {
      const VertexKey ra = root(ends.first), rb = root(ends.second);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  if (cells) {
    cells->assign(n, {});
    for (size_t i = 0; i < n; ++i) {
      std::vector<VertexKey> roots;
      for (const VertexKey& k : cell_keys[i]) {
        const VertexKey r = root(k);
        if (roots.empty() || roots.back() != r) roots.push_back(r);
      }
      while (roots.size() > 1 && roots.front() == roots.back()) roots.pop_back();
      for (const VertexKey& r : roots) (*cells)[i].push_back(vertex(r));
    }
  }
  std::vector<JointSegment> out;
  std::set<std::pair<VertexKey, VertexKey>> seen;
  for (const auto& [ends, seeds] : edges) {
    const VertexKey ra = root(ends.first), rb = root(ends.second);
    if (ra == rb || !seen.insert({std::min(ra, rb), std::max(ra, rb)}).second) continue;
    out.push_back({-1, vertex(ra), vertex(rb), ""});
  }
  return out;
}

}  // namespace fdem::io
