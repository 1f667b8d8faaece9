// Tolerance checks whose tolerance is the one written.
//
// doctest's Approx(v).epsilon(e) accepts |x - v| < e * (scale + max(|x|, |v|)) with
// scale 1 by default: an absolute floor of e. On figures well below 1 (a 1e-6 m
// displacement, a 1e-7 J energy, a stress in MPa·1e-6 units) that floor is the whole
// tolerance, and `x == Approx(1e-9)` passes for any x within 1e-5 of it, zero included.
// Use these instead (see ARCHITECTURE.md, "Tests"):
//
//   CHECK(x == test::rel(expected, 1e-6));            // |x - e| <= 1e-6 * |e|, no floor
//   CHECK(test::abs_near(x, expected, 1e-12));        // |x - e| <= 1e-12, stated in units
//
// Both print the actual value, the expected one, the difference and the allowed one
// when they fail.
#pragma once
#include <cfloat>
#include <cmath>
#include <iomanip>
#include <ostream>

namespace fdem::test {

// A relative check: |actual - expected| <= tol * max(|expected|, DBL_MIN). The scale is
// the expected value alone (not the larger of the two, not 1 + it), so rel(0, ...) accepts
// only 0 (up to DBL_MIN): compare with zero through abs_near and a tolerance in units.
struct Rel {
  double expected;
  double tol;
  double allowed() const { return tol * std::fmax(std::fabs(expected), DBL_MIN); }
  bool accepts(double actual) const {
    return std::isfinite(actual) && std::fabs(actual - expected) <= allowed();
  }
};

inline Rel rel(double expected, double rel_tol) { return Rel{expected, rel_tol}; }

inline bool operator==(double actual, const Rel& r) { return r.accepts(actual); }
inline bool operator==(const Rel& r, double actual) { return r.accepts(actual); }
inline bool operator!=(double actual, const Rel& r) { return !r.accepts(actual); }
inline bool operator!=(const Rel& r, double actual) { return !r.accepts(actual); }

inline std::ostream& operator<<(std::ostream& os, const Rel& r) {
  const auto flags = os.flags();
  const auto prec = os.precision();
  os << std::setprecision(17) << "rel(" << r.expected << " +- " << std::setprecision(3) << r.tol
     << " rel = " << r.allowed() << ")";
  os.flags(flags);
  os.precision(prec);
  return os;
}

// An absolute check with the tolerance in the quantity's units. Converts to bool; doctest
// prints it (both values, the difference, the tolerance) when the check fails.
struct Near {
  double actual;
  double expected;
  double tol;
  explicit operator bool() const {
    return std::isfinite(actual) && std::fabs(actual - expected) <= tol;
  }
};

inline Near abs_near(double actual, double expected, double abs_tol) { return Near{actual, expected, abs_tol}; }

inline std::ostream& operator<<(std::ostream& os, const Near& n) {
  const auto flags = os.flags();
  const auto prec = os.precision();
  os << std::setprecision(17) << "abs_near: actual " << n.actual << ", expected " << n.expected
     << std::setprecision(3) << ", |difference| " << std::fabs(n.actual - n.expected) << " vs tolerance "
     << n.tol;
  os.flags(flags);
  os.precision(prec);
  return os;
}

}  // namespace fdem::test
