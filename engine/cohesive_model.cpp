#include "engine/cohesive_model.hpp"

#include <cmath>

namespace fdem {

double softening(double D, double a, double b, double c) {
  const double ab = a + b;
  const double decay = 1.0 - (ab - 1.0) / ab * std::exp(D * (a + c * b) / (ab * (1.0 - ab)));
  const double shape = a * (1.0 - D) + b * std::pow(1.0 - D, c);
  return decay * shape;
}

namespace {

struct SimpsonPanel {
  double lo, hi, f_lo, f_mid, f_hi, whole;
};

double simpson(double a, double b, double c, const SimpsonPanel& p, double tolerance, int depth) {
  const double mid = 0.5 * (p.lo + p.hi);
  const double left_mid = 0.5 * (p.lo + mid), right_mid = 0.5 * (mid + p.hi);
  const double f_lm = softening(left_mid, a, b, c), f_rm = softening(right_mid, a, b, c);
  const double h = p.hi - p.lo;
  const double left = h / 12.0 * (p.f_lo + 4.0 * f_lm + p.f_mid);
  const double right = h / 12.0 * (p.f_mid + 4.0 * f_rm + p.f_hi);
  const double diff = left + right - p.whole;
  if (depth <= 0 || std::fabs(diff) <= 15.0 * tolerance) return left + right + diff / 15.0;
  return simpson(a, b, c, {p.lo, mid, p.f_lo, f_lm, p.f_mid, left}, 0.5 * tolerance, depth - 1) +
         simpson(a, b, c, {mid, p.hi, p.f_mid, f_rm, p.f_hi, right}, 0.5 * tolerance, depth - 1);
}

}  // namespace

double softening_integral(double a, double b, double c) {
  const double f0 = softening(0.0, a, b, c), f1 = softening(1.0, a, b, c), fm = softening(0.5, a, b, c);
  return simpson(a, b, c, {0.0, 1.0, f0, fm, f1, (f0 + 4.0 * fm + f1) / 6.0}, 1e-12, 40);
}

}  // namespace fdem
