// Fracturable regions end to end: mesh splitting, CE4 insertion, breaking, output.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <set>
#include <sstream>

#include "case_files.hpp"
#include "engine/run/run.hpp"
#include "fixture.hpp"
#include "fracture_tables.hpp"

using namespace fdem;

namespace {

const char* const kFracture = test::kRockFracture;

// The bar with critical viscosity for 2 ms, written to DIR/bar.toml; `material_extra`
// goes into the rock's [[material]] (its fracture table), `extra` after it.
std::string bar(const test::TempDir& dir, const std::string& material_extra, const std::string& extra) {
  test::BarCase c;
  c.time = "dt = \"auto\"\nend = 2e-3\n";
  c.output = "dir = \"" + dir.str() + "\"\nframes = 3\nhistory_every = 2e-5\n";
  c.material = "viscosity = \"critical\"\n" + material_extra;
  c.rest = extra;
  return dir.write("bar.toml", c.text());
}

// The bar's supports: its left edge held in x, its bottom edge in y.
const std::string kHeld = R"(
[[boundary]]
region = "left"
fix = ["x"]
[[boundary]]
region = "bottom"
fix = ["y"]
)";

const std::string kPull = kHeld + R"(
[[boundary]]
region = "right"
velocity = [0.5, 0.0]
rise = 1e-4
)";

// The bar held on its left and bottom edges, pulled by 0.5 MPa on its right edge and
// brought to rest by local damping with mass scaling.
const std::string kBarTension = R"(
[damping]
local = 0.8
mass_scaling = true
)" + kHeld + R"(
[[boundary]]
region = "right"
traction = [0.5e6, 0.0]
)";

}  // namespace

TEST_SUITE("cohesive") {

TEST_CASE("splitting: every fracturable triangle owns three nodes, one CE4 per interior edge, BCs on every copy") {
  test::TempDir dir;
  const PreparedCase whole = prepare_case(bar(dir, "", kPull), {});
  const PreparedCase split = prepare_case(bar(dir, kFracture, kPull), {});
  const Model& m = split.model;
  CHECK(m.num_nodes() == 3 * m.num_triangles());
  // Interior edges of the unsplit mesh: 3 T = 2 I + B, with B boundary edges.
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : whole.model.triangles)
    for (int e = 0; e < 3; ++e) edges[{std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])}]++;
  size_t interior = 0;
  for (const auto& [key, count] : edges) interior += count == 2;
  CHECK(m.ce4.size() == interior);
  for (const auto& c : m.ce4) {  // i' on i, j' on j, and the two faces run opposite in their triangles
    CHECK(m.x[c[0]] == m.x[c[3]]);
    CHECK(m.y[c[0]] == m.y[c[3]]);
    CHECK(m.x[c[1]] == m.x[c[2]]);
    CHECK(m.y[c[1]] == m.y[c[2]]);
  }
  // Every copy of a node on "left" is in the region and fixed in x.
  size_t on_left = 0;
  for (size_t n = 0; n < m.num_nodes(); ++n)
    if (std::fabs(m.x[n]) < 1e-12) {
      ++on_left;
      CHECK((m.groups[m.node_group[n]].mask & 1u) != 0);
    }
  for (const auto& r : m.regions)
    if (r.name == "left") CHECK(r.nodes.size() == on_left);
  // Same mass in total (each copy carries its triangle's share).
  CHECK(m.num_triangles() == whole.model.num_triangles());
}

TEST_CASE("an intact fracturable bar under a small load matches the unsplit bar to the CE4 compliance") {
  const std::string load = kBarTension;
  test::TempDir a, b;
  for (auto* d : {&a, &b})
    test::run(bar(*d, d == &a ? "" : kFracture, load),
              {"time.dt=1.0", "time.end=40000.0", "material.0.viscosity=0.0", "output.history_every=1000.0"});
  const auto sa = test::last_element_values(a.str() + "/bar.exo", "SXX");
  const auto sb = test::last_element_values(b.str() + "/bar.exo", "SXX");
  // Uniform in the unsplit bar; with CE4s (penalties 10 E) the interfaces' finite
  // stiffness perturbs it by up to ~5% near the ends, the mean staying the applied traction.
  double mean = 0;
  for (size_t e = 0; e < sa.size(); ++e) CHECK(sa[e] == doctest::Approx(0.5e6).epsilon(1e-3));
  for (size_t e = 0; e < sb.size(); ++e) {
    CHECK(sb[e] == doctest::Approx(0.5e6).epsilon(0.08));
    mean += sb[e] / sb.size();
  }
  CHECK(mean == doctest::Approx(0.5e6).epsilon(0.01));
  // The split bar stretches more, by the CE4s' compliance: about h σ / P per layer of
  // CE4s across the load (20 layers of h = 0.05 m here: 5e-6 m on 4.8e-5 m).
  const double ua = test::read_variable(a.str() + "/bar_history.nc", "right_disp_x").back();
  const double ub = test::read_variable(b.str() + "/bar_history.nc", "right_disp_x").back();
  CHECK(ub > ua);
  CHECK(ub - ua < 3 * 20 * 0.05 * 0.5e6 / 100e9);
  CHECK(test::read_variable(b.str() + "/bar_history.nc", "broken_ce4").back() == 0);
}

TEST_CASE("a bar pulled apart breaks in mode I near the tensile strength; the crack is in the output") {
  test::TempDir dir;
  const PreparedCase p = prepare_case(bar(dir, kFracture, kPull), {});
  test::run(p);
  const std::string hist = dir.str() + "/bar_history.nc";
  const auto force = test::read_variable(hist, "left_force_x");
  double peak = 0;
  for (double f : force) peak = std::max(peak, -f);
  CHECK(peak / (0.2 * 1.0) == doctest::Approx(2e6).epsilon(0.15));  // σ = F / (height × thickness)
  const double broken = test::read_variable(hist, "broken_ce4").back();
  CHECK(broken >= 4);  // at least a crack across the 0.2 m bar (4 elements at h = 0.05)
  CHECK(test::read_variable(hist, "broken_mode1").back() >= 0.5 * broken);
  CHECK(test::read_variable(hist, "crack_length").back() >= 0.2);
  // The CE4s' dissipated energy: ~0 at the first row (elastic), at the end at least G_fI
  // per unit of crack (all mode I, t = 1 m); more, as it also holds the elastic pre-peak
  // part released at breaking (⅔ T_s o_p = 0.13 G_fI here) and the softening of CE4s
  // damaged but not broken. The halves vibrate after the split; intact CE4s' elastic
  // cycles then move the total by round-off of the trapezoid rule and the Mohr-Coulomb
  // coupling only (0.2 % seen), never by a loss.
  const auto dissipated = test::read_variable(hist, "fracture_dissipation");
  const double crack = test::read_variable(hist, "crack_length").back(), G_crack = 20.0 * crack;
  MESSAGE("bar: fracture_dissipation first row " << dissipated.front() << " J, last " << dissipated.back()
          << " J = " << dissipated.back() / G_crack << " G_fI × crack_length × t");
  CHECK(std::fabs(dissipated.front()) < 1e-4 * G_crack);
  for (size_t k = 1; k < dissipated.size(); ++k) CHECK(dissipated[k] >= dissipated[k - 1] - 0.01 * G_crack);
  CHECK(dissipated.back() > 0.98 * G_crack);
  CHECK(dissipated.back() < 2.0 * G_crack);
  // After breaking, the bar carries no load.
  CHECK(std::fabs(force.back()) < 0.02 * peak);
  // The Exodus file has the cohesive QUAD4 block with its variables.
  const std::string exo = dir.str() + "/bar.exo";
  const auto broken_flags = test::last_element_values(exo, "BROKEN", 2);
  CHECK(broken_flags.size() == p.model.ce4.size());
  double sum = 0;
  for (double b : broken_flags) sum += b;
  CHECK(sum == broken);
}

TEST_CASE("activation 'fractured': only listed regions are candidates until CE4s break; runs are bitwise repeatable") {
  const std::string contact = std::string(kPull) + R"(
[contact]
normal_penalty = 10e9
friction = 0.5
activation = "fractured"
regions = ["right"]
)";
  test::TempDir a, b;
  for (auto* d : {&a, &b}) test::run(bar(*d, kFracture, contact));
  const auto candidates = test::read_variable(a.str() + "/bar_history.nc", "contact_candidates");
  const auto broken = test::read_variable(a.str() + "/bar_history.nc", "broken_ce4");
  CHECK(broken.back() > 0);
  // Listed ahead of joins (a skin, the default): the first list holds the couples of
  // every triangle, as activation "all"'s does; which of them act is the candidate mask's
  // (tests/test_contact_cases.cpp: the same physics whatever the skin).
  test::TempDir all;
  std::string every = contact;
  every.replace(every.find("activation = \"fractured\"\nregions = [\"right\"]"),
                std::string("activation = \"fractured\"\nregions = [\"right\"]").size(), "activation = \"all\"");
  test::run(bar(all, kFracture, every));
  const auto candidates_all = test::read_variable(all.str() + "/bar_history.nc", "contact_candidates");
  CHECK(candidates.front() == candidates_all.front());
  for (const std::string var : {"vals_elem_var1eb1", "vals_nod_var1"}) {
    const auto x = test::read_variable(a.str() + "/bar.exo", var), y = test::read_variable(b.str() + "/bar.exo", var);
    REQUIRE(x.size() == y.size());
    CHECK(std::memcmp(x.data(), y.data(), x.size() * sizeof(double)) == 0);
  }
}

}  // TEST_SUITE

TEST_SUITE("cohesive") {

TEST_CASE("apparent Young's modulus of an intact fracturable bar: within 1% of E at penalties 1000 E, far lower at 1 E") {
  // Plane strain, σyy = 0 (rollers): the bar's apparent modulus σ L / u is E/(1 − ν²).
  const double E = 10e9, nu = 0.2, traction = 0.5e6, length = 1.0;
  auto apparent = [&](double penalty) {
    test::TempDir dir;
    std::ostringstream fracture;
    fracture << kFracture;
    std::string text = fracture.str();
    const std::string from = "penalty = { opening = 100e9, sliding = 100e9, overlap = 100e9 }";
    std::ostringstream to;
    to << "penalty = { opening = " << penalty << ", sliding = " << penalty << ", overlap = " << penalty << " }";
    text.replace(text.find(from), from.size(), to.str());
    const std::string load = kBarTension;
    test::run(bar(dir, text, load),
              {"mesh.size=0.1", "time.dt=1.0", "time.end=200000.0", "material.0.viscosity=0.0", "output.history_every=10000.0"});
    const double u = test::read_variable(dir.str() + "/bar_history.nc", "right_disp_x").back();
    return traction * length / u / (E / (1 - nu * nu));
  };
  const double stiff = apparent(1000 * E), soft = apparent(1 * E);
  MESSAGE("apparent modulus / (E/(1-ν²)): " << stiff << " at penalties 1000 E, " << soft << " at 1 E");
  CHECK(stiff == doctest::Approx(1.0).epsilon(0.01));
  CHECK(soft < 0.5);
}

}  // TEST_SUITE

TEST_SUITE("cohesive") {

TEST_CASE("splitting a square of two triangles: 6 nodes, 1 CE4; two materials bond only through an [[interface]]") {
  io::Mesh mesh;
  mesh.source = "square";
  mesh.x = {0, 1, 1, 0};
  mesh.y = {0, 0, 1, 1};
  mesh.node_tags = {1, 2, 3, 4};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh.triangle_tags = {1, 2};
  mesh.groups = {{2, 1, "a"}, {2, 2, "b"}};
  io::FractureConfig f;
  f.tensile_strength = 1e6, f.cohesion = 2e6, f.friction_angle = 30, f.gf1 = 10, f.gf2 = 100;
  f.penalty_opening = f.penalty_sliding = f.penalty_overlap = 1e12;
  io::CaseConfig config;
  config.path = "square.toml";
  config.materials = {test::material_config("one", io::Elasticity::NeoHookean, io::Plane::Strain)};
  config.materials[0].regions = {"a", "b"};
  config.materials[0].fracture = f;
  std::vector<std::string> notes;

  mesh.triangle_group = {0, 1};
  Model same = build_model(mesh, config, notes);
  CHECK(same.num_nodes() == 6);
  REQUIRE(same.ce4.size() == 1);
  const auto& c = same.ce4[0];
  CHECK(same.x[c[0]] == same.x[c[3]]);  // i' on i
  CHECK(same.x[c[1]] == same.x[c[2]]);  // j' on j
  CHECK(same.ce4_triangles[0][0] != same.ce4_triangles[0][1]);

  // Two fracturable materials: no CE4 unless an interface names the pair.
  config.materials = {test::material_config("one", io::Elasticity::NeoHookean, io::Plane::Strain),
                      test::material_config("two", io::Elasticity::NeoHookean, io::Plane::Strain)};
  config.materials[0].regions = {"a"};
  config.materials[1].regions = {"b"};
  config.materials[0].fracture = config.materials[1].fracture = f;
  CHECK(build_model(mesh, config, notes).ce4.empty());
  config.interfaces = {io::InterfaceConfig{{"one", "two"}, f}};
  const Model bonded = build_model(mesh, config, notes);
  CHECK(bonded.ce4.size() == 1);
  CHECK(bonded.fracture.size() == 3);  // one per material, then the interface
  CHECK(bonded.ce4_properties[0] == 2);

  // One fracturable and one plain material: the plain triangle keeps shared nodes.
  config.interfaces.clear();
  config.materials[1].fracture.reset();
  const Model mixed = build_model(mesh, config, notes);
  CHECK(mixed.num_nodes() == 6);  // 3 own nodes + 3 for the plain triangle
  CHECK(mixed.ce4.empty());
}

}  // TEST_SUITE
