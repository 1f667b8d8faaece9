// Extrinsic cohesive elements (fracture.model = "extrinsic", issue 33): the insertion
// criterion against a plain C++ reference, the tied continuum against a conforming mesh,
// determinism, restart, the energy account and the refusals.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>

#include "approx.hpp"
#include "case_files.hpp"
#include "engine/model/extrinsic.hpp"
#include "engine/run/prepare_case.hpp"
#include "engine/run/run.hpp"
#include "engine/solver.hpp"
#include "fixture.hpp"
#include "fracture_tables.hpp"

using namespace fdem;

namespace {

const std::string kExtrinsic = std::string(test::kRockFracture) + "model = \"extrinsic\"\n";

const std::string kHeld = R"(
[[boundary]]
region = "left"
fix = ["x"]
[[boundary]]
region = "bottom"
fix = ["y"]
)";

// The bar held on its left and bottom edges, its right edge pulled at `speed` [m/s].
std::string pull(double speed) {
  return kHeld + "[[boundary]]\nregion = \"right\"\nvelocity = [" + std::to_string(speed) + ", 0.0]\nrise = 1e-4\n";
}

// The bar (tests/data/cases/bar.geo, 1 m × 0.2 m) with critical viscosity to `end`.
std::string bar(const test::TempDir& dir, const std::string& out, const std::string& fracture, double end,
                const std::string& load, const std::string& name = "bar.toml") {
  test::BarCase c;
  c.time = "dt = \"auto\"\nend = " + std::to_string(end) + "\n";
  c.output = "dir = \"" + out + "\"\nname = \"bar\"\nframes = 3\nhistory_every = 2e-5\n";
  c.material = "viscosity = \"critical\"\n" + fracture;
  c.rest = load;
  return dir.write(name, c.text());
}

// The insertion rule of cl_kernels/extrinsic.cl, written independently: the mean traction
// of the two triangles on the edge from the corner forces opposite it, the intrinsic law's
// peak envelope, and the offsets that carry the traction (capped at the peak).
struct Reference {
  bool inserts = false;
  double sigma = 0, tau = 0;  // the carried traction [Pa]
  double o0 = 0, s0 = 0;      // the law's offsets [m]
  double margin = 0;          // distance from the envelope, relative to T_s (round-off guard)
};

Reference reference(const FractureProperties& f, double h, double thickness, real2 xi, real2 xj, real2 xj2, real2 xi2,
                    real2 f1, real2 f2) {
  Reference r;
  const double cx = (double(xj.x) - xi.x) + (double(xj2.x) - xi2.x), cy = (double(xj.y) - xi.y) + (double(xj2.y) - xi2.y);
  const double cl = std::hypot(cx, cy), tx = cx / cl, ty = cy / cl, nx = ty, ny = -tx;
  const double l1 = std::hypot(double(xj.x) - xi.x, double(xj.y) - xi.y);
  const double l2 = std::hypot(double(xj2.x) - xi2.x, double(xj2.y) - xi2.y);
  // σ n_k = 2 f_k / (t L) for the corner k opposite the edge; the mean over both sides.
  const double px = f1.x / (thickness * l1) - f2.x / (thickness * l2);
  const double py = f1.y / (thickness * l1) - f2.y / (thickness * l2);
  r.sigma = px * nx + py * ny;
  r.tau = px * tx + py * ty;
  const double tanphi = std::tan(f.friction_angle * std::acos(-1.0) / 180.0);
  const double cap = tanphi * std::max(-r.sigma, 0.0);
  r.margin = std::max(r.sigma - f.tensile_strength, std::fabs(r.tau) - (f.cohesion + cap)) / f.tensile_strength;
  r.inserts = r.sigma >= f.tensile_strength || std::fabs(r.tau) >= f.cohesion + cap;
  const double op = 2 * h * f.tensile_strength / f.penalty_opening, sp = 2 * h * f.cohesion / f.penalty_sliding;
  const double oov = 2 * h * f.tensile_strength / f.penalty_overlap;
  const double sn = std::min(r.sigma, f.tensile_strength);
  r.o0 = sn >= 0 ? op * (1 - std::sqrt(1 - sn / f.tensile_strength)) : sn * oov / (2 * f.tensile_strength);
  const double tc = std::min(std::fabs(r.tau), f.cohesion);
  r.s0 = std::copysign(sp * (1 - std::sqrt(1 - tc / f.cohesion)), r.tau);
  return r;
}

bool same_bytes(const std::string& a, const std::string& b) {
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {}), sb((std::istreambuf_iterator<char>(fb)), {});
  return !sa.empty() && sa == sb;
}

}  // namespace

TEST_SUITE("extrinsic") {

TEST_CASE("the case key: \"extrinsic\" per material, \"intrinsic\" the default; bad values and unsupported parts refused") {
  test::TempDir dir;
  const PreparedCase p = prepare_case(bar(dir, dir.str(), kExtrinsic, 1e-4, pull(0.1)), {});
  CHECK(has_extrinsic(p.model));
  const PreparedCase q = prepare_case(bar(dir, dir.str(), test::kRockFracture, 1e-4, pull(0.1), "i.toml"), {});
  CHECK_FALSE(has_extrinsic(q.model));
  auto refused = [&](const std::string& fracture, const std::string& extra) {
    try {
      prepare_case(bar(dir, dir.str(), fracture, 1e-4, pull(0.1) + extra, "bad.toml"), {});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string typo = refused(std::string(test::kRockFracture) + "model = \"extrinsc\"\n", "");
  CHECK(typo.find("material[0].fracture.model") != std::string::npos);
  CHECK(typo.find("did you mean \"extrinsic\"") != std::string::npos);
  const std::string damping = refused(kExtrinsic, "[damping]\nlocal = 0.8\n");
  CHECK(damping.find("fracture.model = \"extrinsic\" cannot be combined with damping.local") != std::string::npos);
  CHECK(damping.find("bad.toml") != std::string::npos);
}

TEST_CASE("node numbering: extrinsic models by mesh vertex (a vertex's copies consecutive), intrinsic by triangle") {
  test::TempDir dir;
  const PreparedCase pe = prepare_case(bar(dir, dir.str(), kExtrinsic, 1e-4, pull(0.1)), {});
  const PreparedCase pi = prepare_case(bar(dir, dir.str(), test::kRockFracture, 1e-4, pull(0.1), "i.toml"), {});
  const Model &e = pe.model, &i = pi.model;
  REQUIRE(e.num_nodes() == i.num_nodes());
  REQUIRE(e.num_triangles() == i.num_triangles());
  REQUIRE(e.ce4.size() == i.ce4.size());
  // Extrinsic: the copies of each mesh vertex are one run of node indices, vertices in order.
  CHECK(std::is_sorted(e.node_origin.begin(), e.node_origin.end()));
  // Intrinsic: each fracturable triangle owns three consecutive nodes, in triangle order.
  size_t consecutive = 0;
  for (size_t t = 0; t < i.num_triangles(); ++t)
    consecutive += i.triangle_fracturable[t] && i.triangles[t][1] == i.triangles[t][0] + 1 && i.triangles[t][2] == i.triangles[t][0] + 2;
  CHECK(consecutive == size_t(std::count(i.triangle_fracturable.begin(), i.triangle_fracturable.end(), true)));
  CHECK(consecutive > 0);
  // The same mesh either way: every triangle's and CE4's corners copy the same mesh vertices
  // at the same coordinates, and every node is a corner of exactly one fracturable triangle.
  size_t same = 0;
  for (size_t t = 0; t < e.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = e.triangles[t][k], b = i.triangles[t][k];
      same += e.node_origin[a] == i.node_origin[b] && e.x[a] == i.x[b] && e.y[a] == i.y[b];
    }
  CHECK(same == 3 * e.num_triangles());
  size_t same_ce4 = 0;
  for (size_t c = 0; c < e.ce4.size(); ++c)
    for (int k = 0; k < 4; ++k) same_ce4 += e.node_origin[e.ce4[c][k]] == i.node_origin[i.ce4[c][k]];
  CHECK(same_ce4 == 4 * e.ce4.size());
  std::vector<int> uses(e.num_nodes(), 0);
  for (const auto& tri : e.triangles)
    for (int n : tri) ++uses[size_t(n)];
  CHECK(std::all_of(uses.begin(), uses.end(), [](int u) { return u == 1; }));
}

TEST_CASE("insertion: an edge gets its CE4 exactly when its traction reaches the peak, at the traction it carried") {
  test::TempDir dir;
  // 0.5 m/s: the front's stress ρ c v is about 2.4 MPa > T_s = 2 MPa, so edges near the
  // pulled end reach the strength, the rest of the bar does not.
  const PreparedCase p = prepare_case(bar(dir, dir.str(), kExtrinsic, 3e-4, pull(0.5)), {});
  Solver solver(test::context(), p.model, p.dt);
  ClContext& cl = test::context();
  CohesiveForces& ce4 = *solver.cohesive();
  const size_t n = p.model.ce4.size();
  std::vector<cl_int> was(n, 0);
  const auto& params = ce4.parameters();
  size_t inserted = 0, checked = 0, near_envelope = 0;
  double worst_o = 0, worst_s = 0;
  for (long s = 0; s < p.steps; ++s) {
    solver.step(false);
    const auto now = download<cl_int>(cl, ce4.inserted(), n);
    const auto gaps = download<real4>(cl, ce4.insertion_gaps(), n);  // o₀, s₀, ψ₀ h t, 0
    const auto x = solver.positions();
    const auto corner = download<real2>(cl, solver.arrays().corner_force, 3 * p.model.num_triangles());
    for (size_t e = 0; e < n; ++e) {
      if (was[e]) {
        CHECK(now[e] == 1);  // once inserted, for good
        continue;
      }
      const auto& c = p.model.ce4[e];
      const auto& tri = p.model.ce4_triangles[e];
      auto opposite = [&](int side) {
        const auto& t = p.model.triangles[tri[side]];
        const int a = side == 0 ? c[0] : c[3], b = side == 0 ? c[1] : c[2];
        for (int k = 0; k < 3; ++k)
          if (t[k] != a && t[k] != b) return corner[3 * tri[side] + k];
        return real2{0, 0};
      };
      const double h = params[layout::COH_STRIDE * e + layout::COH_H];
      const Reference r = reference(p.model.fracture[p.model.ce4_properties[e]], h, p.model.thickness, x[c[0]], x[c[1]],
                                    x[c[2]], x[c[3]], opposite(0), opposite(1));
      ++checked;
      if (std::fabs(r.margin) < 1e-9) {  // on the envelope to round-off: either answer is right
        ++near_envelope;
        continue;
      }
      CHECK(bool(now[e]) == r.inserts);
      if (now[e] && r.inserts) {
        ++inserted;
        const double op = params[layout::COH_STRIDE * e + layout::COH_OP];
        const double sp = params[layout::COH_STRIDE * e + layout::COH_SP];
        worst_o = std::max(worst_o, std::fabs(gaps[e].x - r.o0) / op);
        worst_s = std::max(worst_s, std::fabs(gaps[e].y - r.s0) / sp);
      }
    }
    was = now;
  }
  MESSAGE(inserted << " insertions over " << p.steps << " steps (" << checked << " CE4-steps checked, " << near_envelope
                   << " on the envelope to round-off); offsets against the reference: o₀ within " << worst_o
                   << " o_p, s₀ within " << worst_s << " s_p");
  CHECK(inserted > 0);
  CHECK(inserted < n);  // the bar's far end stays a continuum
  CHECK(worst_o < 1e-6);  // √(1 - σ/T_s) near the peak magnifies the traction's round-off
  CHECK(worst_s < 1e-6);
  CHECK(ce4.count_inserted() == size_t(std::count(was.begin(), was.end(), 1)));  // every CE4 here is extrinsic
}

TEST_CASE("nothing inserted: the extrinsic bar moves as the conforming bar (no CE4 compliance), with no CE4 energy") {
  test::TempDir dir;
  // 0.1 m/s: about 0.5 MPa at the front, a quarter of T_s.
  const PreparedCase e = prepare_case(bar(dir, dir.str() + "/e", kExtrinsic, 4e-4, pull(0.1), "e.toml"), {});
  std::ostringstream step;
  step.precision(17);
  step << e.dt;
  const std::string dt = "time.dt=" + step.str();
  const PreparedCase c = prepare_case(bar(dir, dir.str() + "/c", "", 4e-4, pull(0.1), "c.toml"), {dt});
  const PreparedCase i = prepare_case(bar(dir, dir.str() + "/i", test::kRockFracture, 4e-4, pull(0.1), "i.toml"), {dt});
  REQUIRE(c.dt == e.dt);
  Solver se(test::context(), e.model, e.dt), sc(test::context(), c.model, c.dt), si(test::context(), i.model, i.dt);
  for (long s = 0; s < e.steps; ++s) se.step(false), sc.step(false), si.step(false);
  CHECK(se.cohesive()->count_inserted() == 0);
  const auto xe = se.positions(), xc = sc.positions(), xi = si.positions();
  std::map<long, real2> by_tag;
  for (size_t k = 0; k < xc.size(); ++k) by_tag[c.model.node_tags[k]] = xc[k];
  double worst = 0, worst_intrinsic = 0, largest = 0;
  for (size_t k = 0; k < xe.size(); ++k) {
    const real2 ref = by_tag.at(e.model.node_tags[k]);
    const double d = std::hypot(xe[k].x - ref.x, xe[k].y - ref.y);
    worst = std::max(worst, d);
    worst_intrinsic = std::max(worst_intrinsic, std::hypot(xi[k].x - ref.x, xi[k].y - ref.y));
  }
  for (size_t k = 0; k < xc.size(); ++k) largest = std::max(largest, std::fabs(double(xc[k].x) - c.model.x[k]));
  MESSAGE("after " << e.steps << " steps the right end moved " << largest << " m; extrinsic differs from the "
          << "conforming bar by at most " << worst << " m, intrinsic (penalties 10 E) by " << worst_intrinsic << " m");
  CHECK(largest > 1e-5);
  CHECK(worst < 1e-7 * largest);  // round-off: the tie's sums against the gather's
  CHECK(worst_intrinsic > 1e3 * worst);
  const EnergyTotals t = se.energy();
  CHECK(t.cohesive_stored == 0.0);
  CHECK(t.fracture == 0.0);
}

TEST_CASE("history: the out-of-balance force of tied copies is their sum, as the conforming bar's node's") {
  // Each copy's force is its own triangle's share; the tie moves the copies as one body,
  // whose out-of-balance force is the sum: the conforming bar's, to round-off.
  test::TempDir dir;
  const PreparedCase e = prepare_case(bar(dir, dir.str() + "/e", kExtrinsic, 4e-4, pull(0.1), "e.toml"), {});
  std::ostringstream step;
  step.precision(17);
  step << e.dt;
  test::run(dir.str() + "/e.toml", {});
  test::run(bar(dir, dir.str() + "/c", "", 4e-4, pull(0.1), "c.toml"), {"time.dt=" + step.str()});
  const auto fe = test::read_variable(dir.str() + "/e/bar_history.nc", "max_unbalanced_force");
  const auto fc = test::read_variable(dir.str() + "/c/bar_history.nc", "max_unbalanced_force");
  REQUIRE(fe.size() == fc.size());
  double largest = 0, worst = 0;
  for (size_t k = 0; k < fc.size(); ++k) largest = std::max(largest, fc[k]);
  for (size_t k = 0; k < fc.size(); ++k) worst = std::max(worst, std::fabs(fe[k] - fc[k]));
  // Each copy alone: what the column held before it summed the tied copies.
  Solver se(test::context(), e.model, e.dt);
  for (long s = 0; s < e.steps; ++s) se.step(false);
  const auto f = se.forces();
  double per_copy = 0;
  for (size_t k = 0; k < f.size(); ++k)
    if (!(e.model.groups[e.model.node_group[k]].mask & 1u)) per_copy = std::max(per_copy, std::fabs(double(f[k].x)));
  MESSAGE("largest out-of-balance force " << largest << " N; extrinsic against conforming at most " << worst
          << " N apart; one copy alone at the end " << per_copy << " N against " << fe.back() << " N summed");
  CHECK(largest > 0);
  CHECK(worst <= 1e-6 * largest);
  CHECK(per_copy > 10 * fe.back());
}

TEST_CASE("an extrinsic bar pulled apart: bitwise repeatable, restarts byte for byte, energy account closed") {
  test::TempDir dir;
  const std::string one = dir.str() + "/one", two = dir.str() + "/two", three = dir.str() + "/three";
  const auto whole = test::run(bar(dir, one, kExtrinsic, 4e-4, pull(0.5), "one.toml"));
  test::run(bar(dir, three, kExtrinsic, 4e-4, pull(0.5), "three.toml"));
  const auto half = test::run(bar(dir, two, kExtrinsic, 2e-4, pull(0.5), "two.toml"));
  const auto rest = test::run(bar(dir, two, kExtrinsic, 4e-4, pull(0.5), "two.toml"), {}, test::restart_from(two + "/bar.ckpt"));
  CHECK(half.steps + rest.steps == whole.steps);
  CHECK(same_bytes(one + "/bar_history.nc", three + "/bar_history.nc"));
  CHECK(same_bytes(one + "/bar.exo", three + "/bar.exo"));
  CHECK(same_bytes(one + "/bar_history.nc", two + "/bar_history.nc"));
  CHECK(same_bytes(one + "/bar.exo", two + "/bar.exo"));
  CHECK(same_bytes(one + "/bar_events.nc", two + "/bar_events.nc"));
  const std::string hist = one + "/bar_history.nc";
  const auto inserted = test::read_variable(hist, "inserted_ce4");
  const auto broken = test::read_variable(hist, "broken_ce4");
  const auto error = test::read_variable(hist, "energy_error");
  const auto dissipated = test::read_variable(hist, "fracture_dissipation");
  double worst = 0;
  for (double x : error) worst = std::max(worst, std::fabs(x));
  const size_t middle = inserted.size() / 2;
  MESSAGE("inserted CE4s " << inserted[middle] << " at the checkpoint, " << inserted.back() << " at the end; broken "
          << broken[middle] << " then " << broken.back() << "; worst |energy_error| " << worst << "; fracture_dissipation " << dissipated.back() << " J");
  CHECK(inserted[middle] > 0);
  CHECK(inserted.back() >= inserted[middle]);
  CHECK(broken.back() > broken[middle]);  // inserted before the checkpoint, broken after it
  for (size_t k = 1; k < inserted.size(); ++k) CHECK(inserted[k] >= inserted[k - 1]);
  for (size_t k = 1; k < dissipated.size(); ++k) CHECK(dissipated[k] >= dissipated[k - 1]);
  CHECK(worst < 1e-3);
}

TEST_CASE("the time step: an inserted CE4's penalty sets it; at the rock's own step inserted CE4s make energy") {
  // The bar with no viscosity (so the stable step is h/c with no damping correction), its
  // right edge loaded by a pressure pulse: 4 MPa of tension (twice T_s: edges near the
  // loaded end get their CE4 at the peak), then 8 MPa of compression, which drives the
  // inserted CE4s onto their stiff branches (unloading, overlap) with slope P/h.
  test::TempDir dir;
  auto pulse = [&](const std::string& out, const std::string& fracture, double tension, const std::string& name) {
    test::BarCase c;
    c.time = "dt = \"auto\"\nend = 4e-4\n";
    c.output = "dir = \"" + out + "\"\nname = \"bar\"\nframes = 2\nhistory_every = 2e-5\nenergy_limit = 1e6\n";
    c.material = fracture;
    c.rest = kHeld + "[[boundary]]\nregion = \"right\"\npressure = { times = [0.0, 2e-5, 4e-5, 6e-5, 8e-5], values = [0.0, " +
             std::to_string(-tension) + ", 0.0, " + std::to_string(2 * tension) + ", 0.0] }\n";
    return dir.write(name, c.text());
  };
  const PreparedCase e = prepare_case(pulse(dir.str() + "/e", kExtrinsic, 4e6, "e.toml"), {});
  const PreparedCase c = prepare_case(pulse(dir.str() + "/c", "", 4e6, "c.toml"), {});
  // The stable step by hand (model.cpp's estimate, written out for this case): the
  // smallest triangle height h over the wave speed √(M/ρ), M the plane-strain P-wave
  // modulus of the rock (tests/case_files.hpp: ρ 2000, E 10 GPa, ν 0.2) or, in a
  // fracturable triangle, the stiffest CE4 branch: the sliding penalty twice (the
  // cohesive part and the friction element's stick spring act together).
  const double rho = 2000, E = 10e9, nu = 0.2, P = 100e9;  // P: kRockFracture's penalties
  REQUIRE(e.model.fracture.size() == 1);
  REQUIRE(e.model.fracture[0].penalty_sliding == P);
  const double M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  double h = 1e300;
  for (const auto& t : e.model.triangles) {
    double longest = 0;
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, std::hypot(e.model.x[t[(k + 1) % 3]] - e.model.x[t[k]], e.model.y[t[(k + 1) % 3]] - e.model.y[t[k]]));
    const double area2 = std::fabs((e.model.x[t[1]] - e.model.x[t[0]]) * (e.model.y[t[2]] - e.model.y[t[0]]) -
                                   (e.model.y[t[1]] - e.model.y[t[0]]) * (e.model.x[t[2]] - e.model.x[t[0]]));
    h = std::min(h, area2 / longest);
  }
  const double penalty_step = h / std::sqrt(2 * P / rho), rock_step = h / std::sqrt(M / rho);
  CHECK(e.stable.dt == test::rel(penalty_step, 1e-12));
  CHECK(c.stable.dt == test::rel(rock_step, 1e-12));
  CHECK(e.dt == test::rel(0.5 * penalty_step, 1e-12));  // time.safety's default
  // Runs at a forced step, past prepare_case's check (which refuses a numeric dt above
  // the estimate): the worst |energy_error| and the CE4s inserted.
  auto at = [&](PreparedCase p, double dt) {
    p.dt = dt;
    p.steps = io::run_steps(p.config, dt);
    const RunSummary s = test::run(p);
    const auto inserted = has_extrinsic(p.model) ? test::read_variable(p.history_path, "inserted_ce4") : std::vector<double>{0};
    return std::make_pair(s.worst_energy_error, inserted.back());
  };
  const auto own = at(e, e.dt), rock = at(e, c.dt), intact = at(c, c.dt);
  const auto quiet = at(prepare_case(pulse(dir.str() + "/q", kExtrinsic, 1e6, "q.toml"), {}), c.dt);
  MESSAGE("steps: CE4 penalty " << e.dt << " s, rock " << c.dt << " s (" << c.dt / e.dt << " ×); worst |energy_error| "
          << own.first << " at the CE4 step (" << own.second << " inserted), " << rock.first << " at the rock's ("
          << rock.second << " inserted); at the rock's step the bar without CE4s " << intact.first
          << ", the extrinsic bar under a quarter of the pulse " << quiet.first << " (" << quiet.second << " inserted)");
  CHECK(c.dt / e.dt == doctest::Approx(std::sqrt(2 * P / M)).epsilon(1e-9));
  CHECK(own.second > 0);
  CHECK(own.first < 1e-3);
  CHECK(rock.second > 0);
  CHECK(rock.first > 0.1);  // energy made by the inserted CE4s' springs stepped past their limit
  CHECK(intact.first < 1e-4);  // the rock alone is stable at its step
  CHECK(quiet.second == 0);
  CHECK(quiet.first < 1e-4);  // so is the extrinsic bar as long as nothing is inserted
}

}  // TEST_SUITE
