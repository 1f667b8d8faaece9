// contact_forces_lanes (eight or four work-items per couple, the GPUs' kernel) against
// contact_forces (one work-item per couple) with the same per-term force atomics: the same
// bits in positions, velocities and every energy term, on whichever device runs the suite
// (FDEM_CONTACT_LANES picks the kernel, FDEM_CONTACT_LANES_UP_TO the lanes kernel's
// threshold, for the solvers alike).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "case_files.hpp"
#include "engine/device/checkpoint.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "engine/stages/contact_activation.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

// Sets an environment variable (or removes it, for nullptr) until the end of its scope.
struct ScopedEnv {
  std::string name, saved;
  bool had = false;
  ScopedEnv(const char* variable, const char* value) : name(variable) {
    if (const char* before = std::getenv(variable)) {
      had = true;
      saved = before;
    }
    if (value)
      setenv(variable, value, 1);
    else
      unsetenv(variable);
  }
  ~ScopedEnv() {
    if (had)
      setenv(name.c_str(), saved.c_str(), 1);
    else
      unsetenv(name.c_str());
  }
};

// A solver built with FDEM_CONTACT_LANES=`lanes`, FDEM_CONTACT_LANES_UP_TO=`up_to` and
// FDEM_CONTACT_LANES_NARROW_FROM=`narrow_from` (nullptr: the default); all are read when
// the contact stage is built.
std::unique_ptr<Solver> solver_with_lanes(const PreparedCase& p, const char* lanes, const char* up_to = nullptr,
                                          const char* narrow_from = nullptr) {
  ScopedEnv use_lanes("FDEM_CONTACT_LANES", lanes), threshold("FDEM_CONTACT_LANES_UP_TO", up_to),
      narrow("FDEM_CONTACT_LANES_NARROW_FROM", narrow_from);
  return std::make_unique<Solver>(test::context(), p.model, p.dt);
}

// The same positions and velocities bit for bit, and the same energy terms.
void require_same_state(Solver& reference, Solver& other) {
  const auto x = reference.positions(), v = reference.velocities();
  REQUIRE(std::memcmp(x.data(), other.positions().data(), x.size() * sizeof(real2)) == 0);
  REQUIRE(std::memcmp(v.data(), other.velocities().data(), v.size() * sizeof(real2)) == 0);
  const EnergyTotals a = reference.energy(), b = other.energy();
  CHECK(a.kinetic == b.kinetic);
  CHECK(a.contact_stored == b.contact_stored);
  CHECK(a.friction == b.friction);
  CHECK(a.contact_damping == b.contact_damping);
  CHECK(a.stored() == b.stored());
  CHECK(a.dissipated() == b.dissipated());
}

// Steps four solvers `steps` steps (an energy row every 10th): contact_forces, the lanes
// kernel with eight work-items a couple, the lanes kernel with its narrow lanes (four
// work-items a couple, two passes each) and the lanes kernel above its threshold (one
// work-item a couple); compares them every 10 steps. Returns the number of touching
// couples seen at the comparisons.
long compare_kernels(const PreparedCase& p, int steps) {
  auto one = solver_with_lanes(p, "0"), lanes = solver_with_lanes(p, "1", "1000000"),
       narrow = solver_with_lanes(p, "1", "1000000", "0"), above = solver_with_lanes(p, "1", "0");
  long touching = 0;
  for (int s = 1; s <= steps; ++s) {
    for (Solver* solver : {one.get(), lanes.get(), narrow.get(), above.get()}) solver->step(s % 10 == 0);
    if (s % 10 != 0) continue;
    CAPTURE(s);
    for (Solver* other : {lanes.get(), narrow.get(), above.get()}) require_same_state(*one, *other);
    touching += static_cast<long>(one->contact()->touching());
  }
  return touching;
}

// Steps a solver with sleeping couples (the default) and one that classifies every couple
// every step (FDEM_CONTACT_SLEEPERS=0) `steps` steps; compares positions, velocities and
// the energy terms every 10 steps. Returns the sleeping solver's lean classifications.
long compare_sleepers(const PreparedCase& p, int steps) {
  std::unique_ptr<Solver> all, sleeping;
  {
    ScopedEnv off("FDEM_CONTACT_SLEEPERS", "0");
    all = std::make_unique<Solver>(test::context(), p.model, p.dt);
  }
  {
    ScopedEnv on("FDEM_CONTACT_SLEEPERS", nullptr);
    sleeping = std::make_unique<Solver>(test::context(), p.model, p.dt);
  }
  for (int s = 1; s <= steps; ++s) {
    all->step(s % 10 == 0);
    sleeping->step(s % 10 == 0);
    if (s % 10 != 0) continue;
    CAPTURE(s);
    require_same_state(*all, *sleeping);
    CHECK(all->contact()->touching() == sleeping->contact()->touching());
  }
  CHECK(all->contact()->lean_classifications() == 0);
  return sleeping->contact()->lean_classifications();
}

}  // namespace

TEST_SUITE("contact") {

TEST_CASE("sleeping couples change no bit: a blast that breaks, joins and slides") {
  // The coarse blasting case: intact for its first 50 steps (every step lean), then CE4s
  // break in most steps (full classifications) and in some not (lean ones, with pieces
  // touching and the couples of released CE4s awake).
  test::TempDir dir;
  const PreparedCase p = prepare_case(test::source_path("cases/blasting/case.toml"),
                                      {"mesh.size=0.04", "output.dir=\"" + dir.str() + "\""});
  const long lean = compare_sleepers(p, 400);
  MESSAGE("blasting, coarse: " << lean << " lean classifications in 400 steps");
  CHECK(lean > 50);
  CHECK(lean < 400);
}

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

TEST_CASE("activation on break (the CE4 stage marks the candidates) gives the separate launch's bits") {
  // The coarse blasting case (activation "fractured", couples listed ahead): CE4s break
  // from the 50th step on. A solver whose CE4 stage marks a breaking CE4's triangles
  // (the default here) against one that runs ContactActivation every step
  // (FDEM_ACTIVATE_ON_BREAK=0): the same candidate mask, positions, velocities and energy
  // terms. A checkpoint of the separate-launch solver after step 115, restored into a
  // folding one, continues with the same bits (its first step catches up on the CE4s
  // that broke in the step before the checkpoint).
  auto& cl = test::context();
  test::TempDir dir;
  const PreparedCase p = prepare_case(test::source_path("cases/blasting/case.toml"),
                                      {"mesh.size=0.04", "output.dir=\"" + dir.str() + "\""});
  REQUIRE(p.model.contact.list_ahead);
  REQUIRE(Solver::parts(p.model).activation_on_break);
  std::unique_ptr<Solver> launched, folded, resumed;
  {
    ScopedEnv off("FDEM_ACTIVATE_ON_BREAK", "0");
    CHECK_FALSE(Solver::parts(p.model).activation_on_break);
    launched = std::make_unique<Solver>(cl, p.model, p.dt);
  }
  {
    ScopedEnv on("FDEM_ACTIVATE_ON_BREAK", nullptr);
    folded = std::make_unique<Solver>(cl, p.model, p.dt);
  }
  const size_t triangles = p.model.num_triangles();
  long joined_late = 0, marked_ahead = 0;
  for (int s = 1; s <= 300; ++s) {
    launched->step(s % 10 == 0);
    folded->step(s % 10 == 0);
    if (resumed) resumed->step(s % 10 == 0);
    if (s == 115) {
      io::CheckpointData data;
      StateWriter out(cl, data);
      launched->save_state(out);
      resumed = std::make_unique<Solver>(cl, p.model, p.dt);
      StateReader in(cl, data, "in memory");
      resumed->load_state(in);
    }
    if (s % 10 != 0) continue;
    CAPTURE(s);
    const auto mask = download<cl_uint>(cl, launched->detection()->active_mask(), triangles);
    for (Solver* other : {folded.get(), resumed.get()}) {
      if (!other) continue;
      // The folding solvers marked the CE4s that broke in step s − 1 (0-based) already,
      // with join_stamp(s); the launch marks them at the start of step s.
      const auto other_mask = download<cl_uint>(cl, other->detection()->active_mask(), triangles);
      for (size_t t = 0; t < triangles; ++t) {
        if (mask[t] == other_mask[t]) continue;
        CAPTURE(t);
        REQUIRE(mask[t] == 0u);
        REQUIRE(other_mask[t] == ContactActivation::join_stamp(s));
        ++marked_ahead;
      }
      require_same_state(*launched, *other);
    }
    joined_late = std::count_if(mask.begin(), mask.end(), [](cl_uint m) { return m > 2; });
  }
  MESSAGE("blasting, coarse: " << joined_late << " triangles joined by breaks in 300 steps, "
                               << folded->cohesive()->count_broken() << " CE4s broken; " << marked_ahead
                               << " marked a step ahead at the comparisons");
  CHECK(joined_late > 50);
  CHECK(marked_ahead > 0);
}

}  // TEST_SUITE
