// Expected values of the validation figures: the comparisons and how they print.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "validation.hpp"

namespace fdem::validation {

Expect below(double limit) { return {Expect::Kind::Below, limit, 0}; }
Expect above(double limit) { return {Expect::Kind::Above, limit, 0}; }
Expect between(double low, double high) { return {Expect::Kind::Between, low, high}; }
Expect equal(double expected) { return {Expect::Kind::Equal, expected, 0}; }
Expect approx(double expected, double epsilon) { return {Expect::Kind::Approx, expected, epsilon}; }

bool Expect::holds(double value) const {
  switch (kind) {
    case Kind::Below: return value < a;
    case Kind::Above: return value > a;
    case Kind::Between: return a < value && value < b;
    case Kind::Equal: return value == a;
    case Kind::Approx: return std::fabs(value - a) < b * (1.0 + std::max(std::fabs(value), std::fabs(a)));
  }
  return false;
}

std::string Expect::text() const {
  std::ostringstream out;
  out.precision(6);
  switch (kind) {
    case Kind::Below: out << "< " << a; break;
    case Kind::Above: out << "> " << a; break;
    case Kind::Between: out << "between " << a << " and " << b; break;
    case Kind::Equal: out << "= " << a; break;
    case Kind::Approx: out << "≈ " << a << ": |diff| < " << b << " (1 + the larger)"; break;
  }
  return out.str();
}

}  // namespace fdem::validation
