#include "engine/model/in_situ.hpp"

#include <algorithm>
#include <cmath>

#include "base/format.hpp"

namespace fdem {

InSituGaps in_situ_gaps(const InSituField& field, const FractureProperties& f, std::array<double, 2> a,
                        std::array<double, 2> b, std::string& problem) {
  InSituGaps g;
  problem.clear();
  const double h = std::hypot(b[0] - a[0], b[1] - a[1]);
  // The kernel's frame (cohesive_forces.cl): t along a → b, n = t turned clockwise, away
  // from triangle 1; the traction on triangle 1's face is σ₀ n = σ n + τ t.
  const double tx = (b[0] - a[0]) / h, ty = (b[1] - a[1]) / h, nx = ty, ny = -tx;
  const double sp = 2.0 * h * f.cohesion / f.penalty_sliding;
  const double oov = 2.0 * h * f.tensile_strength / f.penalty_overlap;
  const double k_fric = 2.0 * f.cohesion / sp;
  const double tan_phi = std::tan(f.friction_angle * std::acos(-1.0) / 180.0);
  const double r = 0.3872983346207417;
  const double xi[3] = {0.5 - r, 0.5, 0.5 + r};
  for (int k = 0; k < 3; ++k) {
    const double x = (1 - xi[k]) * a[0] + xi[k] * b[0], y = (1 - xi[k]) * a[1] + xi[k] * b[1];
    const auto s = field.at(y);
    const double scale = std::max({std::fabs(s[0]), std::fabs(s[1]), std::fabs(s[2])});
    const double tn_x = s[0] * nx + s[2] * ny, tn_y = s[2] * nx + s[1] * ny;
    double sigma = tn_x * nx + tn_y * ny;
    const double tau = tn_x * tx + tn_y * ty;
    const std::string at = " at (" + format_number(x, 6) + ", " + format_number(y, 6) + ") m";
    if (sigma > 1e-12 * scale) {
      problem = "the field pulls the CE4 faces apart: normal stress " + format_number(sigma, 6) + " Pa (tension)" + at +
                "; a CE4 holds an in-situ stress on its compression branch only";
      return g;
    }
    sigma = std::min(sigma, 0.0);
    // Compression branch (Eq. 13): σ = 2 o T_s / o_overlap.
    g.opening[k] = sigma * oov / (2.0 * f.tensile_strength);
    // Shear: cohesive part (2q - q²) c (q = |s|/s_p ≤ 1) plus the friction element's stick
    // spring k_f (s - s_f) = 2 q c while below its cap tanφ |σ|; at the cap the element
    // has slipped and the cohesive part carries the rest.
    const double cap = tan_phi * -sigma, c = f.cohesion, mag = std::fabs(tau);
    double q = -1;
    double friction = 0;
    bool stuck = false;
    if (mag <= 3.0 * c) {
      const double stick = 2.0 - std::sqrt(std::max(0.0, 4.0 - mag / c));
      if (2.0 * stick * c <= cap) q = stick, stuck = true;
    }
    if (q < 0 && mag - cap <= c) {
      q = 1.0 - std::sqrt(std::max(0.0, 1.0 - (mag - cap) / c));
      friction = cap;
    }
    if (q < 0) {
      problem = "the field's shear stress " + format_number(tau, 6) + " Pa on the CE4" + at +
                " exceeds what it holds before softening, c + min(2c, tanφ |σ_n|) = " +
                format_number(c + std::min(2.0 * c, cap), 6) + " Pa (σ_n = " + format_number(sigma, 6) + " Pa)";
      return g;
    }
    const double sign = tau < 0 ? -1.0 : 1.0;
    g.slip[k] = sign * q * sp;
    g.friction_slip[k] = stuck ? 0.0 : g.slip[k] - sign * friction / k_fric;
  }
  return g;
}

}  // namespace fdem
