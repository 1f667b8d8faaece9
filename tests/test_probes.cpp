// [[probe]] history points: reading the entries, tying points to a node and a triangle,
// and the values a run records against the same quantities in its Exodus frames.
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>

#include "case_files.hpp"
#include "base/errors.hpp"
#include "engine/probes.hpp"
#include "engine/run.hpp"
#include "fixture.hpp"
#include "io/case_config.hpp"

using namespace fdem;

namespace {

// A 1 m × 0.2 m strip of bar.geo with probes appended.
std::string bar_case(const std::string& out, const std::string& probes) {
  return "[mesh]\ngeo = \"" + test::source_path("tests/data/cases/bar.geo") +
         "\"\nsize = 0.05\n[time]\ndt = \"auto\"\nsteps = 200\n[output]\ndir = \"" + out +
         "\"\nframes = 5\n"
         "[[material]]\nname = \"rock\"\nregions = [\"bar\"]\ndensity = 2000.0\nyoung = 10e9\npoisson = 0.2\n"
         "[[boundary]]\nregion = \"left\"\nvelocity = [0.2, 0.05]\n" + probes;
}

// Two triangles on the unit square (0,0) (1,0) (1,1) (0,1), split along the diagonal
// (0,0)-(1,1): triangle 0 below it, triangle 1 above.
Model unit_square() {
  return test::make_model({0, 1, 1, 0}, {0, 0, 1, 1}, {{0, 1, 2}, {0, 2, 3}},
                          {test::material_config("rock", io::Elasticity::NeoHookean, io::Plane::Strain)});
}

ProbeLocation locate_one(const Model& m, double x, double y) {
  return locate_probes(m, {io::ProbeConfig{"p", {x, y}}}, "case.toml").at(0);
}

}  // namespace

TEST_SUITE("case") {

TEST_CASE("[[probe]]: name and point read; bad names, repeats, missing points and typos are errors") {
  test::TempDir dir;
  const std::string ok = dir.write("ok.toml", bar_case("out", "[[probe]]\nname = \"r2\"\npoint = [0.5, 0.1]\n"
                                                              "[[probe]]\nname = \"tip_1\"\npoint = [1, 0]\n"));
  const auto c = io::read_case(ok);
  REQUIRE(c.probes.size() == 2);
  CHECK(c.probes[0].name == "r2");
  CHECK(c.probes[0].point == std::array<double, 2>{0.5, 0.1});
  CHECK(c.probes[1].name == "tip_1");
  CHECK(c.probes[1].point == std::array<double, 2>{1.0, 0.0});
  CHECK(io::read_case(dir.write("none.toml", bar_case("out", ""))).probes.empty());

  const std::string twice = dir.write("twice.toml", bar_case("out", "[[probe]]\nname = \"a\"\npoint = [0.5, 0.1]\n"
                                                                    "[[probe]]\nname = \"a\"\npoint = [0.6, 0.1]\n"));
  CHECK_THROWS_WITH_AS(io::read_case(twice),
                       doctest::Contains("probe[1].name = \"a\" is already the name of probe[0]"), InputError);
  const std::string bad = dir.write("bad.toml", bar_case("out", "[[probe]]\nname = \"2r\"\npoint = [0.5, 0.1]\n"));
  CHECK_THROWS_WITH_AS(io::read_case(bad), doctest::Contains("probe[0].name = \"2r\" must start with a letter"),
                       InputError);
  const std::string nopoint = dir.write("nopoint.toml", bar_case("out", "[[probe]]\nname = \"a\"\n"));
  CHECK_THROWS_WITH_AS(io::read_case(nopoint),
                       doctest::Contains("[[probe]] #0 ('a') is missing required key 'point'"), InputError);
  const std::string typo = dir.write("typo.toml", bar_case("out", "[[probe]]\nname = \"a\"\npont = [0.5, 0.1]\n"));
  CHECK_THROWS_WITH_AS(io::read_case(typo), doctest::Contains("unknown key 'pont' in [[probe]] (did you mean 'point'?)"),
                       InputError);
  const std::string short_point = dir.write("short.toml", bar_case("out", "[[probe]]\nname = \"a\"\npoint = [0.5]\n"));
  CHECK_THROWS_WITH_AS(io::read_case(short_point), doctest::Contains("probe[0].point must be an array of 2 numbers"),
                       InputError);
}

TEST_CASE("probe location: containing triangle (lowest on a shared edge), nearest node, the mesh's edge, outside") {
  const Model m = unit_square();
  auto p = locate_one(m, 0.7, 0.2);  // below the diagonal
  CHECK(p.triangle == 0);
  CHECK(p.node == 1);
  CHECK(p.node_distance == doctest::Approx(std::hypot(0.3, 0.2)));
  p = locate_one(m, 0.2, 0.7);  // above it
  CHECK(p.triangle == 1);
  CHECK(p.node == 3);
  p = locate_one(m, 0.5, 0.5);  // on the shared diagonal: the lower triangle; four equally near nodes: the lowest
  CHECK(p.triangle == 0);
  CHECK(p.node == 0);
  p = locate_one(m, 1.0, 1.0);  // a corner shared by both
  CHECK(p.triangle == 0);
  CHECK(p.node == 2);
  CHECK(p.node_distance == 0.0);
  p = locate_one(m, 0.3, -0.005);  // 0.5% of the longest edge outside the bottom: on it
  CHECK(p.triangle == 0);
  CHECK(p.node == 0);
  // Farther out: an error naming the probe, the distance and the nearest mesh point.
  CHECK_THROWS_WITH_AS(locate_probes(m, {io::ProbeConfig{"in", {0.5, 0.4}}, io::ProbeConfig{"far", {2.0, 0.5}}}, "case.toml"),
                       doctest::Contains("case.toml: probe[1] ('far'): point = [2, 0.5] is outside the mesh (1 m from its nearest point [1, 0.5])"),
                       InputError);
  CHECK_THROWS_AS(locate_one(m, 0.3, -0.02), InputError);
}

}  // TEST_SUITE

TEST_SUITE("solver") {

TEST_CASE("probe history values are the frames' values of the probe's node and element") {
  test::TempDir dir;
  // 200 steps, frames at steps 0, 50, ..., 200; a history row every 10 steps, so the
  // rows at steps 50, ..., 200 coincide with frames 1-4.
  const std::string path = dir.write(
      "bar.toml", bar_case(dir.str(), "[[probe]]\nname = \"mid\"\npoint = [0.5, 0.1]\n"
                                      "[[probe]]\nname = \"near\"\npoint = [0.1, 0.03]\n"));
  const PreparedCase p = prepare_case(path, {});
  REQUIRE(p.probes.size() == 2);
  const double stride_time = 10 * p.dt;
  std::ostringstream every, log;
  every.precision(17);
  every << "output.history_every=" << stride_time;
  run_case(prepare_case(path, {every.str()}), test::context(), log, false);

  const std::string exo = dir.str() + "/bar.exo", hist = dir.str() + "/bar_history.nc";
  const auto frame_times = test::read_variable(exo, "time_whole");
  const auto row_times = test::read_variable(hist, "time");
  REQUIRE(frame_times.size() == 5);
  REQUIRE(row_times.size() == 20);
  const size_t nodes = test::read_variable(exo, "coordx").size();
  const auto velx = test::read_variable(exo, "vals_nod_var" + std::to_string(test::exodus_variable_index(exo, "name_nod_var", "VELX")));
  const auto vely = test::read_variable(exo, "vals_nod_var" + std::to_string(test::exodus_variable_index(exo, "name_nod_var", "VELY")));
  auto element_series = [&](const std::string& name) {
    return test::read_variable(exo, "vals_elem_var" + std::to_string(test::exodus_variable_index(exo, "name_elem_var", name)) + "eb1");
  };
  const auto sxx = element_series("SXX"), syy = element_series("SYY"), sxy = element_series("SXY"), ps1 = element_series("PS1");
  const size_t elements = sxx.size() / frame_times.size();

  for (const auto& probe : p.probes) {
    CAPTURE(probe.name);
    const auto vx = test::read_variable(hist, probe.name + "_vx"), vy = test::read_variable(hist, probe.name + "_vy");
    const auto h_sxx = test::read_variable(hist, probe.name + "_sxx"), h_syy = test::read_variable(hist, probe.name + "_syy");
    const auto h_sxy = test::read_variable(hist, probe.name + "_sxy"), h_ps1 = test::read_variable(hist, probe.name + "_ps1");
    size_t matched = 0;
    for (size_t f = 1; f < frame_times.size(); ++f) {
      const size_t row = std::lround(frame_times[f] / stride_time) - 1;
      REQUIRE(row < row_times.size());
      REQUIRE(row_times[row] == doctest::Approx(frame_times[f]).epsilon(1e-12));
      const size_t n = f * nodes + probe.node, e = f * elements + probe.triangle;
      CHECK(vx[row] == velx[n]);
      CHECK(vy[row] == vely[n]);
      CHECK(h_sxx[row] == sxx[e]);
      CHECK(h_syy[row] == syy[e]);
      CHECK(h_sxy[row] == sxy[e]);
      CHECK(h_ps1[row] == doctest::Approx(ps1[e]).epsilon(1e-14));
      ++matched;
    }
    CHECK(matched == 4);
    // The wave from the pushed end has reached both points by the end.
    CHECK(std::fabs(h_sxx.back()) > 0);
    CHECK(std::fabs(vx.back()) > 0);
  }
}

}  // TEST_SUITE
