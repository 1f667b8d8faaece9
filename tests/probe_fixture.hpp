// The probe tests' case: a 1 m × 0.2 m strip of tests/data/cases/bar.geo, pulled at its
// left end, with [[probe]] entries appended (tests/test_case_probes.cpp,
// tests/test_solver_probes.cpp).
#pragma once
#include <string>

#include "case_files.hpp"

namespace fdem::test {

inline std::string bar_case(const std::string& out, const std::string& probes) {
  BarCase c;
  c.title = "";
  c.time = "dt = \"auto\"\nsteps = 200\n";
  c.output = "dir = \"" + out + "\"\nframes = 5\n";
  c.rest = "[[boundary]]\nregion = \"left\"\nvelocity = [0.2, 0.05]\n" + probes;
  return c.text();
}

}  // namespace fdem::test
