// Jaeger's single plane of weakness (cases/jaeger): the peak σ1 of a specimen loaded by
// pressures, from its events file, against the formula. Shared by tests/test_joints.cpp
// (coarse angles) and validation/runs.cpp (the series). No doctest here: a figure that
// cannot be measured throws std::runtime_error.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "case_files.hpp"
#include "io/case_config.hpp"

namespace fdem::test {

// σ1 at which a joint of cohesion c and friction angle φ, its normal at β from σ1,
// slips under σ3 (compression positive, Pa, degrees): σ3 + 2 (c + μ σ3) / ((1 − μ cot β)
// sin 2β); +inf where it cannot slip (β ≤ φ or β ≥ 90°).
inline double jaeger_strength(double beta, double sigma3, double cohesion, double phi) {
  const double pi = std::acos(-1.0), b = beta * pi / 180, mu = std::tan(phi * pi / 180);
  const double denominator = (1 - mu / std::tan(b)) * std::sin(2 * b);
  if (!(beta > phi && beta < 90) || !(denominator > 0)) return std::numeric_limits<double>::infinity();
  return sigma3 + 2 * (cohesion + mu * sigma3) / denominator;
}

// The pressure of a [[boundary]] on `region` at time t: its table, linear between points,
// held before the first and after the last (docs/case-format.md).
inline double boundary_pressure(const io::CaseConfig& config, const std::string& region, double t) {
  for (const auto& b : config.boundaries) {
    if (b.region != region || !b.pressure_table) continue;
    const auto& times = b.pressure_table->times;
    const auto& values = b.pressure_table->values;
    if (t <= times.front()) return values.front();
    for (size_t k = 1; k < times.size(); ++k)
      if (t <= times[k]) return values[k - 1] + (values[k] - values[k - 1]) * (t - times[k - 1]) / (times[k] - times[k - 1]);
    return values.back();
  }
  throw std::runtime_error("the case has no pressure table on '" + region + "'");
}

struct JaegerPeak {
  double sigma1 = 0;      // [Pa] σ1 applied (pressure on "top") when the specimen gave
  double time = 0;        // [s] that time
  size_t breaks = 0;      // CE4s broken by the end of the run
  size_t joint_breaks = 0;  // of them on the joint
  bool on_joint = false;  // the breaks that made the peak were mostly the joint's
};

// The specimen gives when `count` CE4s have broken (the joint's CE4s all see the same
// stress and go together; the rock's go in a burst): σ1 is the "top" pressure at the time
// of the count-th break of the events file.
inline JaegerPeak jaeger_peak(const std::string& events_file, const io::CaseConfig& config, size_t count) {
  const auto time = read_variable(events_file, "break_time");
  const auto joint = read_variable(events_file, "break_joint");
  JaegerPeak p;
  p.breaks = time.size();
  for (double j : joint) p.joint_breaks += j >= 0;
  if (time.size() < count)
    throw std::runtime_error(events_file + ": " + std::to_string(time.size()) + " breaks, fewer than the " +
                             std::to_string(count) + " that mark the peak (run longer)");
  p.time = time[count - 1];
  p.sigma1 = boundary_pressure(config, "top", p.time);
  size_t on = 0;
  for (size_t k = 0; k < count; ++k) on += joint[k] >= 0;
  p.on_joint = 2 * on > count;
  return p;
}

}  // namespace fdem::test
