// Figures read from the output of the cases in cases/: what the unit tests check on small
// versions and the validation driver (validation/) on the full ones, computed once here.
// No doctest in this header: a figure that cannot be measured throws std::runtime_error.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "case_files.hpp"

namespace fdem::test {

// ---- cases/geostatic: equilibrium stresses of the column -------------------------------

// Element centroids' reference y of block 1.
inline std::vector<double> centroid_y(const std::string& exo) {
  const auto y = read_variable(exo, "coordy");
  const auto c = read_variable(exo, "connect1");
  std::vector<double> out;
  for (size_t e = 0; e + 2 < c.size(); e += 3)
    out.push_back((y[size_t(c[e]) - 1] + y[size_t(c[e + 1]) - 1] + y[size_t(c[e + 2]) - 1]) / 3);
  return out;
}

// Largest miss of σyy = −ρg(100 − y) and σxx = ν/(1 − ν) σyy over the element centroids
// at the last frame, as fractions of ρg·100 (cases/geostatic/README.md, "How to check").
struct GeostaticErrors {
  size_t elements = 0;
  double worst_yy = 0, worst_xx = 0;
};

inline GeostaticErrors geostatic_errors(const std::string& exo) {
  const auto sxx = last_element_values(exo, "SXX");
  const auto syy = last_element_values(exo, "SYY");
  const auto yc = centroid_y(exo);
  const double rho = 1800, g = 9.806, nu = 0.25, scale = rho * g * 100;
  GeostaticErrors e;
  e.elements = yc.size();
  for (size_t k = 0; k < yc.size(); ++k) {
    const double exact = -rho * g * (100 - yc[k]);
    e.worst_yy = std::max(e.worst_yy, std::fabs(syy[k] - exact));
    e.worst_xx = std::max(e.worst_xx, std::fabs(sxx[k] - nu / (1 - nu) * exact));
  }
  e.worst_yy /= scale;
  e.worst_xx /= scale;
  return e;
}

// ---- cases/brazilian: how the disc split -----------------------------------------------

struct Splitting {
  double peak_ratio = 0;     // peak σ_t = 2F/(πDt) over T_s
  double near_diameter = 0;  // fraction of the broken CE4 length within 0.15 D of x = 0
  double broken_length = 0;  // [m]
};

// From OUT/brazilian_history.nc (the top platen's force) and the last frame of
// OUT/brazilian.exo (broken CE4s of the cohesive block; blocks rock, steel, cohesive).
inline Splitting brazilian_splitting(const std::string& dir) {
  const double D = 0.0517, Ts = 1.77e6, thickness = 1.0;
  Splitting s;
  const auto force = read_variable(dir + "/brazilian_history.nc", "platen_top_force_y");
  for (double f : force) s.peak_ratio = std::max(s.peak_ratio, 2 * std::fabs(f) / (M_PI * D * thickness) / Ts);
  const std::string exo = dir + "/brazilian.exo";
  const auto x = read_variable(exo, "coordx"), y = read_variable(exo, "coordy");
  const int cohesive_block = 3;
  const auto conn = read_variable(exo, "connect" + std::to_string(cohesive_block));
  const auto broken = last_element_values(exo, "BROKEN", cohesive_block);
  double near = 0;
  for (size_t e = 0; e < broken.size(); ++e) {
    if (broken[e] < 0.5) continue;
    const size_t i = size_t(conn[4 * e]) - 1, j = size_t(conn[4 * e + 1]) - 1;
    const double length = std::hypot(x[j] - x[i], y[j] - y[i]);
    s.broken_length += length;
    if (std::fabs(0.5 * (x[i] + x[j])) < 0.15 * D) near += length;
  }
  s.near_diameter = s.broken_length > 0 ? near / s.broken_length : 0;
  return s;
}

// ---- cases/wave-bar, cases/blasting, cases/wave-penalty: apparent P-wave speeds ---------
// The velocity at a station is the time derivative of its mean displacement (history);
// the front arrives when that velocity first reaches a fraction of its largest value
// (half for the plane wave of the bar; 10% for the blast, whose cylindrical pulse
// changes shape as it spreads, so that only its leading edge keeps its speed), and the
// speed is the least-squares slope of station distance against arrival time (so the
// source's own delay, the pulse's rise, drops out).

constexpr double kWaveTheory = 5000.0;  // √((λ+2μ)/ρ), E 60 GPa, ν 0.25, ρ 2880 kg/m³, plane strain

// First time the station's velocity du/dt reaches `fraction` of its largest value
// (linear interpolation between history rows); -1 if it never rises.
inline double arrival_time(const std::vector<double>& t, const std::vector<double>& u, double fraction) {
  std::vector<double> tv, v;
  for (size_t k = 0; k + 1 < t.size(); ++k) {
    tv.push_back(0.5 * (t[k] + t[k + 1]));
    v.push_back((u[k + 1] - u[k]) / (t[k + 1] - t[k]));
  }
  double peak = 0;
  for (double x : v) peak = std::max(peak, x);
  if (peak <= 0) return -1;
  const double level = fraction * peak;
  for (size_t k = 1; k < v.size(); ++k)
    if (v[k] >= level) return tv[k - 1] + (tv[k] - tv[k - 1]) * (level - v[k - 1]) / (v[k] - v[k - 1]);
  return -1;
}

struct SpeedFit {
  double speed = 0;
  std::vector<double> arrivals;
};

// Least-squares slope of distance against arrival time over the stations; throws when a
// station never saw the wave.
inline SpeedFit fit_speed(const std::string& history, const std::vector<std::string>& variables,
                          const std::vector<double>& distances, double fraction) {
  const auto t = read_variable(history, "time");
  SpeedFit fit;
  double mt = 0, mx = 0;
  for (size_t k = 0; k < variables.size(); ++k) {
    fit.arrivals.push_back(arrival_time(t, read_variable(history, variables[k]), fraction));
    if (fit.arrivals.back() <= 0) throw std::runtime_error(history + ": " + variables[k] + " never saw the wave");
    mt += fit.arrivals[k] / variables.size(), mx += distances[k] / variables.size();
  }
  double stt = 0, stx = 0;
  for (size_t k = 0; k < variables.size(); ++k)
    stt += (fit.arrivals[k] - mt) * (fit.arrivals[k] - mt), stx += (fit.arrivals[k] - mt) * (distances[k] - mx);
  fit.speed = stx / stt;
  return fit;
}

// The wave bar's stations s1 … s5 at x = 0.5 … 2.5 m, fronts at half the peak velocity.
inline SpeedFit wave_bar_speed(const std::string& history) {
  return fit_speed(history, {"s1_disp_x", "s2_disp_x", "s3_disp_x", "s4_disp_x", "s5_disp_x"}, {0.5, 1.0, 1.5, 2.0, 2.5}, 0.5);
}

// The blasting stations at 1, 2, 3 m (and 4 m when `far`) on the x and y axes; the
// distance is from the hole's wall (radius 0.05 m), though only differences matter.
inline SpeedFit blast_speed(const std::string& history, bool far, double fraction = 0.1) {
  std::vector<std::string> vars;
  std::vector<double> r;
  for (int k = 1; k <= (far ? 4 : 3); ++k)
    for (const char* axis : {"x", "y"}) {
      vars.push_back(std::string(axis) + std::to_string(k) + "_disp_" + axis);
      r.push_back(k - 0.05);
    }
  return fit_speed(history, vars, r, fraction);
}

}  // namespace fdem::test
