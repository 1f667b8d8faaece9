// Case reader: the key schema (io/case_schema.cpp) and its suggestions for misspelt names, and the
// one edit distance (io/suggest.hpp).
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "case_reader_fixture.hpp"
#include "io/suggest.hpp"

namespace {

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::CaseConfig;
using fdem::io::read_case;
using namespace fdem::test::case_reader;

}  // namespace

TEST_SUITE("case") {

TEST_CASE("unknown keys and tables suggest the nearest name") {
  CaseDir d;
  const std::string path = d.write("c.toml", with(kBase, "young =", "youngs ="));
  CHECK_THROWS_WITH_AS(
      read_case(path),
      contains(path + ":11: unknown key 'youngs' in [[material]] (did you mean 'young'?)"),
      InputError);
  CHECK(error_of(kBase + "[gravty]\ng = [0.0, -9.8]\n") ==
        contains(":13: unknown table [gravty] (did you mean [gravity]?)"));
  CHECK(error_of(with(kBase, "[[material]]", "[[materials]]")) ==
        contains(":7: unknown table [[materials]] (did you mean [[material]]?)"));
  CHECK(error_of(with(kBase, "end = 10.0", "ned = 10.0")) ==
        contains(":6: unknown key 'ned' in [time] (did you mean 'end'?)"));
  CHECK(error_of(with(kBase, "title", "titel")) ==
        contains(":1: unknown key 'titel' (did you mean 'title'?)"));
  const doctest::String far = error_of(kBase + "colour = \"red\"\n");
  CHECK(far == contains(":13: unknown key 'colour' in [[material]]"));
  CHECK(std::string(far.c_str()).find("did you mean") == std::string::npos);
}

TEST_CASE("one edit distance: case files ignore letter case, mesh names do not") {
  using fdem::io::LetterCase;
  using fdem::io::edit_distance;
  using fdem::io::nearest_name;
  CHECK(edit_distance("", "") == 0);
  CHECK(edit_distance("young", "") == 5);
  CHECK(edit_distance("kitten", "sitting") == 3);
  CHECK(edit_distance("youngs", "young") == 1);
  CHECK(edit_distance("Young", "young") == 1);
  CHECK(edit_distance("Young", "young", LetterCase::Ignored) == 0);
  CHECK(edit_distance("GRAVTY", "gravity", LetterCase::Ignored) == 1);
  // The nearest within max(2, length / 3) edits, the first of equally near ones.
  const std::vector<std::string> names{"rock", "rack", "platen_top"};
  CHECK(nearest_name("rocc", names) == "rock");
  CHECK(nearest_name("ROCK", names).empty());
  CHECK(nearest_name("ROCK", names, LetterCase::Ignored) == "rock");
  CHECK(nearest_name("platen_tp", names) == "platen_top");
  CHECK(nearest_name("granite", names).empty());
  CHECK(nearest_name("x", std::vector<std::string>{}).empty());
  CHECK(fdem::io::did_you_mean("rok", names) == " (did you mean 'rock'?)");
  CHECK(fdem::io::did_you_mean("granite", names).empty());
}

}  // TEST_SUITE("case")
