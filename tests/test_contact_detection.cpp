// Contact detection (engine/stages/contact_detection.*) against an O(n²) host reference
// written from the rule itself: boxes grown by skin/2 overlap (closed intervals), i < j,
// no shared node, both triangles active, and no edge line of either has the other's three
// vertices more than the skin outside it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "approx.hpp"
#include "engine/stages/contact_detection.hpp"
#include "fixture.hpp"

using namespace fdem;

namespace {

std::vector<io::MaterialConfig> one_material() {
  return {test::material_config("rock", io::Elasticity::NeoHookean, io::Plane::Strain)};
}

struct Box {
  real lo_x, lo_y, hi_x, hi_y;
};

// The kernel keeps its boxes in float, rounded outward (the low corner down, the high one
// up: convert_float_rtn / _rtp).
real float_down(real v) {
  float f = static_cast<float>(v);
  if (static_cast<real>(f) > v) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return static_cast<real>(f);
}
real float_up(real v) {
  float f = static_cast<float>(v);
  if (static_cast<real>(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return static_cast<real>(f);
}

// The same arithmetic as the kernel (min/max are exact; one rounding in ± half skin, then
// the outward rounding to float).
std::vector<Box> host_boxes(const Model& m, const std::vector<real2>& pos, double skin) {
  const real h = static_cast<real>(0.5 * skin);
  std::vector<Box> boxes;
  for (const auto& t : m.triangles) {
    const real2 a = pos[t[0]], b = pos[t[1]], c = pos[t[2]];
    boxes.push_back({float_down(std::min({a.x, b.x, c.x}) - h), float_down(std::min({a.y, b.y, c.y}) - h),
                     float_up(std::max({a.x, b.x, c.x}) + h), float_up(std::max({a.y, b.y, c.y}) + h)});
  }
  return boxes;
}

// The kernel's apart_beyond in the same arithmetic: outside distance × |edge| as a cross
// product signed by the edge owner's orientation, compared squared with (reach + 16 ε ×
// the largest coordinate) × |edge|.
bool apart_beyond(const std::array<real2, 3>& a, const std::array<real2, 3>& b, real reach) {
  real extent = 0;
  for (int m = 0; m < 3; ++m)
    extent = std::max({extent, std::fabs(a[m].x), std::fabs(a[m].y), std::fabs(b[m].x), std::fabs(b[m].y)});
  const real allowed = reach + real(16) * std::numeric_limits<real>::epsilon() * extent;
  for (int dir = 0; dir < 2; ++dir) {
    const auto& p = dir ? b : a;
    const auto& q = dir ? a : b;
    const real twice_area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
    if (twice_area == 0) continue;
    const real outward = twice_area > 0 ? real(-1) : real(1);
    for (int m = 0; m < 3; ++m) {
      const real2 from = p[m], to = p[(m + 1) % 3];
      const real ex = to.x - from.x, ey = to.y - from.y;
      real gap = std::numeric_limits<real>::infinity();
      for (int k = 0; k < 3; ++k) gap = std::min(gap, outward * (ex * (q[k].y - from.y) - ey * (q[k].x - from.x)));
      if (gap > 0 && gap * gap > allowed * allowed * (ex * ex + ey * ey)) return true;
    }
  }
  return false;
}

std::array<real2, 3> corners(const Model& m, const std::vector<real2>& pos, size_t t) {
  return {pos[m.triangles[t][0]], pos[m.triangles[t][1]], pos[m.triangles[t][2]]};
}

std::vector<uint64_t> brute_force(const Model& m, const std::vector<real2>& pos, double skin,
                                  const std::vector<uint32_t>& active = {}) {
  const auto boxes = host_boxes(m, pos, skin);
  std::vector<uint64_t> keys;
  const size_t n = m.num_triangles();
  for (size_t i = 0; i < n; ++i) {
    if (!active.empty() && !active[i]) continue;
    const Box& a = boxes[i];
    for (size_t j = i + 1; j < n; ++j) {
      if (!active.empty() && !active[j]) continue;
      const Box& b = boxes[j];
      if (!(a.lo_x <= b.hi_x && b.lo_x <= a.hi_x && a.lo_y <= b.hi_y && b.lo_y <= a.hi_y)) continue;
      bool shared = false;
      for (int p : m.triangles[i])
        for (int q : m.triangles[j]) shared = shared || p == q;
      if (!shared && !apart_beyond(corners(m, pos, i), corners(m, pos, j), static_cast<real>(skin)))
        keys.push_back(uint64_t(i) << 32 | uint64_t(j));
    }
  }
  return keys;  // already ascending: i outer, j inner
}

std::vector<uint64_t> detect(ClContext& cl, ContactDetection& stage) {
  const size_t count = stage.run();
  CHECK(count == stage.last_count());
  CHECK(count <= stage.capacity());
  const auto keys = download<cl_ulong>(cl, stage.couple_keys(), count);
  return std::vector<uint64_t>(keys.begin(), keys.end());
}

std::vector<real2> model_positions(const Model& m) {
  std::vector<real2> pos(m.num_nodes());
  for (size_t i = 0; i < pos.size(); ++i) pos[i] = {real(m.x[i]), real(m.y[i])};
  return pos;
}

void add_triangle(std::vector<double>& x, std::vector<double>& y, std::vector<std::array<int, 3>>& tris,
                  double cx, double cy, double size, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int base = static_cast<int>(x.size());
  const double turn = M_PI * u(rng);
  for (int k = 0; k < 3; ++k) {
    const double angle = turn + 2.0 * M_PI * k / 3.0 + 0.4 * u(rng);
    x.push_back(cx + size * std::cos(angle) * (1 + 0.3 * u(rng)));
    y.push_back(cy + size * std::sin(angle) * (1 + 0.3 * u(rng)));
  }
  tris.push_back({base, base + 1, base + 2});
}

// A heavily overlapping soup in [-1, 1]²: sizes from 1 mm to 0.1 m (log-uniform), a few
// large 0.4 m triangles, and a dense cluster of tiny ones within 2 cm (hundreds per cell).
Model varied_soup(size_t count, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x, y;
  std::vector<std::array<int, 3>> tris;
  for (size_t t = 0; t < count; ++t) {
    if (t % 5 == 0) {
      add_triangle(x, y, tris, 0.3 + 0.01 * u(rng), -0.2 + 0.01 * u(rng), 0.002 + 0.004 * (u(rng) + 1), rng);
    } else if (t % 97 == 0) {
      add_triangle(x, y, tris, u(rng), u(rng), 0.2, rng);
    } else {
      add_triangle(x, y, tris, u(rng), u(rng), 0.001 * std::pow(100.0, 0.5 * (u(rng) + 1)), rng);
    }
  }
  return test::make_model(x, y, tris, one_material());
}

// An n×n-square mesh of [0, n·h]² with jittered interior nodes and random diagonals:
// neighbouring triangles share nodes.
Model jittered_mesh(int n, double h, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x, y;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool interior = i > 0 && j > 0 && i < n && j < n;
      x.push_back(h * i + (interior ? 0.3 * h * u(rng) : 0.0));
      y.push_back(h * j + (interior ? 0.3 * h * u(rng) : 0.0));
    }
  std::vector<std::array<int, 3>> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;  // ccw square
      if (u(rng) > 0) {
        tris.push_back({a, b, c});
        tris.push_back({a, c, d});
      } else {
        tris.push_back({a, b, d});
        tris.push_back({b, c, d});
      }
    }
  return test::make_model(x, y, tris, one_material());
}

// The grid must cover every box, hold the largest box in one cell, and respect the cap.
void check_grid(ContactDetection& stage, const Model& m, const std::vector<real2>& pos, double skin) {
  const auto g = stage.grid();
  CHECK(g.nx >= 1);
  CHECK(g.ny >= 1);
  CHECK(size_t(g.nx) * g.ny <= stage.max_cells());
  double largest = 0, smallest = 1e300;
  bool covered = true;
  const auto boxes = host_boxes(m, pos, skin);
  for (const auto& b : boxes) {
    const double side = std::max(double(b.hi_x - b.lo_x), double(b.hi_y - b.lo_y));
    largest = std::max(largest, side);
    smallest = std::min(smallest, side);
    covered = covered && b.lo_x >= g.x0 && b.lo_y >= g.y0 && b.hi_x <= g.x0 + g.nx * g.cell_size &&
              b.hi_y <= g.y0 + g.ny * g.cell_size;
  }
  CHECK(covered);
  // Boxes up to the geometric mean of the smallest and largest side (or what the capped
  // cell holds) go into one cell.
  CHECK(g.small_side >= std::sqrt(smallest * largest) * (1 - 1e-9));
  CHECK(g.small_side <= std::max(largest, g.cell_size / 1.015625) * (1 + 1e-9));  // or the capped cell's
  CHECK(g.cell_size >= g.small_side);
}

}  // namespace

TEST_SUITE("contact") {

TEST_CASE("couples of a random soup equal the brute force, also after bodies move far away") {
  auto& cl = test::context();
  for (double skin : {0.0, 0.02}) {
    CAPTURE(skin);
    std::mt19937 rng(skin == 0.0 ? 11 : 12);
    const Model m = varied_soup(3000, rng);
    DeviceArrays arrays(cl, m);
    ContactDetection stage(cl, arrays, skin);
    auto pos = model_positions(m);

    const auto expected = brute_force(m, pos, skin);
    CHECK(expected.size() > 20000);  // heavy overlap: the test means something
    CHECK(detect(cl, stage) == expected);
    // The GPU's way (nine work-items per triangle, writes in any order, then sorted) and
    // the CPU's (one) give the same list, on any device.
    for (size_t parts : {9, 1, 4}) {
      stage.set_parts(parts);
      CAPTURE(parts);
      CHECK(detect(cl, stage) == expected);
    }
    check_grid(stage, m, pos, skin);
    const double first_cell = stage.grid().cell_size;

    // Every triangle drifts a little; 40 of them go 1000 domain sizes away (to both sides),
    // two of those land on top of each other there.
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (auto& p : pos) p = {p.x + real(0.01 * u(rng)), p.y + real(0.01 * u(rng))};
    for (size_t t = 7; t < m.num_triangles(); t += 75) {
      const double dx = (t % 2 ? 2000.0 : -2000.0), dy = (t % 3 ? 1000.0 : -500.0);
      for (int n : m.triangles[t]) pos[n] = {pos[n].x + real(dx), pos[n].y + real(dy)};
    }
    upload(cl, arrays.position, pos);
    const auto moved = brute_force(m, pos, skin);
    CHECK(detect(cl, stage) == moved);
    check_grid(stage, m, pos, skin);
    CHECK(stage.grid().cell_size > first_cell);  // the cap made the cells grow

    // Back to a compact cloud: the grid shrinks again.
    pos = model_positions(m);
    upload(cl, arrays.position, pos);
    CHECK(detect(cl, stage) == expected);
    CHECK(stage.grid().cell_size == test::rel(first_cell, 1e-12));
  }
}

TEST_CASE("the gap rule drops couples the boxes alone would list, and none that can touch before the skin is used up") {
  // Triangle 0: (0, 0), (1, 0), (0, 1). Triangle 1: a right angle at (0.5 + d, 0.5 + d),
  // pointing at 0's hypotenuse x + y = 1 from 0.3 beyond it (d = 0.3/√2), legs of 1 along
  // +x and +y. That vertex lies inside 0's box: the boxes overlap at any skin. Their
  // distance is 0.3: with a skin of 0.2 not a couple, with 0.3 (and a hair) a couple.
  auto& cl = test::context();
  {
    const double d = 0.3 / std::sqrt(2.0);
    const std::vector<double> x = {0, 1, 0, 0.5 + d, 1.5 + d, 0.5 + d};
    const std::vector<double> y = {0, 0, 1, 0.5 + d, 0.5 + d, 1.5 + d};
    const Model m = test::make_model(x, y, {{0, 1, 2}, {3, 4, 5}}, one_material());
    DeviceArrays arrays(cl, m);
    ContactDetection thin(cl, arrays, 0.2), thick(cl, arrays, 0.3 + 1e-12);
    CHECK(detect(cl, thin).empty());
    CHECK(detect(cl, thick) == std::vector<uint64_t>{1});
    CHECK(brute_force(m, model_positions(m), 0.2).empty());
    CHECK(brute_force(m, model_positions(m), 0.3 + 1e-12) == std::vector<uint64_t>{1});
  }
  // A heavy soup: after every node moved by less than half the skin, every couple that
  // overlaps (boxes touching and no edge line between them: the brute force at skin 0)
  // was in the list; and the list is shorter than the boxes' alone.
  const double skin = 0.01;
  std::mt19937 rng(41);
  const Model m = varied_soup(3000, rng);
  DeviceArrays arrays(cl, m);
  ContactDetection stage(cl, arrays, skin);
  auto pos = model_positions(m);
  const auto listed = detect(cl, stage);
  CHECK(listed == brute_force(m, pos, skin));
  size_t boxes_only = 0;
  {
    const auto boxes = host_boxes(m, pos, skin);
    for (size_t i = 0; i < boxes.size(); ++i)
      for (size_t j = i + 1; j < boxes.size(); ++j)
        boxes_only += boxes[i].lo_x <= boxes[j].hi_x && boxes[j].lo_x <= boxes[i].hi_x &&
                      boxes[i].lo_y <= boxes[j].hi_y && boxes[j].lo_y <= boxes[i].hi_y;
  }
  MESSAGE(listed.size() << " couples listed, " << boxes_only << " by the boxes alone");
  CHECK(listed.size() < boxes_only);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<real2> moved = pos;
    for (auto& p : moved) {
      const double r = 0.4999 * skin * std::sqrt(u(rng)), a = 2 * M_PI * u(rng);
      p = {p.x + real(r * std::cos(a)), p.y + real(r * std::sin(a))};
    }
    const auto touching = brute_force(m, moved, 0.0);
    CHECK(touching.size() > 1000);
    CHECK(std::includes(listed.begin(), listed.end(), touching.begin(), touching.end()));
  }
}

TEST_CASE("triangles of a deformed mesh that share a node are never couples") {
  auto& cl = test::context();
  const double h = 0.1;
  for (double skin : {0.0, 0.3 * h}) {
    CAPTURE(skin);
    std::mt19937 rng(21);
    const Model m = jittered_mesh(40, h, rng);
    DeviceArrays arrays(cl, m);
    ContactDetection stage(cl, arrays, skin);
    auto pos = model_positions(m);

    auto check = [&] {
      // Every pair that shares a node is 0 apart and its boxes overlap: only the shared
      // node keeps it out (thousands of them; the couples left are the few non-neighbours
      // within the skin).
      const auto expected = brute_force(m, pos, skin);
      MESSAGE("skin " << skin << ": " << expected.size() << " couples");
      if (skin > 0) CHECK(expected.size() > 100);
      const auto got = detect(cl, stage);
      CHECK(got == expected);
      size_t sharing = 0;
      for (uint64_t key : got) {
        const auto& a = m.triangles[key >> 32];
        const auto& b = m.triangles[key & 0xffffffffu];
        for (int p : a)
          for (int q : b) sharing += p == q;
      }
      CHECK(sharing == 0);
    };
    check();

    // Deform: a smooth swirl plus node noise (the mesh stays connected through shared nodes).
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (auto& p : pos) {
      const double sx = 0.3 * std::sin(3.0 * p.y), sy = 0.2 * std::sin(2.0 * p.x);
      p = {p.x + real(sx + 0.02 * h * u(rng)), p.y + real(sy + 0.02 * h * u(rng))};
    }
    upload(cl, arrays.position, pos);
    check();
    check_grid(stage, m, pos, skin);
  }
}

TEST_CASE("an output buffer of one couple grows to the count before the keys are written: the same list as a large one") {
  auto& cl = test::context();
  std::mt19937 rng(31);
  const Model m = varied_soup(2000, rng);
  DeviceArrays arrays(cl, m);
  ContactDetection large(cl, arrays, 0.01, 50 * m.num_triangles());
  ContactDetection tiny(cl, arrays, 0.01, 1);
  CHECK(tiny.capacity() == 1);
  const auto expected = detect(cl, large);
  CHECK(large.capacity() == 50 * m.num_triangles());  // did not need to grow
  const auto got = detect(cl, tiny);
  CHECK(got == expected);
  CHECK(tiny.capacity() >= expected.size());
  CHECK(tiny.capacity() <= expected.size() * 3 / 2 + 1);
  CHECK(detect(cl, tiny) == expected);  // second run fits without growing
  CHECK(got == brute_force(m, model_positions(m), 0.01));
}

TEST_CASE("the prefix sums' block edges: soups of 1,023 to 4,097 triangles give the brute force's couples") {
  // The scans run in blocks of 4 x work-group entries (1,024 with groups of 256): the
  // triangle counts straddle one and four blocks, and the cell count (4n + 1024, + 1) many.
  auto& cl = test::context();
  for (int n : {1, 2, 1023, 1024, 1025, 4095, 4097}) {
    CAPTURE(n);
    std::mt19937 rng(71 + n);
    const Model m = varied_soup(n, rng);
    DeviceArrays arrays(cl, m);
    ContactDetection stage(cl, arrays, 0.005);
    const auto a = detect(cl, stage);
    CHECK(a == brute_force(m, model_positions(m), 0.005));
    if (n > 1000) CHECK(a.size() > 100);
  }
}

TEST_CASE("an extension by joined triangles lists what a detection with them would have listed, once each") {
  // A soup where a third of the triangles take part; then others join in three rounds
  // (mask value = a join stamp above the list's), the bodies having moved since the
  // detection. Each extension must hold exactly the couples of a detection at the
  // detection's positions with the new mask that the list did not have: old list +
  // extensions = that detection, as sets; old list unchanged; each extension's own
  // segments sorted per joining triangle.
  auto& cl = test::context();
  for (size_t parts : {1, 9}) {
  CAPTURE(parts);
  std::mt19937 rng(83);
  const Model m = varied_soup(3000, rng);
  const auto at_detection = model_positions(m);
  DeviceArrays arrays(cl, m);
  const double skin = 0.004;
  ContactDetection stage(cl, arrays, skin, 1000);  // a list that must grow, keeping its couples
  stage.set_parts(parts);
  std::vector<uint32_t> mask(m.num_triangles(), 0);
  for (size_t t = 0; t < mask.size(); ++t) mask[t] = t % 3 == 0 ? 1u : 0u;
  stage.set_active(mask);
  const size_t first = stage.run();
  stage.set_covered_stamp(2);
  auto list = download<cl_ulong>(cl, stage.couple_keys(), first);
  const auto expected = brute_force(m, at_detection, skin, mask);
  CHECK(list == std::vector<cl_ulong>(expected.begin(), expected.end()));
  // The nodes move (the extension must use the detection's boxes and gaps, not these: it
  // is given the positions of the detection, as the solver would give the skin's copy).
  std::vector<real2> moved = at_detection;
  for (auto& p : moved) p.x += real(0.003);
  upload(cl, arrays.position, moved);
  compute::buffer positions_at_run(cl.context(), at_detection.size() * sizeof(real2));
  upload(cl, positions_at_run, at_detection);
  std::uniform_int_distribution<int> pick(0, 4);
  size_t listed = first;
  for (cl_uint round = 3; round <= 5; ++round) {
    CAPTURE(round);
    for (size_t t = 0; t < mask.size(); ++t)
      if (mask[t] == 0 && pick(rng) == 0) mask[t] = round;
    stage.set_active(mask);
    const size_t now = stage.extend_joined(listed, 1u << 30, round, positions_at_run);
    REQUIRE(now >= listed);
    CHECK(stage.covered_stamp() == round);
    const auto keys = download<cl_ulong>(cl, stage.couple_keys(), now);
    CHECK(std::equal(list.begin(), list.end(), keys.begin()));  // the list so far, unchanged
    std::vector<uint64_t> all(keys.begin(), keys.end());
    std::sort(all.begin(), all.end());
    CHECK(std::adjacent_find(all.begin(), all.end()) == all.end());  // no couple twice
    std::vector<uint32_t> taking_part(mask.size());
    for (size_t t = 0; t < mask.size(); ++t) taking_part[t] = mask[t] != 0;
    CHECK(all == brute_force(m, at_detection, skin, taking_part));
    MESSAGE("round " << round << ": " << now - listed << " couples appended to " << listed);
    CHECK(now > listed);
    list.assign(keys.begin(), keys.end());
    listed = now;
  }
  // Nothing joined since: nothing appended.
  CHECK(stage.extend_joined(listed, 1u << 30, 6, positions_at_run) == listed);
  // No room: 0, the caller detects again.
  for (size_t t = 0; t < mask.size(); ++t)
    if (mask[t] == 0) mask[t] = 7;
  stage.set_active(mask);
  CHECK(stage.extend_joined(listed, listed, 7, positions_at_run) == 0);
  }
}

TEST_CASE("a graded soup (small triangles by the thousand, a few a hundred times larger): the brute force's couples") {
  // The cell follows the geometric mean of the smallest and largest box: the large triangles are
  // entered in every cell they cover and found there once.
  auto& cl = test::context();
  std::mt19937 rng(97);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x, y;
  std::vector<std::array<int, 3>> tris;
  for (int t = 0; t < 3000; ++t) {
    const bool big = t % 150 == 0;
    add_triangle(x, y, tris, 0.5 * u(rng), 0.5 * u(rng), big ? 0.3 : 0.003, rng);
  }
  const Model m = test::make_model(x, y, tris, one_material());
  DeviceArrays arrays(cl, m);
  ContactDetection stage(cl, arrays, 0.001);
  const auto a = detect(cl, stage);
  CHECK(a == brute_force(m, model_positions(m), 0.001));
  stage.set_parts(9);  // a large triangle's cells shared by nine work-items
  CHECK(detect(cl, stage) == a);
  const auto g = stage.grid();
  CHECK(g.small_side < 0.1);  // not the large triangles' size (about 0.55 m)
  check_grid(stage, m, model_positions(m), 0.001);
}

TEST_CASE("a pile of triangles in one cell: every couple listed once, each triangle's segment sorted") {
  // 60 triangles with no node in common over nearly the same place: 1,770 couples, 59 for
  // the first triangle, written into its segment in any order and sorted there.
  auto& cl = test::context();
  std::mt19937 rng(5);
  std::vector<double> x, y;
  std::vector<std::array<int, 3>> tris;
  for (int t = 0; t < 60; ++t) add_triangle(x, y, tris, 0.001 * (t % 7), 0.001 * (t % 5), 0.05, rng);
  const Model m = test::make_model(x, y, tris, one_material());
  DeviceArrays arrays(cl, m);
  ContactDetection stage(cl, arrays, 0.0);
  const auto a = detect(cl, stage);
  CHECK(a.size() == 60 * 59 / 2);
  CHECK(a == brute_force(m, model_positions(m), 0.0));
  stage.set_parts(9);
  CHECK(detect(cl, stage) == a);
}

TEST_CASE("two runs, and two stages, give identical couple lists") {
  auto& cl = test::context();
  std::mt19937 rng(51);
  const Model m = varied_soup(2000, rng);
  DeviceArrays arrays(cl, m);
  ContactDetection one(cl, arrays, 0.01), two(cl, arrays, 0.01);
  const auto first = detect(cl, one);
  const auto second = detect(cl, one);
  const auto third = detect(cl, two);
  CHECK(!first.empty());
  CHECK(first == second);
  CHECK(first == third);
  CHECK(std::adjacent_find(first.begin(), first.end(), [](uint64_t p, uint64_t q) { return p >= q; }) ==
        first.end());  // strictly ascending: sorted, unique
}

TEST_CASE("the grid covers every triangle's box after the bodies moved") {
  auto& cl = test::context();
  std::mt19937 rng(61);
  const Model m = varied_soup(1000, rng);
  DeviceArrays arrays(cl, m);
  const double skin = 0.05;
  ContactDetection stage(cl, arrays, skin);
  auto pos = model_positions(m);
  stage.run();
  check_grid(stage, m, pos, skin);
  const auto before = stage.grid();

  // The whole cloud moves and stretches: the grid follows (origin moves, box covered).
  for (auto& p : pos) p = {real(3.0 * p.x - 50.0), real(0.5 * p.y + 20.0)};
  upload(cl, arrays.position, pos);
  stage.run();
  check_grid(stage, m, pos, skin);
  const auto after = stage.grid();
  CHECK(after.x0 < before.x0 - 40.0);
  CHECK(after.y0 > before.y0 + 15.0);
  CHECK(detect(cl, stage) == brute_force(m, pos, skin));
}

TEST_CASE("only active triangles take part") {
  auto& cl = test::context();
  std::mt19937 rng(71);
  const Model m = varied_soup(1500, rng);
  DeviceArrays arrays(cl, m);
  ContactDetection stage(cl, arrays, 0.01);
  std::vector<uint32_t> active(m.num_triangles());
  for (auto& a : active) a = rng() % 3 != 0 ? 1u : 0u;
  stage.set_active(active);
  const auto pos = model_positions(m);
  const auto got = detect(cl, stage);
  CHECK(got == brute_force(m, pos, 0.01, active));
  CHECK(got.size() < brute_force(m, pos, 0.01).size());
  stage.set_active(std::vector<uint32_t>(m.num_triangles(), 1u));
  CHECK(detect(cl, stage) == brute_force(m, pos, 0.01));
  CHECK_THROWS(stage.set_active({1, 0}));
}

TEST_CASE("small cases: touching boxes, a shared node, far apart, one triangle") {
  auto& cl = test::context();
  // 0: reference; 1: its box touches 0's box at x = 1 (no shared node); 2: shares node 2
  // with 0; 3: far away; 4: overlaps 3 only when the skin is at least 0.5.
  const std::vector<double> x = {0, 1, 0, 1, 2, 1, -1, 10, 11, 10, 11.5, 12.5, 11.5};
  const std::vector<double> y = {0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 1};
  const std::vector<std::array<int, 3>> tris = {{0, 1, 2}, {3, 4, 5}, {6, 0, 2}, {7, 8, 9}, {10, 11, 12}};
  const Model m = test::make_model(x, y, tris, one_material());
  DeviceArrays arrays(cl, m);
  auto key = [](uint64_t i, uint64_t j) { return i << 32 | j; };
  ContactDetection touching(cl, arrays, 0.0);
  CHECK(detect(cl, touching) == std::vector<uint64_t>{key(0, 1)});
  ContactDetection skinned(cl, arrays, 0.5);
  CHECK(detect(cl, skinned) == std::vector<uint64_t>{key(0, 1), key(3, 4)});
  CHECK(detect(cl, skinned) == brute_force(m, model_positions(m), 0.5));

  const Model single = test::make_model({0, 1, 0}, {0, 0, 1}, {{0, 1, 2}}, one_material());
  DeviceArrays one(cl, single);
  ContactDetection alone(cl, one, 0.1);
  CHECK(alone.run() == 0);
  check_grid(alone, single, model_positions(single), 0.1);
}

}  // TEST_SUITE
