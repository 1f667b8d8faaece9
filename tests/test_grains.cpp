// Grains ([grains], issue 31 item 4): a physical surface cut into Voronoi grains whose
// boundaries the mesh follows; each triangle takes its grain's mineral, the CE4s between
// two grains [grains.boundary], those inside a grain the mineral's own fracture keys; the
// same seed gives the same model bitwise; bad keys are refused naming them. The specimen
// is tests/data/cases/grains.toml: a 40 × 40 mm square of 60 grains of two minerals
// (70 / 30 % by area) on a steel strip, meshed at 1 mm.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "case_files.hpp"
#include "engine/model/model.hpp"
#include "engine/run/prepare_case.hpp"
#include "fdem_cli.hpp"
#include "fixture.hpp"
#include "io/gmsh_reader.hpp"
#include "io/grain_geometry.hpp"

using namespace fdem;

namespace {

std::string grains_case() { return test::source_path("tests/data/cases/grains.toml"); }

PreparedCase prepared(const test::TempDir& dir, const std::string& out, std::vector<std::string> more = {}) {
  more.push_back("output.dir=\"" + dir.str() + "/" + out + "\"");
  return prepare_case(grains_case(), more);
}

// The message of the InputError that preparing the case with `more` throws ("" if none).
std::string error(const test::TempDir& dir, std::vector<std::string> more) {
  try {
    prepared(dir, "bad", std::move(more));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

int material_index(const io::CaseConfig& c, const std::string& name) {
  for (size_t m = 0; m < c.materials.size(); ++m)
    if (c.materials[m].name == name) return static_cast<int>(m);
  return -1;
}

}  // namespace

TEST_SUITE("grains") {

TEST_CASE("grains: the same seed gives the same grains and model bitwise, another seed other grains") {
  test::TempDir dir;
  const PreparedCase a = prepared(dir, "a"), b = prepared(dir, "b");
  const PreparedCase c = prepared(dir, "c", {"grains.seed=6"});
  const Model &ma = a.model, &mb = b.model, &mc = c.model;
  REQUIRE(ma.grain_mineral.size() == 60);
  REQUIRE(ma.triangle_grain.size() == ma.num_triangles());
  CHECK(a.config.grains->points == b.config.grains->points);
  CHECK(ma.triangle_grain == mb.triangle_grain);
  CHECK(ma.triangle_material == mb.triangle_material);
  CHECK(ma.grain_mineral == mb.grain_mineral);
  CHECK(ma.x == mb.x);
  CHECK(ma.y == mb.y);
  CHECK(ma.ce4 == mb.ce4);
  CHECK(ma.ce4_properties == mb.ce4_properties);
  const int steel = material_index(a.config, "steel");
  auto name = [](const std::string& path) { return std::filesystem::path(path).filename().string(); };
  CHECK(name(a.model.mesh_path) == name(b.model.mesh_path));  // the same mesh (its cache name)
  CHECK(c.config.grains->points != a.config.grains->points);
  CHECK(mc.triangle_grain != ma.triangle_grain);
  CHECK(name(c.model.mesh_path) != name(a.model.mesh_path));
  // The grain boundaries lie in the grains' region only: the steel strip keeps the base
  // mesh's triangles within 1 % (the sizes at the embedded points reach the shared edge;
  // with the boundaries embedded in the steel too it had 30 % more).
  const io::Mesh base = io::read_gmsh(io::mesh_geo(test::source_path("tests/data/cases/grains.geo"), 1e-3, dir.str()));
  const int base_group = base.find_group("base", 2);
  const double base_steel = double(std::count(base.triangle_group.begin(), base.triangle_group.end(), base_group));
  for (const Model* m : {&ma, &mc}) {
    const double steel_triangles = double(m->block_start[size_t(steel) + 1] - m->block_start[size_t(steel)]);
    CHECK(std::fabs(steel_triangles / base_steel - 1) < 0.01);
  }  // the appended .geo text differs, so does the cache name
  // Every grain has triangles, the steel strip none.
  std::vector<size_t> count(60, 0);
  for (size_t t = 0; t < ma.num_triangles(); ++t) {
    CHECK((ma.triangle_grain[t] < 0) == (ma.triangle_material[t] == steel));
    if (ma.triangle_grain[t] >= 0) {
      ++count[size_t(ma.triangle_grain[t])];
      CHECK(ma.triangle_material[t] == ma.grain_mineral[size_t(ma.triangle_grain[t])]);
    }
  }
  CHECK(*std::min_element(count.begin(), count.end()) >= 5);
}

TEST_CASE("grains: the minerals' area fractions are met within 3 % (60 grains), and other fractions follow") {
  test::TempDir dir;
  for (double quartz : {0.7, 0.4}) {
    CAPTURE(quartz);
    const PreparedCase p = prepared(dir, "f" + std::to_string(int(quartz * 10)),
                                    {"grains.fractions=[" + std::to_string(quartz) + ", " + std::to_string(1 - quartz) + "]"});
    const Model& m = p.model;
    const int q = material_index(p.config, "quartz"), f = material_index(p.config, "feldspar");
    double total = 0, of_quartz = 0;
    for (size_t k = 0; k < m.grain_area.size(); ++k) {
      total += m.grain_area[k];
      if (m.grain_mineral[k] == q) of_quartz += m.grain_area[k];
      CHECK((m.grain_mineral[k] == q || m.grain_mineral[k] == f));
    }
    CHECK(total == doctest::Approx(0.04 * 0.04).epsilon(1e-9));
    MESSAGE("quartz area fraction " << of_quartz / total << " (asked " << quartz << ")");
    CHECK(std::fabs(of_quartz / total - quartz) < 0.03);
    const std::string line = grains_summary(m, p.config);
    CHECK(line.find("60 grains in 'rock' (seed 5)") != std::string::npos);
  }
}

TEST_CASE("grains: grain-boundary CE4s take [grains.boundary], the others their mineral's fracture keys") {
  test::TempDir dir;
  const PreparedCase p = prepared(dir, "p");
  const Model& m = p.model;
  REQUIRE(m.ce4_grain_boundary.size() == m.ce4.size());
  REQUIRE(m.grain_boundary_fracture >= 0);
  const FractureProperties& boundary = m.fracture[size_t(m.grain_boundary_fracture)];
  CHECK(boundary.tensile_strength == 4e6);
  size_t on = 0, inside = 0;
  for (size_t e = 0; e < m.ce4.size(); ++e) {
    const int g1 = m.triangle_grain[size_t(m.ce4_triangles[e][0])], g2 = m.triangle_grain[size_t(m.ce4_triangles[e][1])];
    REQUIRE(g1 >= 0);  // the steel is not fracturable: every CE4 joins two grains' triangles
    REQUIRE(g2 >= 0);
    const bool across = g1 != g2;
    CHECK(m.ce4_grain_boundary[e] == (across ? 1 : 0));
    CHECK((m.ce4_properties[e] == m.grain_boundary_fracture) == across);
    if (across) {
      ++on;
    } else {
      ++inside;
      const int mat = m.triangle_material[size_t(m.ce4_triangles[e][0])];
      CHECK(m.fracture[size_t(m.ce4_properties[e])].tensile_strength == p.config.materials[size_t(mat)].fracture->tensile_strength);
    }
  }
  MESSAGE(on << " grain-boundary CE4s, " << inside << " inside grains");
  CHECK(on > 300);
  CHECK(inside > on);
}

TEST_CASE("grains: element edges follow the grain boundaries (no triangle straddles two cells)") {
  test::TempDir dir;
  const PreparedCase p = prepared(dir, "e");
  const Model& m = p.model;
  const auto& seeds = p.config.grains->points;
  const double h = 1e-3;  // mesh.size
  // The embedded boundaries, as the front end made them (the same draw over the base mesh).
  io::GrainsConfig again = *p.config.grains;
  const io::Mesh base = io::read_gmsh(io::mesh_geo(test::source_path("tests/data/cases/grains.geo"), 1e-3, dir.str()));
  const io::GrainDraw draw = io::draw_grains(again, base, 1.0, p.config);
  REQUIRE(again.points == seeds);
  std::vector<std::vector<io::Point2>> cells;
  const auto segments = io::grain_boundaries(seeds, draw.lo, draw.hi, io::kGrainMerge * draw.mean_edge, &cells);
  CHECK(cells == p.config.grains->cells);
  // No segment runs through a triangle's interior: clipped to the triangle shrunk by
  // 10^-6 h (Cyrus-Beck), nothing is left. The boundaries stop an element short of the
  // region's boundary, so triangles within 2 h of it are not held to this.
  // And each corner of a grain's triangle lies in the grain's Voronoi cell, up to the
  // vertex merging (kGrainMerge h): its distance beyond the bisector with any other seed.
  size_t checked = 0, region = 0, crossed = 0, beyond = 0;
  double worst = 0;
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    const int g = m.triangle_grain[t];
    if (g < 0) continue;
    ++region;
    bool near_edge = false;
    for (int n : m.triangles[t])
      near_edge |= std::min({m.x[size_t(n)], 0.04 - m.x[size_t(n)], m.y[size_t(n)], 0.04 - m.y[size_t(n)]}) < 2 * h;
    if (near_edge) continue;
    ++checked;
    io::Point2 c[3];
    for (int k = 0; k < 3; ++k) c[k] = {m.x[size_t(m.triangles[t][k])], m.y[size_t(m.triangles[t][k])]};
    for (const auto& s : segments) {
      double t0 = 0, t1 = 1;
      for (int k = 0; k < 3 && t0 < t1; ++k) {
        const io::Point2 u = c[k], v = c[(k + 1) % 3];
        const double nx = -(v[1] - u[1]), ny = v[0] - u[0], len = std::hypot(nx, ny);  // inward normal (CCW)
        const double fa = ((s.a[0] - u[0]) * nx + (s.a[1] - u[1]) * ny) / len - 1e-6 * h;
        const double fb = ((s.b[0] - u[0]) * nx + (s.b[1] - u[1]) * ny) / len - 1e-6 * h;
        if (fa < 0 && fb < 0) t1 = -1;
        else if (fa < 0) t0 = std::max(t0, fa / (fa - fb));
        else if (fb < 0) t1 = std::min(t1, fa / (fa - fb));
      }
      if (t1 - t0 > 1e-9) ++crossed;
    }
    const io::Point2 s = seeds[size_t(g)];
    double far = 0;
    for (const io::Point2& q : c) {
      const double d2 = (q[0] - s[0]) * (q[0] - s[0]) + (q[1] - s[1]) * (q[1] - s[1]);
      for (size_t k = 0; k < seeds.size(); ++k) {
        if (int(k) == g) continue;
        const double e2 = (q[0] - seeds[k][0]) * (q[0] - seeds[k][0]) + (q[1] - seeds[k][1]) * (q[1] - seeds[k][1]);
        far = std::max(far, (d2 - e2) / (2 * std::hypot(seeds[k][0] - s[0], seeds[k][1] - s[1])));
      }
    }
    worst = std::max(worst, far);
    beyond += far > 0.05 * h;
  }
  MESSAGE(checked << " of " << region << " grain triangles checked against " << segments.size() << " boundary segments: "
                  << crossed << " crossed; " << beyond << " with a corner more than 0.05 h beyond its cell, the farthest "
                  << worst / h << " h");
  CHECK(segments.size() > 100);
  CHECK(checked > region / 2);
  CHECK(crossed == 0);
  CHECK(worst < io::kGrainMerge * h);
  CHECK(beyond < checked / 10);  // around the merged vertices only
  // And the triangles' grains agree with the embedded lines: every grain-boundary CE4 off
  // the region's boundary lies on a segment.
  size_t on = 0, off = 0;
  for (size_t e = 0; e < m.ce4.size(); ++e) {
    if (m.ce4_grain_boundary[e] != 1) continue;
    const io::Point2 a{m.x[size_t(m.ce4[e][0])], m.y[size_t(m.ce4[e][0])]}, b{m.x[size_t(m.ce4[e][1])], m.y[size_t(m.ce4[e][1])]};
    if (std::min({a[0], b[0], a[1], b[1], 0.04 - a[0], 0.04 - b[0], 0.04 - a[1], 0.04 - b[1]}) < 2 * h) continue;
    bool lies = false;
    for (const auto& sg : segments) {
      const double dx = sg.b[0] - sg.a[0], dy = sg.b[1] - sg.a[1], l = std::hypot(dx, dy);
      auto dist = [&](io::Point2 q) { return std::fabs((q[0] - sg.a[0]) * dy - (q[1] - sg.a[1]) * dx) / l; };
      auto along = [&](io::Point2 q) { return ((q[0] - sg.a[0]) * dx + (q[1] - sg.a[1]) * dy) / (l * l); };
      lies |= dist(a) < 1e-9 && dist(b) < 1e-9 && along(a) > -1e-9 && along(a) < 1 + 1e-9 && along(b) > -1e-9 &&
              along(b) < 1 + 1e-9;
    }
    (lies ? on : off) += 1;
  }
  MESSAGE(on << " grain-boundary CE4s on the embedded lines, " << off << " off them");
  CHECK(on > 200);
  CHECK(off == 0);
}

TEST_CASE("grains: the Voronoi edges: each vertex is shared exactly; the nearest seed is found through the grid") {
  const std::vector<io::Point2> points = {{0.1, 0.1}, {0.9, 0.2}, {0.5, 0.8}, {0.45, 0.4}, {0.2, 0.7}};
  const auto edges = io::grain_boundaries(points, {0, 0}, {1, 1}, 0.0);
  // Each edge lies on the bisector of two seeds nearer than any other.
  for (const auto& e : edges) {
    CHECK(e.joint == -1);
    const io::Point2 mid{0.5 * (e.a[0] + e.b[0]), 0.5 * (e.a[1] + e.b[1])};
    std::vector<double> d;
    for (const auto& p : points) d.push_back(std::hypot(p[0] - mid[0], p[1] - mid[1]));
    std::sort(d.begin(), d.end());
    CHECK(d[1] - d[0] < 1e-12);
    CHECK(d[2] - d[1] > 1e-6);
  }
  // The inner vertex where seeds 0, 3 and 4 meet ends three edges, at the same doubles.
  size_t ends_at_any_shared = 0;
  for (size_t i = 0; i < edges.size(); ++i)
    for (size_t j = i + 1; j < edges.size(); ++j)
      for (const auto& u : {edges[i].a, edges[i].b})
        for (const auto& v : {edges[j].a, edges[j].b}) ends_at_any_shared += u == v;
  CHECK(ends_at_any_shared >= 6);  // ≥ 2 inner vertices of three edges (3 pairs each)
  const io::GrainFinder finder(points);
  for (double x = 0; x <= 1; x += 0.05)
    for (double y = 0; y <= 1; y += 0.05) {
      int best = 0;
      for (size_t k = 1; k < points.size(); ++k)
        if (std::hypot(points[k][0] - x, points[k][1] - y) < std::hypot(points[size_t(best)][0] - x, points[size_t(best)][1] - y))
          best = int(k);
      CHECK(finder.nearest({x, y}) == best);
    }
}

TEST_CASE("grains: bad [grains] keys are refused naming the key; fdem check prints the grains") {
  test::TempDir dir;
  auto has = [](const std::string& message, const std::string& part) {
    INFO(message);
    CHECK(message.find(part) != std::string::npos);
  };
  has(error(dir, {"grains.fractions=[0.7, 0.4]"}), "grains.fractions sum to 1.1, not 1");
  has(error(dir, {"grains.fractions=[0.7]"}), "grains.fractions must be an array of 2 numbers");
  has(error(dir, {"grains.fractions=[1.2, -0.2]"}), "grains.fractions[0]");
  const std::string three = "grains.fractions=[0.5, 0.3, 0.2]";
  has(error(dir, {"grains.minerals=[\"quartz\", \"feldspar\", \"qartz\"]", three}),
      "grains.minerals[2] = \"qartz\" is not the name of a [[material]] (did you mean \"quartz\"?)");
  has(error(dir, {"grains.minerals=[\"quartz\", \"feldspar\", \"steel\"]", three}), "without [material.fracture]");
  has(error(dir, {"grains.minerals=[\"quartz\", \"feldspar\", \"quartz\"]", three}), "listed twice");
  // A material left out of the minerals needs its regions again.
  has(error(dir, {"grains.minerals=[\"quartz\"]", "grains.fractions=[1.0]"}),
      "('feldspar') is missing required key 'regions' (or name it in grains.minerals");
  has(error(dir, {"grains.region=\"rok\""}), "grains.region = \"rok\" is not a physical surface");
  has(error(dir, {"grains.region=\"rok\""}), "did you mean 'rock'");
  has(error(dir, {"grains.size=0.01"}), "grains.size");  // both size and count
  has(error(dir, {"grains.count=0"}), "grains.count = 0 is out of range");
  has(error(dir, {"grains.count=6000"}), "grains.count = 6000 is out of range");
  has(error(dir, {"grains.count=1000"}), "grains.count = 1000 is too small for the mesh");
  has(error(dir, {"grains.seed=-1"}), "grains.seed");
  has(error(dir, {"grains.boundary.gf1=-5"}), "grains.boundary.gf1");
  has(error(dir, {"grains.colour=3"}), "unknown key 'colour' in [grains]");
  has(error(dir, {"material.2.regions=[\"base\", \"rock\"]"}), "is in the regions of material 'steel'");
  // size instead of count: the region's area over pi size^2 / 4 grains.
  test::TempDir other;
  const std::string text = [] {
    std::FILE* f = std::fopen(grains_case().c_str(), "rb");
    std::string s;
    char buffer[4096];
    size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) s.append(buffer, n);
    std::fclose(f);
    return s;
  }();
  std::string sized = text;
  sized.replace(sized.find("count = 60"), 10, "size = 0.0009");
  sized.replace(sized.find("geo = \"grains.geo\""), 18, "geo = \"" + test::source_path("tests/data/cases/grains.geo") + "\"");
  try {
    prepare_case(other.write("s.toml", sized), {"output.dir=\"" + other.str() + "/out\""});
    FAIL("a size below 3 elements was accepted");
  } catch (const InputError& e) {
    has(e.what(), "grains.size = 0.0009 m is too small for the mesh");
  }
  const test::FdemResult check =
      test::run_fdem_cli("check " + grains_case() + " --set output.dir='\"" + dir.str() + "/cli\"'");
  CHECK(check.code == 0);
  has(check.output, "grains    60 grains in 'rock' (seed 5), mean size ");
  has(check.output, "'quartz' 0.700 / ");
  const test::FdemResult bad =
      test::run_fdem_cli("check " + grains_case() + " --set grains.fractions='[0.5, 0.6]' --set output.dir='\"" + dir.str() + "/cli2\"'");
  CHECK(bad.code == 2);
  has(bad.output, "grains.fractions sum to 1.1");
}

TEST_CASE("grains: a run writes GRAIN in the frames and says which breaks are on grain boundaries") {
  test::TempDir dir;
  const std::vector<std::string> sets = {"time.steps=700", "boundary.1.velocity=[0.0, -50.0]",
                                         "output.dir=\"" + dir.str() + "/run\""};
  const test::FdemResult run = test::run_fdem_cli("run " + grains_case() + " --device cpu --quiet --set time.steps=700 --set "
                                                  "'boundary.1.velocity=[0.0,-50.0]' --set output.dir='\"" + dir.str() + "/run\"'");
  REQUIRE(run.code == 0);
  const PreparedCase p = prepare_case(grains_case(), sets);
  const Model& m = p.model;
  const std::string exo = dir.str() + "/run/grains.exo", events = dir.str() + "/run/grains_events.nc";
  // Blocks: quartz, feldspar, steel, cohesive. GRAIN is the grain + 1 on the minerals' triangles.
  for (int block = 1; block <= 4; ++block) {
    const auto grain = test::last_element_values(exo, "GRAIN", block);
    CAPTURE(block);
    REQUIRE(!grain.empty());
    if (block <= 2) {
      const size_t first = m.block_start[size_t(block - 1)];
      REQUIRE(grain.size() == m.block_start[size_t(block)] - first);
      for (size_t k = 0; k < grain.size(); ++k) CHECK(grain[k] == m.triangle_grain[first + k] + 1);
    } else {
      CHECK(*std::max_element(grain.begin(), grain.end()) == 0.0);
    }
  }
  const auto ce4 = test::read_variable(events, "break_ce4");
  const auto side = test::read_variable(events, "break_grain_boundary");
  REQUIRE(ce4.size() == side.size());
  size_t on = 0;
  for (size_t k = 0; k < ce4.size(); ++k) {
    CHECK(side[k] == m.ce4_grain_boundary[size_t(ce4[k])]);
    on += side[k] == 1;
  }
  MESSAGE(ce4.size() << " breaks, " << on << " on grain boundaries");
  CHECK(on > 0);
  CHECK(on < ce4.size());
}

}  // TEST_SUITE
