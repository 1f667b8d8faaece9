// Case keys of the dynamic boundary loads: blast, pressure tables, absorbing edges.
#include <doctest/doctest.h>

#include <string>

#include "case_files.hpp"
#include "base/errors.hpp"
#include "io/case_config.hpp"

namespace {

// A valid case up to its [[boundary]] entry on the last line (line 13); what a test
// appends starts on line 15.
const std::string kCase =
    "[mesh]\nfile = \"m.msh\"\n[time]\ndt = 1.0\nend = 10.0\n"
    "[[material]]\nname = \"rock\"\nregions = [\"rock\"]\ndensity = 2000.0\nyoung = 1e9\npoisson = 0.25\n"
    "\n[[boundary]]\nregion = \"hole\"\n";

fdem::io::CaseConfig read(const std::string& keys, const std::vector<std::string>& overrides = {}) {
  fdem::test::TempDir dir;
  dir.write("m.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
  return fdem::io::read_case(dir.write("c.toml", kCase + keys), overrides);
}

std::string error_of(const std::string& keys) {
  try {
    read(keys);
  } catch (const fdem::InputError& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& piece) { return text.find(piece) != std::string::npos; }

}  // namespace

TEST_SUITE("case") {

TEST_CASE("blast, pressure table and absorbing keys are read") {
  const auto blast = read("blast = { peak = 1.0e9, rise = 100e-6, ratio = 1.5 }\n").boundaries.at(0);
  REQUIRE(blast.blast);
  CHECK(blast.blast->peak == 1.0e9);
  CHECK(blast.blast->rise == 100e-6);
  CHECK(blast.blast->ratio == 1.5);
  CHECK(!blast.pressure);
  const auto table = read("pressure = { times = [0.0, 1e-4, 2e-4], values = [0, 5e6, 0] }\n").boundaries.at(0);
  REQUIRE(table.pressure_table);
  CHECK(table.pressure_table->times == std::vector<double>{0.0, 1e-4, 2e-4});
  CHECK(table.pressure_table->values == std::vector<double>{0.0, 5e6, 0.0});
  CHECK(!table.pressure);
  CHECK(read("absorbing = true\n").boundaries.at(0).absorbing);
  CHECK(*read("pressure = 2e6\n").boundaries.at(0).pressure == 2e6);
  // --set reaches inside blast.
  const auto set = read("blast = { peak = 1.0e9, rise = 100e-6, ratio = 1.5 }\n", {"boundary.0.blast.peak=2e9"});
  CHECK(set.boundaries.at(0).blast->peak == 2e9);
}

TEST_CASE("bad blast, pressure table and absorbing entries are errors naming the line and key") {
  CHECK(has(error_of("blast = { peak = 1.0e9, rise = 100e-6, ratio = 1.0 }\n"),
            "boundary[0].blast.ratio = 1 is out of range (allowed: boundary[0].blast.ratio > 1)"));
  CHECK(has(error_of("blast = { peek = 1.0e9, rise = 100e-6, ratio = 1.5 }\n"), "did you mean 'peak'"));
  CHECK(has(error_of("blast = { peak = 1.0e9, ratio = 1.5 }\n"), "is missing required key 'rise'"));
  CHECK(has(error_of("blast = { peak = 1.0e9, rise = 1e-4, ratio = 1.5 }\nrise = 1e-4\n"),
            ":16: boundary[0].rise needs a velocity, traction or pressure to ramp (a blast has its own rise"));
  CHECK(has(error_of("pressure = { times = [0.0, 1e-4], values = [1.0] }\n"),
            "boundary[0].pressure: times has 2 entries but values has 1"));
  CHECK(has(error_of("pressure = { times = [0.0, 2e-4, 1e-4], values = [0, 1, 2] }\n"),
            "boundary[0].pressure.times must increase: times[2] = 0.0001 follows 0.0002"));
  CHECK(has(error_of("pressure = { times = [0.0, 1e-4], value = [0, 1] }\n"), "did you mean 'values'"));
  CHECK(has(error_of("pressure = \"high\"\n"), ":15: boundary[0].pressure must be a number or a table"));
  CHECK(has(error_of("pressure = { times = [0.0, 1e-4], values = [0, 1] }\nrise = 1.0\n"),
            "a pressure table gives the time dependence itself"));
  CHECK(has(error_of("absorbing = true\npressure = 1e6\n"), "boundary[0].pressure and boundary[0].absorbing are exclusive"));
  CHECK(has(error_of("absorbing = true\nblast = { peak = 1.0e9, rise = 100e-6, ratio = 1.5 }\n"),
            "boundary[0].blast and boundary[0].absorbing are exclusive"));
  CHECK(has(error_of("absorbing = true\nfix = [\"x\"]\n"), "boundary[0].absorbing cannot be combined with fix or velocity"));
  CHECK(has(error_of("absorbing = 1\n"), "boundary[0].absorbing must be a boolean"));
  CHECK(has(error_of("absorbing = false\n"), "needs at least one of"));
  CHECK(has(error_of("absorbng = true\n"), "did you mean 'absorbing'"));
}

}  // TEST_SUITE
