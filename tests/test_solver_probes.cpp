// [[probe]] history points: the values a run records against the same quantities in
// its Exodus frames.
#include <doctest/doctest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "approx.hpp"
#include "case_files.hpp"
#include "engine/run/run.hpp"
#include "fixture.hpp"
#include "probe_fixture.hpp"

using namespace fdem;
using test::bar_case;

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
  std::ostringstream every;
  every.precision(17);
  every << "output.history_every=" << stride_time;
  test::run(path, {every.str()});

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
      REQUIRE(row_times[row] == test::rel(frame_times[f], 1e-12));
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
