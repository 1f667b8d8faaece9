// Case reader: [[boundary]] and [[initial]] rules (io/case_boundary_tables.cpp); the dynamic loads'
// keys are in tests/test_case_loads.cpp.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "case_reader_fixture.hpp"

namespace {

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::CaseConfig;
using fdem::io::read_case;
using namespace fdem::test::case_reader;

}  // namespace

TEST_SUITE("case") {

TEST_CASE("boundary rules") {
  const std::string b = kBase + "[[boundary]]\nregion = \"left\"\n";  // entry on line 13
  CHECK(error_of(b) == contains(":13: [[boundary]] #0 ('left') needs at least one of "
                                         "'fix', 'velocity', 'traction', 'pressure'"));
  CHECK(error_of(b + "traction = [0.0, 1.0]\npressure = 1.0\n") ==
        contains(":16: boundary[0].traction and boundary[0].pressure are exclusive"));
  CHECK(error_of(b + "fix = [\"x\"]\npressure = 1.0\n") ==
        contains(":16: boundary[0].pressure cannot be combined with fix or velocity"));
  CHECK(error_of(b + "velocity = [1.0, 0.0]\ntraction = [1.0, 0.0]\n") ==
        contains("boundary[0].traction cannot be combined with fix or velocity"));
  CHECK(error_of(b + "fix = [\"x\"]\nvelocity = [0.1, -1.0]\n") ==
        contains(":16: boundary[0].velocity[0] = 0.1 but boundary[0].fix holds \"x\" "
                          "still: it must be 0"));
  CHECK(error_of(b + "fix = [\"x\", \"z\"]\n") ==
        contains(":15: boundary[0].fix[1] = \"z\" is not an axis"));
  CHECK(error_of(b + "fix = [\"y\", \"y\"]\n") ==
        contains("boundary[0].fix lists \"y\" twice"));
  CHECK(error_of(b + "fix = [\"y\"]\nrise = 1.0\n") ==
        contains(":16: boundary[0].rise needs a velocity, traction or pressure"));
  CHECK(error_of(b + "pressure = 1.0\nrise = -1.0\n") ==
        contains("boundary[0].rise = -1 is out of range (allowed: boundary[0].rise >= 0)"));
  CHECK(error_of(b + "fix = [\"x\"]\nvelocity = [0.0, -1.0]\n") == "");
}

}  // TEST_SUITE("case")
