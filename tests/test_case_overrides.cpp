// Case reader: --set KEY=VALUE (io/case_overrides.cpp): values, paths, indices and their errors.
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

TEST_CASE("--set a scalar, an array, an entry of an array of tables, a new key") {
  CaseDir d;
  const std::string path =
      d.write("c.toml", kBase + kSecondMaterial + "[[boundary]]\nregion = \"base\"\nfix = [\"y\"]\n");
  const CaseConfig c = read_case(path, {"material.0.young=2e9", "gravity.g=[0.0,-9.8]",
                                        "material.1.density=3000", "boundary.0.fix=[\"x\",\"y\"]",
                                        "damping.local=0.5", "material.1.viscosity=\"critical\"",
                                        "time.dt=\"auto\"", "output.name=\"run2\"", "title=\"over\""});
  CHECK(c.materials[0].young == 2e9);
  CHECK(c.gravity.g == std::array<double, 2>{0.0, -9.8});
  CHECK(c.materials[1].density == 3000.0);
  CHECK(c.materials[0].density == 2000.0);
  CHECK(c.boundaries[0].fix_x);
  CHECK(c.boundaries[0].fix_y);
  CHECK(c.damping.local_enabled);
  CHECK(c.damping.local == 0.5);
  CHECK(c.materials[1].viscosity_critical);
  CHECK(c.time.dt_auto);
  CHECK(c.output.name == "run2");
  CHECK(c.title == "over");

  // Later overrides win; a whole entry of an array of tables can be replaced.
  const CaseConfig twice = read_case(path, {"time.end=5", "time.end=7"});
  CHECK(twice.time.end == 7.0);
  const CaseConfig whole = read_case(path, {"boundary.0={region=\"top\", pressure=1e6}"});
  CHECK(whole.boundaries[0].region == "top");
  CHECK(whole.boundaries[0].pressure == 1e6);
  CHECK_FALSE(whole.boundaries[0].fix_y);
}

TEST_CASE("--set errors") {
  CaseDir d;
  const std::string path = d.write("c.toml", kBase);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.young=[1,"}),
                       contains(path + " (from --set material.0.young=[1,): value '[1,' "
                                                "is not valid TOML"),
                       InputError);
  // A bare word is a string: fine for output.dir, a type error for a number.
  CHECK(read_case(path, {"output.dir=out2"}).output.dir == "out2");
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.young=abc"}),
                       contains("(from --set material.0.young=abc)"), InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.3.young=1e9"}),
                       contains("(from --set material.3.young=1e9): index 3 is out of "
                                         "range: the case has 1 [[material]] entries"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"boundary.0.region=\"x\""}),
                       contains("index 0 is out of range: the case has 0 [[boundary]] "
                                         "entries"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"gravty.g=[0.0,-9.8]"}),
                       contains("(from --set gravty.g=[0.0,-9.8]): unknown table "
                                         "[gravty] (did you mean [gravity]?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.youngs=1e9"}),
                       contains("unknown key 'youngs' in [[material]] (did you mean "
                                         "'young'?)"),
                       InputError);
  // A value that parses but is out of range is reported against the override, not a line.
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.poisson=0.7"}),
                       contains(path + " (from --set material.0.poisson=0.7): "
                                                "material[0].poisson = 0.7 is out of range"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"gravity.g=[1.0]"}),
                       contains("(from --set gravity.g=[1.0]): gravity.g must be an "
                                         "array of 2 numbers"),
                       InputError);
  // Exclusive keys are blamed on the override, not on the file's line.
  CHECK_THROWS_WITH_AS(read_case(path, {"time.steps=100"}),
                       contains("(from --set time.steps=100): time.end and time.steps are "
                                "exclusive"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"time.dt"}), contains("expected key.path=value"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"time..dt=1"}), contains("empty component"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"time.dt.x=1"}),
                       contains("time.dt is a value, not a table"), InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.young=1"}),
                       contains("material is an array of tables: give an index"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"time.end=1\nsteps=3"}),
                       contains("the value must be one TOML value"), InputError);
}

TEST_CASE("--set contact keys, a pair by index, and damping as an inline table") {
  CaseDir d;
  const std::string path =
      d.write("c.toml", kContact + "[[contact.pair]]\nmaterials = [\"rock\", \"slate\"]\n");
  const CaseConfig c = read_case(
      path, {"contact.friction=0.3", "contact.pair.0.friction=0.2",
             "contact.damping={transition=1e6, exponent=2.0}", "contact.pair.0.damping.exponent=3",
             "contact.rebuild=skin", "contact.skin=1e-4", "contact.tangential_penalty=5e8"});
  REQUIRE(c.contact.has_value());
  CHECK(c.contact->friction == 0.3);
  REQUIRE(c.contact->damping.has_value());
  CHECK(c.contact->damping->transition == 1e6);
  CHECK(c.contact->damping->exponent == 2.0);
  CHECK(c.contact->rebuild == fdem::io::ContactRebuild::Skin);
  CHECK(c.contact->skin == 1e-4);
  CHECK(c.contact->tangential_penalty == 5e8);
  CHECK(c.contact->normal_penalty == 1e9);
  REQUIRE(c.contact->pairs.size() == 1);
  CHECK(c.contact->pairs[0].friction == 0.2);
  REQUIRE(c.contact->pairs[0].damping.has_value());
  CHECK(c.contact->pairs[0].damping->exponent == 3.0);
  CHECK(std::isinf(c.contact->pairs[0].damping->transition));

  // A whole pair replaced; [contact] created by --set on a case without one.
  const CaseConfig whole =
      read_case(path, {"contact.pair.0={materials=[\"slate\", \"slate\"], normal_penalty=2e9}"});
  CHECK(whole.contact->pairs[0].materials == std::array<std::string, 2>{"slate", "slate"});
  CHECK(whole.contact->pairs[0].normal_penalty == 2e9);
  CHECK_FALSE(whole.contact->pairs[0].friction.has_value());
  const std::string bare = d.write("bare.toml", kBase);
  const CaseConfig created = read_case(bare, {"contact.normal_penalty=1e9"});
  REQUIRE(created.contact.has_value());
  CHECK(created.contact->normal_penalty == 1e9);

  CHECK_THROWS_WITH_AS(read_case(bare, {"contact.friction=0.3"}),
                       contains(bare + " (from --set contact.friction=0.3): [contact] is "
                                       "missing required key 'normal_penalty'"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.pair.1.friction=0.2"}),
                       contains("(from --set contact.pair.1.friction=0.2): index 1 is out of "
                                "range: the case has 1 [[contact.pair]] entries"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(bare, {"contact.pair.0.friction=0.2"}),
                       contains("index 0 is out of range: the case has 0 [[contact.pair]] "
                                "entries"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.pair.0.frction=0.2"}),
                       contains("unknown key 'frction' in [[contact.pair]] (did you mean "
                                "'friction'?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.frction=0.2"}),
                       contains("unknown key 'frction' in [contact] (did you mean "
                                "'friction'?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.damping.exponnt=2"}),
                       contains("unknown key 'exponnt' in contact.damping (did you mean "
                                "'exponent'?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.pair.friction=0.2"}),
                       contains("contact.pair is an array of tables: give an index"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.pair.0.friction=-1"}),
                       contains(path + " (from --set contact.pair.0.friction=-1): "
                                       "contact.pair[0].friction = -1 is out of range"),
                       InputError);
  CHECK(read_case(path, {"contact.activation=fractured"}).contact->activation == "fractured");
}

TEST_CASE("--set fracture keys, a whole penalty table, interface keys") {
  CaseDir d;
  const std::string path = d.write("c.toml", kInterface + "[contact]\nnormal_penalty = 1e9\n");
  const CaseConfig c = read_case(
      path, {"material.0.fracture.gf1=20",
             "material.0.fracture.penalty={opening=1e12, sliding=1e12, overlap=1e12}",
             "material.1.fracture.softening.c=5", "interface.0.cohesion=3e6",
             "interface.0.penalty.overlap=2e12", "contact.activation=fractured",
             "contact.regions=[\"rock\"]"});
  const fdem::io::FractureConfig& rock = *c.materials[0].fracture;
  CHECK(rock.gf1 == 20.0);
  CHECK(rock.gf2 == 160.0);
  CHECK(rock.penalty_opening == 1e12);
  CHECK(rock.penalty_sliding == 1e12);
  CHECK(rock.penalty_overlap == 1e12);
  CHECK(c.materials[1].fracture->softening_c == 5.0);
  CHECK(c.materials[1].fracture->softening_a == 0.63);
  REQUIRE(c.interfaces.size() == 1);
  CHECK(c.interfaces[0].fracture.cohesion == 3e6);
  CHECK(c.interfaces[0].fracture.tensile_strength == 1.77e6);
  CHECK(c.interfaces[0].fracture.penalty_overlap == 2e12);
  CHECK(c.interfaces[0].fracture.penalty_opening == 12200e9);
  CHECK(c.contact->activation == "fractured");
  CHECK(c.contact->regions == std::vector<std::string>{"rock"});

  // [material.fracture] created by --set is checked like a file's.
  const std::string bare = d.write("bare.toml", kBase);
  CHECK_THROWS_WITH_AS(read_case(bare, {"material.0.fracture.gf1=20"}),
                       contains(bare + " (from --set material.0.fracture.gf1=20): "
                                       "[material.fracture] of material[0] ('rock') is missing "
                                       "required key 'tensile_strength'"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.fracture.gf1=-1"}),
                       contains("(from --set material.0.fracture.gf1=-1): "
                                "material[0].fracture.gf1 = -1 is out of range"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.fracture.gf3=1"}),
                       contains("(from --set material.0.fracture.gf3=1): unknown key 'gf3' in "
                                "material[0].fracture (did you mean 'gf1'?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.fracture.penalty.openin=1e12"}),
                       contains("unknown key 'openin' in material[0].fracture.penalty (did you "
                                "mean 'opening'?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.fracture.penalty={opening=1e12}"}),
                       contains("(from --set material.0.fracture.penalty={opening=1e12}): "
                                "material[0].fracture.penalty is missing required key "
                                "'sliding'"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"material.0.fracture.softening={a=0.1, b=0.5}"}),
                       contains("(from --set material.0.fracture.softening={a=0.1, b=0.5}): "
                                "material[0].fracture.softening: a + b = 0.6 is out of range"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"interface.0.cohesoin=3e6"}),
                       contains("unknown key 'cohesoin' in [[interface]] (did you mean "
                                "'cohesion'?)"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"interface.1.cohesion=3e6"}),
                       contains("index 1 is out of range: the case has 1 [[interface]] "
                                "entries"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"interface.0.materials=[\"rock\", \"rock\"]"}),
                       contains("(from --set interface.0.materials=[\"rock\", \"rock\"]): "
                                "interface[0].materials names 'rock' twice"),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(path, {"contact.regions=[\"rock\"]"}),
                       contains("(from --set contact.regions=[\"rock\"]): contact.regions is "
                                "only allowed with contact.activation = \"fractured\""),
                       InputError);
}

}  // TEST_SUITE("case")
