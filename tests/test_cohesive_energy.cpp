// Cohesive elements (CE4): energy. Closed cycles of prescribed node motion that would let a
// CE4 give back more work than it took (a rigid turn while sheared and overlapping, which
// the traction pairs' moment turns into work; compress-slip-release with the Mohr-Coulomb
// friction); and the account of the stage: fracture dissipation never decreases, and work
// done on the CE4s = stored energy + fracture dissipation, along random and cyclic
// histories, with totals that are the same bit for bit on a second run.
// Rig: tests/cohesive_rig.hpp.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "cohesive_rig.hpp"
#include "fixture.hpp"
#include "reference_cohesive.hpp"

using namespace fdem;
namespace rc = fdem::reference_cohesive;
using rc::Vec;
using namespace fdem::cohesive_rig;

namespace {

// Places CE4 e with end gaps (normal, tangential) in the frame of the edge a→b turned by
// `angle` about its middle; the work of the step is added to `work` (trapezoid rule on
// the nodal forces, independent of the stage's own account).
struct Driver {
  Rig& rig;
  Vec a, b;
  std::vector<real2> x, x_prev, f_prev;
  double work = 0;
  int steps = 0;
  Driver(Rig& r, const Vec& a_, const Vec& b_) : rig(r), a(a_), b(b_), x(4), x_prev(4), f_prev(4) {
    place_at(Vec::Zero(), Vec::Zero(), 0.0);
    f_prev = rig.step(x, 0.0);
    x_prev = x;
  }
  void place_at(const Vec& gap_i, const Vec& gap_j, double angle) {
    const Vec mid = 0.5 * (a + b);
    const Eigen::Rotation2Dd R(angle);
    place(x, 0, mid + R * (a - mid), mid + R * (b - mid), gap_i, gap_j);
  }
  void to(const Vec& gap, double angle) {
    place_at(gap, gap, angle);
    const auto f = rig.step(x, 1e-6 * ++steps);
    work += work_increment(f_prev, f, x_prev, x);
    f_prev = f;
    x_prev = x;
  }
  // Straight path in (o, s, angle) from the current values, in n steps.
  Vec gap = Vec::Zero();
  double angle = 0;
  void go(const Vec& to_gap, double to_angle, int n) {
    const Vec g0 = gap;
    const double a0 = angle;
    for (int k = 1; k <= n; ++k) to(g0 + (to_gap - g0) * (double(k) / n), a0 + (to_angle - a0) * (double(k) / n));
    gap = to_gap;
    angle = to_angle;
  }
};

}  // namespace

TEST_SUITE("cohesive") {

TEST_CASE("a sheared, overlapping CE4 turned rigidly once round and back does no net work") {
  // Before the frame's share of the force (±M/|c| n), the faces' equal and opposite
  // tractions acted at points δ apart: a couple M = h t Σ w (τ o - σ s), so one turn took
  // or gave 2π M. φ = 0 isolates the frame from the friction.
  FractureProperties p = rock();
  p.friction_angle = 0.0;
  p.penalty_opening = p.penalty_sliding = p.penalty_overlap = 2e11;
  const Vec a(0.2, -0.1), b(0.35, 0.05);
  const double L = (b - a).norm(), thickness = 0.5;
  const rc::Law law = rc::make_law(p, L);
  for (const double o : {-2.0 * law.o_overlap, 0.5 * law.o_p}) {
    CAPTURE(o);
    Rig rig({{a, b}}, {p}, thickness);
    Driver d(rig, a, b);
    const Vec g(o, 0.7 * law.s_p);  // elastic: no damage, no dissipation anywhere on the path
    d.go(g, 0.0, 200);
    const double loaded = d.work;
    d.go(g, 2.0 * M_PI, 3600);  // one full turn at fixed o, s
    const double turn = d.work - loaded;
    d.go(Vec::Zero(), 2.0 * M_PI, 200);
    // The couple the old forces had, for scale: σ, τ from the law at (o, s).
    const double q = 0.7;
    const double sigma = o < 0 ? 2 * o * p.tensile_strength / law.o_overlap
                               : (2 * (o / law.o_p) - (o / law.o_p) * (o / law.o_p)) * p.tensile_strength;
    const double tau = q * (2 - q) * p.cohesion;
    const double couple = L * thickness * (tau * o - sigma * 0.7 * law.s_p);
    MESSAGE("o = ", o, ": work over one turn ", turn, " J (2π M of the traction pairs alone ", 2 * M_PI * couple,
            " J), over the whole cycle ", d.work, " J; elastic energy at the turn ", loaded, " J");
    CHECK(std::fabs(turn) < (kDoublePrecision ? 1e-6 : 1e-3) * std::fabs(2 * M_PI * couple));
    CHECK(std::fabs(d.work) < (kDoublePrecision ? 1e-6 : 1e-2) * loaded);
    CHECK(rig.stage->damage()[0] == 0);
  }
}

TEST_CASE("compress-slip-release cycles: the CE4 never gives back more work than it took") {
  // Slip at σ = 0, compress at that slip, slip back under compression, release: with the
  // paper's shear τ = (2q - q²)(c - σ tanφ) the unslip under compression returned more
  // than the slip cost, about (2/3) s_p |σ| tanφ h t a cycle. The other cycle (compress,
  // slip, release, unslip) costs energy either way. All within the elastic limit s_p.
  FractureProperties p = rock();
  p.penalty_opening = p.penalty_sliding = p.penalty_overlap = 2e11;
  const Vec a(-0.3, 0.15), b(-0.12, 0.2);
  const double L = (b - a).norm(), thickness = 0.8;
  const rc::Law law = rc::make_law(p, L);
  const double sigma = -8.0 * p.tensile_strength, o_c = sigma * law.o_overlap / (2 * p.tensile_strength);
  const double s0 = 0.9 * law.s_p;
  const double scale = (2.0 / 3.0) * s0 * std::fabs(sigma) * law.tan_phi * L * thickness;
  for (const bool extracting : {true, false}) {
    CAPTURE(extracting);
    Rig rig({{a, b}}, {p}, thickness);
    Driver d(rig, a, b);
    std::vector<double> after_cycle;
    for (int cycle = 0; cycle < 5; ++cycle) {
      if (extracting) {
        d.go(Vec(0, s0), 0, 100);
        d.go(Vec(o_c, s0), 0, 100);
        d.go(Vec(o_c, 0), 0, 100);
        d.go(Vec(0, 0), 0, 100);
      } else {
        d.go(Vec(o_c, 0), 0, 100);
        d.go(Vec(o_c, s0), 0, 100);
        d.go(Vec(0, s0), 0, 100);
        d.go(Vec(0, 0), 0, 100);
      }
      after_cycle.push_back(d.work);
    }
    MESSAGE((extracting ? "slip, compress, unslip, release" : "compress, slip, release, unslip"),
            ": work done on the CE4 after 1 and 5 cycles ", after_cycle.front(), ", ", after_cycle.back(),
            " J (scale (2/3) s_p |σ| tanφ h t = ", scale, " J)");
    for (double w : after_cycle) CHECK(w > -1e-9 * scale);
    CHECK(rig.stage->damage()[0] == 0);
  }
}

TEST_CASE("random and cyclic histories: fracture dissipation never decreases and work = stored + dissipation") {
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const size_t count = 120;
  const int steps = 6000;
  std::vector<std::pair<Vec, Vec>> edges;
  std::vector<FractureProperties> props;
  for (size_t e = 0; e < count; ++e) {
    const Vec c(2 * u(rng) - 1, 2 * u(rng) - 1);
    const double angle = 2 * M_PI * u(rng), h = 0.05 + 0.1 * u(rng);
    const Vec dir(std::cos(angle), std::sin(angle));
    edges.push_back({c - 0.5 * h * dir, c + 0.5 * h * dir});
    FractureProperties p = rock();
    p.friction_angle = 45 * u(rng);
    const double I_f = softening_integral(p.a, p.b, p.c);
    const double o_t = p.gf1 / (p.tensile_strength * I_f), s_t = p.gf2 / (p.cohesion * I_f);
    // o_p, s_p, o_overlap 5-30 % of o_t, s_t: the branches are resolved by the steps.
    p.penalty_opening = 2 * h * p.tensile_strength / ((0.05 + 0.25 * u(rng)) * o_t);
    p.penalty_sliding = 2 * h * p.cohesion / ((0.05 + 0.25 * u(rng)) * s_t);
    p.penalty_overlap = 2 * h * p.tensile_strength / ((0.05 + 0.25 * u(rng)) * o_t);
    props.push_back(p);
  }
  const double thickness = 0.4;
  Rig rig(edges, props, thickness);
  Rig twin(edges, props, thickness);  // the same histories again: the totals must agree bitwise
  // Smooth random paths: end gaps (normal, tangential) as sums of a few sines of random
  // period, amplitude and phase (cycles of opening, overlap and slip of either sign), a
  // slow drift towards breaking for a third of them, and a rigid turn and shift.
  struct Path {
    double amp[4], period[4], phase[4], drift_o, drift_s, spin;
  };
  std::vector<Path> path(count);
  for (size_t e = 0; e < count; ++e) {
    auto& w = path[e];
    for (int k = 0; k < 4; ++k) w.amp[k] = 0.2 + 0.6 * u(rng), w.period[k] = 400 + 2000 * u(rng), w.phase[k] = 6.3 * u(rng);
    w.drift_o = e % 3 == 0 ? 1.2 * u(rng) : 0.0;  // towards breaking
    w.drift_s = e % 3 == 0 ? 1.2 * u(rng) : 0.0;
    w.spin = 2.0 * (u(rng) - 0.5);
  }
  std::vector<real2> x(rig.ref.size());
  std::vector<double> previous(count, 0.0);
  double worst_drop = 0, worst_balance = 0, worst_total = 0, largest_dissipation = 0, largest_stored = 0;
  int broke = 0;
  for (int k = 1; k <= steps; ++k) {
    const double s = double(k) / steps;
    for (size_t e = 0; e < count; ++e) {
      const auto& w = path[e];
      const rc::Law& law = rig.laws[e];
      const double so = law.o_p + law.o_t, ss = law.s_p + law.s_t;
      // (ramped in over the first 300 steps: the paths start from the closed reference)
      auto wave = [&](int m) {
        return std::min(1.0, k / 300.0) * w.amp[m] * std::sin(2 * M_PI * k / w.period[m] + w.phase[m]);
      };
      const double on_i = so * (0.6 * wave(0) + w.drift_o * s), on_j = so * (0.6 * wave(1) + w.drift_o * s);
      const double sl_i = ss * (0.8 * wave(2) + w.drift_s * s), sl_j = ss * (0.8 * wave(3) + w.drift_s * s);
      const Vec a = edges[e].first, b = edges[e].second, mid = 0.5 * (a + b);
      const Eigen::Rotation2Dd R(w.spin * s);
      const Vec shift(0.01 * s, -0.02 * s);
      const Vec ra = mid + R * (a - mid) + shift, rb = mid + R * (b - mid) + shift;
      const auto [t, n] = frame(ra, rb);
      const Vec gi = on_i * n + sl_i * t, gj = on_j * n + sl_j * t;
      const Vec pts[4] = {ra - 0.5 * gi, rb - 0.5 * gj, rb + 0.5 * gj, ra + 0.5 * gi};
      for (int q = 0; q < 4; ++q) x[4 * e + q] = {real(pts[q].x()), real(pts[q].y())};
    }
    rig.step(x, 1e-6 * k);
    twin.step(x, 1e-6 * k);
    const auto work = rig.stage->work(), dissipated = rig.stage->dissipated(), stored = rig.stage->stored();
    double sum_d = 0, sum_s = 0;
    for (size_t e = 0; e < count; ++e) {
      const rc::Law& law = rig.laws[e];
      const double energy_scale =
          (law.tensile * (law.o_p + law.o_t) + law.cohesion * (law.s_p + law.s_t)) * law.h * thickness;
      worst_drop = std::max(worst_drop, (previous[e] - dissipated[e]) / energy_scale);
      previous[e] = dissipated[e];
      worst_balance = std::max(worst_balance, std::fabs(work[e] - stored[e] - dissipated[e]) / energy_scale);
      largest_dissipation = std::max(largest_dissipation, dissipated[e] / energy_scale);
      largest_stored = std::max(largest_stored, stored[e] / energy_scale);
      sum_d += dissipated[e];
      sum_s += stored[e];
    }
    if (k % 100 == 0) {
      const double total_d = rig.stage->fracture_dissipation(), total_s = rig.stage->stored_energy();
      worst_total = std::max({worst_total, std::fabs(total_d - sum_d) / (std::fabs(sum_d) + 1e-300),
                              std::fabs(total_s - sum_s) / (std::fabs(sum_s) + 1e-300)});
      CHECK(rig.stage->dissipated_total() == total_d);
      CHECK(twin.stage->fracture_dissipation() == total_d);
      CHECK(twin.stage->stored_energy() == total_s);
    }
  }
  broke = static_cast<int>(rig.stage->count_broken());
  MESSAGE("largest drop of a CE4's fracture dissipation ", worst_drop, ", largest |work - stored - dissipated| ",
          worst_balance, " (per CE4 energy scale); largest dissipation ", largest_dissipation, ", stored ",
          largest_stored, "; broken ", broke, " of ", count, "; totals vs sums ", worst_total);
  CHECK(worst_drop <= 0.0);
  CHECK(worst_balance < (kDoublePrecision ? 1e-4 : 2e-2));
  CHECK(worst_total < (kDoublePrecision ? 1e-12 : 1e-5));
  CHECK(largest_dissipation > 0.5);
  CHECK(largest_stored > 0.05);
  CHECK(broke > 0);
  CHECK(broke < static_cast<int>(count));
}

}  // TEST_SUITE
