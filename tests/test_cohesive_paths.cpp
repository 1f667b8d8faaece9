// Cohesive elements (CE4) along prescribed paths: the dissipated-energy account through
// unloading and reloading, and mixed-mode loading checked step by step against Eq. 9 with
// the failure mode it gives (kernel and reference; rig in tests/cohesive_rig.hpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <tuple>
#include <vector>

#include "approx.hpp"
#include "cohesive_rig.hpp"
#include "fixture.hpp"
#include "reference_cohesive.hpp"

using namespace fdem;
namespace rc = fdem::reference_cohesive;
using rc::Vec;
using namespace fdem::cohesive_rig;

TEST_SUITE("cohesive") {

TEST_CASE("dissipated energy through unloading and reloading: never decreases, constant on the secant, analytic at D = 0.5") {
  FractureProperties p = rock();
  p.penalty_opening = p.penalty_sliding = p.penalty_overlap = 2e12;  // o_p, s_p a few % of o_t, s_t
  const Vec a(-0.15, 0.05), b(0.02, 0.11);
  const double L = (b - a).norm(), thickness = 0.6;
  const rc::Law law = rc::make_law(p, L);
  const double area = L * thickness;
  const double tol = kDoublePrecision ? 1e-9 : 2e-3;
  // Float positions resolve the gaps to ~1e-3 of their size; the energy checks follow.
  const double energy_tol = kDoublePrecision ? 1e-9 : 1e-2;

  // Gaps along one direction, linear within each segment (so every kink of the law's
  // branches falls on a step and the trapezoid rule is exact on the secants). The one
  // discretisation error left is the trapezoid's on the elastic parabola, Δ³ T/(6 x_p²) per
  // unit area and step (it makes the account drift slightly negative while loading
  // elastically, and comes back on unloading): with the elastic range in 400 steps that is
  // 3e-10 G L t per step, under the tolerance of 1e-9 G L t.
  struct Segment {
    double to;
    int steps;
  };
  auto drive = [&](bool opening, const std::vector<Segment>& path, double G) {
    Rig rig({{a, b}}, {p}, thickness);
    std::vector<real2> x(4);
    double gap = 0, previous = 0, worst_drop = 0;
    std::vector<double> dissipated, damage, gaps;
    for (const auto& seg : path) {
      const double from = gap;
      for (int k = 1; k <= seg.steps; ++k) {
        gap = from + (seg.to - from) * k / seg.steps;
        const Vec g = opening ? Vec(gap, 0) : Vec(0, gap);
        place(x, 0, a, b, g, g);
        rig.step(x, 1e-3 * (gaps.size() + 1));
        const double d = rig.stage->dissipated()[0];
        worst_drop = std::max(worst_drop, previous - d);
        previous = d;
        dissipated.push_back(d);
        damage.push_back(rig.stage->damage()[0]);
        gaps.push_back(gap);
      }
    }
    const bool broken = rig.stage->broken()[0] != 0;
    const int mode = rig.stage->mode()[0];
    return std::make_tuple(dissipated, damage, worst_drop / G, broken, mode);
  };

  SUBCASE("normal: open to D = 0.5, close into overlap, reopen, break") {
    const double o1 = law.o_p + 0.5 * law.o_t, G = p.gf1 * area;
    const std::vector<Segment> path{{law.o_p, 400}, {o1, 600}, {0.0, 600}, {-0.5 * law.o_overlap, 100},
                                    {0.0, 100},     {o1, 600}, {1.05 * (law.o_p + law.o_t), 1000}};
    const auto [dissipated, damage, drop, broken, mode] = drive(true, path, G);
    const double at_half = area * envelope_dissipated(o1, law.o_p, law.o_t, p.tensile_strength, p);
    double secant_spread = 0;
    const int at = 999;  // the step that reaches o1
    for (int k = at; k < at + 1400; ++k) {
      secant_spread = std::max(secant_spread, std::fabs(dissipated[k] - dissipated[at]) / G);
      CHECK(damage[k] == test::rel(0.5, tol));  // D never recovers
    }
    MESSAGE("normal unload/reload: dissipated at D = 0.5 ", dissipated[at] / G, " G L t (analytic ", at_half / G,
            "), spread over the unload/reload ", secant_spread, " G L t, largest drop ", drop,
            " G L t, at the end ", dissipated.back() / G, " G L t");
    CHECK(std::fabs(dissipated[at] - at_half) < (kDoublePrecision ? 1e-6 : 2e-2) * G);
    CHECK(secant_spread < energy_tol);
    CHECK(drop < energy_tol);
    REQUIRE(broken);
    CHECK(mode == 1);
    const double elastic = 2.0 / 3.0 * p.tensile_strength * law.o_p * area;
    CHECK(dissipated.back() == doctest::Approx(G + elastic).epsilon(kDoublePrecision ? 1e-3 : 2e-2));
  }

  SUBCASE("shear: slip to D = 0.5, reverse to the same slip the other way, back, break") {
    const double s1 = law.s_p + 0.5 * law.s_t, G = p.gf2 * area;
    const std::vector<Segment> path{{law.s_p, 400}, {s1, 600}, {-s1, 1200}, {s1, 1200}, {1.05 * (law.s_p + law.s_t), 1000}};
    const auto [dissipated, damage, drop, broken, mode] = drive(false, path, G);
    const double at_half = area * envelope_dissipated(s1, law.s_p, law.s_t, p.cohesion, p);
    double secant_spread = 0;
    const int at = 999;  // the step that reaches s1
    for (int k = at; k < at + 2400; ++k) {
      secant_spread = std::max(secant_spread, std::fabs(dissipated[k] - dissipated[at]) / G);
      CHECK(damage[k] == test::rel(0.5, tol));
    }
    MESSAGE("shear unload/reload: dissipated at D = 0.5 ", dissipated[at] / G, " G L t (analytic ", at_half / G,
            "), spread over the reversal ", secant_spread, " G L t, largest drop ", drop, " G L t, at the end ",
            dissipated.back() / G, " G L t");
    CHECK(std::fabs(dissipated[at] - at_half) < (kDoublePrecision ? 1e-6 : 2e-2) * G);
    CHECK(secant_spread < energy_tol);
    CHECK(drop < energy_tol);
    REQUIRE(broken);
    CHECK(mode == 2);
    const double elastic = 2.0 / 3.0 * p.cohesion * law.s_p * area;
    CHECK(dissipated.back() == doctest::Approx(G + elastic).epsilon(kDoublePrecision ? 1e-3 : 2e-2));
  }
}

TEST_CASE("mixed mode end to end: along fixed opening/slip directions D follows Eq. 9, breaks at 1, mode by the dominant term") {
  // One CE4 per direction, all driven together with a uniform gap (o, s) = λ (1, r)
  // (metres; r = slip / opening) from zero, through both elastic limits, to breaking.
  // Eq. 9 is evaluated here from its formula; the kernel and the reference must both
  // follow it at every step.
  const FractureProperties p = rock();
  const Vec a(0.2, -0.3), b = a + 0.2 * Vec(std::cos(-0.4), std::sin(-0.4));
  const double thickness = 0.5;
  struct Direction {
    double open, slip;  // unit-free direction of (o, s)
    int mode;           // expected: the term of Eq. 9 with ≥ 90 % of D² at breaking
  };
  // With these properties s_t / o_t ≈ 2.07: slip/opening = 1 gives an opening share
  // a²/(a²+b²) ≈ 0.81, 3 gives ≈ 0.32 (both mixed), 0.1 gives ≈ 0.998 (mode I),
  // 1/0.05 gives ≈ 0.0106 (mode II); the negative slips check |s|.
  const std::vector<Direction> dirs{{1, 0, 1}, {0, 1, 2}, {1, 1, 3}, {1, -1, 3}, {1, 3, 3},
                                    {1, 0.1, 1}, {0.05, 1, 2}, {0, -1, 2}};
  const size_t count = dirs.size();
  std::vector<std::pair<Vec, Vec>> edges(count, {a, b});
  Rig rig(edges, {p}, thickness);
  const rc::Law& law = rig.laws[0];
  std::vector<rc::Ce4State> state(count);
  std::vector<real2> x(4 * count), x_prev(4 * count), f_prev(4 * count);
  std::vector<double> work(count, 0);

  // Eq. 9 with Macaulay brackets (the paper: D = D_I when |s| <= s_p, D_II when o <= o_p),
  // before the min(1, .), and the opening share of its square.
  auto eq9 = [&](double o, double s) {
    const double x1 = o > law.o_p ? (o - law.o_p) / law.o_t : 0.0;
    const double x2 = std::fabs(s) > law.s_p ? (std::fabs(s) - law.s_p) / law.s_t : 0.0;
    const double sum = x1 * x1 + x2 * x2;
    return std::pair<double, double>{std::sqrt(sum), sum > 0 ? x1 * x1 / sum : 0.0};
  };
  // Step λ so that every direction breaks after about 600 steps.
  std::vector<double> lambda_step(count);
  for (size_t e = 0; e < count; ++e) {
    const double reach = 1.0 / std::hypot(dirs[e].open / law.o_t, dirs[e].slip / law.s_t);
    const double offset = std::max(law.o_p, law.s_p) / std::max(std::fabs(dirs[e].open), std::fabs(dirs[e].slip));
    lambda_step[e] = (reach + offset) / 600.5;  // the .5 keeps the steps off D = 1 exactly
  }
  std::vector<int> break_step(count, -1), expected_break(count, -1), kernel_mode(count, 0);
  std::vector<double> share_at_break(count, 0), dissipated_at_break(count, 0), work_at_break(count, 0);
  double worst_kernel = 0, worst_reference = 0, closest_to_one = 1;
  for (int k = 1; k <= 800; ++k) {
    for (size_t e = 0; e < count; ++e) {
      const double lam = lambda_step[e] * k;
      place(x, e, a, b, Vec(lam * dirs[e].open, lam * dirs[e].slip), Vec(lam * dirs[e].open, lam * dirs[e].slip));
    }
    const auto f = rig.step(x, 1e-4 * k);
    const auto damage = rig.stage->damage(), dissipated = rig.stage->dissipated();
    const auto broken = rig.stage->broken(), mode = rig.stage->mode();
    for (size_t e = 0; e < count; ++e) {
      const double lam = lambda_step[e] * k;
      const auto [raw, share] = eq9(lam * dirs[e].open, lam * dirs[e].slip);
      const double D = std::min(1.0, raw);
      if (expected_break[e] < 0) closest_to_one = std::min(closest_to_one, std::fabs(raw - 1.0));
      if (raw >= 1.0 && expected_break[e] < 0) expected_break[e] = k, share_at_break[e] = share;
      const auto r = rc::step(law, state[e], nodes_of(x, e), thickness, 1e-4 * k);
      if (break_step[e] < 0) {
        std::vector<real2> fe(f.begin() + 4 * e, f.begin() + 4 * e + 4), fp(f_prev.begin() + 4 * e, f_prev.begin() + 4 * e + 4);
        std::vector<real2> xe(x.begin() + 4 * e, x.begin() + 4 * e + 4), xp(x_prev.begin() + 4 * e, x_prev.begin() + 4 * e + 4);
        work[e] += work_increment(fp, fe, xp, xe);
        worst_kernel = std::max(worst_kernel, std::fabs(damage[e] - D));
        worst_reference = std::max(worst_reference, std::fabs(r.damage - D));
      }
      if (broken[e] && break_step[e] < 0) {
        break_step[e] = k;
        kernel_mode[e] = mode[e];
        dissipated_at_break[e] = dissipated[e];
        work_at_break[e] = work[e];
        CHECK(state[e].broken);
        CHECK(state[e].mode == mode[e]);
      }
    }
    f_prev = f;
    x_prev = x;
  }
  MESSAGE("mixed mode: |D_kernel - Eq. 9| <= ", worst_kernel, ", |D_reference - Eq. 9| <= ", worst_reference,
          " (closest approach of Eq. 9 to 1 at a step ", closest_to_one, ")");
  for (size_t e = 0; e < count; ++e) {
    const double scale = (p.gf1 + p.gf2) * 0.2 * thickness;
    MESSAGE("slip/opening ", dirs[e].slip, "/", dirs[e].open, ": broke at step ", break_step[e], " (Eq. 9 reaches 1 at ",
            expected_break[e], "), opening share ", fixed(share_at_break[e], 4), ", mode ", kernel_mode[e],
            ", dissipated ", dissipated_at_break[e], " J (nodal work ", work_at_break[e], " J)");
    CHECK(expected_break[e] > 0);
    // Float positions resolve the gaps to ~1e-3 of their size: one step either way there.
    CHECK(std::abs(break_step[e] - expected_break[e]) <= (kDoublePrecision ? 0 : 1));
    CHECK(kernel_mode[e] == dirs[e].mode);
    CHECK(std::fabs(dissipated_at_break[e] - work_at_break[e]) < (kDoublePrecision ? 1e-9 : 1e-3) * scale);
  }
  CHECK(worst_kernel < (kDoublePrecision ? 1e-9 : 1e-2));
  CHECK(worst_reference < (kDoublePrecision ? 1e-9 : 1e-2));
  CHECK(closest_to_one > 1e-6);  // no step sits so close to D = 1 that round-off could decide it
}

}  // TEST_SUITE
