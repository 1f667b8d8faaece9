// tests/approx.hpp: the tolerance helpers reject what doctest's Approx lets through on
// small figures, and accept what they should.
#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>

#include "approx.hpp"

using namespace fdem;

TEST_SUITE("approx") {

TEST_CASE("Approx's floor of 1 accepts any small figure; test::rel and test::abs_near do not") {
  // A 1e-9 m displacement against 2e-9 m (100% off) and against 0: doctest accepts both.
  CHECK(2e-9 == doctest::Approx(1e-9));
  CHECK(0.0 == doctest::Approx(1e-9).epsilon(1e-3));
  CHECK_FALSE(2e-9 == test::rel(1e-9, 1e-3));
  CHECK_FALSE(0.0 == test::rel(1e-9, 1e-3));
  CHECK_FALSE(test::abs_near(2e-9, 1e-9, 1e-12));
  CHECK_FALSE(test::abs_near(0.0, 1e-9, 1e-12));
}

TEST_CASE("test::rel: |x - e| <= tol |e|, both sides, signs, zero, NaN and infinity") {
  CHECK(1.0005e-9 == test::rel(1e-9, 1e-3));
  CHECK(0.9995e-9 == test::rel(1e-9, 1e-3));
  CHECK(test::rel(1e-9, 1e-3) == 1.0005e-9);
  CHECK(1.002e-9 != test::rel(1e-9, 1e-3));
  CHECK(0.998e-9 != test::rel(1e-9, 1e-3));
  CHECK(-1.0005e-9 == test::rel(-1e-9, 1e-3));
  CHECK(1e-9 != test::rel(-1e-9, 1e-3));
  CHECK(1e12 + 1.0 == test::rel(1e12, 1e-9));
  CHECK(1e12 + 1e4 != test::rel(1e12, 1e-9));
  // The scale is the expected value alone: rel(0, ...) takes only 0 (within DBL_MIN).
  CHECK(0.0 == test::rel(0.0, 1e-3));
  CHECK(1e-300 != test::rel(0.0, 1e-3));
  CHECK(std::nan("") != test::rel(1.0, 1e-3));
  CHECK(std::numeric_limits<double>::infinity() != test::rel(1e300, 1.0));
  // Exactly at the bound: accepted.
  CHECK(1.5 == test::rel(1.0, 0.5));
}

TEST_CASE("test::abs_near: |x - e| <= tol in the quantity's units; NaN and infinity fail") {
  CHECK(test::abs_near(1e-9 + 5e-13, 1e-9, 1e-12));
  CHECK(test::abs_near(-5e-13, 0.0, 1e-12));
  CHECK_FALSE(test::abs_near(2e-12, 0.0, 1e-12));
  CHECK_FALSE(test::abs_near(std::nan(""), 0.0, 1.0));
  CHECK_FALSE(test::abs_near(std::numeric_limits<double>::infinity(), 0.0, 1e300));
  CHECK(test::abs_near(0.25, 0.5, 0.25));  // at the bound
}

TEST_CASE("both print the values a failure is about") {
  std::ostringstream a, b;
  a << test::rel(1e-9, 1e-3);
  b << test::abs_near(2e-9, 1e-9, 1e-12);
  CHECK(a.str() == "rel(1.0000000000000001e-09 +- 0.001 rel = 1e-12)");
  CHECK(b.str() == "abs_near: actual 2.0000000000000001e-09, expected 1.0000000000000001e-09, |difference| 1e-09 vs tolerance 1e-12");
  CHECK(doctest::toString(test::rel(2.0, 0.5)) == "rel(2 +- 0.5 rel = 1)");
}

}
