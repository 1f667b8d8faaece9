// Case reader: [[material]] with [material.stiffness] and [material.fracture], and [[interface]]
// (io/case_material_tables.cpp).
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

TEST_CASE("anisotropic stiffness as a table, c16/c26/angle defaulting to 0") {
  CaseDir d;
  const std::string text = kBase +
                           "elasticity = \"hyperelastic\"\n"
                           "[material.stiffness]\n"
                           "c11 = 4e10\nc22 = 1e10\nc12 = 3e9\nc66 = 5e9\n";
  const CaseConfig c = read_case(d.write("c.toml", text));
  REQUIRE(c.materials[0].stiffness.has_value());
  const auto& s = *c.materials[0].stiffness;
  CHECK(s.c11 == 4e10);
  CHECK(s.c22 == 1e10);
  CHECK(s.c12 == 3e9);
  CHECK(s.c66 == 5e9);
  CHECK(s.c16 == 0.0);
  CHECK(s.c26 == 0.0);
  CHECK(s.angle == 0.0);
}

TEST_CASE("stiffness errors") {
  const std::string hyper = kBase + "elasticity = \"hyperelastic\"\n";
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", kBase + "stiffness = { c11 = 1, c22 = 1, c12 = 0, c66 = 1 }\n")),
      contains(":13: material[0].stiffness is only allowed with elasticity = "
                        "\"hyperelastic\""),
      InputError);
  CHECK(error_of(hyper + "stiffness = { c11 = 1e9, c22 = 1e9, c12 = 0 }\n") ==
        contains(":14: material[0].stiffness is missing required key 'c66'"));
  CHECK(error_of(hyper + "stiffness = { c11 = 1e9, c22 = 1e9, c12 = 2e9, c66 = 1e9 }\n") ==
        contains(":14: material[0].stiffness is not positive definite"));
  CHECK(error_of(hyper + "stiffness = { c11 = 1e9, c22 = 1e9, c12 = 0, c66 = 1e9, angel = 9 }\n") ==
        contains("unknown key 'angel' in material[0].stiffness (did you mean 'angle'?)"));
  CHECK(error_of(hyper + "stiffness = { c11 = -1e9, c22 = 1e9, c12 = 0, c66 = 1e9 }\n") ==
        contains("material[0].stiffness.c11 = -1000000000 is out of range (allowed: "
                          "material[0].stiffness.c11 > 0)"));
}

TEST_CASE("a region in two materials, and a name used twice") {
  CHECK(error_of(kBase + with(kSecondMaterial, "[\"slate\"]", "[\"slate\", \"rock\"]")) ==
        contains(":15: material[1].regions: region 'rock' is already in material[0] "
                          "('rock')"));
  CHECK(error_of(kBase + with(kSecondMaterial, "\"slate\"\n", "\"rock\"\n")) ==
        contains(":14: material[1].name: 'rock' is already the name of material[0]"));
}

TEST_CASE("fracture: every key of [material.fracture] and [[interface]] is read") {
  CaseDir d;
  const std::string text = kBase + R"([material.fracture]
tensile_strength = 1.77e6
cohesion = 5.0e6
friction_angle = 25.0
gf1 = 16.0
gf2 = 160.0
penalty = { opening = 12200e9, sliding = 6100e9, overlap = 24400e9 }
softening = { a = 0.5, b = 2.0, c = 3.0 }
[[material]]
name = "vein"
regions = ["vein"]
density = 2600.0
young = 20e9
poisson = 0.3
fracture = { tensile_strength = 1e6, cohesion = 2e6, friction_angle = 0, gf1 = 5, gf2 = 50, penalty = { opening = 1e12, sliding = 2e12, overlap = 3e12 } }
[[material]]
name = "steel"
regions = ["platen_top", "platen_bottom"]
density = 7800.0
young = 200e9
poisson = 0.3
[[interface]]
materials = ["vein", "rock"]
tensile_strength = 0.5e6
cohesion = 1e6
friction_angle = 30
gf1 = 2
gf2 = 20
softening = { c = 4.0 }
[interface.penalty]
opening = 5e11
sliding = 6e11
overlap = 7e11
[contact]
normal_penalty = 1e9
activation = "fractured"
regions = ["platen_top", "platen_bottom", "rock"]
)";
  const CaseConfig c = read_case(d.write("c.toml", text));
  REQUIRE(c.materials.size() == 3);
  REQUIRE(c.materials[0].fracture.has_value());
  const fdem::io::FractureConfig& rock = *c.materials[0].fracture;
  CHECK(rock.tensile_strength == 1.77e6);
  CHECK(rock.cohesion == 5.0e6);
  CHECK(rock.friction_angle == 25.0);
  CHECK(rock.gf1 == 16.0);
  CHECK(rock.gf2 == 160.0);
  CHECK(rock.penalty_opening == 12200e9);
  CHECK(rock.penalty_sliding == 6100e9);
  CHECK(rock.penalty_overlap == 24400e9);
  CHECK(rock.softening_a == 0.5);
  CHECK(rock.softening_b == 2.0);
  CHECK(rock.softening_c == 3.0);

  REQUIRE(c.materials[1].fracture.has_value());  // inline, softening left out: defaults
  const fdem::io::FractureConfig& vein = *c.materials[1].fracture;
  CHECK(vein.tensile_strength == 1e6);
  CHECK(vein.cohesion == 2e6);
  CHECK(vein.friction_angle == 0.0);
  CHECK(vein.gf1 == 5.0);
  CHECK(vein.gf2 == 50.0);
  CHECK(vein.penalty_opening == 1e12);
  CHECK(vein.penalty_sliding == 2e12);
  CHECK(vein.penalty_overlap == 3e12);
  CHECK(vein.softening_a == 0.63);
  CHECK(vein.softening_b == 1.8);
  CHECK(vein.softening_c == 6.0);
  CHECK_FALSE(c.materials[2].fracture.has_value());

  REQUIRE(c.interfaces.size() == 1);
  const fdem::io::InterfaceConfig& i = c.interfaces[0];
  CHECK(i.materials == std::array<std::string, 2>{"vein", "rock"});
  CHECK(i.fracture.tensile_strength == 0.5e6);
  CHECK(i.fracture.cohesion == 1e6);
  CHECK(i.fracture.friction_angle == 30.0);
  CHECK(i.fracture.gf1 == 2.0);
  CHECK(i.fracture.gf2 == 20.0);
  CHECK(i.fracture.penalty_opening == 5e11);
  CHECK(i.fracture.penalty_sliding == 6e11);
  CHECK(i.fracture.penalty_overlap == 7e11);
  CHECK(i.fracture.softening_a == 0.63);  // softening = { c = 4.0 }: a and b default
  CHECK(i.fracture.softening_b == 1.8);
  CHECK(i.fracture.softening_c == 4.0);

  REQUIRE(c.contact.has_value());
  CHECK(c.contact->activation == "fractured");
  CHECK(c.contact->regions == std::vector<std::string>{"platen_top", "platen_bottom", "rock"});

  // activation = "fractured" without regions: only triangles next to broken CE4s.
  const CaseConfig bare = read_case(d.write("c.toml", kContact + "activation = \"fractured\"\n"));
  CHECK(bare.contact->activation == "fractured");
  CHECK(bare.contact->regions.empty());
  // An empty softening table is all defaults.
  const CaseConfig empty = read_case(d.write("c.toml", kBase + kFracture + "softening = {}\n"));
  CHECK(empty.materials[0].fracture->softening_a == 0.63);
  CHECK(empty.materials[0].fracture->softening_b == 1.8);
  CHECK(empty.materials[0].fracture->softening_c == 6.0);
}

TEST_CASE("fracture errors: [material.fracture]") {
  const std::string f = kBase + kFracture;
  CHECK_THROWS_WITH_AS(read_case(CaseDir().write("c.toml", with(f, "gf1 = 16.0\n", ""))),
                       contains(":13: [material.fracture] of material[0] ('rock') is missing "
                                "required key 'gf1'"),
                       InputError);
  for (const char* key : {"tensile_strength", "cohesion", "friction_angle", "gf2", "penalty"}) {
    const std::size_t at = f.find(std::string(key) + " = ");
    const std::string without = f.substr(0, at) + f.substr(f.find('\n', at) + 1);
    CHECK(error_of(without) == contains(":13: [material.fracture] of material[0] ('rock') is "
                                        "missing required key '" + std::string(key) + "'"));
  }
  CHECK(error_of(with(f, "sliding = 12200e9, ", "")) ==
        contains(":19: material[0].fracture.penalty is missing required key 'sliding'"));
  CHECK(error_of(with(f, ", overlap = 12200e9", "")) ==
        contains(":19: material[0].fracture.penalty is missing required key 'overlap'"));
  CHECK(error_of(with(f, "{ opening = 12200e9, ", "{ ")) ==
        contains(":19: material[0].fracture.penalty is missing required key 'opening'"));

  CHECK(error_of(with(f, "1.77e6", "0")) ==
        contains(":14: material[0].fracture.tensile_strength = 0 is out of range (allowed: "
                 "material[0].fracture.tensile_strength > 0)"));
  CHECK(error_of(with(f, "5.0e6", "-1")) ==
        contains(":15: material[0].fracture.cohesion = -1 is out of range (allowed: "
                 "material[0].fracture.cohesion > 0)"));
  CHECK(error_of(with(f, "25.0", "90")) ==
        contains(":16: material[0].fracture.friction_angle = 90 is out of range (allowed: 0 <= "
                 "material[0].fracture.friction_angle < 90)"));
  CHECK(error_of(with(f, "25.0", "-0.5")) ==
        contains(":16: material[0].fracture.friction_angle = -0.5 is out of range"));
  CHECK(error_of(with(f, "gf1 = 16.0", "gf1 = 0.0")) ==
        contains(":17: material[0].fracture.gf1 = 0 is out of range (allowed: "
                 "material[0].fracture.gf1 > 0)"));
  CHECK(error_of(with(f, "gf2 = 160.0", "gf2 = -160.0")) ==
        contains(":18: material[0].fracture.gf2 = -160 is out of range"));
  CHECK(error_of(with(f, "opening = 12200e9", "opening = 0")) ==
        contains(":19: material[0].fracture.penalty.opening = 0 is out of range (allowed: "
                 "material[0].fracture.penalty.opening > 0)"));
  CHECK(error_of(with(f, "sliding = 12200e9", "sliding = -1")) ==
        contains(":19: material[0].fracture.penalty.sliding = -1 is out of range"));
  CHECK(error_of(with(f, "overlap = 12200e9", "overlap = 0")) ==
        contains(":19: material[0].fracture.penalty.overlap = 0 is out of range"));
  CHECK(error_of(f + "softening = { c = 0 }\n") ==
        contains(":20: material[0].fracture.softening.c = 0 is out of range (allowed: "
                 "material[0].fracture.softening.c > 0)"));
  CHECK(error_of(f + "softening = { a = 0.2, b = 0.8 }\n") ==
        contains(":20: material[0].fracture.softening: a + b = 1 is out of range (allowed: "
                 "a + b > 1)"));
  CHECK(error_of(f + "[material.fracture.softening]\na = 0.1\nb = 0.5\n") ==
        contains(":22: material[0].fracture.softening: a + b = 0.6 is out of range"));
  CHECK(error_of(f + "softening = { b = 0.3 }\n") ==
        contains(":20: material[0].fracture.softening: a + b = 0.93 is out of range"));

  CHECK(error_of(f + "gf3 = 1.0\n") ==
        contains(":20: unknown key 'gf3' in material[0].fracture (did you mean 'gf1'?)"));
  CHECK(error_of(with(f, "friction_angle", "frictionangle")) ==
        contains(":16: unknown key 'frictionangle' in material[0].fracture (did you mean "
                 "'friction_angle'?)"));
  CHECK(error_of(with(f, "sliding =", "slidng =")) ==
        contains(":19: unknown key 'slidng' in material[0].fracture.penalty (did you mean "
                 "'sliding'?)"));
  CHECK(error_of(f + "softening = { a = 0.63, cc = 6.0 }\n") ==
        contains(":20: unknown key 'cc' in material[0].fracture.softening (did you mean "
                 "'c'?)"));
  CHECK(error_of(kBase + "[material.fractur]\n" + kFractureKeys) ==
        contains(":13: unknown key 'fractur' in [[material]] (did you mean 'fracture'?)"));
  CHECK(error_of(kBase + "fracture = 3\n") ==
        contains(":13: material[0].fracture must be a table, found integer 3"));
  CHECK(error_of(with(f, "penalty = {", "penalty = 1e12 #")) ==
        contains(":19: material[0].fracture.penalty must be a table, found number"));
  CHECK(error_of(f + "softening = 0.63\n") ==
        contains(":20: material[0].fracture.softening must be a table, found number 0.63"));
  // The second material's table is named after it.
  CHECK(error_of(kBase + kSecondMaterial + "[material.fracture]\ncohesion = 1e6\n") ==
        contains(":19: [material.fracture] of material[1] ('slate') is missing required key "
                 "'tensile_strength'"));
  CHECK(error_of(f) == "");
}

TEST_CASE("fracture errors: [[interface]]") {
  CHECK(error_of(kInterface) == "");
  const std::string entry = kTwoFracturable + "[[interface]]\n";  // on line 33
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", entry + "materials = [\"rock\", \"slat\"]\n" +
                                              kFractureKeys)),
      contains(":34: interface[0].materials[1] = \"slat\" is not the name of a [[material]] "
               "(did you mean \"slate\"?)"),
      InputError);
  const doctest::String far =
      error_of(entry + "materials = [\"granite\", \"rock\"]\n" + kFractureKeys);
  CHECK(far == contains(":34: interface[0].materials[0] = \"granite\" is not the name of a "
                        "[[material]]"));
  CHECK(std::string(far.c_str()).find("did you mean") == std::string::npos);
  // "slate" without [material.fracture].
  CHECK(error_of(kBase + kFracture + kSecondMaterial +
                 "[[interface]]\nmaterials = [\"rock\", \"slate\"]\n" + kFractureKeys) ==
        contains(":27: interface[0].materials[1] = \"slate\" is a [[material]] without "
                 "[material.fracture]: an interface joins two fracturable materials"));
  CHECK(error_of(entry + "materials = [\"rock\", \"rock\"]\n" + kFractureKeys) ==
        contains(":34: interface[0].materials names 'rock' twice: an interface joins two "
                 "different materials"));
  CHECK(error_of(kInterface + "[[interface]]\nmaterials = [\"slate\", \"rock\"]\n" +
                 kFractureKeys) ==
        contains(":42: interface[1].materials: the pair ('rock', 'slate') is already given in "
                 "interface[0]"));
  CHECK(error_of(entry + kFractureKeys) ==
        contains(":33: [[interface]] #0 is missing required key 'materials'"));
  CHECK(error_of(entry + "materials = [\"rock\", \"slate\"]\n" +
                 with(kFractureKeys, "cohesion = 5.0e6\n", "")) ==
        contains(":33: [[interface]] #0 is missing required key 'cohesion'"));
  CHECK(error_of(entry + "materials = [\"rock\"]\n" + kFractureKeys) ==
        contains(":34: interface[0].materials must be an array of 2 material names, found "
                 "array of 1"));
  CHECK(error_of(kInterface + "cohesoin = 1e6\n") ==
        contains(":41: unknown key 'cohesoin' in [[interface]] (did you mean 'cohesion'?)"));
  CHECK(error_of(kInterface + "softening = { a = 0.1, b = 0.2 }\n") ==
        contains(":41: interface[0].softening: a + b = 0.3 is out of range (allowed: "
                 "a + b > 1)"));
  const std::string last = kInterface.substr(0, kInterface.rfind("penalty = "));  // to line 39
  CHECK(error_of(last + "[interface.penalty]\nopening = 1e12\noverlp = 1e12\n") ==
        contains(":42: unknown key 'overlp' in interface[0].penalty (did you mean "
                 "'overlap'?)"));
  CHECK(error_of(last + "penalty = { opening = 1e12, sliding = 0, overlap = 1e12 }\n") ==
        contains(":40: interface[0].penalty.sliding = 0 is out of range (allowed: "
                 "interface[0].penalty.sliding > 0)"));
  CHECK(error_of(entry + "materials = [\"rock\", \"slate\"]\n" +
                 with(kFractureKeys, "25.0", "95")) ==
        contains(":37: interface[0].friction_angle = 95 is out of range (allowed: 0 <= "
                 "interface[0].friction_angle < 90)"));
  CHECK(error_of(kBase + "[[interfaces]]\n") ==
        contains(":13: unknown table [[interfaces]] (did you mean [[interface]]?)"));
  CHECK(error_of("interface = 3\n" + kBase) ==
        contains(":1: interface must be an array of tables (write [[interface]] entries), "
                 "found integer 3"));
}

}  // TEST_SUITE("case")

TEST_SUITE("case") {

TEST_CASE("[material.heterogeneity]: homogeneity, seed, properties; each error names the key") {
  CaseDir d;
  const std::string h = "[material.heterogeneity]\nhomogeneity = 3.0\nseed = 42\n";
  const CaseConfig c = read_case(d.write("a.toml", kBase + kFracture + h +
                                                       "properties = [\"young\", \"cohesion\"]\n"));
  REQUIRE(c.materials[0].heterogeneity);
  const auto& x = *c.materials[0].heterogeneity;
  CHECK(x.homogeneity == 3.0);
  CHECK(x.seed == 42);
  CHECK(x.young);
  CHECK_FALSE(x.tensile_strength);
  CHECK(x.cohesion);
  CHECK_FALSE(read_case(d.write("b.toml", kBase)).materials[0].heterogeneity);
  // Only E varies in a material that does not fracture.
  CHECK(read_case(d.write("c.toml", kBase + h + "properties = [\"young\"]\n")).materials[0].heterogeneity->young);
  CHECK(error_of(kBase + h + "properties = [\"cohesion\"]\n") ==
        contains("material[0].heterogeneity.properties lists \"cohesion\", a property of the CE4s: material[0] "
                 "('rock') has no [material.fracture]"));
  CHECK(error_of(kBase + kFracture + h + "properties = [\"youngs\"]\n") ==
        contains("lists \"youngs\", not a property that can vary (allowed: \"young\", \"tensile_strength\", "
                 "\"cohesion\") (did you mean \"young\"?)"));
  CHECK(error_of(kBase + h + "properties = [\"young\", \"young\"]\n") == contains("lists \"young\" twice"));
  CHECK(error_of(kBase + h + "properties = []\n") == contains("material[0].heterogeneity.properties must be a non-empty array of strings"));
  CHECK(error_of(kBase + h) == contains("is missing required key 'properties'"));
  CHECK(error_of(kBase + "[material.heterogeneity]\nseed = 1\nproperties = [\"young\"]\n") ==
        contains("is missing required key 'homogeneity'"));
  CHECK(error_of(kBase + "[material.heterogeneity]\nhomogeneity = 0\nseed = 1\nproperties = [\"young\"]\n") ==
        contains("material[0].heterogeneity.homogeneity = 0 is out of range (allowed: "
                 "material[0].heterogeneity.homogeneity > 0)"));
  CHECK(error_of(kBase + "[material.heterogeneity]\nhomogeneity = 2\nseed = -1\nproperties = [\"young\"]\n") ==
        contains("material[0].heterogeneity.seed = -1 is out of range"));
  CHECK(error_of(kBase + "[material.heterogeneity]\nhomogeneity = 2\nseed = 1.5\nproperties = [\"young\"]\n") ==
        contains("material[0].heterogeneity.seed must be an integer"));
  CHECK(error_of(kBase + "[material.heterogeneity]\nhomogeneity = 2\nsed = 1\nproperties = [\"young\"]\n") ==
        contains("unknown key 'sed' in material[0].heterogeneity (did you mean 'seed'?)"));
}

}  // TEST_SUITE
