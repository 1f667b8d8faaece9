// Each OpenCL stage against the plain C++ reference (tests/reference.hpp).
#include <doctest/doctest.h>

#include <climits>
#include <cstring>

#include "engine/stages/boundary_loads.hpp"
#include "engine/stages/integrate.hpp"
#include "engine/stages/lumped_mass.hpp"
#include "engine/stages/node_gather.hpp"
#include "engine/stages/triangle_forces.hpp"
#include "fixture.hpp"
#include "reference.hpp"

using namespace fdem;
using reference::Matrix2d;
using reference::Vector2d;

namespace {

// Tolerances: 1e-12 relative in double (the contract); float builds get 1e-5.
constexpr double kRel = kDoublePrecision ? 1e-12 : 1e-5;

// A fan of `spokes` triangles around node 0 (a node shared by many triangles), with a
// traction on every `edge_step`-th rim edge.
Model loaded_fan(int spokes, int edge_step) {
  std::vector<double> x{0.0}, y{0.0};
  for (int k = 0; k < spokes; ++k) x.push_back(std::cos(2 * M_PI * k / spokes)), y.push_back(std::sin(2 * M_PI * k / spokes));
  std::vector<std::array<int, 3>> tris;
  for (int k = 0; k < spokes; ++k) tris.push_back({0, 1 + k, 1 + (k + 1) % spokes});
  Model m = test::make_model(x, y, tris, test::all_material_variants());
  m.loads.push_back(EdgeLoad::make(LoadKind::Traction, 1e3, 0, 0, 0));
  for (int k = 0; k < spokes; k += edge_step) m.loaded_edges.push_back({1 + k, 1 + (k + 1) % spokes, 0});
  return m;
}

// Deforms every soup triangle with its own random F (det > 0), translation and rotation,
// and gives every node a random velocity.
void deform(const Model& m, std::mt19937& rng, std::vector<real2>& pos, std::vector<real2>& vel,
            double strain = 0.1, double speed = 1.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  pos.resize(m.num_nodes());
  vel.resize(m.num_nodes());
  for (const auto& tri : m.triangles) {
    Matrix2d F;
    do {
      F << 1 + strain * u(rng), strain * u(rng), strain * u(rng), 1 + strain * u(rng);
    } while (F.determinant() < 0.5);
    const double a = M_PI * u(rng);
    Matrix2d R;
    R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    const Vector2d shift(0.2 * u(rng), 0.2 * u(rng));
    for (int n : tri) {
      const Vector2d p = R * F * Vector2d(m.x[n], m.y[n]) + shift;
      pos[n] = {real(p.x()), real(p.y())};
      vel[n] = {real(speed * u(rng)), real(speed * u(rng))};
    }
  }
}

std::array<Vector2d, 3> corners(const std::array<int, 3>& tri, const std::vector<real2>& p) {
  return {Vector2d(p[tri[0]].x, p[tri[0]].y), Vector2d(p[tri[1]].x, p[tri[1]].y), Vector2d(p[tri[2]].x, p[tri[2]].y)};
}
std::array<Vector2d, 3> reference_corners(const Model& m, const std::array<int, 3>& tri) {
  return {Vector2d(m.x[tri[0]], m.y[tri[0]]), Vector2d(m.x[tri[1]], m.y[tri[1]]), Vector2d(m.x[tri[2]], m.y[tri[2]])};
}

void check_triangle_forces(const Model& m, const std::vector<real2>& pos, const std::vector<real2>& vel) {
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  upload(cl, arrays.position, pos);
  upload(cl, arrays.velocity, vel);
  TriangleForces stage(cl, arrays, m.thickness, 1e-6, false);
  stage.enqueue_stress(0);
  const auto force = download<real2>(cl, arrays.corner_force, 3 * m.num_triangles());
  const auto stress = download<real4>(cl, arrays.stress, m.num_triangles());
  const auto cond = download<int>(cl, arrays.conditions, layout::CONDITION_WORDS);
  CHECK(cond[layout::COND_INVERTED_TRI] == INT_MAX);

  double worst = 0;
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    const auto& tri = m.triangles[t];
    const auto r = reference::triangle_forces(m.materials[m.triangle_material[t]], reference_corners(m, tri),
                                              corners(tri, pos), corners(tri, vel), m.thickness);
    double scale = 0, stress_scale = r.stress.cwiseAbs().maxCoeff();
    for (int a = 0; a < 3; ++a) scale = std::max(scale, r.force[a].norm());
    for (int a = 0; a < 3; ++a) {
      const Vector2d got(force[3 * t + a].x, force[3 * t + a].y);
      worst = std::max(worst, (got - r.force[a]).norm() / scale);
    }
    const double ds = std::max({std::fabs(stress[t].x - r.stress(0, 0)), std::fabs(stress[t].y - r.stress(1, 1)),
                                std::fabs(stress[t].z - r.stress(0, 1))});
    worst = std::max(worst, ds / stress_scale);
  }
  CHECK(worst < kRel);
}

}  // namespace

TEST_SUITE("kernels") {

TEST_CASE("triangle forces and stress match the reference for every constitutive model") {
  std::mt19937 rng(42);
  for (double viscosity : {0.0, 3.0e5}) {
    CAPTURE(viscosity);
    const Model m = test::triangle_soup(500, test::all_material_variants(viscosity), rng);
    std::vector<real2> pos, vel;
    deform(m, rng, pos, vel);
    check_triangle_forces(m, pos, vel);
  }
}

TEST_CASE("a rigid rotation of 90 degrees gives zero stress") {
  std::mt19937 rng(7);
  const Model m = test::triangle_soup(50, test::all_material_variants(), rng);
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  std::vector<real2> pos(m.num_nodes());
  for (size_t i = 0; i < m.num_nodes(); ++i) pos[i] = {real(-m.y[i] + 3.0), real(m.x[i] - 1.0)};
  upload(cl, arrays.position, pos);
  TriangleForces stage(cl, arrays, m.thickness, 1e-6, false);
  stage.enqueue_stress(0);
  const auto stress = download<real4>(cl, arrays.stress, m.num_triangles());
  double worst = 0;
  for (const auto& s : stress) worst = std::max({worst, double(std::fabs(s.x)), double(std::fabs(s.y)), double(std::fabs(s.z))});
  CHECK(worst < (kDoublePrecision ? 1e-12 : 1e-4) * 30e9);
}

TEST_CASE("patch test: a linear displacement field gives the exact uniform stress and balanced interior nodes") {
  // An unstructured patch: a 7x7 grid with jittered interior nodes and random diagonals.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 7;
  std::vector<double> x, y;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const bool interior = i > 0 && j > 0 && i < n - 1 && j < n - 1;
      x.push_back(i + (interior ? 0.3 * u(rng) : 0.0));
      y.push_back(j + (interior ? 0.3 * u(rng) : 0.0));
    }
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      if (u(rng) > 0) tris.push_back({a, b, c}), tris.push_back({a, c, d});
      else tris.push_back({a, b, d}), tris.push_back({b, c, d});
    }
  for (const auto& variant : test::all_material_variants()) {
    CAPTURE(variant.name);
    const Model m = test::make_model(x, y, tris, {variant});
    Matrix2d F;
    F << 1.002, 0.0007, -0.0004, 0.9985;
    std::vector<real2> pos(m.num_nodes()), vel(m.num_nodes());
    for (size_t k = 0; k < m.num_nodes(); ++k) {
      const Vector2d p = F * Vector2d(m.x[k], m.y[k]) + Vector2d(0.5, -0.25);
      pos[k] = {real(p.x()), real(p.y())};
    }
    auto& cl = test::context();
    DeviceArrays arrays(cl, m);
    upload(cl, arrays.position, pos);
    upload(cl, arrays.velocity, vel);
    TriangleForces forces(cl, arrays, m.thickness, 1e-6, false);
    NodeGather gather(cl, arrays, nullptr, 0.0);
    forces.enqueue_stress(0);
    gather.enqueue_forces();
    const auto stress = download<real4>(cl, arrays.stress, m.num_triangles());
    const auto node_force = download<real2>(cl, arrays.node_force, m.num_nodes());
    const Matrix2d exact = reference::cauchy_stress(m.materials[0], F, Matrix2d::Zero());
    const double scale = exact.cwiseAbs().maxCoeff();
    double worst = 0;
    for (const auto& s : stress)
      worst = std::max({worst, std::fabs(s.x - exact(0, 0)), std::fabs(s.y - exact(1, 1)), std::fabs(s.z - exact(0, 1))});
    CHECK(worst / scale < (kDoublePrecision ? 1e-10 : 1e-4));
    // Interior nodes are in equilibrium: their forces cancel to round-off of scale × area.
    double interior = 0;
    for (int j = 1; j < n - 1; ++j)
      for (int i = 1; i < n - 1; ++i) interior = std::max(interior, double(std::hypot(node_force[j * n + i].x, node_force[j * n + i].y)));
    CHECK(interior / (scale * m.thickness) < (kDoublePrecision ? 1e-9 : 1e-3));
  }
}

TEST_CASE("node gather sums every corner and edge slot, bitwise the same on every launch") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // A mesh where nodes are shared by many triangles (a fan) plus loaded edges.
  const int spokes = 40;
  const Model m = loaded_fan(spokes, 1);
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  std::vector<real2> corner(3 * m.num_triangles()), edge(2 * m.loaded_edges.size());
  for (auto& c : corner) c = {real(1e6 * u(rng)), real(1e6 * u(rng))};
  for (auto& e : edge) e = {real(1e3 * u(rng)), real(1e3 * u(rng))};
  upload(cl, arrays.corner_force, corner);
  upload(cl, arrays.edge_force, edge);
  NodeGather gather(cl, arrays, nullptr, 0.0);
  gather.enqueue_forces();
  const auto first = download<real2>(cl, arrays.node_force, m.num_nodes());
  gather.enqueue_forces();
  const auto second = download<real2>(cl, arrays.node_force, m.num_nodes());
  CHECK(std::memcmp(first.data(), second.data(), first.size() * sizeof(real2)) == 0);

  std::vector<Vector2d> expected(m.num_nodes(), Vector2d::Zero());
  for (size_t t = 0; t < m.num_triangles(); ++t)
    for (int a = 0; a < 3; ++a) expected[m.triangles[t][a]] += Vector2d(corner[3 * t + a].x, corner[3 * t + a].y);
  for (size_t e = 0; e < m.loaded_edges.size(); ++e) {
    expected[m.loaded_edges[e].a] += Vector2d(edge[2 * e].x, edge[2 * e].y);
    expected[m.loaded_edges[e].b] += Vector2d(edge[2 * e + 1].x, edge[2 * e + 1].y);
  }
  for (size_t i = 0; i < m.num_nodes(); ++i)
    CHECK((Vector2d(first[i].x, first[i].y) - expected[i]).norm() <= (kDoublePrecision ? 1e-12 : 1e-5) * 1e6 * spokes);
}

// The gather's one map (session 25: one start array instead of three): per node its
// corner slots, then its edge slots, then its CE4 slots, tagged in the top two bits.
TEST_CASE("node gather map: corners, then loaded edges, then CE4s per node, each tagged; a slot past 30 bits refused") {
  const std::vector<std::array<int, 3>> triangles{{0, 1, 2}, {2, 1, 3}};
  const std::vector<std::array<int, 2>> edges{{1, 3}};
  const std::vector<std::array<int, 4>> ce4{{1, 2, 2, 1}};
  const SlotMap corners = build_slot_map(4, triangles), edge_map = build_slot_map(4, edges), ce4_map = build_slot_map(4, ce4);
  const SlotMap map = node_slot_map(corners, edge_map, ce4_map);
  const uint32_t E = 1u << 30, C = 2u << 30;
  CHECK(map.start == std::vector<uint32_t>{0, 1, 6, 10, 12});
  CHECK(map.slot == std::vector<uint32_t>{0,                          // node 0: corner 0 of triangle 0
                                          1, 4, E | 0, C | 0, C | 3,  // node 1: corners, its edge end, CE4 slots
                                          2, 3, C | 1, C | 2,         // node 2
                                          5, E | 1});                 // node 3
  SlotMap big = corners;
  big.slot[0] = 1u << 30;
  CHECK_THROWS_AS(node_slot_map(big, edge_map, ce4_map), InputError);
}

TEST_CASE("the integration that gathers the forces itself gives the bits of the gather and the integration") {
  // The Solver's step fuses the gather into the integration on small models and CPU
  // devices (step_gather) and launches both on large GPU models: both paths must agree
  // to the bit. A fan with loaded edges and fixed-point contact forces, gravity, local
  // damping, random velocities and slot values.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Model m = loaded_fan(24, 2);
  m.contact.enabled = true;
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  const double dt = 1e-6, force_scale = std::ldexp(1.0, 40);
  NodeGather gather(cl, arrays, nullptr, force_scale);
  LumpedMass(cl, arrays, m, dt).enqueue(gather);
  std::vector<real2> corner(3 * m.num_triangles()), edge(2 * m.loaded_edges.size()), pos(m.num_nodes()), vel(m.num_nodes());
  std::vector<cl_long> acc(2 * m.num_nodes());
  for (auto& c : corner) c = {real(1e6 * u(rng)), real(1e6 * u(rng))};
  for (auto& e : edge) e = {real(1e3 * u(rng)), real(1e3 * u(rng))};
  for (auto& a : acc) a = static_cast<cl_long>(1e5 * u(rng) * force_scale);
  for (size_t i = 0; i < m.num_nodes(); ++i) pos[i] = {real(m.x[i]), real(m.y[i])}, vel[i] = {real(u(rng)), real(u(rng))};
  auto state = [&] {
    upload(cl, arrays.corner_force, corner);
    upload(cl, arrays.edge_force, edge);
    upload(cl, arrays.contact_acc, acc);
    upload(cl, arrays.position, pos);
    upload(cl, arrays.velocity, vel);
  };
  const std::array<double, 2> g{0.0, -9.81};
  state();
  gather.enqueue_forces();
  Integrate(cl, arrays, g, 0.8, dt, false).enqueue(dt, 3);
  const auto x_two = download<real2>(cl, arrays.position, m.num_nodes());
  const auto v_two = download<real2>(cl, arrays.velocity, m.num_nodes());
  const auto f_two = download<real2>(cl, arrays.node_force, m.num_nodes());
  state();
  upload(cl, arrays.node_force, std::vector<real2>(m.num_nodes()));  // nothing left from the gather
  Integrate fused(cl, arrays, g, 0.8, dt, false, true, nullptr, Integrate::Gather{nullptr, force_scale});
  CHECK(fused.gathers());
  fused.enqueue(dt, 3);
  const auto x_one = download<real2>(cl, arrays.position, m.num_nodes());
  const auto v_one = download<real2>(cl, arrays.velocity, m.num_nodes());
  const auto f_one = download<real2>(cl, arrays.node_force, m.num_nodes());
  CHECK(std::memcmp(x_one.data(), x_two.data(), x_one.size() * sizeof(real2)) == 0);
  CHECK(std::memcmp(v_one.data(), v_two.data(), v_one.size() * sizeof(real2)) == 0);
  CHECK(std::memcmp(f_one.data(), f_two.data(), f_one.size() * sizeof(real2)) == 0);
  // And the forces moved the nodes (the comparison is not of two untouched arrays).
  CHECK(std::memcmp(x_one.data(), pos.data(), pos.size() * sizeof(real2)) != 0);
}

// node_mass as (mass, inertia): the device holds the mass alone without mass scaling.
static std::vector<real2> node_masses(ClContext& cl, const DeviceArrays& arrays) {
  if (arrays.mass_scaling) return download<real2>(cl, arrays.node_mass, arrays.num_nodes);
  std::vector<real2> out;
  for (const real m : download<real>(cl, arrays.node_mass, arrays.num_nodes)) out.push_back(real2{m, m});
  return out;
}

TEST_CASE("lumped mass: ρA₀t/3 per corner, and mass scaling gives 0.3 Δt²Σk") {
  std::mt19937 rng(5);
  Model m = test::triangle_soup(300, test::all_material_variants(), rng);
  auto& cl = test::context();
  for (bool scaling : {false, true}) {
    CAPTURE(scaling);
    m.mass_scaling = scaling;
    DeviceArrays arrays(cl, m);
    NodeGather gather(cl, arrays, nullptr, 0.0);
    const double dt = 0.7;
    LumpedMass(cl, arrays, m, dt).enqueue(gather);
    const auto got = node_masses(cl, arrays);
    for (size_t t = 0; t < m.num_triangles(); ++t) {
      const auto X = reference_corners(m, m.triangles[t]);
      const auto& mat = m.materials[m.triangle_material[t]];
      const double area = 0.5 * ((X[1] - X[0]).x() * (X[2] - X[0]).y() - (X[1] - X[0]).y() * (X[2] - X[0]).x());
      const double mass_ref = mat.density * area * m.thickness / 3.0;
      const auto K = reference::element_stiffness(mat, X, m.thickness);
      for (int a = 0; a < 3; ++a) {  // soup: each node belongs to exactly this triangle
        const int n = m.triangles[t][a];
        const double k = std::max(K.row(2 * a).cwiseAbs().sum(), K.row(2 * a + 1).cwiseAbs().sum());
        const double inertia_ref = scaling ? 0.3 * dt * dt * k : mass_ref;
        CHECK(std::fabs(got[n].x - mass_ref) <= kRel * mass_ref);
        CHECK(std::fabs(got[n].y - inertia_ref) <= kRel * inertia_ref);
      }
    }
  }
}

TEST_CASE("mass scaling makes the chosen step stable: ω_max Δt < 2 on an assembled mesh") {
  // Assemble K on an irregular fan mesh with every material, take its largest
  // generalised eigenvalue against the scaled inertia, and compare with 2/Δt².
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const auto& variant : test::all_material_variants()) {
    CAPTURE(variant.name);
    const int spokes = 9;
    std::vector<double> x{0.05, 0.0}, y{0.0, 0.0};
    x.clear(), y.clear();
    x.push_back(0.02), y.push_back(-0.01);
    for (int k = 0; k < spokes; ++k) {
      const double r = 1.0 + 0.3 * u(rng), a = 2 * M_PI * (k + 0.3 * u(rng)) / spokes;
      x.push_back(r * std::cos(a)), y.push_back(r * std::sin(a));
    }
    std::vector<std::array<int, 3>> tris;
    for (int k = 0; k < spokes; ++k) tris.push_back({0, 1 + k, 1 + (k + 1) % spokes});
    Model m = test::make_model(x, y, tris, {variant});
    m.mass_scaling = true;
    auto& cl = test::context();
    DeviceArrays arrays(cl, m);
    NodeGather gather(cl, arrays, nullptr, 0.0);
    const double dt = 2.5;
    LumpedMass(cl, arrays, m, dt).enqueue(gather);
    const auto inertia = node_masses(cl, arrays);
    const int n = static_cast<int>(2 * m.num_nodes());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
    for (const auto& tri : m.triangles) {
      const auto Ke = reference::element_stiffness(m.materials[0], reference_corners(m, tri), m.thickness);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) K.block<2, 2>(2 * tri[a], 2 * tri[b]) += Ke.block<2, 2>(2 * a, 2 * b);
    }
    Eigen::VectorXd scale(n);
    for (int i = 0; i < n; ++i) scale(i) = 1.0 / std::sqrt(double(inertia[i / 2].y));
    const Eigen::MatrixXd A = scale.asDiagonal() * K * scale.asDiagonal();
    const double omega2 = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().maxCoeff();
    CHECK(omega2 * dt * dt <= (1.0 / 0.3) * (1 + 1e-9));  // < 4: stable
    CHECK(omega2 * dt * dt > 0.5);  // not wastefully over-scaled either
  }
}

TEST_CASE("boundary loads: pressure on a closed boundary has no net force; traction integrates to τLt") {
  // A regular 24-gon made of a fan, rotated and stretched: pressure on every rim edge.
  const int sides = 24;
  std::vector<double> x{0.0}, y{0.0};
  for (int k = 0; k < sides; ++k) x.push_back(0.3 * std::cos(2 * M_PI * k / sides)), y.push_back(0.3 * std::sin(2 * M_PI * k / sides));
  std::vector<std::array<int, 3>> tris;
  for (int k = 0; k < sides; ++k) tris.push_back({0, 1 + k, 1 + (k + 1) % sides});
  Model m = test::make_model(x, y, tris, {test::all_material_variants()[0]});
  m.loads.push_back(EdgeLoad::make(LoadKind::Pressure, 0, 0, 2.0e6, 0));        // pressure
  m.loads.push_back(EdgeLoad::make(LoadKind::Traction, 1.0e5, -3.0e5, 0, 0.5));  // traction with a rise time
  for (int k = 0; k < sides; ++k) m.loaded_edges.push_back({1 + k, 1 + (k + 1) % sides, 0});
  m.loaded_edges.push_back({1, 2, 1});
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  std::vector<real2> pos(m.num_nodes());
  for (size_t i = 0; i < m.num_nodes(); ++i) pos[i] = {real(1.3 * m.x[i] - 0.2 * m.y[i] + 4), real(0.1 * m.x[i] + 0.8 * m.y[i])};
  upload(cl, arrays.position, pos);
  BoundaryLoads loads(cl, arrays, m.thickness, 1e-6);
  const double time = 0.25;  // half way up the traction's ramp
  loads.enqueue(time, 0);
  const auto f = download<real2>(cl, arrays.edge_force, 2 * m.loaded_edges.size());
  Vector2d pressure_total = Vector2d::Zero();
  double moment = 0;
  for (int k = 0; k < sides; ++k) {
    pressure_total += Vector2d(f[2 * k].x + f[2 * k + 1].x, f[2 * k].y + f[2 * k + 1].y);
    // Each rim edge's force points inwards (pressure pushes into the body).
    const int a = 1 + k, b = 1 + (k + 1) % sides;
    const Vector2d mid(0.5 * (pos[a].x + pos[b].x) - 4, 0.5 * (pos[a].y + pos[b].y));
    CHECK(mid.dot(Vector2d(f[2 * k].x, f[2 * k].y)) < 0);
    moment += 0;  // equal halves at both ends: no spurious couple within an edge
  }
  const double perimeter_force = 2.0e6 * m.thickness * 2 * M_PI * 0.3;
  CHECK(pressure_total.norm() < (kDoublePrecision ? 1e-12 : 1e-5) * perimeter_force);
  const size_t e = sides;
  const double L0 = std::hypot(m.x[2] - m.x[1], m.y[2] - m.y[1]);
  const Vector2d traction_total(f[2 * e].x + f[2 * e + 1].x, f[2 * e].y + f[2 * e + 1].y);
  const Vector2d expected = 0.5 * Vector2d(1.0e5, -3.0e5) * L0 * m.thickness;
  CHECK((traction_total - expected).norm() < kRel * expected.norm());
}

TEST_CASE("integration: gravity, local damping and ramped prescribed velocities against the reference") {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Model m = test::triangle_soup(100, test::all_material_variants(), rng);
  m.groups.push_back({1u, 0.3, 0.0, 2.0});      // vx ramped to 0.3 over 2 s
  m.groups.push_back({3u, 0.0, -0.2, 0.0});     // vx = 0, vy = -0.2
  m.groups.push_back({2u, 0.0, 0.0, 0.0});      // vy fixed
  for (size_t i = 0; i < m.num_nodes(); ++i) m.node_group[i] = static_cast<uint32_t>(i % 5 < 3 ? i % 5 : 0) % 4;
  const double dt = 1e-3, alpha = 0.7, time_after = 0.5;
  const std::array<double, 2> g{0.3, -9.8};
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  NodeGather gather(cl, arrays, nullptr, 0.0);
  LumpedMass(cl, arrays, m, dt).enqueue(gather);
  std::vector<real2> pos(m.num_nodes()), vel(m.num_nodes()), force(m.num_nodes());
  for (size_t i = 0; i < m.num_nodes(); ++i) {
    pos[i] = {real(m.x[i]), real(m.y[i])};
    vel[i] = {real(i % 7 == 0 ? 0.0 : u(rng)), real(u(rng))};
    force[i] = {real(1e4 * u(rng)), real(1e4 * u(rng))};
  }
  upload(cl, arrays.position, pos);
  upload(cl, arrays.velocity, vel);
  upload(cl, arrays.node_force, force);
  Integrate integrate(cl, arrays, g, alpha, dt, false);
  integrate.enqueue(time_after, 12);
  const auto masses = node_masses(cl, arrays);
  const auto x = download<real2>(cl, arrays.position, m.num_nodes());
  const auto v = download<real2>(cl, arrays.velocity, m.num_nodes());
  const auto f = download<real2>(cl, arrays.node_force, m.num_nodes());
  auto sgn = [](double s) { return s > 0 ? 1.0 : s < 0 ? -1.0 : 0.0; };
  for (size_t i = 0; i < m.num_nodes(); ++i) {
    const double mi = masses[i].x;
    double fx = force[i].x + mi * g[0], fy = force[i].y + mi * g[1];
    CHECK(std::fabs(f[i].x - fx) <= kRel * std::fabs(fx) + 1e-30);
    double vx = vel[i].x + (fx - alpha * std::fabs(fx) * sgn(vel[i].x)) / mi * dt;
    double vy = vel[i].y + (fy - alpha * std::fabs(fy) * sgn(vel[i].y)) / mi * dt;
    const auto& grp = m.groups[m.node_group[i]];
    const double ramp = grp.rise > 0 ? std::min(time_after / grp.rise, 1.0) : 1.0;
    if (grp.mask & 1u) vx = ramp * grp.vx;
    if (grp.mask & 2u) vy = ramp * grp.vy;
    CHECK(std::fabs(v[i].x - vx) <= kRel * (std::fabs(vx) + 1e-3));
    CHECK(std::fabs(v[i].y - vy) <= kRel * (std::fabs(vy) + 1e-3));
    CHECK(std::fabs(x[i].x - (pos[i].x + vx * dt)) <= kRel * 10);
    CHECK(std::fabs(x[i].y - (pos[i].y + vy * dt)) <= kRel * 10);
  }
  CHECK(download<int>(cl, arrays.conditions, layout::CONDITION_WORDS)[layout::COND_BAD_NODE] == INT_MAX);
}

TEST_CASE("condition flags name the first inverted triangle and the first non-finite node") {
  std::mt19937 rng(29);
  const Model m = test::triangle_soup(20, test::all_material_variants(), rng);
  auto& cl = test::context();
  DeviceArrays arrays(cl, m);
  std::vector<real2> pos(m.num_nodes());
  for (size_t i = 0; i < m.num_nodes(); ++i) pos[i] = {real(m.x[i]), real(m.y[i])};
  // Mirror triangles 7 and 12 (in model order): J < 0.
  for (size_t t : {size_t(12), size_t(7)})
    for (int n : m.triangles[t]) pos[n].x = -pos[n].x;
  upload(cl, arrays.position, pos);
  TriangleForces forces(cl, arrays, m.thickness, 1e-6, false);
  forces.enqueue(33);
  auto cond = download<int>(cl, arrays.conditions, layout::CONDITION_WORDS);
  CHECK(cond[layout::COND_INVERTED_TRI] == 7);
  CHECK(cond[layout::COND_INVERTED_STEP] == 33);
  std::vector<real2> force(m.num_nodes());
  force[5].x = std::numeric_limits<real>::quiet_NaN();
  force[9].y = std::numeric_limits<real>::infinity();
  upload(cl, arrays.node_force, force);
  NodeGather gather(cl, arrays, nullptr, 0.0);
  LumpedMass(cl, arrays, m, 1e-6).enqueue(gather);
  upload(cl, arrays.node_force, force);
  Integrate(cl, arrays, {0, 0}, 0, 1e-6, false).enqueue(1e-6, 40);
  cond = download<int>(cl, arrays.conditions, layout::CONDITION_WORDS);
  CHECK(cond[layout::COND_BAD_NODE] == 5);
  CHECK(cond[layout::COND_BAD_NODE_STEP] == 40);
}

TEST_CASE("stiffness rotation: isotropic is invariant, 90 degrees swaps the axes") {
  const Voigt iso = isotropic_stiffness(10e9, 0.3, io::Plane::Strain);
  const Voigt r = rotate_stiffness(iso, 37.0);
  for (int k = 0; k < 6; ++k) CHECK(r[k] == doctest::Approx(iso[k]).epsilon(1e-12).scale(1e10));
  const Voigt ortho{50e9, 20e9, 0, 12e9, 0, 8e9};
  const Voigt q = rotate_stiffness(ortho, 90.0);
  CHECK(q[0] == doctest::Approx(12e9));
  CHECK(q[3] == doctest::Approx(50e9));
  CHECK(q[1] == doctest::Approx(20e9));
  CHECK(q[5] == doctest::Approx(8e9));
  CHECK(std::fabs(q[2]) < 1e-3);
  // 45 degrees, orthotropic closed form: a global x strain ε gives σxy = (C11 - C22) ε / 4
  const Voigt h = rotate_stiffness(ortho, 45.0);
  const double c11 = 50e9, c22 = 12e9, c12 = 20e9, c66 = 8e9;
  CHECK(h[0] == doctest::Approx((c11 + c22 + 2 * c12 + 4 * c66) / 4));
  CHECK(h[2] == doctest::Approx((c11 - c22) / 4).epsilon(1e-9));
}

}  // TEST_SUITE
