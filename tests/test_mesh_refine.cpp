// [mesh] refine = N (io/mesh_refine.cpp, engine/model/model.cpp): counts, geometry, groups,
// numbering, what the model builds on a refined mesh, and the case key. Meshes are the
// committed tests/data/gmsh/multi22a.msh and a bar built in memory: no gmsh needed.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "approx.hpp"
#include "base/errors.hpp"
#include "case_files.hpp"
#include "case_reader_fixture.hpp"
#include "engine/model/model.hpp"
#include "engine/run/run.hpp"
#include "io/case_config.hpp"
#include "io/gmsh_reader.hpp"

namespace {

using fdem::InputError;
using fdem::Model;
using fdem::io::Mesh;

std::string multi_path() { return fdem::test::source_path("tests/data/gmsh/multi22a.msh"); }

Mesh multi_mesh() {
  Mesh m = fdem::io::read_gmsh(multi_path());
  fdem::io::orient_triangles(m);
  return m;
}

Mesh refined(Mesh m, int levels) {
  fdem::io::refine_mesh(m, levels);
  return m;
}

double signed_area(const Mesh& m, const std::array<int, 3>& t) {
  return 0.5 * ((m.x[t[1]] - m.x[t[0]]) * (m.y[t[2]] - m.y[t[0]]) -
                (m.x[t[2]] - m.x[t[0]]) * (m.y[t[1]] - m.y[t[0]]));
}

double length(const Mesh& m, int a, int b) { return std::hypot(m.x[b] - m.x[a], m.y[b] - m.y[a]); }

// Number of triangles on each undirected edge.
std::map<std::pair<int, int>, int> edge_counts(const Mesh& m) {
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e) ++edges[std::minmax(t[e], t[(e + 1) % 3])];
  return edges;
}

std::map<int, double> area_per_group(const Mesh& m) {
  std::map<int, double> area;
  for (size_t t = 0; t < m.triangles.size(); ++t) area[m.triangle_group[t]] += signed_area(m, m.triangles[t]);
  return area;
}

std::map<int, double> length_per_group(const Mesh& m) {
  std::map<int, double> len;
  for (size_t l = 0; l < m.lines.size(); ++l) len[m.line_group[l]] += length(m, m.lines[l][0], m.lines[l][1]);
  return len;
}

// Distance of point p from segment a–b.
double off_segment(const Mesh& m, int p, int a, int b) {
  const double ex = m.x[b] - m.x[a], ey = m.y[b] - m.y[a];
  double s = ((m.x[p] - m.x[a]) * ex + (m.y[p] - m.y[a]) * ey) / (ex * ex + ey * ey);
  s = std::clamp(s, 0.0, 1.0);
  return std::hypot(m.x[p] - m.x[a] - s * ex, m.y[p] - m.y[a] - s * ey);
}

template <class T>
bool all_unique(std::vector<T> v) {
  std::sort(v.begin(), v.end());
  return std::adjacent_find(v.begin(), v.end()) == v.end();
}

// A bar [0, 2] × [0, 0.5] of nx × ny cells, two triangles each (diagonals alternating,
// every other triangle written clockwise so that orientation is fixed before the split):
// surfaces "left_part" (x < 1) and "right_part", curves "left", "right", "bottom", "top",
// point "corner" at (0, 0).
Mesh bar_mesh(int nx = 4, int ny = 2) {
  Mesh m;
  m.source = "bar";
  auto node = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      m.x.push_back(2.0 * i / nx);
      m.y.push_back(0.5 * j / ny);
      m.node_tags.push_back(100 + node(i, j));  // tags with an offset, as gmsh may leave gaps
    }
  m.groups = {{2, 1, "left_part"}, {2, 2, "right_part"}, {1, 3, "left"},  {1, 4, "right"},
              {1, 5, "bottom"},    {1, 6, "top"},        {0, 7, "corner"}};
  long tag = 1;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
      const int group = 2 * i < nx ? 0 : 1;
      if ((i + j) % 2 == 0) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, d, c});  // clockwise
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, d, c});  // clockwise
      }
      for (int k = 0; k < 2; ++k) {
        m.triangle_group.push_back(group);
        m.triangle_tags.push_back(tag++);
      }
    }
  auto line = [&](int a, int b, int group) {
    m.lines.push_back({a, b});
    m.line_group.push_back(group);
    m.line_tags.push_back(tag++);
  };
  for (int j = 0; j < ny; ++j) line(node(0, j + 1), node(0, j), 2);
  for (int j = 0; j < ny; ++j) line(node(nx, j), node(nx, j + 1), 3);
  for (int i = 0; i < nx; ++i) line(node(i, 0), node(i + 1, 0), 4);
  for (int i = 0; i < nx; ++i) line(node(i + 1, ny), node(i, ny), 5);
  m.points = {node(0, 0)};
  m.point_group = {6};
  return m;
}

fdem::io::MaterialConfig material(const std::string& name, std::vector<std::string> regions) {
  fdem::io::MaterialConfig mat;
  mat.name = name;
  mat.regions = std::move(regions);
  mat.density = 2500.0;
  mat.young = 30e9;
  mat.poisson = 0.25;
  return mat;
}

fdem::io::FractureConfig fracture() {
  fdem::io::FractureConfig f;
  f.tensile_strength = 1e6, f.cohesion = 2e6, f.friction_angle = 30, f.gf1 = 10, f.gf2 = 100;
  f.penalty_opening = f.penalty_sliding = f.penalty_overlap = 3e12;
  return f;
}

// The bar held on the left, pulled by a traction on the right.
fdem::io::CaseConfig bar_config(int refine) {
  fdem::io::CaseConfig c;
  c.path = "bar.toml";
  c.mesh.refine = refine;
  c.mesh.thickness = 0.5;
  c.materials = {material("rock", {"left_part", "right_part"})};
  fdem::io::BoundaryConfig held;
  held.region = "left";
  held.fix_x = held.fix_y = true;
  fdem::io::BoundaryConfig pulled;
  pulled.region = "right";
  pulled.traction = std::array<double, 2>{2e6, -1e5};
  c.boundaries = {held, pulled};
  return c;
}

}  // namespace

TEST_SUITE("gmsh") {

TEST_CASE("refine: T·4^N triangles, L·2^N lines, nodes by Euler's formula, points kept") {
  const Mesh coarse = multi_mesh();
  const auto coarse_edges = edge_counts(coarse);
  // The fixture is the unit square, one piece without holes: V − E + T = 1.
  REQUIRE(coarse.x.size() - coarse_edges.size() + coarse.triangles.size() == 1);
  long T = static_cast<long>(coarse.triangles.size()), E = static_cast<long>(coarse_edges.size());
  for (int n = 0; n <= 3; ++n) {
    CAPTURE(n);
    const Mesh m = refined(coarse, n);
    CHECK(m.triangles.size() == coarse.triangles.size() << (2 * n));
    CHECK(m.triangle_group.size() == m.triangles.size());
    CHECK(m.triangle_tags.size() == m.triangles.size());
    CHECK(m.lines.size() == coarse.lines.size() << n);
    CHECK(m.line_group.size() == m.lines.size());
    CHECK(m.line_tags.size() == m.lines.size());
    CHECK(m.points == coarse.points);
    CHECK(m.point_group == coarse.point_group);
    CHECK(m.groups.size() == coarse.groups.size());
    // Each level adds one node per edge and turns E edges into 2E + 3T.
    CHECK(static_cast<long>(m.x.size()) == 1 + E - T);
    CHECK(static_cast<long>(edge_counts(m).size()) == E);
    CHECK(m.node_tags.size() == m.x.size());
    E = 2 * E + 3 * T;
    T = 4 * T;
  }
}

TEST_CASE("refine: areas per surface and lengths per curve kept, children inside parents, orientation positive") {
  const Mesh coarse = multi_mesh();
  const auto area0 = area_per_group(coarse);
  const auto len0 = length_per_group(coarse);
  for (int n = 1; n <= 2; ++n) {
    CAPTURE(n);
    const Mesh m = refined(coarse, n);
    const auto area = area_per_group(m);
    const auto len = length_per_group(m);
    REQUIRE(area.size() == area0.size());
    REQUIRE(len.size() == len0.size());
    for (const auto& [g, a] : area0) CHECK(area.at(g) == fdem::test::rel(a, 1e-13));
    for (const auto& [g, l] : len0) CHECK(len.at(g) == doctest::Approx(l).epsilon(1e-13));
    for (size_t t = 0; t < m.triangles.size(); ++t) {
      const size_t parent = t >> (2 * n);
      CHECK(m.triangle_group[t] == coarse.triangle_group[parent]);
      const double a = signed_area(m, m.triangles[t]);
      CHECK(a > 0);
      CHECK(a == fdem::test::rel(signed_area(coarse, coarse.triangles[parent]) / (1 << (2 * n)), 1e-9));
    }
    // Every refined line lies on its parent line element, in the same direction.
    for (size_t l = 0; l < m.lines.size(); ++l) {
      const size_t parent = l >> n;
      const int pa = coarse.lines[parent][0], pb = coarse.lines[parent][1];
      const double scale = length(coarse, pa, pb);
      CHECK(m.line_group[l] == coarse.line_group[parent]);
      for (int end = 0; end < 2; ++end) CHECK(off_segment(m, m.lines[l][end], pa, pb) <= 1e-14 * scale);
      const double along = (m.x[m.lines[l][1]] - m.x[m.lines[l][0]]) * (coarse.x[pb] - coarse.x[pa]) +
                           (m.y[m.lines[l][1]] - m.y[m.lines[l][0]]) * (coarse.y[pb] - coarse.y[pa]);
      CHECK(along > 0);
    }
  }
}

TEST_CASE("refine: midpoints shared, tags unique and numbered after the file's, runs reproducible") {
  const Mesh coarse = multi_mesh();
  const Mesh m = refined(coarse, 2);
  // No two nodes at one place: each edge got one midpoint, shared by its triangles and lines.
  std::vector<std::pair<double, double>> points;
  for (size_t k = 0; k < m.x.size(); ++k) points.emplace_back(m.x[k], m.y[k]);
  CHECK(all_unique(points));
  // The old nodes keep their indices, coordinates and tags.
  CHECK(std::equal(coarse.x.begin(), coarse.x.end(), m.x.begin()));
  CHECK(std::equal(coarse.node_tags.begin(), coarse.node_tags.end(), m.node_tags.begin()));
  CHECK(all_unique(m.node_tags));
  std::vector<long> elements = m.triangle_tags;
  elements.insert(elements.end(), m.line_tags.begin(), m.line_tags.end());
  CHECK(all_unique(elements));
  // multi22a.msh has elements 1–67 (duplicates and the point included) and nodes 1–22.
  CHECK(coarse.max_element_tag == 67);
  const Mesh once = refined(coarse, 1);
  CHECK(once.node_tags[22] == 23);
  CHECK(once.triangle_tags.front() == 68);
  CHECK(once.triangle_tags.back() == 67 + 4 * 28);
  CHECK(once.line_tags.front() == 67 + 4 * 28 + 1);
  CHECK(once.max_element_tag == 67 + 4 * 28 + 2 * 8);
  CHECK(*std::min_element(m.triangle_tags.begin(), m.triangle_tags.end()) > once.max_element_tag);
  // Refining twice at once is refining once, twice; and the same input gives the same mesh.
  const Mesh again = refined(once, 1);
  CHECK(again.x == m.x);
  CHECK(again.y == m.y);
  CHECK(again.triangles == m.triangles);
  CHECK(again.triangle_tags == m.triangle_tags);
  CHECK(again.lines == m.lines);
  CHECK(again.line_tags == m.line_tags);
  CHECK(refined(coarse, 2).triangles == m.triangles);
  // Level 0 leaves the mesh as it was.
  const Mesh zero = refined(coarse, 0);
  CHECK(zero.x == coarse.x);
  CHECK(zero.triangles == coarse.triangles);
  CHECK(zero.lines == coarse.lines);
  CHECK(zero.triangle_tags == coarse.triangle_tags);
}

TEST_CASE("refine: a refinement past 2^31 - 1 triangles is refused, naming the key") {
  Mesh m = multi_mesh();
  CHECK_THROWS_WITH_AS(fdem::io::refine_mesh(m, 14, "c.toml: mesh.refine = 14"),
                       doctest::Contains("c.toml: mesh.refine = 14: 28 triangles refined 14 times would be more than "
                                         "2^31 - 1 triangles"),
                       InputError);
  CHECK(m.triangles.size() == 28);  // refused before any work
  // 13 levels stay under 2^31 (1.9e9 triangles) but not under any machine's memory at
  // about 1 KB a triangle: refused too, before any work, rather than killed for memory.
  CHECK_THROWS_WITH_AS(fdem::io::refine_mesh(m, 13, "c.toml: mesh.refine = 13"),
                       doctest::Contains("GB of host memory at 1 KB each; this machine has"), InputError);
  CHECK(m.triangles.size() == 28);
}

TEST_CASE("refine in build_model: loads, supports and regions on refined curves; Δt halves per level") {
  const Mesh mesh = bar_mesh();
  std::vector<std::string> notes;
  const Model coarse = fdem::build_model(mesh, bar_config(0), notes);
  const double dt0 = fdem::stable_time_step(coarse).dt;
  for (int n = 1; n <= 2; ++n) {
    CAPTURE(n);
    notes.clear();
    const Model m = fdem::build_model(mesh, bar_config(n), notes);
    CHECK(m.num_triangles() == coarse.num_triangles() << (2 * n));
    // (nx·2^N + 1)(ny·2^N + 1) nodes of the refined grid.
    CHECK(m.num_nodes() == static_cast<size_t>((4 * (1 << n) + 1) * (2 * (1 << n) + 1)));
    CHECK(std::find_if(notes.begin(), notes.end(), [&](const std::string& s) {
            return s.find("bar refined (mesh.refine = " + std::to_string(n) + "): 16 → " +
                          std::to_string(16 << (2 * n)) + " triangles") != std::string::npos;
          }) != notes.end());
    for (const auto& t : m.triangles)
      CHECK((m.x[t[1]] - m.x[t[0]]) * (m.y[t[2]] - m.y[t[0]]) - (m.x[t[2]] - m.x[t[0]]) * (m.y[t[1]] - m.y[t[0]]) > 0);
    // The traction acts on every refined edge of "right": same loaded length, so the same
    // total force, and each loaded edge on x = 2 with the body on its left.
    REQUIRE(m.loaded_edges.size() == coarse.loaded_edges.size() << n);
    double loaded = 0, loaded0 = 0;
    for (const auto& e : m.loaded_edges) {
      loaded += std::hypot(m.x[e.b] - m.x[e.a], m.y[e.b] - m.y[e.a]);
      CHECK(m.x[e.a] == 2.0);
      CHECK(m.x[e.b] == 2.0);
      CHECK(m.y[e.b] > m.y[e.a]);
    }
    for (const auto& e : coarse.loaded_edges) loaded0 += std::hypot(coarse.x[e.b] - coarse.x[e.a], coarse.y[e.b] - coarse.y[e.a]);
    CHECK(loaded == fdem::test::rel(loaded0, 1e-14));
    CHECK(loaded * m.thickness * m.loads[0].tx == doctest::Approx(0.5 * 0.5 * 2e6).epsilon(1e-14));
    // Every node on x = 0 is held (the support covers the new midpoints), and no other.
    size_t on_left = 0;
    for (size_t k = 0; k < m.num_nodes(); ++k) {
      const bool left = m.x[k] == 0.0;
      on_left += left;
      CHECK((m.node_group[k] != 0) == left);
    }
    CHECK(on_left == static_cast<size_t>(2 * (1 << n) + 1));
    // A uniform split halves every triangle's height, so the stable step.
    CHECK(fdem::stable_time_step(m).dt == fdem::test::rel(dt0 / (1 << n), 1e-12));
  }
}

TEST_CASE("refine in build_model: CE4s on exactly the interior edges of the refined fracturable region") {
  const Mesh mesh = bar_mesh();
  auto config = bar_config(0);
  config.boundaries.clear();
  config.materials = {material("weak", {"left_part"}), material("strong", {"right_part"})};
  config.materials[0].fracture = fracture();
  for (int n = 0; n <= 2; ++n) {
    CAPTURE(n);
    config.mesh.refine = n;
    std::vector<std::string> notes;
    const Model m = fdem::build_model(mesh, config, notes);
    // Independently: edges of the refined mesh between two "left_part" triangles.
    Mesh fine = mesh;
    fdem::io::orient_triangles(fine);
    fdem::io::refine_mesh(fine, n);
    std::map<std::pair<int, int>, int> inside;
    for (size_t t = 0; t < fine.triangles.size(); ++t)
      if (fine.triangle_group[t] == 0)
        for (int e = 0; e < 3; ++e) ++inside[std::minmax(fine.triangles[t][e], fine.triangles[t][(e + 1) % 3])];
    const auto interior = std::count_if(inside.begin(), inside.end(), [](const auto& kv) { return kv.second == 2; });
    CHECK(m.ce4.size() == static_cast<size_t>(interior));
    // The half-bar is 2 × 2 cells: 8 interior edges, 2I + 3T per level.
    const long expected[] = {8, 2 * 8 + 3 * 8, 2 * (2 * 8 + 3 * 8) + 3 * 32};
    CHECK(static_cast<long>(m.ce4.size()) == expected[n]);
  }
}

TEST_CASE("refine = 0 builds the very model of the mesh as read; refine = N the model of the refined mesh") {
  const Mesh mesh = multi_mesh();
  auto config = bar_config(0);
  config.materials = {material("a", {"left_half"}), material("b", {"right_half"})};
  config.materials[0].fracture = fracture();
  fdem::io::BoundaryConfig pressed;
  pressed.region = "top";
  pressed.pressure = 1e6;
  config.boundaries = {pressed};
  auto same = [](const Model& p, const Model& q) {
    CHECK(p.x == q.x);
    CHECK(p.y == q.y);
    CHECK(p.node_tags == q.node_tags);
    CHECK(p.triangles == q.triangles);
    CHECK(p.triangle_tags == q.triangle_tags);
    CHECK(p.triangle_material == q.triangle_material);
    CHECK(p.node_group == q.node_group);
    CHECK(p.ce4 == q.ce4);
    CHECK(p.ce4_triangles == q.ce4_triangles);
    REQUIRE(p.loaded_edges.size() == q.loaded_edges.size());
    for (size_t k = 0; k < p.loaded_edges.size(); ++k) {
      CHECK(p.loaded_edges[k].a == q.loaded_edges[k].a);
      CHECK(p.loaded_edges[k].b == q.loaded_edges[k].b);
    }
  };
  std::vector<std::string> notes, notes0;
  fdem::io::CaseConfig plain = config;
  plain.mesh = fdem::io::MeshConfig{};  // as a case without the key
  plain.mesh.thickness = config.mesh.thickness;
  const Model as_read = fdem::build_model(mesh, plain, notes0);
  same(fdem::build_model(mesh, config, notes), as_read);
  CHECK(notes == notes0);  // no refinement note either

  Mesh fine = mesh;
  fdem::io::refine_mesh(fine, 1);
  config.mesh.refine = 1;
  same(fdem::build_model(mesh, config, notes), fdem::build_model(fine, plain, notes0));
}

TEST_CASE("refine through a case file: prepare_case sees the refined mesh everywhere, probes included") {
  fdem::test::case_reader::CaseDir d;
  const std::string text = "[mesh]\nfile = \"" + multi_path() +
                           "\"\n[time]\ndt = \"auto\"\nsteps = 10\n"
                           "[[material]]\nname = \"rock\"\nregions = [\"left_half\", \"right_half\"]\n"
                           "density = 2500.0\nyoung = 30e9\npoisson = 0.25\n"
                           "[[boundary]]\nregion = \"bottom\"\nfix = [\"x\", \"y\"]\n"
                           "[[boundary]]\nregion = \"top\"\ntraction = [0.0, -1e6]\n"
                           "[[probe]]\nname = \"p\"\npoint = [0.375, 1.0]\n";
  const std::string path = d.write("c.toml", text);
  const auto coarse = fdem::prepare_case(path, {});
  const auto fine = fdem::prepare_case(path, {"mesh.refine=1"});
  CHECK(fine.config.mesh.refine == 1);
  CHECK(fine.model.num_triangles() == 4 * coarse.model.num_triangles());
  CHECK(fine.model.num_nodes() == 71);
  CHECK(fine.model.loaded_edges.size() == 2 * coarse.model.loaded_edges.size());
  CHECK(fine.stable.dt < 0.6 * coarse.stable.dt);
  CHECK(fine.steps == 10);
  // (0.375, 1) is the midpoint of the top edge from 0.25 to 0.5: a node only once refined.
  REQUIRE(fine.probes.size() == 1);
  CHECK(fine.probes[0].node_distance < 1e-12);
  CHECK(coarse.probes[0].node_distance > 0.1);
  CHECK(fine.model.node_tags[fine.probes[0].node] > 22);
}

}  // TEST_SUITE("gmsh")

TEST_SUITE("case") {

using namespace fdem::test::case_reader;

TEST_CASE("mesh.refine: an integer >= 0, 0 when absent, settable with --set, misspellings suggested") {
  CaseDir d;
  CHECK(fdem::io::read_case(d.write("a.toml", kBase)).mesh.refine == 0);
  CHECK(fdem::io::read_case(d.write("b.toml", with(kBase, "[time]", "refine = 2\n[time]"))).mesh.refine == 2);
  CHECK(fdem::io::read_case(d.write("c.toml", kBase), {"mesh.refine=1"}).mesh.refine == 1);
  CHECK(fdem::io::read_case(d.write("e.toml", with(kBase, "[time]", "refine = 0\n[time]"))).mesh.refine == 0);
  // refine sits on line 4, after [mesh] (2) and file (3).
  CHECK(error_of(with(kBase, "[time]", "refine = 1.5\n[time]")) ==
        contains(":4: mesh.refine must be an integer, found number 1.5"));
  CHECK(error_of(with(kBase, "[time]", "refine = -1\n[time]")) ==
        contains(":4: mesh.refine = -1 is out of range (allowed: mesh.refine >= 0"));
  CHECK(error_of(with(kBase, "[time]", "refine = \"2\"\n[time]")) ==
        contains(":4: mesh.refine must be an integer, found string \"2\""));
  CHECK(error_of(with(kBase, "[time]", "refin = 1\n[time]")) ==
        contains(":4: unknown key 'refin' in [mesh] (did you mean 'refine'?)"));
  CHECK_THROWS_WITH_AS(fdem::io::read_case(d.write("f.toml", kBase), {"mesh.refine=-2"}),
                       contains("mesh.refine = -2 is out of range"), InputError);
}

}  // TEST_SUITE("case")

TEST_SUITE("case") {

// [contact] without `rebuild` or `skin` (issue 13): rebuild "skin", the margin a fifth of
// the mean edge length. The bar's cells are 0.5 × 0.25 m, each cut by a diagonal: every
// triangle has edges 0.5, 0.25 and √(0.5² + 0.25²).
TEST_CASE("contact defaults: skin rebuild, margin a fifth of the mean edge, halving per refine level") {
  const Mesh mesh = bar_mesh();
  const double mean_edge = (0.5 + 0.25 + std::sqrt(0.5 * 0.5 + 0.25 * 0.25)) / 3;
  for (int n = 0; n <= 2; ++n) {
    CAPTURE(n);
    auto config = bar_config(n);
    config.contact = fdem::io::ContactConfig{};
    config.contact->normal_penalty = 1e9;
    std::vector<std::string> notes;
    const Model m = fdem::build_model(mesh, config, notes);
    CHECK(m.contact.rebuild_skin);
    CHECK(m.contact.skin_from_mesh);
    CHECK(m.contact.skin == fdem::test::rel(0.2 * mean_edge / (1 << n), 1e-12));
    // A given skin is kept; "step" without a skin does not enlarge the boxes.
    config.contact->skin = 1e-3;
    const Model given = fdem::build_model(mesh, config, notes);
    CHECK(given.contact.rebuild_skin);
    CHECK_FALSE(given.contact.skin_from_mesh);
    CHECK(given.contact.skin == 1e-3);
    config.contact->skin.reset();
    config.contact->rebuild = fdem::io::ContactRebuild::Step;
    const Model step = fdem::build_model(mesh, config, notes);
    CHECK_FALSE(step.contact.rebuild_skin);
    CHECK_FALSE(step.contact.skin_from_mesh);
    CHECK(step.contact.skin == 0.0);
  }
}

}  // TEST_SUITE("case")
