// The probe tests' case: a 1 m × 0.2 m strip of tests/data/cases/bar.geo, pulled at its
// left end, with [[probe]] entries appended (tests/test_case_probes.cpp,
// tests/test_solver_probes.cpp).
#pragma once
#include <string>

#include "case_files.hpp"

namespace fdem::test {

inline std::string bar_case(const std::string& out, const std::string& probes) {
  return "[mesh]\ngeo = \"" + source_path("tests/data/cases/bar.geo") +
         "\"\nsize = 0.05\n[time]\ndt = \"auto\"\nsteps = 200\n[output]\ndir = \"" + out +
         "\"\nframes = 5\n"
         "[[material]]\nname = \"rock\"\nregions = [\"bar\"]\ndensity = 2000.0\nyoung = 10e9\npoisson = 0.2\n"
         "[[boundary]]\nregion = \"left\"\nvelocity = [0.2, 0.05]\n" + probes;
}

}  // namespace fdem::test
