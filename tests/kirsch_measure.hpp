// The hoop stress at the wall of a circular tunnel (cases/tunnel-kirsch) from the last
// frame of its Exodus file, against Kirsch's σ_θθ = σ_H + σ_h − 2 (σ_H − σ_h) cos 2θ
// (compression positive, θ from the σ_H axis, x). Shared by tests/test_solver_excavation.cpp
// (a coarse mesh) and validation/runs.cpp (the case's own mesh). No doctest here: a figure
// that cannot be measured throws std::runtime_error.
#pragma once
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "case_files.hpp"

namespace fdem::test {

struct WallHoop {
  double angle = 0;     // θ [degrees]
  double measured = 0;  // σ_θθ at r = a [Pa], compression positive
  double kirsch = 0;    // [Pa], compression positive
  size_t triangles = 0; // triangles in the fit
  double error() const { return measured / kirsch - 1; }
};

// Solves the small symmetric system A c = b (Gaussian elimination with pivoting).
template <size_t N>
std::array<double, N> solve_small(std::array<std::array<double, N>, N> A, std::array<double, N> b) {
  for (size_t i = 0; i < N; ++i) {
    size_t p = i;
    for (size_t k = i + 1; k < N; ++k)
      if (std::fabs(A[k][i]) > std::fabs(A[p][i])) p = k;
    std::swap(A[i], A[p]);
    std::swap(b[i], b[p]);
    if (A[i][i] == 0) throw std::runtime_error("Kirsch fit: singular system (too few triangles at the wall)");
    for (size_t k = i + 1; k < N; ++k) {
      const double f = A[k][i] / A[i][i];
      for (size_t j = i; j < N; ++j) A[k][j] -= f * A[i][j];
      b[k] -= f * b[i];
    }
  }
  std::array<double, N> c{};
  for (size_t i = N; i-- > 0;) {
    double s = b[i];
    for (size_t j = i + 1; j < N; ++j) s -= A[i][j] * c[j];
    c[i] = s / A[i][i];
  }
  return c;
}

// The hoop stress at the wall (r = a, centre at the origin) at θ = `angle` degrees: the
// triangles of block 1 that are not excavated (EXCAVATED = 0) whose reference centroid is
// within `band` of the wall and within `window` degrees of θ give σ_θθ at their centroid
// (a TRI3's constant stress is its value there); a least-squares fit
// σ_θθ = c0 + c1 ρ + c2 ρ² + c3 (θ − θ₀)², ρ = (r − a)/a, extrapolates them to the wall,
// c0. (A constant in θ: σ_θθ varies as cos 2θ, flat at 0° and 90°, curved in r.)
inline WallHoop wall_hoop(const std::string& exo, double a, double sigma_H, double sigma_h, double angle,
                          double band, double window) {
  const auto x = read_variable(exo, "coordx"), y = read_variable(exo, "coordy");
  const auto c = read_variable(exo, "connect1");
  const auto sxx = last_element_values(exo, "SXX"), syy = last_element_values(exo, "SYY"),
             sxy = last_element_values(exo, "SXY"), gone = last_element_values(exo, "EXCAVATED");
  const double theta0 = angle * M_PI / 180;
  std::array<std::array<double, 4>, 4> A{};
  std::array<double, 4> b{};
  WallHoop h;
  h.angle = angle;
  for (size_t e = 0; 3 * e + 2 < c.size(); ++e) {
    if (gone[e] != 0) continue;
    double cx = 0, cy = 0;
    for (int k = 0; k < 3; ++k) cx += x[size_t(c[3 * e + k]) - 1] / 3, cy += y[size_t(c[3 * e + k]) - 1] / 3;
    const double r = std::hypot(cx, cy), theta = std::atan2(cy, cx);
    if (r < a || r > a + band || std::fabs(theta - theta0) > window * M_PI / 180) continue;
    const double s = std::sin(theta), co = std::cos(theta);
    const double hoop = -(sxx[e] * s * s + syy[e] * co * co - 2 * sxy[e] * s * co);  // compression positive
    const double rho = (r - a) / a, dt = theta - theta0;
    const std::array<double, 4> basis = {1, rho, rho * rho, dt * dt};
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) A[i][j] += basis[i] * basis[j];
      b[i] += basis[i] * hoop;
    }
    ++h.triangles;
  }
  if (h.triangles < 8) throw std::runtime_error("Kirsch fit: only " + std::to_string(h.triangles) + " triangles at the wall");
  h.measured = solve_small<4>(A, b)[0];
  h.kirsch = sigma_H + sigma_h - 2 * (sigma_H - sigma_h) * std::cos(2 * theta0);
  return h;
}

}  // namespace fdem::test
