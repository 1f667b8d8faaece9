#include "io/joint_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "base/errors.hpp"

namespace fdem::io {

namespace {

const double kPi = std::acos(-1.0);

// splitmix64 (as io/mesh_perturb.cpp): integer arithmetic only, the same on every machine.
std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Uniform draws in [0, 1) from one stream: the seed, then a counter.
class Stream {
 public:
  explicit Stream(std::uint64_t seed) : state_(splitmix64(seed ^ 0x6a6f696e74736574ULL)) {}
  double uniform() {
    state_ = splitmix64(state_);
    return double(state_ >> 11) * 0x1.0p-53;
  }
  // Open (0, 1]: for logarithms.
  double positive() { return 1.0 - uniform(); }

 private:
  std::uint64_t state_;
};

// A von Mises angle of concentration κ about 0 (Best and Fisher's rejection method).
double von_mises(Stream& s, double kappa) {
  if (kappa < 1e-8) return kPi * (2 * s.uniform() - 1);
  const double tau = 1 + std::sqrt(1 + 4 * kappa * kappa);
  const double rho = (tau - std::sqrt(2 * tau)) / (2 * kappa);
  const double r = (1 + rho * rho) / (2 * rho);
  for (;;) {
    const double z = std::cos(kPi * s.uniform());
    const double f = (1 + r * z) / (r + z);
    const double c = kappa * (r - f);
    const double u2 = s.positive();
    if (c * (2 - c) - u2 > 0 || std::log(c / u2) + 1 - c >= 0) {
      const double theta = std::acos(std::clamp(f, -1.0, 1.0));
      return s.uniform() < 0.5 ? -theta : theta;
    }
  }
}

std::string trim(const std::string& text) {
  const size_t a = text.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = text.find_last_not_of(" \t\r");
  return text.substr(a, b - a + 1);
}

double cross(Point2 o, Point2 a, Point2 b) { return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]); }

// Distance from p to segment ab.
double segment_distance(Point2 p, Point2 a, Point2 b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

// The base mesh in metres with a grid over its triangles and its boundary edges (edges of
// one triangle, or between two surface entities): which entity holds a point, and how
// far the nearest boundary is.
class Locator {
 public:
  Locator(const Mesh& mesh, double scale) : mesh_(mesh), scale_(scale) {
    if (mesh.triangle_entity.size() != mesh.triangles.size())
      throw InputError(mesh.source + ": the mesh has no surface entities to embed joints in");
    lo_ = {1e300, 1e300}, hi_ = {-1e300, -1e300};
    for (size_t n = 0; n < mesh.x.size(); ++n) {
      lo_ = {std::min(lo_[0], mesh.x[n] * scale), std::min(lo_[1], mesh.y[n] * scale)};
      hi_ = {std::max(hi_[0], mesh.x[n] * scale), std::max(hi_[1], mesh.y[n] * scale)};
    }
    double sum = 0;
    edge_.resize(mesh.triangles.size());
    std::map<std::pair<int, int>, std::vector<int>> sides;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      double s = 0;
      for (int k = 0; k < 3; ++k) {
        const int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
        s += std::hypot(mesh.x[b] - mesh.x[a], mesh.y[b] - mesh.y[a]) * scale;
        sides[{std::min(a, b), std::max(a, b)}].push_back(int(t));
      }
      edge_[t] = s / 3;
      sum += s / 3;
    }
    mean_edge_ = sum / double(std::max<size_t>(1, mesh.triangles.size()));
    cell_ = std::max(mean_edge_, 1e-300);
    nx_ = std::max(1, int(std::ceil((hi_[0] - lo_[0]) / cell_)) + 1);
    ny_ = std::max(1, int(std::ceil((hi_[1] - lo_[1]) / cell_)) + 1);
    // A coarse grid when the region is long and thin beyond 4M cells.
    while (double(nx_) * ny_ > 4e6) {
      cell_ *= 2;
      nx_ = int(std::ceil((hi_[0] - lo_[0]) / cell_)) + 1;
      ny_ = int(std::ceil((hi_[1] - lo_[1]) / cell_)) + 1;
    }
    triangles_.resize(size_t(nx_) * ny_);
    boundary_.resize(size_t(nx_) * ny_);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      Point2 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
      add_box(triangles_, {std::min({a[0], b[0], c[0]}), std::min({a[1], b[1], c[1]})},
              {std::max({a[0], b[0], c[0]}), std::max({a[1], b[1], c[1]})}, int(t));
    }
    for (const auto& [key, ts] : sides) {
      const bool inner = ts.size() == 2 && mesh.triangle_entity[ts[0]] == mesh.triangle_entity[ts[1]];
      if (inner) continue;
      edges_.push_back({point(key.first), point(key.second)});
      const auto& e = edges_.back();
      add_box(boundary_, {std::min(e[0][0], e[1][0]), std::min(e[0][1], e[1][1])},
              {std::max(e[0][0], e[1][0]), std::max(e[0][1], e[1][1])}, int(edges_.size() - 1));
    }
  }

  Point2 lo() const { return lo_; }
  Point2 hi() const { return hi_; }
  double mean_edge() const { return mean_edge_; }

  // The triangle holding p, or -1.
  int triangle_at(Point2 p) const {
    const int i = cell_x(p[0]), j = cell_y(p[1]);
    if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return -1;
    for (int t : triangles_[size_t(j) * nx_ + i]) {
      const Point2 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
      const double area = cross(a, b, c), tol = -1e-12 * std::fabs(area);
      if (cross(a, b, p) * (area > 0 ? 1 : -1) >= tol && cross(b, c, p) * (area > 0 ? 1 : -1) >= tol &&
          cross(c, a, p) * (area > 0 ? 1 : -1) >= tol)
        return t;
    }
    return -1;
  }
  int entity(int t) const { return mesh_.triangle_entity[t]; }
  double local_edge(int t) const { return edge_[t]; }

  // Whether a boundary edge lies within `r` of p.
  bool near_boundary(Point2 p, double r) const {
    const int i0 = cell_x(p[0] - r), i1 = cell_x(p[0] + r), j0 = cell_y(p[1] - r), j1 = cell_y(p[1] + r);
    for (int j = std::max(0, j0); j <= std::min(ny_ - 1, j1); ++j)
      for (int i = std::max(0, i0); i <= std::min(nx_ - 1, i1); ++i)
        for (int e : boundary_[size_t(j) * nx_ + i])
          if (segment_distance(p, edges_[e][0], edges_[e][1]) < r) return true;
    return false;
  }

 private:
  Point2 point(int n) const { return {mesh_.x[n] * scale_, mesh_.y[n] * scale_}; }
  Point2 corner(size_t t, int k) const { return point(mesh_.triangles[t][k]); }
  int cell_x(double x) const { return int(std::floor((x - lo_[0]) / cell_)); }
  int cell_y(double y) const { return int(std::floor((y - lo_[1]) / cell_)); }
  void add_box(std::vector<std::vector<int>>& grid, Point2 a, Point2 b, int item) {
    for (int j = std::max(0, cell_y(a[1])); j <= std::min(ny_ - 1, cell_y(b[1])); ++j)
      for (int i = std::max(0, cell_x(a[0])); i <= std::min(nx_ - 1, cell_x(b[0])); ++i)
        grid[size_t(j) * nx_ + i].push_back(item);
  }

  const Mesh& mesh_;
  double scale_;
  Point2 lo_, hi_;
  double mean_edge_ = 0, cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<double> edge_;
  std::vector<std::vector<int>> triangles_, boundary_;
  std::vector<std::array<Point2, 2>> edges_;
};

// A piece of a segment inside one surface entity.
struct Piece {
  int joint = 0, entity = 0;
  Point2 a{}, b{};
  double lc = 0;                // local element size [m]
  std::vector<double> cuts;     // parameters in (0, 1) of crossings with other pieces
  std::vector<Point2> at;       // the crossing points (the same doubles for both pieces)
};

std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

}  // namespace

std::string embedded_joint_curve(int joint) { return "fdem_joint_" + std::to_string(joint); }

std::vector<JointSegment> read_polylines(const std::string& path, int joint) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the joint file");
  std::vector<JointSegment> out;
  std::string line;
  int number_of_line = 0, points = 0;
  Point2 last{};
  int polyline_line = 0;
  auto close = [&]() {
    if (points == 1)
      throw InputError(path + ":" + std::to_string(polyline_line) + ": a polyline of one point (a joint needs at "
                                                                    "least two; a blank line separates polylines)");
    points = 0;
  };
  while (std::getline(in, line)) {
    ++number_of_line;
    const size_t hash = line.find('#');
    const std::string text = trim(hash == std::string::npos ? line : line.substr(0, hash));
    if (text.empty()) {
      if (hash == std::string::npos) close();  // a blank line ends the polyline; a comment line does not
      continue;
    }
    std::istringstream fields(text);
    double x = 0, y = 0;
    std::string extra;
    if (!(fields >> x >> y) || (fields >> extra) || !std::isfinite(x) || !std::isfinite(y))
      throw InputError(path + ":" + std::to_string(number_of_line) + ": expected a point \"x y\" (two numbers, in m), found \"" +
                       text + "\"");
    const Point2 p{x, y};
    if (points == 0) polyline_line = number_of_line;
    if (points > 0) {
      if (p == last)
        throw InputError(path + ":" + std::to_string(number_of_line) + ": the point repeats the one before it (a joint "
                                                                        "segment of zero length)");
      out.push_back({joint, last, p, path + ":" + std::to_string(number_of_line)});
    }
    last = p;
    ++points;
  }
  close();
  if (out.empty()) throw InputError(path + ": no polyline (points \"x y\" in m, one a line, a blank line between polylines)");
  return out;
}

JointSetDraw draw_joint_set(const JointSetConfig& set, Point2 lo, Point2 hi, int joint) {
  JointSetDraw draw;
  Stream s(set.seed);
  const double theta = set.angle * kPi / 180;
  const Point2 d{std::cos(theta), std::sin(theta)}, n{-d[1], d[0]};
  const Point2 c{0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])};
  const double reach = 0.5 * std::hypot(hi[0] - lo[0], hi[1] - lo[1]) + set.trace_length;
  const double p = set.persistence, period = set.trace_length / p;
  // At most 10^6 traces: a spacing or trace length far below the region's size is refused
  // by the caller before this (embed_joints' count); here it only bounds the loops.
  for (double offset = -reach + set.spacing * -std::log(s.positive()); offset <= reach;
       offset += set.spacing * -std::log(s.positive())) {
    draw.offsets.push_back(offset);
    const Point2 base{c[0] + offset * n[0], c[1] + offset * n[1]};
    auto add = [&](double t0, double length) {
      const double turn = von_mises(s, set.kappa) + theta;
      const Point2 mid{base[0] + (t0 + 0.5 * length) * d[0], base[1] + (t0 + 0.5 * length) * d[1]};
      const Point2 e{std::cos(turn), std::sin(turn)};
      draw.traces.push_back({joint, {mid[0] - 0.5 * length * e[0], mid[1] - 0.5 * length * e[1]},
                             {mid[0] + 0.5 * length * e[0], mid[1] + 0.5 * length * e[1]}, ""});
      double degrees = turn * 180 / kPi;
      draw.angles.push_back(degrees);
    };
    if (p >= 1) {
      add(-reach, 2 * reach);
    } else {
      for (double t = -reach - period * s.uniform(); t <= reach && draw.traces.size() <= 1000000; t += period)
        add(t, set.trace_length);
    }
    if (draw.traces.size() > 1000000) break;
  }
  return draw;
}

JointEmbedding embed_joints(const Mesh& base, double scale, const std::vector<JointSegment>& segments, int joints,
                            const std::vector<int>& grain_entities) {
  JointEmbedding out;
  out.pieces.assign(joints, 0);
  out.length.assign(joints, 0.0);
  const Locator where(base, scale);
  std::vector<Piece> pieces;
  // 1. Clip: sample each segment at a quarter of the mean edge; keep the runs of samples
  // inside one entity and at least half the local edge off every boundary.
  for (const JointSegment& seg : segments) {
    const double length = std::hypot(seg.b[0] - seg.a[0], seg.b[1] - seg.a[1]);
    const long samples = std::clamp<long>(long(std::ceil(4 * length / where.mean_edge())), 1, 1000000);
    int run_entity = -1;
    double run_start = 0, run_end = 0, run_lc = 0;
    bool any = false;
    auto finish = [&]() {
      if (run_entity >= 0 && run_end > run_start) {
        // The segment's own ends exactly (a polyline's segments share their vertices).
        const Point2 a = run_start == 0 ? seg.a : Point2{seg.a[0] + run_start * (seg.b[0] - seg.a[0]),
                                                         seg.a[1] + run_start * (seg.b[1] - seg.a[1])};
        const Point2 b = run_end == 1 ? seg.b : Point2{seg.a[0] + run_end * (seg.b[0] - seg.a[0]),
                                                       seg.a[1] + run_end * (seg.b[1] - seg.a[1])};
        pieces.push_back({seg.joint, run_entity, a, b, run_lc, {}, {}});
        any = true;
      }
      run_entity = -1;
    };
    for (long k = 0; k <= samples; ++k) {
      const double t = double(k) / double(samples);
      const Point2 p{seg.a[0] + t * (seg.b[0] - seg.a[0]), seg.a[1] + t * (seg.b[1] - seg.a[1])};
      const int tri = where.triangle_at(p);
      // Grain boundaries keep a whole element off (a half leaves slivers where they end).
      const bool inside = tri >= 0 && !where.near_boundary(p, (seg.joint < 0 ? 1.0 : 0.5) * where.local_edge(tri));
      int entity = inside ? where.entity(tri) : -1;
      if (seg.joint < 0 && std::find(grain_entities.begin(), grain_entities.end(), entity) == grain_entities.end())
        entity = -1;  // a grain boundary outside the grains' region
      if (entity != run_entity) {
        finish();
        if (entity >= 0) run_entity = entity, run_start = t, run_lc = where.local_edge(tri);
      }
      if (entity >= 0) run_end = t, run_lc = std::min(run_lc, where.local_edge(tri));
    }
    finish();
    if (!any && !seg.origin.empty())
      throw InputError(seg.origin + ": the joint segment from (" + number(seg.a[0]) + ", " + number(seg.a[1]) + ") to (" +
                       number(seg.b[0]) + ", " + number(seg.b[1]) + ") m lies outside the meshed region " + base.source +
                       " (or within half an element of its boundary), which spans x " + number(where.lo()[0]) + " to " +
                       number(where.hi()[0]) + ", y " + number(where.lo()[1]) + " to " + number(where.hi()[1]) + " m");
  }
  if (pieces.size() > 200000)
    throw InputError("[[joint]]: " + std::to_string(pieces.size()) + " joint pieces inside the region, more than the "
                     "200,000 fdem embeds (a larger spacing or trace length)");
  // 2. Crossings within one entity: both pieces split at the same point.
  for (size_t i = 0; i < pieces.size(); ++i)
    for (size_t j = i + 1; j < pieces.size(); ++j) {
      Piece &p = pieces[i], &q = pieces[j];
      if (p.entity != q.entity) continue;
      const double rx = p.b[0] - p.a[0], ry = p.b[1] - p.a[1], sx = q.b[0] - q.a[0], sy = q.b[1] - q.a[1];
      const double denominator = rx * sy - ry * sx;
      if (std::fabs(denominator) < 1e-14 * std::hypot(rx, ry) * std::hypot(sx, sy)) continue;  // parallel
      const double qx = q.a[0] - p.a[0], qy = q.a[1] - p.a[1];
      const double t = (qx * sy - qy * sx) / denominator, u = (qx * ry - qy * rx) / denominator;
      const double eps = 1e-9;
      if (t < -eps || t > 1 + eps || u < -eps || u > 1 + eps) continue;
      const bool p_end = t < eps || t > 1 - eps, q_end = u < eps || u > 1 - eps;
      if (p_end && q_end) continue;  // two ends meet (a polyline's vertex): shared already
      // A T: the end of one piece on the other; that end is the shared point, exactly.
      const Point2 x = p_end ? (t < eps ? p.a : p.b) : q_end ? (u < eps ? q.a : q.b) : Point2{p.a[0] + t * rx, p.a[1] + t * ry};
      if (!p_end) p.cuts.push_back(t), p.at.push_back(x);
      if (!q_end) q.cuts.push_back(u), q.at.push_back(x);
    }
  // 3. The .geo text: points shared by their exact coordinates (polyline vertices and
  // crossings), lines, their embedding and their physical curves.
  std::map<Point2, int> point_index;
  std::vector<std::pair<Point2, double>> points;
  auto point_of = [&](Point2 p, double lc) {
    auto [it, fresh] = point_index.emplace(p, int(points.size()));
    if (fresh) points.push_back({p, lc});
    else points[it->second].second = std::min(points[it->second].second, lc);
    return it->second;
  };
  struct Line {
    int a, b, joint, entity;
  };
  std::vector<Line> lines;
  for (Piece& p : pieces) {
    std::vector<std::pair<double, Point2>> stops = {{0.0, p.a}, {1.0, p.b}};
    for (size_t k = 0; k < p.cuts.size(); ++k) stops.push_back({p.cuts[k], p.at[k]});
    std::sort(stops.begin(), stops.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    const double length = std::hypot(p.b[0] - p.a[0], p.b[1] - p.a[1]);
    for (size_t k = 0; k + 1 < stops.size(); ++k) {
      const double piece = (stops[k + 1].first - stops[k].first) * length;
      // A dangling end shorter than a tenth of an element past a crossing is dropped (it
      // would only force tiny elements); pieces between crossings stay.
      const bool end = k == 0 || k + 2 == stops.size();
      if (piece <= 1e-12 * length || (end && stops.size() > 2 && piece < 0.1 * p.lc)) continue;
      const int a = point_of(stops[k].second, p.lc), b = point_of(stops[k + 1].second, p.lc);
      if (a == b) continue;
      lines.push_back({a, b, p.joint, p.entity});
      if (p.joint < 0) {
        out.grain_pieces += 1, out.grain_length += piece;
      } else {
        out.pieces[p.joint] += 1;
        out.length[p.joint] += piece;
      }
    }
  }
  if (lines.empty()) return out;
  std::ostringstream geo;
  const bool any_joint = std::any_of(lines.begin(), lines.end(), [](const Line& l) { return l.joint >= 0; });
  const bool any_grain = std::any_of(lines.begin(), lines.end(), [](const Line& l) { return l.joint < 0; });
  geo << (any_joint && any_grain ? "// fdem: the [[joint]] files and sets and the [grains] boundaries, embedded (io/joint_geometry.cpp)\n"
          : any_joint            ? "// fdem: the [[joint]] files and sets, embedded (io/joint_geometry.cpp)\n"
                                 : "// fdem: the [grains] boundaries, embedded (io/joint_geometry.cpp)\n");
  geo << "fdem_jp = newp;\n";
  for (size_t k = 0; k < points.size(); ++k)
    geo << "Point(fdem_jp + " << k << ") = {" << number(points[k].first[0] / scale) << ", "
        << number(points[k].first[1] / scale) << ", 0, " << number(points[k].second / scale) << "};\n";
  geo << "fdem_jl = newl;\n";
  for (size_t k = 0; k < lines.size(); ++k)
    geo << "Line(fdem_jl + " << k << ") = {fdem_jp + " << lines[k].a << ", fdem_jp + " << lines[k].b << "};\n";
  std::map<int, std::vector<size_t>> by_entity, by_joint;
  for (size_t k = 0; k < lines.size(); ++k) {
    by_entity[lines[k].entity].push_back(k);
    if (lines[k].joint >= 0) by_joint[lines[k].joint].push_back(k);
  }
  auto list = [&](const std::vector<size_t>& ks) {
    std::string text;
    for (size_t k : ks) text += (text.empty() ? "fdem_jl + " : ", fdem_jl + ") + std::to_string(k);
    return text;
  };
  for (const auto& [entity, ks] : by_entity) geo << "Curve{" << list(ks) << "} In Surface{" << entity << "};\n";
  for (const auto& [joint, ks] : by_joint)
    geo << "Physical Curve(\"" << embedded_joint_curve(joint) << "\") = {" << list(ks) << "};\n";
  out.geo = geo.str();
  return out;
}

}  // namespace fdem::io
