// The Brazilian disc test end to end on a coarse disc (cases/brazilian). The case at full
// size, and the UCS specimen, are validation runs (validation/, `make validate`).
#include <doctest/doctest.h>

#include "case_measures.hpp"
#include "fixture.hpp"

using namespace fdem;

TEST_SUITE("fracture") {

TEST_CASE("a coarse Brazilian disc splits along the loaded diameter with a peak σ_t between 0.8 and 1.6 T_s, its energy account closing within 1%") {
  // The case's activation is "fractured": the couple across each CE4 takes part from the
  // start, so its faces' contact energy grows with the work done on them; switched on when
  // the CE4 broke (as before), it appeared from nothing and the error reached 1.3.
  //
  // The 3 mm disc with the platens 4 times faster than the case's (0.1 m/s each instead
  // of 0.025): the same platen travel in a quarter of the steps (80k instead of 274k;
  // the step is set by the CE4 penalties, not by the load). Still slow loading: the
  // peak comes at 0.37 ms, about 20 times the P wave's 18 µs across the disc. Measured
  // on PoCL: peak 1.20 T_s (1.145 at the case's speed), the crack spans the disc by
  // 0.44 ms; at 0.48 ms (as the case's speed stopped at 1.65 ms after a split at 1.51 ms)
  // 0.083 m of crack, all of it within 0.15 D of the loaded diameter, and a worst
  // energy_error of 3.3e-6. The checks and their bounds are those of the case's speed.
  test::TempDir dir;
  const RunSummary run = test::run(test::source_path("cases/brazilian/case.toml"),
                                   {"mesh.size=3e-3", "time.end=0.48e-3", "output.frames=2",
                                    "boundary.0.velocity=[0.0, -0.1]", "boundary.1.velocity=[0.0, 0.1]",
                                    "output.dir=\"" + dir.str() + "\""});
  const test::Splitting s = test::brazilian_splitting(dir.str());
  MESSAGE("coarse Brazilian: peak σ_t = " << s.peak_ratio << " T_s; " << 100 * s.near_diameter
                                          << "% of " << s.broken_length << " m of crack within 0.15 D of the diameter; worst energy_error "
                                          << run.worst_energy_error);
  CHECK(s.peak_ratio > 0.8);
  CHECK(s.peak_ratio < 1.6);
  CHECK(s.broken_length > 0.0517);
  CHECK(s.near_diameter > 0.5);
  CHECK(run.worst_energy_error < (kDoublePrecision ? 0.01 : 0.05));
}

}  // TEST_SUITE
