// The wave cases end to end (cases/wave-bar, cases/blasting): a wave-bar run and a coarse
// blast. The paper's blasting model at full size (Section 3.4, Figs. 17–19) and the
// fracturable wave bar are validation runs (validation/, `make validate`). Apparent
// P-wave speeds and arrival times: tests/case_measures.hpp.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "case_files.hpp"
#include "case_measures.hpp"
#include "engine/run/run.hpp"
#include "fixture.hpp"

using namespace fdem;

TEST_SUITE("waves") {

TEST_CASE("wave-bar case (gmsh mesh, no CE4): the front travels at V_p within 0.5%") {
  test::TempDir dir;
  test::run(test::source_path("cases/wave-bar/case.toml"), {"output.dir=\"" + dir.str() + "\""});
  const test::SpeedFit fit = test::wave_bar_speed(dir.str() + "/wave-bar_history.nc");
  MESSAGE("wave-bar case: V_p = " << fit.speed << " m/s (" << 100 * (fit.speed / test::kWaveTheory - 1) << "% from 5000 m/s)");
  CHECK(std::fabs(fit.speed / test::kWaveTheory - 1) < 0.005);
}

TEST_CASE("contact takes no part in intact rock: the CE4 wave bar with contact on everywhere is bitwise the bar without") {
  // The two triangles of an intact CE4 and two triangles meeting at a corner of an intact,
  // bonded fan are held by the CE4s; contact adding its penalty to their compressive
  // overlap made the rock stiffer (before 2026-12-02 this bar's s3 displacement moved by
  // 7e-8 m of 8e-8 m, with 3,352 touching couples).
  test::TempDir plain, with_contact;
  const std::vector<std::string> common = {"mesh.size=0.02", "time.end=300e-6"};
  auto args = [&](const test::TempDir& d, bool contact) {
    std::vector<std::string> a = common;
    a.push_back("output.dir=\"" + d.str() + "\"");
    if (contact) a.insert(a.end(), {"contact.normal_penalty=500e9", "contact.friction=0.5", "contact.activation=\"all\""});
    return a;
  };
  test::run(test::source_path("cases/wave-bar/ce4.toml"), args(plain, false));
  test::run(test::source_path("cases/wave-bar/ce4.toml"), args(with_contact, true));
  const std::string a = plain.str() + "/wave-bar-ce4_history.nc", b = with_contact.str() + "/wave-bar-ce4_history.nc";
  for (const char* v : {"s1_disp_x", "s3_disp_x", "s5_disp_x", "kinetic_energy", "strain_energy", "cohesive_stored_energy"}) {
    CAPTURE(v);
    CHECK(test::read_variable(a, v) == test::read_variable(b, v));
  }
  double most = 0;
  for (double c : test::read_variable(b, "contact_couples")) most = std::max(most, c);
  MESSAGE("touching couples at most " << most);
  CHECK(most == 0);
  CHECK(test::read_variable(b, "s3_disp_x").back() > 0);  // the wave got there
}

TEST_CASE("loaded and absorbing edges on split fracturable nodes belong to their own triangle, body on the left") {
  test::TempDir dir;
  const PreparedCase p = prepare_case(test::source_path("cases/wave-bar/ce4.toml"), {"output.dir=\"" + dir.str() + "\""});
  const Model& m = p.model;
  REQUIRE(!m.ce4.empty());
  std::map<std::pair<int, int>, int> ccw_edges;  // (a, b) in a triangle's counter-clockwise order → triangle
  for (size_t t = 0; t < m.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k) ccw_edges[{m.triangles[t][k], m.triangles[t][(k + 1) % 3]}] = static_cast<int>(t);
  int absorbing = 0;
  for (const auto& e : m.loaded_edges) {
    CHECK(ccw_edges.count({e.a, e.b}) == 1);
    if (m.loads[e.load].kind == LoadKind::Absorbing) {
      ++absorbing;
      CHECK(m.loads[e.load].material == 0);
      CHECK(m.x[e.a] == doctest::Approx(3.0));
      CHECK(m.x[e.b] == doctest::Approx(3.0));
    }
  }
  CHECK(absorbing == 5);  // the right end, 5 cm at 1 cm elements
}

TEST_CASE("coarse blast: the hole pushes the rock outwards and the front reaches the stations in order") {
  test::TempDir dir;
  const auto s = test::run(test::source_path("cases/blasting/case.toml"),
                           {"mesh.size=0.05", "time.end=450e-6", "output.every=150e-6", "output.dir=\"" + dir.str() + "\""});
  CHECK(s.steps > 1000);
  const std::string history = dir.str() + "/blasting_history.nc";
  const auto t = test::read_variable(history, "time");
  double previous = 0;
  for (const char* station : {"x1_disp_x", "x2_disp_x"}) {
    CAPTURE(station);
    const auto u = test::read_variable(history, station);
    CHECK(u.back() > 0);  // outwards
    const double arrival = test::arrival_time(t, u, 0.1);
    CHECK(arrival > previous);
    previous = arrival;
  }
  // The crushed and cracked zone: CE4s break around the hole.
  const auto broken = test::read_variable(history, "broken_ce4");
  MESSAGE("coarse blast: " << broken.back() << " broken CE4s at " << t.back() * 1e6 << " µs");
  CHECK(broken.back() > 10);
}

}  // TEST_SUITE
