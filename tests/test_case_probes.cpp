// [[probe]] history points: reading the entries, and tying each point to a node and a
// triangle (engine/model/probes.cpp). The values a run records: tests/test_solver_probes.cpp.
#include <doctest/doctest.h>

#include <array>
#include <string>

#include "approx.hpp"
#include "base/errors.hpp"
#include "case_files.hpp"
#include "engine/model/probes.hpp"
#include "fixture.hpp"
#include "io/case_config.hpp"
#include "probe_fixture.hpp"

using namespace fdem;
using test::bar_case;

namespace {

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
  CHECK(p.node_distance == test::rel(std::hypot(0.3, 0.2), 1e-12));
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
