// Tests of the Gmsh reader: the four MSH forms, tag gaps, skipped types, every error
// case, triangle orientation and .geo meshing with its cache.
#include <doctest/doctest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "io/gmsh_reader.hpp"

namespace fs = std::filesystem;
using fdem::InputError;
using fdem::io::Mesh;

namespace {

std::string fixture(const std::string& name) {
  return std::string(FDEM_SOURCE_DIR) + "/tests/data/gmsh/" + name;
}

bool contains(const std::vector<std::string>& notes, const std::string& part) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(part) != std::string::npos; });
}

// Rounded so that ASCII (16 digits) and binary (exact) forms of one mesh compare equal.
std::string point_text(const Mesh& m, int node) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.12g,%.12g)", m.x[node], m.y[node]);
  return buf;
}

// Each triangle as its group name and corner coordinates, rotated to start at the
// smallest corner (keeping the orientation), then sorted: equal for meshes that differ
// only in node and element numbering.
std::vector<std::string> triangle_signature(const Mesh& m) {
  std::vector<std::string> out;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    std::vector<std::string> p;
    for (int n : m.triangles[t]) p.push_back(point_text(m, n));
    std::rotate(p.begin(), std::min_element(p.begin(), p.end()), p.end());
    out.push_back(m.groups.at(m.triangle_group[t]).name + ":" + p[0] + p[1] + p[2]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> line_signature(const Mesh& m) {
  std::vector<std::string> out;
  for (size_t l = 0; l < m.lines.size(); ++l)
    out.push_back(m.groups.at(m.line_group[l]).name + ":" + point_text(m, m.lines[l][0]) + point_text(m, m.lines[l][1]));
  for (size_t p = 0; p < m.points.size(); ++p) out.push_back(m.groups.at(m.point_group[p]).name + ":" + point_text(m, m.points[p]));
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> group_signature(const Mesh& m) {
  std::vector<std::string> out;
  for (const auto& g : m.groups) out.push_back(std::to_string(g.dim) + ":" + g.name);
  return out;
}

// A fresh directory under the system temp dir, removed at scope end.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("fdem_gmsh_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f << bytes;
}

}  // namespace

TEST_SUITE("gmsh") {

TEST_CASE("the fixture square reads alike in MSH 2.2/4.1, ASCII/binary, both byte orders") {
  const Mesh ref = fdem::io::read_gmsh(fixture("sq41a.msh"));
  REQUIRE(ref.x.size() == 22);
  REQUIRE(ref.triangles.size() == 28);
  CHECK(ref.lines.size() == 8);
  CHECK(ref.points.size() == 1);
  CHECK(group_signature(ref) == std::vector<std::string>{"0:origin", "1:bottom", "1:top", "2:left_half", "2:right_half"});
  const int left = ref.find_group("left_half", 2);
  REQUIRE(left >= 0);
  CHECK(std::count(ref.triangle_group.begin(), ref.triangle_group.end(), left) == 14);
  CHECK(ref.find_group("bottom", 1) >= 0);
  CHECK(ref.find_group("bottom", 2) == -1);
  CHECK(ref.source == fixture("sq41a.msh"));
  CHECK(ref.triangle_tags.size() == ref.triangles.size());
  CHECK(ref.line_tags.size() == ref.lines.size());

  for (const char* name : {"sq22a.msh", "sq22b.msh", "sq22b_be.msh", "sq41b.msh"}) {
    CAPTURE(name);
    std::vector<std::string> notes;
    const Mesh m = fdem::io::read_gmsh(fixture(name), &notes);
    CHECK(notes.empty());
    CHECK(m.x.size() == ref.x.size());
    CHECK(m.node_tags == ref.node_tags);
    CHECK(m.triangles.size() == ref.triangles.size());
    CHECK(m.lines.size() == ref.lines.size());
    CHECK(m.points.size() == ref.points.size());
    CHECK(group_signature(m) == group_signature(ref));
    CHECK(triangle_signature(m) == triangle_signature(ref));
    CHECK(line_signature(m) == line_signature(ref));
  }
}

TEST_CASE("node tags with gaps, parametric nodes, skipped types and sections, multi-group entity") {
  std::vector<std::string> notes;
  const Mesh m = fdem::io::read_gmsh(fixture("gaps41.msh"), &notes);
  CHECK(m.node_tags == std::vector<long>{60, 20, 36, 10, 35, 50, 51});
  REQUIRE(m.x.size() == 7);
  CHECK(m.x[0] == 1.5);
  CHECK(m.x[1] == 1.0);
  CHECK(m.y[2] == 1.0);
  REQUIRE(m.triangles.size() == 2);
  CHECK(m.triangles[0] == std::array<int, 3>{3, 1, 2});
  CHECK(m.triangles[1] == std::array<int, 3>{3, 2, 4});
  CHECK(m.triangle_tags == std::vector<long>{1, 2});
  REQUIRE(m.lines.size() == 1);
  CHECK(m.lines[0] == std::array<int, 2>{3, 1});
  CHECK(m.line_tags == std::vector<long>{5});
  CHECK(group_signature(m) == std::vector<std::string>{"1:edge", "2:rock", "2:also rock"});
  CHECK(m.triangle_group == std::vector<int>{1, 1});
  CHECK(m.line_group == std::vector<int>{0});
  CHECK(notes.size() == 3);
  CHECK(contains(notes, "skipped 1 elements of Gmsh type 3 (4-node quadrangle)"));
  CHECK(contains(notes, "skipped 1 elements of Gmsh type 8 (3-node line)"));
  CHECK(contains(notes, "surface entity 5 is in physical groups 1, 2"));
}

TEST_CASE("entities in two physical groups: 2.2 element copies are dropped, 4.1 takes the first group") {
  const Mesh ref = fdem::io::read_gmsh(fixture("sq41a.msh"));
  for (const char* name : {"multi22a.msh", "multi41b.msh"}) {
    CAPTURE(name);
    std::vector<std::string> notes;
    const Mesh m = fdem::io::read_gmsh(fixture(name), &notes);
    CHECK(m.triangles.size() == 28);
    CHECK(m.triangle_tags.size() == 28);
    CHECK(m.lines.size() == 8);
    CHECK(m.line_tags.size() == 8);
    CHECK(m.points.size() == 1);
    CHECK(group_signature(m) == std::vector<std::string>{"0:origin", "1:bottom", "1:top", "1:bottom_left", "2:left_half", "2:right_half", "2:all"});
    CHECK(triangle_signature(m) == triangle_signature(ref));
    CHECK(line_signature(m) == line_signature(ref));
    CHECK(notes.size() == 3);
    CHECK(contains(notes, "surface entity 1 is in physical groups 1, 6; its elements are assigned to the first (1) only"));
    CHECK(contains(notes, "surface entity 2 is in physical groups 2, 6"));
    CHECK(contains(notes, "curve entity 1 is in physical groups 3, 7"));
  }
}

TEST_CASE("MSH 2.2: unnamed physical group, second-order line and unknown type are skipped") {
  std::vector<std::string> notes;
  const Mesh m = fdem::io::read_gmsh(fixture("unnamed22.msh"), &notes);
  CHECK(m.triangles.size() == 2);
  CHECK(m.lines.empty());
  REQUIRE(m.groups.size() == 1);
  CHECK(m.groups[0].name.empty());
  CHECK(m.groups[0].dim == 2);
  CHECK(m.groups[0].tag == 4);
  CHECK(m.find_group("", 2) == 0);
  CHECK(contains(notes, "skipped 1 elements of Gmsh type 8 (3-node line)"));
  CHECK(contains(notes, "Gmsh type 99"));
}

TEST_CASE("malformed files throw InputError naming the file and the fault") {
  using doctest::Contains;
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("does_not_exist.msh")), Contains("does_not_exist.msh: Gmsh mesh file not found"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("")), Contains("is a directory"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("not_gmsh.msh")), Contains("not_gmsh.msh: not a Gmsh .msh file"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("version40.msh")), Contains("unsupported MSH version 4.0; fdem reads MSH 2.2 and 4.1"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("version40.msh")), Contains("version40.msh: line 2"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("bad_number.msh")), Contains("bad_number.msh: line 11 ($Nodes): expected y coordinate (a number), found 'abc'"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("missing_endnodes.msh")), Contains("missing_endnodes.msh: line 9 ($Nodes): missing $EndNodes"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("unknown_node.msh")), Contains("unknown_node.msh: line 17 ($Elements): element 2 refers to unknown node tag 99"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("untagged_triangle.msh")), Contains("untagged_triangle.msh: line 18: triangles of surface entity 7 have no physical group; name every surface"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("no_groups.msh")), Contains("no_groups.msh: the mesh has no physical groups; fdem needs named physical surfaces"), InputError);
  std::vector<std::string> notes;
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fixture("tri6_only.msh"), &notes), Contains("tri6_only.msh: no 3-node triangles"), InputError);
  CHECK(contains(notes, "skipped 1 elements of Gmsh type 9 (6-node triangle): fdem uses 3-node triangles only; mesh with Mesh.ElementOrder = 1"));
}

TEST_CASE("duplicate node tags, misplaced sections and missing sections throw") {
  using doctest::Contains;
  TempDir dir("ascii");
  const std::string head = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  const std::string nodes = "$Nodes\n3\n1 0 0 0\n2 1 0 0\n1 0 1 0\n$EndNodes\n";
  const std::string elements = "$Elements\n1\n1 2 2 1 1 1 2 3\n$EndElements\n";
  write_bytes(dir.path / "dup.msh", head + nodes + elements);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh((dir.path / "dup.msh").string()), Contains("dup.msh: line 8 ($Nodes): node tag 1 appears twice"), InputError);
  write_bytes(dir.path / "order.msh", head + elements);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh((dir.path / "order.msh").string()), Contains("order.msh: line 4 ($Elements): $Elements before $Nodes"), InputError);
  write_bytes(dir.path / "only_nodes.msh", head + "$Nodes\n1\n1 0 0 0\n$EndNodes\n");
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh((dir.path / "only_nodes.msh").string()), Contains("only_nodes.msh: no $Elements section"), InputError);
  write_bytes(dir.path / "stray.msh", head + "junk\n");
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh((dir.path / "stray.msh").string()), Contains("stray.msh: line 4: expected a section header"), InputError);
  write_bytes(dir.path / "wrong_end.msh", head + "$Nodes\n1\n1 0 0 0\n$Elements\n");
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh((dir.path / "wrong_end.msh").string()), Contains("wrong_end.msh: line 7 ($Nodes): expected $EndNodes, found '$Elements'"), InputError);
  write_bytes(dir.path / "open_section.msh", head + "$Periodic\n0\n");
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh((dir.path / "open_section.msh").string()), Contains("open_section.msh: line 5 ($Periodic): missing $EndPeriodic"), InputError);
}

TEST_CASE("binary files that are truncated or corrupt throw") {
  using doctest::Contains;
  TempDir dir("binary");
  const std::string full = read_bytes(fixture("sq41b.msh"));
  const size_t nodes_at = full.find("$Nodes");
  REQUIRE(nodes_at != std::string::npos);
  const fs::path cut = dir.path / "cut41b.msh";
  write_bytes(cut, full.substr(0, nodes_at + 200));
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(cut.string()), Contains("cut41b.msh: byte "), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(cut.string()), Contains("($Nodes): unexpected end of file"), InputError);

  std::string bad_one = read_bytes(fixture("sq22b.msh"));
  const size_t one_at = bad_one.find("2.2 1 8\n") + 8;
  bad_one[one_at] = 7;  // the endianness check integer
  const fs::path odd = dir.path / "odd22b.msh";
  write_bytes(odd, bad_one);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(odd.string()), Contains("odd22b.msh: byte 20 ($MeshFormat): binary endianness check failed"), InputError);
}

TEST_CASE("orient_triangles flips clockwise triangles and rejects degenerate ones") {
  Mesh m;
  m.source = "hand.msh";
  m.x = {0, 1, 0, 1, 2};
  m.y = {0, 0, 1, 1, 2};
  m.node_tags = {101, 102, 103, 104, 105};
  m.triangles = {{0, 1, 2}, {0, 2, 1}};
  m.triangle_tags = {7, 8};
  std::vector<std::string> notes;
  CHECK(fdem::io::orient_triangles(m, &notes) == 1);
  CHECK(m.triangles[0] == std::array<int, 3>{0, 1, 2});
  CHECK(m.triangles[1] == std::array<int, 3>{0, 1, 2});
  REQUIRE(notes.size() == 1);
  CHECK(notes[0].find("hand.msh") != std::string::npos);
  CHECK(notes[0].find("Gmsh element 8") != std::string::npos);
  CHECK(fdem::io::orient_triangles(m, &notes) == 0);
  CHECK(notes.size() == 1);

  Mesh many = m;
  many.triangles.assign(13, {0, 2, 1});
  many.triangle_tags.assign(13, 1);
  notes.clear();
  CHECK(fdem::io::orient_triangles(many, &notes) == 13);
  CHECK(notes.size() == 11);
  CHECK(notes.back().find("13 clockwise triangles re-oriented in all (3 not listed)") != std::string::npos);

  Mesh flat = m;
  flat.triangles = {{0, 1, 2}, {0, 3, 4}};  // (0,0), (1,1), (2,2) are collinear
  CHECK_THROWS_WITH_AS(fdem::io::orient_triangles(flat), doctest::Contains("hand.msh: degenerate triangle (Gmsh element 8) with nodes 101 (0, 0), 104 (1, 1), 105 (2, 2)"), InputError);
  flat.triangles = {{0, 1, 2}, {0, 3, 3}};
  CHECK_THROWS_WITH_AS(fdem::io::orient_triangles(flat), doctest::Contains("Gmsh element 8"), InputError);

  Mesh sliver = m;
  sliver.x = {0, 1, 0.5};
  sliver.y = {0, 0, 1e-6};
  sliver.triangles = {{0, 1, 2}};
  sliver.triangle_tags = {3};
  CHECK(fdem::io::orient_triangles(sliver, nullptr, 1e-10) == 0);
  CHECK_THROWS_AS(fdem::io::orient_triangles(sliver, nullptr, 1e-5), InputError);
}

TEST_CASE("orient_triangles leaves the fixture mesh counter-clockwise") {
  Mesh m = fdem::io::read_gmsh(fixture("sq22b.msh"));
  fdem::io::orient_triangles(m);
  for (const auto& t : m.triangles) {
    const double cross = (m.x[t[1]] - m.x[t[0]]) * (m.y[t[2]] - m.y[t[0]]) - (m.x[t[2]] - m.x[t[0]]) * (m.y[t[1]] - m.y[t[0]]);
    CHECK(cross > 0);
  }
}

TEST_CASE("read_gmsh names a directory, a FIFO and a device instead of reading them") {
  using doctest::Contains;
  TempDir dir("special");
  const fs::path fifo = dir.path / "pipe.msh";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh(fifo.string()), Contains("pipe.msh: is not a regular file"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::read_gmsh("/dev/zero"), Contains("/dev/zero: is not a regular file"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo("/dev/zero", 0, dir.path.string()), Contains("/dev/zero: is not a regular file"), InputError);
}

TEST_CASE("geo_program_commands lists what would run a program, outside comments and strings") {
  TempDir dir("programs");
  write_bytes(dir.path / "inner.geo", "x = 1;\nNonBlockingSystemCall \"sleep 1\";\n");
  write_bytes(dir.path / "outer.geo",
              "// SystemCall \"in a comment\";\n"
              "/* OnelabRun(\"in a block comment\"); */\n"
              "Printf(\"SystemCall in a string\");\n"
              "SystemCall \"touch marker\";\n"
              "Include \"inner.geo\";\n"
              "Merge \"mesh.msh\";\n"
              "Merge \"tool.py\";\n"
              "Include Sprintf(\"part%g.geo\", 1);\n"
              "System \"ls\"; OnelabRun(\"x\", \"y\");\n");
  const auto found = fdem::io::geo_program_commands((dir.path / "outer.geo").string());
  const std::string outer = (dir.path / "outer.geo").string(), inner = (dir.path / "inner.geo").string();
  CHECK(found == std::vector<std::string>{
                     outer + ":4: SystemCall (runs a program)",
                     inner + ":2: NonBlockingSystemCall (runs a program)",
                     outer + ":7: Merge \"tool.py\" (gmsh runs .py files and other programs it merges)",
                     outer + ":8: Include of a file whose name is computed (it cannot be checked)",
                     outer + ":9: System (runs a program)",
                     outer + ":9: OnelabRun (runs a program)"});
  for (const char* name : {"sq.geo", "bad_syntax.geo", "multi.geo"}) CHECK(fdem::io::geo_program_commands(fixture(name)).empty());
  for (const char* rel : {"cases/geostatic/column.geo", "cases/blasting/blasting.geo", "cases/wave-bar/bar.geo", "cases/stack/stack.geo"})
    CHECK(fdem::io::geo_program_commands(std::string(FDEM_SOURCE_DIR) + "/" + rel).empty());
}

TEST_CASE("mesh_geo refuses a .geo that runs programs unless allowed") {
  using doctest::Contains;
  TempDir dir("systemcall");
  const fs::path marker = dir.path / "marker";
  const fs::path geo = dir.path / "sq_call.geo";
  write_bytes(geo, read_bytes(fixture("sq.geo")) + "SystemCall \"touch " + marker.string() + "\";\n");
  const std::string cache = (dir.path / "cache").string();
  fdem::io::GeoMeshing options;
  const std::string expected = "sq_call.geo: this .geo file would make gmsh run other programs:\n  " + geo.string() + ":29: SystemCall";
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(geo.string(), 0, cache, options), Contains(expected.c_str()), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(geo.string(), 0, cache, options), Contains("--allow-geo-programs"), InputError);
  CHECK_FALSE(fs::exists(marker));
  CHECK_FALSE(fs::exists(cache));  // refused before anything was written
  if (fdem::io::find_on_path("gmsh").empty()) return;  // the rest runs gmsh
  options.allow_programs = true;
  CHECK(fdem::io::read_gmsh(fdem::io::mesh_geo(geo.string(), 0, cache, options)).triangles.size() == 28);
  CHECK(fs::exists(marker));
}

// The two tests below need the gmsh program; where it is missing (the GPU machine) they
// are skipped. `make test` installs gmsh, so they run on CI.
TEST_CASE("mesh_geo meshes a .geo once and reuses the cached mesh" * doctest::skip(fdem::io::find_on_path("gmsh").empty())) {
  TempDir dir("geo");
  const fs::path cache = dir.path / "cache" / "meshes";
  const std::string first = fdem::io::mesh_geo(fixture("sq.geo"), 0.25, cache.string());
  CHECK(fs::path(first).parent_path() == cache);
  CHECK(fs::path(first).filename().string().rfind("sq-", 0) == 0);
  CHECK(fs::path(first).filename().string().size() == std::string("sq-0123456789abcdef.msh").size());
  const Mesh m = fdem::io::read_gmsh(first);
  CHECK(m.triangles.size() > 28);  // finer than the fixture meshed at size 0.4
  CHECK(m.find_group("left_half", 2) >= 0);
  CHECK(std::distance(fs::directory_iterator(cache), fs::directory_iterator()) == 1);  // no temp file left

  const auto stamp = fs::last_write_time(first);
  const std::string again = fdem::io::mesh_geo(fixture("sq.geo"), 0.25, cache.string());
  CHECK(again == first);
  CHECK(fs::last_write_time(again) == stamp);

  const std::string coarse = fdem::io::mesh_geo(fixture("sq.geo"), 0.5, cache.string());
  CHECK(coarse != first);
  CHECK(fdem::io::read_gmsh(coarse).triangles.size() < m.triangles.size());
  const std::string default_size = fdem::io::mesh_geo(fixture("sq.geo"), 0, cache.string());
  CHECK(fdem::io::read_gmsh(default_size).triangles.size() == 28);
}

TEST_CASE("mesh_geo reports gmsh errors, a missing .geo and a missing gmsh" * doctest::skip(fdem::io::find_on_path("gmsh").empty())) {
  using doctest::Contains;
  TempDir dir("geo_errors");
  const std::string cache = (dir.path / "cache").string();
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(fixture("bad_syntax.geo"), 0, cache), Contains("bad_syntax.geo: gmsh failed"), InputError);
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(fixture("bad_syntax.geo"), 0, cache), Contains("syntax error"), InputError);
  CHECK(fs::is_empty(cache));  // the failed mesh is not cached
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(fixture("nope.geo"), 0, cache), Contains("nope.geo: .geo file not found"), InputError);

  const fs::path no_surface = dir.path / "no_surface.geo";
  write_bytes(no_surface, "Point(1) = {0, 0, 0, 0.1};\n");
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(no_surface.string(), 0, cache), Contains("no_surface.geo: gmsh ran but its mesh is unusable"), InputError);
  CHECK(fs::is_empty(cache));

  const char* old_path = std::getenv("PATH");
  const std::string saved = old_path ? old_path : "";
  ::setenv("PATH", dir.path.c_str(), 1);
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(fixture("sq.geo"), 0, cache), Contains("sq.geo: cannot mesh: the gmsh program is not on PATH; install it (Debian/Ubuntu package 'gmsh'"), InputError);
  ::setenv("PATH", saved.c_str(), 1);
}

TEST_CASE("mesh_geo estimates the triangle count before meshing and refuses above the limit" * doctest::skip(fdem::io::find_on_path("gmsh").empty())) {
  using doctest::Contains;
  TempDir dir("limit");
  const std::string cache = (dir.path / "cache").string();
  fdem::io::GeoMeshing options;
  // Progress every 50 ms here (5 s by default): gmsh's start alone takes longer.
  std::ostringstream progress;
  options.progress = &progress;
  options.progress_every = 0.05;
  const size_t actual = fdem::io::read_gmsh(fdem::io::mesh_geo(fixture("sq.geo"), 0.02, cache, options)).triangles.size();
  CHECK(actual > 4000);
  CHECK(progress.str().rfind("meshing " + fixture("sq.geo") + " with gmsh, ", 0) == 0);
  options.progress = nullptr;
  // Just below the count: refused, with the estimate, and nothing written to the cache
  // besides the mesh above.
  options.max_triangles = static_cast<long>(actual) / 2;
  std::string message;
  try {
    fdem::io::mesh_geo(fixture("sq.geo"), 0.019, cache, options);
  } catch (const InputError& e) {
    message = e.what();
  }
  INFO(message);
  CHECK(message.find("sq.geo at size 0.019: gmsh would make about ") != std::string::npos);
  CHECK(message.find("triangles (estimated from coarser meshes of the same .geo), above the limit of " +
                     std::to_string(options.max_triangles) + "; give a larger size (mesh.size), or raise the limit with --max-triangles N") != std::string::npos);
  CHECK(std::distance(fs::directory_iterator(cache), fs::directory_iterator()) == 1);
  // The estimate within 10% of the count gmsh makes (size 0.019: about 1.1 x the 0.02 mesh).
  const double estimate = std::stod(message.substr(message.find("about ") + 6));
  options.max_triangles = 5'000'000;
  const double made = static_cast<double>(fdem::io::read_gmsh(fdem::io::mesh_geo(fixture("sq.geo"), 0.019, cache, options)).triangles.size());
  CHECK(estimate == doctest::Approx(made).epsilon(0.10));
  // A request for ~10^12 triangles is refused in the time of a few coarse meshes.
  CHECK_THROWS_WITH_AS(fdem::io::mesh_geo(fixture("sq.geo"), 1e-6, cache, options), Contains("sq.geo at size 1e-06: gmsh would make about 2.5e+12 triangles"), InputError);
}

}  // TEST_SUITE
