// Case reader: read_case as a whole (io/case_reader.cpp): every key of every table, the defaults,
// TOML syntax errors and unreadable files.
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
  CHECK(c.output.energy_limit == 0.05);
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

TEST_CASE("TOML syntax error and unreadable file") {
  CaseDir d;
  const std::string path = d.write("c.toml", with(kBase, "dt = 1.0", "dt = 1.0.0"));
  CHECK_THROWS_WITH_AS(read_case(path), contains(path + ":5:"), InputError);
  CHECK_THROWS_WITH_AS(read_case(d.path("absent.toml")),
                       contains(d.path("absent.toml") + ": cannot open"), InputError);
}

}  // TEST_SUITE("case")
