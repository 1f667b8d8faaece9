// The output schedules (engine/outputs/output.hpp, Trigger): what the run driver writes
// when, and which earlier records a restart copies over.
#include <doctest/doctest.h>

#include "engine/outputs/output.hpp"

using fdem::Trigger;

TEST_SUITE("restart") {

TEST_CASE("triggers: every N steps and the last; a restart copies only the schedule's records") {
  const Trigger rows = Trigger::every_steps(20, 689);
  CHECK_FALSE(rows.due(0, 0.0));  // no row at the initial state
  CHECK(rows.due(20, 0.0));
  CHECK_FALSE(rows.due(21, 0.0));
  CHECK(rows.due(689, 0.0));            // the run's last step
  CHECK_FALSE(rows.on_schedule(689));   // ... which a longer run does not write
  CHECK(rows.on_schedule(680));
}

TEST_CASE("triggers: listed steps") {
  const Trigger frames = Trigger::at_steps({0, 100, 250});
  CHECK(frames.due(0, 0.0));
  CHECK(frames.due(250, 0.0));
  CHECK_FALSE(frames.due(101, 0.0));
  CHECK(frames.on_schedule(100));
}

TEST_CASE("triggers: every T seconds moves on after each write, reckoned, never by additions") {
  const double dt = 1e-7;
  Trigger checkpoints = Trigger::every_seconds(4e-5, dt, 0.0);
  CHECK_FALSE(checkpoints.due(399, 399 * dt));
  CHECK(checkpoints.due(400, 400 * dt));  // 4e-5 within 1e-6 dt
  checkpoints.passed(400 * dt);
  CHECK_FALSE(checkpoints.due(401, 401 * dt));
  CHECK(checkpoints.due(800, 800 * dt));
  // A restart at 5e-5 s: the next is 8e-5 s.
  const Trigger resumed = Trigger::every_seconds(4e-5, dt, 500 * dt);
  CHECK_FALSE(resumed.due(700, 700 * dt));
  CHECK(resumed.due(800, 800 * dt));
  CHECK_FALSE(Trigger::every_seconds(0, dt, 0).due(1, 1.0));  // 0: none
}

TEST_CASE("triggers: any of others (the break catalogue: with rows and checkpoints)") {
  const Trigger rows = Trigger::every_steps(10, 95);
  const Trigger checkpoints = Trigger::at_steps({33});
  const Trigger breaks = Trigger::any_of({&rows, &checkpoints});
  CHECK(breaks.due(10, 0.0));
  CHECK(breaks.due(33, 0.0));
  CHECK(breaks.due(95, 0.0));
  CHECK_FALSE(breaks.due(34, 0.0));
}

}  // TEST_SUITE
