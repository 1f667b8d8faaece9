#include "engine/model/cohesive_model.hpp"

#include <cmath>

#include "base/errors.hpp"
#include "base/format.hpp"

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

// Adaptive Simpson with a depth limit and a budget of evaluations: a curve that is not
// finite (a, b, c so large that a + b overflows) or will not converge throws instead of
// recursing 2^depth times.
double simpson(double a, double b, double c, const SimpsonPanel& p, double tolerance, int depth, long& budget) {
  const double mid = 0.5 * (p.lo + p.hi);
  const double left_mid = 0.5 * (p.lo + mid), right_mid = 0.5 * (mid + p.hi);
  const double f_lm = softening(left_mid, a, b, c), f_rm = softening(right_mid, a, b, c);
  if (!std::isfinite(f_lm) || !std::isfinite(f_rm))
    throw NumericalError("softening curve (a = " + format_number(a, 15) + ", b = " + format_number(b, 15) +
                         ", c = " + format_number(c, 15) + ") is not finite at D = " +
                         format_number(std::isfinite(f_lm) ? right_mid : left_mid, 6) +
                         ": I_f cannot be computed");
  if ((budget -= 2) < 0)
    throw NumericalError("softening curve (a = " + format_number(a, 15) + ", b = " + format_number(b, 15) +
                         ", c = " + format_number(c, 15) + "): I_f did not converge within " +
                         std::to_string(kSofteningPanels) + " evaluations");
  const double h = p.hi - p.lo;
  const double left = h / 12.0 * (p.f_lo + 4.0 * f_lm + p.f_mid);
  const double right = h / 12.0 * (p.f_mid + 4.0 * f_rm + p.f_hi);
  const double diff = left + right - p.whole;
  if (depth <= 0 || std::fabs(diff) <= 15.0 * tolerance) return left + right + diff / 15.0;
  return simpson(a, b, c, {p.lo, mid, p.f_lo, f_lm, p.f_mid, left}, 0.5 * tolerance, depth - 1, budget) +
         simpson(a, b, c, {mid, p.hi, p.f_mid, f_rm, p.f_hi, right}, 0.5 * tolerance, depth - 1, budget);
}

}  // namespace

double softening_integral(double a, double b, double c) {
  const double f0 = softening(0.0, a, b, c), f1 = softening(1.0, a, b, c), fm = softening(0.5, a, b, c);
  if (!std::isfinite(f0) || !std::isfinite(f1) || !std::isfinite(fm))
    throw NumericalError("softening curve (a = " + format_number(a, 15) + ", b = " + format_number(b, 15) +
                         ", c = " + format_number(c, 15) + ") is not finite on [0, 1]: I_f cannot be computed");
  long budget = kSofteningPanels;
  return simpson(a, b, c, {0.0, 1.0, f0, fm, f1, (f0 + 4.0 * fm + f1) / 6.0}, 1e-12, 40, budget);
}

std::string softening_curve_problem(double a, double b, double c) {
  constexpr int kSamples = 1000;
  constexpr double kRoundOff = 1e-9;
  double previous = 0;
  for (int k = 0; k <= kSamples; ++k) {
    const double D = double(k) / kSamples, f = softening(D, a, b, c);
    const std::string at = "f(" + format_number(D, 4) + ") = " + format_number(f, 6);
    if (!std::isfinite(f)) return "the curve is not finite: " + at;
    if (k == 0 && std::fabs(f - 1.0) > kRoundOff) return "the curve does not start at f(0) = 1: " + at;
    if (k == kSamples && std::fabs(f) > kRoundOff) return "the curve does not end at f(1) = 0: " + at;
    if (k > 0 && f > previous + kRoundOff)
      return "the curve rises: f(" + format_number(D - 1.0 / kSamples, 4) + ") = " + format_number(previous, 6) +
             " < " + at;
    if (f < -kRoundOff) return "the curve goes below 0: " + at;
    previous = f;
  }
  try {
    const double integral = softening_integral(a, b, c);
    if (!(integral > 0)) return "its integral I_f = " + format_number(integral, 6) + " is not positive";
  } catch (const NumericalError& e) {
    return e.what();
  }
  return "";
}

size_t cohesive_property_sets(const CohesiveModel& model) {
  size_t sets = model.fracture.size();
  for (const auto& f : model.strength_factor) sets += (f[0] != 1.0 || f[1] != 1.0) ? 1 : 0;
  return sets;
}

}  // namespace fdem
