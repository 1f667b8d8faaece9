// The partition of a model over ranks (engine/parallel/partition.*): every triangle in exactly
// one part, balanced work, deterministic, and the owner and ghost counts of `fdem check
// --ranks` against a brute-force reference written here from the rules in
// engine/parallel/partition.hpp.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <functional>
#include <set>
#include <vector>
#include <cmath>
#include <cstring>
#include <memory>
#include "approx.hpp"
#include "base/errors.hpp"
#include "case_files.hpp"
#include "engine/model/extrinsic.hpp"
#include "engine/parallel/halo.hpp"
#include "engine/parallel/partition.hpp"
#include "engine/run/split_run.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"
#include "fracture_tables.hpp"

using namespace fdem;

namespace {

// nx × ny squares of side h, each split into two counter-clockwise triangles sharing
// nodes. With `cohesive`, every triangle has its own three nodes and each interior edge
// gets a CE4 joining its two triangles (as a fracturable region's mesh has them).
Model grid(int nx, int ny, double h, bool cohesive) {
  std::vector<double> x, y;
  std::vector<std::array<int, 3>> tris;
  auto node = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) x.push_back(i * h), y.push_back(j * h);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      tris.push_back({node(i, j), node(i + 1, j), node(i + 1, j + 1)});
      tris.push_back({node(i, j), node(i + 1, j + 1), node(i, j + 1)});
    }
  if (!cohesive) return test::make_model(x, y, tris, {test::material_config("rock", io::Elasticity::NeoHookean, io::Plane::Strain)});
  // Own nodes per triangle; CE4s across the edges that two triangles shared.
  std::vector<double> sx, sy;
  std::vector<std::array<int, 3>> split;
  for (const auto& t : tris) {
    std::array<int, 3> s{};
    for (int k = 0; k < 3; ++k) s[k] = static_cast<int>(sx.size()), sx.push_back(x[t[k]]), sy.push_back(y[t[k]]);
    split.push_back(s);
  }
  Model m = test::make_model(sx, sy, split, {test::material_config("rock", io::Elasticity::NeoHookean, io::Plane::Strain)});
  for (size_t a = 0; a < tris.size(); ++a)
    for (size_t b = a + 1; b < tris.size(); ++b)
      for (int ea = 0; ea < 3; ++ea)
        for (int eb = 0; eb < 3; ++eb)
          if (tris[a][ea] == tris[b][(eb + 1) % 3] && tris[a][(ea + 1) % 3] == tris[b][eb]) {
            m.ce4.push_back({split[a][ea], split[a][(ea + 1) % 3], split[b][eb], split[b][(eb + 1) % 3]});
            m.ce4_triangles.push_back({static_cast<int>(a), static_cast<int>(b)});
          }
  m.triangle_fracturable.assign(m.num_triangles(), true);
  return m;
}

std::vector<PartitionMethod> methods() {
  std::vector<PartitionMethod> list{PartitionMethod::Bisection};
  if (partition_has_metis()) list.push_back(PartitionMethod::Metis);
  return list;
}

// The rules of engine/parallel/partition.hpp, with sets.
std::vector<PartStats> reference_stats(const Model& m, const Partition& p, double reach) {
  std::vector<int> owner(m.num_nodes(), -1);
  for (size_t t = 0; t < m.num_triangles(); ++t)
    for (int v : m.triangles[t])
      if (owner[v] < 0) owner[v] = p.triangle_part[t];
  std::vector<PartStats> s(p.parts);
  for (int r = 0; r < p.parts; ++r) {
    std::set<int> tri_ghosts, ce4_ghosts, nodes, touched;
    for (size_t v = 0; v < m.num_nodes(); ++v)
      if (owner[v] == r) nodes.insert(static_cast<int>(v));
    for (size_t t = 0; t < m.num_triangles(); ++t) {
      const bool mine = p.triangle_part[t] == r;
      bool uses = false;
      for (int v : m.triangles[t]) uses = uses || nodes.count(v);
      if (mine) ++s[r].tri3, s[r].work += triangle_work(m)[t];
      if (!mine && uses) tri_ghosts.insert(static_cast<int>(t));
      if (mine || uses)
        for (int v : m.triangles[t]) touched.insert(v);
    }
    for (size_t c = 0; c < m.ce4.size(); ++c) {
      const bool mine = p.triangle_part[m.ce4_triangles[c][0]] == r;
      bool uses = false;
      for (int v : m.ce4[c]) uses = uses || nodes.count(v);
      if (mine) ++s[r].ce4;
      if (!mine && uses) ce4_ghosts.insert(static_cast<int>(c));
      if (mine || uses)
        for (int v : m.ce4[c]) touched.insert(v);
    }
    s[r].nodes = nodes.size();
    s[r].ghost_tri3 = tri_ghosts.size();
    s[r].ghost_ce4 = ce4_ghosts.size();
    for (int v : touched) s[r].ghost_nodes += owner[v] != r;
    if (m.contact.enabled && p.parts > 1) {
      auto box = [&](size_t t) {
        const auto& v = m.triangles[t];
        return std::array<double, 4>{std::min({m.x[v[0]], m.x[v[1]], m.x[v[2]]}), std::max({m.x[v[0]], m.x[v[1]], m.x[v[2]]}),
                                     std::min({m.y[v[0]], m.y[v[1]], m.y[v[2]]}), std::max({m.y[v[0]], m.y[v[1]], m.y[v[2]]})};
      };
      std::set<size_t> near;
      for (size_t t = 0; t < m.num_triangles(); ++t) {
        if (p.triangle_part[t] != r) continue;
        const auto a = box(t);
        for (size_t u = 0; u < m.num_triangles(); ++u) {
          if (p.triangle_part[u] == r) continue;
          const auto b = box(u);
          if (b[0] <= a[1] + reach && b[1] >= a[0] - reach && b[2] <= a[3] + reach && b[3] >= a[2] - reach) near.insert(u);
        }
      }
      s[r].contact_ghost_tri3 = near.size();
    }
  }
  return s;
}

void check_equal(const std::vector<PartStats>& got, const std::vector<PartStats>& want) {
  REQUIRE(got.size() == want.size());
  for (size_t r = 0; r < got.size(); ++r) {
    CAPTURE(r);
    CHECK(got[r].tri3 == want[r].tri3);
    CHECK(got[r].ce4 == want[r].ce4);
    CHECK(got[r].nodes == want[r].nodes);
    CHECK(got[r].ghost_tri3 == want[r].ghost_tri3);
    CHECK(got[r].ghost_ce4 == want[r].ghost_ce4);
    CHECK(got[r].ghost_nodes == want[r].ghost_nodes);
    CHECK(got[r].contact_ghost_tri3 == want[r].contact_ghost_tri3);
    CHECK(got[r].work == want[r].work);
  }
}

// The bar of tests/data/cases/bar.geo, fracturable, critical viscosity, gravity, pulled
// at 5 m/s on its right edge (CE4s there break within tens of steps) and pressed by a
// traction on its top edge (loaded edges).
// `fracture_extra`: more [material.fracture] keys (e.g. the extrinsic model).
std::string pulled_bar(const test::TempDir& dir, const std::string& fracture_extra = "") {
  test::BarCase c;
  c.time = "dt = \"auto\"\nsteps = 400\n";
  c.output = "dir = \"" + dir.str() + "\"\nframes = 2\n";
  c.material = std::string("viscosity = \"critical\"\n") + test::kRockFracture + fracture_extra;
  c.rest = R"(
[gravity]
g = [0.0, -9.81]
[[boundary]]
region = "left"
fix = ["x", "y"]
[[boundary]]
region = "right"
velocity = [5.0, 0.0]
[[boundary]]
region = "top"
traction = [0.0, -1e6]
)";
  return dir.write("bar.toml", c.text());
}

bool same_bits(const real2& a, const real2& b) { return std::memcmp(&a, &b, sizeof(real2)) == 0; }

// Emulated ranks in one process: the engine's exchange for each rank's Solver, through the
// hub's in-process transports.
std::vector<std::unique_ptr<HaloExchange>> emulated_halos(ClContext& cl, const std::vector<std::unique_ptr<Solver>>& ranks,
                                                          const Model& model, const Partition& partition,
                                                          const std::vector<LocalModel>& locals, InProcessHub& hub) {
  std::vector<std::unique_ptr<HaloExchange>> halos;
  for (size_t r = 0; r < ranks.size(); ++r)
    halos.push_back(std::make_unique<HaloExchange>(cl, ranks[r]->arrays(), halo_plan(model, partition, locals[r], int(r)),
                                                   hub.rank(int(r))));
  return halos;
}

// Owned nodes of the emulated ranks whose positions differ from one rank's (`x_whole`).
size_t owned_drift(const std::vector<std::unique_ptr<Solver>>& ranks, const std::vector<LocalModel>& locals,
                   const std::vector<real2>& x_whole) {
  size_t drift = 0;
  for (size_t r = 0; r < ranks.size(); ++r) {
    const auto xl = ranks[r]->positions();
    for (size_t i = 0; i < xl.size(); ++i)
      drift += locals[r].node_owner[i] == int(r) && !same_bits(xl[i], x_whole[locals[r].node_global[i]]);
  }
  return drift;
}

}  // namespace

TEST_SUITE("partition") {
  // The heart of the scale-out design (ARCHITECTURE.md): each rank holds its own
  // elements plus every element that uses one of its nodes, in the global order, so its
  // own nodes' forces are summed as one rank sums them; only ghost nodes' positions and
  // velocities travel, once a step. Here the ranks run one after another in one process
  // and the exchange is the engine's (engine/parallel/halo.*) over in-process transports.
  TEST_CASE("ranks emulated in one process: every owned node bitwise as one rank, CE4s breaking") {
    test::TempDir dir;
    const PreparedCase p = prepare_case(pulled_bar(dir), {});
    ClContext& cl = test::context();
    const long steps = p.steps;
    Solver whole(cl, p.model, p.dt);
    for (long k = 0; k < steps; ++k) whole.step();
    const auto x_whole = whole.positions(), v_whole = whole.velocities();
    const size_t broken = whole.cohesive()->count_broken();
    CHECK(broken > 0);
    CHECK(broken < p.model.ce4.size());
    // A split run labels the pieces on the host (rank 0): the device's labels.
    CHECK(host_fragment_labels(p.model, whole.cohesive()->broken()) == whole.fragment_labels());
    for (auto method : methods())
      for (int parts : {2, 3}) {
        CAPTURE(partition_method_name(method));
        CAPTURE(parts);
        const auto partition = partition_model(p.model, parts, method);
        std::vector<LocalModel> locals;
        std::vector<std::unique_ptr<Solver>> ranks;
        for (int r = 0; r < parts; ++r) {
          locals.push_back(local_model(p.model, partition, r));
          CHECK(!locals.back().ghost_nodes.empty());
          ranks.push_back(std::make_unique<Solver>(cl, locals.back().model, p.dt));
        }
        // The engine's exchange (engine/parallel/halo.*) through in-process transports: every
        // rank posts its owned boundary nodes, then every rank takes its ghosts.
        InProcessHub hub(parts);
        std::vector<std::unique_ptr<HaloExchange>> halos;
        auto make_halos = [&] { halos = emulated_halos(cl, ranks, p.model, partition, locals, hub); };
        make_halos();
        for (int r = 0; r < parts; ++r) {
          // Every ghost is received from its owner, and what one rank sends another receives.
          CHECK(halos[r]->plan().received() == locals[r].ghost_nodes.size());
          for (int q = 0; q < parts; ++q)
            CHECK(halos[r]->plan().send[q].size() == halos[q]->plan().receive[r].size());
        }
        auto step_all = [&](bool exchange) {
          for (auto& s : ranks) s->step();
          if (!exchange) return;
          for (auto& h : halos) h->send();
          for (auto& h : halos) h->receive();
        };
        for (long k = 0; k < steps; ++k) step_all(true);
        size_t owned = 0, differ = 0, broken_owned = 0;
        for (int r = 0; r < parts; ++r) {
          const auto xl = ranks[r]->positions(), vl = ranks[r]->velocities();
          for (size_t i = 0; i < xl.size(); ++i) {  // owned nodes, and ghosts after the last exchange
            owned += locals[r].node_owner[i] == r;
            const int g = locals[r].node_global[i];
            differ += !same_bits(xl[i], x_whole[g]) || !same_bits(vl[i], v_whole[g]);
          }
          const auto b = ranks[r]->cohesive()->broken();
          for (size_t c = 0; c < b.size(); ++c)
            broken_owned += b[c] && partition.triangle_part[p.model.ce4_triangles[locals[r].ce4_global[c]][0]] == r;
        }
        CHECK(owned == p.model.num_nodes());
        CHECK(differ == 0);
        CHECK(broken_owned == broken);
        // Without the exchange the ghosts drift and the owned nodes next to them with them.
        if (method == PartitionMethod::Bisection && parts == 2) {
          for (int r = 0; r < parts; ++r) ranks[r] = std::make_unique<Solver>(cl, locals[r].model, p.dt);
          make_halos();
          for (long k = 0; k < steps; ++k) step_all(false);
          CHECK(owned_drift(ranks, locals, x_whole) > 0);
        }
      }
  }

  // Extrinsic CE4s (issue 33): a rank ties every mesh node it owns a copy of, so it holds
  // all of its copies and extrinsic CE4s, and the step exchanges the ghosts twice: after
  // the integration (the tie reads every copy) and after the tie (the insertions read the
  // tied positions of ghost CE4s). Here the parts of the step run rank by rank with the
  // engine's exchange between them, as the hooks of a split run place it.
  TEST_CASE("ranks emulated in one process, extrinsic CE4s: every node bitwise as one rank, CE4s inserted and broken") {
    test::TempDir dir;
    const PreparedCase p = prepare_case(pulled_bar(dir, "model = \"extrinsic\"\n"), {});
    REQUIRE(has_extrinsic(p.model));
    ClContext& cl = test::context();
    const long steps = p.steps;
    Solver whole(cl, p.model, p.dt);
    for (long k = 0; k < steps; ++k) whole.step();
    const auto x_whole = whole.positions(), v_whole = whole.velocities();
    const size_t inserted = whole.cohesive()->count_inserted(), broken = whole.cohesive()->count_broken();
    CHECK(inserted > 0);
    CHECK(broken > 0);
    CHECK(inserted < p.model.ce4.size());
    CHECK(count_inserted(p.model, whole.cohesive()->inserted_flags()) == inserted);
    for (auto method : methods())
      for (int parts : {2, 3}) {
        CAPTURE(partition_method_name(method));
        CAPTURE(parts);
        const auto partition = partition_model(p.model, parts, method);
        std::vector<LocalModel> locals;
        std::vector<std::unique_ptr<Solver>> ranks;
        for (int r = 0; r < parts; ++r) {
          locals.push_back(local_model(p.model, partition, r));
          ranks.push_back(std::make_unique<Solver>(cl, locals.back().model, p.dt));
          REQUIRE(ranks.back()->has_extrinsic_stage());
        }
        // Every copy of a mesh node a rank owns a copy of is in its local model.
        for (int r = 0; r < parts; ++r) {
          std::set<int> tied;
          for (size_t i = 0; i < locals[r].node_global.size(); ++i)
            if (locals[r].node_owner[i] == r) tied.insert(p.model.node_origin[locals[r].node_global[i]]);
          size_t copies = 0, held = 0;
          std::set<int> held_global(locals[r].node_global.begin(), locals[r].node_global.end());
          for (size_t g = 0; g < p.model.num_nodes(); ++g)
            if (tied.count(p.model.node_origin[g])) ++copies, held += held_global.count(int(g));
          CHECK(held == copies);
        }
        InProcessHub hub(parts);
        std::vector<std::unique_ptr<HaloExchange>> halos;
        auto make_halos = [&] { halos = emulated_halos(cl, ranks, p.model, partition, locals, hub); };
        auto exchange_all = [&] {
          for (auto& h : halos) h->send();
          for (auto& h : halos) h->receive();
        };
        // in_step: the split run's order; else one exchange after the whole step, as
        // for intrinsic CE4s.
        auto step_all = [&](bool in_step) {
          for (auto& s : ranks) s->step_forces();
          if (in_step) exchange_all();
          for (auto& s : ranks) s->step_tie();
          if (in_step) exchange_all();
          for (auto& s : ranks) s->step_finish();
          if (!in_step) exchange_all();
        };
        make_halos();
        for (long k = 0; k < steps; ++k) step_all(true);
        size_t owned = 0, differ = 0, inserted_owned = 0, broken_owned = 0;
        std::vector<cl_int> flags_whole(p.model.ce4.size(), 0);
        for (int r = 0; r < parts; ++r) {
          const auto xl = ranks[r]->positions(), vl = ranks[r]->velocities();
          for (size_t i = 0; i < xl.size(); ++i) {  // owned nodes and ghosts
            owned += locals[r].node_owner[i] == r;
            const int g = locals[r].node_global[i];
            differ += !same_bits(xl[i], x_whole[g]) || !same_bits(vl[i], v_whole[g]);
          }
          const auto b = ranks[r]->cohesive()->broken();
          const auto f = ranks[r]->cohesive()->inserted_flags();
          for (size_t c = 0; c < b.size(); ++c) {
            const int g = locals[r].ce4_global[c];
            if (partition.triangle_part[p.model.ce4_triangles[g][0]] != r) continue;
            broken_owned += b[c] != 0;
            flags_whole[g] = f[c];
          }
        }
        inserted_owned = count_inserted(p.model, flags_whole);
        CHECK(owned == p.model.num_nodes());
        CHECK(differ == 0);
        CHECK(inserted_owned == inserted);
        CHECK(broken_owned == broken);
        // With one exchange after the step, as for intrinsic CE4s, the ties at the ranks'
        // borders read stale ghost copies and the owned nodes drift from one rank's.
        if (method == PartitionMethod::Bisection && parts == 2) {
          for (int r = 0; r < parts; ++r) ranks[r] = std::make_unique<Solver>(cl, locals[r].model, p.dt);
          make_halos();
          for (long k = 0; k < steps; ++k) step_all(false);
          CHECK(owned_drift(ranks, locals, x_whole) > 0);
        }
      }
  }

  TEST_CASE("host fragment labels: the smallest triangle of each piece, through nodes and intact CE4s") {
    const Model m = grid(2, 1, 0.01, true);  // 4 triangles, each with its own nodes, 3 CE4s
    REQUIRE(m.ce4.size() == 3);
    CHECK(host_fragment_labels(m, {0, 0, 0}) == std::vector<int>{0, 0, 0, 0});
    CHECK(host_fragment_labels(m, {1, 1, 1}) == std::vector<int>{0, 1, 2, 3});
    // The squares' diagonals join 0-1 and 2-3, their shared side 0-3: breaking only that
    // one leaves the pieces {0, 1} and {2, 3}.
    std::vector<int> one(3, 0);
    for (size_t c = 0; c < 3; ++c) one[c] = m.ce4_triangles[c][0] == 0 && m.ce4_triangles[c][1] == 3;
    CHECK(std::count(one.begin(), one.end(), 1) == 1);
    CHECK(host_fragment_labels(m, one) == std::vector<int>{0, 0, 2, 2});
    // Shared nodes join triangles whatever the CE4s (no CE4s at all here).
    const Model shared = grid(2, 1, 0.01, false);
    CHECK(host_fragment_labels(shared, {}) == std::vector<int>{0, 0, 0, 0});
  }

  TEST_CASE("ordered sums: blocks of items left to right, the same bits on the device and on the host") {
    // Within a block, left to right: 1e16 + 1 would lose the 1 in any other grouping.
    const std::vector<real> small{real(1e16), 1, real(-1e16), 2, 1, 3};  // 3 items × 2
    const auto sums = blocked_sums(small, 3, 2, 0, 2);
    REQUIRE(sums.size() == 2);
    CHECK(sums[0] == double(real(real(1e16) + real(-1e16)) + real(1)));
    CHECK(sums[1] == 6.0);
    // Many blocks, values of mixed sign and size, columns 1 and 2 of rows of 4: the
    // device's OrderedSums (one rank) gives the host rule's bits (a split run's rank 0).
    ClContext& cl = test::context();
    const size_t count = 5 * kOrderedBlock + 37;
    std::vector<real> rows(4 * count);
    uint64_t state = 12345;
    for (auto& v : rows) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      v = real((double(state >> 11) / double(1ULL << 53) - 0.4) * std::pow(10.0, double(state % 13)));
    }
    compute::buffer buffer = cl.allocate(rows.size() * sizeof(real), "test rows");
    upload(cl, buffer, rows);
    OrderedSums device(cl, count);
    const auto on_device = device.sums(buffer, count, 4, 1, 2);
    const auto on_host = blocked_sums(rows, count, 4, 1, 2);
    REQUIRE(on_device.size() == 2);
    for (int c = 0; c < 2; ++c) {
      CAPTURE(c);
      CHECK(std::memcmp(&on_device[c], &on_host[c], sizeof(double)) == 0);
      CHECK(on_host[c] != 0.0);
    }
    CHECK(all_items(cl, buffer, count, 4, 1, 2, ItemKind::Node)() == on_host);
    // Queued (a history row): two sums in a row reuse the block-sum array; each gets its
    // own bits once both have landed.
    RowReads reads(cl);
    reads.begin();
    const auto first = device.queue(buffer, count, 4, 1, 2, reads);
    const auto second = device.queue(buffer, count, 4, 0, 1, reads);
    CHECK(second() == blocked_sums(rows, count, 4, 0, 1));
    CHECK(first() == on_host);
  }

  TEST_CASE("row reads: many queued reads past the first staging chunk land with their own values, row after row") {
    ClContext& cl = test::context();
    // 40 arrays of 3,000 doubles (24 kB each): about 15 times the first 64 KiB chunk.
    std::vector<compute::buffer> buffers;
    std::vector<std::vector<double>> values;
    for (int k = 0; k < 40; ++k) {
      std::vector<double> v(3000);
      for (size_t i = 0; i < v.size(); ++i) v[i] = 1000.0 * k + double(i) + 0.25;
      buffers.push_back(cl.allocate(v.size() * sizeof(double), "test row read"));
      upload(cl, buffers.back(), v);
      values.push_back(v);
    }
    RowReads reads(cl);
    for (int row = 0; row < 3; ++row) {
      CAPTURE(row);
      reads.begin();
      std::vector<std::function<std::vector<double>()>> pending;
      for (int k = 0; k < 40; ++k) pending.push_back(reads.read<double>(buffers[k], 3000 - k, k));
      for (int k = 39; k >= 0; --k) {
        const auto got = pending[k]();
        REQUIRE(got.size() == size_t(3000 - k));
        CHECK(std::equal(got.begin(), got.end(), values[k].begin() + k));
      }
      // The next row sees the device's new values, not the last row's.
      for (auto& v : values) std::transform(v.begin(), v.end(), v.begin(), [](double x) { return x + 1.0; });
      for (int k = 0; k < 40; ++k) upload(cl, buffers[k], values[k]);
    }
    CHECK(reads.read<double>(buffers[0], 0)().empty());
  }

  TEST_CASE("split sums: each rank's whole blocks and rank 0's shared ones give the rule's bits") {
    // 3 ranks over 7 blocks and a short one: runs of one owner (whole blocks, and blocks
    // cut by a run's end) and single items scattered between them (shared blocks).
    const size_t count = 7 * kOrderedBlock + 45;
    const int ranks = 3, stride = 4;
    uint64_t state = 777;
    auto next = [&] { return state = state * 6364136223846793005ULL + 1442695040888963407ULL; };
    std::vector<int> owner(count);
    for (size_t g = 0; g < count;) {
      const int r = static_cast<int>(next() % ranks);
      const size_t run = next() % 3 == 0 ? 1 + next() % 700 : 1;
      for (size_t k = 0; k < run && g < count; ++k) owner[g++] = r;
    }
    std::vector<real> rows(stride * count);
    for (auto& v : rows) v = real((double(next() >> 11) / double(1ULL << 53) - 0.4) * std::pow(10.0, double(next() % 13)));
    // Each rank holds its owned items and some ghosts, in global order (as local_model).
    std::vector<BlockShare> shares;
    std::vector<std::vector<real>> local(ranks);
    std::vector<std::vector<int64_t>> whole, shared;
    for (int r = 0; r < ranks; ++r) {
      std::vector<int> global;
      std::vector<char> owned;
      for (size_t g = 0; g < count; ++g)
        if (owner[g] == r || next() % 5 == 0) {
          global.push_back(static_cast<int>(g));
          owned.push_back(owner[g] == r ? 1 : 0);
          local[r].insert(local[r].end(), rows.begin() + g * stride, rows.begin() + (g + 1) * stride);
        }
      shares.push_back(BlockShare::of(global, owned, count));
      whole.push_back(shares.back().whole);
      shared.push_back(shares.back().shared);
    }
    size_t whole_blocks = 0;
    for (const auto& w : whole) whole_blocks += w.size();
    CHECK(whole_blocks > 0);
    CHECK(whole_blocks < 8);
    const BlockMerge merge(count, whole, shared);
    for (const auto& [first, width] : {std::pair<int, int>{0, 4}, {1, 2}, {3, 1}}) {
      CAPTURE(first);
      std::vector<Bytes> messages(ranks);
      std::vector<const Bytes*> all;
      for (int r = 0; r < ranks; ++r) {
        shares[r].message(local[r].data(), stride, first, width, messages[r]);
        all.push_back(&messages[r]);
      }
      const auto split = merge.sums(all, width);
      const auto one = blocked_sums(rows, count, stride, first, width);
      REQUIRE(split.size() == one.size());
      CHECK(std::memcmp(split.data(), one.data(), one.size() * sizeof(double)) == 0);
    }
    // Items with two owners or none are refused.
    auto twice = shared;
    twice[1].push_back(twice[0].front());
    std::sort(twice[1].begin(), twice[1].end());
    CHECK_THROWS_AS(BlockMerge(count, whole, twice), std::logic_error);
    auto missing = shared;
    missing[2].pop_back();
    CHECK_THROWS_AS(BlockMerge(count, whole, missing), std::logic_error);
  }

  TEST_CASE("split contact stored energy: the group tree from the nonzero values and their places alone") {
    // A list of which a few couples hold a value, some −0 (a touching couple storing
    // nothing); the dense tree of contact_stored_partials over the whole list, zeros and
    // all, against tree_group_sums over the nonzero values and their places.
    const size_t group = 64, n = 40 * group + 17;
    uint64_t state = 99;
    auto next = [&] { return state = state * 6364136223846793005ULL + 1442695040888963407ULL; };
    std::vector<real> list(n, real(0));
    std::vector<std::pair<uint64_t, real>> nonzero;
    for (size_t c = 0; c < n; ++c) {
      const auto pick = next() % 16;
      if (pick == 0) list[c] = real(-0.0);
      if (pick == 1 || pick == 2)  // mixed signs and sizes: any other grouping loses other bits
        list[c] = real((double(next() >> 11) / double(1ULL << 53) - 0.5) * std::pow(10.0, double(next() % 17)));
      if (pick == 3) list[c] = real(1e-300);  // lost beside larger values, kept alone
      if (list[c] != real(0)) nonzero.emplace_back(c, list[c]);
    }
    double dense = 0;
    std::vector<real> scratch(group);
    for (size_t begin = 0; begin < n; begin += group) {
      for (size_t l = 0; l < group; ++l) scratch[l] = begin + l < n ? list[begin + l] : real(0);
      for (size_t s = group / 2; s > 0; s >>= 1)
        for (size_t l = 0; l < s; ++l) scratch[l] += scratch[l + s];
      dense += static_cast<double>(scratch[0]);
    }
    const double sparse = tree_group_sums(nonzero, group);
    // The places matter: the same values packed at the list's front sum otherwise.
    auto packed = nonzero;
    for (size_t k = 0; k < packed.size(); ++k) packed[k].first = k;
    CHECK(tree_group_sums(packed, group) != dense);
    CHECK(std::memcmp(&dense, &sparse, sizeof(double)) == 0);
    CHECK(tree_group_sums({}, group) == 0.0);
    // The places: keys below each query, over ascending runs of queries.
    std::vector<cl_ulong> keys;
    for (size_t k = 0; k < 5000; ++k) keys.push_back(next() % 100000);
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<cl_ulong> queries;
    for (int run = 0; run < 3; ++run) {
      std::vector<cl_ulong> q;
      for (size_t k = 0; k < 300; ++k) q.push_back(next() % 2 ? keys[next() % keys.size()] : next() % 110000);
      std::sort(q.begin(), q.end());
      q.erase(std::unique(q.begin(), q.end()), q.end());
      queries.insert(queries.end(), q.begin(), q.end());
    }
    const auto below = count_below(keys, queries);
    REQUIRE(below.size() == queries.size());
    for (size_t k = 0; k < queries.size(); ++k)
      CHECK(below[k] == static_cast<uint64_t>(std::lower_bound(keys.begin(), keys.end(), queries[k]) - keys.begin()));
  }

  TEST_CASE("contact ghosts: every triangle within the reach of an owned one, and the owned masks") {
    for (bool cohesive : {false, true}) {
      CAPTURE(cohesive);
      Model m = grid(12, 6, 0.01, cohesive);
      m.ce4_properties.assign(m.ce4.size(), 0);
      m.contact.enabled = true;
      m.contact.skin = 0.002;
      Partition p = partition_model(m, 3, PartitionMethod::Bisection);
      // Without a reach a split model with contact is refused (it would miss couples).
      CHECK_THROWS_AS(local_model(m, p, 0), InputError);
      p.contact_reach = contact_ghost_reach(m, 0.004);
      auto box = [&](size_t t) {
        std::array<double, 4> b{1e300, 1e300, -1e300, -1e300};
        for (int v : m.triangles[t])
          b = {std::min(b[0], m.x[v]), std::min(b[1], m.y[v]), std::max(b[2], m.x[v]), std::max(b[3], m.y[v])};
        return b;
      };
      for (int rank = 0; rank < 3; ++rank) {
        const LocalModel l = local_model(m, p, rank);
        std::vector<char> held(m.num_triangles(), 0);
        for (int g : l.triangle_global) held[g] = 1;
        size_t owned = 0;
        for (size_t t = 0; t < l.triangle_global.size(); ++t) {
          CHECK(l.model.triangle_owned[t] == (p.triangle_part[l.triangle_global[t]] == rank ? 1 : 0));
          owned += l.model.triangle_owned[t];
        }
        CHECK(owned == static_cast<size_t>(std::count(p.triangle_part.begin(), p.triangle_part.end(), rank)));
        for (size_t t = 0; t < m.num_triangles(); ++t) {
          if (p.triangle_part[t] != rank) continue;
          const auto a = box(t);
          for (size_t u = 0; u < m.num_triangles(); ++u) {
            const auto b = box(u);
            const bool near = b[0] <= a[2] + p.contact_reach && b[2] >= a[0] - p.contact_reach &&
                              b[1] <= a[3] + p.contact_reach && b[3] >= a[1] - p.contact_reach;
            if (near) CHECK(held[u]);
          }
        }
        CHECK(l.model.node_owned.size() == l.model.num_nodes());
        CHECK(l.model.whole_longest_edge > 0);
        if (cohesive) CHECK(l.model.ce4_owned.size() == l.model.ce4.size());
      }
    }
  }

  TEST_CASE("every triangle in exactly one part, every part used, the same twice") {
    const Model m = grid(24, 12, 0.01, true);
    for (auto method : methods())
      for (int parts : {1, 2, 3, 4, 7}) {
        CAPTURE(partition_method_name(method));
        CAPTURE(parts);
        const auto p = partition_model(m, parts, method);
        REQUIRE(p.triangle_part.size() == m.num_triangles());
        std::vector<size_t> count(parts, 0);
        for (int q : p.triangle_part) {
          REQUIRE(q >= 0);
          REQUIRE(q < parts);
          ++count[q];
        }
        for (size_t c : count) CHECK(c > 0);
        CHECK(partition_model(m, parts, method).triangle_part == p.triangle_part);
      }
  }

  TEST_CASE("balanced work on a uniform grid") {
    const Model m = grid(40, 40, 0.01, false);
    for (int parts : {2, 4, 8}) {
      CAPTURE(parts);
      const double bisection = partition_imbalance(partition_stats(m, partition_model(m, parts, PartitionMethod::Bisection), 0));
      CHECK(bisection < 1.01);
      if (partition_has_metis()) {
        const double metis = partition_imbalance(partition_stats(m, partition_model(m, parts, PartitionMethod::Metis), 0));
        CHECK(metis < 1.05);
      }
    }
  }

  TEST_CASE("bisection cuts across the longer side, into compact parts") {
    const Model m = grid(40, 10, 0.01, false);  // 0.4 m wide, 0.1 m tall
    const auto p = partition_model(m, 2, PartitionMethod::Bisection);
    double left_max = -1, right_min = 1e9;
    for (size_t t = 0; t < m.num_triangles(); ++t) {
      const auto& v = m.triangles[t];
      const double cx = (m.x[v[0]] + m.x[v[1]] + m.x[v[2]]) / 3;
      if (p.triangle_part[t] == 0) left_max = std::max(left_max, cx);
      else right_min = std::min(right_min, cx);
    }
    CHECK(left_max < right_min);
    CHECK(left_max == test::rel(0.2, 0.05));
  }

  // Runs `check(contact, partition)` on `m` without and with contact, split by each method
  // into 2, 3 and 5 parts (the failure names the combination).
  template <class Check>
  void for_each_grid_split(Model& m, Check check) {
    for (bool contact : {false, true}) {
      m.contact.enabled = contact;
      for (auto method : methods())
        for (int parts : {2, 3, 5}) {
          CAPTURE(contact);
          CAPTURE(partition_method_name(method));
          CAPTURE(parts);
          check(contact, partition_model(m, parts, method));
        }
    }
  }

  TEST_CASE("owners and ghosts against the brute-force rules, with CE4s and contact") {
    Model m = grid(10, 6, 0.01, true);
    for_each_grid_split(m, [&](bool, const Partition& p) {
      const double reach = 0.004;
      check_equal(partition_stats(m, p, reach), reference_stats(m, p, reach));
    });
    // A model whose triangles share nodes (no CE4s).
    const Model shared = grid(9, 7, 0.02, false);
    for (int parts : {2, 4}) check_equal(partition_stats(shared, partition_model(shared, parts, PartitionMethod::Bisection), 0),
                                         reference_stats(shared, partition_model(shared, parts, PartitionMethod::Bisection), 0));
  }

  TEST_CASE("fdem check's held counts are what each rank's local model holds") {
    // Each part's held triangles, CE4s and nodes against the local model built for it.
    auto check_held = [](const Model& m, Partition p, double reach) {
      p.contact_reach = m.contact.enabled ? reach : 0.0;
      const auto stats = partition_stats(m, p, reach);
      size_t ce4_beyond = 0, tri3_beyond = 0;  // held elements the ghost columns leave out
      for (int r = 0; r < p.parts; ++r) {
        CAPTURE(r);
        const LocalModel l = local_model(m, p, r);
        CHECK(stats[r].held_tri3 == l.model.num_triangles());
        CHECK(stats[r].held_ce4 == l.model.ce4.size());
        CHECK(stats[r].held_nodes == l.model.num_nodes());
        REQUIRE(stats[r].held_tri3 >= stats[r].tri3 + stats[r].ghost_tri3);
        REQUIRE(stats[r].held_ce4 >= stats[r].ce4 + stats[r].ghost_ce4);
        tri3_beyond += stats[r].held_tri3 - (stats[r].tri3 + stats[r].ghost_tri3);
        ce4_beyond += stats[r].held_ce4 - (stats[r].ce4 + stats[r].ghost_ce4);
      }
      return std::array<size_t, 2>{tri3_beyond, ce4_beyond};
    };
    Model m = grid(10, 6, 0.01, true);
    m.ce4_properties.assign(m.ce4.size(), 0);
    for_each_grid_split(m, [&](bool contact, const Partition& p) {
      const auto beyond = check_held(m, p, 0.004);
      // Without contact a rank holds its own CE4s and their ghosts only (but also the
      // triangles of those CE4s, which need not use an owned node).
      if (!contact) CHECK(beyond[1] == 0);
      else CHECK(beyond[0] > 0);  // the contact ghosts' triangles
    });
    // A meshed case with CE4s and contact: the CE4s around the contact ghosts (whose
    // states contact reads) are held too, which the ghost columns do not count.
    const PreparedCase c = prepare_case(test::source_path("tests/data/cases/blast_small.toml"), {});
    REQUIRE(c.model.contact.enabled);
    REQUIRE(!c.model.ce4.empty());
    const double reach = contact_ghost_reach(c.model, default_contact_travel(c.model));
    for (int parts : {2, 3}) {
      CAPTURE(parts);
      const auto beyond = check_held(c.model, partition_model(c.model, parts, PartitionMethod::Bisection), reach);
      CHECK(beyond[0] > 0);
      CHECK(beyond[1] > 0);
    }
    // Extrinsic CE4s (the pulled bar, no contact): a rank holds every copy of the mesh
    // nodes it owns a copy of, and the extrinsic CE4s there, beyond the intrinsic ghosts.
    test::TempDir dir;
    const PreparedCase in = prepare_case(pulled_bar(dir), {});
    const PreparedCase ex = prepare_case(pulled_bar(dir, "model = \"extrinsic\"\n"), {});
    REQUIRE(has_extrinsic(ex.model));
    REQUIRE(!ex.model.contact.enabled);
    for (int parts : {2, 3}) {
      CAPTURE(parts);
      const auto pe = partition_model(ex.model, parts, PartitionMethod::Bisection);
      const auto pi = partition_model(in.model, parts, PartitionMethod::Bisection);
      const auto beyond = check_held(ex.model, pe, 0.0);
      CHECK(beyond[1] > 0);  // extrinsic CE4s that use no owned node
      const auto se = partition_stats(ex.model, pe, 0.0), si = partition_stats(in.model, pi, 0.0);
      for (int r = 0; r < parts; ++r) {
        CHECK(se[r].held_ce4 > si[r].held_ce4);
        CHECK(se[r].held_tri3 > si[r].held_tri3);
      }
    }
  }

  TEST_CASE("the work weights: a contact candidate outweighs a CE4, a CE4 a bare triangle") {
    Model m = grid(3, 3, 0.01, true);
    auto w = triangle_work(m);
    // A corner triangle has one CE4, an inner one three.
    CHECK(*std::min_element(w.begin(), w.end()) == 4 + 5);
    CHECK(*std::max_element(w.begin(), w.end()) == 4 + 3 * 5);
    m.contact.enabled = true;
    w = triangle_work(m);
    CHECK(*std::min_element(w.begin(), w.end()) == 4 + 5 + 100);
  }

  TEST_CASE("a number of ranks the model cannot take is refused") {
    const Model m = grid(2, 2, 0.01, false);  // 8 triangles
    CHECK_THROWS_AS(partition_model(m, 0, PartitionMethod::Bisection), InputError);
    CHECK_THROWS_AS(partition_model(m, 9, PartitionMethod::Bisection), InputError);
    CHECK_NOTHROW(partition_model(m, 8, PartitionMethod::Bisection));
  }
}
