// Case file reader: every key, the defaults, every error message, and --set.
#include "base/errors.hpp"
#include "io/case_config.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::CaseConfig;
using fdem::io::read_case;

// A fresh directory per test, holding the case and the mesh files it names.
class CaseDir {
 public:
  CaseDir() {
    static std::mt19937_64 random{std::random_device{}()};
    dir_ = fs::temp_directory_path() / ("fdem_case_test_" + std::to_string(random()));
    fs::create_directories(dir_ / "meshes");
    write("m.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    write("meshes/column.geo", "// stands in for a real .geo\n");
  }
  ~CaseDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  CaseDir(const CaseDir&) = delete;
  CaseDir& operator=(const CaseDir&) = delete;

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

// The smallest valid case; tests edit it, so its line numbers matter:
// [mesh] on line 2, [[material]] on line 7, density on line 10, poisson on line 12.
const std::string kBase =
    "title = \"t\"\n"        // 1
    "[mesh]\n"               // 2
    "file = \"m.msh\"\n"     // 3
    "[time]\n"               // 4
    "dt = 1.0\n"             // 5
    "end = 10.0\n"           // 6
    "[[material]]\n"         // 7
    "name = \"rock\"\n"      // 8
    "regions = [\"rock\"]\n" // 9
    "density = 2000.0\n"     // 10
    "young = 1e9\n"          // 11
    "poisson = 0.25\n";      // 12

std::string with(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  REQUIRE_MESSAGE(at != std::string::npos, "test bug: '" << from << "' not in the case");
  return text.replace(at, from.size(), to);
}

// doctest::Contains takes doctest::String, which has no constructor from std::string.
doctest::Contains contains(const std::string& piece) { return doctest::Contains(piece.c_str()); }

// Reads a case from a fresh directory; returns the InputError's message, "" if none.
// (Any other exception escapes and fails the test.) Compared with doctest::Contains.
doctest::String error_of(const std::string& text) {
  CaseDir d;
  try {
    read_case(d.write("c.toml", text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kSecondMaterial =
    "[[material]]\n"
    "name = \"slate\"\n"
    "regions = [\"slate\"]\n"
    "density = 2700.0\n"
    "young = 5e10\n"
    "poisson = 0.3\n";

// The keys of a [material.fracture] without its header: 6 lines.
const std::string kFractureKeys =
    "tensile_strength = 1.77e6\n"
    "cohesion = 5.0e6\n"
    "friction_angle = 25.0\n"
    "gf1 = 16.0\n"
    "gf2 = 160.0\n"
    "penalty = { opening = 12200e9, sliding = 12200e9, overlap = 12200e9 }\n";

// kBase + this: [material.fracture] of "rock" on line 13, tensile_strength on 14, gf1 on
// 17, penalty on 19, so what a test appends starts on line 20 (inside the table).
const std::string kFracture = "[material.fracture]\n" + kFractureKeys;

// Two fracturable materials ("rock" and "slate") and one [[interface]] between them:
// [[interface]] on line 33, materials on line 34, so what a test appends starts on line 41.
const std::string kTwoFracturable = kBase + kFracture + kSecondMaterial + kFracture;
const std::string kInterface = kTwoFracturable + "[[interface]]\n"
                                                 "materials = [\"rock\", \"slate\"]\n" +
                               kFractureKeys;

// Two materials and the smallest [contact]: [contact] on line 19, normal_penalty on line
// 20, so what a test appends starts on line 21.
const std::string kContact = kBase + kSecondMaterial +
                             "[contact]\n"
                             "normal_penalty = 1e9\n";

}  // namespace

TEST_SUITE("case") {

TEST_CASE("every key is read into its field") {
  CaseDir d;
  const std::string path = d.write("full.toml", R"(title = "Full"
[mesh]
geo = "meshes/column.geo"
size = 0.25
scale = 0.001
thickness = 2
[time]
dt = "auto"
safety = 0.4
steps = 5000
[output]
dir = "results"
name = "run1"
every = 0.5
history_every = 0.01
[[material]]
name = "rock"
regions = ["rock", "rock2"]
density = 2500
young = 30e9
poisson = 0.2
elasticity = "neo-hookean"
plane = "stress"
viscosity = 1.5
[[material]]
name = "slate"
regions = ["slate"]
density = 2700.0
young = 50e9
poisson = -0.1
elasticity = "hyperelastic"
stiffness = { c11 = 60e9, c22 = 20e9, c12 = 5e9, c66 = 8e9, c16 = 1e9, c26 = -1e9, angle = 30.0 }
viscosity = "critical"
[gravity]
g = [0.5, -9.806]
[damping]
local = 0.8
mass_scaling = true
[[boundary]]
region = "left"
fix = ["x"]
velocity = [0.0, -0.05]
rise = 1e-4
[[boundary]]
region = "top"
traction = [100.0, -1e6]
rise = 0.5
[[boundary]]
region = "hole"
pressure = 2e6
[[boundary]]
region = "base"
fix = ["y", "x"]
[[initial]]
region = "rock"
velocity = [1.0, -2.0]
)");
  const CaseConfig c = read_case(path);
  CHECK(c.path == path);
  CHECK(c.dir == fs::path(path).parent_path().string());
  CHECK(c.title == "Full");

  CHECK(c.mesh.geo == d.path("meshes/column.geo"));
  CHECK(c.mesh.file.empty());
  CHECK(c.mesh.size == 0.25);
  CHECK(c.mesh.scale == 0.001);
  CHECK(c.mesh.thickness == 2.0);

  CHECK(c.time.dt_auto);
  CHECK(c.time.safety == 0.4);
  CHECK(c.time.steps == 5000);
  CHECK(c.time.end < 0);

  CHECK(c.output.dir == "results");
  CHECK(c.output.name == "run1");
  CHECK(c.output.every == 0.5);
  CHECK(c.output.frames < 0);
  CHECK(c.output.history_every == 0.01);

  REQUIRE(c.materials.size() == 2);
  const auto& rock = c.materials[0];
  CHECK(rock.name == "rock");
  CHECK(rock.regions == std::vector<std::string>{"rock", "rock2"});
  CHECK(rock.density == 2500.0);
  CHECK(rock.young == 30e9);
  CHECK(rock.poisson == 0.2);
  CHECK(rock.elasticity == fdem::io::Elasticity::NeoHookean);
  CHECK(rock.plane == fdem::io::Plane::Stress);
  CHECK_FALSE(rock.stiffness.has_value());
  CHECK_FALSE(rock.viscosity_critical);
  CHECK(rock.viscosity == 1.5);

  const auto& slate = c.materials[1];
  CHECK(slate.name == "slate");
  CHECK(slate.poisson == -0.1);
  CHECK(slate.elasticity == fdem::io::Elasticity::Hyperelastic);
  CHECK(slate.plane == fdem::io::Plane::Strain);
  REQUIRE(slate.stiffness.has_value());
  CHECK(slate.stiffness->c11 == 60e9);
  CHECK(slate.stiffness->c22 == 20e9);
  CHECK(slate.stiffness->c12 == 5e9);
  CHECK(slate.stiffness->c66 == 8e9);
  CHECK(slate.stiffness->c16 == 1e9);
  CHECK(slate.stiffness->c26 == -1e9);
  CHECK(slate.stiffness->angle == 30.0);
  CHECK(slate.viscosity_critical);

  CHECK(c.gravity.g == std::array<double, 2>{0.5, -9.806});
  CHECK(c.damping.local_enabled);
  CHECK(c.damping.local == 0.8);
  CHECK(c.damping.mass_scaling);

  REQUIRE(c.boundaries.size() == 4);
  const auto& left = c.boundaries[0];
  CHECK(left.region == "left");
  CHECK(left.fix_x);
  CHECK_FALSE(left.fix_y);
  CHECK(left.velocity == std::array<double, 2>{0.0, -0.05});
  CHECK(left.rise == 1e-4);
  CHECK_FALSE(left.traction.has_value());
  CHECK_FALSE(left.pressure.has_value());
  const auto& top = c.boundaries[1];
  CHECK(top.traction == std::array<double, 2>{100.0, -1e6});
  CHECK(top.rise == 0.5);
  CHECK_FALSE(top.velocity.has_value());
  CHECK_FALSE(top.fix_x);
  CHECK(c.boundaries[2].pressure == 2e6);
  CHECK(c.boundaries[2].rise == 0.0);
  CHECK(c.boundaries[3].fix_x);
  CHECK(c.boundaries[3].fix_y);

  REQUIRE(c.initials.size() == 1);
  CHECK(c.initials[0].region == "rock");
  CHECK(c.initials[0].velocity == std::array<double, 2>{1.0, -2.0});
}

TEST_CASE("defaults of a minimal case") {
  CaseDir d;
  const CaseConfig c = read_case(d.write("base.toml", kBase));
  CHECK(c.title == "t");
  CHECK(c.mesh.file == d.path("m.msh"));
  CHECK(c.mesh.geo.empty());
  CHECK(c.mesh.size == 0.0);
  CHECK(c.mesh.scale == 1.0);
  CHECK(c.mesh.thickness == 1.0);
  CHECK_FALSE(c.time.dt_auto);
  CHECK(c.time.dt == 1.0);
  CHECK(c.time.safety == 0.5);
  CHECK(c.time.end == 10.0);
  CHECK(c.time.steps < 0);
  CHECK(c.output.dir == "out");
  CHECK(c.output.name == "base");
  CHECK(c.output.frames == 20);
  CHECK(c.output.every < 0);
  CHECK(c.output.history_every < 0);
  REQUIRE(c.materials.size() == 1);
  CHECK(c.materials[0].elasticity == fdem::io::Elasticity::NeoHookean);
  CHECK(c.materials[0].plane == fdem::io::Plane::Strain);
  CHECK_FALSE(c.materials[0].stiffness.has_value());
  CHECK_FALSE(c.materials[0].viscosity_critical);
  CHECK(c.materials[0].viscosity == 0.0);
  CHECK(c.gravity.g == std::array<double, 2>{0.0, 0.0});
  CHECK_FALSE(c.damping.local_enabled);
  CHECK_FALSE(c.damping.mass_scaling);
  CHECK(c.boundaries.empty());
  CHECK(c.initials.empty());
  CHECK_FALSE(c.contact.has_value());
  CHECK_FALSE(c.materials[0].fracture.has_value());
  CHECK(c.interfaces.empty());
}

TEST_CASE("title is optional, frames and an absolute mesh path are kept") {
  CaseDir d;
  std::string text = with(kBase, "title = \"t\"\n", "\n");
  text = with(text, "file = \"m.msh\"", "file = \"" + d.path("m.msh") + "\"");
  text += "[output]\nframes = 7\n";
  const CaseConfig c = read_case(d.write("c.toml", text));
  CHECK(c.title.empty());
  CHECK(c.mesh.file == d.path("m.msh"));
  CHECK(c.output.frames == 7);
  CHECK(c.output.every < 0);
}

TEST_CASE("dt = \"auto\", viscosity = \"critical\" and integers for floats") {
  CaseDir d;
  std::string text = with(kBase, "dt = 1.0", "dt = \"auto\"");
  text = with(text, "density = 2000.0", "density = 2000");
  text += "viscosity = \"critical\"\n";
  const CaseConfig c = read_case(d.write("c.toml", text));
  CHECK(c.time.dt_auto);
  CHECK(c.time.safety == 0.5);
  CHECK(c.materials[0].density == 2000.0);
  CHECK(c.materials[0].viscosity_critical);

  CHECK_THROWS_WITH_AS(read_case(d.write("c.toml", with(kBase, "dt = 1.0", "dt = \"fast\""))),
                       contains(":5: time.dt must be a number or the string \"auto\", "
                                         "found string \"fast\""),
                       InputError);
  CHECK_THROWS_WITH_AS(read_case(d.write("c.toml", kBase + "viscosity = \"high\"\n")),
                       contains("material[0].viscosity must be a number or the string "
                                         "\"critical\""),
                       InputError);
}

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

TEST_CASE("TOML syntax error and unreadable file") {
  CaseDir d;
  const std::string path = d.write("c.toml", with(kBase, "dt = 1.0", "dt = 1.0.0"));
  CHECK_THROWS_WITH_AS(read_case(path), contains(path + ":5:"), InputError);
  CHECK_THROWS_WITH_AS(read_case(d.path("absent.toml")),
                       contains(d.path("absent.toml") + ": cannot open"), InputError);
}

TEST_CASE("mesh: missing file, geo and file together, neither, size without geo") {
  CaseDir d;
  const std::string path = d.write("c.toml", with(kBase, "m.msh", "nope.msh"));
  CHECK_THROWS_WITH_AS(read_case(path),
                       contains(path + ":3: mesh.file: file not found: " +
                                         d.path("nope.msh")),
                       InputError);
  CHECK(error_of(with(kBase, "[time]", "geo = \"meshes/column.geo\"\n[time]")) ==
        contains(":4: mesh.geo and mesh.file are exclusive"));
  CHECK(error_of(with(kBase, "file = \"m.msh\"\n", "")) ==
        contains(":2: [mesh] needs one of 'geo' or 'file'"));
  CHECK(error_of(with(kBase, "[time]", "size = 0.5\n[time]")) ==
        contains(":4: mesh.size only applies with mesh.geo"));
  CHECK(error_of(with(kBase, "title = \"t\"\n[mesh]\nfile = \"m.msh\"\n", "")) ==
        contains("missing required table [mesh]"));
}

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

TEST_CASE("missing required keys name their table") {
  const std::string path_piece = ":7: [[material]] #0 ('rock') is missing required key 'density'";
  CHECK(error_of(with(kBase, "density = 2000.0\n", "")) == contains(path_piece));
  CHECK(error_of(with(kBase, "name = \"rock\"\n", "")) ==
        contains(":7: [[material]] #0 is missing required key 'name'"));
  CHECK(error_of(kBase + kSecondMaterial + "[[boundary]]\nfix = [\"x\"]\n") ==
        contains(":19: [[boundary]] #0 is missing required key 'region'"));
  CHECK(error_of(with(kBase, "dt = 1.0\n", "")) ==
        contains(":4: [time] is missing required key 'dt'"));
  CHECK(error_of(kBase + "[gravity]\n") ==
        contains(":13: [gravity] is missing required key 'g'"));
  CHECK(error_of(kBase + "[[initial]]\nregion = \"rock\"\n") ==
        contains(":13: [[initial]] #0 ('rock') is missing required key 'velocity'"));
  const std::string no_material = kBase.substr(0, kBase.find("[[material]]"));
  CHECK(error_of(no_material) == contains("at least one [[material]]"));
}

TEST_CASE("wrong types name the key, the expected type and what was found") {
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", with(kBase, "2000.0", "\"high\""))),
      contains(":10: material[0].density must be a number, found string \"high\""),
      InputError);
  CHECK(error_of(with(kBase, "end = 10.0", "steps = 10.5")) ==
        contains(":6: time.steps must be an integer, found number 10.5"));
  CHECK(error_of(kBase + "[damping]\nmass_scaling = 1\n") ==
        contains(":14: damping.mass_scaling must be a boolean, found integer 1"));
  CHECK(error_of(kBase + "[gravity]\ng = [0.0, -9.8, 1.0]\n") ==
        contains(":14: gravity.g must be an array of 2 numbers, found array of 3"));
  CHECK(error_of(kBase + "[gravity]\ng = [0.0, \"down\"]\n") ==
        contains("gravity.g[1] must be a number, found string \"down\""));
  CHECK(error_of(with(kBase, "[\"rock\"]", "\"rock\"")) ==
        contains(":9: material[0].regions must be a non-empty array of strings, found "
                          "string \"rock\""));
  CHECK(error_of(with(kBase, "[\"rock\"]", "[]")) ==
        contains("material[0].regions must be a non-empty array of strings"));
  CHECK(error_of(with(kBase, "[[material]]", "[material]")) ==
        contains(":7: material must be an array of tables"));
  CHECK(error_of(with(kBase, "[mesh]\nfile = \"m.msh\"\n", "mesh = 3\n")) ==
        contains(":2: mesh must be a table, found integer 3"));
  CHECK(error_of(with(kBase, "0.25", "nan")) ==
        contains(":12: material[0].poisson must be finite"));
}

TEST_CASE("out-of-range values give the allowed range") {
  CHECK_THROWS_WITH_AS(
      read_case(CaseDir().write("c.toml", with(kBase, "0.25", "0.5"))),
      contains(":12: material[0].poisson = 0.5 is out of range (allowed: -1 < "
                        "material[0].poisson < 0.5)"),
      InputError);
  CHECK(error_of(with(kBase, "dt = 1.0", "dt = 1.0\nsafety = 0")) ==
        contains(":6: time.safety = 0 is out of range (allowed: 0 < time.safety <= 1)"));
  CHECK(error_of(with(kBase, "dt = 1.0", "dt = -1")) ==
        contains("time.dt = -1 is out of range (allowed: time.dt > 0)"));
  CHECK(error_of(with(kBase, "end = 10.0", "steps = 0")) ==
        contains("time.steps = 0 is out of range (allowed: time.steps >= 1)"));
  CHECK(error_of(kBase + "[damping]\nlocal = 1.0\n") ==
        contains(":14: damping.local = 1 is out of range (allowed: 0 <= damping.local < 1)"));
  CHECK(error_of(kBase + "viscosity = -1\n") ==
        contains("material[0].viscosity = -1 is out of range (allowed: "
                          "material[0].viscosity >= 0)"));
  CHECK(error_of(kBase + "[output]\nframes = 0\n") ==
        contains("output.frames = 0 is out of range"));
  CHECK(error_of(with(kBase, "[time]", "thickness = 0\n[time]")) ==
        contains(":4: mesh.thickness = 0 is out of range (allowed: mesh.thickness > 0)"));
  CHECK(error_of(kBase + "elasticity = \"neohookean\"\n") ==
        contains(":13: material[0].elasticity = \"neohookean\" is not valid (allowed: "
                          "\"neo-hookean\", \"hyperelastic\") (did you mean \"neo-hookean\"?)"));
}

TEST_CASE("exclusive and exactly-one keys") {
  CHECK(error_of(with(kBase, "end = 10.0", "end = 10.0\nsteps = 10")) ==
        contains(":7: time.end and time.steps are exclusive"));
  CHECK(error_of(with(kBase, "end = 10.0\n", "")) ==
        contains(":4: [time] needs one of 'end' or 'steps'"));
  CHECK(error_of(kBase + "[output]\nframes = 5\nevery = 1.0\n") ==
        contains(":15: output.frames and output.every are exclusive"));
}

TEST_CASE("a region in two materials, and a name used twice") {
  CHECK(error_of(kBase + with(kSecondMaterial, "[\"slate\"]", "[\"slate\", \"rock\"]")) ==
        contains(":15: material[1].regions: region 'rock' is already in material[0] "
                          "('rock')"));
  CHECK(error_of(kBase + with(kSecondMaterial, "\"slate\"\n", "\"rock\"\n")) ==
        contains(":14: material[1].name: 'rock' is already the name of material[0]"));
}

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
  CHECK(c.contact->tangential_penalty == 1e9);  // = normal_penalty, numerically
  CHECK(c.contact->friction == 0.0);
  CHECK_FALSE(c.contact->damping.has_value());
  CHECK(c.contact->activation == "all");
  CHECK(c.contact->rebuild == fdem::io::ContactRebuild::Step);
  CHECK(c.contact->skin == 0.0);
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
  const CaseConfig step = read_case(
      d.write("c.toml", kContact + "skin = 2e-3\ntangential_penalty = 0\nfriction = 0\n"));
  CHECK(step.contact->rebuild == fdem::io::ContactRebuild::Step);
  CHECK(step.contact->skin == 2e-3);
  CHECK(step.contact->tangential_penalty == 0.0);
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
  CHECK(error_of(kContact + "rebuild = \"skin\"\n") ==
        contains(":21: contact.rebuild = \"skin\" needs contact.skin > 0"));
  CHECK(error_of(kContact + "rebuild = \"skin\"\nskin = 0\n") ==
        contains(":22: contact.skin = 0 is out of range (allowed: contact.skin > 0)"));
  CHECK(error_of(kContact + "skin = -1e-3\n") ==
        contains(":21: contact.skin = -0.001 is out of range (allowed: contact.skin >= 0)"));
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
