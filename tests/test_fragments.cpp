// Fragments: the device labelling of the body's pieces (FragmentLabels) against a plain
// union-find, and end to end: a bar with two weak sections pulled apart, ids that stay
// put, the history columns and the fragments file.
#include <doctest/doctest.h>
#include <netcdf.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <numeric>
#include <random>
#include <sstream>

#include "approx.hpp"
#include "case_files.hpp"
#include "engine/device/device_arrays.hpp"
#include "engine/run/run.hpp"
#include "engine/stages/fragment_labels.hpp"
#include "fixture.hpp"
#include "fracture_tables.hpp"
#include "io/fragment_writer.hpp"

using namespace fdem;

namespace {

// A graph as the labelling sees it: triangles naming nodes, CE4 pairs with a broken flag.
struct Graph {
  size_t nodes = 0;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::array<int, 2>> ce4;
  std::vector<int> broken;  // per CE4
};

// Plain C++ reference: union-find over triangles and nodes (path halving, union by the
// smaller index), then per triangle the smallest triangle index of its set.
std::vector<int> reference_labels(const Graph& g) {
  const size_t n = g.triangles.size();
  std::vector<size_t> parent(n + g.nodes);
  std::iota(parent.begin(), parent.end(), size_t(0));
  std::function<size_t(size_t)> find = [&](size_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  auto unite = [&](size_t a, size_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) unite(t, n + size_t(g.triangles[t][k]));
  for (size_t e = 0; e < g.ce4.size(); ++e)
    if (!g.broken[e]) unite(size_t(g.ce4[e][0]), size_t(g.ce4[e][1]));
  std::vector<int> smallest(n + g.nodes, -1), out(n);
  for (size_t t = 0; t < n; ++t) {
    int& s = smallest[find(t)];
    if (s < 0) s = int(t);
    out[t] = s;
  }
  return out;
}

// The OpenCL path: the graph on the device, FragmentLabels over it.
std::vector<int> device_labels(const Graph& g, int* rounds = nullptr) {
  ClContext& cl = test::context();
  std::vector<cl_uint> nodes;
  for (const auto& t : g.triangles) nodes.insert(nodes.end(), {cl_uint(t[0]), cl_uint(t[1]), cl_uint(t[2])});
  std::vector<cl_int> status;
  for (int b : g.broken) status.insert(status.end(), {b, b ? 1 : 0});
  compute::buffer tri_nodes = cl.allocate(std::max<size_t>(1, nodes.size()) * sizeof(cl_uint), "test tri_nodes");
  compute::buffer status_buffer = cl.allocate(std::max<size_t>(1, status.size()) * sizeof(cl_int), "test status");
  upload(cl, tri_nodes, nodes);
  upload(cl, status_buffer, status);
  FragmentLabels labels(cl, g.triangles.size(), g.nodes, tri_nodes, g.ce4, &status_buffer);
  auto out = labels.labels();
  if (rounds) *rounds = labels.rounds();
  return out;
}

using Labeller = std::function<std::vector<int>(const Graph&)>;

// The same checks for either labeller: graphs whose pieces are known.
void check_known_graphs(const Labeller& label) {
  // Four triangles with their own nodes, a chain of CE4s 3-1, 1-0, 2-3 (order mixed).
  Graph chain{12, {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}, {9, 10, 11}}, {{3, 1}, {1, 0}, {2, 3}}, {0, 0, 0}};
  CHECK(label(chain) == std::vector<int>{0, 0, 0, 0});
  chain.broken = {0, 1, 0};  // 1-0 broken: {0}, {1, 2, 3}
  CHECK(label(chain) == std::vector<int>{0, 1, 1, 1});
  chain.broken = {1, 1, 1};
  CHECK(label(chain) == std::vector<int>{0, 1, 2, 3});
  // Shared nodes join without a CE4: 0 and 2 share node 2, 1 and 3 node 7.
  Graph shared{10, {{0, 1, 2}, {3, 4, 7}, {2, 5, 6}, {7, 8, 9}}, {}, {}};
  CHECK(label(shared) == std::vector<int>{0, 1, 0, 1});
  // A broken CE4 between triangles that also share a node: still one piece.
  Graph both{5, {{0, 1, 2}, {2, 3, 4}}, {{0, 1}}, {1}};
  CHECK(label(both) == std::vector<int>{0, 0});
  // A long chain numbered backwards (the worst order for single hooks).
  Graph line;
  const int n = 300;
  line.nodes = 3 * n;
  for (int t = 0; t < n; ++t) line.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  for (int t = n - 1; t > 0; --t) line.ce4.push_back({t, t - 1}), line.broken.push_back(t == 150);
  std::vector<int> expect(n);
  for (int t = 0; t < n; ++t) expect[t] = t < 150 ? 0 : 150;
  CHECK(label(line) == expect);
}

// A random graph: triangles on random nodes of a pool (sharing some), random CE4 pairs,
// about `broken_share` of them broken.
Graph random_graph(std::mt19937& rng, size_t triangles, size_t nodes, size_t ce4, double broken_share) {
  Graph g;
  g.nodes = nodes;
  std::uniform_int_distribution<int> node(0, int(nodes) - 1), tri(0, int(triangles) - 1);
  std::bernoulli_distribution broken(broken_share);
  for (size_t t = 0; t < triangles; ++t) g.triangles.push_back({node(rng), node(rng), node(rng)});
  for (size_t e = 0; e < ce4; ++e) {
    g.ce4.push_back({tri(rng), tri(rng)});
    g.broken.push_back(broken(rng) ? 1 : 0);
  }
  return g;
}

size_t count_pieces(const std::vector<int>& labels) {
  size_t n = 0;
  for (size_t t = 0; t < labels.size(); ++t) n += labels[t] == int(t);
  return n;
}

// A bar 0.3 m × 0.05 m of 12 × 2 squares, two triangles each, written as MSH 2.2:
// surfaces "left", "middle", "right" (a third of the length each), curves "left_end"
// and "right_end". Built in code, so the tests need no gmsh.
std::string bar_mesh(const test::TempDir& dir) {
  const int nx = 12, ny = 2;
  const double lx = 0.3, ly = 0.05;
  std::ostringstream nodes, elements;
  auto id = [&](int i, int j) { return j * (nx + 1) + i + 1; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) nodes << id(i, j) << " " << lx * i / nx << " " << ly * j / ny << " 0\n";
  int count = 0;
  for (int j = 0; j < ny; ++j) {
    elements << ++count << " 1 2 4 4 " << id(0, j) << " " << id(0, j + 1) << "\n";
    elements << ++count << " 1 2 5 5 " << id(nx, j) << " " << id(nx, j + 1) << "\n";
  }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int region = 1 + 3 * i / nx;  // 1 left, 2 middle, 3 right
      elements << ++count << " 2 2 " << region << " " << region << " " << id(i, j) << " " << id(i + 1, j) << " "
               << id(i + 1, j + 1) << "\n";
      elements << ++count << " 2 2 " << region << " " << region << " " << id(i, j) << " " << id(i + 1, j + 1) << " "
               << id(i, j + 1) << "\n";
    }
  std::ostringstream msh;
  msh << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n2 1 \"left\"\n2 2 \"middle\"\n2 3 \"right\"\n"
      << "1 4 \"left_end\"\n1 5 \"right_end\"\n$EndPhysicalNames\n$Nodes\n" << (nx + 1) * (ny + 1) << "\n"
      << nodes.str() << "$EndNodes\n$Elements\n" << count << "\n" << elements.str() << "$EndElements\n";
  return dir.write("bar3.msh", msh.str());
}

// The three-part bar: each part its own fracturable material (strong), the parts bonded
// by weak [[interface]]s when `weak_interfaces` (else not bonded at all: three pieces
// from the start), the ends pulled apart at ±`speed`.
std::string bar_case(const test::TempDir& dir, bool weak_interfaces, double speed, double end,
                     const std::string& frames = "frames = 5\n", const std::string& out = "") {
  const std::string strong = test::kStrongFracture;
  std::ostringstream c;
  c << "title = \"three-part bar\"\n[mesh]\nfile = \"" << bar_mesh(dir) << "\"\nthickness = 0.1\n"
    << "[time]\ndt = \"auto\"\nend = " << end << "\n[output]\ndir = \"" << (out.empty() ? dir.str() : out)
    << "\"\nhistory_every = 2e-5\n" << frames;
  for (const char* name : {"left", "middle", "right"})
    c << "[[material]]\nname = \"" << name << "\"\nregions = [\"" << name
      << "\"]\ndensity = 2000.0\nyoung = 10e9\npoisson = 0.2\nviscosity = \"critical\"\n" << strong;
  if (weak_interfaces)
    for (const char* other : {"left", "right"})
      c << "[[interface]]\nmaterials = [\"middle\", \"" << other << "\"]\ntensile_strength = 0.5e6\ncohesion = 1e6\n"
        << "friction_angle = 30.0\ngf1 = 1.0\ngf2 = 10.0\n"
        << "penalty = { opening = 100e9, sliding = 100e9, overlap = 100e9 }\n";
  c << "[[boundary]]\nregion = \"left_end\"\nvelocity = [" << -speed << ", 0.0]\nrise = 1e-4\n"
    << "[[boundary]]\nregion = \"right_end\"\nvelocity = [" << speed << ", 0.0]\nrise = 1e-4\n";
  return dir.write("bar3.toml", c.str());
}

// FRAGMENT values of Exodus frame `frame` on TRI3 block `block` (1-based).
std::vector<double> fragment_values(const std::string& exo, int frame, int block) {
  const int k = test::exodus_variable_index(exo, "name_elem_var", "FRAGMENT");
  REQUIRE(k > 0);
  const auto all = test::read_variable(exo, "vals_elem_var" + std::to_string(k) + "eb" + std::to_string(block));
  const size_t per = all.size() / 5;  // frames = 5
  return std::vector<double>(all.begin() + long(frame * per), all.begin() + long((frame + 1) * per));
}

const double kPartArea = 0.1 * 0.05;

}  // namespace

TEST_SUITE("fragments") {

TEST_CASE("labelling: known graphs give their pieces, on the reference and on the device") {
  SUBCASE("reference union-find") { check_known_graphs(reference_labels); }
  SUBCASE("FragmentLabels (OpenCL)") { check_known_graphs([](const Graph& g) { return device_labels(g); }); }
}

TEST_CASE("labelling: the device equals the union-find reference on random graphs") {
  std::mt19937 rng(14);
  int most_rounds = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const size_t triangles = 1 + rng() % 3000;
    // Few nodes: triangles share nodes a lot; many: mostly joined by CE4s only.
    const size_t nodes = trial % 2 ? 3 * triangles : 1 + triangles / 2;
    const size_t ce4 = rng() % (2 * triangles);
    const Graph g = random_graph(rng, triangles, nodes, ce4, (trial % 5) / 4.0);
    int rounds = 0;
    const auto device = device_labels(g, &rounds);
    const auto reference = reference_labels(g);
    INFO("trial " << trial << ": " << triangles << " triangles, " << nodes << " nodes, " << ce4 << " CE4s, "
                  << count_pieces(reference) << " pieces");
    CHECK(device == reference);
    most_rounds = std::max(most_rounds, rounds);
  }
  MESSAGE("most labelling rounds on the random graphs: " << most_rounds);
}

TEST_CASE("a bar with two weak sections pulled apart gives exactly three fragments of the right areas") {
  test::TempDir dir;
  test::run(bar_case(dir, true, 0.5, 1.2e-3));
  const std::string hist = dir.str() + "/bar3_history.nc", exo = dir.str() + "/bar3.exo";
  const auto fragments = test::read_variable(hist, "fragments");
  const auto largest = test::read_variable(hist, "largest_fragment");
  REQUIRE(!fragments.empty());
  CHECK(fragments.front() == 1);
  CHECK(largest.front() == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(fragments.back() == 3);
  CHECK(largest.back() == test::rel(1.0 / 3.0, 1e-3));
  // Only the weak CE4s broke: 2 rows of 2 squares' edges across the bar at each interface.
  CHECK(test::read_variable(hist, "broken_ce4").back() == 4);

  const io::FragmentFrames frames = io::read_fragment_file(dir.str() + "/bar3_fragments.nc");
  REQUIRE(frames.time.size() == 5);
  CHECK(frames.fragments.front().size() == 1);
  CHECK(frames.fragments.front()[0].id == 0);
  CHECK(frames.fragments.front()[0].area == test::rel(3 * kPartArea, 1e-9));
  const auto& last = frames.fragments.back();
  REQUIRE(last.size() == 3);
  // Triangles are stored by material (left 0-15, middle 16-31, right 32-47): the ids
  // are the first triangle of each part, the left part keeping the body's id 0.
  CHECK(last[0].id == 0);
  CHECK(last[1].id == 16);
  CHECK(last[2].id == 32);
  const double sign[3] = {-1, 0, 1};
  for (int k = 0; k < 3; ++k) {
    CHECK(last[k].triangles == 16);
    CHECK(last[k].area == test::rel(kPartArea, 2e-3));  // current areas: small elastic strains
    CHECK(last[k].mass == doctest::Approx(2000.0 * kPartArea * 0.1).epsilon(1e-12));
    CHECK(last[k].diameter == test::rel(std::sqrt(4 * last[k].area / M_PI), 1e-12));
    CHECK(last[k].y == test::rel(0.025, 1e-3));
    // Centres: the outer parts moved out, the middle stayed.
    const double x0 = 0.05 + 0.1 * k;
    CHECK((last[k].x - x0) * sign[k] >= 0);
    if (k == 1) CHECK(std::fabs(last[k].x - x0) < 2e-4);
  }
  // FRAGMENT in the Exodus file: the same ids, 1-based, on each part's block.
  for (int b = 1; b <= 3; ++b)
    for (double v : fragment_values(exo, 4, b)) CHECK(v == 16 * (b - 1) + 1);
  for (int b = 1; b <= 3; ++b)
    for (double v : fragment_values(exo, 0, b)) CHECK(v == 1);
}

TEST_CASE("fragment ids stay the same between frames when nothing breaks; an intact body is one fragment") {
  test::TempDir dir;
  SUBCASE("bonded: one piece all along") {
    test::run(bar_case(dir, true, 0.002, 1e-3));
    const auto fragments = test::read_variable(dir.str() + "/bar3_history.nc", "fragments");
    REQUIRE(fragments.size() > 10);
    for (double f : fragments) CHECK(f == 1);
    for (double l : test::read_variable(dir.str() + "/bar3_history.nc", "largest_fragment"))
      CHECK(l == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(test::read_variable(dir.str() + "/bar3_history.nc", "broken_ce4").back() == 0);
    for (int frame = 0; frame < 5; ++frame)
      for (int b = 1; b <= 3; ++b)
        for (double v : fragment_values(dir.str() + "/bar3.exo", frame, b)) CHECK(v == 1);
  }
  SUBCASE("not bonded: three pieces from the start, the same ids in every frame") {
    test::run(bar_case(dir, false, 0.002, 1e-3));
    const auto fragments = test::read_variable(dir.str() + "/bar3_history.nc", "fragments");
    for (double f : fragments) CHECK(f == 3);
    const io::FragmentFrames frames = io::read_fragment_file(dir.str() + "/bar3_fragments.nc");
    REQUIRE(frames.time.size() == 5);
    for (const auto& frame : frames.fragments) {
      REQUIRE(frame.size() == 3);
      CHECK(frame[0].id == 0);
      CHECK(frame[1].id == 16);
      CHECK(frame[2].id == 32);
    }
    const auto first = fragment_values(dir.str() + "/bar3.exo", 0, 2);
    for (int frame = 1; frame < 5; ++frame) CHECK(fragment_values(dir.str() + "/bar3.exo", frame, 2) == first);
  }
}

TEST_CASE("fragments file: a run to T and a run to T/2 restarted to T write the same bytes") {
  test::TempDir dir;
  const std::string one = dir.str() + "/one", two = dir.str() + "/two";
  const std::string every = "every = 1e-4\n";
  // Pulled slowly: the weak sections break after the checkpoint at T/2.
  test::run(bar_case(dir, true, 0.012, 1.2e-3, every, one));
  test::run(bar_case(dir, true, 0.012, 0.6e-3, every, two));
  const auto half = io::read_fragment_file(two + "/bar3_fragments.nc");
  test::run(bar_case(dir, true, 0.012, 1.2e-3, every, two), {}, test::restart_from(two + "/bar3.ckpt"));
  const auto a = io::read_fragment_file(one + "/bar3_fragments.nc");
  const auto b = io::read_fragment_file(two + "/bar3_fragments.nc");
  REQUIRE(a.time.size() == 13);
  CHECK(half.time.size() == 7);
  CHECK(b.time == a.time);
  CHECK(a.fragments.back().size() == 3);  // it broke after the checkpoint
  CHECK(half.fragments.back().size() == 1);
  std::ifstream fa(one + "/bar3_fragments.nc", std::ios::binary), fb(two + "/bar3_fragments.nc", std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
  CHECK(!sa.empty());
  CHECK(sa == sb);
}

TEST_CASE("fragments file: records read back; a writer killed without close leaves every synced frame") {
  test::TempDir dir;
  const std::string path = dir.str() + "/k_fragments.nc";
  const std::vector<io::FragmentRecord> one{{0, 10, 2.5, 7.0, 0.1, 0.2, std::sqrt(10 / M_PI)}};
  const std::vector<io::FragmentRecord> two{{0, 4, 1.0, 3.0, -0.1, 0.2, 1.1}, {4, 6, 1.5, 4.0, 0.3, 0.25, 1.4}};
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    try {
      io::FragmentWriter w(path, "killed");
      w.write_frame(0.0, one);
      w.write_frame(1e-3, two);
    } catch (...) {
      _exit(3);
    }
    kill(getpid(), SIGKILL);
    _exit(4);
  }
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFSIGNALED(status));
  const io::FragmentFrames frames = io::read_fragment_file(path);
  REQUIRE(frames.time == std::vector<double>{0.0, 1e-3});
  REQUIRE(frames.fragments[0].size() == 1);
  REQUIRE(frames.fragments[1].size() == 2);
  CHECK(frames.fragments[0][0].area == 2.5);
  CHECK(frames.fragments[0][0].diameter == std::sqrt(10 / M_PI));
  CHECK(frames.fragments[1][1].id == 4);
  CHECK(frames.fragments[1][1].triangles == 6);
  CHECK(frames.fragments[1][1].mass == 4.0);
  CHECK(frames.fragments[1][1].x == 0.3);
  CHECK(frames.fragments[1][1].y == 0.25);
  CHECK(test::read_variable(path, "fragment_id") == std::vector<double>{1, 1, 5});  // 1-based in the file
  CHECK(test::read_variable(path, "fragment_frame") == std::vector<double>{0, 1, 1});
  CHECK_THROWS_AS(io::FragmentWriter(path, "t").write_frame(0.0, {}), std::invalid_argument);
}

}  // TEST_SUITE
