// In-situ stress ([in_situ]): a body started in its in-situ state stays there, its
// triangles and CE4s carry the field from the first step, and the energy account stays
// closed; a model without it is unchanged (the memory plan lists no in-situ array).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "case_files.hpp"
#include "base/errors.hpp"
#include "engine/model/model.hpp"
#include "engine/run/prepare_case.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

// The test bar (1 m × 0.2 m, tests/data/cases/bar.geo) under a field that grows with depth
// below y = 0.5 m (ρ g of the rock itself, k_H 1.5, k_h 0.5 at 30° from x) on top of a
// uniform part with shear, held by in-situ tractions on the top, right and left edges and a
// fixed bottom (which holds the shear there too). `fracture`: the rock has CE4s.
std::string in_situ_case(bool fracture, const std::string& extra = "") {
  test::BarCase c;
  c.time = "dt = \"auto\"\nsteps = 1000\n";
  c.output = "dir = \"out\"\nframes = 2\nhistory_every = 1e-6\n";
  if (fracture)
    c.material = R"(
[material.fracture]
tensile_strength = 2.0e6
cohesion = 6.0e6
friction_angle = 30.0
gf1 = 20.0
gf2 = 200.0
penalty = { opening = 500e9, sliding = 500e9, overlap = 500e9 }
)";
  c.rest = R"(
[gravity]
g = [0.0, -9.81]
[in_situ]
stress = [-5.0e6, -4.0e6, 1.0e6]
datum = 0.5
k_H = 1.5
k_h = 0.5
azimuth = 30.0
[[boundary]]
region = "bottom"
fix = ["x", "y"]
[[boundary]]
region = "top"
in_situ = true
[[boundary]]
region = "left"
in_situ = true
[[boundary]]
region = "right"
in_situ = true
)" + extra;
  return c.text();
}

struct Start {
  double unbalanced_ratio = 0;  // largest out-of-balance component / the in-situ force scale
  double largest_move = 0;      // [m] after the steps
};

// Builds the case's Solver, takes one step and reads the out-of-balance forces, then takes
// the rest of `steps` and reads the largest displacement. The force scale is the largest
// in-situ stress component × the mean edge × thickness: the force one edge's share of the
// field puts on a node.
Start start_in_situ(const std::string& path, long steps) {
  const PreparedCase p = prepare_case(path, {"output.dir=\"" + std::filesystem::path(path).parent_path().string() + "/out\""});
  const Model& m = p.model;
  REQUIRE(m.in_situ.enabled);
  Solver solver(test::context(), m, p.dt);
  solver.step(true);
  const auto f = solver.forces();
  double largest = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    const uint32_t mask = m.groups[m.node_group[i]].mask;
    if (!(mask & 1u)) largest = std::max(largest, std::fabs(double(f[i].x)));
    if (!(mask & 2u)) largest = std::max(largest, std::fabs(double(f[i].y)));
  }
  double stress = 0;
  for (const auto& s : in_situ_triangle_stress(m))
    for (double v : s) stress = std::max(stress, std::fabs(v));
  Start out;
  out.unbalanced_ratio = largest / (stress * mean_edge_length(m) * m.thickness);
  for (long k = 1; k < steps; ++k) solver.step(false);
  const auto x = solver.positions();
  for (size_t i = 0; i < x.size(); ++i)
    out.largest_move = std::max(out.largest_move, std::hypot(double(x[i].x) - m.x[i], double(x[i].y) - m.y[i]));
  return out;
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("in-situ stress: a body started in its in-situ state stays there (continuum and CE4s), account closed") {
  for (bool fracture : {false, true}) {
    CAPTURE(fracture);
    test::TempDir dir;
    const std::string path = dir.write("bar.toml", in_situ_case(fracture));
    const Start s = start_in_situ(path, 1000);
    MESSAGE("fracture " << fracture << ": unbalanced ratio at the first step " << s.unbalanced_ratio
                        << ", largest displacement after 1,000 steps " << s.largest_move << " m");
    CHECK(s.unbalanced_ratio < 1e-3);
    CHECK(s.largest_move < 1e-9);
    // The run: every history row's account closed, the stress in the frames the field's.
    const RunSummary run = test::run(path, {"output.dir=\"" + dir.str() + "/out\""});
    CHECK(run.steps == 1000);
    // Closed to round-off: R, the account's round-off floor (docs/case-format.md), is
    // most of the denominator of a body at rest, so the error is noise of that size, and
    // it does not grow: the rows of the second half are no worse than those of the first,
    // or both are below 1e-9 (the sums' own rounding, with the CE4s' E₀ as denominator).
    const auto error = test::read_variable(dir.str() + "/out/bar_history.nc", "energy_error");
    double first = 0, second = 0;
    for (size_t k = 0; k < error.size(); ++k) {
      double& half = k < error.size() / 2 ? first : second;
      half = std::max(half, std::fabs(error[k]));
    }
    MESSAGE("worst |energy_error| " << run.worst_energy_error << " (first half " << first << ", second half " << second
                                    << ", " << error.size() << " rows)");
    CHECK(std::fabs(run.worst_energy_error) < 1e-3);
    CHECK(second <= std::max(first, 1e-9));
    const auto sxy = test::last_element_values(dir.str() + "/out/bar.exo", "SXY");
    for (double v : sxy) CHECK(v == doctest::Approx(1.0e6).epsilon(1e-9));
    if (fracture) {
      const auto broken = test::read_variable(dir.str() + "/out/bar_history.nc", "broken_ce4");
      CHECK(broken.back() == 0);
    }
  }
}

TEST_CASE("in-situ stress: without its tractions the body moves (the test above can fail)") {
  test::TempDir dir;
  std::string text = in_situ_case(false);
  // The right edge left free: its σ₀·n is held by nothing.
  const std::string right = "[[boundary]]\nregion = \"right\"\nin_situ = true\n";
  text.replace(text.find(right), right.size(), "");
  const std::string path = dir.write("bar.toml", text);
  const Start s = start_in_situ(path, 50);
  CHECK(s.unbalanced_ratio > 0.1);
  CHECK(s.largest_move > 1e-6);
}

TEST_CASE("in-situ stress: what the model cannot hold is refused, naming the key and the place") {
  test::TempDir dir;
  auto error = [&](const std::string& text) -> std::string {
    try {
      prepare_case(dir.write("c.toml", text), {"output.dir=\"" + dir.str() + "/out\""});
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  auto edited = [](std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
  };
  const std::string fractured = in_situ_case(true);
  // Tension across the CE4s.
  const std::string tension = error(edited(fractured, "stress = [-5.0e6, -4.0e6, 1.0e6]", "stress = [5.0e6, 4.0e6, 0.0]"));
  CHECK(tension.find("c.toml:") != std::string::npos);
  CHECK(tension.find("[in_situ]: the field pulls the CE4 faces apart: normal stress") != std::string::npos);
  CHECK(tension.find("(material 'rock')") != std::string::npos);
  // The same field in a rock that does not fracture is held (a continuum carries tension).
  CHECK(error(edited(in_situ_case(false), "stress = [-5.0e6, -4.0e6, 1.0e6]", "stress = [5.0e6, 4.0e6, 0.0]")).empty());
  // Shear above what a CE4 holds: 20 MPa on the axes' planes under 40 MPa of compression, against
  // c + min(2c, tanφ |σ_n|) = 6 + min(12, 23) MPa.
  CHECK(error(edited(fractured, "stress = [-5.0e6, -4.0e6, 1.0e6]", "stress = [-4.0e7, -4.0e7, 2.0e7]"))
            .find("exceeds what it holds before softening") != std::string::npos);
  // Depth needs gravity along -y, and a datum on or above the mesh.
  CHECK(error(edited(fractured, "g = [0.0, -9.81]", "g = [1.0, -9.81]")).find("c.toml:") != std::string::npos);
  CHECK(error(edited(fractured, "g = [0.0, -9.81]", "g = [1.0, -9.81]"))
            .find("in_situ.datum: a stress that grows with depth needs [gravity] g = [0, -g]") != std::string::npos);
  CHECK(error(edited(fractured, "datum = 0.5", "datum = 0.1"))
            .find("in_situ.datum = 0.1 m is below the top of the mesh (y = 0.2 m)") != std::string::npos);
  // A density other than the rock's is accepted, with a warning.
  const std::vector<std::string> out = {"output.dir=\"" + dir.str() + "/out\""};
  const PreparedCase p = prepare_case(dir.write("w.toml", edited(fractured, "datum = 0.5", "datum = 0.5\ndensity = 2500.0")), out);
  bool warned = false;
  for (const auto& w : model_warnings(p.model, p.config, p.dt))
    warned |= w.find("in_situ.density = 2500 kg/m³ differs from material[0].density = 2000") != std::string::npos;
  CHECK(warned);
  // An edge whose traction nothing holds is named by fdem check's warnings.
  const std::string right = "[[boundary]]\nregion = \"right\"\nin_situ = true\n";
  const PreparedCase free_right = prepare_case(dir.write("f.toml", edited(fractured, right, "")), out);
  bool unheld = false;
  for (const auto& w : model_warnings(free_right.model, free_right.config, free_right.dt))
    unheld |= w.find("boundary edges (e.g. the edge from (1,") != std::string::npos;
  CHECK(unheld);
  for (const auto& w : model_warnings(p.model, p.config, p.dt)) CHECK(w.find("boundary edges") == std::string::npos);
}

TEST_CASE("in-situ stress with Weibull strengths: a run to T and a run to T/2 restarted write the same bytes") {
  // The bar in situ, heterogeneous, pulled at its right end until CE4s break: the CE4s'
  // initial gaps and friction slips and the drawn properties are rebuilt from the case,
  // the rest is the checkpoint's state.
  std::string text = in_situ_case(true);
  auto edit = [&](const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    text.replace(at, from.size(), to);
  };
  edit("region = \"right\"\nin_situ = true", "region = \"right\"\nvelocity = [2.0, 0.0]");
  edit("fix = [\"x\", \"y\"]", "fix = [\"y\"]");
  edit("[gravity]", "[material.heterogeneity]\nhomogeneity = 3.0\nseed = 4\nproperties = [\"tensile_strength\", "
                    "\"cohesion\", \"young\"]\n[gravity]");
  edit("steps = 1000", "steps = 600");
  edit("history_every = 1e-6", "history_every = 2e-5");
  test::TempDir dir;
  const std::string path = dir.write("bar.toml", text);
  const std::string one = dir.str() + "/one", two = dir.str() + "/two";
  test::run(path, {"output.dir=\"" + one + "\""});
  test::run(path, {"output.dir=\"" + two + "\"", "time.steps=300"});
  const auto rest = test::run(path, {"output.dir=\"" + two + "\""}, test::restart_from(two + "/bar.ckpt"));
  CHECK(rest.first_step == 300);
  auto bytes = [](const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const char* f : {"/bar.exo", "/bar_history.nc", "/bar_events.nc"}) {
    CAPTURE(f);
    CHECK(bytes(one + f) == bytes(two + f));
  }
  const auto broken = test::read_variable(one + "/bar_history.nc", "broken_ce4");
  MESSAGE("broken CE4s at the middle row " << broken[broken.size() / 2] << ", at the end " << broken.back());
  CHECK(broken.back() > 0);
}

TEST_CASE("in-situ stress: the arrays exist only in models with [in_situ]") {
  test::TempDir dir;
  auto names = [&](bool in_situ, bool fracture) {
    std::string text = in_situ_case(fracture);
    if (!in_situ) {
      text = text.substr(0, text.find("[in_situ]")) +
             "[[boundary]]\nregion = \"bottom\"\nfix = [\"x\", \"y\"]\n";
    }
    const std::string path = dir.write("c.toml", text);
    const PreparedCase p = prepare_case(path, {"output.dir=\"" + dir.str() + "/out\""});
    std::vector<std::string> out;
    const MemoryPlan plan = Solver::plan(p.model, test::context().group_size());
    for (const auto& a : plan.arrays()) out.push_back(a.name);
    return out;
  };
  auto has = [](const std::vector<std::string>& v, const std::string& name) {
    return std::find(v.begin(), v.end(), name) != v.end();
  };
  CHECK(has(names(true, true), "triangle initial_stress"));
  CHECK(has(names(true, true), "ce4_in_situ_gaps"));
  CHECK_FALSE(has(names(false, true), "triangle initial_stress"));
  CHECK_FALSE(has(names(false, true), "ce4_in_situ_gaps"));
}

}  // TEST_SUITE
