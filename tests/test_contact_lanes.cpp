// contact_forces_lanes (eight work-items per couple, the GPUs' kernel) against
// contact_forces (one work-item per couple) with the same per-term force atomics: the same
// bits in positions, velocities and every energy term, on whichever device runs the suite
// (FDEM_CONTACT_LANES picks the kernel, for both solvers alike).
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

// A solver built with FDEM_CONTACT_LANES=`lanes` (the variable is read when the contact
// stage is built, so it is set only around the construction).
std::unique_ptr<Solver> solver_with_lanes(const PreparedCase& p, const char* lanes) {
  const char* before = std::getenv("FDEM_CONTACT_LANES");
  const std::string saved = before ? before : "";
  setenv("FDEM_CONTACT_LANES", lanes, 1);
  auto solver = std::make_unique<Solver>(test::context(), p.model, p.dt);
  if (before)
    setenv("FDEM_CONTACT_LANES", saved.c_str(), 1);
  else
    unsetenv("FDEM_CONTACT_LANES");
  return solver;
}

// Steps both kernels' solvers `steps` steps (an energy row every 10th) and compares them
// every 10 steps; returns the number of touching couples seen at the comparisons.
long compare_kernels(const PreparedCase& p, int steps) {
  auto one = solver_with_lanes(p, "0"), lanes = solver_with_lanes(p, "1");
  long touching = 0;
  for (int s = 1; s <= steps; ++s) {
    one->step(s % 10 == 0);
    lanes->step(s % 10 == 0);
    if (s % 10 != 0) continue;
    CAPTURE(s);
    const auto x = one->positions(), v = one->velocities();
    REQUIRE(std::memcmp(x.data(), lanes->positions().data(), x.size() * sizeof(real2)) == 0);
    REQUIRE(std::memcmp(v.data(), lanes->velocities().data(), v.size() * sizeof(real2)) == 0);
    const EnergyTotals a = one->energy(), b = lanes->energy();
    CHECK(a.kinetic == b.kinetic);
    CHECK(a.contact_stored == b.contact_stored);
    CHECK(a.friction == b.friction);
    CHECK(a.contact_damping == b.contact_damping);
    CHECK(a.stored() == b.stored());
    CHECK(a.dissipated() == b.dissipated());
    touching += static_cast<long>(one->contact()->touching());
  }
  return touching;
}

}  // namespace

TEST_SUITE("contact") {

TEST_CASE("contact_forces_lanes gives contact_forces' bits: a breaking blast with friction and joins") {
  // The coarse blasting case (about 4,300 TRI3, activation "fractured"): CE4s break from
  // the 50th step on and the pieces touch and slide.
  test::TempDir dir;
  const PreparedCase p = prepare_case(test::source_path("cases/blasting/case.toml"),
                                      {"mesh.size=0.04", "output.dir=\"" + dir.str() + "\""});
  const long touching = compare_kernels(p, 300);
  MESSAGE("blasting, coarse: " << touching << " touching couples over the 30 comparisons");
  CHECK(touching > 100);
}

TEST_CASE("contact_forces_lanes gives contact_forces' bits: a damped impact (An-Tannant, b = 2)") {
  test::TempDir dir;
  const PreparedCase p = prepare_case(test::source_path("cases/impact/case.toml"),
                                      {"mesh.size=0.02", "contact.damping={exponent=2.0}",
                                       "output.dir=\"" + dir.str() + "\""});
  const long touching = compare_kernels(p, 1200);
  MESSAGE("impact, b = 2: " << touching << " touching couples over the 120 comparisons");
  CHECK(touching > 100);
}

}  // TEST_SUITE
