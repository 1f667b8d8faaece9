// Dynamic boundary loads: the boundary-load stage against the plain C++ reference for
// every load kind, the blast pressure of Eq. 21, and stress waves in a laterally
// constrained strip (plane P waves): reflection at an absorbing and at a free end, and
// the wave speed against √((λ+2μ)/ρ).
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "approx.hpp"
#include "engine/solver.hpp"
#include "engine/stages/boundary_loads.hpp"
#include "fixture.hpp"
#include "reference.hpp"

using namespace fdem;
using reference::Matrix2d;
using reference::Vector2d;

namespace {

constexpr double kRel = kDoublePrecision ? 1e-12 : 1e-5;

// Plain reference of one loaded edge: the forces on its nodes a and b.
struct EdgeForces {
  Vector2d a, b;
};

// Impedance (ρΓ)^½ through an eigen-decomposition of the acoustic tensor built index by
// index from the 4th-order stiffness (independent of the kernel's closed form).
Matrix2d reference_impedance(const MaterialConstants& m, const Vector2d& n) {
  Matrix2d gamma = Matrix2d::Zero();
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int l = 0; l < 2; ++l) gamma(i, k) += reference::stiffness_tensor(m.c, i, j, k, l) * n(j) * n(l);
  Eigen::SelfAdjointEigenSolver<Matrix2d> eig(m.density * gamma);
  return eig.eigenvectors() * eig.eigenvalues().cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
}

// Eq. 21 with α found by bisection on t₀(α) = ln r / (α (r − 1)) (not the closed form).
double reference_blast(double peak, double rise, double ratio, double t) {
  double lo = 1e-9 / rise, hi = 1e9 / rise;
  for (int k = 0; k < 200; ++k) {
    const double mid = std::sqrt(lo * hi);
    const double t0 = std::log(ratio) / (ratio * mid - mid);
    (t0 > rise ? lo : hi) = mid;
  }
  const double alpha = std::sqrt(lo * hi), beta = ratio * alpha;
  auto shape = [&](double s) { return std::exp(-alpha * s) - std::exp(-beta * s); };
  return peak * shape(t) / shape(rise);
}

double reference_table(const EdgeLoad& l, double t) {
  if (t <= l.times.front()) return l.values.front();
  if (t >= l.times.back()) return l.values.back();
  const size_t k = std::upper_bound(l.times.begin(), l.times.end(), t) - l.times.begin();
  const double w = (t - l.times[k - 1]) / (l.times[k] - l.times[k - 1]);
  return (1 - w) * l.values[k - 1] + w * l.values[k];
}

EdgeForces reference_edge(const Model& m, const LoadedEdge& e, const std::vector<real2>& pos,
                          const std::vector<real2>& vel, double t) {
  const EdgeLoad& l = m.loads[e.load];
  const Vector2d xa(pos[e.a].x, pos[e.a].y), xb(pos[e.b].x, pos[e.b].y);
  const Vector2d d = xb - xa;
  const Vector2d outward = Vector2d(d.y(), -d.x()).normalized();
  const double L = d.norm(), th = m.thickness;
  if (l.kind == LoadKind::Absorbing) {
    const Matrix2d Z = reference_impedance(m.materials[l.material], outward);
    const Vector2d va(vel[e.a].x, vel[e.a].y), vb(vel[e.b].x, vel[e.b].y);
    return {-0.5 * L * th * Z * va, -0.5 * L * th * Z * vb};
  }
  Vector2d f;
  if (l.kind == LoadKind::Traction) {
    const double L0 = std::hypot(m.x[e.b] - m.x[e.a], m.y[e.b] - m.y[e.a]);
    const double ramp = l.rise > 0 ? std::min(1.0, t / l.rise) : 1.0;
    f = ramp * L0 * th * Vector2d(l.tx, l.ty);
  } else {
    double p = 0;
    if (l.kind == LoadKind::Pressure) p = l.pressure * (l.rise > 0 ? std::min(1.0, t / l.rise) : 1.0);
    if (l.kind == LoadKind::Blast) p = reference_blast(l.pressure, l.rise, l.ratio, t);
    if (l.kind == LoadKind::Table) p = reference_table(l, t);
    f = -p * L * th * outward;
  }
  return {0.5 * f, 0.5 * f};
}

std::vector<real2> edge_forces(Model& m, const std::vector<real2>& pos, const std::vector<real2>& vel, double t) {
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  upload(cl, arrays.position, pos);
  upload(cl, arrays.velocity, vel);
  BoundaryLoads stage(cl, arrays, m.thickness, 1e-6);
  stage.enqueue(t, 0);
  return download<real2>(cl, arrays.edge_force, 2 * m.loaded_edges.size());
}

// A regular polygon of `sides` around a centre node (a fan), radius r.
Model fan(int sides, double r, double first_angle = 0.0, double last_angle = 2 * M_PI) {
  const bool closed = std::fabs(last_angle - first_angle - 2 * M_PI) < 1e-12;
  std::vector<double> x{0.0}, y{0.0};
  const int rim = closed ? sides : sides + 1;
  for (int k = 0; k < rim; ++k) {
    const double a = first_angle + (last_angle - first_angle) * k / sides;
    x.push_back(r * std::cos(a)), y.push_back(r * std::sin(a));
  }
  std::vector<std::array<int, 3>> tris;
  for (int k = 0; k < sides; ++k) tris.push_back({0, 1 + k, 1 + (k + 1) % rim});
  return test::make_model(x, y, tris, {test::all_material_variants()[0]});
}

// A laterally constrained strip [0, length] × [0, height] of right triangles of side h:
// rollers (vy = 0) on the top and bottom, so that a load on the left end sends a plane
// P wave along x. E 60 GPa, ν 0.25, ρ 2880 kg/m³ in plane strain: V_p = 5000 m/s.
struct Strip {
  Model model;
  int nx = 0, ny = 0;
  double h = 0;
  std::vector<int> end_edges[2];  // boundary edges (body on the left) at x = 0 and x = length
};

Strip strip(double length, double height, double h) {
  Strip s;
  s.h = h;
  s.nx = static_cast<int>(std::lround(length / h));
  s.ny = static_cast<int>(std::lround(height / h));
  std::vector<double> x, y;
  for (int i = 0; i <= s.nx; ++i)
    for (int j = 0; j <= s.ny; ++j) x.push_back(i * h), y.push_back(j * h);
  auto node = [&](int i, int j) { return i * (s.ny + 1) + j; };
  std::vector<std::array<int, 3>> tris;
  for (int i = 0; i < s.nx; ++i)
    for (int j = 0; j < s.ny; ++j) {
      tris.push_back({node(i, j), node(i + 1, j), node(i + 1, j + 1)});
      tris.push_back({node(i, j), node(i + 1, j + 1), node(i, j + 1)});
    }
  io::MaterialConfig rock = test::material_config("rock", io::Elasticity::NeoHookean, io::Plane::Strain);
  rock.young = 60e9, rock.poisson = 0.25, rock.density = 2880;
  s.model = test::make_model(x, y, tris, {rock}, 1.0);
  s.model.groups.push_back({2u, 0.0, 0.0, 0.0});  // vy = 0
  for (int i = 0; i <= s.nx; ++i) s.model.node_group[node(i, 0)] = s.model.node_group[node(i, s.ny)] = 1;
  // Boundary edges of the ends, in their triangle's counter-clockwise order.
  for (const auto& t : s.model.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      for (int end = 0; end < 2; ++end) {
        const double xe = end * s.nx * h;
        if (std::fabs(x[a] - xe) < 1e-9 && std::fabs(x[b] - xe) < 1e-9) {
          s.end_edges[end].push_back(static_cast<int>(s.model.loaded_edges.size()));
          s.model.loaded_edges.push_back({a, b, -1});  // no load yet: load_end or drop_unloaded
        }
      }
    }
  return s;
}

// Attaches load `load` to the edges of one end of the strip.
void load_end(Strip& s, int end, EdgeLoad load) {
  const int index = static_cast<int>(s.model.loads.size());
  s.model.loads.push_back(std::move(load));
  for (int e : s.end_edges[end]) s.model.loaded_edges[e].load = index;
}

// Drops end edges that carry no load.
void drop_unloaded(Model& m) {
  m.loaded_edges.erase(std::remove_if(m.loaded_edges.begin(), m.loaded_edges.end(), [](const LoadedEdge& e) { return e.load < 0; }),
                       m.loaded_edges.end());
}

double wave_speed(const Model& m) {
  const auto& mat = m.materials[0];
  return std::sqrt((mat.lambda + 2 * mat.mu) / mat.density);
}

// Mean σxx over the triangles whose centroid lies within h/2 of x = probe, each step
// until `end`: a Hann pressure pulse (duration `pulse`, peak 1 MPa, given as a pressure
// table) on the left end; the right end absorbing or free.
std::vector<std::pair<double, double>> probe_stress(bool absorbing, double length, double probe, double pulse, double end) {
  Strip s = strip(length, 0.05, 0.01);
  EdgeLoad pressure;
  pressure.kind = LoadKind::Table;
  for (int k = 0; k <= 40; ++k) {
    const double t = pulse * k / 40.0;
    pressure.times.push_back(t);
    pressure.values.push_back(1.0e6 * std::pow(std::sin(M_PI * t / pulse), 2));
  }
  load_end(s, 0, pressure);
  if (absorbing) {
    EdgeLoad dashpot;
    dashpot.kind = LoadKind::Absorbing;
    dashpot.material = 0;
    load_end(s, 1, dashpot);
  }
  drop_unloaded(s.model);
  std::vector<int> probes;
  for (size_t t = 0; t < s.model.num_triangles(); ++t) {
    const auto& tri = s.model.triangles[t];
    const double xc = (s.model.x[tri[0]] + s.model.x[tri[1]] + s.model.x[tri[2]]) / 3;
    if (std::fabs(xc - probe) < 0.5 * s.h) probes.push_back(static_cast<int>(t));
  }
  REQUIRE(!probes.empty());
  const double dt = 0.5 * stable_time_step(s.model).dt;
  Solver solver(test::context(), s.model, dt);
  std::vector<std::pair<double, double>> history;
  while (solver.time() < end) {
    solver.step();
    solver.enqueue_stress();
    const auto stress = solver.stresses();
    double sum = 0;
    for (int t : probes) sum += stress[t].x;
    history.push_back({solver.time(), sum / probes.size()});
  }
  REQUIRE(solver.conditions().ok());
  return history;
}

// Largest |σ| before and after `split`, with their signs.
std::pair<double, double> incident_and_reflected(const std::vector<std::pair<double, double>>& h, double split) {
  double incident = 0, reflected = 0;
  for (const auto& [t, s] : h) {
    double& slot = t < split ? incident : reflected;
    if (std::fabs(s) > std::fabs(slot)) slot = s;
  }
  return {incident, reflected};
}

}  // namespace

TEST_SUITE("waves") {

TEST_CASE("boundary loads of every kind match the reference, absorbing edges on every constitutive model") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Model m = test::triangle_soup(40, test::all_material_variants(), rng);
  const EdgeLoad traction = EdgeLoad::make(LoadKind::Traction, 2e5, -1e5, 0, 3e-4);
  const EdgeLoad pressure = EdgeLoad::make(LoadKind::Pressure, 0, 0, 3e6, 2e-4);
  const EdgeLoad blast = EdgeLoad::make(LoadKind::Blast, 0, 0, 1e9, 1e-4, 1.5);
  EdgeLoad table;
  table.kind = LoadKind::Table;
  table.times = {0.0, 1e-4, 2.5e-4, 4e-4};
  table.values = {0.0, 2e6, -1e6, 5e5};
  m.loads = {traction, pressure, blast, table};
  for (int mat = 0; mat < static_cast<int>(m.materials.size()); ++mat) {
    EdgeLoad absorbing;
    absorbing.kind = LoadKind::Absorbing;
    absorbing.material = mat;
    m.loads.push_back(absorbing);
  }
  // Every triangle edge, loaded in turn by each kind (the soup's edges are all boundary).
  for (size_t t = 0; t < m.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3];
      const int kind = static_cast<int>((3 * t + k) % 5);
      const int load = kind < 4 ? kind : 4 + m.triangle_material[t];
      m.loaded_edges.push_back({a, b, load});
    }
  std::vector<real2> pos(m.num_nodes()), vel(m.num_nodes());
  for (size_t i = 0; i < m.num_nodes(); ++i) {
    pos[i] = {real(1.1 * m.x[i] + 0.05 * u(rng)), real(0.9 * m.y[i] + 0.05 * u(rng))};
    vel[i] = {real(3 * u(rng)), real(3 * u(rng))};
  }
  for (double t : {0.0, 0.7e-4, 1e-4, 1.8e-4, 3.1e-4, 6e-4}) {
    CAPTURE(t);
    const auto f = edge_forces(m, pos, vel, t);
    double worst = 0;
    for (size_t e = 0; e < m.loaded_edges.size(); ++e) {
      const EdgeForces r = reference_edge(m, m.loaded_edges[e], pos, vel, t);
      const double scale = std::max({r.a.norm(), r.b.norm(), 1e-30});
      worst = std::max(worst, (Vector2d(f[2 * e].x, f[2 * e].y) - r.a).norm() / scale);
      worst = std::max(worst, (Vector2d(f[2 * e + 1].x, f[2 * e + 1].y) - r.b).norm() / scale);
    }
    CHECK(worst < (kDoublePrecision ? 1e-10 : 1e-5));  // the bisection's α limits the blast to ~1e-13
  }
}

TEST_CASE("absorbing impedance of an isotropic material: ρV_p on the normal, ρV_s on the tangent, plane strain and stress") {
  for (io::Plane plane : {io::Plane::Strain, io::Plane::Stress}) {
    io::MaterialConfig c = test::material_config("m", io::Elasticity::NeoHookean, plane);
    const double E = c.young, nu = c.poisson, rho = c.density;
    const double vp2 = plane == io::Plane::Strain ? E * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * rho) : E / ((1 - nu * nu) * rho);
    const double vs2 = E / (2 * (1 + nu) * rho);
    // One edge of a triangle, at 30 degrees, both nodes moving with v.
    const double a = M_PI / 6;
    Model m = test::make_model({0.0, std::cos(a), -0.5}, {0.0, std::sin(a), 0.5}, {{0, 1, 2}}, {c}, 0.5);
    EdgeLoad absorbing;
    absorbing.kind = LoadKind::Absorbing;
    absorbing.material = 0;
    m.loads.push_back(absorbing);
    m.loaded_edges.push_back({0, 1, 0});
    const Vector2d n(std::sin(a), -std::cos(a)), s(std::cos(a), std::sin(a));
    const std::vector<real2> pos{{0, 0}, {real(std::cos(a)), real(std::sin(a))}, {-0.5, 0.5}};
    const std::vector<real2> vel{{real(2 * n.x() + 3 * s.x()), real(2 * n.y() + 3 * s.y())},
                                 {real(2 * n.x() + 3 * s.x()), real(2 * n.y() + 3 * s.y())}, {0, 0}};
    const auto f = edge_forces(m, pos, vel, 0.0);
    const Vector2d total(f[0].x + f[1].x, f[0].y + f[1].y);
    // Traction −ρV_p v_n n − ρV_s v_s s over a unit edge of thickness 0.5.
    CHECK(total.dot(n) == doctest::Approx(-rho * std::sqrt(vp2) * 2 * 0.5).epsilon(kRel * 10));
    CHECK(total.dot(s) == doctest::Approx(-rho * std::sqrt(vs2) * 3 * 0.5).epsilon(kRel * 10));
  }
}

TEST_CASE("blast pressure: zero net force on a full hole, 2·P·r·t on a half hole, Eq. 21 peaks at t₀ with P₀") {
  const double peak = 1e9, rise = 100e-6, ratio = 1.5, r = 0.05;
  const BlastPulse pulse = blast_pulse(peak, rise, ratio);
  CHECK(std::log(pulse.beta / pulse.alpha) / (pulse.beta - pulse.alpha) == test::rel(rise, 1e-12));
  CHECK(pulse.beta / pulse.alpha == doctest::Approx(ratio).epsilon(1e-14));
  // The hole is a fan's rim with its edges reversed: the body is outside, so the
  // pressure pushes away from the centre, into the rock.
  auto hole_force = [&](Model m, double t, double* largest_edge_ratio) {
    m.loads.push_back(EdgeLoad::make(LoadKind::Blast, 0, 0, peak, rise, ratio));
    for (const auto& tri : m.triangles) m.loaded_edges.push_back({tri[2], tri[1], 0});
    std::vector<real2> pos(m.num_nodes()), vel(m.num_nodes(), real2{0, 0});
    for (size_t i = 0; i < m.num_nodes(); ++i) pos[i] = {real(m.x[i]), real(m.y[i])};
    const auto f = edge_forces(m, pos, vel, t);
    Vector2d total = Vector2d::Zero();
    for (size_t e = 0; e < m.loaded_edges.size(); ++e) {
      const Vector2d fe(f[2 * e].x + f[2 * e + 1].x, f[2 * e].y + f[2 * e + 1].y);
      total += fe;
      const auto& le = m.loaded_edges[e];
      const Vector2d mid(0.5 * (m.x[le.a] + m.x[le.b]), 0.5 * (m.y[le.a] + m.y[le.b]));
      CHECK(mid.dot(fe) > 0);  // outwards, into the rock
      const double L = std::hypot(m.x[le.b] - m.x[le.a], m.y[le.b] - m.y[le.a]);
      if (largest_edge_ratio) *largest_edge_ratio = std::max(*largest_edge_ratio, fe.norm() / (L * m.thickness));
    }
    return total;
  };
  const Model full = fan(48, r), half = fan(48, r, 0.0, M_PI);
  double p_at_peak = 0;
  const Vector2d full_total = hole_force(full, rise, &p_at_peak);
  CHECK(p_at_peak == doctest::Approx(peak).epsilon(kRel * 10));
  CHECK(full_total.norm() < kRel * 10 * peak * 2 * M_PI * r * full.thickness);
  // Half hole (angles 0 … π): the chord normals add up to the diameter, 2 r.
  for (double t : {0.3 * rise, rise, 4 * rise}) {
    CAPTURE(t);
    const double p = peak * (std::exp(-pulse.alpha * t) - std::exp(-pulse.beta * t)) /
                     (std::exp(-pulse.alpha * rise) - std::exp(-pulse.beta * rise));
    const Vector2d total = hole_force(half, t, nullptr);
    CHECK(total.y() == doctest::Approx(2 * p * r * half.thickness).epsilon(kRel * 10));
    CHECK(std::fabs(total.x()) < kRel * 10 * p * r * half.thickness);
  }
  // The peak: P(t₀) = P₀ and P is lower on both sides.
  for (double t : {0.99 * rise, 1.01 * rise}) {
    double p = 0;
    hole_force(full, t, &p);
    CHECK(p < peak);
    CHECK(p > 0.999 * peak);
  }
}

TEST_CASE("a plane P wave leaves through an absorbing end (< 5% reflected) and comes back reversed from a free end") {
  // Strip 2 m long; a 1 MPa Hann pulse of 80 µs (0.4 m, 40 elements) enters on the
  // left. The probe at 1.6 m sees the incident pulse around 360 µs and the reflection
  // from the right end around 520 µs.
  const double length = 2.0, probe = 1.6, pulse = 80e-6, split = 440e-6, end = 600e-6;
  const auto absorbing = incident_and_reflected(probe_stress(true, length, probe, pulse, end), split);
  const auto free_end = incident_and_reflected(probe_stress(false, length, probe, pulse, end), split);
  const double absorbed_ratio = absorbing.second / absorbing.first, free_ratio = free_end.second / free_end.first;
  MESSAGE("incident σxx " << absorbing.first / 1e6 << " MPa; reflected/incident: absorbing end " << 100 * absorbed_ratio
                          << "%, free end " << 100 * free_ratio << "%");
  CHECK(absorbing.first == doctest::Approx(-1e6).epsilon(0.03));  // compressive, the pulse's amplitude
  CHECK(std::fabs(absorbed_ratio) < 0.05);
  CHECK(free_ratio == doctest::Approx(-1.0).epsilon(0.05));
}

TEST_CASE("absorbing edges shrink the stable step estimate enough to run at 0.95 × it; the estimate without them does not") {
  // A 1 m strip hit by a short pulse, its right end absorbing; run long enough for a
  // dashpot instability at the end's corner nodes to grow from round-off.
  auto run_strip = [](double dt) {
    Strip s = strip(1.0, 0.05, 0.01);
    EdgeLoad pulse;
    pulse.kind = LoadKind::Table;
    pulse.times = {0.0, 20e-6, 40e-6};
    pulse.values = {0.0, 1e6, 0.0};
    load_end(s, 0, pulse);
    EdgeLoad dashpot;
    dashpot.kind = LoadKind::Absorbing;
    dashpot.material = 0;
    load_end(s, 1, dashpot);
    drop_unloaded(s.model);
    Solver solver(test::context(), s.model, dt);
    for (int k = 0; k < 3000; ++k) solver.step();
    return solver.conditions().ok();
  };
  Strip plain = strip(1.0, 0.05, 0.01);
  drop_unloaded(plain.model);
  const double without = stable_time_step(plain.model).dt;
  Strip absorbing = strip(1.0, 0.05, 0.01);
  EdgeLoad dashpot;
  dashpot.kind = LoadKind::Absorbing;
  dashpot.material = 0;
  load_end(absorbing, 1, dashpot);
  drop_unloaded(absorbing.model);
  const double with = stable_time_step(absorbing.model).dt;
  MESSAGE("stable step estimate " << without * 1e9 << " ns, with the absorbing end " << with * 1e9 << " ns");
  CHECK(with < without);
  CHECK(with > 0.49 * without);
  CHECK(run_strip(0.95 * with));
  CHECK(!run_strip(0.95 * without));
}

TEST_CASE("wave bar: the front of a velocity step travels at √((λ+2μ)/ρ) within 0.5%") {
  // Strip 3 m long, h = 1 cm; the left end is pushed at 1 m/s, ramped over 50 µs (so the
  // front spans 25 elements and the mesh's dispersion does not blur it). Arrival: the
  // mean vx at a station crossing 0.5 m/s.
  Strip s = strip(3.0, 0.05, 0.01);
  const double v0 = 1.0, rise = 50e-6;
  s.model.groups.push_back({3u, v0, 0.0, rise});  // left end: vx driven, vy held (also its corners)
  for (int j = 0; j <= s.ny; ++j) s.model.node_group[j] = 2;
  drop_unloaded(s.model);
  const std::vector<double> stations{0.5, 1.0, 1.5, 2.0, 2.5};
  std::vector<std::vector<int>> station_nodes(stations.size());
  for (size_t i = 0; i < s.model.num_nodes(); ++i)
    for (size_t k = 0; k < stations.size(); ++k)
      if (std::fabs(s.model.x[i] - stations[k]) < 1e-9) station_nodes[k].push_back(static_cast<int>(i));
  const double dt = 0.5 * stable_time_step(s.model).dt;
  Solver solver(test::context(), s.model, dt);
  std::vector<double> arrival(stations.size(), -1), previous(stations.size(), 0);
  const double c = wave_speed(s.model);
  while (solver.time() < stations.back() / c + 4 * rise) {
    solver.step();
    const auto v = solver.velocities();
    for (size_t k = 0; k < stations.size(); ++k) {
      double mean = 0;
      for (int n : station_nodes[k]) mean += v[n].x;
      mean /= station_nodes[k].size();
      if (arrival[k] < 0 && mean >= 0.5 * v0)
        arrival[k] = solver.time() - dt * (mean - 0.5 * v0) / (mean - previous[k]);
      previous[k] = mean;
    }
  }
  REQUIRE(solver.conditions().ok());
  // Least-squares slope of station position against arrival time.
  double mt = 0, mx = 0;
  for (size_t k = 0; k < stations.size(); ++k) {
    REQUIRE(arrival[k] > 0);
    mt += arrival[k] / stations.size(), mx += stations[k] / stations.size();
  }
  double stt = 0, stx = 0;
  for (size_t k = 0; k < stations.size(); ++k) stt += (arrival[k] - mt) * (arrival[k] - mt), stx += (arrival[k] - mt) * (stations[k] - mx);
  const double speed = stx / stt;
  MESSAGE("wave bar: V_p = " << speed << " m/s against " << c << " m/s (" << 100 * (speed / c - 1) << "%), "
                             << solver.steps_done() << " steps of " << dt * 1e9 << " ns");
  CHECK(c == doctest::Approx(5000.0).epsilon(1e-12));
  CHECK(std::fabs(speed / c - 1) < 0.005);
}

}  // TEST_SUITE
