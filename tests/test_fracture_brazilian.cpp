// The Brazilian disc test end to end: a coarse disc in `make test`, the case's own mesh
// and the UCS specimen in `make validate`.
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>

#include "case_files.hpp"
#include "engine/run.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

struct Splitting {
  double peak_ratio = 0;     // peak σ_t / T_s
  double near_diameter = 0;  // fraction of the broken CE4 length within 0.15 D of x = 0
  double broken_length = 0;  // [m]
  double worst_energy_error = 0;  // largest |energy_error| of any history row
};

Splitting brazilian(const std::string& dir, const std::vector<std::string>& extra) {
  std::vector<std::string> overrides = extra;
  overrides.push_back("output.dir=\"" + dir + "\"");
  const PreparedCase p = prepare_case(test::source_path("cases/brazilian/case.toml"), overrides);
  std::ostringstream log;
  const RunSummary summary = run_case(p, test::context(), log, false);
  const double D = 0.0517, Ts = 1.77e6;
  Splitting s;
  s.worst_energy_error = summary.worst_energy_error;
  const auto force = test::read_variable(dir + "/brazilian_history.nc", "platen_top_force_y");
  for (double f : force) s.peak_ratio = std::max(s.peak_ratio, 2 * std::fabs(f) / (M_PI * D * 1.0) / Ts);
  const std::string exo = dir + "/brazilian.exo";
  const auto x = test::read_variable(exo, "coordx"), y = test::read_variable(exo, "coordy");
  const int cohesive_block = 3;  // rock, steel, cohesive
  const auto conn = test::read_variable(exo, "connect" + std::to_string(cohesive_block));
  const auto broken = test::last_element_values(exo, "BROKEN", cohesive_block);
  double near = 0;
  for (size_t e = 0; e < broken.size(); ++e) {
    if (broken[e] < 0.5) continue;
    const size_t i = size_t(conn[4 * e]) - 1, j = size_t(conn[4 * e + 1]) - 1;
    const double length = std::hypot(x[j] - x[i], y[j] - y[i]);
    s.broken_length += length;
    if (std::fabs(0.5 * (x[i] + x[j])) < 0.15 * D) near += length;
  }
  s.near_diameter = s.broken_length > 0 ? near / s.broken_length : 0;
  return s;
}

}  // namespace

TEST_SUITE("fracture") {

TEST_CASE("a coarse Brazilian disc splits along the loaded diameter with a peak σ_t between 0.8 and 1.6 T_s, its energy account closing within 1%") {
  // The case's activation is "fractured": the couple across each CE4 takes part from the
  // start, so its faces' contact energy grows with the work done on them; switched on when
  // the CE4 broke (as before), it appeared from nothing and the error reached 1.3.
  test::TempDir dir;
  const Splitting s = brazilian(dir.str(), {"mesh.size=3e-3", "time.end=1.65e-3", "output.frames=2"});
  MESSAGE("coarse Brazilian: peak σ_t = " << s.peak_ratio << " T_s; " << 100 * s.near_diameter
                                          << "% of " << s.broken_length << " m of crack within 0.15 D of the diameter; worst energy_error "
                                          << s.worst_energy_error);
  CHECK(s.peak_ratio > 0.8);
  CHECK(s.peak_ratio < 1.6);
  CHECK(s.broken_length > 0.0517);
  CHECK(s.near_diameter > 0.5);
  CHECK(s.worst_energy_error < (kDoublePrecision ? 0.01 : 0.05));
}

}  // TEST_SUITE

TEST_SUITE("validation") {

TEST_CASE("Brazilian disc on the case's own 0.7 mm mesh") {
  const std::string dir = test::source_path("out/validate/brazilian");
  const Splitting s = brazilian(dir, {});
  MESSAGE("Brazilian: peak σ_t = " << s.peak_ratio << " T_s; " << 100 * s.near_diameter << "% of "
                                   << s.broken_length << " m of crack within 0.15 D of the diameter; worst energy_error "
                                   << s.worst_energy_error);
  CHECK(s.peak_ratio > 0.8);
  CHECK(s.peak_ratio < 1.6);
  CHECK(s.near_diameter > 0.5);
  CHECK(s.worst_energy_error < 0.01);
}

TEST_CASE("uniaxial compression to post-peak") {
  const std::string dir = test::source_path("out/validate/ucs");
  const PreparedCase p = prepare_case(test::source_path("cases/ucs/case.toml"), {"output.dir=\"" + dir + "\""});
  std::ostringstream log;
  run_case(p, test::context(), log, false);
  const auto force = test::read_variable(dir + "/ucs_history.nc", "platen_top_force_y");
  double peak = 0;
  for (double f : force) peak = std::max(peak, std::fabs(f) / 0.0517);
  const double last = std::fabs(force.back()) / 0.0517;
  MESSAGE("UCS: peak " << peak / 1e6 << " MPa, last " << last / 1e6 << " MPa");
  CHECK(peak > 10e6);
  CHECK(last < 0.7 * peak);  // post-peak drop
}

}  // TEST_SUITE
