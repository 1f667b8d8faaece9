// Case reader: typed access to the TOML tree (io/case_toml.cpp): keywords in place of numbers,
// integers for reals, missing keys, wrong types, ranges, exclusive keys.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "case_reader_fixture.hpp"

namespace {

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::CaseConfig;
using fdem::io::read_case;
using namespace fdem::test::case_reader;

}  // namespace

TEST_SUITE("case") {

TEST_CASE("dt = \"auto\", viscosity = \"critical\" and integers for floats") {
  CaseDir d;
  std::string text = with(kBase, "dt = 1.0", "dt = \"auto\"");
  text = with(text, "density = 2000.0", "density = 2000");
  text += "viscosity = \"critical\"\n";
  const CaseConfig c = read_case(d.write("c.toml", text));
  CHECK(c.time.dt_auto);
  CHECK(c.time.safety == 0.5);
  CHECK(c.materials[0].density == 2000.0);
  CHECK(c.materials[0].viscosity_critical);

  CHECK_THROWS_WITH_AS(read_case(d.write("c.toml", with(kBase, "dt = 1.0", "dt = \"fast\""))),
                       contains(":5: time.dt must be a number or the string \"auto\", "
                                         "found string \"fast\""),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(d.write("c.toml", kBase + "viscosity = \"high\"\n")),
                       contains("material[0].viscosity must be a number or the string "
                                         "\"critical\""),
                       InputError);
}

TEST_CASE("missing required keys name their table") {
  const std::string path_piece = ":7: [[material]] #0 ('rock') is missing required key 'density'";
  CHECK(error_of(with(kBase, "density = 2000.0\n", "")) == contains(path_piece));
  CHECK(error_of(with(kBase, "name = \"rock\"\n", "")) ==
        contains(":7: [[material]] #0 is missing required key 'name'"));
  CHECK(error_of(kBase + kSecondMaterial + "[[boundary]]\nfix = [\"x\"]\n") ==
        contains(":19: [[boundary]] #0 is missing required key 'region'"));
  CHECK(error_of(with(kBase, "dt = 1.0\n", "")) ==
        contains(":4: [time] is missing required key 'dt'"));
  CHECK(error_of(kBase + "[gravity]\n") ==
        contains(":13: [gravity] is missing required key 'g'"));
  CHECK(error_of(kBase + "[[initial]]\nregion = \"rock\"\n") ==
        contains(":13: [[initial]] #0 ('rock') is missing required key 'velocity'"));
  const std::string no_material = kBase.substr(0, kBase.find("[[material]]"));
  CHECK(error_of(no_material) == contains("at least one [[material]]"));
}

TEST_CASE("wrong types name the key, the expected type and what was found") {
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", with(kBase, "2000.0", "\"high\""))),
      contains(":10: material[0].density must be a number, found string \"high\""),
      InputError);
  CHECK(error_of(with(kBase, "end = 10.0", "steps = 10.5")) ==
        contains(":6: time.steps must be an integer, found number 10.5"));
  CHECK(error_of(kBase + "[damping]\nmass_scaling = 1\n") ==
        contains(":14: damping.mass_scaling must be a boolean, found integer 1"));
  CHECK(error_of(kBase + "[gravity]\ng = [0.0, -9.8, 1.0]\n") ==
        contains(":14: gravity.g must be an array of 2 numbers, found array of 3"));
  CHECK(error_of(kBase + "[gravity]\ng = [0.0, \"down\"]\n") ==
        contains("gravity.g[1] must be a number, found string \"down\""));
  CHECK(error_of(with(kBase, "[\"rock\"]", "\"rock\"")) ==
        contains(":9: material[0].regions must be a non-empty array of strings, found "
                          "string \"rock\""));
  CHECK(error_of(with(kBase, "[\"rock\"]", "[]")) ==
        contains("material[0].regions must be a non-empty array of strings"));
  CHECK(error_of(with(kBase, "[[material]]", "[material]")) ==
        contains(":7: material must be an array of tables"));
  CHECK(error_of(with(kBase, "[mesh]\nfile = \"m.msh\"\n", "mesh = 3\n")) ==
        contains(":2: mesh must be a table, found integer 3"));
  CHECK(error_of(with(kBase, "0.25", "nan")) ==
        contains(":12: material[0].poisson must be finite"));
}

TEST_CASE("out-of-range values give the allowed range") {
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", with(kBase, "0.25", "0.5"))),
      contains(":12: material[0].poisson = 0.5 is out of range (allowed: -1 < "
                        "material[0].poisson < 0.5)"),
      InputError);
  CHECK(error_of(with(kBase, "dt = 1.0", "dt = 1.0\nsafety = 0")) ==
        contains(":6: time.safety = 0 is out of range (allowed: 0 < time.safety <= 1)"));
  CHECK(error_of(with(kBase, "dt = 1.0", "dt = -1")) ==
        contains("time.dt = -1 is out of range (allowed: time.dt > 0)"));
  CHECK(error_of(with(kBase, "end = 10.0", "steps = 0")) ==
        contains("time.steps = 0 is out of range (allowed: time.steps >= 1)"));
  CHECK(error_of(kBase + "[damping]\nlocal = 1.0\n") ==
        contains(":14: damping.local = 1 is out of range (allowed: 0 <= damping.local < 1)"));
  CHECK(error_of(kBase + "viscosity = -1\n") ==
        contains("material[0].viscosity = -1 is out of range (allowed: "
                          "material[0].viscosity >= 0)"));
  CHECK(error_of(kBase + "[output]\nframes = 0\n") ==
        contains("output.frames = 0 is out of range"));
  CHECK(error_of(with(kBase, "[time]", "thickness = 0\n[time]")) ==
        contains(":4: mesh.thickness = 0 is out of range (allowed: mesh.thickness > 0)"));
  CHECK(error_of(kBase + "elasticity = \"neohookean\"\n") ==
        contains(":13: material[0].elasticity = \"neohookean\" is not valid (allowed: "
                          "\"neo-hookean\", \"hyperelastic\") (did you mean \"neo-hookean\"?)"));
}

TEST_CASE("exclusive and exactly-one keys") {
  CHECK(error_of(with(kBase, "end = 10.0", "end = 10.0\nsteps = 10")) ==
        contains(":7: time.end and time.steps are exclusive"));
  CHECK(error_of(with(kBase, "end = 10.0\n", "")) ==
        contains(":4: [time] needs one of 'end' or 'steps'"));
  CHECK(error_of(kBase + "[output]\nframes = 5\nevery = 1.0\n") ==
        contains(":15: output.frames and output.every are exclusive"));
}

}  // TEST_SUITE("case")
