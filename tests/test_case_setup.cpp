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
