// Launches folded into others give the same bits: the boundary loads in the triangle
// stage's launch (BoundaryLoads::bind_tail, BOUNDARY_TAIL in triangle_forces.cl) against
// their own launch (FDEM_BOUNDARY_FUSED=0), on the load kinds whose kernel branches are
// built only on request (blast pressure and absorbing edges; the in-situ tractions; the
// gas's hole), with the output's stress pass, which must not load the edges again, in
// between. (The CE4 stage's activation on break: tests/test_contact_lanes.cpp.)
#include <doctest/doctest.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "case_files.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

// A Solver of `p` built with FDEM_BOUNDARY_FUSED=`fused` (the variable restored after).
std::unique_ptr<Solver> solver_with(const PreparedCase& p, const char* fused) {
  const char* before = std::getenv("FDEM_BOUNDARY_FUSED");
  const std::string saved = before ? before : "";
  setenv("FDEM_BOUNDARY_FUSED", fused, 1);
  auto solver = std::make_unique<Solver>(test::context(), p.model, p.dt);
  if (before)
    setenv("FDEM_BOUNDARY_FUSED", saved.c_str(), 1);
  else
    unsetenv("FDEM_BOUNDARY_FUSED");
  return solver;
}

// Steps both `steps` steps (an energy row every 10th, a stress pass every 25th) and
// compares positions, velocities and the energy terms every 10; returns the load work
// and absorbed energy at the end.
std::pair<double, double> compare_fused(const PreparedCase& p, int steps) {
  REQUIRE(p.model.loaded_edges.size() > 0);
  auto own = solver_with(p, "0"), fused = solver_with(p, "1");
  for (int s = 1; s <= steps; ++s) {
    for (Solver* solver : {own.get(), fused.get()}) solver->step(s % 10 == 0);
    if (s % 25 == 0) {
      for (Solver* solver : {own.get(), fused.get()}) solver->enqueue_stress();
      const auto a = own->stresses(), b = fused->stresses();
      REQUIRE(a.size() == b.size());
      CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(real4)) == 0);
      for (Solver* solver : {own.get(), fused.get()}) solver->release_output();
    }
    if (s % 10 != 0) continue;
    CAPTURE(s);
    const auto x = own->positions(), v = own->velocities();
    REQUIRE(std::memcmp(x.data(), fused->positions().data(), x.size() * sizeof(real2)) == 0);
    REQUIRE(std::memcmp(v.data(), fused->velocities().data(), v.size() * sizeof(real2)) == 0);
    const EnergyTotals a = own->energy(), b = fused->energy();
    CHECK(a.load_work == b.load_work);
    CHECK(a.absorbed == b.absorbed);
    CHECK(a.stored() == b.stored());
    CHECK(a.dissipated() == b.dissipated());
  }
  const EnergyTotals e = fused->energy();
  return {e.load_work, e.absorbed};
}

}  // namespace

TEST_SUITE("solver") {

TEST_CASE("boundary loads in the triangle stage's launch give their own launch's bits") {
  test::TempDir dir;
  const std::string out = "output.dir=\"" + dir.str() + "\"";
  SUBCASE("blast pressure and absorbing edges (blasting, coarse)") {
    const auto [work, absorbed] =
        compare_fused(prepare_case(test::source_path("cases/blasting/case.toml"), {"mesh.size=0.1", out}), 200);
    CHECK(work > 0);
    CHECK(absorbed > 0);
  }
  SUBCASE("in-situ tractions (tunnel, excavated)") {
    const auto [work, absorbed] =
        compare_fused(prepare_case(test::source_path("tests/data/cases/tunnel_small.toml"), {out}), 200);
    CHECK(work != 0);
    (void)absorbed;
  }
  SUBCASE("the gas's hole (small gas blast)") {
    const PreparedCase p = prepare_case(test::source_path("tests/data/cases/gas_small.toml"), {out});
    REQUIRE(p.model.fluid.gas);
    const auto [work, absorbed] = compare_fused(p, 200);
    CHECK(work > 0);
    (void)absorbed;
  }
}

}  // TEST_SUITE
