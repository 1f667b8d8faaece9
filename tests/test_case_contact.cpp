// Case reader: [contact] and [[contact.pair]] (io/case_contact_table.cpp).
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

TEST_CASE("contact: every key is read, pairs override the defaults") {
  CaseDir d;
  const std::string text = kBase + kSecondMaterial + R"([contact]
normal_penalty = 1220e9
tangential_penalty = 600e9
friction = 0.5
damping = { transition = 1.0e6, exponent = 2.0 }
activation = "all"
rebuild = "skin"
skin = 0.1e-3
[[contact.pair]]
materials = ["slate", "rock"]
friction = 0.1
normal_penalty = 50e9
tangential_penalty = 0
damping = { transition = 2e5 }
[[contact.pair]]
materials = ["rock", "rock"]
[contact.pair.damping]
exponent = 1.5
[[contact.pair]]
materials = ["slate", "slate"]
)";
  const CaseConfig c = read_case(d.write("c.toml", text));
  REQUIRE(c.contact.has_value());
  const fdem::io::ContactConfig& k = *c.contact;
  CHECK(k.normal_penalty == 1220e9);
  CHECK(k.tangential_penalty == 600e9);
  CHECK(k.friction == 0.5);
  REQUIRE(k.damping.has_value());
  CHECK(k.damping->transition == 1.0e6);
  CHECK(k.damping->exponent == 2.0);
  CHECK(k.activation == "all");
  CHECK(k.rebuild == fdem::io::ContactRebuild::Skin);
  CHECK(k.skin == 0.1e-3);

  REQUIRE(k.pairs.size() == 3);
  const auto& first = k.pairs[0];
  CHECK(first.materials == std::array<std::string, 2>{"slate", "rock"});
  CHECK(first.friction == 0.1);
  CHECK(first.normal_penalty == 50e9);
  CHECK(first.tangential_penalty == 0.0);
  REQUIRE(first.damping.has_value());
  CHECK(first.damping->transition == 2e5);
  CHECK(first.damping->exponent == 1.0);
  const auto& second = k.pairs[1];  // the same material twice, damping as a section
  CHECK(second.materials == std::array<std::string, 2>{"rock", "rock"});
  CHECK_FALSE(second.friction.has_value());
  CHECK_FALSE(second.normal_penalty.has_value());
  CHECK_FALSE(second.tangential_penalty.has_value());
  REQUIRE(second.damping.has_value());
  CHECK(std::isinf(second.damping->transition));
  CHECK(second.damping->exponent == 1.5);
  CHECK(k.pairs[2].materials == std::array<std::string, 2>{"slate", "slate"});
  CHECK_FALSE(k.pairs[2].damping.has_value());
}

TEST_CASE("contact: defaults, and damping with only an exponent") {
  CaseDir d;
  const CaseConfig c = read_case(d.write("c.toml", kContact));
  REQUIRE(c.contact.has_value());
  CHECK(c.contact->normal_penalty == 1e9);
  // Not given: the model takes 6 P_n / h from the mesh (engine/model/model.cpp).
  CHECK_FALSE(c.contact->tangential_penalty.has_value());
  CHECK(c.contact->friction == 0.0);
  CHECK_FALSE(c.contact->damping.has_value());
  CHECK(c.contact->activation == "all");
  // The fast path by default: skin rebuilds, the margin taken from the mesh (nullopt here).
  CHECK(c.contact->rebuild == fdem::io::ContactRebuild::Skin);
  CHECK_FALSE(c.contact->skin.has_value());
  CHECK(c.contact->pairs.empty());
  CHECK(c.contact->regions.empty());

  const CaseConfig only_b = read_case(d.write("c.toml", kContact + "damping = { exponent = 3 }\n"));
  REQUIRE(only_b.contact->damping.has_value());
  CHECK(std::isinf(only_b.contact->damping->transition));
  CHECK(only_b.contact->damping->transition > 0);
  CHECK(only_b.contact->damping->exponent == 3.0);
  const CaseConfig empty = read_case(d.write("c.toml", kContact + "damping = {}\n"));
  REQUIRE(empty.contact->damping.has_value());
  CHECK(std::isinf(empty.contact->damping->transition));
  CHECK(empty.contact->damping->exponent == 1.0);

  // A skin with rebuild = "step" is a margin on the boxes; tangential_penalty 0 is allowed.
  const CaseConfig step = read_case(d.write(
      "c.toml", kContact + "rebuild = \"step\"\nskin = 2e-3\ntangential_penalty = 0\nfriction = 0\n"));
  CHECK(step.contact->rebuild == fdem::io::ContactRebuild::Step);
  CHECK(step.contact->skin == 2e-3);
  CHECK(step.contact->tangential_penalty == 0.0);
  // "step" alone: no margin; a skin alone is the skin rebuild's margin; "skin" alone takes
  // its margin from the mesh.
  const CaseConfig bare_step = read_case(d.write("c.toml", kContact + "rebuild = \"step\"\n"));
  CHECK(bare_step.contact->rebuild == fdem::io::ContactRebuild::Step);
  CHECK_FALSE(bare_step.contact->skin.has_value());
  const CaseConfig skin_only = read_case(d.write("c.toml", kContact + "skin = 2e-3\n"));
  CHECK(skin_only.contact->rebuild == fdem::io::ContactRebuild::Skin);
  CHECK(skin_only.contact->skin == 2e-3);
  const CaseConfig rebuild_only = read_case(d.write("c.toml", kContact + "rebuild = \"skin\"\n"));
  CHECK(rebuild_only.contact->rebuild == fdem::io::ContactRebuild::Skin);
  CHECK_FALSE(rebuild_only.contact->skin.has_value());
}

TEST_CASE("contact errors: [contact] keys") {
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", kBase + "[contact]\nfriction = 0.5\n")),
      contains(":13: [contact] is missing required key 'normal_penalty'"), InputError);
  CHECK(error_of(kBase + "[[contact.pair]]\nmaterials = [\"rock\", \"rock\"]\n") ==
        contains(":13: [contact] is missing required key 'normal_penalty', which "
                 "[[contact.pair]] entries need"));
  CHECK(error_of(kBase + kSecondMaterial + "[contact]\nnormal_penalty = 0\n") ==
        contains(":20: contact.normal_penalty = 0 is out of range (allowed: "
                 "contact.normal_penalty > 0)"));
  CHECK(error_of(kContact + "friction = -0.1\n") ==
        contains(":21: contact.friction = -0.1 is out of range (allowed: contact.friction >= 0)"));
  CHECK(error_of(kContact + "tangential_penalty = -1\n") ==
        contains(":21: contact.tangential_penalty = -1 is out of range (allowed: "
                 "contact.tangential_penalty >= 0)"));
  CHECK(error_of(kContact + "damping = { transition = 1e6, exponent = 0.5 }\n") ==
        contains(":21: contact.damping.exponent = 0.5 is out of range (allowed: "
                 "contact.damping.exponent >= 1)"));
  CHECK(error_of(kContact + "damping = { transition = 0 }\n") ==
        contains(":21: contact.damping.transition = 0 is out of range (allowed: "
                 "contact.damping.transition > 0)"));
  CHECK(error_of(kContact + "damping = { exponnt = 2 }\n") ==
        contains(":21: unknown key 'exponnt' in contact.damping (did you mean 'exponent'?)"));
  CHECK(error_of(kContact + "damping = 2.0\n") ==
        contains(":21: contact.damping must be a table, found number 2"));
  CHECK(error_of(kContact + "rebuild = \"skin\"\nskin = 0\n") ==
        contains(":22: contact.skin = 0 is out of range (allowed: contact.skin > 0)"));
  CHECK(error_of(kContact + "skin = 0\n") ==
        contains(":21: contact.skin = 0 is out of range (allowed: contact.skin > 0)"));
  CHECK(error_of(kContact + "rebuild = \"step\"\nskin = -1e-3\n") ==
        contains(":22: contact.skin = -0.001 is out of range (allowed: contact.skin >= 0)"));
  CHECK(error_of(kContact + "rebuild = \"steps\"\n") ==
        contains(":21: contact.rebuild = \"steps\" is not valid (allowed: \"step\", \"skin\") "
                 "(did you mean \"step\"?)"));
  CHECK(error_of(kContact + "activation = \"al\"\n") ==
        contains(":21: contact.activation = \"al\" is not valid (allowed: \"all\", "
                 "\"fractured\") (did you mean \"all\"?)"));
  CHECK(error_of(kContact + "frction = 0.5\n") ==
        contains(":21: unknown key 'frction' in [contact] (did you mean 'friction'?)"));
  CHECK(error_of(kBase + "[contakt]\nnormal_penalty = 1e9\n") ==
        contains(":13: unknown table [contakt] (did you mean [contact]?)"));
  CHECK(error_of("contact = 3\n" + kBase) ==
        contains(":1: contact must be a table, found integer 3"));
}

TEST_CASE("contact errors: [[contact.pair]]") {
  const std::string pair = kContact + "[[contact.pair]]\n";  // entry on line 21
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", pair + "materials = [\"rock\", \"slate\"]\n"
                                                 "fricton = 0.1\n")),
      contains(":23: unknown key 'fricton' in [[contact.pair]] (did you mean 'friction'?)"),
      InputError);
  CHECK(error_of(pair + "friction = 0.1\n") ==
        contains(":21: [[contact.pair]] #0 is missing required key 'materials'"));
  CHECK(error_of(pair + "materials = [\"rock\", \"slat\"]\n") ==
        contains(":22: contact.pair[0].materials[1] = \"slat\" is not the name of a "
                 "[[material]] (did you mean \"slate\"?)"));
  const doctest::String far = error_of(pair + "materials = [\"granite\", \"rock\"]\n");
  CHECK(far == contains(":22: contact.pair[0].materials[0] = \"granite\" is not the name of a "
                        "[[material]]"));
  CHECK(std::string(far.c_str()).find("did you mean") == std::string::npos);
  CHECK(error_of(pair + "materials = [\"rock\", \"slate\"]\n[[contact.pair]]\n"
                        "materials = [\"slate\", \"rock\"]\n") ==
        contains(":24: contact.pair[1].materials: the pair ('rock', 'slate') is already given "
                 "in contact.pair[0]"));
  CHECK(error_of(pair + "materials = [\"rock\", \"rock\"]\n[[contact.pair]]\n"
                        "materials = [\"rock\", \"rock\"]\n") ==
        contains(":24: contact.pair[1].materials: the pair ('rock', 'rock') is already given"));
  CHECK(error_of(pair + "materials = [\"rock\"]\n") ==
        contains(":22: contact.pair[0].materials must be an array of 2 material names, found "
                 "array of 1"));
  CHECK(error_of(pair + "materials = [\"rock\", \"slate\", \"rock\"]\n") ==
        contains(":22: contact.pair[0].materials must be an array of 2 material names, found "
                 "array of 3"));
  CHECK(error_of(pair + "materials = \"rock\"\n") ==
        contains(":22: contact.pair[0].materials must be an array of 2 material names, found "
                 "string \"rock\""));
  CHECK(error_of(pair + "materials = [\"rock\", 3]\n") ==
        contains(":22: contact.pair[0].materials[1] must be a string, found integer 3"));
  const std::string valid = pair + "materials = [\"rock\", \"slate\"]\n";  // overrides on line 23
  CHECK(error_of(valid + "friction = -1\n") ==
        contains(":23: contact.pair[0].friction = -1 is out of range (allowed: "
                 "contact.pair[0].friction >= 0)"));
  CHECK(error_of(valid + "normal_penalty = 0\n") ==
        contains(":23: contact.pair[0].normal_penalty = 0 is out of range"));
  CHECK(error_of(valid + "damping = { exponent = 0.9 }\n") ==
        contains(":23: contact.pair[0].damping.exponent = 0.9 is out of range (allowed: "
                 "contact.pair[0].damping.exponent >= 1)"));
  CHECK(error_of(kContact + "pair = 3\n") ==
        contains(":21: contact.pair must be an array of tables (write [[contact.pair]] "
                 "entries), found integer 3"));
  CHECK(error_of(valid) == "");
}

TEST_CASE("contact: activation and regions") {
  CHECK(error_of(kContact + "regions = [\"rock\"]\n") ==
        contains(":21: contact.regions is only allowed with contact.activation = "
                 "\"fractured\""));
  CHECK(error_of(kContact + "activation = \"all\"\nregions = [\"rock\"]\n") ==
        contains(":22: contact.regions is only allowed with contact.activation = "
                 "\"fractured\" (with \"all\" every triangle takes part in contact from the "
                 "start)"));
  CHECK(error_of(kContact + "activation = \"fractued\"\n") ==
        contains(":21: contact.activation = \"fractued\" is not valid (allowed: \"all\", "
                 "\"fractured\") (did you mean \"fractured\"?)"));
  CHECK(error_of(kContact + "activation = \"fractured\"\nregions = []\n") ==
        contains(":22: contact.regions must be a non-empty array of strings, found array of "
                 "0"));
  CHECK(error_of(kContact + "activation = \"fractured\"\nregions = \"rock\"\n") ==
        contains(":22: contact.regions must be a non-empty array of strings, found string "
                 "\"rock\""));
  CHECK(error_of(kContact + "activation = \"fractured\"\nregions = [\"rock\", 2]\n") ==
        contains(":22: contact.regions[1] must be a string, found integer 2"));
  CHECK(error_of(kContact + "activation = \"fractured\"\nregion = [\"rock\"]\n") ==
        contains(":22: unknown key 'region' in [contact] (did you mean 'regions'?)"));
}

}  // TEST_SUITE("case")
