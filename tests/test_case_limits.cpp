// Case reader: values the parser returns but the run cannot take (issue 28): subnormal
// numbers, step and frame counts that do not fit, names the output files cannot hold,
// softening curves the CE4 law cannot integrate. Each is refused with the key, its file
// and line (or its --set), before anything is allocated from it.
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "approx.hpp"
#include "base/errors.hpp"
#include "case_reader_fixture.hpp"
#include "engine/model/cohesive_model.hpp"

namespace {

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::CaseConfig;
using fdem::io::read_case;
using namespace fdem::test::case_reader;

// The InputError of read_case with these overrides, "" if none.
doctest::String error_with(const std::string& text, const std::vector<std::string>& overrides) {
  CaseDir d;
  try {
    read_case(d.write("c.toml", text), overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_SUITE("case") {

TEST_CASE("subnormal and absurd magnitudes are refused with the key, in the file and from --set (issue 28, rows 1 and 8)") {
  // kBase has 12 lines: [gravity] on line 13, g on line 14.
  CHECK(error_of(kBase + "[gravity]\ng = [0.0, -1e-310]\n") ==
        contains(":14: gravity.g[1] = -1e-310 is out of range (allowed: 0, or 1e-30 <= |gravity.g[1]| <= 1e+30; "
                 "subnormal numbers are refused: no quantity of a case in SI units lies outside"));
  CHECK(error_with(kBase, {"gravity.g=[0.0,-1e-310]"}) ==
        contains("c.toml (from --set gravity.g=[0.0,-1e-310]): gravity.g[1] = -1e-310 is out of range"));
  CHECK(error_of(with(kBase, "2000.0", "4.9e-324")) ==
        contains(":10: material[0].density = 5e-324 is out of range (allowed: 0, or"));
  CHECK(error_with(kBase, {"time.dt=1e-315"}) == contains("(from --set time.dt=1e-315): time.dt = 1e-315 is out of range"));
  // dt = 1e308 with mass scaling ran one step to a NaN state and exit 0.
  CHECK(error_with(kBase, {"time.dt=1e308"}) ==
        contains("(from --set time.dt=1e308): time.dt = 1e+308 is out of range (allowed: 0, or 1e-30 <= |time.dt| <= "
                 "1e+30: no quantity"));
  CHECK(error_of(with(kBase, "1e9", "1e31")) == contains(":11: material[0].young = 1e+31 is out of range"));
  CHECK(error_of(with(kBase, "0.25", "1e-31")) == contains(":12: material[0].poisson = 1e-31 is out of range"));
  // The limits themselves and zero are numbers like any other.
  CaseDir d;
  const CaseConfig c = read_case(d.write("c.toml", kBase + "[gravity]\ng = [1e-30, -1e30]\n"));
  CHECK(c.gravity.g[0] == 1e-30);
  CHECK(c.settings.at("gravity.g") == "[1e-30, -1e+30]");
  CHECK(c.origin.at("gravity.g") == d.path("c.toml") + ":14");
  CHECK(read_case(d.write("z.toml", kBase + "[gravity]\ng = [0.0, -0.0]\n")).gravity.g[1] == 0.0);
}

TEST_CASE("inf and nan are refused for every number, from --set too (issue 28, rows 8 and 12)") {
  CHECK(error_with(kBase, {"time.dt=inf"}) == contains("(from --set time.dt=inf): time.dt must be finite, found inf"));
  CHECK(error_with(kBase, {"time.end=nan"}) == contains("(from --set time.end=nan): time.end must be finite"));
  CHECK(error_with(kBase, {"gravity.g=[-inf,0.0]"}) == contains("gravity.g[0] must be finite, found -inf"));
  // A literal too large for a double is a syntax error at its line and column.
  CHECK(error_of(with(kBase, "end = 10.0", "end = 1e400")) ==
        contains(":6:12: Error while parsing floating-point: '1e400' could not be interpreted as a value"));
}

TEST_CASE("a step count beyond 2^53 or an infinite end time is refused, naming the key (issue 28, row 8)") {
  CHECK(error_with(kBase, {"time.end=1e19"}) ==
        contains("(from --set time.end=1e19): time.end = 1e+19 s at time.dt = 1 s is 1e+19 steps, more than "
                 "the limit of 2^53 = 9007199254740992 steps"));
  CHECK(error_of(with(kBase, "end = 10.0", "end = 1e25")) == contains(":6: time.end = 1e+25 s at time.dt = 1 s"));
  CHECK(error_of(with(with(kBase, "end = 10.0", "end = 1.0"), "dt = 1.0", "dt = 1e-20")) ==
        contains(":6: time.end = 1 s at time.dt = 1e-20 s is 1e+20 steps, more than the limit"));
  CHECK(error_of(with(kBase, "end = 10.0", "steps = 9007199254740993")) ==
        contains(":6: time.steps = 9007199254740993 is more than the limit of 2^53 = 9007199254740992 steps"));
  // An infinite end time (unreachable through the magnitude limit, kept as a guard).
  CaseDir e;
  CaseConfig ten = read_case(e.write("c.toml", with(kBase, "end = 10.0", "steps = 10")));
  CHECK_THROWS_WITH_AS(fdem::io::run_steps(ten, 1e308),
                       contains(":6: the run's end time, 10 steps × time.dt = 1e+308 s, is not a finite number"),
                       InputError);
  // At the limit it is a count like any other (frames = 20 by default: a long run has them).
  CaseDir d;
  CHECK(fdem::io::run_steps(read_case(d.write("c.toml", with(kBase, "end = 10.0", "end = 9007199254740992.0"))),
                            1.0) == fdem::io::kMaxSteps);
  const CaseConfig c = read_case(d.write("c.toml", kBase));
  CHECK(fdem::io::run_steps(c, 1.0) == 10);
  CHECK(fdem::io::run_steps(c, 3.0) == 4);  // rounded up
  // With dt = "auto" the run checks its own dt: a stable step of 1e-20 s for 1e-1 s.
  const CaseConfig automatic = read_case(d.write("a.toml", with(with(kBase, "dt = 1.0", "dt = \"auto\""), "end = 10.0", "end = 0.1")));
  CHECK_THROWS_WITH_AS(fdem::io::run_steps(automatic, 1e-20),
                       contains(d.path("a.toml") + ":6: time.end = 0.1 s at time.dt = 1e-20 s (\"auto\") is 1e+19 steps"),
                       InputError);
}

TEST_CASE("frames: at most 10^6, refused before any schedule is built (issue 28, row 10); more than steps + 1 is a frame a step") {
  // kBase runs 10 steps of 1 s; [output] on line 13, frames on line 14.
  const auto started = std::chrono::steady_clock::now();
  CHECK(error_of(kBase + "[output]\nframes = 2147483647\n") ==
        contains(":14: output.frames = 2147483647 is more than the limit of 1000000 frames"));
  CHECK(std::chrono::steady_clock::now() - started < std::chrono::seconds(1));
  CHECK(error_of(kBase + "[output]\nframes = 12\n") == "");  // a frame after every step: 11
  CHECK(error_of(kBase + "[output]\nframes = 11\n") == "");
  CHECK(error_of(kBase) == "");  // the default 20 frames of a 10-step run: the 11 it has
  CHECK(error_with(with(kBase, "end = 10.0", "end = 2e6"), {"output.frames=1000001"}) ==
        contains("(from --set output.frames=1000001): output.frames = 1000001 is more than the limit of 1000000 "
                 "frames"));
  // With dt = "auto" the step count waits for the mesh, the limit of 10^6 does not.
  const std::string automatic = with(kBase, "dt = 1.0", "dt = \"auto\"");
  CHECK(error_with(automatic, {"output.frames=2147483647"}) ==
        contains("(from --set output.frames=2147483647): output.frames = 2147483647 is more than the limit of 1000000"));
  CHECK(error_with(automatic, {"output.frames=1000"}) == "");
  CHECK(error_with(with(automatic, "end = 10.0", "steps = 10"), {"output.frames=12"}) == "");
  // output.every: one frame a step at most, and the count is the one the run would write.
  CHECK(error_of(kBase + "[output]\nevery = 1e-9\n") == "");
  CHECK(error_of(with(kBase, "end = 10.0", "end = 2e6") + "[output]\nevery = 1.0\n") ==
        contains(":14: output.every = 1 s gives 2000001 frames (one every 1 steps at time.dt = 1 s), which is more "
                 "than the limit of 1000000 frames"));
  CHECK(error_of(kBase + "[output]\nevery = 1e20\n") ==
        contains(":14: output.every = 1e+20 s at time.dt = 1 s is 1e+20 steps, more than the limit"));
  CHECK(error_of(kBase + "[output]\nhistory_every = 1e20\n") ==
        contains(":14: output.history_every = 1e+20 s at time.dt = 1 s is 1e+20 steps, more than the limit"));
}

TEST_CASE("output.name is one file name: no separators, control characters, . or .., at most 200 bytes (issue 28, row 11)") {
  // [output] on line 13, name on line 14.
  CHECK(error_of(kBase + "[output]\nname = \"../../x\"\n") ==
        contains(":14: output.name = \"../../x\" holds a path separator: it is the base name of files inside "
                 "output.dir"));
  CHECK(error_of(kBase + "[output]\nname = \"/tmp/x\"\n") == contains(":14: output.name = \"/tmp/x\" holds a path separator"));
  CHECK(error_of(kBase + "[output]\nname = 'a\\b'\n") == contains(":14: output.name = \"a\\\\b\" holds a path separator"));
  CHECK(error_of(kBase + "[output]\nname = \"a\\nb\"\n") ==
        contains(":14: output.name = \"a\\nb\" holds a control character (byte 0x0a)"));
  CHECK(error_of(kBase + "[output]\nname = \"..\"\n") == contains(":14: output.name = \"..\" is a directory, not a file name"));
  CHECK(error_of(kBase + "[output]\nname = \".\"\n") == contains(":14: output.name = \".\" is a directory"));
  CHECK(error_of(kBase + "[output]\nname = \"\"\n") == contains(":14: output.name = \"\" must not be empty"));
  CHECK(error_of(kBase + "[output]\nname = \"" + std::string(201, 'n') + "\"\n") ==
        contains(":14: output.name = \"" + std::string(201, 'n') + "\" is 201 bytes long, more than the limit of 200"));
  CHECK(error_with(kBase, {"output.name=../x"}) == contains("(from --set output.name=../x): output.name = \"../x\" holds"));
  CHECK(error_of(kBase + "[output]\nname = \"" + std::string(200, 'n') + "\"\n") == "");
  CHECK(error_of(kBase + "[output]\nname = \"run 2 (soft)\"\n") == "");
  // The default, the case file's stem, obeys the same rule.
  CaseDir d;
  const std::string odd = d.write("two\nlines.toml", kBase);
  CHECK_THROWS_WITH_AS(read_case(odd),
                       contains("output.name is not given, and the case file's stem \"two\\nlines\", its default, holds "
                                "a control character (byte 0x0a): a name is one line of printable characters: give "
                                "output.name"),
                       InputError);
  CHECK(read_case(odd, {"output.name=fine"}).output.name == "fine");
}

TEST_CASE("material names the Exodus writer cannot hold are refused at read time (issue 28, rows 2, 3 and 12)") {
  // name on line 8.
  CHECK(error_of(with(kBase, "\"rock\"\n", "\"granite_from_the_north_quarry_2024\"\n")) ==
        contains(":8: material[0].name = \"granite_from_the_north_quarry_2024\" is 34 bytes long, more than the 32 "
                 "that fit in an Exodus block name"));
  CHECK(error_with(kBase, {"material.0.name=granite_from_the_north_quarry_2024"}) ==
        contains("(from --set material.0.name=granite_from_the_north_quarry_2024): material[0].name"));
  CHECK(error_of(with(kBase, "\"rock\"\n", "\"" + std::string(32, 'g') + "\"\n")) == "");
  CHECK(error_of(with(kBase, "\"rock\"\n", "\"cohesive\"\n")) ==
        contains(":8: material[0].name = \"cohesive\" is reserved: the Exodus file names its block of cohesive "
                 "elements (CE4s) \"cohesive\""));
  CHECK(error_with(kBase + kFracture, {"material.0.name=cohesive"}) ==
        contains("(from --set material.0.name=cohesive): material[0].name = \"cohesive\" is reserved"));
  CHECK(error_of(with(kBase, "\"rock\"\n", "\"ro\\tck\"\n")) ==
        contains(":8: material[0].name = \"ro\\tck\" holds a control character (byte 0x09)"));
}

TEST_CASE("names that history variables cannot hold: probes and regions (issue 28, row 12)") {
  const std::string long_name(253, 'p');
  CHECK(error_of(kBase + "[[probe]]\nname = \"" + long_name + "\"\npoint = [0.0, 0.0]\n") ==
        contains(":14: probe[0].name is 253 characters long, more than the 252 that its history variables"));
  const std::string long_region(247, 'r');
  CHECK(error_of(kBase + "[[boundary]]\nregion = \"" + long_region + "\"\nfix = [\"x\"]\n") ==
        contains(":14: boundary[0].region: region name \"rrrr"));
  CHECK(error_of(kBase + "[[boundary]]\nregion = \"" + long_region + "\"\nfix = [\"x\"]\n") ==
        contains("is 247 bytes long, more than the 246 that history variable names leave for it"));
  CHECK(error_of(kBase + "[output]\nregions = [\"" + long_region + "\"]\n") == contains(":14: output.regions: region name"));
}

TEST_CASE("softening curves the CE4 law cannot use are refused; the integral never recurses on NaN (issue 28, row 7)") {
  // kBase + kFracture: what a test appends starts on line 20, inside [material.fracture].
  const auto started = std::chrono::steady_clock::now();
  // The a = b = 1e308 is out of the magnitude range; within it, a + b can still
  // be so large that f(0) cancels to 0.
  CHECK(error_of(kBase + kFracture + "softening = { a = 1e308, b = 1e308 }\n") ==
        contains(":20: material[0].fracture.softening.a = 1e+308 is out of range"));
  CHECK(error_of(kBase + kFracture + "softening = { a = 1e20, b = 1e20 }\n") ==
        contains(":20: material[0].fracture.softening = { a = 1e+20, b = 1e+20, c = 6 } is not a softening curve "
                 "the CE4 law can use (Eq. 10: f falls from 1 at D = 0 to 0 at D = 1): the curve does not start at "
                 "f(0) = 1"));
  CHECK(error_of(kBase + kFracture + "softening = { a = 1000, b = 1000, c = 1000 }\n") ==
        contains("the curve rises: f(0) = 1 < f(0.001) ="));
  CHECK(error_with(kBase + kFracture, {"material.0.fracture.softening={a=1e20,b=1e20}"}) ==
        contains("(from --set material.0.fracture.softening={a=1e20,b=1e20}): material[0].fracture.softening = "
                 "{ a = 1e+20, b = 1e+20, c = 6 } is not a softening curve"));
  CHECK(error_of(kBase + kFracture + "softening = { a = 0.5, b = 2.0, c = 3.0 }\n") == "");
  CHECK(fdem::softening_curve_problem(0.63, 1.8, 6.0) == "");
  // The integrator on its own: a NaN curve throws at once instead of splitting 2^40 panels.
  CHECK_THROWS_AS(fdem::softening_integral(1e308, 1e308, 6.0), fdem::NumericalError);
  CHECK_THROWS_WITH(fdem::softening_integral(1e308, 1e308, 6.0), contains("is not finite"));
  CHECK(fdem::softening_integral(0.63, 1.8, 6.0) == fdem::test::rel(0.38631, 1e-5));
  CHECK(std::chrono::steady_clock::now() - started < std::chrono::seconds(2));
}

}  // TEST_SUITE("case")
