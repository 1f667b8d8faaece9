// Case reader: [mesh], [time], [output], [gravity], [damping] (io/case_setup_tables.cpp).
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

TEST_CASE("mesh: missing file, geo and file together, neither, size without geo") {
  CaseDir d;
  const std::string path = d.write("c.toml", with(kBase, "m.msh", "nope.msh"));
  CHECK_THROWS_WITH_AS(read_case(path),
                       contains(path + ":3: mesh.file: file not found: " +
                                         d.path("nope.msh")),
                       InputError);
  CHECK(error_of(with(kBase, "[time]", "geo = \"meshes/column.geo\"\n[time]")) ==
        contains(":4: mesh.geo and mesh.file are exclusive"));
  CHECK(error_of(with(kBase, "file = \"m.msh\"\n", "")) ==
        contains(":2: [mesh] needs one of 'geo' or 'file'"));
  CHECK(error_of(with(kBase, "[time]", "size = 0.5\n[time]")) ==
        contains(":4: mesh.size only applies with mesh.geo"));
  CHECK(error_of(with(kBase, "title = \"t\"\n[mesh]\nfile = \"m.msh\"\n", "")) ==
        contains("missing required table [mesh]"));
}

TEST_CASE("output.energy_limit: a fraction > 0, 0.05 when absent") {
  CaseDir d;
  CHECK(read_case(d.write("a.toml", kBase)).output.energy_limit == 0.05);
  CHECK(read_case(d.write("b.toml", kBase + "[output]\nenergy_limit = 0.2\n")).output.energy_limit == 0.2);
  CHECK(read_case(d.write("c.toml", kBase + "[output]\nenergy_limit = 1\n")).output.energy_limit == 1.0);
  CHECK(read_case(d.write("d.toml", kBase), {"output.energy_limit=0.01"}).output.energy_limit == 0.01);
  // kBase has 12 lines: [output] on line 13, energy_limit on line 14.
  const std::string zero = d.write("zero.toml", kBase + "[output]\nenergy_limit = 0.0\n");
  CHECK_THROWS_WITH_AS(read_case(zero),
                       contains(zero + ":14: output.energy_limit = 0 is out of range (allowed: "
                                       "output.energy_limit > 0)"),
                       InputError);
  CHECK(error_of(kBase + "[output]\nenergy_limit = -0.05\n") ==
        contains(":14: output.energy_limit = -0.05 is out of range (allowed: output.energy_limit > 0)"));
  CHECK(error_of(kBase + "[output]\nenergy_limit = \"5%\"\n") ==
        contains(":14: output.energy_limit must be a number, found string \"5%\""));
  CHECK(error_of(kBase + "[output]\nenergy_limt = 0.1\n") ==
        contains(":14: unknown key 'energy_limt' in [output] (did you mean 'energy_limit'?)"));
}

TEST_CASE("output.precision and output.compress: double and false when absent, near names suggested") {
  CaseDir d;
  const auto plain = read_case(d.write("a.toml", kBase)).output;
  CHECK(!plain.float_frames);
  CHECK(!plain.compress);
  const auto chosen =
      read_case(d.write("b.toml", kBase + "[output]\nprecision = \"float\"\ncompress = true\n")).output;
  CHECK(chosen.float_frames);
  CHECK(chosen.compress);
  CHECK(!read_case(d.write("c.toml", kBase + "[output]\nprecision = \"double\"\n")).output.float_frames);
  CHECK(read_case(d.write("d.toml", kBase), {"output.precision=float"}).output.float_frames);
  CHECK(error_of(kBase + "[output]\nprecision = \"flaot\"\n") ==
        contains(":14: output.precision = \"flaot\" is not valid (allowed: \"double\", \"float\") (did you mean "
                 "\"float\"?)"));
  CHECK(error_of(kBase + "[output]\ncompress = \"yes\"\n") == contains(":14: output.compress must be"));
  CHECK(error_of(kBase + "[output]\nprecission = \"float\"\n") ==
        contains(":14: unknown key 'precission' in [output] (did you mean 'precision'?)"));
  CHECK(error_of(kBase + "[output]\ncompres = true\n") ==
        contains(":14: unknown key 'compres' in [output] (did you mean 'compress'?)"));
}

}  // TEST_SUITE("case")

TEST_SUITE("case") {

TEST_CASE("[in_situ]: a uniform field, principal stresses at an angle, a field growing with depth; errors") {
  CaseDir d;
  // kBase has 12 lines: [in_situ] on line 13, its first key on line 14.
  const CaseConfig uniform = read_case(d.write("u.toml", kBase + "[in_situ]\nstress = [-5e6, -3e6, 1e6]\n"));
  REQUIRE(uniform.in_situ);
  CHECK(uniform.in_situ->stress == std::array<double, 3>{-5e6, -3e6, 1e6});
  CHECK_FALSE(uniform.in_situ->datum);
  CHECK_FALSE(read_case(d.write("none.toml", kBase)).in_situ);
  // principal = [σ1, σ2] with σ1 at 90°: σyy = σ1.
  const auto p = read_case(d.write("p.toml", kBase + "[in_situ]\nprincipal = [-8e6, -2e6]\nangle = 90.0\n")).in_situ;
  CHECK(p->stress[0] == doctest::Approx(-2e6));
  CHECK(p->stress[1] == doctest::Approx(-8e6));
  CHECK(std::fabs(p->stress[2]) < 1e-6);
  const auto z = read_case(d.write("z.toml", kBase + "[in_situ]\ndatum = 100.0\nk_H = 1.5\n")).in_situ;
  CHECK(*z->datum == 100.0);
  CHECK(z->k_H == 1.5);
  CHECK(z->k_h == 1.5);  // defaults to k_H
  CHECK(z->azimuth == 0.0);
  CHECK_FALSE(z->density);
  CHECK(error_of(kBase + "[in_situ]\nk_H = 1.0\n") ==
        contains(":13: [in_situ] needs 'stress', 'principal' or 'datum'"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, -1e6]\n") ==
        contains(":14: in_situ.stress must hold 3 numbers [sxx, syy, sxy] (Pa, tension positive), found 2"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, -1e6, 0]\nprincipal = [-1e6, -1e6]\n") ==
        contains("in_situ.stress and in_situ.principal are exclusive"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, -1e6, 0]\nangle = 30\n") ==
        contains(":15: in_situ.angle is the direction of principal[0]: it needs 'principal'"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, -1e6, 0]\nk_H = 1\n") ==
        contains(":15: in_situ.k_H belongs to the part that grows with depth: it needs 'datum'"));
  CHECK(error_of(kBase + "[in_situ]\ndatum = 10.0\n") ==
        contains(":13: [in_situ] is missing required key 'k_H'"));
  CHECK(error_of(kBase + "[in_situ]\ndatum = 10.0\nk_H = -1\n") ==
        contains(":15: in_situ.k_H = -1 is out of range (allowed: in_situ.k_H >= 0)"));
  CHECK(error_of(kBase + "[in_situ]\ndatum = 10.0\nk_H = 1\ndensity = 0\n") ==
        contains(":16: in_situ.density = 0 is out of range (allowed: in_situ.density > 0)"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, nan, 0]\n") == contains(":14:"));
  CHECK(error_of(kBase + "[in_situ]\nstres = [-1e6, -1e6, 0]\n") ==
        contains(":14: unknown key 'stres' in [in_situ] (did you mean 'stress'?)"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, -1e6, 0]\nk_x = 1\n") ==
        contains("unknown key 'k_x' in [in_situ]"));
  CHECK(error_of(kBase + "[in_situ]\nstress = [-1e6, -1e6, 0]\nstress_table = 1\n") ==
        contains("unknown key 'stress_table' in [in_situ]"));
}

TEST_CASE("[[boundary]] in_situ = true: needs [in_situ], one load per entry") {
  CaseDir d;
  const std::string held = "[in_situ]\nstress = [-1e6, -1e6, 0]\n[[boundary]]\nregion = \"top\"\nin_situ = true\n";
  CHECK(read_case(d.write("a.toml", kBase + held)).boundaries[0].in_situ);
  CHECK(error_of(kBase + "[[boundary]]\nregion = \"top\"\nin_situ = true\n") ==
        contains(":15: boundary[0].in_situ = true needs an [in_situ] table"));
  CHECK(error_of(kBase + held + "traction = [1.0, 0.0]\n") ==
        contains("boundary[0].traction and boundary[0].in_situ are exclusive"));
  CHECK(error_of(kBase + held + "fix = [\"x\"]\n") ==
        contains("boundary[0].in_situ cannot be combined with fix or velocity in one [[boundary]]"));
}

}  // TEST_SUITE
